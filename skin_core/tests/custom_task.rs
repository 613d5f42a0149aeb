//! A task of the user's own, written in one file against the `Task` interface and found by its
//! name in the supervisor's arrangements (the example of docs/tasks.md, "Adding a task").

use std::path::PathBuf;

use nalgebra::{Isometry3, Matrix6xX, Vector3};
use skin_core::controller::{Controller, ControllerConfig, ControllerInput, SetupError};
use skin_core::hierarchy::{Reference, TaskLevel};
use skin_core::model::point_jacobian;
use skin_core::skin::signals::CellReading;
use skin_core::tasks::{entry, Cycle, Role, Rows, Task, TaskError, TaskSetup};

/// Keeps the end effector at a height: a spring-damper force on the world z row.
#[derive(Debug)]
struct HoldHeight {
    frame: usize,
    height_m: f64,
    jac: Matrix6xX<f64>,
}

impl Task for HoldHeight {
    fn name() -> &'static str {
        "hold_height"
    }

    fn role() -> Role {
        Role::Level(Rows::Fixed(1))
    }

    fn build(s: &TaskSetup) -> Result<Self, TaskError> {
        Ok(HoldHeight { frame: s.end_effector, height_m: 1.2, jac: Matrix6xX::zeros(s.model.nv()) })
    }

    fn fill(&mut self, cx: &Cycle, level: &mut TaskLevel) -> Result<(), TaskError> {
        point_jacobian(cx.model, cx.data, self.frame, &Vector3::zeros(), &mut self.jac)?;
        let z = cx.data.frame_pose(self.frame).translation.z;
        let vz: f64 = self.jac.row(2).iter().zip(cx.data.qd()).map(|(j, qd)| j * qd).sum();
        let f = 300.0 * (self.height_m - z) - 30.0 * vz;
        level.set(&self.jac.fixed_rows::<1>(2), Reference::Force { f: &[f] })?;
        Ok(())
    }
}

fn tomm_with_hold_height() -> ControllerConfig {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut config = ControllerConfig::load(&root.join("config/controller/tomm.yaml")).unwrap();
    config.supervisor.tasks.push("hold_height".into());
    config.supervisor.arrangements.avoidance.insert(0, "hold_height".into());
    config
}

fn one_cycle(c: &mut Controller) -> Vec<f64> {
    let q = c.config().setup.posture.clone();
    let qd = vec![0.0; q.len()];
    let cells = vec![CellReading::default(); c.config().layout.num_cells()];
    let input = ControllerInput { t_s: 0.01, dt_s: 0.01, q: &q, qd: &qd, cells: &cells, scan: &[] };
    c.update(&input);
    assert!(c.output().fault.is_none(), "{:?}", c.output().fault);
    c.torque().iter().copied().collect()
}

#[test]
fn a_task_of_ones_own_is_found_by_name_and_takes_its_priority() {
    let goal = Isometry3::translation(0.6, -0.3, 1.0);
    let mut own = Controller::with_tasks(tomm_with_hold_height(), 0.0, &[entry::<HoldHeight>()]).unwrap();
    own.set_goal(Some(goal)).unwrap();
    let tau = one_cycle(&mut own);
    let levels = own.level_diagnostics();
    assert_eq!(levels.len(), 4, "hold_height, avoidance, goal, contact_reaction");
    assert_eq!((levels[0].rows, levels[0].rank), (1, 1), "the new task is the top level");

    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut plain = Controller::from_setup_file(&root.join("config/controller/tomm.yaml"), 0.0).unwrap();
    plain.set_goal(Some(goal)).unwrap();
    let tau_plain = one_cycle(&mut plain);
    let diff: f64 = tau.iter().zip(&tau_plain).map(|(a, b)| (a - b).abs()).sum();
    assert!(diff > 1e-3, "the new level changes the torque ({diff})");
}

#[test]
fn an_unregistered_task_name_is_refused_with_the_file_and_key() {
    let err = Controller::new(tomm_with_hold_height(), 0.0).unwrap_err();
    let text = err.to_string();
    assert!(matches!(err, SetupError::Invalid { .. }), "{text}");
    assert!(text.contains("supervisor.yaml") && text.contains("hold_height") && text.contains("tasks["), "{text}");
}
