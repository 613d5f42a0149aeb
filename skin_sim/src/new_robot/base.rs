//! A planar mobile base for a URDF that has none as joints (a Tiago's base moves on wheels):
//! `base_x_joint` and `base_y_joint` (prismatic along world x and y) and `base_yaw_joint`
//! (continuous about z) put in front of the URDF's root link, the joints
//! `skin_core::model::BASE_JOINTS` the controller and the simulator move a base with.

use std::path::Path;

use skin_core::model::BASE_JOINTS;

/// Mass \[kg\] and inertia \[kg m²\] of each of the two links between the joints (a moving body
/// needs some; the base's admittance, not these, sets how it moves).
const LINK_MASS_KG: f64 = 1.0;
const LINK_INERTIA: f64 = 0.01;

/// `urdf` (the text of the file `path`) with the planar base joints in front of its root link,
/// and relative mesh file names made absolute (the result is written elsewhere). Errors name
/// the file.
pub fn with_planar_base(urdf: &str, path: &Path) -> Result<String, String> {
    let file = path.display();
    let doc = roxmltree::Document::parse(urdf).map_err(|e| format!("{file}: {e}"))?;
    let robot = doc.root_element();
    let children: Vec<&str> = robot
        .children()
        .filter(|n| n.has_tag_name("joint"))
        .filter_map(|j| j.children().find(|c| c.has_tag_name("child"))?.attribute("link"))
        .collect();
    let roots: Vec<&str> = robot
        .children()
        .filter(|n| n.has_tag_name("link"))
        .filter_map(|l| l.attribute("name"))
        .filter(|l| !children.contains(l))
        .collect();
    let [root] = roots.as_slice() else {
        return Err(format!("{file}: {} root links {roots:?}, expected one", roots.len()));
    };
    let names = robot.children().filter_map(|n| n.attribute("name")).collect::<Vec<_>>();
    if let Some(taken) = ["skin_setup_odom", "skin_setup_base_x", "skin_setup_base_y"]
        .into_iter()
        .chain(BASE_JOINTS)
        .find(|n| names.contains(n))
    {
        return Err(format!("{file}: already has an element named `{taken}`"));
    }
    let inertial = format!(
        "<inertial><mass value=\"{LINK_MASS_KG}\"/><inertia ixx=\"{LINK_INERTIA}\" iyy=\"{LINK_INERTIA}\" izz=\"{LINK_INERTIA}\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/></inertial>"
    );
    let [x, y, yaw] = BASE_JOINTS;
    let base = format!(
        r#"
  <!-- planar base joints added by skin_setup, option mobile-base -->
  <link name="skin_setup_odom"/>
  <joint name="{x}" type="prismatic"><parent link="skin_setup_odom"/><child link="skin_setup_base_x"/><axis xyz="1 0 0"/><limit lower="-100" upper="100" velocity="0.5" effort="1000"/></joint>
  <link name="skin_setup_base_x">{inertial}</link>
  <joint name="{y}" type="prismatic"><parent link="skin_setup_base_x"/><child link="skin_setup_base_y"/><axis xyz="0 1 0"/><limit lower="-100" upper="100" velocity="0.5" effort="1000"/></joint>
  <link name="skin_setup_base_y">{inertial}</link>
  <joint name="{yaw}" type="continuous"><parent link="skin_setup_base_y"/><child link="{root}"/><axis xyz="0 0 1"/><limit velocity="0.8" effort="500"/></joint>
"#
    );
    // After the opening <robot ...> tag.
    let open = robot.range().start;
    let end = open + urdf[open..].find('>').ok_or_else(|| format!("{file}: unterminated <robot>"))? + 1;
    let mut out = format!("{}{base}{}", &urdf[..end], &urdf[end..]);
    // Relative mesh file names: relative to the original file's directory.
    let dir = std::path::absolute(path.parent().unwrap_or(Path::new("."))).map_err(|e| format!("{file}: {e}"))?;
    for m in robot.descendants().filter(|n| n.has_tag_name("mesh")) {
        let Some(f) = m.attribute("filename") else { continue };
        if !f.contains("://") && !Path::new(f).is_absolute() {
            out = out.replace(&format!("filename=\"{f}\""), &format!("filename=\"{}\"", dir.join(f).display()));
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use skin_core::model::RobotModel;

    #[test]
    fn adds_the_base_joints_in_front_of_the_root() {
        let urdf = r#"<robot name="r"><link name="a"><collision><geometry><mesh filename="meshes/a.stl"/></geometry></collision></link>
            <joint name="j" type="revolute"><parent link="a"/><child link="b"/><axis xyz="1 0 0"/><limit lower="-1" upper="1" velocity="1" effort="1"/></joint>
            <link name="b"><inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link></robot>"#;
        let out = with_planar_base(urdf, Path::new("/robots/r.urdf")).unwrap();
        assert!(out.contains("filename=\"/robots/meshes/a.stl\""), "{out}");
        let m = RobotModel::from_urdf_str(&out, "r").unwrap();
        assert_eq!(m.joint_names(), ["base_x_joint", "base_y_joint", "base_yaw_joint", "j"]);
        let e = with_planar_base(&out, Path::new("/robots/r.urdf")).unwrap_err();
        assert!(e.contains("already has") && e.contains("r.urdf"), "{e}");
    }
}
