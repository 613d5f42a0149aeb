//! Errors of a task update.

use thiserror::Error;

use crate::hierarchy::HierarchyError;
use crate::model::ModelError;
use crate::skin::aggregate::LengthMismatch;

/// Errors of a task update.
#[derive(Debug, Error)]
pub enum TaskError {
    /// Kinematics query failed (bad frame, non-finite point, wrong size).
    #[error(transparent)]
    Model(#[from] ModelError),
    /// The level rejected the rows (too many rows, wrong sizes).
    #[error(transparent)]
    Level(#[from] HierarchyError),
    /// Skin readings do not match the layout.
    #[error(transparent)]
    Skin(#[from] LengthMismatch),
    /// A per-cycle input has the wrong length.
    #[error("{what}: expected length {expected}, got {got}")]
    Length {
        /// What was wrong.
        what: &'static str,
        /// Expected length.
        expected: usize,
        /// Given length.
        got: usize,
    },
    /// A per-cycle input is NaN or infinite.
    #[error("{what}[{index}] is not finite")]
    NonFinite {
        /// What was wrong.
        what: &'static str,
        /// Index of the first bad value.
        index: usize,
    },
}
