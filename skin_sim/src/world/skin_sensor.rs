//! Simulated skin: per cell, the proximity sensor as a ray along the cell's outward normal and
//! the three force sensors from the MuJoCo contacts near the cell, both through the cell
//! characteristics of `config/skin_model.yaml` (interactive-force-control paper Sec. 2.3: normalized, nonlinear).
//!
//! - Proximity: a ray from the cell's world position along its outward normal, testing only
//!   objects and persons (`crate::world::mjcf::SENSED_GROUPS`: the robot never sees itself) near the
//!   ray (`ProximityRays`); the hit distance goes through `p(d)` (0 from the sensor range on).
//!   A cell in contact reads 1.
//! - Force: the contacts of one robot geom with one other geom give their summed normal force
//!   (`mj_contactForce`), which the cells of the touched body share in proportion to how deep the
//!   other geom presses into each cell's face (`CellFace::compression`: the soft cover's
//!   pressure integrated over the cell); the cells' normal loads balance the force
//!   (`SkinSensor::distribute`), and each load in newtons goes through `f(F)` on all
//!   three sensors. MuJoCo's contact points do not decide the split: it reports a flat contact
//!   between boxes as corners or, tilted by a hundredth of a radian, as one edge, and split by
//!   distance to those points a flat palm's load jumped between 8 and 3 cells. When no face is
//!   pressed (a corner or an edge of the geom between sample points), the cells within
//!   `contact_radius_m` of the box spanned by the contact points share it, weighted by that
//!   distance and by how squarely they face the force.
//! - Touches: a scripted push on a robot link (the scene's user, `pushes:` with `link:`) is felt
//!   like a contact by the cells where its line of action enters the link: the cells facing the
//!   force within [`TOUCH_RADIUS_M`] of that line (on the side the force comes from) share it as
//!   they share a contact (the user's hand is no MuJoCo geom; the push acts through
//!   `xfrc_applied`).
//! - Optional zero-mean Gaussian noise on every signal (seeded), then clamped to [0, 1].

use std::ops::Range;

use mujoco_rs::prelude::*;
use mujoco_rs::wrappers::mj_model::traits::ModelType;
use nalgebra::{Point3, Vector3};
use skin_core::skin::characteristic::{PreparedForce, PreparedProximity};
use skin_core::skin::signals::CellReading;

use crate::scene::Scene;
use crate::world::cell_face::CellFace;
use crate::world::contact_patches::{self, ContactPatch};
use crate::world::frames::{body_pose, FrameRef};
use crate::world::noise::Noise;
use crate::world::proximity_rays::ProximityRays;

/// One cell in its MuJoCo body's frame.
#[derive(Debug, Clone, Copy)]
struct SimCell {
    body: usize,
    position: Point3<f64>,
    normal: Vector3<f64>,
    face: CellFace,
    active: bool,
}

/// The skin of a [`crate::world::World`]; readings are indexed like the scene layout's cells.
#[derive(Debug, Clone)]
pub struct SkinSensor {
    cells: Vec<SimCell>,
    /// Cell indices ordered by body, and each MuJoCo body's range in that order.
    by_body: Vec<usize>,
    body_range: Vec<Range<usize>>,
    /// Per MuJoCo body: the sphere (center in the body frame, radius) holding its cells.
    body_sphere: Vec<(Point3<f64>, f64)>,
    proximity: PreparedProximity,
    rays: ProximityRays,
    force: PreparedForce,
    contact_radius_m: f64,
    proximity_noise_std: f64,
    force_noise_std: f64,
    noise: Noise,
    /// Scratch: normal force per cell \[N\].
    force_n: Vec<f64>,
    /// Scratch: the proximity ray's hit distance per cell, None when nothing is within range \[m\].
    distance_m: Vec<Option<f64>>,
    /// Scratch: this sample's contacts, one per pair of touching geoms.
    patches: Vec<ContactPatch>,
    /// Scratch: weight of each cell of one body (in `by_body` order) in a patch's split.
    weights: Vec<f64>,
    readings: Vec<CellReading>,
}

/// A scripted touch of the scene's user on a robot body, at the current state.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Touch {
    /// MuJoCo body pressed.
    pub body: usize,
    /// A point on the force's line of action (world) \[m\].
    pub point: Point3<f64>,
    /// Force on the body (world) \[N\].
    pub force: Vector3<f64>,
}

/// Radius of the user's hand: cells this close to a touch's line of action share its force \[m\].
pub const TOUCH_RADIUS_M: f64 = 0.05;

/// A sphere holding `points`: their centroid and the largest distance from it (zero radius at
/// the origin for none).
fn bounding_sphere(points: impl Iterator<Item = Point3<f64>> + Clone) -> (Point3<f64>, f64) {
    let n = points.clone().count().max(1) as f64;
    let center = Point3::from(points.clone().fold(Vector3::zeros(), |s, p| s + p.coords) / n);
    (center, points.map(|p| (p - center).norm()).fold(0.0, f64::max))
}

/// Noise stream of the skin (see [`Noise::new`]).
const NOISE_STREAM: u64 = 1;

impl SkinSensor {
    /// The skin of `scene` (None when it has none) on the MuJoCo model generated from it.
    pub(crate) fn new(scene: &Scene, mj: &MjModel) -> Option<Self> {
        let (skin, spec) = (scene.skin.as_ref()?, scene.spec.skin.as_ref()?);
        let cells: Vec<SimCell> = skin
            .layout
            .cells()
            .iter()
            .zip(&skin.active)
            .map(|(c, &active)| {
                let f = FrameRef::new(&scene.model, mj, c.frame);
                let (position, normal) = (f.placement * Point3::from(c.position_link), f.placement * c.normal_link);
                SimCell {
                    body: f.body,
                    position,
                    normal,
                    face: CellFace::new(position, normal, spec.cell_radius_m),
                    active,
                }
            })
            .collect();
        let mut by_body: Vec<usize> = (0..cells.len()).collect();
        by_body.sort_by_key(|&i| cells[i].body);
        let nbody = mj.ffi().nbody as usize;
        let body_range = (0..nbody)
            .map(|b| {
                let start = by_body.partition_point(|&i| cells[i].body < b);
                let end = by_body.partition_point(|&i| cells[i].body <= b);
                start..end
            })
            .collect::<Vec<_>>();
        let body_sphere =
            body_range.iter().map(|r| bounding_sphere(by_body[r.clone()].iter().map(|&i| cells[i].position))).collect();
        let n = cells.len();
        Some(SkinSensor {
            cells,
            by_body,
            body_range,
            body_sphere,
            proximity: skin.params.proximity.prepared(),
            rays: ProximityRays::new(mj, skin.params.proximity.range_m),
            force: skin.params.force.prepared(),
            contact_radius_m: spec.contact_radius_m,
            proximity_noise_std: spec.proximity_noise_std,
            force_noise_std: spec.force_noise_std,
            noise: Noise::new(scene.spec.seed, NOISE_STREAM),
            force_n: vec![0.0; n],
            distance_m: vec![None; n],
            patches: Vec::new(),
            weights: Vec::new(),
            readings: vec![CellReading::default(); n],
        })
    }

    /// The last sample, indexed like the layout's cells (inactive cells read 0).
    pub fn readings(&self) -> &[CellReading] {
        &self.readings
    }

    /// World position and outward unit normal of cell `i` at the data's current kinematics.
    pub fn cell_world<M: ModelType>(&self, data: &MjData<M>, i: usize) -> (Point3<f64>, Vector3<f64>) {
        let c = &self.cells[i];
        let pose = body_pose(data, c.body);
        (pose * c.position, pose * c.normal)
    }

    /// Samples every active cell from the data's current kinematics, contacts and `touches`.
    pub(crate) fn sample<M: ModelType>(&mut self, data: &mut MjData<M>, touches: impl Iterator<Item = Touch>) {
        self.contact_forces(data);
        for t in touches {
            self.distribute_touch(data, &t);
        }
        self.cast_rays(data);
        for i in 0..self.cells.len() {
            if !self.cells[i].active {
                continue;
            }
            let f = self.force_n[i];
            let p = if f > 0.0 { 1.0 } else { self.distance_m[i].map_or(0.0, |d| self.proximity.signal(d)) };
            let force = self.force.signal(f);
            let mut reading = CellReading { force: [force; 3], proximity: p };
            for s in &mut reading.force {
                *s = (*s + self.noise.gaussian(self.force_noise_std)).clamp(0.0, 1.0);
            }
            reading.proximity = (reading.proximity + self.noise.gaussian(self.proximity_noise_std)).clamp(0.0, 1.0);
            self.readings[i] = reading;
        }
    }

    /// Fills `distance_m` for the active cells not in contact, body by body, in the body's frame:
    /// a body with no sensed geom near its cells casts no ray ([`ProximityRays::select_near`]).
    fn cast_rays<M: ModelType>(&mut self, data: &mut MjData<M>) {
        self.distance_m.fill(None);
        for b in 0..self.body_range.len() {
            let cells = self.body_range[b].clone();
            if cells.is_empty() {
                continue;
            }
            let pose = body_pose(data, b);
            let (center, radius) = self.body_sphere[b];
            if !self.rays.select_near(data, &pose, center, radius) {
                continue;
            }
            for &i in &self.by_body[cells] {
                let c = &self.cells[i];
                let in_contact = self.force_n[i] > 0.0;
                if c.active && !in_contact {
                    self.distance_m[i] = self.rays.cast(data, &pose, c.position, c.normal);
                }
            }
        }
    }

    /// Fills `force_n` with each cell's share of the normal contact forces on the robot. MuJoCo
    /// reports a flat contact between two boxes as the corners of the touching area, so the
    /// contacts of one robot body with one other geom are taken together ([`contact_patches`]):
    /// their summed force is shared by the cells near the box spanned by their points (a flat
    /// palm on a board: every palm cell; an edge: the cells along it; one point: the cells around
    /// it).
    fn contact_forces<M: ModelType>(&mut self, data: &MjData<M>) {
        self.force_n.fill(0.0);
        contact_patches::collect(data, &mut self.patches);
        for k in 0..self.patches.len() {
            let p = self.patches[k];
            self.distribute(data, &p);
        }
    }

    /// Splits the patch's force (world, acting on its robot body) over the body's cells: by the
    /// compression of their faces, or, with none compressed, by distance to the contact points.
    ///
    /// A cell is a rigid plate whose force sensors read the load normal to it. The loads `N_i` are
    /// proportional to the weights and balance the contact force: `‖Σ N_i n_i‖ = |F|`. A flat
    /// palm reads `|F|` in total; two cells meeting at 45° under a contact on their common edge
    /// each read `0.71 |F|`, as plates there would. Balanced only along the force's direction,
    /// the cells of a small cap (planar7's fingertip, 60-90° apart) pressed on one side read up
    /// to twice the force (`docs/supervisor.md`, "The simulated skin reads a fingertip contact").
    fn distribute<M: ModelType>(&mut self, data: &MjData<M>, patch: &ContactPatch) {
        let range = self.body_range[patch.body].clone();
        let pose = body_pose(data, patch.body);
        let local_f = pose.inverse_transform_vector(&patch.force);
        let Some(u) = local_f.try_normalize(0.0) else { return };
        let facing = |c: &SimCell| -u.dot(&c.normal);
        let cells = &self.cells;
        let compression = |i: usize| {
            if facing(&cells[i]) > 0.0 {
                cells[i].face.compression(data, &pose, patch.other)
            } else {
                0.0
            }
        };
        self.weights.clear();
        self.weights.extend(self.by_body[range.clone()].iter().map(|&i| compression(i)));
        if self.weights.iter().sum::<f64>() <= 0.0 {
            let r = self.contact_radius_m;
            // distance from a world point to the patch's box (world axes)
            let to_patch = |w: Point3<f64>| (w - w.sup(&patch.min).inf(&patch.max)).norm();
            // Near cells facing the force share it, squarely facing ones more: cells at right
            // angles to it (a palm's rim under a flat contact) take none.
            let weight = |c: &SimCell| (1.0 - to_patch(pose * c.position) / r).max(0.0) * facing(c).max(0.0);
            self.weights.clear();
            self.weights.extend(self.by_body[range.clone()].iter().map(|&i| weight(&cells[i])));
        }
        self.share(range, local_f.norm());
    }

    /// A touch's force shared by the cells of its body near its line of action (see the module
    /// doc), as [`Self::distribute`] shares a contact's.
    fn distribute_touch<M: ModelType>(&mut self, data: &MjData<M>, touch: &Touch) {
        let Some(range) = self.body_range.get(touch.body).cloned() else { return };
        let pose = body_pose(data, touch.body);
        let Some(u) = pose.inverse_transform_vector(&touch.force).try_normalize(0.0) else { return };
        let point = pose.inverse_transform_point(&touch.point);
        let weight = |c: &SimCell| {
            let d = c.position - point;
            let along = d.dot(&u);
            let off_line = (d - u * along).norm();
            // before the point along the force (where it comes from), facing it
            if along > 0.0 {
                0.0
            } else {
                (1.0 - off_line / TOUCH_RADIUS_M).max(0.0) * (-u.dot(&c.normal)).max(0.0)
            }
        };
        self.weights.clear();
        self.weights.extend(self.by_body[range.clone()].iter().map(|&i| weight(&self.cells[i])));
        self.share(range, touch.force.norm());
    }

    /// Adds `magnitude` to the cells of `range` (by-body order) in proportion to `self.weights`,
    /// scaled so that the cells' normal loads balance it: `‖Σ N_i n_i‖ = |F|`.
    fn share(&mut self, range: Range<usize>, magnitude: f64) {
        let cells = &self.cells;
        let normals: Vector3<f64> =
            self.by_body[range.clone()].iter().zip(&self.weights).map(|(&i, w)| cells[i].normal * *w).sum();
        let balance = normals.norm(); // ‖Σ w_i n_i‖
        if balance <= 0.0 {
            return; // no skin there facing the force
        }
        let scale = magnitude / balance;
        for (&i, w) in self.by_body[range].iter().zip(&self.weights) {
            self.force_n[i] += w * scale;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::world::mjcf::ROBOT_GROUP;
    use crate::world::mjcf::SENSED_GROUPS;
    use crate::World;
    use mujoco_rs::mujoco_c;
    use nalgebra::Isometry3;

    /// Culling by body, in the body's frame, changes no reading: every cell's proximity distance
    /// is the one `mj_ray` reads along its normal when within range, over the motion of scenes
    /// whose hand nears a board, a wall and a table while the base turns.
    #[test]
    fn the_body_culled_rays_read_what_mj_ray_reads() {
        let (mut hits, mut culled) = (0, 0);
        for name in ["force_tracking_base_motion", "poster_phrc", "tomm_movable_obstacles"] {
            let file = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("../config/scenes/{name}.yaml"));
            let mut world = World::from_scene_file(&file).unwrap();
            world.set_base_twist([0.05, 0.0, 0.2]);
            for _ in 0..6 {
                for _ in 0..250 {
                    world.step();
                }
                let mut data = world.mj_data().clone();
                let mut sensor = world.skin().unwrap().clone();
                let range_m = world.scene().skin.as_ref().unwrap().params.proximity.range_m;
                sensor.contact_forces(&data);
                sensor.cast_rays(&mut data);
                for i in 0..sensor.cells.len() {
                    let (p, n) = sensor.cell_world(&data, i);
                    let in_contact = sensor.force_n[i] > 0.0;
                    let (hit, d) = data.ray(&p.into(), &n.into(), Some(&SENSED_GROUPS), true, None, None);
                    let seen = hit.map(|_| d).filter(|&d| d < range_m);
                    let expected = seen.filter(|_| sensor.cells[i].active && !in_contact);
                    assert_eq!(sensor.distance_m[i], expected, "{name}: cell {i} at {} s", world.time());
                    hits += usize::from(expected.is_some());
                    let world_frame = Isometry3::identity();
                    culled += usize::from(!sensor.rays.select_near(&data, &world_frame, p, 0.0));
                }
            }
        }
        assert!(hits > 100 && culled > 0, "the scenes must both hit and cull: {hits} hits, {culled} culled");
    }

    /// The shipped planar scene's world.
    fn planar_scene() -> World {
        let file = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../config/scenes/intentional_contact.yaml");
        World::from_scene_file(&file).unwrap()
    }

    /// The world's state with the obstacle's centre at `at` in `link7`'s frame, forwarded.
    fn obstacle_at(world: &World, at: Point3<f64>) -> MjData<Box<MjModel>> {
        let model = world.mj_model();
        let [tip, obstacle] = ["link7", "obstacle"].map(|n| model.name_to_id(MjtObjBase::mjOBJ_BODY, n).unwrap());
        let qpos = model.jnt_qposadr()[model.body_jntadr()[obstacle] as usize] as usize;
        let mut data = world.mj_data().clone();
        let at = body_pose(&data, tip) * at;
        data.qpos_mut()[qpos..qpos + 3].copy_from_slice(&[at.x, at.y, at.z]);
        data.forward();
        data
    }

    /// The cells' normal loads balance the force of a contact: `‖Σ N_i n_i‖ = |F|` for every body
    /// pressed by one geom, with planar7's fingertip pressed by a cylinder from 24 directions,
    /// among them contacts where a balance along the force alone (`Σ N_i (−n_i · u) = |F|`)
    /// differs by more than 10 %.
    #[test]
    fn the_loads_of_a_contact_balance_its_force() {
        let world = planar_scene();
        let mut sensor = world.skin().unwrap().clone();
        let (mut checked, mut asymmetric) = (0, 0);
        for k in 0..24 {
            // the fingertip sphere (radius 0.021 m at x = 0.25 m of link7), the cylinder's side 2 mm into it
            let phi = k as f64 * std::f64::consts::TAU / 24.0;
            let reach = 0.1 + 0.021 - 0.002;
            let data = obstacle_at(&world, Point3::new(0.25 + phi.cos() * reach, phi.sin() * reach, 0.0));
            sensor.contact_forces(&data);
            for p in &sensor.patches {
                if sensor.patches.iter().filter(|q| q.body == p.body).count() > 1 {
                    continue; // loads of two contacts add up on one body
                }
                let pose = body_pose(&data, p.body);
                let u = p.force.normalize();
                let (mut sum, mut along) = (Vector3::zeros(), 0.0);
                for &i in &sensor.by_body[sensor.body_range[p.body].clone()] {
                    let n = pose * sensor.cells[i].normal;
                    sum += n * sensor.force_n[i];
                    along -= n.dot(&u) * sensor.force_n[i];
                }
                let f = p.force.norm();
                assert!((sum.norm() - f).abs() <= 1e-9 * f, "direction {k}: loads {} N, force {f} N", sum.norm());
                checked += 1;
                asymmetric += usize::from((along - f).abs() > 0.1 * f);
            }
        }
        assert!(checked >= 12, "{checked} contacts checked");
        assert!(asymmetric > 0, "no contact where the two balances differ");
    }

    /// One object on one link is one contact, its force the net force of MuJoCo's contacts
    /// between them: where planar7's fingertip cylinder and its end cap overlap, MuJoCo gives the
    /// two geoms' contacts with a cylinder pressed there opposite normals at times (in this sweep
    /// around the fingertip, and in campaign planar seed 6 scene 116: 70 N each way for one step,
    /// a link at rest read as 141 N and its skin as 9.8 N, a hard contact (c) from nothing).
    #[test]
    fn one_object_on_one_link_is_its_net_force() {
        let world = planar_scene();
        let model = world.mj_model();
        let tip = model.name_to_id(MjtObjBase::mjOBJ_BODY, "link7").unwrap();
        let mut sensor = world.skin().unwrap().clone();
        let (mut both, mut opposed) = (0, 0);
        for k in 0..4000 {
            // the cylinder's centre in the arm's plane around points 0-5 cm before the cap's
            // centre (x = 0.25 m of link7), every 4.5°, 0.01-1 mm into the fingertip's radius
            let phi = (k % 80) as f64 * 4.5_f64.to_radians();
            let along = 0.2 + 0.05 * ((k / 80) % 10) as f64 / 9.0;
            let reach = 0.1 + 0.021 - 1e-5 * 10_f64.powf((k / 800) as f64 / 2.0);
            let data = obstacle_at(&world, Point3::new(along + phi.cos() * reach, phi.sin() * reach, 0.0));
            let (group, geom_body) = (model.geom_group(), model.geom_bodyid());
            let mut net = Vector3::zeros();
            let mut normals = Vec::new();
            for (c, con) in data.contact().iter().enumerate() {
                let [g1, g2] = [con.geom1 as usize, con.geom2 as usize];
                let on_tip = |g: usize| group[g] == ROBOT_GROUP as i32 && geom_body[g] as usize == tip;
                if !(on_tip(g1) ^ on_tip(g2)) {
                    continue;
                }
                let mut f = [0.0; 6];
                // SAFETY: model and data belong together and c < ncon.
                unsafe { mujoco_c::mj_contactForce(model.ffi(), data.ffi(), c as i32, &mut f) };
                let n = Vector3::new(con.frame[0], con.frame[1], con.frame[2]) * if on_tip(g1) { -f[0] } else { f[0] };
                net += n;
                normals.push(n);
            }
            both += usize::from(normals.len() > 1);
            let magnitudes: f64 = normals.iter().map(|n| n.norm()).sum();
            opposed += usize::from(
                normals.iter().any(|a| normals.iter().any(|b| a.dot(b) < 0.0)) && magnitudes > 1.25 * net.norm(),
            );
            sensor.contact_forces(&data);
            let patches: Vec<_> = sensor.patches.iter().filter(|p| p.body == tip).collect();
            assert!(patches.len() <= 1, "state {k}: {} contacts of one object on the link", patches.len());
            if let Some(p) = patches.first() {
                assert!((p.force - net).norm() <= 1e-9 * net.norm().max(1.0), "state {k}");
            }
        }
        assert!(both > 100 && opposed > 0, "{both} states with two of the link's geoms touching, {opposed} opposed");
    }

    #[test]
    fn the_bounding_sphere_holds_its_points() {
        let points = [Point3::new(0.0, 0.0, 0.0), Point3::new(0.2, 0.0, 0.0), Point3::new(0.1, 0.1, -0.1)];
        let (c, r) = bounding_sphere(points.iter().copied());
        assert!(points.iter().all(|p| (p - c).norm() <= r + 1e-15));
        assert_eq!(bounding_sphere(std::iter::empty()), (Point3::origin(), 0.0));
    }
}
