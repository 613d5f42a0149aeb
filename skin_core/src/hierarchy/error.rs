//! Errors of the hierarchy solver and of filling task levels.

/// Everything that can go wrong while filling a [`super::TaskLevel`] or solving the hierarchy.
/// Messages name the input (and the level, by priority index and name) and the offending index,
/// so that a bad cycle can be traced without a debugger. The solver never writes its output when
/// it returns an error.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum HierarchyError {
    /// An input vector or matrix has the wrong size.
    #[error("{what} has size {got}, expected {expected}")]
    Dimension {
        /// Which argument (e.g. `mass matrix rows`, `posture torque`).
        what: &'static str,
        /// Expected size.
        expected: usize,
        /// Actual size.
        got: usize,
    },
    /// An entry of the mass matrix is NaN or infinite.
    #[error("mass matrix entry ({row}, {col}) is not finite ({value})")]
    NonFiniteMassMatrix {
        /// Row index.
        row: usize,
        /// Column index.
        col: usize,
        /// The offending value.
        value: f64,
    },
    /// An entry of a joint-space input vector is NaN or infinite.
    #[error("{what}[{index}] is not finite ({value})")]
    NonFinite {
        /// Which argument (`bias`, `posture torque`).
        what: &'static str,
        /// Index in the vector (joint index).
        index: usize,
        /// The offending value.
        value: f64,
    },
    /// An entry of a task level (Jacobian or reference) is NaN or infinite.
    #[error("level {level} (`{name}`): {what}[{index}] is not finite ({value})")]
    NonFiniteLevel {
        /// Priority index of the level in the list given to the solver (0 = highest).
        level: usize,
        /// Name of the level.
        name: String,
        /// Which part: `jacobian` (index = row * nv + column), `xdd_star`, `jdot_qdot`, `force`.
        what: &'static str,
        /// Index in that part.
        index: usize,
        /// The offending value.
        value: f64,
    },
    /// A level was built for another number of joints than the solver.
    #[error("level {level} (`{name}`) has {got} Jacobian columns, the solver has {expected} joints")]
    LevelColumns {
        /// Priority index of the level.
        level: usize,
        /// Name of the level.
        name: String,
        /// Solver's number of joints.
        expected: usize,
        /// Level's number of Jacobian columns.
        got: usize,
    },
    /// More levels, or a level with more rows, than the solver was sized for.
    #[error("{what}: {got} exceeds the capacity {capacity} fixed at construction")]
    Capacity {
        /// What overflowed (`levels`, `rows of level ...`).
        what: String,
        /// Requested count.
        got: usize,
        /// Capacity.
        capacity: usize,
    },
    /// Rows pushed into a level do not fit its shape or reference kind.
    #[error("level `{name}`: {message}")]
    LevelInput {
        /// Name of the level.
        name: String,
        /// What is wrong.
        message: String,
    },
    /// The mass matrix is not (numerically) positive definite: Cholesky pivot `index` failed.
    #[error("mass matrix is not positive definite (Cholesky pivot {index} = {pivot})")]
    NotPositiveDefinite {
        /// Joint index of the failed pivot.
        index: usize,
        /// Value of the pivot before its square root.
        pivot: f64,
    },
    /// Finite inputs produced a non-finite torque (overflow, e.g. references near 1e300).
    #[error("level {level}: the torque overflowed (inputs too large)")]
    Overflow {
        /// Priority index of the level at which the torque stopped being finite
        /// (= number of levels for the posture and bias terms).
        level: usize,
    },
    /// The model evaluation of [`super::HierarchySolver::solve_model`] failed.
    #[error("model evaluation failed: {message}")]
    Model {
        /// The model error's message.
        message: String,
    },
    /// An [`super::InverseParams`] value is out of its range.
    #[error("inverse parameter `{name}` = {value}: {reason}")]
    InvalidParameter {
        /// Parameter name.
        name: &'static str,
        /// Given value.
        value: f64,
        /// Allowed range.
        reason: &'static str,
    },
}
