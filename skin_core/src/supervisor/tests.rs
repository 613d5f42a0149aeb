use std::path::PathBuf;

use super::blend::{chi, step_bound};
use super::*;

const DT: f64 = 0.004; // 250 Hz

fn shipped() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../config/supervisor.yaml")
}

fn params() -> SupervisorParams {
    SupervisorParams::load(&shipped()).expect("shipped supervisor.yaml")
}

fn phases_params() -> SupervisorParams {
    let mut p = params();
    p.policy = Policy::Phases;
    p
}

/// Deterministic splitmix64 → uniform [-1, 1).
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    }
}

fn input(v: f64, fd: f64, fc: f64, ge: f64) -> SupervisorInput {
    SupervisorInput {
        ee_speed_mps: v,
        avoidance_force_n: fd,
        contact_force_n: fc,
        goal_error_m: ge,
        contact_advance_mps: f64::NAN,
    }
}

/// `u` with the pressed link advancing into its contact at `mps`.
fn advancing(u: SupervisorInput, mps: f64) -> SupervisorInput {
    SupervisorInput { contact_advance_mps: mps, ..u }
}

/// Runs `steps` cycles of `u` from `*t`; returns the transitions seen.
fn run(sup: &mut Supervisor, t: &mut f64, steps: usize, u: SupervisorInput) -> Vec<Transition> {
    let mut out = Vec::new();
    for _ in 0..steps {
        *t += DT;
        sup.update(*t, &u);
        out.extend(sup.last_transition());
    }
    out
}

/// Cycles a force over ε_c must last to be a hard contact (`dwell.hard_contact_s`).
fn held(p: &SupervisorParams) -> usize {
    (p.dwell.hard_contact_s / DT).ceil() as usize + 2 // + 2: t is summed from DT
}

fn stuck() -> SupervisorInput {
    input(0.0, 3.0, 0.0, 0.2)
}

/// Drives the intentional-contact paper supervisor into (b).
/// A supervisor of `p` driven from (a) into (b), and the time it got there.
fn in_b(p: &SupervisorParams) -> (Supervisor, f64) {
    let mut sup = Supervisor::new(p, 0.0).unwrap();
    let mut t = 0.0;
    into_b(&mut sup, &mut t);
    (sup, t)
}

fn into_b(sup: &mut Supervisor, t: &mut f64) {
    let tr = run(sup, t, 200, stuck());
    assert_eq!(tr.len(), 1, "{tr:?}");
    assert_eq!(sup.mode(), Mode::IntentionalContact);
}

#[test]
fn shipped_config_loads_and_mirrors_table_i() {
    let p = params();
    let sup = Supervisor::new(&p, 0.0).unwrap();
    assert_eq!(sup.mode(), Mode::Avoidance);
    let names: Vec<&str> = sup.arrangement().task_names(sup.tasks()).collect();
    assert_eq!(names, ["avoidance", "goal", "contact_reaction"]);
    for (i, m) in Mode::ALL.iter().enumerate() {
        assert_eq!(m.as_u8() as usize, i);
        assert_eq!(Mode::from_u8(i as u8), Some(*m));
    }
    assert_eq!(Mode::from_u8(5), None);
}

#[test]
fn stuck_switches_a_to_b_after_dwell() {
    let p = params();
    let mut sup = Supervisor::new(&p, 0.0).unwrap();
    let mut t = 0.0;
    let tr = run(&mut sup, &mut t, 200, stuck());
    assert_eq!(tr.len(), 1);
    assert_eq!((tr[0].from, tr[0].to, tr[0].cause), (Mode::Avoidance, Mode::IntentionalContact, Cause::Stuck));
    // First sample at DT starts the dwell; the switch comes once stuck_s has elapsed.
    assert!((tr[0].t_s - DT - p.dwell.stuck_s).abs() < DT + 1e-9, "{}", tr[0].t_s);
    assert_eq!(sup.arrangement().switch_time_s, tr[0].t_s);
    let names: Vec<&str> = sup.arrangement().task_names(sup.tasks()).collect();
    assert_eq!(names, ["goal", "contact_reaction", "avoidance"]);
}

#[test]
fn no_switch_to_b_when_moving_or_clear_or_at_goal() {
    let p = params();
    // moving for less than one progress window (moving toward the goal for longer:
    // `a_crawl_without_goal_progress_is_stuck`)
    let mut sup = Supervisor::new(&p, 0.0).unwrap();
    let mut t = 0.0;
    let within = (p.thresholds.progress_window_s / DT) as usize - 1;
    assert!(run(&mut sup, &mut t, within, input(0.05, 3.0, 0.0, 0.2)).is_empty());
    for u in [
        input(0.0, 0.0, 0.0, 0.2),   // nothing in range
        input(0.0, 3.0, 0.0, 0.005), // goal reached
    ] {
        let mut sup = Supervisor::new(&p, 0.0).unwrap();
        let mut t = 0.0;
        assert!(run(&mut sup, &mut t, 1000, u).is_empty(), "{u:?}");
    }
}

#[test]
fn contact_over_limit_in_b_goes_to_c_and_the_push_is_given_up() {
    let p = params();
    let (mut sup, mut t) = in_b(&p);
    let tr = run(&mut sup, &mut t, held(&p), input(0.0, 0.0, 6.0, 0.2));
    assert_eq!(tr.len(), 1);
    assert_eq!((tr[0].from, tr[0].to), (Mode::IntentionalContact, Mode::HardContact));
    assert_eq!(tr[0].cause, Cause::ContactOverLimit);
    let names: Vec<&str> = sup.arrangement().task_names(sup.tasks()).collect();
    assert_eq!(names, ["contact_reaction", "goal", "avoidance"]);
    // Below eps_c but inside the band: stays in (c).
    assert!(run(&mut sup, &mut t, 500, input(0.0, 0.0, 4.0, 0.2)).is_empty());
    assert_eq!(sup.blocked(), None);
    // Below eps_c - band for the dwell: the push of (b) reached eps_c, so back to (a), blocked,
    // where avoidance relieves the rest of the contact.
    let tr = run(&mut sup, &mut t, 200, input(0.0, 3.0, 2.0, 0.2));
    assert_eq!(tr.len(), 1);
    assert_eq!((tr[0].from, tr[0].to, tr[0].cause), (Mode::HardContact, Mode::Avoidance, Cause::PushBlocked));
    let b = sup.blocked().expect("blocked");
    assert_eq!((b.since_s, b.goal_error_m, b.contact_force_n), (tr[0].t_s, 0.2, 6.0));
}

/// A push that got the goal nearer by `progress_min_m` since it began (or since its last hard
/// contact) before reaching ε_c is tried again ((c) → (b)); a second hard contact within `retry_interval_s` gives it up,
/// so (b) → (c) happens at most twice in that long (no chatter). A push that got nowhere is
/// given up at once.
#[test]
fn a_push_that_made_progress_is_retried_once_per_interval() {
    let p = params();
    let min = p.thresholds.progress_min_m;
    let (mut sup, mut t) = in_b(&p);
    run(&mut sup, &mut t, 10, input(0.02, 0.0, 2.0, 0.2));
    assert!(!sup.releasing(), "(b) is no hard contact");
    let tr = run(&mut sup, &mut t, held(&p), input(0.02, 0.0, 6.0, 0.2 - 2.0 * min));
    assert_eq!((tr[0].to, tr[0].cause), (Mode::HardContact, Cause::ContactOverLimit));
    assert!(sup.releasing(), "a retried push's hard contact presses nothing either");
    let tr = run(&mut sup, &mut t, 200, input(0.0, 3.0, 0.0, 0.2));
    assert_eq!(
        (tr[0].from, tr[0].to, tr[0].cause),
        (Mode::HardContact, Mode::IntentionalContact, Cause::ContactReleased)
    );
    assert_eq!(sup.blocked(), None);
    assert!(!sup.releasing(), "relieved, the retried push presses again in (b)");
    // Progress again, but 0.8 s after the last hard contact: given up.
    run(&mut sup, &mut t, 10, input(0.02, 0.0, 2.0, 0.2));
    run(&mut sup, &mut t, held(&p), input(0.02, 0.0, 6.0, 0.2 - 4.0 * min));
    assert!(sup.releasing(), "a push given up is released, not pressed again");
    let tr = run(&mut sup, &mut t, 200, input(0.0, 3.0, 0.0, 0.2));
    assert_eq!(tr.last().map(|tr| tr.cause), Some(Cause::PushBlocked));
    assert!(sup.releasing(), "the hold after a push given up presses nothing either");

    // No progress since the push began: blocked on the first hard contact.
    let (mut sup, mut t) = in_b(&p);
    run(&mut sup, &mut t, 10, input(0.02, 0.0, 2.0, 0.2));
    run(&mut sup, &mut t, held(&p), input(0.0, 0.0, 6.0, 0.2 - 0.5 * min));
    let tr = run(&mut sup, &mut t, 200, input(0.0, 3.0, 0.0, 0.2));
    assert_eq!(tr.last().map(|tr| tr.cause), Some(Cause::PushBlocked));
}

/// `‖F_c‖ ≥ ε_c` is a hard contact when it lasts `hard_contact_s` (dips shorter than
/// `hard_contact_gap_s` included), when it strikes ε_c again within `hard_contact_repeat_s` of
/// its last strike, or at once from `impact_force_n`; one strike shorter than the dwell (a rigid
/// touch's peak) is none, and a rise after a dip shorter than the gap is the same strike (an
/// impact's ringing).
#[test]
fn a_hard_contact_lasts_strikes_again_or_is_an_impact() {
    let p = params();
    let (th, dw) = (p.thresholds, p.dwell);
    let strike = input(0.02, 3.0, th.contact_force_n + 0.5, 0.2);
    let light = input(0.02, 3.0, 2.0, 0.2);
    let (mut sup, mut t) = in_b(&p);
    // the dwell goes on through a dip shorter than the gap: the strike and the gap within it
    let short = ((dw.hard_contact_s - dw.hard_contact_gap_s) / DT) as usize - 2;
    assert!(run(&mut sup, &mut t, short, strike).is_empty(), "shorter than the dwell");
    let apart = (dw.hard_contact_repeat_s / DT) as usize + 2;
    assert!(run(&mut sup, &mut t, apart, light).is_empty());
    assert!(run(&mut sup, &mut t, 1, strike).is_empty(), "a strike more than repeat_s after the last");
    assert!(DT < dw.hard_contact_gap_s);
    run(&mut sup, &mut t, 1, light);
    assert!(run(&mut sup, &mut t, 1, strike).is_empty(), "a rise after a dip within the gap: the same strike");
    run(&mut sup, &mut t, 10, light);
    let tr = run(&mut sup, &mut t, 1, strike);
    let to: Vec<_> = tr.iter().map(|tr| (tr.to, tr.cause)).collect();
    assert_eq!(to, [(Mode::HardContact, Cause::ContactOverLimit)], "struck again within repeat_s");

    let (mut sup, mut t) = in_b(&p);
    assert_eq!(run(&mut sup, &mut t, 1, input(0.02, 0.0, th.impact_force_n, 0.2)).len(), 1);
    assert_eq!(sup.mode(), Mode::HardContact, "an impact, at once");
}

/// In a push (b), a link that advances into its contact (the obstacle slides) may strike ε_c
/// again and again, each strike shorter than the dwell: the peaks of a sliding push. The same
/// strikes where the link stands are a hard contact, and so are strikes in (a).
#[test]
fn strikes_of_a_contact_that_gives_way_are_no_hard_contact() {
    let p = params();
    let (th, dw) = (p.thresholds, p.dwell);
    let speed = 2.0 * th.give_way_speed_mps;
    let strikes = |sup: &mut Supervisor, t: &mut f64, mps: f64| {
        let (peak, push) = (input(0.02, 3.0, th.contact_force_n + 0.5, 0.2), input(0.02, 3.0, 3.0, 0.2));
        let mut tr = run(sup, t, (2.0 * dw.give_way_s / DT) as usize, advancing(push, mps));
        for _ in 0..5 {
            tr.extend(run(sup, t, 2, advancing(peak, mps)));
            tr.extend(run(sup, t, (0.2 / DT) as usize, advancing(push, mps)));
        }
        tr
    };
    let (mut sup, mut t) = in_b(&p);
    assert!(strikes(&mut sup, &mut t, speed).is_empty(), "the obstacle gives way: a push with peaks");
    let (mut sup, mut t) = in_b(&p);
    let tr = strikes(&mut sup, &mut t, 0.0);
    assert_eq!(tr.first().map(|tr| tr.to), Some(Mode::HardContact), "where the link stands: struck again");
    let mut sup = Supervisor::new(&p, 0.0).unwrap();
    let tr = strikes(&mut sup, &mut 0.0, speed);
    assert_eq!(tr.first().map(|tr| tr.to), Some(Mode::HardContact), "in (a) nothing is pushed");
}

/// A force that alternates over and under ε_c from one skin sample to the next (the contact's
/// peaks fall between the samples) is over ε_c for the dwell, however fast the link advances.
#[test]
fn a_force_flickering_over_eps_c_sample_by_sample_lasts() {
    let p = params();
    let (th, dw) = (p.thresholds, p.dwell);
    assert!(2.0 * DT <= dw.hard_contact_gap_s, "a dip of one sample is within the gap");
    let (mut sup, mut t) = in_b(&p);
    let (over, under) = (input(0.02, 3.0, th.contact_force_n + 3.0, 0.2), input(0.02, 3.0, 2.0, 0.2));
    assert!(run(&mut sup, &mut t, (2.0 * dw.give_way_s / DT) as usize, advancing(under, 0.05)).is_empty());
    let t0 = t;
    let mut tr = Vec::new();
    while tr.is_empty() && t - t0 < 1.0 {
        tr.extend(run(&mut sup, &mut t, 1, advancing(over, 0.05)));
        tr.extend(run(&mut sup, &mut t, 1, advancing(under, 0.05)));
    }
    assert_eq!(tr.first().map(|tr| tr.to), Some(Mode::HardContact));
    assert!(t - t0 >= dw.hard_contact_s && t - t0 <= dw.hard_contact_s + 3.0 * DT, "after the dwell: {}", t - t0);
}

/// A hard contact that strikes the arm while it holds its goal in (b) (an obstacle pushed into
/// it) is no push that failed: released, the arm goes back to (b); struck again within
/// `retry_interval_s`, now knocked off its goal, it goes to (a), not held blocked, so stuck
/// detection can start the push back to the goal.
#[test]
fn a_hit_at_the_goal_is_no_blocked_push() {
    let p = params();
    let tol = p.thresholds.goal_tolerance_m;
    let (mut sup, mut t) = in_b(&p);
    assert!(
        run(&mut sup, &mut t, 500, input(0.0, 3.0, 0.5, 0.5 * tol)).is_empty(),
        "at the goal, obstacle in range: (b)"
    );
    let tr = run(&mut sup, &mut t, held(&p), input(0.0, 3.0, 8.0, 0.5 * tol));
    assert_eq!((tr[0].to, tr[0].cause), (Mode::HardContact, Cause::ContactOverLimit));
    let tr = run(&mut sup, &mut t, 200, input(0.0, 3.0, 0.0, 2.0 * tol));
    assert_eq!((tr[0].to, tr[0].cause), (Mode::IntentionalContact, Cause::ContactReleased));
    run(&mut sup, &mut t, held(&p), input(0.0, 3.0, 8.0, 3.0 * tol));
    let tr = run(&mut sup, &mut t, 200, input(0.0, 3.0, 0.0, 3.0 * tol));
    assert_eq!((tr[0].to, tr[0].cause), (Mode::Avoidance, Cause::ContactReleased));
    assert_eq!(sup.blocked(), None);
    assert!(!sup.releasing());
    into_b(&mut sup, &mut t);
}

/// A push in (b) that gets the goal less than `progress_min_m` nearer in `push_stall_s` (it
/// stalls, or its contact flickers under the hard-contact rules) is given up as one that reached
/// ε_c: (a), held, pressing nothing; a push that gains on the goal slowly goes on.
#[test]
fn a_push_that_gets_nowhere_is_given_up() {
    let p = params();
    let (th, dw) = (p.thresholds, p.dwell);
    let (mut sup, mut t) = in_b(&p);
    let steps = ((dw.push_stall_s + 0.6) / DT) as usize;
    let tr = run(&mut sup, &mut t, steps, input(0.0, 3.0, 3.0, 0.2));
    let to: Vec<_> = tr.iter().map(|tr| (tr.from, tr.to, tr.cause)).collect();
    assert_eq!(to, [(Mode::IntentionalContact, Mode::Avoidance, Cause::PushStalled)]);
    let b = sup.blocked().expect("held");
    assert_eq!((b.goal_error_m, b.contact_force_n), (0.2, 3.0));
    assert!(sup.releasing());
    assert!(run(&mut sup, &mut t, 2000, stuck()).is_empty(), "no second push while held");

    let (mut sup, mut t) = in_b(&p);
    let t0 = t;
    let rate = 1.2 * th.progress_min_m / dw.push_stall_s;
    for _ in 0..(4.0 * dw.push_stall_s / DT) as usize {
        t += DT;
        sup.update(t, &input(0.01, 3.0, 3.0, 0.2 - rate * (t - t0)));
        assert_eq!(sup.last_transition(), None, "a slow push that gains on the goal goes on");
    }
}

/// Against a fixed obstacle the arm is stuck again right after backing off: while blocked the
/// stuck test is off, so there is no second push (no (b) <-> (c) cycle); a new goal ends it.
#[test]
fn blocked_holds_a_until_a_new_goal() {
    let p = params();
    let (mut sup, mut t) = in_b(&p);
    run(&mut sup, &mut t, 10, input(0.0, 3.0, 20.0, 0.2));
    let tr = run(&mut sup, &mut t, 200, input(0.0, 3.0, 0.0, 0.2));
    assert_eq!(tr.last().map(|tr| tr.cause), Some(Cause::PushBlocked));
    assert!(run(&mut sup, &mut t, 5000, stuck()).is_empty(), "20 s stuck while blocked: no switch");
    assert_eq!(sup.blocked().map(|b| b.contact_force_n), Some(20.0));
    sup.new_goal();
    assert_eq!(sup.blocked(), None);
    into_b(&mut sup, &mut t);
}

/// A hold ends when the situation changed: the goal error fell by `progress_min_m` (the
/// obstacle gave way) or nothing is in range for `clear_s`; a hard contact while held returns
/// to the held (a).
#[test]
fn blocked_ends_on_goal_progress_or_nothing_in_range() {
    let p = params();
    let blocked = || {
        let (mut sup, mut t) = in_b(&p);
        run(&mut sup, &mut t, held(&p), input(0.0, 3.0, 8.0, 0.2));
        run(&mut sup, &mut t, 200, input(0.0, 3.0, 0.0, 0.2));
        assert!(sup.blocked().is_some());
        // Within `retry_interval_s` of the hard contact nothing ends the hold (the arm backing
        // out of range is no changed situation).
        let interval = (p.dwell.retry_interval_s / DT) as usize;
        run(&mut sup, &mut t, interval - 220, input(0.0, 0.0, 0.0, 0.1));
        assert!(sup.blocked().is_some(), "held until retry_interval_s after the hard contact");
        run(&mut sup, &mut t, 20, input(0.0, 3.0, 0.0, 0.2));
        (sup, t)
    };
    let (mut sup, mut t) = blocked();
    run(&mut sup, &mut t, 100, input(0.02, 3.0, 0.0, 0.195));
    assert!(sup.blocked().is_some(), "5 mm of progress is not enough");
    run(&mut sup, &mut t, 1, input(0.02, 3.0, 0.0, 0.2 - p.thresholds.progress_min_m - 1e-3));
    assert_eq!(sup.blocked(), None);

    let (mut sup, mut t) = blocked();
    let steps = (p.dwell.clear_s / DT) as usize;
    run(&mut sup, &mut t, steps - 2, input(0.0, 0.0, 0.0, 0.3));
    assert!(sup.blocked().is_some(), "nothing in range for less than clear_s");
    run(&mut sup, &mut t, 4, input(0.0, 0.0, 0.0, 0.3)); // 4: t is summed from DT, ~11 s here
    assert_eq!(sup.blocked(), None);

    let (mut sup, mut t) = blocked();
    let tr = run(&mut sup, &mut t, held(&p), input(0.0, 3.0, 9.0, 0.2));
    assert_eq!((tr[0].from, tr[0].to), (Mode::Avoidance, Mode::HardContact));
    let tr = run(&mut sup, &mut t, 200, input(0.0, 3.0, 0.0, 0.2));
    assert_eq!((tr[0].to, tr[0].cause), (Mode::Avoidance, Cause::ContactReleased));
    assert!(sup.blocked().is_some(), "still held");
}

#[test]
fn hard_contact_from_a_returns_to_a() {
    let p = params();
    let mut sup = Supervisor::new(&p, 0.0).unwrap();
    let mut t = 0.0;
    let tr = run(&mut sup, &mut t, held(&p), input(0.1, 0.0, 5.0, 0.2));
    assert_eq!((tr[0].from, tr[0].to), (Mode::Avoidance, Mode::HardContact));
    let tr = run(&mut sup, &mut t, 200, input(0.1, 0.0, 0.0, 0.2));
    assert_eq!((tr[0].from, tr[0].to), (Mode::HardContact, Mode::Avoidance));
}

/// Table I (a) needs `‖F_c‖ = 0`: a hard contact is left for (a) only when the contact is gone
/// (`contact_zero_n`), not while the arm still presses below `ε_c − band`.
#[test]
fn hard_contact_is_left_for_a_only_without_contact() {
    let p = params();
    let th = p.thresholds;
    let mut sup = Supervisor::new(&p, 0.0).unwrap();
    let mut t = 0.0;
    run(&mut sup, &mut t, held(&p), input(0.1, 0.0, th.contact_force_n, 0.2));
    assert_eq!(sup.mode(), Mode::HardContact);
    let pressing = 0.5 * (th.contact_zero_n + th.contact_force_n - th.contact_band_n);
    assert!(run(&mut sup, &mut t, 500, input(0.1, 0.0, pressing, 0.2)).is_empty(), "still in contact");
    let tr = run(&mut sup, &mut t, 200, input(0.1, 0.0, th.contact_zero_n, 0.2));
    assert_eq!((tr[0].from, tr[0].to), (Mode::HardContact, Mode::Avoidance));
}

#[test]
fn goal_reached_or_cleared_b_to_a() {
    let p = params();
    for (u, cause) in [
        (input(0.0, 0.0, 0.0, 0.005), Cause::GoalReached), // wins: shorter dwell
        (input(0.05, 0.0, 0.0, 0.2), Cause::ObstacleCleared),
        (input(f64::NAN, 3.0, 0.0, 0.2), Cause::InvalidInput),
    ] {
        let (mut sup, mut t) = in_b(&p);
        let tr = run(&mut sup, &mut t, 300, u);
        assert_eq!(tr.len(), 1, "{u:?}");
        assert_eq!((tr[0].from, tr[0].to, tr[0].cause), (Mode::IntentionalContact, Mode::Avoidance, cause));
    }
}

/// Table I's (b) holds at rest at the goal while an obstacle is in range (going back to (a)
/// there would let avoidance push the end effector off the goal, stuck again, (b) again); (a)
/// follows once the obstacle is out of range.
#[test]
fn goal_reached_with_an_obstacle_in_range_stays_in_b() {
    let p = params();
    let (mut sup, mut t) = in_b(&p);
    assert!(run(&mut sup, &mut t, 1000, input(0.0, 3.0, 0.0, 0.0)).is_empty());
    let tr = run(&mut sup, &mut t, 300, input(0.0, 0.0, 0.0, 0.0));
    assert_eq!(tr.len(), 1, "{tr:?}");
    assert_eq!((tr[0].to, tr[0].cause), (Mode::Avoidance, Cause::GoalReached));
}

#[test]
fn sensing_range_shrinks_gradually_in_b_and_is_restored_in_a() {
    let p = params();
    let r = p.sensing_range;
    let (mut sup, mut t) = in_b(&p);
    let mut prev = sup.arrangement().sensing_range_m;
    let mut hit_zero_at = None;
    let stall_s = sup.arrangement().switch_time_s + p.dwell.push_stall_s; // the push gets nowhere here
    while t + DT < stall_s - 0.05 {
        t += DT;
        let range = sup.update(t, &stuck()).sensing_range_m;
        assert_eq!(sup.last_transition(), None);
        let d = prev - range;
        assert!((-1e-15..=r.shrink_rate_mps * DT + 1e-12).contains(&d), "step {d}");
        prev = range;
        if prev == r.intentional_contact_m && hit_zero_at.is_none() {
            hit_zero_at = Some(t);
        }
    }
    assert_eq!(prev, r.intentional_contact_m);
    assert!(hit_zero_at.is_some());
    // Goal reached, nothing in range -> (a); the range comes back gradually to nominal.
    let tr = run(&mut sup, &mut t, 100, input(0.0, 0.0, 0.0, 0.0));
    assert_eq!(tr[0].to, Mode::Avoidance);
    prev = sup.arrangement().sensing_range_m;
    for _ in 0..1000 {
        t += DT;
        let a = sup.update(t, &input(0.0, 0.0, 0.0, 0.0));
        let d = a.sensing_range_m - prev;
        assert!((-1e-15..=r.restore_rate_mps * DT + 1e-12).contains(&d));
        prev = a.sensing_range_m;
    }
    assert_eq!(prev, r.nominal_m);
}

/// Noise uniform ±20 % of the threshold around each threshold causes at most the expected
/// transition.
#[test]
fn noise_around_thresholds_does_not_chatter() {
    let p = params();
    let th = p.thresholds;
    let n = 5000;
    let mut rng = Rng(42);

    // Speed around eps_v in (a), obstacle in range, goal far (nearing at 5 mm/s, so that the push
    // is no stall): at most the one (a) -> (b).
    let mut sup = Supervisor::new(&p, 0.0).unwrap();
    let mut t = 0.0;
    let mut count = 0;
    for _ in 0..n {
        t += DT;
        let v = th.speed_mps * (1.0 + 0.2 * rng.next());
        sup.update(t, &input(v, 3.0, 0.0, 0.2 - 0.005 * t));
        count += sup.last_transition().is_some() as usize;
    }
    assert!(count <= 1, "speed noise: {count}");

    // Contact force around eps_c in (b): one (b) -> (c), never back (band 30 % > noise).
    let (mut sup, mut t) = in_b(&p);
    let base = sup.log().total();
    for _ in 0..n {
        t += DT;
        let fc = th.contact_force_n * (1.0 + 0.2 * rng.next());
        sup.update(t, &input(0.0, 3.0, fc, 0.2));
    }
    assert_eq!(sup.log().total() - base, 1, "contact noise");
    assert_eq!(sup.mode(), Mode::HardContact);

    // Contact force around the release level eps_c - band in (c): at most one way back.
    let release = th.contact_force_n - th.contact_band_n;
    let base = sup.log().total();
    for _ in 0..n {
        t += DT;
        let fc = release + 0.2 * th.contact_force_n * rng.next();
        sup.update(t, &input(0.0, 3.0, fc, 0.2));
    }
    assert!(sup.log().total() - base <= 1, "release noise");

    // Goal error around the tolerance in (b): at most one (b) -> (a), no re-entry.
    let (mut sup, mut t) = in_b(&p);
    let base = sup.log().total();
    for _ in 0..n {
        t += DT;
        let ge = th.goal_tolerance_m * (1.0 + 0.2 * rng.next());
        sup.update(t, &input(0.0, 3.0, 0.0, ge));
    }
    assert!(sup.log().total() - base <= 1, "goal noise");

    // Obstacle force around the in-range level in (a) while stopped (the goal nearing at 5 mm/s,
    // no stall): at most one (a) -> (b).
    let mut sup = Supervisor::new(&p, 0.0).unwrap();
    let mut t = 0.0;
    let level = th.obstacle_force_n + th.obstacle_band_n;
    for _ in 0..n {
        t += DT;
        let fd = level * (1.0 + 0.2 * rng.next());
        sup.update(t, &input(0.0, fd, 0.0, 0.2 - 0.005 * t));
    }
    assert!(sup.log().total() <= 1, "obstacle noise");
}

#[test]
fn nan_contact_counts_as_over_limit_and_blocks_release() {
    let p = params();
    let mut sup = Supervisor::new(&p, 0.0).unwrap();
    let mut t = 0.0;
    let tr = run(&mut sup, &mut t, 1, input(0.0, 0.0, f64::NAN, 0.2));
    assert_eq!(tr[0].to, Mode::HardContact);
    assert!(run(&mut sup, &mut t, 1000, input(0.0, 0.0, f64::NAN, 0.2)).is_empty());
}

#[test]
fn nan_speed_or_goal_never_counts_as_stuck() {
    let p = params();
    for u in [input(f64::NAN, 3.0, 0.0, 0.2), input(0.0, f64::NAN, 0.0, 0.2), input(0.0, 3.0, 0.0, f64::NAN)] {
        let mut sup = Supervisor::new(&p, 0.0).unwrap();
        let mut t = 0.0;
        assert!(run(&mut sup, &mut t, 1000, u).is_empty(), "{u:?}");
    }
}

#[test]
fn nan_time_is_replaced_by_previous_time() {
    let p = params();
    let mut sup = Supervisor::new(&p, 0.0).unwrap();
    sup.update(f64::NAN, &stuck());
    sup.update(0.1, &stuck());
    sup.update(f64::INFINITY, &stuck());
    assert_eq!(sup.mode(), Mode::Avoidance);
    assert!(sup.arrangement().sensing_range_m.is_finite());
}

#[test]
fn phase_requests_refused_under_paper_000_policy() {
    let p = params();
    let mut sup = Supervisor::new(&p, 0.0).unwrap();
    let e = sup.request_phase(Phase::Contact).unwrap_err();
    assert!(e.to_string().contains("policy"), "{e}");
    sup.update(0.1, &SupervisorInput::default());
    assert_eq!(sup.mode(), Mode::Avoidance);
}

#[test]
fn phases_switch_on_request_and_weight_follows_sigmoid() {
    let p = phases_params();
    let f = p.fusion;
    let mut sup = Supervisor::new(&p, 0.0).unwrap();
    assert_eq!(sup.mode(), Mode::PreContact);
    let names: Vec<&str> = sup.arrangement().task_names(sup.tasks()).collect();
    assert_eq!(names, ["hand_distance", "wrist", "tactile_guidance", "base_avoidance", "posture"]);
    let u = SupervisorInput::default();
    let mut t = 0.0;
    // No switch without a request, whatever the sensed signals.
    assert!(run(&mut sup, &mut t, 100, input(0.0, 3.0, 50.0, 0.2)).is_empty());
    sup.request_phase(Phase::Contact).unwrap();
    t += DT;
    sup.update(t, &u);
    let tr = sup.last_transition().unwrap();
    assert_eq!((tr.from, tr.to, tr.cause), (Mode::PreContact, Mode::Contact, Cause::PhaseRequest));
    assert_eq!(sup.arrangement().fusion_weight, f.w_precontact);
    assert_eq!(sup.arrangement().fusion_weight_target, f.w_contact);
    let names: Vec<&str> = sup.arrangement().task_names(sup.tasks()).collect();
    assert_eq!(names, ["hand_force", "wrist", "position_hold", "base_avoidance", "compliance", "posture"]);
    let mut prev = sup.arrangement().fusion_weight;
    let mut max_step: f64 = 0.0;
    let steps = (f.duration_s / DT) as usize + 10;
    for _ in 0..steps {
        t += DT;
        let w = sup.update(t, &u).fusion_weight;
        assert!(w >= prev - 1e-15, "not monotonic: {prev} -> {w}");
        max_step = max_step.max(w - prev);
        prev = w;
    }
    assert_eq!(prev, f.w_contact);
    assert!(max_step < 0.05, "weight step {max_step}");
    // Same phase again: accepted, no transition.
    sup.request_phase(Phase::Contact).unwrap();
    assert!(run(&mut sup, &mut t, 1, u).is_empty());
    // Back to precontact: w returns monotonically.
    sup.request_phase(Phase::PreContact).unwrap();
    let tr = run(&mut sup, &mut t, 1, u);
    assert_eq!(tr[0].to, Mode::PreContact);
    let mut prev = sup.arrangement().fusion_weight;
    for _ in 0..steps {
        t += DT;
        let w = sup.update(t, &u).fusion_weight;
        assert!(w <= prev + 1e-15);
        prev = w;
    }
    assert_eq!(prev, f.w_precontact);
    assert_eq!(sup.arrangement().sensing_range_m, p.sensing_range.nominal_m);
}

#[test]
fn reversal_mid_shift_is_continuous() {
    let p = phases_params();
    let mut sup = Supervisor::new(&p, 0.0).unwrap();
    let u = SupervisorInput::default();
    sup.request_phase(Phase::Contact).unwrap();
    sup.update(0.0, &u);
    let w_mid = sup.update(0.5, &u).fusion_weight;
    sup.request_phase(Phase::PreContact).unwrap();
    let w_after = sup.update(0.5, &u).fusion_weight;
    assert_eq!(w_mid, w_after);
}

#[test]
fn switching_does_not_reallocate_task_order() {
    let p = params();
    let mut sup = Supervisor::new(&p, 0.0).unwrap();
    let ptr = sup.arrangement().task_order().as_ptr();
    let mut t = 0.0;
    into_b(&mut sup, &mut t);
    run(&mut sup, &mut t, held(&p), input(0.0, 3.0, 9.0, 0.2));
    assert_eq!(sup.mode(), Mode::HardContact);
    assert_eq!(sup.arrangement().task_order().as_ptr(), ptr);
}

#[test]
fn log_ring_buffer_keeps_latest() {
    let mut p = params();
    p.log_capacity = 2;
    let (mut sup, mut t) = in_b(&p); // a -> b
    run(&mut sup, &mut t, held(&p), input(0.0, 3.0, 9.0, 0.2)); // b -> c
    run(&mut sup, &mut t, 200, input(0.0, 3.0, 0.0, 0.2)); // c -> a (push given up)
    assert_eq!(sup.log().total(), 3);
    let kept: Vec<(Mode, Mode)> = sup.log().iter().map(|t| (t.from, t.to)).collect();
    assert_eq!(kept, [(Mode::IntentionalContact, Mode::HardContact), (Mode::HardContact, Mode::Avoidance)]);
    assert_eq!(sup.log().last().unwrap().to, Mode::Avoidance);
}

// --- blending -------------------------------------------------------------------------------

#[test]
fn chi_starts_at_one_and_decreases_to_zero() {
    let g = 10.0;
    assert_eq!(chi(g, 0.0), 1.0);
    assert_eq!(chi(g, -1.0), 1.0);
    let mut prev = 1.0;
    for k in 1..1000 {
        let c = chi(g, k as f64 * 1e-3);
        assert!(c <= prev && c >= 0.0);
        prev = c;
    }
    assert!(chi(g, 5.0) < 1e-15);
    // The paper's eq. (11) would start at 1/2: a step of half the torque gap.
    let paper = (1.0 - (g * 0.0f64).tanh()) / 2.0;
    assert_eq!(paper, 0.5);
}

#[test]
fn blend_has_no_step_and_respects_per_cycle_bound() {
    let n = 15;
    let g = 10.0;
    let dt = 0.008; // 125 Hz
    let mut rng = Rng(7);
    let norm = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
    for trial in 0..50 {
        let mut blender = TorqueBlender::new(n);
        let mut old = vec![0.0; n];
        let mut new = vec![0.0; n];
        for i in 0..n {
            old[i] = 20.0 * rng.next();
            new[i] = 20.0 * rng.next();
        }
        let mut out = vec![0.0; n];
        let mut t = 0.0;
        // Old arrangement's torque, then switch at t_t.
        for _ in 0..5 {
            t += dt;
            blender.apply(t, &old, &mut out);
        }
        let before = out.clone();
        blender.start(t + dt, g);
        let mut prev = before.clone();
        let mut tau_k = new.clone();
        for step in 0..300 {
            t += dt;
            let prev_k = tau_k.clone();
            // The new arrangement's torque keeps changing (random drift).
            if step > 0 {
                for x in tau_k.iter_mut() {
                    *x += 0.5 * rng.next();
                }
            }
            blender.apply(t, &tau_k, &mut out);
            if step == 0 {
                for i in 0..n {
                    assert!((out[i] - before[i]).abs() <= 1e-12, "step at switch, trial {trial}");
                }
            } else {
                let d: Vec<f64> = out.iter().zip(&prev).map(|(a, b)| a - b).collect();
                let dk: Vec<f64> = tau_k.iter().zip(&prev_k).map(|(a, b)| a - b).collect();
                let gap: Vec<f64> = before.iter().zip(&prev_k).map(|(a, b)| a - b).collect();
                let bound = step_bound(g, dt, norm(&gap), norm(&dk));
                assert!(norm(&d) <= bound * (1.0 + 1e-12) + 1e-12, "trial {trial} step {step}: {} > {bound}", norm(&d));
            }
            prev.copy_from_slice(&out);
        }
        assert!(!blender.is_blending());
        assert_eq!(out, tau_k);
    }
}

#[test]
fn blend_syncs_with_arrangement_switch_time() {
    let p = params();
    let mut sup = Supervisor::new(&p, 0.0).unwrap();
    let mut blender = TorqueBlender::new(2);
    let mut out = [0.0; 2];
    let mut t = 0.0;
    for _ in 0..300 {
        t += DT;
        let a = sup.update(t, &stuck());
        blender.sync(a);
        let tau = if a.mode == Mode::Avoidance { [1.0, 2.0] } else { [-1.0, 0.0] };
        let last = out;
        blender.apply(t, &tau, &mut out);
        if sup.last_transition().is_some() {
            assert_eq!(out, last, "first output after the switch is the held torque");
            assert!(blender.is_blending());
        }
    }
    assert_eq!(sup.log().total(), 1);
}

#[test]
fn weight_shift_endpoints_and_monotonic() {
    let s = WeightShift::new(0.2, 0.9, 1.0, 2.0, 10.0);
    assert_eq!(s.at(0.0), 0.2);
    assert_eq!(s.at(1.0), 0.2);
    assert_eq!(s.at(3.0), 0.9);
    assert_eq!(s.at(f64::NAN), 0.2);
    let mut prev = 0.2;
    for k in 0..=2000 {
        let w = s.at(1.0 + k as f64 * 1e-3);
        assert!(w >= prev - 1e-15);
        prev = w;
    }
}

// --- configuration errors -------------------------------------------------------------------

fn shipped_text() -> String {
    std::fs::read_to_string(shipped()).unwrap()
}

fn load_err(old: &str, new: &str) -> String {
    let text = shipped_text();
    let bad = text.replace(old, new);
    assert_ne!(bad, text, "test expects `{old}` in the shipped file");
    SupervisorParams::from_yaml_str(&bad, "bad.yaml").unwrap_err().to_string()
}

#[test]
fn unknown_task_names_file_and_key() {
    let e = load_err("[goal, contact_reaction, avoidance]", "[goal, contact_reactoin, avoidance]");
    assert!(
        e.contains("bad.yaml") && e.contains("arrangements.intentional_contact[1]") && e.contains("contact_reactoin"),
        "{e}"
    );
}

#[test]
fn duplicate_task_in_arrangement_is_rejected() {
    let e = load_err("[goal, contact_reaction, avoidance]", "[goal, goal, avoidance]");
    assert!(
        e.contains("bad.yaml") && e.contains("arrangements.intentional_contact[1]") && e.contains("duplicate"),
        "{e}"
    );
}

#[test]
fn negative_eps_names_file_and_key() {
    let e = load_err("speed_mps: 0.01 ", "speed_mps: -0.01 ");
    assert!(e.contains("bad.yaml") && e.contains("thresholds.speed_mps"), "{e}");
    let e = load_err("contact_force_n: 5.0", "contact_force_n: -5.0");
    assert!(e.contains("bad.yaml") && e.contains("thresholds.contact_force_n"), "{e}");
}

#[test]
fn hysteresis_larger_than_eps_c_is_rejected() {
    for band in ["contact_band_n: 6.0", "contact_band_n: 5.0"] {
        let e = load_err("contact_band_n: 1.5", band);
        assert!(e.contains("bad.yaml") && e.contains("thresholds.contact_band_n"), "{e}");
    }
}

#[test]
fn other_invalid_values_are_rejected() {
    for (old, new, key) in [
        ("intentional_contact_m: 0.0", "intentional_contact_m: 0.5", "sensing_range.intentional_contact_m"),
        ("smoothing_gain_per_s: 10.0", "smoothing_gain_per_s: 0.0", "smoothing_gain_per_s"),
        ("w_contact: 1.0", "w_contact: 1.5", "fusion.w_contact"),
        ("stuck_s: 0.5", "stuck_s: -0.5", "dwell.stuck_s"),
        ("log_capacity: 64", "log_capacity: 0", "log_capacity"),
        ("impact_force_n: 10.0", "impact_force_n: 4.0", "thresholds.impact_force_n"),
        ("push_margin_n: 0.5", "push_margin_n: 5.0", "thresholds.push_margin_n"),
        ("push_stall_s: 3.0", "push_stall_s: 0.0", "dwell.push_stall_s"),
    ] {
        let e = load_err(old, new);
        assert!(e.contains("bad.yaml") && e.contains(key), "{e}");
    }
}

/// Fuzz finding (config_yaml): a huge `log_capacity` validated, then `Supervisor::new` panicked
/// (capacity overflow) or aborted (allocation failure) reserving the log.
#[test]
fn huge_log_capacity_is_rejected_not_allocated() {
    for huge in ["18446744073709551615", "1000000000000", "100001"] {
        let e = load_err("log_capacity: 64", &format!("log_capacity: {huge}"));
        assert!(e.contains("bad.yaml") && e.contains("log_capacity") && e.contains("100000"), "{e}");
    }
    let mut p = SupervisorParams::from_yaml_str(&shipped_text(), "s.yaml").unwrap();
    p.log_capacity = 100_000;
    Supervisor::new(&p, 0.0).expect("the largest capacity builds");
}

#[test]
fn unknown_key_and_bad_policy_are_parse_errors() {
    let e = load_err("log_capacity: 64", "log_capacity: 64\nlog_capacty: 3");
    assert!(e.starts_with("bad.yaml:"), "{e}");
    let e = load_err("policy: intentional_contact", "policy: intentional");
    assert!(e.starts_with("bad.yaml:"), "{e}");
}

/// A follower reproduces the decider's arrangement, switch times, range and weight exactly.
#[test]
fn follower_reproduces_the_deciding_supervisor() {
    for params in [params(), phases_params()] {
        let mut decider = Supervisor::new(&params, 0.0).unwrap();
        let mut follower = Supervisor::new(&params, 0.0).unwrap();
        let mut t = 0.0;
        let mut rng = Rng(3);
        let mut seen = [false; 2]; // released in a hard contact, in the blocked hold
        for k in 0..3000 {
            t += 0.008;
            if k == 500 {
                let _ = decider.request_phase(Phase::Contact);
            }
            // two hard contacts in (b): the first after the push got the goal nearer (a retry
            // follows), the second too soon after it (given up: the blocked hold)
            let fc = if (1500..1800).contains(&k) || (2200..2400).contains(&k) { 8.0 } else { 0.0 };
            let u = input(0.002 * rng.next().abs(), 2.0, fc, 0.3 - 1e-5 * k as f64);
            let a = decider.update(t, &u).clone();
            follower
                .impose(Imposed {
                    mode: a.mode,
                    switch_time_s: a.switch_time_s,
                    sensing_range_m: a.sensing_range_m,
                    fusion_weight_target: a.fusion_weight_target,
                    blocked: decider.blocked(),
                })
                .unwrap();
            let f = follower.update(t, &SupervisorInput::default()).clone();
            assert_eq!(f.mode, a.mode, "cycle {k}");
            assert_eq!(f.task_order(), a.task_order());
            assert_eq!(f.switch_time_s.to_bits(), a.switch_time_s.to_bits());
            assert_eq!(f.sensing_range_m, a.sensing_range_m);
            assert_eq!(follower.releasing(), decider.releasing(), "cycle {k}");
            assert_eq!(follower.blocked(), decider.blocked(), "cycle {k}");
            if follower.releasing() {
                seen[usize::from(f.mode != Mode::HardContact)] = true;
            }
            assert!(
                (f.fusion_weight - a.fusion_weight).abs() < 1e-12,
                "cycle {k}: w {} vs {}",
                f.fusion_weight,
                a.fusion_weight
            );
        }
        assert!(decider.log().total() >= 1, "{:?}: something switched", params.policy);
        if params.policy == Policy::IntentionalContact {
            assert_eq!(seen, [true, true], "a hard contact and the blocked hold followed");
        }
    }
    let mut s = Supervisor::new(&params(), 0.0).unwrap();
    let bad = Imposed {
        mode: Mode::Avoidance,
        switch_time_s: f64::NAN,
        sensing_range_m: 0.1,
        fusion_weight_target: 0.0,
        blocked: None,
    };
    assert!(s.impose(bad).is_err());
}

/// A crawl along an obstacle, faster than ε_v but getting nearer the goal slower than
/// `crawl_speed_mps`, counts as stuck one progress window after it began (and a sixth of a
/// window, the window's step, and the stuck dwell), wherever it begins in a window; the same
/// speed with the goal error falling twice as fast as `crawl_speed_mps` never does.
#[test]
fn a_crawl_without_goal_progress_is_stuck() {
    let p = params();
    let th = p.thresholds;
    let speed = 5.0 * th.speed_mps;
    let mut sup = Supervisor::new(&p, 0.0).unwrap();
    let mut t = 0.0;
    let steps = |s: f64| (s / DT).ceil() as usize;
    // the goal error falls at twice the crawl speed: progress
    let rate = 2.0 * th.crawl_speed_mps;
    assert!(rate < speed, "the goal cannot come nearer faster than the end effector moves");
    for _ in 0..steps(4.5 * th.progress_window_s) {
        t += DT;
        sup.update(t, &input(speed, 3.0, 0.0, 1.0 - rate * t));
        assert_eq!(sup.last_transition(), None, "progress is not a local minimum (t = {t})");
    }
    // then it crawls at the same speed, the goal error falling at half the crawl speed
    let (t0, e0) = (t, 1.0 - rate * t);
    let mut tr = Vec::new();
    // (a window fixed in time would see it only at the end of the next whole window, 1.5 windows)
    for _ in 0..steps(7.0 / 6.0 * th.progress_window_s + p.dwell.stuck_s) + 1 {
        t += DT;
        sup.update(t, &input(speed, 3.0, 0.0, e0 - 0.5 * th.crawl_speed_mps * (t - t0)));
        tr.extend(sup.last_transition());
    }
    assert_eq!(tr.len(), 1, "{tr:?}");
    assert_eq!((tr[0].to, tr[0].cause), (Mode::IntentionalContact, Cause::Stuck));
}
