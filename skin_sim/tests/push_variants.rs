//! Issue 17 item 2: a push that cannot succeed ends safely. A family of variants of the
//! shipped `intentional_contact` scene, generated here (not shipped scene files): the obstacle
//! fixed, heavier (1-1.5 kg) or too heavy to slide under eps_c (2 and 3 kg: friction 3.9 /
//! 5.9 N plus the push to start it), or moved by 5-10 cm. Every run must be safe by the shared definition
//! (`skin_sim::outputs::safety::violations`: no non-finite command, safe-stop, joint over its velocity
//! limit, contact over eps_c for more than 0.5 s in one event, chatter) and end `reached` or
//! `blocked`; the fixed obstacle must end `blocked` after a single (b) -> (c).

use skin_core::supervisor::{Mode, SupervisorParams};
use skin_sim::outputs::outcome;
use skin_sim::outputs::report::RunReport;
use skin_sim::outputs::safety;
use skin_sim::run::runner::RunTarget;
use skin_sim::run::scenario;
use skin_sim::scene::spec::{ExpectSpec, PersonSpec, WaypointSpec};
use skin_sim::Scene;

/// Runs the shipped scene changed by `change`.
fn run_variant(change: impl FnOnce(&mut Scene)) -> RunReport {
    let target = RunTarget::from(scenario::find("intentional_contact").expect("the scenario"));
    let mut scene = Scene::load(&target.scene).expect("the shipped scene");
    change(&mut scene);
    target.run_scene(scene, |_| {}).expect("the variant runs")
}

/// The shipped scene's `expect:`.
fn shipped_expect() -> ExpectSpec {
    let target = RunTarget::from(scenario::find("intentional_contact").unwrap());
    Scene::load(&target.scene).unwrap().spec.expect.expect("the shipped scene declares its outcome")
}

fn outcome(r: &RunReport) -> &'static str {
    r.metrics.goal.as_ref().expect("goal metrics").outcome
}

fn assert_no_violations(name: &str, r: &RunReport) {
    let v = safety::violations(&r.metrics.safety, r.metrics.faulted_cycles);
    assert!(v.is_empty(), "{name}: {v:?}; switches {:?}", r.record.switches);
}

fn assert_safe(name: &str, r: &RunReport) {
    assert_no_violations(name, r);
    let o = outcome(r);
    assert!(o == "reached" || o == "blocked", "{name}: outcome {o}");
}

fn hard_contacts_from_b(r: &RunReport) -> usize {
    r.record.switches.iter().filter(|s| (s.from, s.to) == (Mode::IntentionalContact, Mode::HardContact)).count()
}

#[test]
fn a_fixed_obstacle_is_pushed_at_most_twice_then_the_arm_holds_blocked() {
    let r = run_variant(|s| {
        s.spec.objects[0].mass_kg = None; // welded to the world
        s.spec.pushes.clear(); // a push needs a movable object
    });
    assert_safe("fixed", &r);
    assert_eq!(outcome(&r), "blocked", "switches {:?}", r.record.switches);
    // The first push's progress includes its approach, so it may be retried once; a retry
    // within `retry_interval_s` of a hard contact is never made (docs/supervisor.md).
    let n = hard_contacts_from_b(&r);
    assert!((1..=2).contains(&n), "at most two pushes, no (b) <-> (c) cycle: {:?}", r.record.switches);
    let last = r.record.cycles.last().unwrap();
    assert_eq!(last.mode, Mode::Avoidance, "held in (a)");
    // Settled: once held and backed off (avoidance's sensing range restored from the push's 0 to
    // nominal, plus the 0.5 s of the switch's blend), the arm touches nothing over eps_c and
    // stands still.
    let sup = SupervisorParams::load(&skin_sim::scene::config_dir().join("supervisor.yaml")).unwrap();
    let back_off = sup.sensing_range.nominal_m / sup.sensing_range.restore_rate_mps + 0.5;
    let held = r.metrics.goal.as_ref().unwrap().blocked_at_s + back_off;
    let after: Vec<_> = r.record.cycles.iter().filter(|c| c.t_s >= held).collect();
    assert!(after.len() > 1000, "held for {} cycles", after.len());
    let eps_c = r.metrics.goal.as_ref().unwrap().eps_c_n;
    assert!(after.iter().all(|c| c.link_force_n < eps_c), "contact over eps_c while held");
    let speed = after.iter().map(|c| c.signals.ee_speed_mps).fold(0.0, f64::max);
    assert!(speed < 0.05, "the held arm moves at {speed} m/s");
    // Judged as the shipped scene declares (goal within 1 cm) it fails; a scene that declares its
    // goal may be unreachable (`expect: {safety: true, ...}`) passes blocked and safe.
    assert!(!r.passed(), "the goal is not reached");
    let unreachable = ExpectSpec { safety: true, ..shipped_expect() };
    let checks = outcome::checks(&r.metrics, Some(&unreachable));
    assert!(checks.iter().all(|c| c.passed), "{checks:?}");
}

/// 1-3 kg (friction 2-5.9 N): every one ends safe, with at most two pushes that reach eps_c (a
/// retry of a push that made progress). An arm that had its goal when the scripted push at 15 s
/// threw the obstacle into it may end dodging the thrown obstacle in (a), not blocked (2 kg: the
/// goal within 0.9 mm at 15 s, both hard contacts hits at the goal, 17.8 mm off at 20 s).
#[test]
fn heavier_obstacles_end_safely() {
    for kg in [1.0, 1.5, 2.0, 3.0] {
        let r = run_variant(|s| s.spec.objects[0].mass_kg = Some(kg));
        let name = format!("{kg} kg");
        let goal = r.metrics.goal.as_ref().expect("goal metrics");
        let had_goal = goal.goal_error_before_pushes_m <= goal.goal_tolerance_m; // NaN (no push): false
        if had_goal {
            assert_no_violations(&name, &r);
        } else {
            assert_safe(&name, &r);
        }
        assert!(hard_contacts_from_b(&r) <= 2, "{kg} kg: {:?}", r.record.switches);
    }
}

#[test]
fn a_shifted_obstacle_ends_safely() {
    for (dx, dy) in [(0.05, 0.0), (-0.05, 0.0), (0.0, 0.05), (0.07, 0.07), (-0.1, 0.0)] {
        let r = run_variant(|s| {
            s.spec.objects[0].xyz[0] += dx;
            s.spec.objects[0].xyz[1] += dy;
        });
        assert_safe(&format!("obstacle moved by ({dx}, {dy}) m"), &r);
    }
}

#[test]
fn the_shipped_movable_obstacle_is_still_pushed_to_the_goal() {
    let r = run_variant(|_| {});
    assert_safe("shipped", &r);
    assert_eq!(outcome(&r), "reached");
    let goal = r.metrics.goal.as_ref().unwrap();
    assert!(goal.reached_before_pushes(), "by the push at 15 s: {} m before it", goal.goal_error_before_pushes_m);
}

/// A controller setup in `dir` that is the shipped planar7 one with `config/supervisor.yaml`'s
/// text changed by `changes` (each `(from, to)`, `from` must be there).
fn setup_with_supervisor(dir: &std::path::Path, changes: &[(&str, &str)]) -> std::path::PathBuf {
    let config = skin_sim::scene::config_dir();
    let mut supervisor = std::fs::read_to_string(config.join("supervisor.yaml")).unwrap();
    for (from, to) in changes {
        assert!(supervisor.contains(from), "config/supervisor.yaml has `{from}`");
        supervisor = supervisor.replace(from, to);
    }
    std::fs::write(dir.join("supervisor.yaml"), supervisor).unwrap();
    let setup = std::fs::read_to_string(config.join("controller/planar7.yaml")).unwrap();
    let anchored = setup.replace(": ../", &format!(": {}/../", config.join("controller").display()));
    let setup = anchored.replace(
        &format!("supervisor: {}/../supervisor.yaml", config.join("controller").display()),
        &format!("supervisor: {}", dir.join("supervisor.yaml").display()),
    );
    assert!(setup.contains(&dir.display().to_string()), "the setup names the changed supervisor");
    let path = dir.join("planar7.yaml");
    std::fs::write(&path, setup).unwrap();
    path
}

/// Done-when of issue 17: removing contact reaction (intentional-contact paper eq. (6)) from
/// the arrangements makes a check fail. At 15 s the arm rests at its goal in Table I (b) (the
/// obstacle in range, the sensing range shrunk to 0: no avoidance); a person walks into `link5`
/// broadside and stops 5 cm past its surface. Eq. (6), first in (c), makes the pressed link give
/// way: the peak contact stays under 10 `ε_c` (35 N measured). Without it the goal holds the arm
/// where the person is going: 117 N. (The scripted shove of the campaign's seed 1 scene 176 showed
/// it before; it no longer does since the simulated skin reads a link's contact with one object as
/// their net force, `docs/scenes.md`.)
#[test]
fn removing_contact_reaction_lets_a_person_press_the_held_arm() {
    let walker = |s: &mut Scene| {
        // link5 at the goal posture runs from (0.776, 0.108) to (0.898, -0.111); outward normal
        // (0.876, 0.488); the person's radius 0.2 m, the link's 0.033 m.
        let path = [(0.0, [2.5, 1.5]), (14.0, [2.5, 1.5]), (15.0, [1.172, 0.185]), (16.5, [0.997, 0.088])];
        s.spec.persons.push(PersonSpec {
            name: "walker".into(),
            radius_m: 0.2,
            height_m: 1.7,
            path: path.map(|(t_s, xy_m)| WaypointSpec { t_s, xy_m }).to_vec(),
        });
        s.spec.expect = Some(ExpectSpec { max_contact_force_n: Some(50.0), ..ExpectSpec::default() });
    };
    let peak = "peak contact force (outside pushes)";
    let passed = |r: &RunReport| r.checks.iter().find(|c| c.name == peak).expect("the declared check").passed;
    let with = run_variant(walker);
    assert!(passed(&with), "with contact reaction: {} N", with.metrics.goal.as_ref().unwrap().max_contact_force_n);

    let dir = std::env::temp_dir().join(format!("skin_sim_no_reaction_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let no_reaction = [
        ("avoidance: [avoidance, goal, contact_reaction]", "avoidance: [avoidance, goal]"),
        ("intentional_contact: [goal, contact_reaction, avoidance]", "intentional_contact: [goal, avoidance]"),
        ("hard_contact: [contact_reaction, goal, avoidance]", "hard_contact: [goal, avoidance]"),
    ];
    let target = RunTarget {
        controller: setup_with_supervisor(&dir, &no_reaction),
        ..RunTarget::from(scenario::find("intentional_contact").unwrap())
    };
    let mut scene = Scene::load(&target.scene).unwrap();
    walker(&mut scene);
    let without = target.run_scene(scene, |_| {}).unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
    assert!(!passed(&without), "without: {} N", without.metrics.goal.as_ref().unwrap().max_contact_force_n);
}

/// A push through the stick-slip peaks of an obstacle that slides (`docs/supervisor.md`, "Strikes
/// of a push that gives way"): in campaign planar seed 4 scene 84 (4.14 N of friction, under the
/// push force of 4.5 N the push holds; scene 140 showed it until its friction was held under the
/// tipping limit, `families::TIP_MARGIN`) the pressed link's force strikes eps_c again within
/// `hard_contact_repeat_s`, each strike a skin sample or two, while the link advances into the
/// obstacle. The push goes on and reaches the goal before the scripted shove; told that no
/// contact gives way (`give_way_speed_mps` out of reach), the supervisor takes the strikes for a
/// hard contact and gives the push up.
#[test]
fn strikes_of_an_obstacle_that_slides_do_not_end_the_push() {
    let scene = skin_sim::campaign::scene(4, 84).unwrap();
    assert!(scene.feasible, "the obstacle slides under eps_c");
    let verdict = |r: skin_sim::campaign::SceneResult| r.verdict.expect("the scene runs");
    let v = verdict(skin_sim::campaign::run_scene(&scene, None));
    assert!(v.violations.is_empty() && v.goal_reached == Some(true), "shipped: {v:?}");

    let dir = std::env::temp_dir().join(format!("skin_sim_no_give_way_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let rigid = [("give_way_speed_mps: 0.005", "give_way_speed_mps: 1.0")];
    let rigid = skin_sim::campaign::scene(4, 84).unwrap().with_controller(setup_with_supervisor(&dir, &rigid));
    let v = verdict(skin_sim::campaign::run_scene(&rigid, None));
    std::fs::remove_dir_all(&dir).unwrap();
    assert_eq!(v.goal_reached, Some(false), "every strike a hard contact: {v:?}");
}
