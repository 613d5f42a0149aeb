//! The two papers' signal figures as ready-made layouts over plain slices.

use super::figure::{intervals_where, Figure, Panel, Tint};

/// Signals of an intentional-contact paper run, laid out like its Figs. 3, 7 and 8; one sample per control cycle,
/// every slice as long as `t`.
#[derive(Debug, Clone, Copy)]
pub struct IntentionalContactSignals<'a> {
    /// Time \[s\].
    pub t: &'a [f64],
    /// Active arrangement of Table I per sample: 0 = (a) avoidance first, 1 = (b) intentional
    /// contact, 2 = (c) hard contact (`Arrangement.MODE_*`).
    pub arrangement: &'a [usize],
    /// End-effector speed ||x_dot|| \[m/s\].
    pub ee_speed: &'a [f64],
    /// Speed threshold eps_v of a local minimum \[m/s\].
    pub eps_v: f64,
    /// Proximity (avoidance) force at the closest point ||F_d|| \[N\].
    pub avoidance_force: &'a [f64],
    /// Largest contact force ||F_c|| \[N\].
    pub contact_force: &'a [f64],
    /// Permitted contact force eps_c \[N\].
    pub eps_c: f64,
    /// Norm of the commanded torque ||tau|| \[N m\].
    pub torque_norm: &'a [f64],
    /// Scripted external pushes `(start, end)` \[s\], on objects (the hard-contact scenario) or
    /// on the robot, shaded.
    pub pushes: &'a [(f64, f64)],
    /// Per sample: the arm holds blocked after a push given up (`docs/supervisor.md`).
    pub blocked: &'a [bool],
}

/// Intentional-contact paper's figure: (a) arrangement, (b) end-effector speed with eps_v, (c) proximity force,
/// (d) contact force with eps_c, (e) torque norm; intentional-contact periods (arrangement (b)),
/// blocked holds and pushes shaded.
pub fn intentional_contact_figure(title: &str, s: &IntentionalContactSignals) -> Figure {
    let t = s.t;
    let contact: Vec<bool> = s.arrangement.iter().map(|&a| a == 1).collect();
    let fig = Figure::new(title)
        .panel(Panel::steps(
            "(a) Priority arrangement (Table I)",
            "arrangement",
            &["(a)", "(b)", "(c)"],
            t,
            s.arrangement,
        ))
        .panel(
            Panel::lines("(b) End-effector speed", "speed [m/s]")
                .line("||x_dot||", t, s.ee_speed)
                .threshold("eps_v", s.eps_v),
        )
        .panel(Panel::lines("(c) Proximity force at the closest point", "force [N]").line(
            "||F_d||",
            t,
            s.avoidance_force,
        ))
        .panel(
            Panel::lines("(d) Largest contact force", "force [N]")
                .line("||F_c||", t, s.contact_force)
                .threshold("eps_c", s.eps_c),
        )
        .panel(Panel::lines("(e) Torque norm", "torque [N m]").line("||tau||", t, s.torque_norm));
    fig.shade_all(&intervals_where(t, &contact), "intentional contact", Tint::Green)
        .shade_all(&intervals_where(t, s.blocked), "blocked hold", Tint::Gray)
        .shade_all(s.pushes, "external push", Tint::Red)
}

/// Signals of an interactive-force-control paper force experiment, laid out like its Figs. 5, 7 and 8; one sample per
/// control cycle, every slice as long as `t`.
#[derive(Debug, Clone, Copy)]
pub struct ForceTrackingSignals<'a> {
    /// Time \[s\].
    pub t: &'a [f64],
    /// Desired normal hand force \[N\].
    pub force_desired: &'a [f64],
    /// Measured normal hand force \[N\].
    pub force_measured: &'a [f64],
    /// State machine phase per sample (Table 1): 0 = pre-contact, 1 = contact.
    pub phase: &'a [usize],
    /// Force/proximity fusion weight w of eq. 6, \[0, 1\].
    pub fusion_weight: &'a [f64],
    /// Mobile-base speed \[m/s\].
    pub base_speed: &'a [f64],
    /// Tactile guidance periods `(start, end)` \[s\] (green in the paper).
    pub tactile: &'a [(f64, f64)],
    /// Scripted interaction periods `(start, end)` \[s\]: touches on the arm, a person near the
    /// base (red, as the paper marks base collision avoidance).
    pub interaction: &'a [(f64, f64)],
}

/// Interactive-force-control paper's figure: (a) desired and measured hand force, (b) force error with its RMS over
/// the contact phase (the measure of Table 3), (c) phase, (d) fusion weight, (e) base speed;
/// tactile and base-avoidance periods shaded.
pub fn force_tracking_figure(title: &str, s: &ForceTrackingSignals) -> Figure {
    let t = s.t;
    let error: Vec<f64> = s.force_measured.iter().zip(s.force_desired).map(|(m, d)| m - d).collect();
    let in_contact = error.iter().zip(s.phase).filter(|(_, &p)| p == 1).map(|(e, _)| e * e);
    let (sum, n) = in_contact.fold((0.0, 0usize), |(sum, n), e2| (sum + e2, n + 1));
    let error_title = match n {
        0 => "(b) Force error".to_string(),
        _ => format!("(b) Force error (RMS in contact {:.3} N)", (sum / n as f64).sqrt()),
    };
    let fig = Figure::new(title)
        .panel(
            Panel::lines("(a) Hand force", "force [N]")
                .line("measured", t, s.force_measured)
                // Drawn last: the reference stays visible over the measurement.
                .line("desired", t, s.force_desired),
        )
        .panel(Panel::lines(&error_title, "error [N]").line("measured - desired", t, &error))
        .panel(Panel::steps("(c) Phase (Table 1)", "phase", &["pre-contact", "contact"], t, s.phase))
        .panel(Panel::lines("(d) Fusion weight (eq. 6)", "w [-]").line("w", t, s.fusion_weight))
        .panel(Panel::lines("(e) Mobile-base speed", "speed [m/s]").line("||v_b||", t, s.base_speed));
    fig.shade_all(s.tactile, "tactile guidance", Tint::Green).shade_all(
        s.interaction,
        "interaction (touch, person)",
        Tint::Red,
    )
}

/// Signals of interactive-force-control paper's Exp. 2 (pre-contact approach and tactile guidance), laid out like its
/// Fig. 6; one sample per control cycle, every slice as long as `t`.
#[derive(Debug, Clone, Copy)]
pub struct GuidanceSignals<'a> {
    /// Time \[s\].
    pub t: &'a [f64],
    /// Distance `d_p` of the hand to the surface ahead of the palm \[m\] (NaN: nothing ahead).
    pub distance: &'a [f64],
    /// `d_p,d` \[m\].
    pub distance_desired: &'a [f64],
    /// `ʰΓ`, the hand skin's moment in the hand frame, x, y, z (NaN: not recorded).
    pub moment: [&'a [f64]; 3],
    /// Hand position in the world, x, y, z \[m\].
    pub hand: [&'a [f64]; 3],
    /// Base position in the world, x, y \[m\].
    pub base: [&'a [f64]; 2],
    /// Scripted interaction periods `(start, end)` \[s\]: touches on the arm, a person near the
    /// base.
    pub interaction: &'a [(f64, f64)],
}

/// Interactive-force-control paper Fig. 6: (a) the hand's distance to the surface against `d_p,d`, (b) the skin
/// moments `ʰΓ` the compliant wrist drives to zero (left out when not recorded: runs through the
/// ROS graph), (c) the hand's position (guided along the surface by the touches), (d) the base's
/// position (moved by base collision avoidance); interaction periods shaded.
pub fn guidance_figure(title: &str, s: &GuidanceSignals) -> Figure {
    let t = s.t;
    let mut fig = Figure::new(title).panel(
        Panel::lines("(a) Hand distance to the surface", "d_p [m]").line("measured", t, s.distance).line(
            "desired",
            t,
            s.distance_desired,
        ),
    );
    if s.moment.iter().any(|m| m.iter().any(|v| v.is_finite())) {
        fig = fig.panel(
            Panel::lines("(b) Skin moments at the hand", "h_Gamma [m]")
                .line("x", t, s.moment[0])
                .line("y", t, s.moment[1])
                .line("z", t, s.moment[2]),
        );
    }
    fig = fig
        .panel(
            Panel::lines("(c) Hand position", "w_x_h [m]")
                .line("x", t, s.hand[0])
                .line("y", t, s.hand[1])
                .line("z", t, s.hand[2]),
        )
        .panel(Panel::lines("(d) Base position", "w_x_b [m]").line("x", t, s.base[0]).line("y", t, s.base[1]));
    fig.shade_all(s.interaction, "interaction (touch, person)", Tint::Red)
}
