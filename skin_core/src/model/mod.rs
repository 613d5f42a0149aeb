//! Robot model (immutable, from a URDF) and its preallocated data workspace.
//!
//! [`RobotModel`] is a kinematic tree of one-degree-of-freedom joints (revolute, continuous,
//! prismatic) built from a URDF; links joined by fixed joints are merged into the moving body
//! they hang from, and every URDF link stays available as a *frame* with a constant placement in
//! that body (like pinocchio's frames). Mimic joints are independent joints (pinocchio's
//! default) or follow their leader (one generalized coordinate), see [`UrdfOptions`]; the rules
//! of loading are in docs/dynamics.md, "Loading any URDF". [`ModelData`] holds everything the algorithms compute;
//! after [`ModelData::new`] no function of this module allocates.
//!
//! Typical use:
//! ```no_run
//! use skin_core::model::*;
//! let model = RobotModel::from_urdf_file(std::path::Path::new("urdf/tomm.urdf")).unwrap();
//! let mut data = ModelData::new(&model);
//! let (q, qd) = (vec!(0.0; model.nv()), vec!(0.0; model.nv()));
//! update_kinematics(&model, &mut data, &q, &qd).unwrap();
//! let mut m = nalgebra::DMatrix::zeros(model.nv(), model.nv());
//! crba(&model, &mut data, &mut m).unwrap();
//! ```

mod crba;
mod data;
mod error;
mod inertia_check;
mod kinematics;
mod rnea;
mod robot;
pub mod spatial;
mod urdf;
mod urdf_xml;

#[cfg(test)]
mod tests;

pub use crba::crba;
pub use data::ModelData;
pub use error::ModelError;
pub use kinematics::{
    frame_pose, point_jacobian, point_jacobian_along, point_jacobian_dot_qdot, point_velocity, update_kinematics,
};
pub use rnea::{bias_forces, gravity, rnea};
pub use robot::{
    is_base_joint_name, Collision, JointKind, JointLimits, MimicMode, RobotModel, Shape, UrdfOptions, BASE_JOINTS,
    STANDARD_GRAVITY,
};
