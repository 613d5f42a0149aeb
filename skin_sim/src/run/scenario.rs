//! The scenarios: a scene file and the controller setup that runs it. The outcome the papers
//! report for it is declared in the scene file (`expect:`, checked by [`crate::outputs::outcome`]), so a
//! copy of the file under another name is checked the same way. `docs/scenarios.md` has the
//! measured numbers.

use std::path::PathBuf;

use crate::scene::config_dir;

/// A named scenario.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Scenario {
    /// Name (`skin_sim run <name>`), also the scene file's stem.
    pub name: &'static str,
    /// What it reproduces, one line.
    pub description: &'static str,
    /// Controller setup file in `config/controller/`.
    pub controller: &'static str,
}

/// Every scenario, intentional-contact paper first.
pub const SCENARIOS: [Scenario; 7] = [
    Scenario {
        name: "intentional_contact",
        description: "intentional-contact paper Figs. 2-3: planar 7-DoF arm pushes a movable obstacle out of a local minimum; hard push at 15 s",
        controller: "planar7.yaml",
    },
    Scenario {
        name: "tomm_movable_obstacles",
        description: "intentional-contact paper Fig. 5: TOMM's right arm reaches a goal over a table through movable obstacles",
        controller: "tomm.yaml",
    },
    Scenario {
        name: "tomm_fixed_obstacle",
        description: "intentional-contact paper Fig. 6: a fixed and a movable block form a local minimum; the arm pushes the movable one",
        controller: "tomm.yaml",
    },
    Scenario {
        name: "force_tracking_base_motion",
        description: "interactive-force-control paper Exp. 1 (Fig. 5): the hand tracks a 4 +- 1 N sinusoid on a board",
        controller: "tomm_phases.yaml",
    },
    Scenario {
        name: "tactile_guidance",
        description: "interactive-force-control paper Exp. 2 (Fig. 6): proximity approach to a table, touches guide the hand, a person nears the base",
        controller: "tomm_phases.yaml",
    },
    Scenario {
        name: "force_tracking_interaction",
        description: "interactive-force-control paper Exp. 3 (Fig. 7): 5 +- 2 N sinusoid while the arm is touched and a person nears the base",
        controller: "tomm_phases.yaml",
    },
    Scenario {
        name: "poster_phrc",
        description: "interactive-force-control paper Exp. 4 (Figs. 1, 8): hold a poster on a tilted wall with 6 N while the user works next to the robot",
        controller: "tomm_phases.yaml",
    },
];

/// The scenario called `name`.
pub fn find(name: &str) -> Option<&'static Scenario> {
    SCENARIOS.iter().find(|s| s.name == name)
}

impl Scenario {
    /// Its scene file.
    pub fn scene_file(&self) -> PathBuf {
        config_dir().join("scenes").join(format!("{}.yaml", self.name))
    }

    /// Its controller setup file.
    pub fn controller_file(&self) -> PathBuf {
        config_dir().join("controller").join(self.controller)
    }
}
