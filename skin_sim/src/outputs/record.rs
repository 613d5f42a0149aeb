//! The run record of a closed-loop simulation: one [`CycleRecord`] per control cycle and the
//! arrangement switches, everything the metrics, the summary, the plots (`skin_sim::outputs::plot`) and the
//! bag writer (the `skin_bag` crate) read. Plain data; nothing in it is computed twice.

use crate::world::{BusyTime, KeyFrame};
use skin_core::supervisor::{Blocked, Mode, SupervisorInput};

use crate::outputs::view::View;

/// One control cycle: the measurements the controller got, what it decided and what the
/// simulation measured at the same instant.
#[derive(Debug, Clone, PartialEq)]
pub struct CycleRecord {
    /// Simulation time of the measurements \[s\].
    pub t_s: f64,
    /// Joint positions, model order (frozen joints: their fixed value).
    pub q: Vec<f64>,
    /// Joint velocities, model order (frozen joints: 0).
    pub qd: Vec<f64>,
    /// Commanded arm joint velocities, in [`RunRecord::arm_joints`] order \[rad/s or m/s\].
    pub joint_velocities: Vec<f64>,
    /// Commanded base twist `(vx, vy, wz)` in the base frame (a scene's base motion is the
    /// controller's reference, so it is in here, not added to it).
    pub base_twist: [f64; 3],
    /// Active arrangement (intentional-contact paper Table I / interactive-force-control paper Table 1).
    pub mode: Mode,
    /// Why the supervisor holds the arm in (a) after a push that reached `ε_c` (`None`: not
    /// blocked; `ControllerState.blocked` when the controller ran elsewhere).
    pub blocked: Option<Blocked>,
    /// Nothing is to be pressed: in a hard contact (c) and in the blocked hold after a push given
    /// up (`skin_core::supervisor::Supervisor::releasing`, `ControllerState.releasing`).
    pub releasing: bool,
    /// `χ` of intentional-contact paper eq. (10)-(11), 0 outside a blend.
    pub blend: f64,
    /// Fusion weight `w(t)` of interactive-force-control paper eq. (6) the skin was fused with.
    pub fusion_weight: f64,
    /// The supervisor's signals: ee speed, `‖F_d‖`, skin contact force `‖F_c‖`, goal error.
    pub signals: SupervisorInput,
    /// `‖τ*‖` \[N m\].
    pub torque_norm: f64,
    /// Normal force of the environment pressing on the hand along its z axis, from MuJoCo's
    /// contacts \[N\] (interactive-force-control paper's contact force `f_c`, measured physically).
    pub hand_force_n: f64,
    /// Largest total normal contact force of the environment on one robot link, from MuJoCo
    /// \[N\] (the physical counterpart of the skin's `‖F_c‖`).
    pub link_force_n: f64,
    /// Hand frame origin in the world, from MuJoCo \[m\].
    pub hand_position_m: [f64; 3],
    /// Distance ahead of the palm (along `+z_h`) to the first object or person, from MuJoCo \[m\]
    /// (infinite: nothing ahead).
    pub hand_distance_m: f64,
    /// Largest tilt of a movable object from its start orientation, from MuJoCo \[deg\]: over
    /// 45° an obstacle toppled (a planar scene's obstacle left the plane it models).
    pub object_tilt_deg: f64,
    /// `ʰΓ`, the hand skin's moment in the hand frame that the controller computed (interactive-force-control paper
    /// eq. 10; normalized-signal units times metres); NaN when the controller ran elsewhere (the ROS
    /// graph does not publish it).
    pub hand_moment: [f64; 3],
    /// Force reference of the scene at this time \[N\] (NaN: none active).
    pub force_reference_n: f64,
    /// The force reference as the hand signal of an even press of the palm, `n f(F/n)`
    /// (`HandForceMap`; NaN: none), what the paper's summed signal would read. The controller is
    /// given the newtons and regulates the pressed hand cells' newtons (`skin_core::skin::measured`).
    pub force_reference_signal: f64,
    /// Whether a scripted interaction (push on the robot, a person near the base, scripted base
    /// motion) is going on.
    pub interaction: bool,
    /// The controller's fault text when the cycle was a safe-stop step.
    pub fault: Option<String>,
    /// Wall-clock time of `Controller::update` \[µs\] (the only field that is not reproducible).
    pub compute_us: f64,
}

#[cfg(test)]
impl CycleRecord {
    /// A cycle at `t_s` in the contact phase with nothing moving, the hand and link force `force_n`
    /// (tests).
    pub(crate) fn at_rest(t_s: f64, force_n: f64) -> Self {
        CycleRecord {
            t_s,
            q: vec![],
            qd: vec![],
            joint_velocities: vec![],
            base_twist: [0.0; 3],
            mode: Mode::Contact,
            blocked: None,
            releasing: false,
            blend: 0.0,
            fusion_weight: 1.0,
            signals: SupervisorInput {
                ee_speed_mps: 0.0,
                avoidance_force_n: 0.0,
                contact_force_n: 0.0,
                goal_error_m: 0.0,
                contact_advance_mps: f64::NAN,
            },
            torque_norm: 0.0,
            hand_force_n: force_n,
            link_force_n: force_n,
            hand_position_m: [0.0; 3],
            hand_distance_m: 0.0,
            object_tilt_deg: 0.0,
            hand_moment: [0.0; 3],
            force_reference_n: f64::NAN,
            force_reference_signal: 0.0,
            interaction: false,
            fault: None,
            compute_us: 0.0,
        }
    }
}

/// One arrangement switch of the supervisor.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Switch {
    /// Time of the switch \[s\].
    pub t_s: f64,
    /// Mode before.
    pub from: Mode,
    /// Mode after.
    pub to: Mode,
}

/// A whole run.
#[derive(Debug, Clone, PartialEq)]
pub struct RunRecord {
    /// Scenario name (or the scene file's stem).
    pub name: String,
    /// The scene file.
    pub scene_file: String,
    /// Joint names, model order (the order of `q`, `qd`).
    pub joint_names: Vec<String>,
    /// Names of the commanded arm joints (the order of `joint_velocities`).
    pub arm_joints: Vec<String>,
    /// Control rate \[Hz\].
    pub control_rate_hz: f64,
    /// MuJoCo timestep \[s\].
    pub timestep_s: f64,
    /// Seed of the sensor noise.
    pub seed: u64,
    /// The supervisor's speed threshold `ε_v` \[m/s\] (intentional-contact paper Table I).
    pub eps_v_mps: f64,
    /// The supervisor's contact force limit `ε_c` \[N\] (intentional-contact paper Table I).
    pub eps_c_n: f64,
    /// The scene's scripted pushes on objects `(start, end)` \[s\] (intentional-contact paper
    /// Fig. 2d: the obstacle pushed into the arm).
    pub object_pushes: Vec<(f64, f64)>,
    /// One entry per control cycle, in time order.
    pub cycles: Vec<CycleRecord>,
    /// Arrangement switches in time order.
    pub switches: Vec<Switch>,
    /// Wall-clock duration of the run \[s\].
    pub wall_time_s: f64,
    /// Of that, the world's physics and sensors (the rest: the controller, the recording).
    pub busy: BusyTime,
    /// The MJCF the run simulated (primitive geoms only: self-contained).
    pub mjcf: String,
    /// What a viewer sees: frames at the view rate and the key frames (the start, the first
    /// switches, the end; at most [`crate::outputs::view::MAX_KEY_FRAMES`]).
    pub view: View,
}

impl RunRecord {
    /// The key frames: the labelled frames of the view.
    pub fn key_frames(&self) -> impl Iterator<Item = &KeyFrame> {
        self.view.frames.iter().filter(|f| !f.label.is_empty())
    }

    /// Simulated duration \[s\]: control cycles times the control period.
    pub fn sim_duration_s(&self) -> f64 {
        self.cycles.len() as f64 / self.control_rate_hz
    }

    /// A copy without the wall-clock fields, for comparing runs bit for bit.
    pub fn without_timing(&self) -> RunRecord {
        let mut r = self.clone();
        r.wall_time_s = 0.0;
        r.busy = BusyTime::default();
        for c in &mut r.cycles {
            c.compute_us = 0.0;
        }
        r
    }
}
