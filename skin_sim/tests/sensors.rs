//! The simulated skin and LIDAR measure what the geometry says, and repeat with the seed.

mod common;

use common::{planar7, run, tomm_right_and_base, world};
use nalgebra::{Point3, Vector3};
use skin_sim::World;

/// Index of the cell on `link` whose world normal is closest to `dir`.
fn cell_facing(w: &World, link: &str, dir: Vector3<f64>) -> usize {
    let skin = w.scene().skin.as_ref().unwrap();
    let frame = w.scene().model.frame_index(link).unwrap();
    let sensor = w.skin().unwrap();
    (0..skin.layout.num_cells())
        .filter(|&i| skin.layout.cells()[i].frame == frame)
        .max_by(|&a, &b| {
            let da = sensor.cell_world(w.mj_data(), a).1.dot(&dir);
            let db = sensor.cell_world(w.mj_data(), b).1.dot(&dir);
            da.total_cmp(&db)
        })
        .unwrap()
}

#[test]
fn a_box_along_a_cell_normal_gives_the_proximity_of_its_distance_and_cells_facing_away_read_0() {
    let bare = world(&planar7(""));
    let i = cell_facing(&bare, "link3", Vector3::y());
    let away = cell_facing(&bare, "link3", -Vector3::y());
    let (p, n) = bare.skin().unwrap().cell_world(bare.mj_data(), i);
    let d = 0.05;
    // A thin box, its near face at distance d along the normal, square to it.
    let c = p + n * (d + 0.01);
    let yaw = n.y.atan2(n.x);
    let w = world(&planar7(&format!(
        "objects:\n  - {{name: b, shape: {{box: {{size_m: [0.02, 0.04, 0.04]}}}}, xyz: [{}, {}, {}], rpy: [0, 0, {yaw}]}}\n",
        c.x, c.y, c.z
    )));
    let params = &w.scene().skin.as_ref().unwrap().params;
    let expected = params.proximity.signal(d);
    let got = w.skin_readings()[i].proximity;
    assert!(expected > 0.1);
    assert!((got - expected).abs() < 1e-6, "proximity {got}, expected {expected}");
    assert_eq!(w.skin_readings()[away].proximity, 0.0);
    assert_eq!(w.skin_readings()[i].force, [0.0; 3]);
    // Without the box the cell reads nothing.
    assert_eq!(bare.skin_readings()[i].proximity, 0.0);
}

#[test]
fn a_link_pressed_into_a_fixed_box_gives_force_on_the_cells_near_the_contact_only() {
    // link3 spans x in [0.5, 0.75] with radius 0.037; the box face is 1 cm beside it (+y).
    let mut w = world(&planar7(
        "objects:\n  - {name: b, shape: {box: {size_m: [0.06, 0.1, 0.4]}}, xyz: [0.625, 0.097, 0.0]}\n",
    ));
    let mut cmd = vec![0.0; 7];
    cmd[0] = 0.2;
    w.set_arm_velocity_commands(&cmd).unwrap();
    run(&mut w, 0.4);
    let contact = Point3::new(0.625, 0.047, 0.0);
    let sensor = w.skin().unwrap();
    let mut near_max: f64 = 0.0;
    for (i, r) in w.skin_readings().iter().enumerate() {
        let dist = (sensor.cell_world(w.mj_data(), i).0 - contact).norm();
        if dist > 0.1 {
            assert_eq!(r.force, [0.0; 3], "cell {i} at {dist} m from the contact");
        } else if dist < 0.04 {
            near_max = near_max.max(r.force[0]);
        }
    }
    assert!(near_max > 0.3, "largest force signal near the contact: {near_max}");
    let pressed = w.skin_readings().iter().filter(|r| r.force[0] > 0.0).count();
    assert!((1..=12).contains(&pressed), "{pressed} cells pressed");
    // The touching cells also read full proximity.
    assert!(w.skin_readings().iter().filter(|r| r.force[0] > 0.0).all(|r| r.proximity == 1.0));
}

#[test]
fn a_touch_on_a_link_is_felt_by_the_cells_where_it_enters_and_ramps_with_the_push() {
    // The user pushes link3 (x in [0.5, 0.75], radius 0.037) at its middle along -y: the cells
    // on its +y side, around x = 0.625, feel it; the -y side and other links do not.
    let push = "pushes:\n  - {link: link3, force_n: [0.0, -20.0, 0.0], point_m: [0.125, 0.0, 0.0], start_s: 0.1, end_s: 0.9, ramp_s: 0.2}\n";
    let mut w = world(&planar7(push));
    let entry = Point3::new(0.625, 0.037, 0.0);
    let felt = |w: &World| -> Vec<(f64, f64)> {
        let sensor = w.skin().unwrap();
        (0..w.skin_readings().len())
            .filter(|&i| w.skin_readings()[i].force[0] > 0.0)
            .map(|i| ((sensor.cell_world(w.mj_data(), i).0 - entry).norm(), w.skin_readings()[i].force[0]))
            .collect()
    };
    run(&mut w, 0.05);
    assert!(felt(&w).is_empty(), "nothing before the push");
    run(&mut w, 0.1); // 0.15 s: a quarter of the way up the ramp
    let rising: f64 = felt(&w).iter().map(|c| c.1).sum();
    run(&mut w, 0.25); // 0.4 s: full force
    let full = felt(&w);
    assert!(!full.is_empty(), "the touch is felt");
    assert!(full.iter().all(|&(d, _)| d < 0.07), "only cells near where the force enters: {full:?}");
    let total: f64 = full.iter().map(|c| c.1).sum();
    assert!(rising > 0.0 && rising < total, "the ramp: {rising} then {total}");
    run(&mut w, 0.6); // 1.0 s: after the window
    assert!(felt(&w).is_empty(), "nothing after the push");
}

#[test]
fn the_lidar_measures_a_box_in_the_base_frame_and_never_the_robot() {
    let lidar = "lidar: {rays: 360, range_m: 8.0}\n";
    for (yaw, box_xy) in [(0.0, [2.0, 0.0]), (std::f64::consts::FRAC_PI_2, [0.0, 2.0])] {
        let w = world(&tomm_right_and_base(
            &format!(", base_yaw_joint: {yaw}"),
            &format!(
                "{lidar}objects:\n  - {{name: b, shape: {{box: {{size_m: [0.2, 0.2, 1.0]}}}}, xyz: [{}, {}, 0.5], rpy: [0, 0, {yaw}]}}\n",
                box_xy[0], box_xy[1]
            ),
        ));
        let points = w.lidar().unwrap().points();
        // The box's near face is at 1.9 m ahead of the base, whatever the base's heading.
        assert!(points.iter().any(|p| (p[0] - 1.9).abs() < 1e-6 && p[1].abs() < 1e-6), "yaw {yaw}: {points:?}");
        assert!(points.iter().all(|p| p[0] > 1.9 - 1e-6 && p[1].abs() < 0.1 + 1e-6), "yaw {yaw}: {points:?}");
        assert_eq!(w.lidar().unwrap().ranges().len(), 360);
    }
}

fn noisy_run(seed: u64) -> (Vec<u64>, Vec<u64>) {
    let mut w = world(&tomm_right_and_base(
        "",
        &format!(
            "seed: {seed}\nlidar: {{rays: 90, noise_std_m: 0.01}}\n\
             skin: {{layout: ../skin/tomm.yaml, params: ../skin_model.yaml, proximity_noise_std: 0.02, force_noise_std: 0.02}}\n\
             objects:\n  - {{name: t, shape: {{table: {{top_m: [0.8, 1.2, 0.04], height_m: 0.85}}}}, xyz: [0.95, -0.45, 0]}}\n"
        ),
    ));
    w.set_base_twist([0.05, 0.0, 0.1]);
    run(&mut w, 0.1);
    let skin = w.skin_readings().iter().flat_map(|r| [r.force[0], r.force[2], r.proximity]).map(f64::to_bits).collect();
    let scan = w.lidar().unwrap().ranges().iter().map(|r| r.to_bits()).collect();
    (skin, scan)
}

#[test]
fn two_runs_with_the_same_seed_give_bit_identical_readings() {
    let a = noisy_run(3);
    assert_eq!(a, noisy_run(3));
    assert_ne!(a, noisy_run(4));
}
