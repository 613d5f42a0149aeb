//! MuJoCo's contacts on the robot, one per robot body and other geom: the force of all their
//! contact points summed as a vector, and the box the points span. Summed over the body's geoms,
//! not per geom: where two of a link's geoms overlap (planar7's cylinder and its end caps),
//! MuJoCo at times gives one of them a flipped normal, and the two squeeze the object 70 N each
//! way for a step, which the link as a whole does not feel (`docs/scenes.md`). The simulated skin
//! and the ground-truth probe read the same patches.

use mujoco_rs::mujoco_c;
use mujoco_rs::prelude::*;
use mujoco_rs::wrappers::mj_model::traits::ModelType;
use nalgebra::{Point3, Vector3};

use crate::world::mjcf::ROBOT_GROUP;

/// The contacts of one robot body with one other geom in a sample.
#[derive(Debug, Clone, Copy)]
pub(crate) struct ContactPatch {
    /// MuJoCo body of the robot.
    pub body: usize,
    /// The geom the robot body touches.
    pub other: usize,
    /// Summed normal force on the robot body (world) \[N\].
    pub force: Vector3<f64>,
    /// Box spanned by the contact points (world axes).
    pub min: Point3<f64>,
    pub max: Point3<f64>,
}

/// Fills `patches` with the contacts of `data` on robot bodies (a contact between two robot
/// geoms gives a patch on each side), each contact's normal force from `mj_contactForce`.
pub(crate) fn collect<M: ModelType>(data: &MjData<M>, patches: &mut Vec<ContactPatch>) {
    patches.clear();
    let model = data.model();
    let (group, geom_body) = (model.geom_group(), model.geom_bodyid());
    for (k, con) in data.contact().iter().enumerate() {
        let [g1, g2] = [con.geom1 as usize, con.geom2 as usize];
        let mut force = [0.0; 6];
        // SAFETY: model and data belong together and k < ncon.
        unsafe { mujoco_c::mj_contactForce(model.ffi(), data.ffi(), k as i32, &mut force) };
        if force[0] <= 0.0 {
            continue;
        }
        // The contact normal points from geom1 to geom2; the force pushes geom2 along it.
        let normal = Vector3::new(con.frame[0], con.frame[1], con.frame[2]) * force[0];
        let pos = Point3::from(con.pos);
        for (g, other, f) in [(g1, g2, -normal), (g2, g1, normal)] {
            if group[g] != ROBOT_GROUP as i32 {
                continue;
            }
            let body = geom_body[g] as usize;
            match patches.iter_mut().find(|p| p.body == body && p.other == other) {
                Some(p) => {
                    p.force += f;
                    p.min = p.min.inf(&pos);
                    p.max = p.max.sup(&pos);
                }
                None => patches.push(ContactPatch { body, other, force: f, min: pos, max: pos }),
            }
        }
    }
}
