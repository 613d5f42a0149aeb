//! What the scene tells the controller over time: the active end-effector goal (`goals`), the
//! force reference (`force_references`, in newtons; [`HandForceMap`] checks the hand can sense one
//! and gives its even-press signal for the record), the commanded base motion (`base_motions`, [`BaseMotions`]) and, for interactive-force-control paper's phase policy, the switch to the contact phase when
//! the first force reference starts (interactive-force-control paper Sec. 4.2.2: "the contact phase is manually
//! activated by the user"; the scene's `start_s` is that moment).

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use skin_core::controller::{Controller, Fault};
use skin_core::supervisor::{Phase, Policy};

use crate::run::base_motion::BaseMotions;
use crate::scene::{ForceReferenceSpec, GoalSpec, Scene};
use skin_core::controller::HandForceMap;

/// A scene input the controller cannot take.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("`{key}`: {reason}")]
pub struct ScheduleError {
    /// Dotted key of the scene.
    pub key: String,
    /// Why.
    pub reason: String,
}

/// The controller's inputs at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScheduledInputs {
    /// Force reference \[N\] (NaN: none active).
    pub force_n: f64,
    /// Its hand signal for an even press of the palm (`HandForceMap`, recorded beside it; NaN:
    /// none). The controller is given the newtons.
    pub force_signal: f64,
}

impl ScheduledInputs {
    /// No force reference.
    pub const NONE: ScheduledInputs = ScheduledInputs { force_n: f64::NAN, force_signal: f64::NAN };
}

/// Goals, force references and the phase plan of a scene, applied to a controller by time.
#[derive(Debug, Clone)]
pub struct Schedule {
    goals: Vec<GoalSpec>,
    forces: Vec<ForceReferenceSpec>,
    map: Option<HandForceMap>,
    motions: BaseMotions,
    /// Model indices of the base joints (x, y, yaw) when the scene's base moves.
    base: Option<[usize; 3]>,
    /// Start of the contact phase (interactive-force-control paper policy with force references).
    contact_from_s: Option<f64>,
    /// Index of the goal last given to the controller.
    active_goal: Option<usize>,
    contact_requested: bool,
}

/// The last spec (in start order) that has started at `t_s`.
fn latest<T>(specs: &[T], start: impl Fn(&T) -> f64, t_s: f64) -> Option<usize> {
    specs.iter().rposition(|s| start(s) <= t_s)
}

impl Schedule {
    /// The schedule of `scene` for `controller`: every goal must be for the controller's end
    /// effector, force references need the phase policy and a hand with skin.
    pub fn new(scene: &Scene, controller: &Controller) -> Result<Self, ScheduleError> {
        let spec = &scene.spec;
        let config = controller.config();
        let ee = &config.setup.end_effector;
        for (i, g) in spec.goals.iter().enumerate() {
            if &g.frame != ee {
                return Err(ScheduleError {
                    key: format!("goals[{i}].frame"),
                    reason: format!("the controller moves `{ee}`, not `{}`", g.frame),
                });
            }
        }
        let mut goals = spec.goals.clone();
        goals.sort_by(|a, b| a.start_s.total_cmp(&b.start_s));
        let mut forces = spec.force_references.clone();
        forces.sort_by(|a, b| a.start_s.total_cmp(&b.start_s));
        let map = HandForceMap::new(config);
        if !forces.is_empty() {
            let reject = |reason: &str| ScheduleError { key: "force_references".into(), reason: reason.into() };
            if controller.supervisor().policy() != Policy::Phases {
                return Err(reject(
                    "need a controller with `policy: phases` (interactive-force-control paper Table 1)",
                ));
            }
            if map.is_none() {
                return Err(reject(
                    "the controller's hand_patches have no cell facing along the end effector's z axis",
                ));
            }
        }
        let contact_from_s = match controller.supervisor().policy() {
            Policy::Phases => forces.first().map(|f| f.start_s),
            Policy::IntentionalContact => None,
        };
        Ok(Schedule {
            goals,
            forces,
            map,
            motions: BaseMotions::new(&spec.base_motions),
            base: scene.moving_base(),
            contact_from_s,
            active_goal: None,
            contact_requested: false,
        })
    }

    /// The hand force map (None without hand skin).
    pub fn hand_force_map(&self) -> Option<&HandForceMap> {
        self.map.as_ref()
    }

    /// Gives `controller` what the scene asks for at `t_s` with the robot measured at `q` (model
    /// order): the goal that started last, the force reference in newtons, the base
    /// motion's reference, the contact phase once it is due.
    pub fn apply(&mut self, t_s: f64, q: &[f64], controller: &mut Controller) -> Result<ScheduledInputs, Fault> {
        let goal = latest(&self.goals, |g| g.start_s, t_s);
        if goal != self.active_goal {
            controller.set_goal(goal.map(|k| goal_pose(&self.goals[k])))?;
            self.active_goal = goal;
        }
        let mut inputs = ScheduledInputs::NONE;
        if let (Some(k), Some(map)) = (latest(&self.forces, |f| f.start_s, t_s), &self.map) {
            inputs.force_n = self.forces[k].value(t_s);
            inputs.force_signal = map.signal(inputs.force_n);
            controller.set_hand_force_reference(inputs.force_n)?;
        }
        if let Some(b) = self.base {
            let reference = self.motions.reference(t_s, b.map(|j| q[j]));
            if reference.is_some() || controller.base_reference().is_some() {
                controller.set_base_reference(reference)?;
            }
        }
        if !self.contact_requested && self.contact_from_s.is_some_and(|s| t_s >= s) {
            // The policy is `phases` (checked in new), so the request is accepted.
            let _ = controller.request_phase(Phase::Contact);
            self.contact_requested = true;
        }
        Ok(inputs)
    }
}

/// The goal pose; identity orientation when the goal gives none (only `goal_orientation` reads
/// it, and intentional-contact paper's arrangements do not use that task).
fn goal_pose(g: &GoalSpec) -> Isometry3<f64> {
    let rotation = g.rpy.map_or(UnitQuaternion::identity(), |[r, p, y]| UnitQuaternion::from_euler_angles(r, p, y));
    Isometry3::from_parts(Translation3::from(Vector3::from(g.position_m)), rotation)
}
