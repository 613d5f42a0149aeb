//! A small fixed-seed campaign: one scene of each family (the full campaign is `make campaign`).

use super::*;

#[test]
fn scenes_are_reproducible_from_the_seed() {
    let (a, b) = (scene(7, 5).unwrap(), scene(7, 5).unwrap());
    assert_eq!(a.drawn, b.drawn);
    assert_ne!(a.drawn, scene(8, 5).unwrap().drawn, "another seed draws another scene");
}

#[test]
fn one_scene_per_family_runs_and_is_judged() {
    let (results, summary) = run(1, FAMILIES.len(), 2, None, |_, _| {});
    for r in &results {
        assert!(r.error.is_none(), "scene {} ({}): {:?}", r.id, r.family, r.error);
        assert!(r.verdict.is_some() && r.metrics.is_some());
    }
    assert_eq!(summary.scenes, FAMILIES.len());
    let md = robustness_md(&results, &summary, "robustness");
    assert!(md.contains("| planar_contact | 1 |") && md.contains("](robustness/goals.png)"));
    let dir = std::env::temp_dir().join(format!("skin_campaign_charts_{}", std::process::id()));
    let files = write(&dir, Some(&dir.join("page.md")), &results, &summary).unwrap();
    for name in ["page/goals.png", "page/forces.png"] {
        let f = dir.join(name);
        assert!(files.contains(&f) && std::fs::metadata(&f).unwrap().len() > 10_000, "{name}: a drawn figure");
    }
    assert!(files.contains(&dir.join("page.md")));
    std::fs::remove_dir_all(dir).unwrap();
}

/// The planar family's obstacles slide rather than tip under the arm's push (`μ h < r`, with the
/// family's margin), the second one too: over it, 191 of 238 toppled in twelve seeds of the bare
/// push, and those over the limit itself under a hand's push too.
#[test]
fn planar_obstacles_slide_rather_than_tip() {
    let mut seen = 0;
    for id in (0..400).step_by(FAMILIES.len()) {
        let s = scene(3, id).unwrap();
        for o in s.spec.objects.iter().filter(|o| o.mass_kg.is_some()) {
            let crate::scene::spec::ShapeSpec::Cylinder { radius_m, .. } = o.shape else { panic!("a cylinder") };
            let height = o.xyz[2] - s.spec.floor_z_m;
            assert!(
                o.friction * height <= families::TIP_MARGIN * radius_m + 1e-12,
                "scene {id} {}: mu {} r {radius_m}",
                o.name,
                o.friction
            );
            seen += 1;
        }
    }
    assert!(seen > 100, "{seen} movable obstacles");
}

#[test]
fn a_fixed_obstacle_is_infeasible_and_a_light_slippery_one_feasible() {
    let mut s = scene(1, 0).unwrap();
    s.spec.objects[0].mass_kg = None;
    let pushed = ["obstacle"];
    assert_eq!(families::resistance_n(&s.spec, &pushed), f64::INFINITY);
    s.spec.objects[0].mass_kg = Some(0.5);
    s.spec.objects[0].friction = 0.2;
    assert!((families::resistance_n(&s.spec, &pushed) - 0.981).abs() < 1e-9, "0.98 N of friction");
    s.spec.objects[0].mass_kg = Some(3.0);
    assert!(families::resistance_n(&s.spec, &pushed) > EPS_C_N, "5.9 N of friction");
    assert_eq!(families::resistance_n(&s.spec, &[]), 0.0, "nothing pushed");
}

/// A board tilted by 8° about both of its axes, where an edge of the palm makes the summed skin
/// signal read a force low: the controller regulates the pressed hand cells' newtons
/// (`skin_core::skin::measured`), so MuJoCo's force settles at the reference, and the first
/// touch stays within 2 N of it. With the even-press signal reference of before, such boards
/// peaked at 6-9 N over the reference (campaign seed 1).
#[test]
fn on_a_tilted_board_the_hand_holds_the_reference_in_newtons_without_impact() {
    for tilt_deg in [[8.0, 8.0], [-8.0, 8.0], [8.0, -8.0]] {
        let mut s = scene(1, 2).unwrap();
        let r = &mut s.spec.force_references[0];
        (r.mean_n, r.amplitude_n) = (5.0, 0.0);
        let rpy = [0.0, f64::to_radians(tilt_deg[0]), f64::to_radians(tilt_deg[1])];
        families::tilt_about(&mut s.spec.objects[0], families::PALM_HEIGHT_M, rpy);
        s.spec.base_motions.clear();
        s.spec.duration_s = 30.0;
        let text = serde_json::to_string(&s.spec).unwrap();
        let dir = s.target.scene.parent().unwrap();
        let scene = Scene::from_yaml_str(&text, "tilted board", dir).unwrap();
        let report = s.target.run_scene(scene, |_| {}).unwrap();
        let v = judge(&report);
        assert!(v.violations.is_empty(), "tilt {tilt_deg:?}: {:?}", v.violations);
        let overshoot = v.first_contact_overshoot_n.unwrap();
        assert!(overshoot <= 2.0, "tilt {tilt_deg:?}: first touch {overshoot} N over the reference");
        let last: Vec<f64> = report.record.cycles.iter().filter(|c| c.t_s >= 25.0).map(|c| c.hand_force_n).collect();
        let mean = last.iter().sum::<f64>() / last.len() as f64;
        assert!((mean - 5.0).abs() < 0.2, "tilt {tilt_deg:?}: {mean} N over the last 5 s for 5 N");
    }
}

#[test]
fn failure_classes_drop_details_and_values_only() {
    assert_eq!(failure_class("Table 3 force error exceeded"), "Table 3 force error exceeded");
    assert_eq!(failure_class("first-contact overshoot 2.31 N"), "first-contact overshoot");
    assert_eq!(failure_class("safety: chatter: one switch 3 times"), "safety");
    assert_eq!(failure_class("goal not reached (feasible)"), "goal not reached (feasible)");
}
