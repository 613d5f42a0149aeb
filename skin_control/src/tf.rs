//! TF out (`/tf`, `/tf_static`: tf2_msgs/TFMessage), as a robot's drivers publish it (REP 105):
//! the simulator sends `world -> odom` (fixed) and `odom -> base_link` (the base driver's
//! transform), the aggregator the skin patch frames `<link> -> skin_patch_<id>` (fixed).
//!
//! tf2_msgs is not among the ROS 2 wheels: r2r generates it only when it is installed (a robot's
//! /opt/ros/jazzy; here scripts/bootstrap with ROS2_PYTHON_TOOLS), which `build.rs` detects as
//! `cfg(tf2_msgs)`. Built without it, [`TfPublisher::new`] says why there is no TF.
use nalgebra::Isometry3;
use r2r::builtin_interfaces::msg::Time;

/// The world frame (the root link of the URDFs; the scenes' goals are given in it). The
/// controller's world is the odometry frame: its base joints are the odometry pose.
pub const WORLD_FRAME: &str = "world";
/// The odometry frame of `/base/odom` (REP 105).
pub const ODOM_FRAME: &str = "odom";
/// The base frame of a robot with a base: the child of [`ODOM_FRAME`] in `/base/odom` and TF.
pub const BASE_FRAME: &str = "base_link";

/// One transform: the pose of `child` in `parent`.
#[derive(Debug, Clone, PartialEq)]
pub struct FrameTransform {
    /// Parent frame.
    pub parent: String,
    /// Child frame.
    pub child: String,
    /// Pose of the child frame in the parent frame.
    pub pose: Isometry3<f64>,
}

#[cfg(tf2_msgs)]
mod imp {
    use super::*;
    use crate::topics::{TF, TF_STATIC};
    use r2r::geometry_msgs::msg::{Quaternion, Transform, TransformStamped, Vector3};
    use r2r::tf2_msgs::msg::TFMessage;

    pub struct Publishers {
        pub dynamic: r2r::Publisher<TFMessage>,
        pub fixed: r2r::Publisher<TFMessage>,
    }

    pub fn publishers(node: &mut r2r::Node) -> r2r::Result<Publishers> {
        Ok(Publishers {
            dynamic: node.create_publisher(TF, crate::qos::stream().keep_last(100))?,
            // tf2's static broadcaster: reliable, transient local, keep last 1.
            fixed: node.create_publisher(TF_STATIC, crate::qos::latched())?,
        })
    }

    pub fn message(transforms: &[FrameTransform], stamp: &Time) -> TFMessage {
        let transforms = transforms
            .iter()
            .map(|t| {
                let mut m = TransformStamped::default();
                m.header.stamp = stamp.clone();
                m.header.frame_id.clone_from(&t.parent);
                m.child_frame_id.clone_from(&t.child);
                let v = t.pose.translation.vector;
                let r = t.pose.rotation.coords; // (i, j, k, w)
                m.transform = Transform {
                    translation: Vector3 { x: v.x, y: v.y, z: v.z },
                    rotation: Quaternion { x: r.x, y: r.y, z: r.z, w: r.w },
                };
                m
            })
            .collect();
        TFMessage { transforms }
    }
}

/// The `/tf` and `/tf_static` publishers of a node.
pub struct TfPublisher {
    #[cfg(tf2_msgs)]
    pubs: imp::Publishers,
    /// Built without tf2_msgs there is no value of this type.
    #[cfg(not(tf2_msgs))]
    never: std::convert::Infallible,
}

impl TfPublisher {
    /// The publishers; `Ok(Err(reason))` when this build has no tf2_msgs.
    pub fn new(node: &mut r2r::Node) -> r2r::Result<Result<Self, &'static str>> {
        #[cfg(tf2_msgs)]
        {
            Ok(Ok(TfPublisher { pubs: imp::publishers(node)? }))
        }
        #[cfg(not(tf2_msgs))]
        {
            let _ = node;
            Ok(Err("built without tf2_msgs (install ROS 2 Jazzy's tf2_msgs, or run scripts/bootstrap with ROS2_PYTHON_TOOLS set, and rebuild): no /tf, /tf_static"))
        }
    }

    /// Sends `transforms` on `/tf_static` (latched: send them all in one message, once).
    pub fn send_static(&self, transforms: &[FrameTransform], stamp: &Time) -> r2r::Result<()> {
        #[cfg(tf2_msgs)]
        return self.pubs.fixed.publish(&imp::message(transforms, stamp));
        #[cfg(not(tf2_msgs))]
        {
            let _ = (transforms, stamp);
            match self.never {}
        }
    }

    /// Sends `transforms` on `/tf`, stamped `stamp`.
    pub fn send(&self, transforms: &[FrameTransform], stamp: &Time) -> r2r::Result<()> {
        #[cfg(tf2_msgs)]
        return self.pubs.dynamic.publish(&imp::message(transforms, stamp));
        #[cfg(not(tf2_msgs))]
        {
            let _ = (transforms, stamp);
            match self.never {}
        }
    }
}

#[cfg(all(test, tf2_msgs))]
mod tests {
    use super::*;
    use nalgebra::{Translation3, UnitQuaternion};

    #[test]
    fn transforms_become_stamped_messages() {
        let pose =
            Isometry3::from_parts(Translation3::new(1.0, 2.0, 0.0), UnitQuaternion::from_euler_angles(0.0, 0.0, 0.5));
        let t = FrameTransform { parent: "odom".into(), child: "base_link".into(), pose };
        let m = imp::message(&[t], &Time { sec: 3, nanosec: 4 });
        let ts = &m.transforms[0];
        assert_eq!(
            (ts.header.frame_id.as_str(), ts.child_frame_id.as_str(), ts.header.stamp.sec),
            ("odom", "base_link", 3)
        );
        assert_eq!((ts.transform.translation.x, ts.transform.translation.y), (1.0, 2.0));
        assert!(
            (ts.transform.rotation.z - 0.25f64.sin()).abs() < 1e-15
                && (ts.transform.rotation.w - 0.25f64.cos()).abs() < 1e-15
        );
    }
}
