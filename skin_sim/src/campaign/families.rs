//! The randomized scene families of the campaign, each a shipped scenario's scene varied from a
//! seed: what the controller was not tuned on.

use nalgebra::{Rotation3, Vector3};
use serde_json::{json, Value};

use crate::scene::spec::{ObjectSpec, SceneSpec, ShapeSpec};
use crate::world::noise::Noise;

/// Standard gravity \[m/s²\].
const G: f64 = 9.81;

/// `ε_c` the feasibility of a push is judged with \[N\] (config/supervisor.yaml).
pub const EPS_C_N: f64 = 5.0;

/// A scene family.
#[derive(Debug, Clone, Copy)]
pub struct Family {
    /// Name in the results.
    pub name: &'static str,
    /// The scenario whose scene and controller it varies.
    pub scenario: &'static str,
    /// Varies `spec`; returns what was drawn.
    pub vary: fn(&mut Noise, &mut SceneSpec) -> Value,
    /// The objects between the robot and its goal (those present in a scene): what a push must move.
    pub obstacles: &'static [&'static str],
}

/// Every family, in the order scenes cycle through them.
pub const FAMILIES: [Family; 4] = [
    Family {
        name: "planar_contact",
        scenario: "intentional_contact",
        vary: planar_contact,
        obstacles: &["obstacle", "second_obstacle"],
    },
    Family {
        name: "tomm_reach",
        scenario: "tomm_movable_obstacles",
        vary: tomm_reach,
        obstacles: &["obstacle_path", "obstacle_goal"],
    },
    Family { name: "force_tracking", scenario: "force_tracking_base_motion", vary: force_tracking, obstacles: &[] },
    Family { name: "tactile_guidance", scenario: "tactile_guidance", vary: tactile_guidance, obstacles: &[] },
];

/// The largest Coulomb friction `μ m g` among the objects of `spec` named in `pushed`, what a
/// push must overcome \[N\]: infinite if one is fixed, 0 without any. Under `ε_c` the goal is
/// reachable by pushing (intentional-contact paper Sec. IV).
pub fn resistance_n(spec: &SceneSpec, pushed: &[&str]) -> f64 {
    spec.objects
        .iter()
        .filter(|o| pushed.contains(&o.name.as_str()))
        .map(|o| o.mass_kg.map_or(f64::INFINITY, |m| o.friction * m * G))
        .fold(0.0, f64::max)
}

/// An obstacle pushed at height `h` above the floor slides rather than tips when `μ h < r`
/// (`r` its radius: the push's moment about the edge it would tip over against its weight's);
/// the planar family keeps its friction at most this share of that limit, a margin for the
/// impacts of a push (`docs/supervisor.md`: over it obstacles toppled, out of the arm's plane).
/// A friction drawn over it is clamped to it: the scenes under it stay what they were.
pub(super) const TIP_MARGIN: f64 = 0.8;

/// Radius of the planar family's second obstacle \[m\].
const SECOND_RADIUS_M: f64 = 0.05;

/// Movable with probability `1 - p_fixed`: a mass in `[lo, hi]` kg, or fixed (`None`).
fn mass(rng: &mut Noise, p_fixed: f64, lo: f64, hi: f64) -> Option<f64> {
    (rng.uniform() > p_fixed).then(|| rng.between(lo, hi))
}

/// The planar arm pushes an obstacle between it and its goal (intentional-contact paper Figs.
/// 2-3): obstacle position, size, mass 0.2-3 kg or fixed, friction, a second obstacle, start
/// posture, goal, skin noise.
fn planar_contact(rng: &mut Noise, spec: &mut SceneSpec) -> Value {
    let (dx, dy) = (rng.between(-0.08, 0.08), rng.between(-0.03, 0.05));
    let radius = rng.between(0.07, 0.12);
    let mass_kg = mass(rng, 0.2, 0.2, 3.0);
    let obstacle = &mut spec.objects[0];
    let sliding = |r: f64| TIP_MARGIN * r / (obstacle.xyz[2] - spec.floor_z_m);
    let friction = rng.between(0.1, 0.4).min(sliding(radius));
    let second_friction = friction.min(sliding(SECOND_RADIUS_M));
    obstacle.xyz[0] += dx;
    obstacle.xyz[1] += dy - (radius - 0.1); // the same gap to the goal below it
    obstacle.shape = ShapeSpec::Cylinder { radius_m: radius, length_m: 0.6 };
    obstacle.mass_kg = mass_kg;
    obstacle.friction = friction;
    if mass_kg.is_none() {
        spec.pushes.clear(); // nothing pushes a fixed obstacle into the arm
    }
    let second = rng.uniform() < 0.3;
    if second {
        let side = if rng.uniform() < 0.5 { -1.0 } else { 1.0 };
        let mut o: ObjectSpec = spec.objects[0].clone();
        o.name = "second_obstacle".into();
        o.shape = ShapeSpec::Cylinder { radius_m: SECOND_RADIUS_M, length_m: 0.6 };
        o.friction = second_friction;
        o.xyz = [1.0 + side * rng.between(0.25, 0.35), -0.62, 0.0];
        o.mass_kg = Some(0.5);
        spec.objects.push(o);
    }
    let posture: Vec<f64> = spec
        .robot
        .initial
        .values_mut()
        .map(|q| {
            let d = rng.between(-0.1, 0.1);
            *q += d;
            d
        })
        .collect();
    let goal = [rng.between(-0.03, 0.03), rng.between(-0.02, 0.0)];
    spec.goals[0].position_m[0] += goal[0];
    spec.goals[0].position_m[1] += goal[1];
    let noise = rng.between(0.0, 0.02);
    if let Some(skin) = &mut spec.skin {
        skin.proximity_noise_std = noise;
        skin.force_noise_std = noise;
    }
    spec.seed = rng.uniform().to_bits() % 1000;
    json!({"obstacle_shift_m": [dx, dy], "radius_m": radius, "mass_kg": mass_kg, "friction": friction,
           "second_obstacle": second, "posture_shift_rad": posture, "goal_shift_m": goal, "skin_noise_std": noise})
}

/// TOMM's right arm reaches over a table through two movable obstacles (intentional-contact
/// paper Fig. 5): obstacle shifts, masses and friction.
fn tomm_reach(rng: &mut Noise, spec: &mut SceneSpec) -> Value {
    let mut drawn = Vec::new();
    for o in spec.objects.iter_mut().filter(|o| o.mass_kg.is_some()) {
        let (dx, dy) = (rng.between(-0.05, 0.05), rng.between(-0.05, 0.05));
        o.xyz[0] += dx;
        o.xyz[1] += dy;
        o.mass_kg = Some(rng.between(0.2, 2.0));
        o.friction = rng.between(0.1, 0.4);
        drawn.push(json!({"name": o.name, "shift_m": [dx, dy], "mass_kg": o.mass_kg, "friction": o.friction}));
    }
    spec.seed = rng.uniform().to_bits() % 1000;
    json!({ "obstacles": drawn })
}

/// The hand tracks a sinusoidal force on a board while the base moves (interactive-force-control
/// paper Exp. 1): reference mean 2-8 N, amplitude, period 2-8 s, board tilt ±10°, circle radius.
fn force_tracking(rng: &mut Noise, spec: &mut SceneSpec) -> Value {
    let mean = rng.between(2.0, 8.0);
    let amplitude = rng.between(0.0, 2.0_f64.min(mean - 1.0));
    let period = rng.between(2.0, 8.0);
    let (pitch, yaw) = (rng.between(-10.0, 10.0), rng.between(-10.0, 10.0));
    let radius = rng.between(0.0, 0.3);
    let r = &mut spec.force_references[0];
    (r.mean_n, r.amplitude_n, r.period_s) = (mean, amplitude, Some(period));
    tilt_about(&mut spec.objects[0], PALM_HEIGHT_M, [0.0, pitch.to_radians(), yaw.to_radians()]);
    spec.base_motions.truncate(1);
    spec.duration_s = 45.0;
    let m = &mut spec.base_motions[0];
    m.end_s = spec.duration_s;
    if let Some(c) = &mut m.circle {
        c.radius_m = radius;
    }
    spec.seed = rng.uniform().to_bits() % 1000;
    json!({"mean_n": mean, "amplitude_n": amplitude, "period_s": period, "tilt_deg": [pitch, yaw], "circle_radius_m": radius})
}

/// Height of the palm in `force_tracking_base_motion` \[m\] (its scene: the hand at (0.8, -0.3, 1.0)).
pub(super) const PALM_HEIGHT_M: f64 = 1.0;

/// Turns a board (a box, its face toward `-x` in its frame) to the orientation `rpy` about the
/// point of that face at `height_m` in front of the hand, not about its centre: a tilt changes the
/// surface's direction, not its distance from the palm (about the centre, 10° moved the face 5 cm
/// into the hand, which started the run pressed at 90 N). The board may be turned already.
pub(super) fn tilt_about(board: &mut ObjectSpec, height_m: f64, rpy: [f64; 3]) {
    let ShapeSpec::Box { size_m } = board.shape else { return };
    let (centre, turned) = (Vector3::from(board.xyz), rotation(board.rpy));
    // the face's point on the board's centre line at the palm's height, in the board frame
    let face = Vector3::new(-0.5 * size_m[0], 0.0, 0.0);
    let up = (height_m - centre.z - (turned * face).z) / turned[(2, 2)];
    let point = face + Vector3::new(0.0, 0.0, up);
    let pivot = centre + turned * point;
    board.xyz = (pivot - rotation(rpy) * point).into();
    board.rpy = rpy;
}

/// The rotation of URDF roll-pitch-yaw angles.
fn rotation(rpy: [f64; 3]) -> Rotation3<f64> {
    Rotation3::from_euler_angles(rpy[0], rpy[1], rpy[2])
}

/// Touches on the arm guide the hand (interactive-force-control paper Exp. 2): which link is
/// touched, how hard and when.
fn tactile_guidance(rng: &mut Noise, spec: &mut SceneSpec) -> Value {
    let mut drawn = Vec::new();
    for p in &mut spec.pushes {
        let scale = rng.between(0.6, 1.2);
        let shift = rng.between(-3.0, 3.0);
        if rng.uniform() < 0.5 {
            p.link = Some(
                if p.link.as_deref() == Some("right_forearm_link") {
                    "right_upper_arm_link"
                } else {
                    "right_forearm_link"
                }
                .into(),
            );
        }
        p.force_n = p.force_n.map(|f| f * scale);
        p.start_s += shift;
        p.end_s += shift;
        drawn.push(json!({"link": p.link, "force_scale": scale, "time_shift_s": shift}));
    }
    spec.seed = rng.uniform().to_bits() % 1000;
    json!({ "touches": drawn })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_tilted_board_keeps_its_face_point_in_front_of_the_palm() {
        let shape = ShapeSpec::Box { size_m: [0.04, 1.2, 1.0] };
        let mut board: ObjectSpec =
            serde_json::from_value(json!({"name": "board", "shape": shape, "xyz": [0.87, -0.3, 0.7]})).unwrap();
        let face_point = |b: &ObjectSpec| Vector3::from(b.xyz) + rotation(b.rpy) * Vector3::new(-0.02, 0.0, 0.3);
        for rpy in [[0.0, 10f64.to_radians(), -8f64.to_radians()], [0.0, -8f64.to_radians(), 8f64.to_radians()]] {
            tilt_about(&mut board, 1.0, rpy); // the second time from the first tilt
            assert!((face_point(&board) - Vector3::new(0.85, -0.3, 1.0)).norm() < 1e-12, "{rpy:?}");
        }
        assert_ne!(board.xyz, [0.87, -0.3, 0.7], "the centre moves");
    }
}
