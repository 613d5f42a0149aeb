//! Skin tests that need the robot model: shipped layouts, torques against finite differences
//! and the model's Jacobian, generator determinism.

use std::path::PathBuf;

use approx::assert_relative_eq;
use nalgebra::{DVector, Isometry3, Matrix6xX, Point3, Vector3};
use skin_core::model::{point_jacobian, update_kinematics, ModelData, RobotModel};
use skin_core::skin::aggregate::{aggregate_patches, FusionParams, PatchWrench};
use skin_core::skin::cell_forces::{cell_contact_forces, cell_repulsion_forces, PointForce};
use skin_core::skin::coverage::coverage;
use skin_core::skin::generate::{generate_layout, GeneratorSpec, LinkSelection, PatchFrame};
use skin_core::skin::layout::{ResolvedLayout, SkinLayout};
use skin_core::skin::params::SkinParams;
use skin_core::skin::signals::{CellReading, ForceReduction};
use skin_core::skin::tiling::Face;
use skin_core::skin::torques::{patch_wrenches_to_torques, point_forces_to_torques};
use skin_core::skin::transforms::{patch_poses_world, patch_wrench_world};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn load(robot: &str) -> (RobotModel, ResolvedLayout, SkinLayout) {
    let model = RobotModel::from_urdf_file(&root().join(format!("urdf/{robot}.urdf"))).unwrap();
    let layout = SkinLayout::load(&root().join(format!("config/skin/{robot}.yaml"))).unwrap();
    let resolved = layout.resolve(&model).unwrap();
    (model, resolved, layout)
}

fn config_q(model: &RobotModel, seed: f64) -> Vec<f64> {
    (0..model.nv()).map(|i| 0.6 * ((i as f64 + 1.0) * 1.3 + seed).sin()).collect()
}

/// World pose of link `frame` at configuration `q`.
fn link_state(model: &RobotModel, data: &mut ModelData, q: &[f64], frame: usize) -> Isometry3<f64> {
    let qd = vec![0.0; model.nv()];
    update_kinematics(model, data, q, &qd).unwrap();
    *data.frame_pose(frame)
}

#[test]
fn shipped_layouts_resolve_with_expected_counts() {
    let (tomm, l, raw) = load("tomm");
    assert!((1000..=1200).contains(&l.num_cells()), "tomm cells: {}", l.num_cells());
    assert_eq!(l.patches().len(), raw.patches.len());
    // Both arms: upper arm, forearm, wrists and palms.
    for side in ["left", "right"] {
        for link in ["upper_arm_link", "forearm_link", "wrist_1_link", "wrist_2_link", "wrist_3_link", "palm"] {
            let name = format!("{side}_{link}");
            let p = l.patches().iter().find(|p| p.link == name).unwrap_or_else(|| panic!("no patch on {name}"));
            assert!(!p.cells.is_empty());
            assert_eq!(Some(p.frame), tomm.frame_index(&name));
        }
    }
    let (_, p7, _) = load("planar7");
    assert_eq!(p7.patches().len(), 7);
    assert!((450..=650).contains(&p7.num_cells()), "planar7 cells: {}", p7.num_cells());
    for p in p7.patches() {
        // Cells facing within the x-y plane (link ±y) on every link.
        let in_plane = |s: f64| p7.cells()[p.cells.clone()].iter().filter(|c| (c.normal_link.y * s) > 0.99).count();
        assert!(in_plane(1.0) >= 3 && in_plane(-1.0) >= 3, "patch {} lacks in-plane cells", p.link);
    }
    for c in l.cells().iter().chain(p7.cells()) {
        assert_relative_eq!(c.normal_link.norm(), 1.0, epsilon = 1e-9);
    }
}

fn spec(links: &[&str], pitch: f64, faces: Vec<(String, Vec<Face>)>) -> GeneratorSpec {
    GeneratorSpec {
        links: links.iter().map(|s| s.parse::<LinkSelection>().unwrap()).collect(),
        pitch_m: pitch,
        faces,
        spheres: false,
        patch_frame: PatchFrame::Primitive,
        ..Default::default()
    }
}

/// Extracts the `skin_layout` command line from a shipped file's header.
fn header_command(text: &str) -> Vec<String> {
    let line = text
        .lines()
        .find(|l| l.trim_start_matches('#').trim().starts_with("skin_layout "))
        .expect("header with the skin_layout command");
    line.trim_start_matches('#').split_whitespace().map(str::to_string).collect()
}

#[test]
fn shipped_layouts_match_the_generator() {
    for robot in ["tomm", "planar7"] {
        let path = root().join(format!("config/skin/{robot}.yaml"));
        let text = std::fs::read_to_string(&path).unwrap();
        let cmd = header_command(&text);
        let arg = |name: &str| cmd.iter().position(|a| a == name).map(|i| cmd[i + 1].clone());
        let links: Vec<String> = arg("--links").unwrap().split(',').map(str::to_string).collect();
        let links: Vec<&str> = links.iter().map(String::as_str).collect();
        let pitch: f64 = arg("--pitch").map(|p| p.parse().unwrap()).unwrap_or(0.025);
        let mut faces = Vec::new();
        for (i, a) in cmd.iter().enumerate() {
            if a == "--faces" {
                let (l, f) = cmd[i + 1].split_once('=').unwrap();
                faces.push((l.to_string(), f.split(',').map(|x| x.parse().unwrap()).collect()));
            }
        }
        assert!(arg("--patch-frame").is_none(), "extend this test");
        let flag = |name: &str| cmd.iter().any(|a| a == name);
        let model = RobotModel::from_urdf_file(&root().join(arg("--urdf").unwrap())).unwrap();
        let spec = GeneratorSpec { spheres: flag("--spheres"), caps: flag("--caps"), ..spec(&links, pitch, faces) };
        let generated = generate_layout(&model, &spec).unwrap();
        let shipped = SkinLayout::load(&path).unwrap();
        assert_eq!(generated.cells.len(), shipped.cells.len(), "{robot}: regenerate the layout");
        assert_eq!(generated.patches.len(), shipped.patches.len());
        for (g, s) in generated.cells.iter().zip(&shipped.cells) {
            assert_eq!((g.id, g.patch), (s.id, s.patch));
            for k in 0..3 {
                assert!((g.position[k] - s.position[k]).abs() < 1e-6 && (g.normal[k] - s.normal[k]).abs() < 1e-6);
            }
        }
    }
}

#[test]
fn generator_rejects_bad_input_and_normals_point_outward() {
    let model = RobotModel::from_urdf_file(&root().join("urdf/planar7.urdf")).unwrap();
    let e = generate_layout(&model, &spec(&["nope"], 0.025, vec![])).unwrap_err().to_string();
    assert!(e.contains("planar7.urdf") && e.contains("nope"), "{e}");
    let e = generate_layout(&model, &spec(&["link1:9"], 0.025, vec![])).unwrap_err().to_string();
    assert!(e.contains("link1") && e.contains('9'), "{e}");
    assert!(generate_layout(&model, &spec(&["link1"], 0.0, vec![])).is_err());
    // Cylinder of link1 lies along link x at y = z = 0: normals radial, outward.
    let l = generate_layout(&model, &spec(&["link1:0"], 0.025, vec![])).unwrap();
    let r = l.resolve(&model).unwrap();
    assert!(!r.cells().is_empty());
    for c in r.cells() {
        let radial = Vector3::new(0.0, c.position_link.y, c.position_link.z);
        assert_relative_eq!(radial.normalize(), c.normal_link, epsilon = 1e-9);
        assert_relative_eq!(radial.norm(), 0.045, epsilon = 1e-9);
    }
}

/// `tau = J_v^T F` against the model's point Jacobian and against finite-difference virtual
/// work `F · dp/dq_j`, on TOMM (prismatic base joints and revolute arm joints).
#[test]
fn cell_torques_match_jacobian_and_virtual_work() {
    let (model, layout, _) = load("tomm");
    let params = SkinParams::load(&root().join("config/skin_model.yaml")).unwrap();
    let mut data = ModelData::new(&model);
    let q = config_q(&model, 0.3);
    let qd = vec![0.0; model.nv()];
    update_kinematics(&model, &mut data, &q, &qd).unwrap();
    // A few cells on different links repelled by an obstacle.
    let mut readings = vec![CellReading::default(); layout.num_cells()];
    let picks: Vec<usize> = (0..layout.num_cells()).step_by(97).collect();
    for (k, &i) in picks.iter().enumerate() {
        readings[i].proximity = 0.4 + 0.05 * k as f64;
    }
    let mut forces = Vec::with_capacity(layout.num_cells());
    cell_repulsion_forces(
        &layout,
        &readings,
        &params.proximity,
        &params.repulsion,
        |f| data.frame_pose(f),
        &mut forces,
    )
    .unwrap();
    assert_eq!(forces.len(), picks.len());
    let mut tau = DVector::zeros(model.nv());
    point_forces_to_torques(&model, &data, &forces, &mut tau);

    let mut expected = DVector::zeros(model.nv());
    let mut jac = Matrix6xX::zeros(model.nv());
    for f in &forces {
        let c = &layout.cells()[f.cell];
        point_jacobian(&model, &data, c.frame, &c.position_link, &mut jac).unwrap();
        expected += jac.fixed_rows::<3>(0).transpose() * f.force;
        // Direction: -normal (world), magnitude K (d_range - d).
        let n_world = data.frame_pose(c.frame).rotation * c.normal_link;
        assert_relative_eq!(f.force.normalize(), -n_world, epsilon = 1e-12);
        let d = params.proximity.distance_m(readings[f.cell].proximity);
        assert_relative_eq!(f.force.norm(), params.repulsion.linear_n(d), epsilon = 1e-12);
    }
    assert_relative_eq!(tau, expected, epsilon = 1e-10);

    // Finite differences of the virtual work.
    let h = 1e-6;
    let mut fd = DVector::zeros(model.nv());
    let mut scratch = ModelData::new(&model);
    for j in 0..model.nv() {
        let (mut qp, mut qm) = (q.clone(), q.clone());
        qp[j] += h;
        qm[j] -= h;
        for f in &forces {
            let c = &layout.cells()[f.cell];
            let pp = link_state(&model, &mut scratch, &qp, c.frame) * Point3::from(c.position_link);
            let pm = link_state(&model, &mut scratch, &qm, c.frame) * Point3::from(c.position_link);
            fd[j] += f.force.dot(&((pp - pm) / (2.0 * h)));
        }
    }
    assert_relative_eq!(tau, fd, epsilon = 1e-6, max_relative = 1e-6);
    assert!(tau.norm() > 1.0, "non-trivial torques");
}

/// Interactive-force-control paper eq. (14) torques of patch wrenches equal the virtual work of force and moment.
#[test]
fn patch_torques_match_virtual_work() {
    let (model, layout, _) = load("tomm");
    let mut data = ModelData::new(&model);
    let q = config_q(&model, 1.1);
    let qd = vec![0.0; model.nv()];
    update_kinematics(&model, &mut data, &q, &qd).unwrap();
    // Asymmetric touch on every patch: first 5 cells of each.
    let mut readings = vec![CellReading::default(); layout.num_cells()];
    for p in layout.patches() {
        for (k, i) in p.cells.clone().take(5).enumerate() {
            readings[i] = CellReading::uniform(0.2 + 0.1 * k as f64, 0.5);
        }
    }
    let fusion = FusionParams { weight_force: 0.5, activity_threshold: 0.01, force_reduction: ForceReduction::Mean };
    let mut wrenches: Vec<PatchWrench> = Vec::new();
    aggregate_patches(&layout, &readings, &fusion, &mut wrenches).unwrap();
    assert!(wrenches.iter().all(|w| w.active_cells == 5));
    let mut tau = DVector::zeros(model.nv());
    patch_wrenches_to_torques(&model, &data, &layout, &wrenches, |_| true, &mut tau);

    let mut poses = Vec::new();
    patch_poses_world(&layout, |f| data.frame_pose(f), |_| true, &mut poses);
    let h = 1e-6;
    let mut fd = DVector::zeros(model.nv());
    let mut scratch = ModelData::new(&model);
    for j in 0..model.nv() {
        let (mut qp, mut qm) = (q.clone(), q.clone());
        qp[j] += h;
        qm[j] -= h;
        for (k, p) in layout.patches().iter().enumerate() {
            let ww = patch_wrench_world(&poses[k], &wrenches[k]);
            let tp = link_state(&model, &mut scratch, &qp, p.frame) * p.link_from_patch;
            let tm = link_state(&model, &mut scratch, &qm, p.frame) * p.link_from_patch;
            let v = (tp.translation.vector - tm.translation.vector) / (2.0 * h);
            // Angular velocity from the rotation difference: R+ R-^T ≈ exp([w] 2h).
            let w = (tp.rotation * tm.rotation.inverse()).scaled_axis() / (2.0 * h);
            fd[j] += ww.force.dot(&v) + ww.moment.dot(&w);
        }
    }
    assert_relative_eq!(tau, fd, epsilon = 1e-6, max_relative = 1e-6);
    assert!(tau.norm() > 1e-3);
}

/// Contact forces: newtons from the inverse characteristic, pointing inward.
#[test]
fn contact_forces_inward_with_newtons() {
    let (model, layout, _) = load("planar7");
    let params = SkinParams::load(&root().join("config/skin_model.yaml")).unwrap();
    let mut data = ModelData::new(&model);
    update_kinematics(&model, &mut data, &config_q(&model, 0.0), &vec![0.0; model.nv()]).unwrap();
    let mut readings = vec![CellReading::default(); layout.num_cells()];
    let i = layout.patches()[3].cells.start + 2;
    readings[i] = CellReading::uniform(params.force.signal(4.0), 0.0);
    let mut out: Vec<PointForce> = Vec::new();
    cell_contact_forces(&layout, &readings, &params.force, &params.fusion, |f| data.frame_pose(f), &mut out).unwrap();
    assert_eq!(out.len(), 1);
    assert_relative_eq!(out[0].force.norm(), 4.0, epsilon = 1e-9);
    let c = &layout.cells()[i];
    let pose = data.frame_pose(c.frame);
    assert_relative_eq!(out[0].force / 4.0, -(pose.rotation * c.normal_link), epsilon = 1e-9);
    assert_relative_eq!(out[0].point, (pose * Point3::from(c.position_link)).coords, epsilon = 1e-12);
}

/// Intentional-contact paper Sec. III needs contacts sensed wherever they happen: every point of
/// a skinned link's collision surface (not buried in another primitive of the link) lies within
/// one cell pitch of a cell that faces it, on every shipped layout (end caps and knuckles
/// included).
#[test]
fn shipped_layouts_have_no_blind_spots() {
    for robot in ["tomm", "planar7"] {
        let path = root().join(format!("config/skin/{robot}.yaml"));
        let cmd = header_command(&std::fs::read_to_string(&path).unwrap());
        let pitch: f64 = cmd.iter().position(|a| a == "--pitch").map(|i| cmd[i + 1].parse().unwrap()).unwrap();
        let (model, layout, _) = load(robot);
        for link in coverage(&model, &layout, pitch) {
            assert!(link.samples > 50, "{robot}: {} sampled too sparsely", link.link);
            assert_eq!(
                link.blind, 0,
                "{robot}: {} has {} of {} surface points farther than {pitch} m from a cell facing them, e.g. {:?} (link frame)",
                link.link, link.blind, link.samples, link.first_blind
            );
        }
    }
}
