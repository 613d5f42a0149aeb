//! Value checks of a scene file that need no robot model: every error names the dotted key.

use super::spec::{
    BaseMotionSpec, ExpectSpec, LidarSpec, ObjectSpec, PersonSpec, PushSpec, SceneSpec, ShapeSpec, SkinSpec, ViewSpec,
};

/// A rejected value: its dotted key (e.g. `objects[2].shape.box.size_m`) and why.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Rejected {
    pub(crate) key: String,
    pub(crate) reason: String,
}

pub(crate) type Checked = Result<(), Rejected>;

pub(crate) fn reject(key: impl Into<String>, reason: impl Into<String>) -> Rejected {
    Rejected { key: key.into(), reason: reason.into() }
}

fn positive(key: impl Into<String>, v: f64) -> Checked {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(reject(key, format!("{v} must be finite and > 0")))
    }
}

fn non_negative(key: impl Into<String>, v: f64) -> Checked {
    if v.is_finite() && v >= 0.0 {
        Ok(())
    } else {
        Err(reject(key, format!("{v} must be finite and >= 0")))
    }
}

fn finite(key: impl Into<String>, values: &[f64]) -> Checked {
    match values.iter().find(|v| !v.is_finite()) {
        Some(v) => Err(reject(key, format!("{v} is not finite"))),
        None => Ok(()),
    }
}

/// A rate whose period is a whole number of integration steps (so that sampling instants are
/// exact and runs reproducible).
fn rate(key: &str, hz: f64, timestep_s: f64) -> Checked {
    positive(key, hz)?;
    let steps = 1.0 / (hz * timestep_s);
    if steps < 0.999_999 || (steps - steps.round()).abs() > 1e-6 {
        return Err(reject(key, format!("{hz} Hz: its period must be a whole number of timestep_s ({timestep_s} s)")));
    }
    Ok(())
}

fn check_view(view: &ViewSpec, control_rate_hz: f64) -> Checked {
    positive("view.fps", view.fps)?;
    if view.fps > control_rate_hz {
        return Err(reject("view.fps", format!("{} Hz: at most control_rate_hz ({control_rate_hz} Hz)", view.fps)));
    }
    if let Some(d) = view.distance_m {
        positive("view.distance_m", d)?;
    }
    finite("view.lookat_m", &view.lookat_m.unwrap_or_default())?;
    finite("view.azimuth_deg", &[view.azimuth_deg, view.elevation_deg])?;
    if !(-90.0..=90.0).contains(&view.elevation_deg) {
        return Err(reject("view.elevation_deg", format!("{}: within [-90, 90]", view.elevation_deg)));
    }
    Ok(())
}

/// Checks every value of `spec` that does not need the robot model.
pub(crate) fn check_values(spec: &SceneSpec) -> Checked {
    positive("duration_s", spec.duration_s)?;
    positive("timestep_s", spec.timestep_s)?;
    rate("control_rate_hz", spec.control_rate_hz, spec.timestep_s)?;
    finite("floor_z_m", &[spec.floor_z_m])?;
    check_view(&spec.view, spec.control_rate_hz)?;
    for (name, q) in &spec.robot.initial {
        finite(format!("robot.initial.{name}"), &[*q])?;
    }
    if let Some(skin) = &spec.skin {
        check_skin(skin, spec.timestep_s)?;
    }
    if let Some(lidar) = &spec.lidar {
        check_lidar(lidar, spec.timestep_s)?;
    }
    let mut names: Vec<&str> = Vec::new();
    for (i, o) in spec.objects.iter().enumerate() {
        check_object(&format!("objects[{i}]"), o)?;
        unique_name(&format!("objects[{i}].name"), &o.name, &mut names)?;
    }
    for (i, p) in spec.persons.iter().enumerate() {
        check_person(&format!("persons[{i}]"), p)?;
        unique_name(&format!("persons[{i}].name"), &p.name, &mut names)?;
    }
    for (i, p) in spec.pushes.iter().enumerate() {
        check_push(&format!("pushes[{i}]"), p, &spec.objects)?;
    }
    for (i, g) in spec.goals.iter().enumerate() {
        let key = format!("goals[{i}]");
        non_negative(format!("{key}.start_s"), g.start_s)?;
        finite(format!("{key}.position_m"), &g.position_m)?;
        finite(format!("{key}.rpy"), &g.rpy.unwrap_or_default())?;
    }
    for (i, f) in spec.force_references.iter().enumerate() {
        let key = format!("force_references[{i}]");
        non_negative(format!("{key}.start_s"), f.start_s)?;
        finite(format!("{key}.mean_n"), &[f.mean_n, f.amplitude_n])?;
        match f.period_s {
            Some(p) => positive(format!("{key}.period_s"), p)?,
            None if f.amplitude_n != 0.0 => {
                return Err(reject(format!("{key}.period_s"), "required when amplitude_n is not 0"))
            }
            None => {}
        }
    }
    if let Some(e) = &spec.expect {
        check_expect(e, spec)?;
    }
    for (i, m) in spec.base_motions.iter().enumerate() {
        check_base_motion(&format!("base_motions[{i}]"), m)?;
        if i > 0 && m.start_s < spec.base_motions[i - 1].end_s {
            return Err(reject(
                format!("base_motions[{i}].start_s"),
                "before the previous motion's end_s (list them in time order, not overlapping)",
            ));
        }
    }
    Ok(())
}

fn check_base_motion(key: &str, m: &BaseMotionSpec) -> Checked {
    positive(format!("{key}.ramp_s"), m.ramp_s)?;
    window(key, m.start_s, m.end_s, m.ramp_s)?;
    match (&m.circle, &m.swing) {
        (Some(c), None) => {
            positive(format!("{key}.circle.radius_m"), c.radius_m)?;
            positive(format!("{key}.circle.period_s"), c.period_s)
        }
        (None, Some(s)) => {
            positive(format!("{key}.swing.amplitude_m"), s.amplitude_m)?;
            positive(format!("{key}.swing.period_s"), s.period_s)?;
            finite(format!("{key}.swing.axis"), &s.axis)?;
            if s.axis[0].hypot(s.axis[1]) < 1e-9 {
                return Err(reject(format!("{key}.swing.axis"), "must not be zero"));
            }
            Ok(())
        }
        _ => Err(reject(key, "give exactly one of `circle` and `swing`")),
    }
}

fn unique_name<'a>(key: &str, name: &'a str, names: &mut Vec<&'a str>) -> Checked {
    if name.is_empty() {
        return Err(reject(key, "must not be empty"));
    }
    if names.contains(&name) {
        return Err(reject(key, format!("`{name}` is already the name of another object or person")));
    }
    names.push(name);
    Ok(())
}

fn check_skin(s: &SkinSpec, timestep_s: f64) -> Checked {
    rate("skin.rate_hz", s.rate_hz, timestep_s)?;
    positive("skin.contact_radius_m", s.contact_radius_m)?;
    positive("skin.cell_radius_m", s.cell_radius_m)?;
    non_negative("skin.proximity_noise_std", s.proximity_noise_std)?;
    non_negative("skin.force_noise_std", s.force_noise_std)
}

fn check_lidar(l: &LidarSpec, timestep_s: f64) -> Checked {
    if l.rays == 0 {
        return Err(reject("lidar.rays", "must be at least 1"));
    }
    if !(l.fov_deg > 0.0 && l.fov_deg <= 360.0) {
        return Err(reject("lidar.fov_deg", format!("{} must be in (0, 360]", l.fov_deg)));
    }
    positive("lidar.range_m", l.range_m)?;
    rate("lidar.rate_hz", l.rate_hz, timestep_s)?;
    non_negative("lidar.noise_std_m", l.noise_std_m)
}

fn check_object(key: &str, o: &ObjectSpec) -> Checked {
    finite(format!("{key}.xyz"), &o.xyz)?;
    finite(format!("{key}.rpy"), &o.rpy)?;
    if let Some(m) = o.mass_kg {
        positive(format!("{key}.mass_kg"), m)?;
    }
    non_negative(format!("{key}.friction"), o.friction)?;
    positive(format!("{key}.contact_time_constant_s"), o.contact_time_constant_s)?;
    let shape = format!("{key}.shape");
    match &o.shape {
        ShapeSpec::Box { size_m } => size_m.iter().try_for_each(|&s| positive(format!("{shape}.box.size_m"), s)),
        ShapeSpec::Cylinder { radius_m, length_m } => {
            positive(format!("{shape}.cylinder.radius_m"), *radius_m)?;
            positive(format!("{shape}.cylinder.length_m"), *length_m)
        }
        ShapeSpec::Sphere { radius_m } => positive(format!("{shape}.sphere.radius_m"), *radius_m),
        ShapeSpec::Capsule { radius_m, length_m } => {
            positive(format!("{shape}.capsule.radius_m"), *radius_m)?;
            positive(format!("{shape}.capsule.length_m"), *length_m)
        }
        ShapeSpec::Table { top_m, height_m, leg_radius_m } => {
            top_m.iter().try_for_each(|&s| positive(format!("{shape}.table.top_m"), s))?;
            positive(format!("{shape}.table.leg_radius_m"), *leg_radius_m)?;
            if !(height_m.is_finite() && *height_m > top_m[2]) {
                return Err(reject(
                    format!("{shape}.table.height_m"),
                    format!("{height_m} must exceed the top's thickness {}", top_m[2]),
                ));
            }
            if 2.0 * leg_radius_m >= top_m[0].min(top_m[1]) {
                return Err(reject(format!("{shape}.table.leg_radius_m"), "legs wider than the top"));
            }
            Ok(())
        }
    }
}

fn check_person(key: &str, p: &PersonSpec) -> Checked {
    positive(format!("{key}.radius_m"), p.radius_m)?;
    if !(p.height_m.is_finite() && p.height_m > 2.0 * p.radius_m) {
        return Err(reject(format!("{key}.height_m"), format!("{} must exceed twice radius_m", p.height_m)));
    }
    if p.path.is_empty() {
        return Err(reject(format!("{key}.path"), "needs at least one waypoint"));
    }
    for (k, w) in p.path.iter().enumerate() {
        let wkey = format!("{key}.path[{k}]");
        non_negative(format!("{wkey}.t_s"), w.t_s)?;
        finite(format!("{wkey}.xy_m"), &w.xy_m)?;
        if k > 0 && w.t_s <= p.path[k - 1].t_s {
            return Err(reject(format!("{wkey}.t_s"), "waypoint times must increase strictly"));
        }
    }
    Ok(())
}

/// A time window `[start_s, end_s)` from `start_s` >= 0 on, with room for the rise and the fall
/// of its (checked) `ramp_s`.
fn window(key: &str, start_s: f64, end_s: f64, ramp_s: f64) -> Checked {
    non_negative(format!("{key}.start_s"), start_s)?;
    if !(end_s.is_finite() && end_s > start_s) {
        return Err(reject(format!("{key}.end_s"), format!("{end_s} must be after start_s")));
    }
    if 2.0 * ramp_s > end_s - start_s {
        return Err(reject(
            format!("{key}.ramp_s"),
            format!("{ramp_s} s: the rise and the fall must fit in the window (at most half of it)"),
        ));
    }
    Ok(())
}

fn check_push(key: &str, p: &PushSpec, objects: &[ObjectSpec]) -> Checked {
    finite(format!("{key}.force_n"), &p.force_n)?;
    finite(format!("{key}.point_m"), &p.point_m)?;
    non_negative(format!("{key}.ramp_s"), p.ramp_s)?;
    if let Some(v) = p.max_speed_mps {
        positive(format!("{key}.max_speed_mps"), v)?;
    }
    window(key, p.start_s, p.end_s, p.ramp_s)?;
    match (&p.object, &p.link) {
        (Some(o), None) => {
            if !objects.iter().any(|x| &x.name == o) {
                return Err(reject(format!("{key}.object"), format!("no object named `{o}`")));
            }
            if objects.iter().any(|x| &x.name == o && x.mass_kg.is_none()) {
                return Err(reject(format!("{key}.object"), format!("`{o}` is fixed: give it a mass_kg")));
            }
            Ok(())
        }
        // The link is checked against the robot model by the loader.
        (None, Some(_)) => Ok(()),
        _ => Err(reject(key, "give exactly one of `object` and `link`")),
    }
}

fn check_expect(e: &ExpectSpec, spec: &SceneSpec) -> Checked {
    let needs_goals = |key: &str| match spec.goals.is_empty() {
        true => Err(reject(format!("expect.{key}"), "the scene has no goals")),
        false => Ok(()),
    };
    if let Some(t) = e.goal_tolerance_m {
        positive("expect.goal_tolerance_m", t)?;
        needs_goals("goal_tolerance_m")?;
    }
    if let Some(f) = e.eps_c_n {
        positive("expect.eps_c_n", f)?;
        needs_goals("eps_c_n")?;
    }
    if let Some(f) = e.max_contact_force_n {
        positive("expect.max_contact_force_n", f)?;
        needs_goals("max_contact_force_n")?;
    }
    if e.safety {
        needs_goals("safety")?;
    }
    if let Some(t) = &e.force_targets {
        positive("expect.force_targets.rms_without_n", t.rms_without_n)?;
        positive("expect.force_targets.rms_with_n", t.rms_with_n)?;
        if spec.force_references.is_empty() {
            return Err(reject("expect.force_targets", "the scene has no force_references"));
        }
    }
    Ok(())
}
