//! `/diagnostics` of the task controller (`diagnostic_msgs/DiagnosticArray`), as ROS 2's
//! diagnostic_updater publishes them, for rqt_robot_monitor and diagnostic_aggregator: once per
//! [`PERIOD`] on the global [`TOPIC`], each status named `<node>: <what>` (the node's name
//! without the leading `/`), `hardware_id` the robot's name from the URDF. One status for the
//! control loop (state, cycle time, overruns), one for the task hierarchy (the arrangement
//! followed, and a push given up: the blocked hold, WARN, with its reason) and one per required
//! input (ok, waiting, stale or skewed, with its age).
use std::time::Duration;

use r2r::builtin_interfaces::msg::Time;
use r2r::diagnostic_msgs::msg::{DiagnosticArray, DiagnosticStatus, KeyValue};
use r2r::std_msgs::msg::Header;

use skin_core::controller::Controller;
use skin_core::supervisor::Blocked;

use crate::input_health::{fresh, IssueTable, StampIssue};
use crate::task_controller::InputAge;
use crate::timing::Timing;

/// The topic (global, as diagnostic_updater's).
pub const TOPIC: &str = "/diagnostics";
/// Time between two reports (diagnostic_updater's default period).
pub const PERIOD: Duration = Duration::from_secs(1);

/// `DiagnosticStatus.level` values (the message's constants, as bytes).
pub mod level {
    use r2r::diagnostic_msgs::msg::DiagnosticStatus;
    /// All is well.
    pub const OK: u8 = DiagnosticStatus::OK as u8;
    /// Degraded: the controller holds still or something was refused.
    pub const WARN: u8 = DiagnosticStatus::WARN as u8;
    /// The controller cannot command (a stale or skewed input, another commander).
    pub const ERROR: u8 = DiagnosticStatus::ERROR as u8;
}

/// One input's health at a report.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InputHealth {
    /// Its age is in `[-max_stamp_lead_s, timeout]`.
    Ok,
    /// Not received yet.
    Waiting,
    /// Older than its timeout: the commands ramp to zero.
    Stale,
    /// Stamped ahead of this node's clock by more than `max_stamp_lead_s` (its messages are
    /// refused, or its age is below the lead): the sender's clock is not synchronized.
    Skewed,
}

impl InputHealth {
    /// The health of an input of age `age_s` (None: not received) with `timeout_s`;
    /// `future_refused`: messages stamped ahead of the clock were refused since the last report.
    pub fn of(age_s: Option<f64>, timeout_s: f64, max_lead_s: f64, future_refused: bool) -> Self {
        match age_s {
            Some(a) if fresh(a, timeout_s, max_lead_s) => InputHealth::Ok,
            Some(a) if a < -max_lead_s => InputHealth::Skewed,
            _ if future_refused => InputHealth::Skewed,
            Some(_) => InputHealth::Stale,
            None => InputHealth::Waiting,
        }
    }

    /// The status level.
    pub fn level(self) -> u8 {
        match self {
            InputHealth::Ok => level::OK,
            InputHealth::Waiting => level::WARN,
            InputHealth::Stale | InputHealth::Skewed => level::ERROR,
        }
    }

    /// The word that starts the status message.
    pub fn name(self) -> &'static str {
        match self {
            InputHealth::Ok => "ok",
            InputHealth::Waiting => "waiting",
            InputHealth::Stale => "stale",
            InputHealth::Skewed => "skewed",
        }
    }
}

/// The control loop over one report period.
#[derive(Debug, Clone)]
pub struct LoopReport {
    /// Level and message (what the controller does and why).
    pub level: u8,
    /// The message.
    pub message: String,
    /// Managed-node state (`unconfigured`, `inactive`, `active`, ...).
    pub lifecycle: &'static str,
    /// Control rate \[Hz\].
    pub rate_hz: f64,
    /// Cycle computation times of this period.
    pub timing: Timing,
    /// Since start: cycles, cycles whose computation took longer than the control period,
    /// timer periods that came more than 1.5 periods after the last commands, safe-stop cycles,
    /// periods without a cycle.
    pub cycles: u64,
    /// See `cycles`.
    pub overruns: u64,
    /// See `cycles`.
    pub late_periods: u64,
    /// See `cycles`.
    pub safe_stop_cycles: u64,
    /// See `cycles`.
    pub idle_periods: u64,
}

/// The task hierarchy at a report: the arrangement in force and the blocked hold.
#[derive(Debug, Clone, PartialEq)]
pub struct HierarchyReport {
    /// The arrangement's mode (`Mode::name`).
    pub mode: &'static str,
    /// Its tasks, highest priority first.
    pub tasks: Vec<String>,
    /// Nothing is to be pressed (a hard contact, the blocked hold).
    pub releasing: bool,
    /// Why the arm holds after a push given up.
    pub blocked: Option<Blocked>,
}

impl HierarchyReport {
    /// The hierarchy of `controller`'s last cycle.
    pub fn of(controller: &Controller) -> Self {
        let sup = controller.supervisor();
        let out = controller.output();
        HierarchyReport {
            mode: out.mode.name(),
            tasks: sup.arrangement().task_names(sup.tasks()).map(str::to_string).collect(),
            releasing: out.releasing,
            blocked: out.blocked,
        }
    }
}

/// Builds the reports of one node; remembers the input issue counts of the last report (an
/// input whose messages were refused since then is at least WARN).
#[derive(Debug, Clone)]
pub struct Diagnostics {
    prefix: String,
    hardware_id: String,
    last_counts: Vec<(String, u64)>,
}

fn kv(key: &str, value: impl ToString) -> KeyValue {
    KeyValue { key: key.into(), value: value.to_string() }
}

fn ms(d: Duration) -> String {
    format!("{:.3}", d.as_secs_f64() * 1e3)
}

impl Diagnostics {
    /// Reports of the node `fqn` (its fully qualified name) on robot `hardware_id`.
    pub fn new(fqn: &str, hardware_id: &str) -> Self {
        let prefix = fqn.trim_start_matches('/').to_string();
        Diagnostics { prefix, hardware_id: hardware_id.into(), last_counts: Vec::new() }
    }

    /// The robot is known now (its name from the URDF).
    pub fn set_hardware_id(&mut self, id: &str) {
        self.hardware_id = id.into();
    }

    fn status(&self, what: &str, level: u8, message: String, values: Vec<KeyValue>) -> DiagnosticStatus {
        DiagnosticStatus {
            level,
            name: format!("{}: {what}", self.prefix),
            message,
            hardware_id: self.hardware_id.clone(),
            values,
        }
    }

    fn hierarchy_status(&self, h: &HierarchyReport) -> DiagnosticStatus {
        let order = h.tasks.join(" > ");
        let mut values = vec![kv("mode", h.mode), kv("tasks", &order), kv("releasing", h.releasing)];
        let (level, message) = match &h.blocked {
            None => (level::OK, format!("{}: {order}", h.mode)),
            Some(b) => {
                values.push(kv("blocked since [s]", format!("{:.3}", b.since_s)));
                values.push(kv("blocking force [N]", format!("{:.2}", b.contact_force_n)));
                values.push(kv("goal error then [m]", format!("{:.3}", b.goal_error_m)));
                (level::WARN, format!("blocked: {b}"))
            }
        };
        self.status("task hierarchy", level, message, values)
    }

    /// A report before the controller exists: the control loop WAITING for `what`.
    pub fn waiting(&self, stamp: Time, what: &str) -> DiagnosticArray {
        let lp = self.status(
            "control loop",
            level::WARN,
            format!("WAITING for {what}"),
            vec![kv("state", "WAITING"), kv("waiting for", what)],
        );
        DiagnosticArray { header: Header { stamp, frame_id: String::new() }, status: vec![lp] }
    }

    /// The report at `now_s` (the node's clock, for the ages), stamped `stamp`: the control
    /// loop `lp`, the task hierarchy `h`, then one status per input of `inputs`, with its
    /// counters from `issues`.
    pub fn report(
        &mut self,
        stamp: Time,
        lp: &LoopReport,
        h: &HierarchyReport,
        inputs: &[InputAge],
        max_lead_s: f64,
        issues: &IssueTable,
    ) -> DiagnosticArray {
        let t = &lp.timing;
        let mean = t.total.checked_div(t.count.max(1) as u32).unwrap_or_default();
        let mut status = vec![self.status(
            "control loop",
            lp.level,
            lp.message.clone(),
            vec![
                kv("lifecycle state", lp.lifecycle),
                kv("control rate [Hz]", lp.rate_hz),
                kv("cycles in the last period", t.count),
                kv("cycle time mean [ms]", ms(mean)),
                kv("cycle time max [ms]", ms(t.max)),
                kv("cycles", lp.cycles),
                kv("overruns", lp.overruns),
                kv("late periods", lp.late_periods),
                kv("safe-stop cycles", lp.safe_stop_cycles),
                kv("idle periods", lp.idle_periods),
            ],
        )];
        status.push(self.hierarchy_status(h));
        let future = StampIssue::Future.name();
        let mut counts = Vec::new();
        for input in inputs {
            let mut values = vec![
                kv("age [s]", input.age_s.map_or("none".into(), |a| format!("{a:.4}"))),
                kv("timeout [s]", input.timeout_s),
            ];
            let (mut future_refused, mut new_issues) = (false, Vec::new());
            for (kind, count) in issues.of_topic(input.topic) {
                let key = format!("{}: {kind}", input.topic);
                let before = self.last_counts.iter().find(|(k, _)| *k == key).map_or(0, |(_, c)| *c);
                if count > before {
                    future_refused |= kind == future;
                    new_issues.push(format!("{kind}: {}", count - before));
                }
                values.push(kv(kind, count));
                counts.push((key, count));
            }
            let health = InputHealth::of(input.age_s, input.timeout_s, max_lead_s, future_refused);
            values.insert(0, kv("health", health.name()));
            let mut message = health.name().to_string();
            match (health, input.age_s) {
                (InputHealth::Waiting, _) | (_, None) => {}
                (_, Some(a)) => message += &format!(": {a:.3} s old (timeout {} s)", input.timeout_s),
            }
            if let Some(d) = &input.detail {
                message += &format!(", {d}");
                values.push(kv("detail", d));
            }
            let mut level = health.level();
            if !new_issues.is_empty() {
                message += &format!("; since the last report: {}", new_issues.join(", "));
                level = level.max(level::WARN);
            }
            status.push(self.status(&format!("input {}", input.topic), level, message, values));
        }
        self.last_counts = counts;
        DiagnosticArray { header: Header { stamp, frame_id: String::new() }, status }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::convert::robot::time_msg;

    fn lp() -> LoopReport {
        LoopReport {
            level: level::OK,
            message: "commanding".into(),
            lifecycle: "active",
            rate_hz: 125.0,
            timing: Timing { count: 4, total: Duration::from_millis(8), max: Duration::from_millis(3) },
            cycles: 10,
            overruns: 1,
            late_periods: 2,
            safe_stop_cycles: 0,
            idle_periods: 3,
        }
    }

    fn hierarchy(blocked: Option<Blocked>) -> HierarchyReport {
        HierarchyReport {
            mode: "avoidance",
            tasks: vec!["avoidance".into(), "goal".into()],
            releasing: blocked.is_some(),
            blocked,
        }
    }

    /// A push given up is a WARN with its reason, what an operator needs to step in.
    #[test]
    fn the_blocked_hold_is_a_warning_with_its_reason() {
        let d = Diagnostics::new("/task_controller", "planar7");
        let b = Blocked { since_s: 11.01, goal_error_m: 0.129, contact_force_n: 6.95 };
        let s = d.hierarchy_status(&hierarchy(Some(b)));
        assert_eq!(s.level, level::WARN);
        assert!(s.message.starts_with("blocked: the push was given up at t = 11.010 s (6.95 N"), "{}", s.message);
        assert_eq!((value(&s, "blocking force [N]"), value(&s, "releasing")), ("6.95", "true"));
    }

    fn value<'a>(s: &'a DiagnosticStatus, key: &str) -> &'a str {
        &s.values.iter().find(|v| v.key == key).unwrap_or_else(|| panic!("{key} in {:?}", s.values)).value
    }

    #[test]
    fn health_by_age_and_refusals() {
        assert_eq!(InputHealth::of(Some(0.05), 0.1, 0.02, false), InputHealth::Ok);
        assert_eq!(InputHealth::of(Some(0.2), 0.1, 0.02, false), InputHealth::Stale);
        assert_eq!(InputHealth::of(Some(-0.5), 0.1, 0.02, false), InputHealth::Skewed);
        assert_eq!(InputHealth::of(None, 0.1, 0.02, false), InputHealth::Waiting);
        assert_eq!(InputHealth::of(Some(0.2), 0.1, 0.02, true), InputHealth::Skewed, "old because refused");
        assert_eq!(InputHealth::of(None, 0.1, 0.02, true), InputHealth::Skewed);
        assert_eq!(InputHealth::of(Some(0.05), 0.1, 0.02, true), InputHealth::Ok, "some got through");
    }

    #[test]
    fn a_report_names_every_input_with_its_health_age_and_new_issues() {
        let mut table = IssueTable::default();
        let js = table.register("/joint_states", StampIssue::ALL.map(StampIssue::name));
        table.register("/scan", ["message refused"]);
        let mut d = Diagnostics::new("/tomm/task_controller", "tomm");
        let inputs = [
            InputAge {
                topic: "/joint_states",
                age_s: Some(0.5),
                timeout_s: 0.1,
                detail: Some("oldest joint `j1`".into()),
            },
            InputAge { topic: "/scan", age_s: None, timeout_s: 0.25, detail: None },
        ];
        let a = d.report(time_msg(3.0), &lp(), &hierarchy(None), &inputs, 0.02, &table);
        assert_eq!(a.status.len(), 4);
        let names: Vec<&str> = a.status.iter().map(|s| s.name.as_str()).collect();
        assert_eq!(
            names,
            [
                "tomm/task_controller: control loop",
                "tomm/task_controller: task hierarchy",
                "tomm/task_controller: input /joint_states",
                "tomm/task_controller: input /scan"
            ]
        );
        assert!(a.status.iter().all(|s| s.hardware_id == "tomm"));
        let (lp_s, js_s, scan) = (&a.status[0], &a.status[2], &a.status[3]);
        assert_eq!((a.status[1].level, a.status[1].message.as_str()), (level::OK, "avoidance: avoidance > goal"));
        assert_eq!((value(lp_s, "cycle time mean [ms]"), value(lp_s, "cycle time max [ms]")), ("2.000", "3.000"));
        assert_eq!((value(lp_s, "overruns"), value(lp_s, "late periods")), ("1", "2"));
        assert_eq!(js_s.level, level::ERROR);
        assert_eq!(js_s.message, "stale: 0.500 s old (timeout 0.1 s), oldest joint `j1`");
        assert_eq!((value(js_s, "health"), value(js_s, "age [s]")), ("stale", "0.5000"));
        assert_eq!((scan.level, scan.message.as_str()), (level::WARN, "waiting"));

        // future stamps refused since the last report: skewed, and the counts say so
        table.count(js + StampIssue::Future as usize);
        let b = d.report(time_msg(4.0), &lp(), &hierarchy(None), &inputs, 0.02, &table);
        assert_eq!(b.status[2].level, level::ERROR);
        assert!(b.status[2].message.starts_with("skewed: 0.500 s old"), "{}", b.status[2].message);
        assert!(
            b.status[2].message.ends_with("since the last report: stamp in the future: 1"),
            "{}",
            b.status[2].message
        );
        let fresh = [InputAge { age_s: Some(0.01), ..inputs[0].clone() }];
        let c = d.report(time_msg(5.0), &lp(), &hierarchy(None), &fresh, 0.02, &table);
        assert_eq!((c.status[2].level, value(&c.status[2], "stamp in the future")), (level::OK, "1"), "nothing new");
        let w = d.waiting(time_msg(0.0), "the URDF on /robot_description");
        assert_eq!(
            (w.status[0].level, w.status[0].message.as_str()),
            (level::WARN, "WAITING for the URDF on /robot_description")
        );
    }
}
