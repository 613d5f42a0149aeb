//! Ground truth from MuJoCo, not from the skin: the force pressing on the hand (interactive-force-control paper's `f_c`
//! in newtons), the largest force on one robot link (intentional-contact paper's `‖F_c‖` against `ε_c`), and where
//! the hand is (its position and its distance `d_p` to the surface ahead of the palm, interactive-force-control paper
//! Fig. 6), and how far a movable object tipped.

use mujoco_rs::mujoco_c;
use nalgebra::Vector3;

use crate::world::frames::FrameRef;
use crate::world::mjcf::{ROBOT_GROUP, SENSED_GROUPS};
use crate::world::World;

/// Contact forces on the robot and the hand's place at the world's current state.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ProbeReadings {
    /// Environment force pressing on the hand body along `-z_h` (into the palm) \[N\].
    pub hand_n: f64,
    /// Largest total normal force of the environment on one robot body \[N\].
    pub max_link_n: f64,
    /// Hand frame origin in the world \[m\].
    pub hand_position_m: [f64; 3],
    /// Distance from the hand frame origin along `+z_h` to the first object or person (the
    /// sensed geoms) \[m\]; infinite when nothing is ahead.
    pub hand_distance_m: f64,
    /// Largest tilt of a movable object from its start orientation \[deg\] ([`World::object_tilt_deg`]).
    pub object_tilt_deg: f64,
}

/// Measures contact forces for one hand frame (a URDF link of the scene's robot).
#[derive(Debug, Clone)]
pub struct ContactProbe {
    hand: FrameRef,
    hand_frame: usize,
    /// Scratch: total normal force per MuJoCo body.
    per_body: Vec<f64>,
    /// Scratch: the summed force of each robot body's contacts with one other geom (body, geom,
    /// force on the robot).
    pairs: Vec<(usize, usize, Vector3<f64>)>,
}

impl ContactProbe {
    /// A probe for the hand frame `hand_frame` (model frame index) of `world`.
    pub fn new(world: &World, hand_frame: usize) -> Self {
        ContactProbe {
            hand: FrameRef::new(&world.scene().model, world.mj_model(), hand_frame),
            hand_frame,
            per_body: vec![0.0; world.mj_model().ffi().nbody as usize],
            pairs: Vec::new(),
        }
    }

    /// The forces of the world's current contacts: every contact between a robot geom and the
    /// environment (objects, persons, floor) contributes its normal force (`mj_contactForce`),
    /// summed as vectors per robot body and other geom (as the skin takes them: two overlapping
    /// geoms of a link that MuJoCo at times gives opposite normals squeeze nothing), then by
    /// magnitude per body (a link pinched between two objects bears both).
    pub fn measure(&mut self, world: &World) -> ProbeReadings {
        let (model, data) = (world.mj_model(), world.mj_data());
        let (group, geom_body) = (model.geom_group(), model.geom_bodyid());
        let hand = world.frame_pose(self.hand_frame);
        let z_hand = hand.rotation * Vector3::z();
        self.per_body.fill(0.0);
        self.pairs.clear();
        for (k, con) in data.contact().iter().enumerate() {
            let [g1, g2] = [con.geom1 as usize, con.geom2 as usize];
            let robot = |g: usize| group[g] == ROBOT_GROUP as i32;
            if robot(g1) == robot(g2) {
                continue; // self-contact or environment only
            }
            let mut f = [0.0; 6];
            // SAFETY: model and data belong together and k < ncon.
            unsafe { mujoco_c::mj_contactForce(model.ffi(), data.ffi(), k as i32, &mut f) };
            if f[0] <= 0.0 {
                continue;
            }
            // The normal points from geom1 to geom2; the force pushes geom2 along it.
            let normal = Vector3::new(con.frame[0], con.frame[1], con.frame[2]) * f[0];
            let (body, other, on_robot) =
                if robot(g1) { (geom_body[g1], g2, -normal) } else { (geom_body[g2], g1, normal) };
            let body = body as usize;
            match self.pairs.iter_mut().find(|(b, o, _)| (*b, *o) == (body, other)) {
                Some((_, _, f)) => *f += on_robot,
                None => self.pairs.push((body, other, on_robot)),
            }
        }
        let mut hand_n = 0.0;
        for &(body, _, on_robot) in &self.pairs {
            self.per_body[body] += on_robot.norm();
            if body == self.hand.body {
                hand_n += (-on_robot.dot(&z_hand)).max(0.0);
            }
        }
        let origin = hand.translation.vector;
        let (pnt, vec): ([f64; 3], [f64; 3]) = (origin.into(), z_hand.into());
        let mut geom = [-1i32];
        // SAFETY: model and data belong together; the arrays have mj_ray's sizes (3, 3, mjNGROUP, 1), no normal wanted.
        let distance = unsafe {
            mujoco_c::mj_ray(
                model.ffi(),
                data.ffi(),
                &pnt,
                &vec,
                SENSED_GROUPS.as_ptr(),
                true,
                -1,
                geom.as_mut_ptr(),
                std::ptr::null_mut(),
            )
        };
        ProbeReadings {
            hand_n,
            max_link_n: self.per_body.iter().copied().fold(0.0, f64::max),
            hand_position_m: origin.into(),
            hand_distance_m: if geom[0] >= 0 { distance } else { f64::INFINITY },
            object_tilt_deg: world.object_tilt_deg(),
        }
    }
}
