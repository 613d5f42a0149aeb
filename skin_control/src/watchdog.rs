//! The decision of `skin_watchdog` (docs/reliability.md), without DDS: when the task
//! controller's heartbeat ([`crate::heartbeat`]) has been silent for longer than the timeout, zero
//! velocities go out on every command topic, and keep going out until heartbeats return.
use std::time::{Duration, Instant};

/// What to do at a check.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Verdict {
    /// The controller is alive: publish nothing.
    Quiet,
    /// The heartbeat just stopped: publish zeros now, and say so.
    Trip,
    /// Still silent: publish zeros again (every `hold_period`).
    Hold,
}

/// Heartbeat timeout and zero holding.
#[derive(Debug, Clone)]
pub struct Watchdog {
    timeout: Duration,
    hold_period: Duration,
    last_beat: Option<Instant>,
    /// Since when zeros go out, and when they last did.
    tripped: Option<Instant>,
    last_zero: Option<Instant>,
    trips: u64,
}

impl Watchdog {
    /// A watchdog that trips after `timeout` without a heartbeat and then repeats the zeros every
    /// `hold_period`. It starts tripped: until a controller is heard, the command topics are held
    /// at zero (a controller that died before the watchdog started is covered too).
    pub fn new(timeout: Duration, hold_period: Duration, now: Instant) -> Self {
        Watchdog { timeout, hold_period, last_beat: None, tripped: Some(now), last_zero: None, trips: 0 }
    }

    /// A heartbeat arrived at `now`; returns true when it ends a trip (the controller is back).
    pub fn beat(&mut self, now: Instant) -> bool {
        self.last_beat = Some(now);
        self.tripped.take().is_some()
    }

    /// The check at `now`.
    pub fn check(&mut self, now: Instant) -> Verdict {
        if self.tripped.is_none() {
            let silent = self.last_beat.is_none_or(|b| now.duration_since(b) > self.timeout);
            if !silent {
                return Verdict::Quiet;
            }
            self.tripped = Some(now);
            self.trips += 1;
            self.last_zero = Some(now);
            return Verdict::Trip;
        }
        if self.last_zero.is_none_or(|z| now.duration_since(z) >= self.hold_period) {
            self.last_zero = Some(now);
            return Verdict::Hold;
        }
        Verdict::Quiet
    }

    /// The latest time of the next check that matters (a trip or a repeated zero).
    pub fn next_check(&self, now: Instant) -> Instant {
        match (self.tripped, self.last_beat, self.last_zero) {
            (None, Some(b), _) => b + self.timeout + Duration::from_micros(1),
            (Some(_), _, Some(z)) => z + self.hold_period,
            _ => now,
        }
    }

    /// Whether zeros are going out.
    pub fn is_tripped(&self) -> bool {
        self.tripped.is_some()
    }

    /// Trips after a heartbeat was heard (the start without one does not count).
    pub fn trips(&self) -> u64 {
        self.trips
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn trips_after_the_timeout_holds_zero_and_releases_on_a_heartbeat() {
        let ms = Duration::from_millis;
        let t0 = Instant::now();
        let mut w = Watchdog::new(ms(12), ms(8), t0);
        assert!(w.is_tripped(), "zeros until a controller is heard");
        assert_eq!(w.check(t0), Verdict::Hold);
        assert_eq!(w.check(t0 + ms(4)), Verdict::Quiet);
        assert_eq!(w.check(t0 + ms(8)), Verdict::Hold);
        assert!(w.beat(t0 + ms(10)), "the controller is back");
        let mut t = t0 + ms(10);
        for _ in 0..10 {
            t += ms(8);
            assert_eq!(w.check(t - ms(1)), Verdict::Quiet);
            assert!(!w.beat(t));
        }
        assert_eq!(w.next_check(t), t + ms(12) + Duration::from_micros(1));
        assert_eq!(w.check(t + ms(12)), Verdict::Quiet, "exactly the timeout: not yet");
        assert_eq!(w.check(t + ms(13)), Verdict::Trip);
        assert_eq!((w.trips(), w.next_check(t + ms(13))), (1, t + ms(21)));
        assert_eq!(w.check(t + ms(14)), Verdict::Quiet);
        assert_eq!(w.check(t + ms(21)), Verdict::Hold);
        assert_eq!(w.check(t + ms(2000)), Verdict::Hold, "zeros until a heartbeat, however long");
        assert!(w.beat(t + ms(2001)));
        assert_eq!(w.check(t + ms(2002)), Verdict::Quiet);
    }
}
