//! The study's figures (PNG, the shipped font): per scenario the Pareto plot of accuracy against
//! cost, and one chart of how long each setting stayed stable.

use std::path::Path;

use plotters::prelude::*;

use super::analysis::{self, Candidate};
use super::grid::Axis;
use super::variant::PointResult;
use crate::outputs::plot::{chart_error, font, legend, FONT, PALETTE};

/// Colour of the points that vary `axis`.
fn axis_colour(axis: Axis) -> RGBColor {
    PALETTE[match axis {
        Axis::RateTimestep => 0,
        Axis::Density => 1,
        Axis::Inverse => 2,
        Axis::All => 4,
    }]
}

/// The name of a scenario's accuracy figure, by what it measured.
pub fn error_name(points: &[&PointResult]) -> &'static str {
    let goal = points.iter().filter_map(|p| p.figures()).any(|f| f.goal_error_m.is_some());
    if goal {
        "final goal error [m]"
    } else {
        "RMS force error [N]"
    }
}

/// A log axis range around `values` (positive ones), padded.
fn log_range(values: impl Iterator<Item = f64>) -> std::ops::Range<f64> {
    let (lo, hi) =
        values.filter(|v| *v > 0.0 && v.is_finite()).fold((f64::INFINITY, 0.0_f64), |(l, h), v| (l.min(v), h.max(v)));
    if lo > hi {
        return 0.1..10.0;
    }
    lo / 1.6..hi * 1.6
}

/// `pareto_<scenario>.png`: error against wall time per simulated second, one colour per axis,
/// crosses for unstable points, the baseline ringed, the Pareto front of the stable points joined
/// and labelled.
pub fn pareto(points: &[&PointResult], path: &Path) -> anyhow::Result<()> {
    font().map_err(chart_error)?;
    let scenario = points.first().map_or("", |p| p.point.scenario.as_str());
    let plotted: Vec<(&PointResult, f64, f64)> = points
        .iter()
        .filter_map(|p| p.figures().and_then(|f| Some((*p, f.cost(), f.error()?))))
        .filter(|(_, x, y)| *x > 0.0 && *y > 0.0)
        .collect();
    let root = BitMapBackend::new(path, (1000, 650)).into_drawing_area();
    root.fill(&WHITE).map_err(chart_error)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(format!("{scenario}: accuracy against cost"), (FONT, 20))
        .margin(16)
        .x_label_area_size(46)
        .y_label_area_size(80)
        .build_cartesian_2d(
            log_range(plotted.iter().map(|p| p.1)).log_scale(),
            log_range(plotted.iter().map(|p| p.2)).log_scale(),
        )
        .map_err(chart_error)?;
    chart
        .configure_mesh()
        .x_desc("CPU time per simulated second [s/s] (log)")
        .y_desc(format!("{} (log)", error_name(points)))
        .label_style((FONT, 12))
        .axis_desc_style((FONT, 13))
        .x_labels(12)
        .y_labels(12)
        .x_label_formatter(&|v| format!("{v:.3}"))
        .y_label_formatter(&|v| format!("{v:.3}"))
        .draw()
        .map_err(chart_error)?;
    for axis in [Axis::RateTimestep, Axis::Density, Axis::Inverse, Axis::All] {
        let colour = axis_colour(axis);
        let of_axis: Vec<_> = plotted.iter().filter(|p| p.0.point.axis == axis).collect();
        if of_axis.is_empty() {
            continue;
        }
        let stable = |p: &&&(&PointResult, f64, f64)| p.0.figures().is_some_and(|f| f.unstable.is_none());
        chart
            .draw_series(of_axis.iter().filter(stable).map(|p| Circle::new((p.1, p.2), 5, colour.filled())))
            .map_err(chart_error)?
            .label(axis.name())
            .legend(move |(x, y)| Circle::new((x + 10, y), 5, colour.filled()));
        chart
            .draw_series(
                of_axis.iter().filter(|p| !stable(p)).map(|p| Cross::new((p.1, p.2), 6, colour.stroke_width(2))),
            )
            .map_err(chart_error)?;
    }
    chart
        .draw_series(
            plotted.iter().filter(|p| p.0.point.baseline).map(|p| Circle::new((p.1, p.2), 9, BLACK.stroke_width(1))),
        )
        .map_err(chart_error)?
        .label("scenario's own setting (ringed); x: unstable")
        .legend(|(x, y)| Circle::new((x + 10, y), 7, BLACK.stroke_width(1)));
    let front: Vec<Candidate> = analysis::pareto(&analysis::candidates(points));
    chart
        .draw_series(LineSeries::new(front.iter().map(|c| (c.cost, c.error)), BLACK.mix(0.5).stroke_width(1)))
        .map_err(chart_error)?
        .label("Pareto front (stable points)")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK.mix(0.5)));
    chart
        .draw_series(front.iter().map(|c| {
            let s = &c.result.point.setting;
            let text = format!("{} Hz/{} ms/{}", s.control_rate_hz, s.timestep_s * 1e3, s.density.name());
            Text::new(text, (c.cost, c.error), (FONT, 11).into_font().color(&BLACK.mix(0.8)))
        }))
        .map_err(chart_error)?;
    legend(&mut chart, SeriesLabelPosition::UpperRight).map_err(chart_error)?;
    root.present().map_err(chart_error)
}

/// Height of one row of the stability chart \[px\].
const ROW: u32 = 17;

/// `stability.png`: per scenario, one bar per point that ran, green up to the end of the run when
/// it stayed stable, red up to the time it went unstable.
pub fn stability(points: &[PointResult], path: &Path) -> anyhow::Result<()> {
    font().map_err(chart_error)?;
    let scenarios = analysis::scenarios(points);
    let ran: Vec<Vec<&PointResult>> = scenarios
        .iter()
        .map(|s| analysis::of(points, s).into_iter().filter(|p| p.figures().is_some()).collect())
        .collect();
    let heights: Vec<u32> = ran.iter().map(|r| 70 + ROW * r.len() as u32).collect();
    let root = BitMapBackend::new(path, (1000, heights.iter().sum::<u32>().max(100))).into_drawing_area();
    root.fill(&WHITE).map_err(chart_error)?;
    let mut rest = root.clone();
    for ((scenario, rows), h) in scenarios.iter().zip(&ran).zip(&heights) {
        let (area, below) = rest.split_vertically(*h);
        rest = below;
        let end = rows.iter().map(|p| p.point.duration_s).fold(0.0, f64::max);
        let labels: Vec<String> = rows.iter().map(|p| p.point.setting.label()).collect();
        let mut chart = ChartBuilder::on(&area)
            .caption(format!("{scenario}: time stable (red: unstable from there)"), (FONT, 15))
            .margin(8)
            .x_label_area_size(30)
            .y_label_area_size(330)
            .build_cartesian_2d(0.0..end.max(1e-3), -0.5..rows.len() as f64 - 0.5)
            .map_err(chart_error)?;
        let label = |v: &f64| {
            labels.get(v.round() as usize).filter(|_| (v - v.round()).abs() < 1e-6).cloned().unwrap_or_default()
        };
        chart
            .configure_mesh()
            .disable_y_mesh()
            .x_desc("simulated time [s]")
            .label_style((FONT, 11))
            .axis_desc_style((FONT, 12))
            .y_labels(rows.len().max(1))
            .y_label_formatter(&label)
            .draw()
            .map_err(chart_error)?;
        chart
            .draw_series(rows.iter().enumerate().map(|(k, p)| {
                let f = p.figures().expect("filtered on figures");
                let (t, colour) = match &f.unstable {
                    Some(u) => (u.t_s, PALETTE[1]),
                    None => (p.point.duration_s, PALETTE[2]),
                };
                let y = k as f64;
                Rectangle::new([(0.0, y - 0.35), (t.max(end * 0.003), y + 0.35)], colour.mix(0.8).filled())
            }))
            .map_err(chart_error)?;
    }
    root.present().map_err(chart_error)
}
