//! The campaign's figures (PNG, the shipped font): every scene a point at what was drawn against
//! what it showed, beside the limit it is judged by, so a failure class reads as a region.
//! - `goals.png`: per goal family, the final goal error against the friction the push had to
//!   overcome, with `ε_c` (what makes a scene feasible) and the goal tolerance;
//! - `forces.png`: the force family's Table 3 errors against what drives them (how fast the
//!   reference moves, how far the base circles) and the first-touch overshoot against the
//!   reference.

use std::path::Path;

use plotters::coord::ranged1d::ValueFormatter;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

use super::families::EPS_C_N;
use super::result::SceneResult;
use crate::outputs::outcome::FIRST_CONTACT_OVERSHOOT_N;
use crate::outputs::plot::{chart_error, font, legend, FONT, PALETTE};

/// How a scene ended, as its marker.
#[derive(Clone, Copy, PartialEq)]
enum Mark {
    Passed,
    Failed,
    /// A goal scene that gave up an infeasible push and held (a feasible one that did failed).
    Blocked,
    /// Any safety violation, whatever else.
    Unsafe,
}

impl Mark {
    const ALL: [Mark; 4] = [Mark::Passed, Mark::Failed, Mark::Blocked, Mark::Unsafe];

    fn of(r: &SceneResult, passed: bool) -> Self {
        match &r.verdict {
            Some(v) if !v.violations.is_empty() => Mark::Unsafe,
            _ if !passed => Mark::Failed,
            Some(v) if v.outcome == Some("blocked") => Mark::Blocked,
            _ => Mark::Passed,
        }
    }

    fn label(self) -> &'static str {
        match self {
            Mark::Passed => "passed",
            Mark::Failed => "failed",
            Mark::Blocked => "blocked (held, safe)",
            Mark::Unsafe => "safety violation",
        }
    }

    fn colour(self) -> RGBColor {
        match self {
            Mark::Passed => PALETTE[2],
            Mark::Failed => PALETTE[1],
            Mark::Blocked => PALETTE[3],
            Mark::Unsafe => BLACK,
        }
    }
}

/// One panel's points: (x, y, mark).
type Points = Vec<(f64, f64, Mark)>;

/// A metric of a scene's `metrics.json` row.
fn metric(r: &SceneResult, key: &str) -> Option<f64> {
    r.metrics.as_ref()?.get(key)?.as_f64()
}

/// A drawn value of a scene.
fn drawn(r: &SceneResult, key: &str) -> Option<f64> {
    r.drawn.get(key)?.as_f64()
}

/// One scatter panel: `points` in `x` × `y` (log-scaled y when `log_y`), horizontal limit
/// `y_limit` and vertical `x_limit` as dashed lines.
struct Scatter<'a> {
    title: &'a str,
    x_label: &'a str,
    y_label: &'a str,
    x: std::ops::Range<f64>,
    y: std::ops::Range<f64>,
    log_y: bool,
    x_limit: Option<(f64, &'a str)>,
    y_limit: Option<(f64, &'a str)>,
    points: Points,
}

/// One panel in `area`: points off the chart at its edge.
fn scatter<DB: DrawingBackend>(area: &DrawingArea<DB, plotters::coord::Shift>, s: &Scatter) -> anyhow::Result<()> {
    // off the chart (or never measured: NaN) at its edge
    let y = |v: f64| if v.is_nan() { s.y.end } else { v.clamp(s.y.start, s.y.end) };
    let points: Points =
        s.points.iter().filter(|p| !p.0.is_nan()).map(|p| (p.0.clamp(s.x.start, s.x.end), y(p.1), p.2)).collect();
    let mut builder = ChartBuilder::on(area);
    builder.caption(s.title, (FONT, 16)).margin(12).x_label_area_size(40).y_label_area_size(58);
    if s.log_y {
        draw(builder.build_cartesian_2d(s.x.clone(), (s.y.clone()).log_scale()).map_err(chart_error)?, s, &points)
    } else {
        draw(builder.build_cartesian_2d(s.x.clone(), s.y.clone()).map_err(chart_error)?, s, &points)
    }
}

/// A tick value without trailing zeros (0.01, 0.5, 100).
fn tick(v: &f64) -> String {
    let s = format!("{v:.3}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// The axes, the limits and the points of `s` on `chart`.
fn draw<'a, DB: DrawingBackend + 'a, Y: Ranged<ValueType = f64> + ValueFormatter<f64>>(
    mut chart: ChartContext<'a, DB, Cartesian2d<RangedCoordf64, Y>>,
    s: &Scatter,
    points: &Points,
) -> anyhow::Result<()> {
    chart
        .configure_mesh()
        .x_desc(s.x_label)
        .y_desc(s.y_label)
        .label_style((FONT, 11))
        .axis_desc_style((FONT, 12))
        .x_label_formatter(&tick)
        .y_label_formatter(&tick)
        .draw()
        .map_err(chart_error)?;
    let grey = RGBColor(60, 60, 60);
    if let Some((x, name)) = s.x_limit {
        chart
            .draw_series(DashedLineSeries::new([(x, s.y.start), (x, s.y.end)], 6, 4, grey.stroke_width(1)))
            .map_err(chart_error)?
            .label(name)
            .legend(move |(a, b)| PathElement::new([(a, b), (a + 14, b)], grey));
    }
    if let Some((y, name)) = s.y_limit {
        chart
            .draw_series(DashedLineSeries::new([(s.x.start, y), (s.x.end, y)], 6, 4, grey.mix(0.6).stroke_width(2)))
            .map_err(chart_error)?
            .label(name)
            .legend(move |(a, b)| PathElement::new([(a, b), (a + 14, b)], grey.mix(0.6).stroke_width(2)));
    }
    for mark in Mark::ALL {
        let c = mark.colour();
        let style = if mark == Mark::Unsafe { c.stroke_width(2) } else { c.mix(0.8).filled() };
        let these = points.iter().filter(|p| p.2 == mark).map(|p| Circle::new((p.0, p.1), 4, style));
        let n = points.iter().filter(|p| p.2 == mark).count();
        if n == 0 {
            continue;
        }
        chart
            .draw_series(these)
            .map_err(chart_error)?
            .label(format!("{} ({n})", mark.label()))
            .legend(move |(a, b)| Circle::new((a + 7, b), 4, style));
    }
    legend(&mut chart, SeriesLabelPosition::UpperLeft).map_err(chart_error)
}

/// Draws `panels` side by side into a PNG of `size` at `path`.
fn panels(path: &Path, title: &str, size: (u32, u32), panels: &[Scatter]) -> anyhow::Result<()> {
    font().map_err(chart_error)?;
    let root = BitMapBackend::new(path, size).into_drawing_area();
    root.fill(&WHITE).map_err(chart_error)?;
    let root = root.titled(title, (FONT, 19)).map_err(chart_error)?;
    for (area, s) in root.split_evenly((1, panels.len())).iter().zip(panels) {
        scatter(area, s)?;
    }
    root.present().map_err(chart_error)
}

/// Past the largest finite friction: where fixed obstacles are drawn \[N\].
const FIXED_AT_N: f64 = 12.0;

/// `goals.png`: per goal family, the final goal error against the friction the push had to
/// overcome (fixed obstacles at the right edge).
pub fn goals(results: &[SceneResult], path: &Path) -> anyhow::Result<()> {
    let family = |name: &'static str, title: &'static str| {
        let points = results
            .iter()
            .filter(|r| r.family == name)
            .filter_map(|r| {
                let e = metric(r, "goal_error_m")? * 100.0;
                let x = if r.resistance_n.is_finite() { r.resistance_n } else { FIXED_AT_N };
                let reached = r.verdict.as_ref()?.goal_reached? || !r.feasible;
                Some((x, e.max(0.01), Mark::of(r, reached)))
            })
            .collect();
        Scatter {
            title,
            x_label: "friction of the heaviest pushed obstacle μ m g [N] (12: fixed)",
            y_label: "goal error at the end [cm]",
            x: 0.0..FIXED_AT_N + 0.5,
            y: 0.01..100.0,
            log_y: true,
            x_limit: Some((EPS_C_N, "ε_c: feasible on its left")),
            y_limit: Some((1.0, "goal tolerance")),
            points,
        }
    };
    panels(
        path,
        "Goal scenes: what the push had to overcome, and how near the goal it ended",
        (1400, 560),
        &[
            family("planar_contact", "planar arm (intentional contact)"),
            family("tomm_reach", "TOMM reaching over a table"),
        ],
    )
}

/// `forces.png`: the force family's RMS errors without base motion against the reference's
/// peak rate, with base motion against the circle's radius, and the first-touch overshoot
/// against the reference's mean.
pub fn forces(results: &[SceneResult], path: &Path) -> anyhow::Result<()> {
    let rows: Vec<&SceneResult> = results.iter().filter(|r| r.family == "force_tracking").collect();
    let points = |x: &dyn Fn(&SceneResult) -> Option<f64>, y: &dyn Fn(&SceneResult) -> Option<f64>| -> Points {
        rows.iter()
            .filter_map(|r| {
                let passed = r.verdict.as_ref()?.force_table3?;
                Some((x(r)?, y(r).unwrap_or(f64::NAN), Mark::of(r, passed)))
            })
            .collect()
    };
    let rate = |r: &SceneResult| Some(std::f64::consts::TAU * drawn(r, "amplitude_n")? / drawn(r, "period_s")?);
    let overshoot = |r: &SceneResult| r.verdict.as_ref()?.first_contact_overshoot_n;
    panels(
        path,
        "Force scenes (interactive-force-control paper Table 3, Exp. 1 limits)",
        (1500, 520),
        &[
            Scatter {
                title: "(a) without base motion",
                x_label: "peak rate of the reference 2π A / T [N/s]",
                y_label: "RMS error from reaching the reference [N]",
                x: 0.0..6.5,
                y: 0.0..0.6,
                log_y: false,
                x_limit: None,
                y_limit: Some((0.16, "Table 3: 0.16 N")),
                points: points(&rate, &|r| metric(r, "rms_force_error_from_reach_n")),
            },
            Scatter {
                title: "(b) with base motion",
                x_label: "radius of the base's circle [m]",
                y_label: "RMS error with base motion [N]",
                x: 0.0..0.32,
                y: 0.0..0.8,
                log_y: false,
                x_limit: None,
                y_limit: Some((0.37, "Table 3: 0.37 N")),
                points: points(&|r| drawn(r, "circle_radius_m"), &|r| metric(r, "rms_force_error_interaction_n")),
            },
            Scatter {
                title: "(c) first touch",
                x_label: "mean of the reference [N]",
                y_label: "peak over the reference at the first touch [N]",
                x: 1.5..8.5,
                y: -1.0..3.0,
                log_y: false,
                x_limit: None,
                y_limit: Some((FIRST_CONTACT_OVERSHOOT_N, "limit: 2 N")),
                points: points(&|r| drawn(r, "mean_n"), &overshoot),
            },
        ],
    )
}
