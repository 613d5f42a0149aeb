//! A robot that cannot be written as MJCF.

use thiserror::Error;

/// A robot that cannot be written as MJCF.
#[derive(Debug, Error)]
pub enum MjcfError {
    /// A mesh collision element whose mesh the scene did not read (a scene built by hand).
    #[error("link `{link}`: collision element {index} is a mesh the scene has not read")]
    Mesh {
        /// The URDF link.
        link: String,
        /// Its collision element index.
        index: usize,
    },
    /// A joint that moves in the scene without finite, positive velocity and effort limits.
    #[error(
        "joint `{joint}`: velocity limit {velocity}, effort limit {effort}: its velocity servo needs both finite and \
         > 0 (URDF <limit velocity effort>), or freeze the joint (leave it out of robot.joints)"
    )]
    Limits {
        /// The joint.
        joint: String,
        /// Its velocity limit.
        velocity: f64,
        /// Its effort limit.
        effort: f64,
    },
}
