//! When the scene's user interacts with the robot: a scripted push on a robot link (touches of
//! interactive-force-control paper Exp. 2-4, green areas) or a person within the base avoidance range of the base
//! footprint (red areas), or a commanded base motion (interactive-force-control paper Exp. 1's circle and swings).
//! Interactive-force-control paper Table 3 splits the force-tracking error by these periods.

use skin_core::tasks::params::BaseAvoidanceParams;

use crate::scene::{PersonSpec, PushSpec, Scene};

/// The scripted interactions of a scene.
#[derive(Debug, Clone)]
pub struct Interactions {
    /// Windows `[start, end)` of pushes on robot links and of base motions.
    windows: Vec<(f64, f64)>,
    persons: Vec<PersonSpec>,
    /// Model indices of base x, y, yaw (None: no base, persons never count).
    base: Option<[usize; 3]>,
    footprint: BaseAvoidanceParams,
}

impl Interactions {
    /// The interactions of `scene`, with the base footprint and range of base avoidance.
    pub fn new(scene: &Scene, footprint: BaseAvoidanceParams) -> Self {
        let on_robot = |p: &&PushSpec| p.link.is_some();
        Interactions {
            windows: (scene.spec.pushes.iter().filter(on_robot).map(|p| (p.start_s, p.end_s)))
                .chain(scene.spec.base_motions.iter().map(|m| (m.start_s, m.end_s)))
                .collect(),
            persons: scene.spec.persons.clone(),
            base: scene.model.planar_base(),
            footprint,
        }
    }

    /// Whether an interaction is going on at `t_s` with the robot at `q` (model order).
    pub fn active(&self, t_s: f64, q: &[f64]) -> bool {
        self.windows.iter().any(|&(a, b)| t_s >= a && t_s < b) || self.person_near(t_s, q)
    }

    /// A person's surface within `range_m` of the footprint rectangle (base frame).
    fn person_near(&self, t_s: f64, q: &[f64]) -> bool {
        let Some([x, y, w]) = self.base else { return false };
        let (s, c) = q[w].sin_cos();
        let f = &self.footprint;
        self.persons.iter().any(|p| {
            let [px, py] = p.position(t_s);
            let (dx, dy) = (px - q[x], py - q[y]);
            // World offset to the base frame (rotation by -yaw).
            let (bx, by) = (c * dx + s * dy, -s * dx + c * dy);
            let ox = (f.footprint_x_m[0] - bx).max(bx - f.footprint_x_m[1]).max(0.0);
            let oy = (f.footprint_y_m[0] - by).max(by - f.footprint_y_m[1]).max(0.0);
            ox.hypot(oy) - p.radius_m < f.range_m
        })
    }
}
