//! Simulated planar LIDAR: a fan of rays in the x-y plane of the scanner's frame, cast against
//! objects and persons ([`crate::world::mjcf::SENSED_GROUPS`], never the robot), reported as 2-D points in the BASE
//! frame (x forward, y left): the closest-obstacle points that base avoidance consumes (interactive-force-control paper
//! eq. (15)-(17)). Ranges get optional seeded Gaussian noise.

use mujoco_rs::prelude::*;
use mujoco_rs::wrappers::mj_model::traits::ModelType;
use nalgebra::{Isometry3, Point3, Vector3};

use crate::scene::Scene;
use crate::world::frames::FrameRef;
use crate::world::noise::Noise;
use crate::world::proximity_rays::ProximityRays;

/// Noise stream of the LIDAR (see [`Noise::new`]).
const NOISE_STREAM: u64 = 2;

/// The base LIDAR of a [`crate::world::World`].
#[derive(Debug, Clone)]
pub struct Lidar {
    scanner: FrameRef,
    /// Pose of the scanner frame in the base frame (both ride on the base body).
    base_from_scanner: Isometry3<f64>,
    /// Unit ray directions in the scanner frame.
    directions: Vec<Vector3<f64>>,
    /// The sensed geoms, every return read (a return beyond `range_m` still draws its noise).
    rays: ProximityRays,
    range_m: f64,
    noise_std_m: f64,
    noise: Noise,
    /// Per ray: the measured range \[m\], `f64::INFINITY` for no return.
    ranges: Vec<f64>,
    points: Vec<[f64; 2]>,
}

impl Lidar {
    /// The LIDAR of `scene` (None when it has none) on the MuJoCo model generated from it.
    pub(crate) fn new(scene: &Scene, mj: &MjModel) -> Option<Self> {
        let spec = scene.spec.lidar.as_ref()?;
        let model = &scene.model;
        // Scene validation checked both frames.
        let frame = model.frame_index(&spec.frame)?;
        let base = model.joint_child_frame(model.planar_base()?[2]);
        let scanner = FrameRef::new(model, mj, frame);
        let base_ref = FrameRef::new(model, mj, base);
        let (first, step) = spec.fan();
        let directions = (0..spec.rays)
            .map(|k| {
                let a = first + step * k as f64;
                Vector3::new(a.cos(), a.sin(), 0.0)
            })
            .collect();
        Some(Lidar {
            base_from_scanner: base_ref.placement.inverse() * scanner.placement,
            scanner,
            rays: ProximityRays::new(mj, f64::INFINITY),
            directions,
            range_m: spec.range_m,
            noise_std_m: spec.noise_std_m,
            noise: Noise::new(scene.spec.seed, NOISE_STREAM),
            ranges: vec![f64::INFINITY; spec.rays],
            points: Vec::with_capacity(spec.rays),
        })
    }

    /// The last scan's returns as points in the base frame \[m\] (rays without a return within
    /// range are left out).
    pub fn points(&self) -> &[[f64; 2]] {
        &self.points
    }

    /// The last scan's range per ray \[m\], `f64::INFINITY` where nothing was within range.
    pub fn ranges(&self) -> &[f64] {
        &self.ranges
    }

    /// Casts every ray at the data's current kinematics, against the sensed geoms only, each
    /// tested against a shape holding it in the scanner's frame before its ray is cast
    /// ([`ProximityRays`] with an infinite range: `mj_ray`'s distances).
    pub(crate) fn scan<M: ModelType>(&mut self, data: &mut MjData<M>) {
        let pose = self.scanner.world_pose(data);
        self.rays.select_near(data, &pose, Point3::origin(), 0.0);
        self.points.clear();
        for (k, dir) in self.directions.iter().enumerate() {
            let r = match self.rays.cast(data, &pose, Point3::origin(), *dir) {
                Some(d) => d + self.noise.gaussian(self.noise_std_m),
                None => f64::INFINITY,
            };
            self.ranges[k] = if r <= self.range_m { r } else { f64::INFINITY };
            if r <= self.range_m {
                let p = self.base_from_scanner * Point3::from(dir * r);
                self.points.push([p.x, p.y]);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::world::mjcf::SENSED_GROUPS;
    use crate::World;

    /// The scan of `lidar` as one `mj_ray` per ray against every geom.
    fn scan_ray_by_ray<M: ModelType>(lidar: &mut Lidar, data: &mut MjData<M>) -> Vec<f64> {
        let pose = lidar.scanner.world_pose(data);
        let origin = pose.translation.vector;
        let mut ranges = Vec::new();
        for dir in &lidar.directions {
            let d = pose.rotation * dir;
            let (hit, dist) = data.ray(&origin.into(), &d.into(), Some(&SENSED_GROUPS), true, None, None);
            let r = hit.map_or(f64::INFINITY, |_| dist + lidar.noise.gaussian(lidar.noise_std_m));
            ranges.push(if r <= lidar.range_m { r } else { f64::INFINITY });
        }
        ranges
    }

    /// Over the motion of two scenes with a moving base (a board, tables, a wall, persons walking
    /// up, noise on every return), the culled scan reads every ray's range to the bit as one
    /// `mj_ray` per ray does, noise included.
    #[test]
    fn the_culled_scan_reads_what_mj_ray_reads() {
        let mut returns = 0;
        for name in ["tactile_guidance", "poster_phrc"] {
            let file = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("../config/scenes/{name}.yaml"));
            let mut world = World::from_scene_file(&file).unwrap();
            world.set_base_twist([0.2, 0.1, 0.3]);
            for _ in 0..8 {
                for _ in 0..250 {
                    world.step();
                }
                let mut data = world.mj_data().clone();
                let mut culled = world.lidar().unwrap().clone();
                let mut by_ray = culled.clone();
                culled.scan(&mut data);
                let expected = scan_ray_by_ray(&mut by_ray, &mut data);
                let bits = |r: &[f64]| r.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(culled.ranges()), bits(&expected), "{name} at {} s", world.time());
                returns += expected.iter().filter(|r| r.is_finite()).count();
            }
        }
        assert!(returns > 500, "the scans must see something: {returns} returns");
    }
}
