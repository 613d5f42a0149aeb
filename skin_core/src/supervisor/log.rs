//! The transition log: a ring buffer allocated once, keeping the latest transitions.

use super::types::Transition;

/// The latest `capacity` transitions, oldest overwritten first; never allocates after
/// [`TransitionLog::new`].
#[derive(Debug, Clone)]
pub struct TransitionLog {
    buf: Vec<Transition>,
    capacity: usize,
    next: usize,
    total: u64,
}

impl TransitionLog {
    /// An empty log holding up to `capacity` (≥ 1) transitions.
    pub fn new(capacity: usize) -> Self {
        let capacity = capacity.max(1);
        TransitionLog { buf: Vec::with_capacity(capacity), capacity, next: 0, total: 0 }
    }

    /// Records a transition.
    pub fn push(&mut self, t: Transition) {
        if self.buf.len() < self.capacity {
            self.buf.push(t); // within the reserved capacity
        } else {
            self.buf[self.next] = t;
        }
        self.next = (self.next + 1) % self.capacity;
        self.total += 1;
    }

    /// How many transitions were ever recorded (including overwritten ones).
    pub fn total(&self) -> u64 {
        self.total
    }

    /// The kept transitions, oldest first.
    pub fn iter(&self) -> impl Iterator<Item = &Transition> + '_ {
        let split = if self.buf.len() < self.capacity { 0 } else { self.next };
        self.buf[split..].iter().chain(self.buf[..split].iter())
    }

    /// The most recent transition.
    pub fn last(&self) -> Option<&Transition> {
        if self.buf.is_empty() {
            None
        } else {
            let i = (self.next + self.capacity - 1) % self.capacity;
            self.buf.get(i)
        }
    }
}
