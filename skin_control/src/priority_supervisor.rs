//! The priority supervisor's work without the node around it: `/controller/state` in,
//! `skin_core::supervisor::Supervisor` updated on the state's stamp, `/supervisor/arrangement`
//! out when it changed; phase requests from `/supervisor/set_phase`; a new goal (the state's
//! `goal_count` changed) ends a blocked hold.
use r2r::skin_msgs::msg::{Arrangement as ArrangementMsg, ControllerState};
use skin_core::supervisor::{Phase, Supervisor, SupervisorParams};

use crate::convert::control::{arrangement_msg, supervisor_input};

/// The `SetPhase.srv` phase constants.
pub const PRECONTACT: u8 = 0;
/// See [`PRECONTACT`].
pub const CONTACT: u8 = 1;

/// The supervisor with its last published arrangement.
#[derive(Debug, Clone)]
pub struct PrioritySupervisor {
    sup: Supervisor,
    last: Option<ArrangementMsg>,
    updates: u64,
    goal_count: Option<u32>,
}

impl PrioritySupervisor {
    /// A supervisor from `params` at `t0_s`.
    pub fn new(params: &SupervisorParams, t0_s: f64) -> Result<Self, String> {
        Ok(PrioritySupervisor {
            sup: Supervisor::new(params, t0_s).map_err(|e| e.to_string())?,
            last: None,
            updates: 0,
            goal_count: None,
        })
    }

    /// The supervisor.
    pub fn supervisor(&self) -> &Supervisor {
        &self.sup
    }

    /// Number of controller states taken.
    pub fn updates(&self) -> u64 {
        self.updates
    }

    /// The active arrangement as a message.
    pub fn current(&self) -> ArrangementMsg {
        arrangement_msg(self.sup.arrangement(), self.sup.tasks(), self.sup.blocked())
    }

    /// Takes one controller state; returns the arrangement to publish when it differs from the
    /// last one published (a switch, a sensing-range step, a new fusion target). States of
    /// periods without a cycle (waiting or stale inputs) repeat old signals and are skipped: a
    /// stalled robot must not look stuck (Table I (a) -> (b)).
    pub fn on_state(&mut self, msg: &ControllerState) -> Option<ArrangementMsg> {
        if msg.input_status != ControllerState::INPUT_FRESH as u8 {
            return None;
        }
        if self.goal_count.replace(msg.goal_count).is_some_and(|c| c != msg.goal_count) {
            self.sup.new_goal(); // as the controller's own supervisor does in `set_goal`
        }
        let (t, input) = supervisor_input(msg);
        self.sup.update(t, &input);
        self.updates += 1;
        let now = self.current();
        if self.last.as_ref() == Some(&now) {
            return None;
        }
        self.last = Some(now.clone());
        Some(now)
    }

    /// Marks `msg` as published (the initial and periodic publications).
    pub fn published(&mut self, msg: &ArrangementMsg) {
        self.last = Some(msg.clone());
    }

    /// A `SetPhase` request: `(accepted, message)`.
    pub fn request_phase(&mut self, phase: u8) -> (bool, String) {
        let p = match phase {
            PRECONTACT => Phase::PreContact,
            CONTACT => Phase::Contact,
            other => return (false, format!("phase = {other}: not SetPhase.PRECONTACT (0) or CONTACT (1)")),
        };
        match self.sup.request_phase(p) {
            Ok(()) => (true, format!("{p:?} requested: takes effect with the next controller state")),
            Err(e) => (false, e.to_string()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::convert::robot::time_msg;
    use std::path::Path;

    fn params(policy: &str) -> SupervisorParams {
        let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("../config/supervisor.yaml");
        let text =
            std::fs::read_to_string(p).unwrap().replace("policy: intentional_contact", &format!("policy: {policy}"));
        SupervisorParams::from_yaml_str(&text, "supervisor.yaml").unwrap()
    }

    fn state(t: f64, speed: f64, fd: f64, fc: f64, ge: f64) -> ControllerState {
        ControllerState {
            header: r2r::std_msgs::msg::Header { stamp: time_msg(t), ..Default::default() },
            ee_speed: speed,
            avoidance_force: fd,
            contact_force: fc,
            goal_error: ge,
            ..Default::default()
        }
    }

    #[test]
    fn switches_are_published_once_and_phases_refused_under_table_i() {
        let mut s = PrioritySupervisor::new(&params("intentional_contact"), 0.0).unwrap();
        let first = s.on_state(&state(0.01, 0.5, 0.0, 0.0, 0.3)).unwrap();
        assert_eq!((first.mode, first.task_order[0].as_str()), (0, "avoidance"));
        assert!(s.on_state(&state(0.02, 0.5, 0.0, 0.0, 0.3)).is_none());
        let stale =
            ControllerState { input_status: ControllerState::INPUT_STALE as u8, ..state(0.025, 0.5, 0.0, 9.0, 0.3) };
        assert!(s.on_state(&stale).is_none() && s.updates() == 2, "a stale period's state is not an input");
        let impact = state(0.03, 0.5, 0.0, params("intentional_contact").thresholds.impact_force_n, 0.3);
        let hard = s.on_state(&impact).unwrap();
        assert_eq!(hard.mode, 2);
        assert_eq!(hard.switch_time, time_msg(0.03));
        let (ok, why) = s.request_phase(CONTACT);
        assert!(!ok && why.contains("intentional_contact policy"), "{why}");
        let (ok, why) = s.request_phase(7);
        assert!(!ok && why.contains("phase = 7"), "{why}");
    }

    /// A push that reached ε_c holds the arm blocked, announced in the arrangement with its
    /// reason; the hold ends when the controller reports a new goal (its `goal_count`), as it
    /// ends in the controller's own supervisor.
    #[test]
    fn a_blocked_hold_is_published_and_ended_by_a_new_goal() {
        let mut s = PrioritySupervisor::new(&params("intentional_contact"), 0.0).unwrap();
        let mut t = 0.0;
        let mut last = None;
        let mut feed = |s: &mut PrioritySupervisor, steps: usize, fc: f64, goals: u32| {
            for _ in 0..steps {
                t += 0.004;
                let msg = ControllerState { goal_count: goals, ..state(t, 0.0, 3.0, fc, 0.2) };
                last = s.on_state(&msg).or(last.take());
            }
            last.clone().unwrap()
        };
        // 2.4 s: stuck for `stuck_s`, then pushing for less than `push_stall_s`
        assert_eq!(feed(&mut s, 600, 0.0, 7).mode, 1, "stuck at an obstacle: (b)");
        assert_eq!(feed(&mut s, 30, 20.0, 7).mode, 2, "the push reached eps_c: (c)");
        let held = feed(&mut s, 500, 0.0, 7);
        assert_eq!(held.mode, 0);
        assert!(s.supervisor().releasing() && held.blocked.active, "{held:?}");
        assert_eq!((held.blocked.goal_error, held.blocked.contact_force), (0.2, 20.0));
        let held = feed(&mut s, 2500, 0.0, 7);
        assert!(held.blocked.active && held.mode == 0, "10 s still stuck: held, no second push");
        let freed = feed(&mut s, 1, 0.0, 8);
        assert!(!freed.blocked.active && !s.supervisor().releasing(), "a new goal ends the hold: {freed:?}");
        assert_eq!(feed(&mut s, 600, 0.0, 8).mode, 1, "and the arm may push toward it");
    }

    #[test]
    fn phases_on_request() {
        let mut s = PrioritySupervisor::new(&params("phases"), 0.0).unwrap();
        assert_eq!(s.on_state(&state(0.01, 0.0, 0.0, 0.0, -1.0)).unwrap().mode, 3);
        let (ok, why) = s.request_phase(CONTACT);
        assert!(ok, "{why}");
        let m = s.on_state(&state(0.02, 0.0, 0.0, 0.0, -1.0)).unwrap();
        assert_eq!(m.mode, 4);
        assert_eq!(m.task_order[0], "hand_force");
    }
}
