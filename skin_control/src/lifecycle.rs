//! The task controller's managed-node (lifecycle) state machine, as ROS 2 defines it
//! (`lifecycle_msgs`; design.ros2.org "Managed nodes"): the primary states unconfigured,
//! inactive, active, finalized and the transitions between them, by id or label. The node
//! (`nodes::task_controller`) serves it through `<node>/change_state`, `<node>/get_state`,
//! `<node>/get_available_states`, `<node>/get_available_transitions` and announces every
//! transition on `<node>/transition_event`. Only `active` commands motion; the other states hold
//! (the commands ramp to zero within the acceleration limits, then stay zero).

/// A primary state (ids and labels of `lifecycle_msgs/msg/State`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum State {
    /// Created; the configuration is loaded at start, so `configure` has nothing left to fail.
    Unconfigured = 1,
    /// Configured, holding still.
    Inactive = 2,
    /// Commanding.
    Active = 3,
    /// Shut down: the node sends zeros and exits.
    Finalized = 4,
}

impl State {
    /// Every primary state.
    pub const ALL: [State; 4] = [State::Unconfigured, State::Inactive, State::Active, State::Finalized];

    /// `lifecycle_msgs/msg/State` id.
    pub fn id(self) -> u8 {
        self as u8
    }

    /// `lifecycle_msgs/msg/State` label.
    pub fn label(self) -> &'static str {
        match self {
            State::Unconfigured => "unconfigured",
            State::Inactive => "inactive",
            State::Active => "active",
            State::Finalized => "finalized",
        }
    }
}

/// A transition (ids and labels of `lifecycle_msgs/msg/Transition`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Transition {
    /// Its id.
    pub id: u8,
    /// Its label.
    pub label: &'static str,
    /// From this state.
    pub from: State,
    /// To this state.
    pub to: State,
}

/// The transitions of the managed-node state machine that start from a primary state.
pub const TRANSITIONS: [Transition; 7] = [
    Transition { id: 1, label: "configure", from: State::Unconfigured, to: State::Inactive },
    Transition { id: 2, label: "cleanup", from: State::Inactive, to: State::Unconfigured },
    Transition { id: 3, label: "activate", from: State::Inactive, to: State::Active },
    Transition { id: 4, label: "deactivate", from: State::Active, to: State::Inactive },
    Transition { id: 5, label: "shutdown", from: State::Unconfigured, to: State::Finalized },
    Transition { id: 6, label: "shutdown", from: State::Inactive, to: State::Finalized },
    Transition { id: 7, label: "shutdown", from: State::Active, to: State::Finalized },
];

/// The current state and its transitions.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Lifecycle {
    state: State,
}

impl Default for Lifecycle {
    fn default() -> Self {
        Lifecycle { state: State::Unconfigured }
    }
}

impl Lifecycle {
    /// The current state.
    pub fn state(&self) -> State {
        self.state
    }

    /// The transitions available from the current state.
    pub fn available(&self) -> impl Iterator<Item = &'static Transition> + '_ {
        TRANSITIONS.iter().filter(|t| t.from == self.state)
    }

    /// Takes the transition asked by `id`, or by `label` when `id` is 0 (as `ros2 lifecycle set
    /// <node> activate` asks); the error says why it is not available.
    pub fn change(&mut self, id: u8, label: &str) -> Result<Transition, String> {
        let asked = |t: &&Transition| if id == 0 { t.label == label } else { t.id == id };
        let Some(t) = self.available().find(asked).copied() else {
            let what = if id == 0 { format!("`{label}`") } else { format!("id {id}") };
            let names: Vec<&str> = self.available().map(|t| t.label).collect();
            return Err(format!(
                "transition {what} is not available in state {} (available: {})",
                self.state.label(),
                names.join(", ")
            ));
        };
        self.state = t.to;
        Ok(t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_managed_node_transitions_by_id_and_label() {
        let mut l = Lifecycle::default();
        assert_eq!(l.state(), State::Unconfigured);
        let e = l.change(0, "activate").unwrap_err();
        assert!(
            e.contains("`activate` is not available in state unconfigured (available: configure, shutdown)"),
            "{e}"
        );
        assert_eq!(l.change(1, "").unwrap().to, State::Inactive);
        assert_eq!(l.change(0, "activate").unwrap().id, 3);
        assert_eq!(l.state(), State::Active);
        assert_eq!(l.available().map(|t| t.label).collect::<Vec<_>>(), ["deactivate", "shutdown"]);
        assert!(l.change(3, "").is_err(), "already active");
        assert_eq!(l.change(4, "").unwrap().to, State::Inactive);
        let t = l.change(0, "shutdown").unwrap();
        assert_eq!((t.id, l.state(), l.state().label()), (6, State::Finalized, "finalized"));
        assert_eq!(l.available().count(), 0);
        assert_eq!(State::ALL.map(State::id), [1, 2, 3, 4]);
    }
}
