//! Where the task controller's URDF comes from: the file the controller setup names, a
//! `urdf_file` parameter, or the `robot_description` topic (`std_msgs/String`, transient local),
//! as robot_state_publisher publishes it and ROS 2 Jazzy's controllers take it.
//!
//! robot_state_publisher sees a mobile robot rooted at its base frame: TF gets the base's pose
//! from the base driver's `odom -> base_link` (REP 105). The controller models that pose with
//! three virtual joints (`skin_core::model::BASE_JOINTS`: prismatic x, prismatic y, revolute
//! yaw from the root `world`); [`mount_on_planar_base`] puts them back under such a URDF.
use std::path::Path;

use skin_core::model::RobotModel;
use skin_core::model::BASE_JOINTS;

/// The topic (relative in the node's namespace, as robot_state_publisher's).
pub const TOPIC: &str = "/robot_description";

/// Where the URDF comes from.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum UrdfSource {
    /// The file the controller setup names (`urdf`).
    Setup,
    /// The `urdf_file` parameter.
    File(String),
    /// The `robot_description` topic.
    Topic,
}

/// The source of the URDF from the node's settings: `urdf_file` (empty: not given),
/// `use_robot_description`, and the controller setup `setup` (whether it names a URDF). Giving
/// both `urdf_file` and the topic is an error, so is giving none of the three; the topic (`topic`,
/// resolved) replaces the setup's file.
pub fn choose(
    urdf_file: &str,
    use_topic: bool,
    setup_urdf: Option<&Path>,
    setup: &str,
    topic: &str,
) -> Result<UrdfSource, String> {
    match (urdf_file.is_empty(), use_topic) {
        (false, true) => Err(format!(
            "the URDF is given twice: urdf_file `{urdf_file}` and use_robot_description (topic {topic}): set only one"
        )),
        (false, false) => Ok(UrdfSource::File(urdf_file.to_string())),
        (true, true) => Ok(UrdfSource::Topic),
        (true, false) if setup_urdf.is_some() => Ok(UrdfSource::Setup),
        (true, false) => Err(format!(
            "no URDF given: the controller setup {setup} names no `urdf` and the parameter urdf_file is empty; \
             set urdf_file, or use_robot_description:=true to take it from {topic} (robot_state_publisher publishes it)"
        )),
    }
}

/// The robot's model from the text received on `topic`; `mobile_base`: the URDF is rooted at
/// the base frame and gets the virtual planar base ([`mount_on_planar_base`]). Errors name the
/// topic.
pub fn model(xml: &str, topic: &str, mobile_base: bool) -> Result<RobotModel, String> {
    let mounted;
    let xml = if mobile_base {
        mounted = mount_on_planar_base(xml).map_err(|e| format!("{topic} (mobile_base: true): {e}"))?;
        &mounted
    } else {
        xml
    };
    RobotModel::from_urdf_str(xml, topic).map_err(|e| format!("{topic}: invalid URDF: {e}"))
}

/// `xml` with the virtual planar base under its root link: `world -> base_x_link -> base_y_link
/// -> <root>` through [`BASE_JOINTS`] (the virtual carriages' small masses, axes and limits of
/// `urdf/tomm.urdf`). A URDF that already has the three joints is returned as it is; one with
/// only some of them, or with a link of the names added, is an error.
pub fn mount_on_planar_base(xml: &str) -> Result<String, String> {
    let doc = roxmltree::Document::parse(xml).map_err(|e| format!("not XML: {e}"))?;
    let robot = doc.root_element();
    if robot.tag_name().name() != "robot" {
        return Err(format!("the root element is <{}>, not <robot>", robot.tag_name().name()));
    }
    let named =
        |tag: &'static str| robot.children().filter(move |n| n.has_tag_name(tag)).filter_map(|n| n.attribute("name"));
    let have: Vec<&str> = named("joint").filter(|j| BASE_JOINTS.contains(j)).collect();
    if have.len() == BASE_JOINTS.len() {
        return Ok(xml.to_string());
    }
    if !have.is_empty() {
        return Err(format!("has the base joints {have:?} but not all of {BASE_JOINTS:?}"));
    }
    let children: Vec<&str> = robot
        .children()
        .filter(|n| n.has_tag_name("joint"))
        .filter_map(|j| j.children().find(|c| c.has_tag_name("child")).and_then(|c| c.attribute("link")))
        .collect();
    let roots: Vec<&str> = named("link").filter(|l| !children.contains(l)).collect();
    let [root] = roots[..] else {
        return Err(format!("needs exactly one root link to mount on the planar base, has {roots:?}"));
    };
    if let Some(clash) = named("link").find(|l| PLANAR_LINKS.contains(l)) {
        return Err(format!("already has a link `{clash}` (root `{root}`): not a URDF rooted at the base frame"));
    }
    let at = robot.first_child().map(|c| c.range().start).ok_or("<robot> is empty")?;
    let [x, y, yaw] = BASE_JOINTS;
    let [world, x_link, y_link] = PLANAR_LINKS;
    let carriage = |link: &str| {
        format!(
            "<link name=\"{link}\"><inertial><origin xyz=\"0 0 0\" rpy=\"0 0 0\"/><mass value=\"1\"/>\
             <inertia ixx=\"0.01\" ixy=\"0\" ixz=\"0\" iyy=\"0.01\" iyz=\"0\" izz=\"0.01\"/></inertial></link>"
        )
    };
    let joint = |name: &str, kind: &str, parent: &str, child: &str, axis: &str, limit: &str| {
        format!(
            "<joint name=\"{name}\" type=\"{kind}\"><parent link=\"{parent}\"/><child link=\"{child}\"/>\
             <origin xyz=\"0 0 0\" rpy=\"0 0 0\"/><axis xyz=\"{axis}\"/><limit {limit}/></joint>"
        )
    };
    let linear = "lower=\"-100\" upper=\"100\" velocity=\"1\" effort=\"1000\"";
    let planar = [
        format!("\n  <!-- virtual planar base (skin_control: mobile_base) -->\n  <link name=\"{world}\"/>"),
        carriage(x_link),
        joint(x, "prismatic", world, x_link, "1 0 0", linear),
        carriage(y_link),
        joint(y, "prismatic", x_link, y_link, "0 1 0", linear),
        joint(
            yaw,
            "revolute",
            y_link,
            root,
            "0 0 1",
            "lower=\"-6.283185307179586\" upper=\"6.283185307179586\" velocity=\"1\" effort=\"500\"",
        ),
    ];
    Ok(format!("{}{}\n{}", &xml[..at], planar.join("\n  "), &xml[at..]))
}

/// The links of the virtual planar base: the fixed root and the two carriages.
const PLANAR_LINKS: [&str; 3] = ["world", "base_x_link", "base_y_link"];

#[cfg(test)]
mod tests {
    use super::*;
    use skin_core::model::{frame_pose, update_kinematics, ModelData};

    fn tomm() -> String {
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../urdf/tomm.urdf")).unwrap()
    }

    /// urdf/tomm.urdf as robot_state_publisher gets it (launch/skin_control_launch.py's
    /// mounted_description): without the planar base's links and joints.
    fn rooted_at_base_link(xml: &str) -> String {
        let doc = roxmltree::Document::parse(xml).unwrap();
        let mut drop: Vec<_> = doc
            .root_element()
            .children()
            .filter(|n| {
                n.attribute("name").is_some_and(|name| PLANAR_LINKS.contains(&name) || BASE_JOINTS.contains(&name))
            })
            .map(|n| n.range())
            .collect();
        assert_eq!(drop.len(), 6);
        drop.sort_by_key(|r| std::cmp::Reverse(r.start));
        let mut out = xml.to_string();
        for r in drop {
            out.replace_range(r, "");
        }
        out
    }

    #[test]
    fn a_urdf_rooted_at_the_base_gets_back_the_model_of_the_full_one() {
        let full = RobotModel::from_urdf_str(&tomm(), "tomm.urdf").unwrap();
        let rooted = rooted_at_base_link(&tomm());
        let bare = RobotModel::from_urdf_str(&rooted, "rooted").unwrap();
        assert_eq!(bare.nv(), full.nv() - 3, "the base joints are gone");
        let m = model(&rooted, "/robot_description", true).unwrap();
        assert_eq!(m.joint_names(), full.joint_names());
        // the same kinematics at a pose that moves the base and every arm joint
        let q: Vec<f64> = (0..full.nv()).map(|k| 0.1 + 0.07 * k as f64).collect();
        let qd = vec![0.0; full.nv()];
        let (mut a, mut b) = (ModelData::new(&full), ModelData::new(&m));
        update_kinematics(&full, &mut a, &q, &qd).unwrap();
        update_kinematics(&m, &mut b, &q, &qd).unwrap();
        for frame in ["base_link", "laser", "right_hand", "left_hand"] {
            let (i, j) = (full.frame_index(frame).unwrap(), m.frame_index(frame).unwrap());
            let d = frame_pose(&a, i).inverse() * frame_pose(&b, j);
            assert!(d.translation.vector.norm() < 1e-12 && d.rotation.angle() < 1e-12, "{frame}: {d}");
        }
        assert_eq!(mount_on_planar_base(&tomm()).unwrap(), tomm(), "a full URDF stays as it is");
    }

    #[test]
    fn bad_descriptions_are_refused_naming_the_topic() {
        let e = model("<robot name=\"r\"><link name=\"a\"/>", "/ns/robot_description", false).unwrap_err();
        assert!(e.starts_with("/ns/robot_description: invalid URDF"), "{e}");
        let e = model("not xml", "/robot_description", true).unwrap_err();
        assert!(e.contains("/robot_description (mobile_base: true): not XML"), "{e}");
        let planar7 =
            std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../urdf/planar7.urdf")).unwrap();
        let e = mount_on_planar_base(&planar7).unwrap_err();
        assert!(e.contains("already has a link `world`"), "{e}");
        let two_roots = "<robot name=\"r\"><link name=\"a\"/><link name=\"b\"/></robot>";
        assert!(mount_on_planar_base(two_roots).unwrap_err().contains("exactly one root link"));
    }

    #[test]
    fn the_urdf_is_given_once() {
        let setup = Some(Path::new("tomm.urdf"));
        let choose = |file: &str, topic: bool, setup| choose(file, topic, setup, "s.yaml", "/robot_description");
        assert_eq!(choose("", false, setup), Ok(UrdfSource::Setup));
        assert_eq!(choose("r.urdf", false, None), Ok(UrdfSource::File("r.urdf".into())));
        assert_eq!(choose("", true, setup), Ok(UrdfSource::Topic), "the topic replaces the setup's file");
        let both = choose("r.urdf", true, None).unwrap_err();
        assert!(both.contains("given twice") && both.contains("/robot_description"), "{both}");
        let neither = choose("", false, None).unwrap_err();
        assert!(neither.contains("no URDF given") && neither.contains("s.yaml"), "{neither}");
    }
}
