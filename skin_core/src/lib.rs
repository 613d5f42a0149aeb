//! `skin_core`: the control law of skin_control, written once and used unchanged by the
//! simulation loop, the ROS 2 nodes and the benchmarks. Pure Rust: no ROS, no MuJoCo.
//!
//! - [`controller`]: the whole cycle behind one [`controller::Controller::update`]: measurements in,
//!   joint and base velocity commands out.
//! - [`model`]: the immutable [`model::RobotModel`] built from a URDF and the preallocated
//!   [`model::ModelData`] workspace that kinematics and dynamics (CRBA, RNEA) fill.
//! - [`skin`]: skin layouts, the cells' signal characteristics and the aggregation of cells into
//!   forces, patch wrenches and joint torques.
//! - [`hierarchy`]: the multi-priority torque solver (interactive-force-control paper eq. 19-25, with intentional-contact paper's
//!   task-space force levels): ordered [`hierarchy::TaskLevel`]s and a posture torque in, joint
//!   torque out, with damped, rank-aware inverses.
//! - [`resolver`]: the admittance torque resolver (interactive-force-control paper eq. 26): torques to joint and base
//!   velocity commands within the limits.
//! - [`tasks`]: the tasks of both papers filling the hierarchy's levels (intentional-contact paper eq. 3-9,
//!   interactive-force-control paper eq. 4-18).
//! - [`supervisor`]: which arrangement of tasks is active (intentional-contact paper Table I, interactive-force-control paper Table 1)
//!   and the smooth switch between them (intentional-contact paper eq. 10-11).
#![warn(missing_docs)]

/// Defines `pub(crate) fn $name` calling `$kernel` compiled for AVX2 when the CPU has it (4
/// doubles per instruction instead of SSE2's 2; the same operations in the same order, so the
/// same results: Rust never fuses a multiply and an add by itself), else as compiled.
macro_rules! avx2_dispatch {
    ($(#[$doc:meta])* $name:ident => $kernel:ident($($arg:ident: $ty:ty),*) $(-> $ret:ty)?) => {
        $(#[$doc])*
        #[inline]
        pub(crate) fn $name($($arg: $ty),*) $(-> $ret)? {
            #[cfg(target_arch = "x86_64")]
            if std::arch::is_x86_feature_detected!("avx2") {
                #[target_feature(enable = "avx2")]
                unsafe fn avx2($($arg: $ty),*) $(-> $ret)? {
                    $kernel($($arg),*)
                }
                // SAFETY: the CPU supports AVX2 (checked above).
                return unsafe { avx2($($arg),*) };
            }
            $kernel($($arg),*)
        }
    };
}

pub mod controller;
pub mod hierarchy;
pub mod mesh;
pub mod model;
pub mod param_file;
pub mod params_doc;
pub mod resolver;
pub mod skin;
pub mod supervisor;
pub mod tasks;
