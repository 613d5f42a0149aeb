//! Multi-priority torque control: the task hierarchy of interactive-force-control paper Sec. 3.3 (eq. 19-25, after
//! Sadeghian et al.), with the task-space force levels of intentional-contact paper (`τ = J_kᵀ F_k`) composed in
//! the same augmented null-space projection.
//!
//! - [`TaskLevel`]: one priority level, a Jacobian block and a [`Reference`] (acceleration or
//!   force), in storage allocated once;
//! - [`HierarchySolver::solve`]: the one function (mass matrix, ordered levels, posture torque,
//!   bias) → joint torque, with per-level [`LevelDiagnostics`] ([`HierarchySolver::solve_model`]
//!   computes `M` and the bias from the robot model first);
//! - [`InverseParams`]: the damped, rank-aware inverse used for every `Λ̄_k` (rank loss from
//!   stacked skin-cell rows, dependent levels, singular arms).
//!
//! Nothing here allocates after construction. The method, the inverse and the bounds are
//! described in `docs/hierarchy.md`.
//!
//! ```
//! use nalgebra::{DMatrix, DVector};
//! use skin_core::hierarchy::*;
//! let n = 3;
//! let mut solver = HierarchySolver::new(n, 2, 3, InverseParams::default()).unwrap();
//! let mut hand = TaskLevel::new("hand", n, 3);
//! let j = DMatrix::from_row_slice(2, 3, &[1.0, 0.5, 0.2, 0.0, 1.0, 0.3]);
//! hand.set(&j, Reference::Acceleration { xdd_star: &[0.1, -0.2], jdot_qdot: &[0.0, 0.0] }).unwrap();
//! let m = DMatrix::from_diagonal(&DVector::from_vec(vec![2.0, 1.0, 0.5]));
//! let mut tau = DVector::zeros(n);
//! solver.solve(&m, [&hand], Some(&[0.0, 0.0, 1.0]), None, &mut tau).unwrap();
//! let qdd = m.clone().cholesky().unwrap().solve(&tau);
//! assert!(((&j * qdd)[0] - 0.1).abs() < 1e-12);
//! ```

#[macro_use]
mod dense;
mod error;
mod inverse;
mod solver;
mod task;

pub use error::HierarchyError;
pub use inverse::InverseParams;
pub use solver::{HierarchySolver, LevelDiagnostics};
pub use task::{Reference, ReferenceKind, TaskLevel};
