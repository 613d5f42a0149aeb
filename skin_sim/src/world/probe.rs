//! Ground truth from MuJoCo, not from the skin: the force pressing on the hand (interactive-force-control paper's `f_c`
//! in newtons), the largest force on one robot link (intentional-contact paper's `‖F_c‖` against `ε_c`), and where
//! the hand is (its position and its distance `d_p` to the surface ahead of the palm, interactive-force-control paper
//! Fig. 6), and how far a movable object tipped.

use mujoco_rs::mujoco_c;
use nalgebra::Vector3;

use crate::world::contact_patches::{self, ContactPatch};
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
    /// Scratch: the contacts per robot body and other geom.
    patches: Vec<ContactPatch>,
}

impl ContactProbe {
    /// A probe for the hand frame `hand_frame` (model frame index) of `world`.
    pub fn new(world: &World, hand_frame: usize) -> Self {
        ContactProbe {
            hand: FrameRef::new(&world.scene().model, world.mj_model(), hand_frame),
            hand_frame,
            per_body: vec![0.0; world.mj_model().ffi().nbody as usize],
            patches: Vec::new(),
        }
    }

    /// The forces of the world's current contacts between the robot and the environment (objects,
    /// persons, floor): per robot body and other geom as the skin takes them ([`contact_patches`]),
    /// then by magnitude per body (a link pinched between two objects bears both).
    pub fn measure(&mut self, world: &World) -> ProbeReadings {
        let (model, data) = (world.mj_model(), world.mj_data());
        let group = model.geom_group();
        let hand = world.frame_pose(self.hand_frame);
        let z_hand = hand.rotation * Vector3::z();
        self.per_body.fill(0.0);
        contact_patches::collect(data, &mut self.patches);
        let mut hand_n = 0.0;
        for p in self.patches.iter().filter(|p| group[p.other] != ROBOT_GROUP as i32) {
            self.per_body[p.body] += p.force.norm();
            if p.body == self.hand.body {
                hand_n += (-p.force.dot(&z_hand)).max(0.0);
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
