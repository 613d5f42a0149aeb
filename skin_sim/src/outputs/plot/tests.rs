use std::path::{Path, PathBuf};

use super::*;

/// A synthetic 20 s paper-000 run at 100 Hz: a local minimum at 6 s, intentional contact until
/// 12 s, a push 14-15 s that forces arrangement (c).
fn intentional_contact_run() -> Figure {
    let t: Vec<f64> = (0..2001).map(|k| k as f64 * 0.01).collect();
    let arrangement: Vec<usize> = t
        .iter()
        .map(|&t| {
            if (6.0..12.0).contains(&t) {
                1
            } else if (14.0..15.5).contains(&t) {
                2
            } else {
                0
            }
        })
        .collect();
    let speed: Vec<f64> = t.iter().map(|t| 0.2 * (-t / 3.0).exp() + 0.01 * (3.0 * t).sin().abs()).collect();
    let prox: Vec<f64> = t.iter().map(|t| 4.0 * (-(t - 5.0) * (t - 5.0)).exp()).collect();
    let contact: Vec<f64> = t.iter().map(|&t| if (7.0..12.0).contains(&t) { 3.0 } else { 0.0 }).collect();
    let torque: Vec<f64> = t.iter().map(|t| 10.0 + 5.0 * (0.5 * t).cos()).collect();
    let blocked: Vec<bool> = t.iter().map(|&t| (12.5..14.0).contains(&t)).collect();
    let signals = IntentionalContactSignals {
        t: &t,
        arrangement: &arrangement,
        ee_speed: &speed,
        eps_v: 0.02,
        avoidance_force: &prox,
        contact_force: &contact,
        eps_c: 5.0,
        torque_norm: &torque,
        pushes: &[(14.0, 15.0)],
        blocked: &blocked,
    };
    intentional_contact_figure("synthetic intentional-contact paper run", &signals)
}

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("skin_sim_plot_{name}_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn png_has_the_expected_size_and_is_deterministic() {
    let fig = intentional_contact_run();
    assert_eq!(fig.pixel_size(), (1000, 36 + 5 * 190));
    let dir = temp_dir("png");
    let (a, b) = (dir.join("a.png"), dir.join("b.png"));
    fig.save_png(&a).unwrap();
    fig.save_png(&b).unwrap();
    let bytes = std::fs::read(&a).unwrap();
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
    // IHDR: width and height, big endian, right after the chunk length and type.
    let width = u32::from_be_bytes(bytes[16..20].try_into().unwrap());
    let height = u32::from_be_bytes(bytes[20..24].try_into().unwrap());
    assert_eq!((width, height), fig.pixel_size());
    assert_eq!(bytes, std::fs::read(&b).unwrap(), "two renders differ");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn pixels_show_lines_text_and_shading() {
    let rgb = intentional_contact_run().render_rgb().unwrap();
    let pixels: Vec<&[u8]> = rgb.chunks(3).collect();
    let share = |f: &dyn Fn(&[u8]) -> bool| pixels.iter().filter(|p| f(p)).count() as f64 / pixels.len() as f64;
    let white = share(&|p| p.iter().all(|&c| c == 255));
    // Text, axes and thresholds; the signal lines.
    let dark = share(&|p| p.iter().all(|&c| c < 80));
    let blue = share(&|p| p[2] > 150 && p[0] < 80);
    // The shading: light green, well above red and blue.
    let green_tint = share(&|p| {
        let [r, g, b] = [p[0], p[1], p[2]].map(i32::from);
        g > 200 && g > r + 10 && g > b + 10
    });
    assert!((0.3..0.97).contains(&white), "white share {white}");
    assert!(dark > 0.002, "dark share {dark}");
    assert!(blue > 0.002, "blue share {blue}");
    assert!(green_tint > 0.01, "green tint share {green_tint}");
}

#[test]
fn svg_carries_the_panel_titles() {
    let dir = temp_dir("svg");
    let path = dir.join("fig.svg");
    intentional_contact_run().save_svg(&path).unwrap();
    let svg = std::fs::read_to_string(&path).unwrap();
    assert!(svg.starts_with("<svg"));
    assert!(svg.contains("(d) Largest contact force") && svg.contains("eps_c"));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn force_tracking_layout_reports_the_contact_rms_error() {
    let t: Vec<f64> = (0..1000).map(|k| k as f64 * 0.01).collect();
    let phase: Vec<usize> = t.iter().map(|&t| usize::from(t >= 3.0)).collect();
    let desired: Vec<f64> = t.iter().map(|&t| if t >= 3.0 { 5.0 + 2.0 * (t * 1.57).sin() } else { 0.0 }).collect();
    // Contact error alternates +-0.25 N: RMS 0.25.
    let measured: Vec<f64> = desired
        .iter()
        .zip(&phase)
        .enumerate()
        .map(|(k, (d, &p))| d + if p == 1 { 0.25 * (-1f64).powi(k as i32) } else { 0.0 })
        .collect();
    let w: Vec<f64> = phase.iter().map(|&p| p as f64).collect();
    let base: Vec<f64> = t.iter().map(|t| 0.1 * t.sin().abs()).collect();
    let fig = force_tracking_figure(
        "synthetic force tracking",
        &ForceTrackingSignals {
            t: &t,
            force_desired: &desired,
            force_measured: &measured,
            phase: &phase,
            fusion_weight: &w,
            base_speed: &base,
            tactile: &[(4.0, 5.0)],
            interaction: &[(6.0, 7.5)],
        },
    );
    assert!(fig.panels[1].title.contains("RMS in contact 0.250 N"), "{}", fig.panels[1].title);
    assert!(fig.render_rgb().unwrap().iter().any(|&c| c != 255));
}

#[test]
fn the_guidance_figure_has_paper_003_fig_6_panels() {
    let t: Vec<f64> = (0..200).map(|k| k as f64 * 0.05).collect();
    let d: Vec<f64> = t.iter().map(|t| 0.03 + 0.02 * (-t).exp()).collect();
    let x: Vec<f64> = t.iter().map(|t| 0.8 + 0.01 * t).collect();
    let m: Vec<f64> = t.iter().map(|t| 0.2 * (-t).exp()).collect();
    let signals = GuidanceSignals {
        t: &t,
        distance: &d,
        distance_desired: &[0.03; 200],
        moment: [&m, &m, &m],
        hand: [&x, &x, &x],
        base: [&x, &x],
        interaction: &[(2.0, 4.0)],
    };
    let fig = guidance_figure("synthetic guidance", &signals);
    let titles: Vec<&str> = fig.panels.iter().map(|p| p.title.as_str()).collect();
    assert_eq!(
        titles,
        ["(a) Hand distance to the surface", "(b) Skin moments at the hand", "(c) Hand position", "(d) Base position"]
    );
    assert!(fig.render_rgb().unwrap().iter().any(|&c| c != 255));
    // a run through the ROS graph has no moments: the panel is left out, the others keep the paper's letters
    let none = [f64::NAN; 200];
    let fig = guidance_figure("synthetic guidance", &GuidanceSignals { moment: [&none, &none, &none], ..signals });
    let titles: Vec<&str> = fig.panels.iter().map(|p| p.title.as_str()).collect();
    assert_eq!(titles, ["(a) Hand distance to the surface", "(c) Hand position", "(d) Base position"]);
}

#[test]
fn mismatched_lengths_name_file_panel_and_series() {
    let fig = Figure::new("bad").panel(Panel::lines("speed", "[m/s]").line("v", &[0.0, 1.0], &[0.0]));
    let err = fig.save_png(Path::new("/tmp/out.png")).unwrap_err().to_string();
    assert_eq!(err, "/tmp/out.png: panel \"speed\", series \"v\": 2 time samples but 1 values");
    let fig = Figure::new("bad").panel(Panel::steps("mode", "", &["a"], &[0.0], &[3]));
    assert!(matches!(fig.render_rgb(), Err(PlotError::Category { state: 3, categories: 1, .. })));
}

#[test]
fn intervals_end_where_the_condition_stops() {
    let t = [0.0, 1.0, 2.0, 3.0, 4.0];
    assert_eq!(intervals_where(&t, &[false, true, true, false, true]), [(1.0, 3.0), (4.0, 4.0)]);
    assert!(intervals_where(&t, &[false; 5]).is_empty());
}
