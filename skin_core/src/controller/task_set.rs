//! The configured tasks, built from their names in `config/supervisor.yaml` through
//! [`crate::tasks::REGISTRY`]: one level per name, and the posture torque of
//! interactive-force-control paper eq. (18) from the terms an arrangement names.

use nalgebra::DVector;

use super::setup::{ControllerConfig, SetupError};
use crate::hierarchy::TaskLevel;
use crate::model::ModelData;
use crate::tasks::{lookup, Cycle, Role, Task, TaskEntry, TaskError, TaskSetup, REGISTRY};

/// One task object and one level per configured name (torque tasks have zero rows).
#[derive(Debug)]
pub(crate) struct TaskSet {
    roles: Vec<Role>,
    tasks: Vec<Box<dyn Task>>,
    /// One level per configured name, in the supervisor's `tasks` order.
    pub(crate) levels: Vec<TaskLevel>,
    /// `τ_s` of eq. (18): the sum of the arrangement's posture terms.
    tau_s: DVector<f64>,
    /// `τ_c*` of eq. (18).
    posture: DVector<f64>,
}

impl TaskSet {
    /// Builds every configured task (`setup` carries the model, the parameters and the frames),
    /// looking names up in `extra` first, then in [`REGISTRY`].
    pub(crate) fn new(config: &ControllerConfig, setup: &TaskSetup, extra: &[TaskEntry]) -> Result<Self, SetupError> {
        let nv = config.model.nv();
        let (mut roles, mut tasks, mut levels) = (Vec::new(), Vec::new(), Vec::new());
        for (i, name) in config.supervisor.tasks.iter().enumerate() {
            let entry = extra.iter().find(|e| e.name == name).or_else(|| lookup(name)).ok_or_else(|| {
                let known: Vec<&str> = extra.iter().chain(REGISTRY.iter()).map(|e| e.name).collect();
                SetupError::Invalid {
                    file: config.setup.supervisor.display().to_string(),
                    key: format!("tasks[{i}]"),
                    reason: format!("unknown task `{name}` (known: {})", known.join(", ")),
                }
            })?;
            let task = (entry.build)(setup).map_err(|error| SetupError::Task { file: config.source.clone(), error })?;
            roles.push(entry.role);
            tasks.push(task);
            levels.push(TaskLevel::new(name, nv, entry.role.max_rows(config.layout.num_cells())));
        }
        Ok(TaskSet { roles, tasks, levels, tau_s: DVector::zeros(nv), posture: DVector::zeros(nv) })
    }

    /// Whether configured task `index` is a level of the hierarchy.
    pub(crate) fn is_level(&self, index: usize) -> bool {
        self.roles[index].is_level()
    }

    /// The arrangement switched at the state in `data`.
    pub(crate) fn on_switch(&mut self, data: &ModelData) {
        for task in &mut self.tasks {
            task.on_switch(data);
        }
    }

    /// Fills the level of configured task `index` for this cycle (empty for a torque task).
    pub(crate) fn fill(&mut self, index: usize, cx: &Cycle) -> Result<(), TaskError> {
        let level = &mut self.levels[index];
        level.clear();
        self.tasks[index].fill(cx, level)
    }

    /// Computes `τ_c* = −K_c (q − q_post) − D_c q̇ − τ_s` of eq. (18) (read it with
    /// [`TaskSet::posture`]) with the terms the arrangement `order` names, zero on the `locked`
    /// joints; `false` when it names none.
    pub(crate) fn posture_torque(&mut self, order: &[usize], cx: &Cycle, locked: &[bool]) -> Result<bool, TaskError> {
        if order.iter().all(|&i| self.roles[i].is_level()) {
            return Ok(false);
        }
        self.tau_s.fill(0.0);
        let mut joint = false;
        for &i in order {
            match self.roles[i] {
                Role::PostureTerm => self.tasks[i].torque(cx, &mut self.tau_s)?,
                Role::Posture => {
                    self.tasks[i].torque(cx, &mut self.posture)?;
                    joint = true;
                }
                Role::Level(_) => {}
            }
        }
        if joint {
            self.posture -= &self.tau_s;
        } else {
            self.posture.copy_from(&self.tau_s);
            self.posture.neg_mut();
        }
        for (t, _) in self.posture.iter_mut().zip(locked).filter(|(_, &l)| l) {
            *t = 0.0;
        }
        Ok(true)
    }

    /// `τ_c*` of the last [`TaskSet::posture_torque`].
    pub(crate) fn posture(&self) -> &DVector<f64> {
        &self.posture
    }
}
