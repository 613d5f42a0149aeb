//! Errors of building and running the torque resolver.

use crate::param_file::InvalidParam;

/// Everything that can go wrong in the resolver. Messages name the input and the offending index
/// so that a bad cycle can be traced from the log alone. The per-cycle variants carry no heap data.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ResolverError {
    /// A parameter is out of its range (key = dotted path in `resolver.yaml`).
    #[error("resolver parameter {0}")]
    Param(#[from] InvalidParam),
    /// A per-joint override names a joint that is not an arm joint of the model.
    #[error("resolver parameter `{key}`: `{joint}` is not an arm joint of the model")]
    UnknownJoint {
        /// Dotted key of the override (`arm.joints.<name>`).
        key: String,
        /// The joint name.
        joint: String,
    },
    /// The model's joints do not fit the resolver (partial base, unusable URDF limits).
    #[error("robot model: {0}")]
    Model(String),
    /// An input vector has the wrong size.
    #[error("{what} has size {got}, expected {expected}")]
    Dimension {
        /// Which argument (`tau`, `gravity`, `q_measured`, `qd_measured`).
        what: &'static str,
        /// Expected size (the model's number of joints).
        expected: usize,
        /// Actual size.
        got: usize,
    },
    /// An entry of an input vector is NaN or infinite.
    #[error("{what}[{index}] is not finite ({value})")]
    NonFinite {
        /// Which argument (`tau`, `gravity`, `q_measured`, `qd_measured`).
        what: &'static str,
        /// Index in the vector (model joint index).
        index: usize,
        /// The offending value.
        value: f64,
    },
    /// The time step is not finite and > 0.
    #[error("dt_s = {0}: must be finite and > 0")]
    InvalidDt(f64),
}
