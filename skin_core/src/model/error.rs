//! Errors of model loading and of the kinematics/dynamics entry points.

/// Everything that can go wrong while building a [`super::RobotModel`] from a URDF or while
/// evaluating it. Messages always name the URDF source (file) and the offending element, or the
/// joint whose input value is bad, so that a user can fix the input without a debugger.
#[derive(Debug, thiserror::Error)]
pub enum ModelError {
    /// The URDF file could not be read.
    #[error("cannot read URDF file `{file}`: {io}")]
    Io {
        /// Path of the file.
        file: String,
        /// Underlying I/O error (part of the message, not a separate error source).
        io: std::io::Error,
    },
    /// The XML is malformed or does not follow the URDF schema.
    #[error("malformed URDF in `{file}`: {message}")]
    Parse {
        /// Source name (file).
        file: String,
        /// Parser message.
        message: String,
    },
    /// An element of the URDF is invalid (bad inertia, zero axis, dangling link, ...).
    #[error("invalid URDF `{file}`: {element}: {message}")]
    Invalid {
        /// Source name (file).
        file: String,
        /// The element, e.g. `link "left_wrist_3_link"` or `joint "elbow"`.
        element: String,
        /// What is wrong with it.
        message: String,
    },
    /// The URDF uses a feature this model does not support (mimic, floating, planar joints).
    #[error("unsupported URDF feature in `{file}`: {element}: {message}")]
    Unsupported {
        /// Source name (file).
        file: String,
        /// The element, e.g. `joint "gripper_mimic"`.
        element: String,
        /// What is unsupported.
        message: String,
    },
    /// An input vector (q, qd, qdd) or output buffer has the wrong size.
    #[error("{what} has length {got}, expected {expected}")]
    Dimension {
        /// Which argument (e.g. `q`, `jacobian output columns`).
        what: &'static str,
        /// Expected length.
        expected: usize,
        /// Actual length.
        got: usize,
    },
    /// An input value is NaN or infinite.
    #[error("{what}[{index}] for joint `{joint}` is not finite ({value})")]
    NonFinite {
        /// Which argument (`q`, `qd`, `qdd`, `point`).
        what: &'static str,
        /// Index in the vector.
        index: usize,
        /// Name of the joint (or frame, for points) the value belongs to.
        joint: String,
        /// The offending value.
        value: f64,
    },
    /// A frame index is out of range.
    #[error("frame index {index} out of range (model has {count} frames)")]
    FrameIndex {
        /// Requested index.
        index: usize,
        /// Number of frames.
        count: usize,
    },
}
