//! The scene's commanded base motions (`base_motions`, interactive-force-control paper Exp. 1: "the base is commanded
//! to move on a circle with a radius of 0.2 m", then "lateral swings parallel to the table"),
//! turned into the controller's [`BaseReference`] per cycle: the posture level's moving target
//! `q_d(t)`, `q̇_d(t)` of the base joints (`Controller::set_base_reference`).

use std::f64::consts::TAU;

use skin_core::controller::BaseReference;

use crate::scene::BaseMotionSpec;

/// The base motions of a scene and the pose they are relative to.
#[derive(Debug, Clone)]
pub struct BaseMotions {
    /// In time order, not overlapping (checked by the scene loader).
    motions: Vec<BaseMotionSpec>,
    /// Base x, y, yaw when the first motion started (None: not started yet).
    origin: Option<[f64; 3]>,
}

/// `3u² − 2u³` and its derivative in `u`, for `u` clamped to `[0, 1]`.
fn smoothstep(u: f64) -> (f64, f64) {
    let u = u.clamp(0.0, 1.0);
    (u * u * (3.0 - 2.0 * u), 6.0 * u * (1.0 - u))
}

impl BaseMotionSpec {
    /// The motion's offset from the start pose and its velocity at `t_s` (world x, y; zero
    /// outside the window).
    pub fn offset(&self, t_s: f64) -> ([f64; 2], [f64; 2]) {
        if !(t_s >= self.start_s && t_s < self.end_s) {
            return ([0.0; 2], [0.0; 2]);
        }
        // Fade-in and fade-out envelope e(t) and its time derivative.
        let (rise, drise) = smoothstep((t_s - self.start_s) / self.ramp_s);
        let (fall, dfall) = smoothstep((self.end_s - t_s) / self.ramp_s);
        let (e, de) = (rise * fall, (drise * fall - rise * dfall) / self.ramp_s);
        let tau = t_s - self.start_s;
        match (self.circle, self.swing) {
            (Some(c), _) => {
                let w = TAU / c.period_s;
                let (s, co) = (w * tau).sin_cos();
                let r = c.radius_m;
                ([e * r * co, e * r * s], [r * (de * co - e * w * s), r * (de * s + e * w * co)])
            }
            (None, Some(sw)) => {
                let w = TAU / sw.period_s;
                let (s, co) = (w * tau).sin_cos();
                let n = sw.axis[0].hypot(sw.axis[1]);
                let (ax, ay) = (sw.axis[0] / n, sw.axis[1] / n);
                let (p, v) = (e * sw.amplitude_m * s, sw.amplitude_m * (de * s + e * w * co));
                ([p * ax, p * ay], [v * ax, v * ay])
            }
            (None, None) => ([0.0; 2], [0.0; 2]),
        }
    }
}

impl BaseMotions {
    /// The motions of a scene (in time order, as the loader checked them).
    pub fn new(motions: &[BaseMotionSpec]) -> Self {
        BaseMotions { motions: motions.to_vec(), origin: None }
    }

    /// The reference at `t_s`, with `base_q` the measured base x, y, yaw: None before the first
    /// motion starts (the posture's `q_post`); from then on the pose the base had at that start
    /// (captured then, so the reference starts where the base is) plus the active motion's
    /// offset, yaw held. Between and after the motions the reference holds that pose.
    pub fn reference(&mut self, t_s: f64, base_q: [f64; 3]) -> Option<BaseReference> {
        let first = self.motions.first()?;
        if t_s < first.start_s {
            return None;
        }
        let origin = *self.origin.get_or_insert(base_q);
        let (p, v) = self
            .motions
            .iter()
            .find(|m| t_s >= m.start_s && t_s < m.end_s)
            .map_or(([0.0; 2], [0.0; 2]), |m| m.offset(t_s));
        Some(BaseReference { position: [origin[0] + p[0], origin[1] + p[1], origin[2]], velocity: [v[0], v[1], 0.0] })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{CircleSpec, SwingSpec};

    fn circle() -> BaseMotionSpec {
        BaseMotionSpec {
            start_s: 15.0,
            end_s: 50.0,
            ramp_s: 5.0,
            circle: Some(CircleSpec { radius_m: 0.2, period_s: 17.5 }),
            swing: None,
        }
    }

    fn swing() -> BaseMotionSpec {
        BaseMotionSpec {
            start_s: 50.0,
            end_s: 90.0,
            ramp_s: 5.0,
            circle: None,
            swing: Some(SwingSpec { amplitude_m: 0.3, period_s: 20.0, axis: [0.0, 2.0] }),
        }
    }

    #[test]
    fn velocity_is_the_derivative_of_the_offset() {
        let h = 1e-6;
        for m in [circle(), swing()] {
            let mut t = m.start_s + 0.01;
            while t < m.end_s - 0.01 {
                let ((p0, _), (p1, _), (_, v)) = (m.offset(t - h), m.offset(t + h), m.offset(t));
                for k in 0..2 {
                    assert!(((p1[k] - p0[k]) / (2.0 * h) - v[k]).abs() < 1e-6, "t {t}: {k}");
                }
                t += 0.37;
            }
        }
    }

    #[test]
    fn motions_start_and_end_at_rest_and_reach_their_size() {
        for m in [circle(), swing()] {
            for t in [m.start_s, m.end_s - 1e-9] {
                let (p, v) = m.offset(t);
                assert!(p.iter().chain(&v).all(|x| x.abs() < 1e-6), "{t}: {p:?} {v:?}");
            }
        }
        let (p, _) = circle().offset(15.0 + 17.5 * 0.75); // after the fade-in, a quarter before a turn
        assert!((p[0].hypot(p[1]) - 0.2).abs() < 1e-12);
        let (p, _) = swing().offset(50.0 + 25.0); // a swing's peak after the fade-in
        assert!(p[0].abs() < 1e-12 && (p[1] - 0.3).abs() < 1e-9, "{p:?}");
    }

    #[test]
    fn the_reference_starts_at_the_measured_pose_and_holds_it_after() {
        let mut motions = BaseMotions::new(&[circle(), swing()]);
        assert_eq!(motions.reference(10.0, [0.0; 3]), None);
        let start = [0.03, -0.04, 0.01];
        let r = motions.reference(15.0, start).unwrap();
        assert_eq!(r.position, start);
        assert_eq!(r.velocity, [0.0; 3]);
        // later measurements do not move the origin
        let r = motions.reference(95.0, [1.0, 1.0, 1.0]).unwrap();
        assert!(r.position.iter().zip(&start).all(|(a, b)| (a - b).abs() < 1e-12));
    }
}
