//! The supervisor state machine: intentional-contact paper Table I switched on sensed conditions, or
//! interactive-force-control paper Table 1 phases switched on request. The exact rules are in `docs/supervisor.md`.

use super::blend::WeightShift;
use super::log::TransitionLog;
use super::params::{DwellTimes, FusionShift, ParamError, Policy, SensingRange, SupervisorParams, Thresholds};
use super::types::{Arrangement, Blocked, Cause, Imposed, Mode, Phase, PhaseRefused, SupervisorInput, Transition};

/// A condition that must hold for a dwell time, with a hysteresis between the condition that
/// starts the timer (`set`) and the weaker one that keeps it running (`keep`).
#[derive(Debug, Clone, Copy)]
struct Dwell {
    /// Start of the current holding interval; NaN when not holding.
    since: f64,
}

impl Dwell {
    const IDLE: Dwell = Dwell { since: f64::NAN };

    /// Advances to `t` and returns whether the condition has held for `dwell_s`.
    fn step(&mut self, t: f64, set: bool, keep: bool, dwell_s: f64) -> bool {
        if self.since.is_nan() {
            if set {
                self.since = t;
            }
        } else if !(keep || set) {
            self.since = f64::NAN;
        }
        !self.since.is_nan() && t - self.since >= dwell_s
    }
}

/// Checkpoints per progress window: the window slides by a sixth of its length.
const CHECKPOINTS: usize = 6;

/// The goal error at the checkpoints of the last progress window, and whether it fell too little
/// over that window (a crawl that the speed test misses).
#[derive(Debug, Clone, Copy)]
struct Progress {
    /// Time of the next checkpoint (NaN: the next sample starts a window).
    next_s: f64,
    /// Goal errors at the last checkpoints; `head` is the next one written (the oldest once full).
    errors: [f64; CHECKPOINTS],
    count: usize,
    head: usize,
    crawling: bool,
}

impl Progress {
    const IDLE: Progress =
        Progress { next_s: f64::NAN, errors: [f64::NAN; CHECKPOINTS], count: 0, head: 0, crawling: false };

    /// Advances to `t` with the goal error `e`: crawling when the error fell by less than `min_m`
    /// over the last `window_s` (checked every sixth of it, so a crawl is seen at most a sixth
    /// of a window late, not a whole window); NaN restarts the window.
    fn step(&mut self, t: f64, e: f64, window_s: f64, min_m: f64) -> bool {
        if e.is_nan() {
            *self = Progress::IDLE;
        } else if self.next_s.is_nan() || t >= self.next_s {
            if self.count == CHECKPOINTS {
                self.crawling = self.errors[self.head] - e < min_m; // the one a window ago
            } else {
                self.count += 1;
            }
            self.errors[self.head] = e;
            self.head = (self.head + 1) % CHECKPOINTS;
            self.next_s = t + window_s / CHECKPOINTS as f64;
        }
        self.crawling
    }
}

/// The priority supervisor. Allocates in [`Supervisor::new`] only.
#[derive(Debug, Clone)]
pub struct Supervisor {
    policy: Policy,
    thresholds: Thresholds,
    dwell: DwellTimes,
    range: SensingRange,
    fusion: FusionShift,
    tasks: Vec<String>,
    orders: [Vec<usize>; 5],
    arrangement: Arrangement,
    /// The mode (a) or (b) to return to when a hard contact (c) is released.
    resume: Mode,
    /// Largest `‖F_c‖` since the last switch, in a push (b) or a hard contact (c) (NaN counts
    /// as infinite).
    peak_n: f64,
    /// A push that reached ε_c was given up: (a) holds, no (a) → (b).
    blocked: Option<Blocked>,
    /// Goal error when the current push began ((a) → (b)) or at its last hard contact: what the
    /// next hard contact's goal error is compared with (NaN: none).
    push_ref_error_m: f64,
    /// Time the last push reached its limit: (b) → (c), or stalled (NaN: none yet).
    push_limit_s: f64,
    /// The hard contact (c) entered from (b) ends the push with another try (the push had got
    /// the goal nearer, and the one before did not also reach ε_c within `retry_interval_s`).
    retry: bool,
    /// The hard contact (c) was entered from (b) with the goal within tolerance, now or when the
    /// push began: the arm held its goal, so the contact is the environment's hit, not the
    /// push's limit, and no [`Blocked`] hold follows it.
    hit_at_goal: bool,
    over_limit: Dwell,
    /// `‖F_c‖ ≥ ε_c` at the last update.
    was_over: bool,
    /// When `‖F_c‖` last rose to ε_c in this (a) or (b) (NaN: not yet).
    last_strike_s: f64,
    /// When `‖F_c‖` was last at or over ε_c (NaN: not yet).
    last_over_s: f64,
    /// The speed at which the link pressed hardest advanced into its contact, averaged over the
    /// cycles in contact of this push (b) (time constant `dwell.give_way_s`) \[m/s\].
    advance_mps: f64,
    released: Dwell,
    stuck: Dwell,
    goal_reached: Dwell,
    cleared: Dwell,
    invalid: Dwell,
    progress: Progress,
    pending: Option<Phase>,
    weight: WeightShift,
    last_t: f64,
    last_transition: Option<Transition>,
    log: TransitionLog,
    /// Following another supervisor ([`Supervisor::impose`]): its own rules are off.
    follower: bool,
    imposed: Option<Imposed>,
}

impl Supervisor {
    /// A supervisor at time `t0_s` in the initial mode of the policy: (a) avoidance for
    /// intentional-contact paper, precontact for interactive-force-control paper. `t0_s` is the initial switch time.
    pub fn new(params: &SupervisorParams, t0_s: f64) -> Result<Self, ParamError> {
        params.validate()?;
        let orders = params.task_indices()?;
        let capacity = orders.iter().map(Vec::len).max().unwrap_or(0);
        let mode = match params.policy {
            Policy::IntentionalContact => Mode::Avoidance,
            Policy::Phases => Mode::PreContact,
        };
        let mut task_order = Vec::with_capacity(capacity);
        task_order.extend_from_slice(&orders[mode as usize]);
        let t0 = if t0_s.is_finite() { t0_s } else { 0.0 };
        let w = params.fusion.w_precontact;
        Ok(Supervisor {
            policy: params.policy,
            thresholds: params.thresholds,
            dwell: params.dwell,
            range: params.sensing_range,
            fusion: params.fusion,
            tasks: params.tasks.clone(),
            orders,
            arrangement: Arrangement {
                mode,
                task_order,
                switch_time_s: t0,
                smoothing_gain_per_s: params.smoothing_gain_per_s,
                sensing_range_m: params.sensing_range.nominal_m,
                fusion_weight: w,
                fusion_weight_target: w,
            },
            resume: Mode::Avoidance,
            peak_n: 0.0,
            blocked: None,
            push_ref_error_m: f64::NAN,
            push_limit_s: f64::NAN,
            retry: false,
            hit_at_goal: false,
            over_limit: Dwell::IDLE,
            was_over: false,
            last_strike_s: f64::NAN,
            last_over_s: f64::NAN,
            advance_mps: 0.0,
            released: Dwell::IDLE,
            stuck: Dwell::IDLE,
            goal_reached: Dwell::IDLE,
            cleared: Dwell::IDLE,
            invalid: Dwell::IDLE,
            progress: Progress::IDLE,
            pending: None,
            weight: WeightShift::constant(w),
            last_t: t0,
            last_transition: None,
            log: TransitionLog::new(params.log_capacity),
            follower: false,
            imposed: None,
        })
    }

    /// Advances to `t_s` with the sensed `input` and returns the active arrangement.
    ///
    /// `t_s` should not decrease; a non-finite `t_s` is replaced by the previous update time.
    /// NaN inputs are treated conservatively, toward the safer arrangement:
    /// - NaN contact force counts as `‖F_c‖ ≥ ε_c` (enters/keeps hard contact (c));
    /// - NaN speed, obstacle force or goal error never count as stuck (no (a) → (b)), and in (b)
    ///   they count toward returning to avoidance (a) after `dwell.clear_s`.
    pub fn update(&mut self, t_s: f64, input: &SupervisorInput) -> &Arrangement {
        let t = if t_s.is_finite() { t_s } else { self.last_t };
        let dt = (t - self.last_t).max(0.0);
        self.last_t = t;
        self.last_transition = None;
        if self.follower {
            if let Some(a) = self.imposed.take() {
                self.follow(t, a);
            }
        } else {
            match self.policy {
                Policy::IntentionalContact => self.step_table_i(t, dt, input),
                Policy::Phases => self.step_phases(t),
            }
            self.ramp_range(dt);
        }
        self.arrangement.fusion_weight = self.weight.at(t);
        &self.arrangement
    }

    /// Requests a interactive-force-control paper phase; it takes effect at the next [`Self::update`] (whose time is
    /// the switch time). Refused under the intentional-contact paper policy, which switches on sensed
    /// conditions only. Requesting the active phase is accepted and changes nothing.
    pub fn request_phase(&mut self, phase: Phase) -> Result<(), PhaseRefused> {
        match self.policy {
            Policy::Phases => {
                self.pending = Some(phase);
                Ok(())
            }
            Policy::IntentionalContact => Err(PhaseRefused {
                reason: "the intentional_contact policy (intentional-contact paper Table I) switches on sensed \
                         conditions only; configure `policy: phases` to request phases",
            }),
        }
    }

    /// Makes this supervisor follow `a`, decided by another one with the same configuration
    /// (the ROS graph: `priority_supervisor` decides, `task_controller` follows). From the first
    /// call on, its own rules are off; each imposed arrangement takes effect at the next
    /// [`Self::update`] with the deciding supervisor's switch time (so the torque blend and the
    /// fusion weight shift run on the same clock) and its sensing range. Invalid values are
    /// refused and change nothing.
    pub fn impose(&mut self, a: Imposed) -> Result<(), PhaseRefused> {
        let valid = a.switch_time_s.is_finite()
            && a.sensing_range_m.is_finite()
            && a.sensing_range_m >= 0.0
            && (0.0..=1.0).contains(&a.fusion_weight_target);
        if !valid {
            return Err(PhaseRefused {
                reason: "imposed arrangement: switch time and sensing range must be finite, the range >= 0 and the fusion weight in [0, 1]",
            });
        }
        self.follower = true;
        self.imposed = Some(a);
        Ok(())
    }

    /// Applies an imposed arrangement (see [`Self::impose`]).
    fn follow(&mut self, t: f64, a: Imposed) {
        let current = &self.arrangement;
        let new_switch = a.mode != current.mode || a.switch_time_s.to_bits() != current.switch_time_s.to_bits();
        if a.fusion_weight_target != self.weight.target() {
            let now = self.weight.at(t);
            self.weight = WeightShift::new(
                now,
                a.fusion_weight_target,
                a.switch_time_s,
                self.fusion.duration_s,
                self.fusion.gain,
            );
            self.arrangement.fusion_weight_target = a.fusion_weight_target;
        }
        if new_switch {
            self.switch(a.switch_time_s, a.mode, Cause::Imposed);
        }
        self.arrangement.sensing_range_m = a.sensing_range_m;
        self.blocked = a.blocked; // a follower's own rules never set it
    }

    /// The active arrangement.
    pub fn arrangement(&self) -> &Arrangement {
        &self.arrangement
    }

    /// The active mode.
    pub fn mode(&self) -> Mode {
        self.arrangement.mode
    }

    /// The configured policy.
    pub fn policy(&self) -> Policy {
        self.policy
    }

    /// The configured task names ([`Arrangement::task_order`] indexes into them).
    pub fn tasks(&self) -> &[String] {
        &self.tasks
    }

    /// Why the arm holds in (a) instead of pushing again (`None`: not blocked). A follower
    /// ([`Self::impose`]) has the deciding supervisor's.
    pub fn blocked(&self) -> Option<Blocked> {
        self.blocked
    }

    /// Nothing is to be pressed: in a hard contact (c), whose reaction relieves the contact (a
    /// retried push goes on in (b) once it is relieved; its goal pressing on in (c) held a fixed
    /// obstacle there to the end of the run), and in the [`Blocked`] hold after a push given up,
    /// where the goal would drive the arm back into the obstacle that blocked it and into ε_c
    /// again. The skin's approach bound then lets nothing close on a sensed surface
    /// (`docs/resolver.md`). A follower ([`Self::impose`]) applies the same rule to the
    /// decider's mode and hold.
    pub fn releasing(&self) -> bool {
        self.arrangement.mode == Mode::HardContact || self.blocked.is_some()
    }

    /// The goal changed: a push that was given up may succeed toward the new goal, so the
    /// [`Blocked`] hold ends.
    pub fn new_goal(&mut self) {
        self.blocked = None;
    }

    /// The transition made by the last [`Self::update`], if any.
    pub fn last_transition(&self) -> Option<Transition> {
        self.last_transition
    }

    /// The transition log (ring buffer of the latest transitions).
    pub fn log(&self) -> &TransitionLog {
        &self.log
    }

    /// Intentional-contact paper Table I with dwell times and hysteresis (rules in `docs/supervisor.md`).
    fn step_table_i(&mut self, t: f64, dt: f64, u: &SupervisorInput) {
        let th = self.thresholds;
        let dw = self.dwell;
        let fc = u.contact_force_n;
        let over = fc.is_nan() || fc >= th.contact_force_n; // NaN counts as over the limit
        let impact = fc.is_nan() || fc >= th.impact_force_n;
        // A dip under ε_c shorter than the gap is no release: a force that alternates over and
        // under ε_c from one skin sample to the next is over it (the contact's own peaks are),
        // and its rise after such a dip is no new strike.
        let in_gap = t - self.last_over_s <= dw.hard_contact_gap_s; // NaN: false
        let strike = over && !self.was_over && !in_gap;
        self.was_over = over;
        let held = over || in_gap;
        if over {
            self.last_over_s = t;
        }
        // In a push (b), strikes of a contact that gives way are the peaks of an obstacle that
        // slides, not a contact that keeps striking ε_c where it stands.
        let mode = self.arrangement.mode;
        let pushing = mode == Mode::IntentionalContact;
        if pushing && u.contact_advance_mps.is_finite() && dt > 0.0 {
            let a = 1.0 - (-dt / dw.give_way_s).exp();
            self.advance_mps += (u.contact_advance_mps - self.advance_mps) * a;
        }
        let gave_way = pushing && self.advance_mps >= th.give_way_speed_mps;
        let struck_again = strike && t - self.last_strike_s <= dw.hard_contact_repeat_s && !gave_way; // NaN: false
        if strike {
            self.last_strike_s = t;
        }
        let below = fc < th.contact_force_n - th.contact_band_n; // NaN is never below
        let (v, fd, ge) = (u.ee_speed_mps, u.avoidance_force_n, u.goal_error_m);
        let invalid = v.is_nan() || fd.is_nan() || ge.is_nan();
        match mode {
            Mode::Avoidance | Mode::IntentionalContact => {
                // A hard contact can happen in (a) or (b): checked first, it has priority.
                if self.over_limit.step(t, over, held, dw.hard_contact_s) || impact || struck_again {
                    self.resume = mode;
                    if mode == Mode::IntentionalContact {
                        // Another try only if this push got the goal nearer (the obstacle gave
                        // way) and the last hard contact of the push is long enough ago that the
                        // (b) → (c) switch cannot repeat more than twice in `retry_interval_s`.
                        let progress = self.push_ref_error_m - ge >= th.progress_min_m;
                        // At its goal when this push began (or at its last hard contact), or
                        // now, the arm pushed nothing: the contact struck it, and there is no
                        // progress to ask of the arm.
                        let tol = th.goal_tolerance_m;
                        self.hit_at_goal = self.push_ref_error_m <= tol || ge <= tol; // NaN: false
                        let spaced = self.retry_spaced(t);
                        self.retry = (progress || self.hit_at_goal) && spaced;
                        self.push_ref_error_m = ge;
                        self.push_limit_s = t;
                    }
                    self.switch(t, Mode::HardContact, Cause::ContactOverLimit);
                    self.record_peak(fc);
                    return;
                }
                if mode == Mode::Avoidance {
                    if let Some(b) = self.blocked {
                        // Held after a failed push: only a changed situation lets (b) be tried
                        // again (progress toward the goal, or nothing in range any more).
                        // (Not within `retry_interval_s` of the last (b) → (c): a push then is
                        // a retry, and the arm backing out of range is no changed situation.)
                        let clear = fd <= th.obstacle_force_n;
                        let cleared = self.cleared.step(t, clear, clear, dw.clear_s);
                        let spaced = self.retry_spaced(t);
                        if spaced && (cleared || ge < b.goal_error_m - th.progress_min_m) {
                            self.blocked = None;
                        }
                        return;
                    }
                    // Stopped: slower than ε_v, or crawling toward the goal slower than
                    // `crawl_speed_mps` (a NaN speed is never stopped).
                    let crawl_min_m = th.crawl_speed_mps * th.progress_window_s;
                    let crawl = self.progress.step(t, ge, th.progress_window_s, crawl_min_m) && !v.is_nan();
                    let set = (v <= th.speed_mps || crawl)
                        && fd > th.obstacle_force_n + th.obstacle_band_n
                        && ge > th.goal_tolerance_m + th.goal_band_m;
                    let keep = (v <= th.speed_mps + th.speed_band_mps || crawl)
                        && fd > th.obstacle_force_n
                        && ge > th.goal_tolerance_m;
                    if self.stuck.step(t, set, keep, dw.stuck_s) {
                        self.push_ref_error_m = ge;
                        self.switch(t, Mode::IntentionalContact, Cause::Stuck);
                    }
                } else {
                    let clear = fd <= th.obstacle_force_n;
                    // At rest at the goal with an obstacle still in range is Table I's (b): going
                    // back to (a) there lets avoidance push the hand off the goal, stuck again,
                    // (b) again (a cycle seen in the TOMM scenes).
                    let reached = ge <= th.goal_tolerance_m && clear;
                    // Every timer advances every cycle; then the first that has held wins.
                    let g = self.goal_reached.step(t, reached, reached, dw.goal_reached_s);
                    let c = self.cleared.step(t, clear, clear, dw.clear_s);
                    let i = self.invalid.step(t, invalid, invalid, dw.clear_s);
                    // A push that gets nowhere below ε_c (a rigid contact's touches each too short
                    // for `hard_contact_s`, or a stall) is given up as one that reached ε_c.
                    let no_progress = self.progress.step(t, ge, dw.push_stall_s, th.progress_min_m);
                    let stalled = no_progress && ge > th.goal_tolerance_m + th.goal_band_m;
                    self.record_peak(fc);
                    let cause = if g {
                        Some(Cause::GoalReached)
                    } else if c {
                        Some(Cause::ObstacleCleared)
                    } else if i {
                        Some(Cause::InvalidInput)
                    } else {
                        None
                    };
                    if let Some(cause) = cause {
                        self.switch(t, Mode::Avoidance, cause);
                    } else if stalled {
                        self.blocked = Some(Blocked { since_s: t, goal_error_m: ge, contact_force_n: self.peak_n });
                        self.push_limit_s = t;
                        self.switch(t, Mode::Avoidance, Cause::PushStalled);
                    }
                }
            }
            Mode::HardContact => {
                self.record_peak(fc);
                // Back to (b) when the force is below ε_c − band (Table I (b): `‖F_c‖ < ε_c`);
                // a hard contact of (a) back to (a) only when the contact is gone (Table I (a):
                // `‖F_c‖ = 0`).
                let to_b = self.resume == Mode::IntentionalContact && self.retry;
                // A push given up is released into (a) below the band too: avoidance, first
                // there, relieves the rest of the contact.
                let pushed = self.resume == Mode::IntentionalContact;
                let released = if pushed { below } else { fc <= th.contact_zero_n }; // NaN: never
                if self.released.step(t, released, released, dw.contact_release_s) {
                    if to_b {
                        // The obstacle gave way before the push reached ε_c: push on.
                        self.switch(t, Mode::IntentionalContact, Cause::ContactReleased);
                    } else if pushed && self.hit_at_goal {
                        // Hit again too soon at the goal: (a), where stuck detection starts the
                        // next push once the hits have stopped; nothing of the arm's is blocked.
                        self.switch(t, Mode::Avoidance, Cause::ContactReleased);
                    } else if pushed {
                        // The push of (b) reached ε_c without getting the goal nearer (or again
                        // too soon): pushing again would only hit ε_c again (the (b) <-> (c)
                        // cycle of a fixed or too heavy obstacle).
                        self.blocked = Some(Blocked { since_s: t, goal_error_m: ge, contact_force_n: self.peak_n });
                        self.switch(t, Mode::Avoidance, Cause::PushBlocked);
                    } else {
                        self.switch(t, self.resume, Cause::ContactReleased);
                    }
                }
            }
            // Not reachable under this policy; nothing to do.
            Mode::PreContact | Mode::Contact => {}
        }
    }

    /// Interactive-force-control paper Table 1: a pending request switches the phase and starts the weight shift
    /// from the current `w` (so a reversal mid-shift is continuous too).
    fn step_phases(&mut self, t: f64) {
        let Some(phase) = self.pending.take() else {
            return;
        };
        let to = phase.mode();
        if to == self.arrangement.mode {
            return;
        }
        let target = match phase {
            Phase::PreContact => self.fusion.w_precontact,
            Phase::Contact => self.fusion.w_contact,
        };
        let now = self.weight.at(t);
        self.weight = WeightShift::new(now, target, t, self.fusion.duration_s, self.fusion.gain);
        self.arrangement.fusion_weight_target = target;
        self.switch(t, to, Cause::PhaseRequest);
    }

    /// Sensing range ramp (intentional-contact paper Sec. III: reduced gradually during intentional contact):
    /// toward `intentional_contact_m` in (b), back to nominal in (a) and the interactive-force-control paper phases,
    /// held in (c).
    fn ramp_range(&mut self, dt: f64) {
        let target = match self.arrangement.mode {
            Mode::IntentionalContact => self.range.intentional_contact_m,
            Mode::HardContact => return,
            Mode::Avoidance | Mode::PreContact | Mode::Contact => self.range.nominal_m,
        };
        let r = &mut self.arrangement.sensing_range_m;
        *r = if *r > target {
            (*r - self.range.shrink_rate_mps * dt).max(target)
        } else {
            (*r + self.range.restore_rate_mps * dt).min(target)
        };
    }

    /// Keeps the largest `‖F_c‖` of this (b) or (c) (NaN counts as infinite).
    fn record_peak(&mut self, fc: f64) {
        self.peak_n = if fc.is_nan() { f64::INFINITY } else { self.peak_n.max(fc) };
    }

    /// Whether the last push limit ((b) → (c), or a stall) is at least `retry_interval_s`
    /// before `t` (or there was none).
    fn retry_spaced(&self, t: f64) -> bool {
        self.push_limit_s.is_nan() || t - self.push_limit_s >= self.dwell.retry_interval_s
    }

    fn switch(&mut self, t: f64, to: Mode, cause: Cause) {
        let from = self.arrangement.mode;
        let a = &mut self.arrangement;
        a.mode = to;
        a.task_order.clear();
        a.task_order.extend_from_slice(&self.orders[to as usize]); // within reserved capacity
        a.switch_time_s = t;
        for d in [
            &mut self.over_limit,
            &mut self.released,
            &mut self.stuck,
            &mut self.goal_reached,
            &mut self.cleared,
            &mut self.invalid,
        ] {
            *d = Dwell::IDLE;
        }
        self.progress = Progress::IDLE;
        self.last_strike_s = f64::NAN;
        self.advance_mps = 0.0;
        self.peak_n = 0.0;
        let tr = Transition { t_s: t, from, to, cause };
        self.last_transition = Some(tr);
        self.log.push(tr);
    }
}
