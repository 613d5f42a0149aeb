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
    let (results, summary) = run(1, FAMILIES.len(), None, 2, |_, _| {});
    for r in &results {
        assert!(r.error.is_none(), "scene {} ({}): {:?}", r.id, r.family, r.error);
        assert!(r.verdict.is_some() && r.metrics.is_some());
    }
    assert_eq!(summary.scenes, FAMILIES.len());
    assert!(robustness_md(&results, &summary).contains("| planar_contact | 1 |"));
}

#[test]
fn a_fixed_obstacle_is_infeasible_and_a_light_slippery_one_feasible() {
    let mut s = scene(1, 0).unwrap();
    s.spec.objects[0].mass_kg = None;
    let pushed = ["obstacle"];
    assert!(!families::feasible(&s.spec, EPS_C_N, &pushed));
    s.spec.objects[0].mass_kg = Some(0.5);
    s.spec.objects[0].friction = 0.2;
    assert!(families::feasible(&s.spec, EPS_C_N, &pushed), "0.98 N of friction");
    s.spec.objects[0].mass_kg = Some(3.0);
    assert!(!families::feasible(&s.spec, EPS_C_N, &pushed), "5.9 N of friction");
}

#[test]
fn a_family_filter_keeps_that_family_s_scenes_of_the_campaign() {
    let force = family("force_tracking").unwrap();
    assert_eq!(scene_ids(12, Some(force)), [2, 6, 10], "the same scene ids as in the whole campaign");
    assert_eq!(scene_ids(3, None), [0, 1, 2]);
    assert!(family("force").unwrap_err().contains("force_tracking"), "the error lists the names");
}
