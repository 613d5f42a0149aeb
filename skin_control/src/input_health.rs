//! The task controller's input health (docs/reliability.md): a stamp check per timed input and
//! one counter per kind of rejected or sanitized input, published in `/controller/state`.
use std::fmt;

use r2r::builtin_interfaces::msg::Time;
use r2r::skin_msgs::msg::ControllerState;

use crate::convert::robot::time_s;

/// Why a message's stamp was refused (the whole message is ignored).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StampIssue {
    /// Older than the last accepted message of the same input: a reordered or replayed message
    /// would move the state back in time.
    OutOfOrder,
    /// Ahead of the node's clock by more than `max_stamp_lead_s`: a sender with a wrong clock,
    /// whose messages would look fresh for too long.
    Future,
}

impl StampIssue {
    /// Every kind, in counter order.
    pub const ALL: [StampIssue; 2] = [StampIssue::OutOfOrder, StampIssue::Future];

    /// Short name for logs and counters.
    pub fn name(self) -> &'static str {
        match self {
            StampIssue::OutOfOrder => "stamp out of order",
            StampIssue::Future => "stamp in the future",
        }
    }
}

/// The stamp check of one timed input: its messages must not go back in time nor run ahead of
/// the clock. Only accepted messages ([`StampGate::accept`]) set the order.
#[derive(Debug, Clone, Copy, Default)]
pub struct StampGate {
    last_s: Option<f64>,
}

impl StampGate {
    /// Checks `stamp`: refused when more than `max_lead_s` ahead of `now_s` (`None`: no clock to
    /// compare with, as in lockstep), or older than the last accepted one. A last stamp that is
    /// itself ahead of the clock by more than `max_lead_s` (the clock went back) holds nothing
    /// back. An equal stamp passes: a resent period.
    pub fn check(&self, stamp: &Time, now_s: Option<f64>, max_lead_s: f64) -> Result<(), StampIssue> {
        let t = time_s(stamp);
        let limit = now_s.map_or(f64::INFINITY, |now| now + max_lead_s);
        if t > limit {
            return Err(StampIssue::Future);
        }
        if self.last_s.is_some_and(|last| t < last && last <= limit) {
            return Err(StampIssue::OutOfOrder);
        }
        Ok(())
    }

    /// Records `stamp` as the last accepted one (a message that passed [`Self::check`] and was
    /// used).
    pub fn accept(&mut self, stamp: &Time) {
        self.last_s = Some(time_s(stamp));
    }

    /// The last accepted stamp \[s\].
    pub fn last(&self) -> Option<f64> {
        self.last_s
    }
}

/// Whether an input of `age_s` (clock minus stamp) is fresh: in `[-max_lead_s, timeout_s]`.
/// A negative age beyond the lead (the clock went back, or a stamp that passed when the clock
/// was ahead) is not fresh: the input's value may be from any time.
pub fn fresh(age_s: f64, timeout_s: f64, max_lead_s: f64) -> bool {
    (-max_lead_s..=timeout_s).contains(&age_s)
}

/// Counters of bad input, one per `"<topic>: <kind>"`, in the fixed order of registration.
#[derive(Debug, Clone, Default)]
pub struct IssueTable {
    names: Vec<String>,
    counts: Vec<u64>,
}

impl IssueTable {
    /// Adds a counter per kind of `topic`; returns the index of the first (the others follow).
    pub fn register<'a>(&mut self, topic: &str, kinds: impl IntoIterator<Item = &'a str>) -> usize {
        let first = self.names.len();
        for kind in kinds {
            self.names.push(format!("{topic}: {kind}"));
            self.counts.push(0);
        }
        first
    }

    /// Counts one issue of counter `k`; true the first time (the time to log it).
    pub fn count(&mut self, k: usize) -> bool {
        self.counts[k] += 1;
        self.counts[k] == 1
    }

    /// Count of counter `k`.
    pub fn get(&self, k: usize) -> u64 {
        self.counts[k]
    }

    /// Count of the counter named `name` (`"<topic>: <kind>"`), if there is one.
    pub fn by_name(&self, name: &str) -> Option<u64> {
        self.names.iter().position(|n| n == name).map(|k| self.counts[k])
    }

    /// The counters of `topic`: `(kind, count)` in registration order.
    pub fn of_topic<'a>(&'a self, topic: &'a str) -> impl Iterator<Item = (&'a str, u64)> + 'a {
        self.names.iter().zip(&self.counts).filter_map(move |(name, &count)| {
            let kind = name.strip_prefix(topic)?.strip_prefix(": ")?;
            Some((kind, count))
        })
    }

    /// Sum of all counters.
    pub fn total(&self) -> u64 {
        self.counts.iter().sum()
    }

    /// Writes every counter into `msg.issue_names` / `msg.issue_counts` (the names only once).
    pub fn write(&self, msg: &mut ControllerState) {
        if msg.issue_names.len() != self.names.len() {
            msg.issue_names.clone_from(&self.names);
        }
        msg.issue_counts.clear();
        msg.issue_counts.extend_from_slice(&self.counts);
    }
}

/// The counters that are not zero, `name: count` separated by `; ` (`none` when all are).
impl fmt::Display for IssueTable {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut seen = self.names.iter().zip(&self.counts).filter(|(_, &c)| c > 0).peekable();
        if seen.peek().is_none() {
            return write!(f, "none");
        }
        for (k, (name, count)) in seen.enumerate() {
            let sep = if k == 0 { "" } else { "; " };
            write!(f, "{sep}{name}: {count}")?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::convert::robot::time_msg;

    #[test]
    fn stamps_must_not_go_back_nor_run_ahead() {
        let mut gate = StampGate::default();
        let pass = |gate: &mut StampGate, t: f64, now: Option<f64>| {
            let r = gate.check(&time_msg(t), now, 0.05);
            if r.is_ok() {
                gate.accept(&time_msg(t));
            }
            r
        };
        assert_eq!(pass(&mut gate, 10.0, Some(10.0)), Ok(()));
        assert_eq!(pass(&mut gate, 10.0, Some(10.01)), Ok(()), "a resent period");
        assert_eq!(pass(&mut gate, 9.99, Some(10.02)), Err(StampIssue::OutOfOrder));
        assert_eq!(pass(&mut gate, 10.2, Some(10.1)), Err(StampIssue::Future));
        assert_eq!(pass(&mut gate, 10.11, Some(10.11)), Ok(()), "the refused future stamp holds nothing back");
        assert_eq!(pass(&mut gate, 10.2, None), Ok(()), "no clock: only the order");
        assert_eq!(
            pass(&mut gate, 10.1, None),
            Err(StampIssue::OutOfOrder),
            "the refused stamps did not count, 10.2 did"
        );
        // the clock went back by 5 s: 10.2 is now from the future and blocks no honest message
        assert_eq!(pass(&mut gate, 5.0, Some(5.0)), Ok(()));
        assert_eq!(gate.last(), Some(5.0));
        let unused = StampGate::default();
        assert_eq!(unused.check(&time_msg(1.0), Some(1.0), 0.0), Ok(()));
    }

    #[test]
    fn ages_outside_minus_lead_to_timeout_are_not_fresh() {
        assert!(fresh(0.0, 0.1, 0.02) && fresh(0.1, 0.1, 0.02) && fresh(-0.02, 0.1, 0.02));
        assert!(!fresh(0.1001, 0.1, 0.02) && !fresh(-0.021, 0.1, 0.02) && !fresh(f64::NAN, 0.1, 0.02));
    }

    #[test]
    fn the_table_counts_by_topic_and_kind() {
        let mut t = IssueTable::default();
        let a = t.register("/a", ["x", "y"]);
        let b = t.register("/b", ["z"]);
        assert_eq!((a, b), (0, 2));
        assert!(t.count(a + 1));
        assert!(!t.count(a + 1));
        assert!(t.count(b));
        assert_eq!((t.get(a), t.get(a + 1), t.total()), (0, 2, 3));
        assert_eq!(t.by_name("/a: y"), Some(2));
        assert_eq!(t.of_topic("/a").collect::<Vec<_>>(), [("x", 0), ("y", 2)]);
        assert_eq!(t.of_topic("/").count(), 0, "a whole topic name only");
        assert_eq!(t.to_string(), "/a: y: 2; /b: z: 1");
        let mut msg = ControllerState::default();
        t.write(&mut msg);
        assert_eq!(msg.issue_names, ["/a: x", "/a: y", "/b: z"]);
        assert_eq!(msg.issue_counts, [0, 2, 1]);
        assert_eq!(IssueTable::default().to_string(), "none");
    }
}
