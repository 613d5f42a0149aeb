//! The sensing face of one skin cell and how deep a touching geom presses into it.
//!
//! A real cell (interactive-force-control paper Sec. 4.1.2: a rigid element about the size of a two-euro coin, force
//! sensors under a soft cover) reads the pressure on its whole face; the cover's pressure grows
//! with its local compression. The face is sampled as a disk of the cell's radius with the 7-point
//! rule (centre weight 1/4, six points at `sqrt(2/3) r` with 1/8 each, exact for cubic
//! polynomials), and the compression at a sample point is how far the touching geom's surface lies
//! beyond it along the cell's outward normal (a ray from behind the face, `mju_rayGeom`).

use mujoco_rs::prelude::*;
use mujoco_rs::wrappers::fun::utility::mju_ray_geom;
use mujoco_rs::wrappers::mj_model::traits::ModelType;
use nalgebra::{Isometry3, Point3, Vector3};

/// Rays start this far behind the face \[m\]: the deepest compression that is measured. A geom
/// pressed in deeper holds the ray's origin and reads no compression there (MuJoCo's contacts in
/// the scenes penetrate by millimetres).
const REACH_M: f64 = 0.02;

/// Weights of the 7-point disk rule: the centre, then each of the six ring points.
const WEIGHTS: [f64; 7] = [0.25, 0.125, 0.125, 0.125, 0.125, 0.125, 0.125];

/// A cell's face in its MuJoCo body's frame.
#[derive(Debug, Clone, Copy)]
pub(crate) struct CellFace {
    /// Sample points: the centre, then the ring.
    points: [Point3<f64>; 7],
    /// Outward unit normal.
    normal: Vector3<f64>,
}

impl CellFace {
    /// The disk of `radius_m` around `centre` facing along the unit vector `normal` (body frame).
    pub(crate) fn new(centre: Point3<f64>, normal: Vector3<f64>, radius_m: f64) -> Self {
        let u =
            normal.cross(&Vector3::x()).try_normalize(1e-6).unwrap_or_else(|| normal.cross(&Vector3::y()).normalize());
        let v = normal.cross(&u);
        let r = radius_m * (2.0f64 / 3.0).sqrt();
        let mut points = [centre; 7];
        for (k, p) in points.iter_mut().skip(1).enumerate() {
            let a = k as f64 * std::f64::consts::FRAC_PI_3;
            *p = centre + r * (a.cos() * u + a.sin() * v);
        }
        CellFace { points, normal }
    }

    /// Mean compression of the face \[m\] by geom `geom` with the face's body at `pose` (world):
    /// 0 when the geom does not reach beyond the face.
    pub(crate) fn compression<M: ModelType>(&self, data: &MjData<M>, pose: &Isometry3<f64>, geom: usize) -> f64 {
        let model = data.model();
        let n = pose * self.normal;
        let (pos, mat, size) = (&data.geom_xpos()[geom], &data.geom_xmat()[geom], &model.geom_size()[geom]);
        let kind = model.geom_type()[geom];
        let dir = [n.x, n.y, n.z];
        self.points
            .iter()
            .zip(WEIGHTS)
            .map(|(p, w)| {
                let o = pose * p - n * REACH_M;
                let t = mju_ray_geom(pos, mat, size, &[o.x, o.y, o.z], &dir, kind, None);
                if t >= 0.0 {
                    w * (REACH_M - t).max(0.0)
                } else {
                    0.0
                }
            })
            .sum()
    }
}
