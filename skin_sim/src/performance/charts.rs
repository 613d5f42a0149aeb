//! The performance figures: per series, the time of one cycle at each point as a bar stacked by
//! stage; per scenario, the wall time of a simulated second as a bar stacked by part of the loop
//! (PNG, the shipped font).

use std::path::Path;

use plotters::prelude::*;
use skin_core::controller::Stage;

use super::measurements::Series;
use super::simulator::{SimPoint, PARTS};
use crate::outputs::plot::{chart_error, font, legend, FONT, PALETTE};

/// `<key>.png`: microseconds per cycle against the series' quantity, one bar per point stacked
/// by stage, at its true x (so a straight rise reads as linear).
pub fn stacked(series: &Series, path: &Path) -> anyhow::Result<()> {
    font().map_err(chart_error)?;
    let xs: Vec<f64> = series.points.iter().map(|p| p.0).collect();
    let (x0, x1) = (xs[0], xs[xs.len() - 1]);
    let gap = xs.windows(2).map(|w| w[1] - w[0]).fold(f64::INFINITY, f64::min).max((x1 - x0) / 60.0);
    let half = 0.35 * gap;
    let top = series.points.iter().map(|p| p.1.total_ns).fold(0.0, f64::max) * 1e-3 * 1.15;
    let root = BitMapBackend::new(path, (900, 520)).into_drawing_area();
    root.fill(&WHITE).map_err(chart_error)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(series.title, (FONT, 19))
        .margin(14)
        .x_label_area_size(44)
        .y_label_area_size(64)
        .build_cartesian_2d(x0 - 2.0 * half..x1 + 2.0 * half, 0.0..top.max(1e-3))
        .map_err(chart_error)?;
    chart
        .configure_mesh()
        .x_desc(series.x_label)
        .y_desc("Controller::update [µs] (median)")
        .label_style((FONT, 12))
        .axis_desc_style((FONT, 13))
        .x_labels(10)
        .y_labels(10)
        .x_label_formatter(&|v| format!("{v:.0}"))
        .y_label_formatter(&|v| format!("{v:.0}"))
        .draw()
        .map_err(chart_error)?;
    for (k, stage) in Stage::ALL.into_iter().enumerate() {
        let colour = PALETTE[k];
        let bars = series.points.iter().map(move |(x, p)| {
            let below: f64 = Stage::ALL[..k].iter().map(|s| p.stage_ns(*s)).sum::<f64>() * 1e-3;
            let h = p.stage_ns(stage) * 1e-3;
            Rectangle::new([(x - half, below), (x + half, below + h)], colour.mix(0.85).filled())
        });
        chart
            .draw_series(bars)
            .map_err(chart_error)?
            .label(stage.name())
            .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 14, y + 5)], colour.mix(0.85).filled()));
    }
    chart
        .draw_series(series.points.iter().map(|(x, p)| {
            Text::new(format!("{:.1}", p.total_ns * 1e-3), (x - half, p.total_ns * 1e-3 + top * 0.01), (FONT, 11))
        }))
        .map_err(chart_error)?;
    legend(&mut chart, SeriesLabelPosition::UpperLeft).map_err(chart_error)?;
    root.present().map_err(chart_error)
}

/// `<key>.png`: wall milliseconds per simulated second of each scenario, stacked by part of the
/// loop, with the real-time factor over each bar.
pub fn loop_parts(points: &[SimPoint], path: &Path) -> anyhow::Result<()> {
    font().map_err(chart_error)?;
    let top = points.iter().map(|p| p.ms_per_s.iter().sum::<f64>()).fold(0.0, f64::max) * 1.35;
    let root = BitMapBackend::new(path, (1200, 520)).into_drawing_area();
    root.fill(&WHITE).map_err(chart_error)?;
    let mut chart = ChartBuilder::on(&root)
        .caption("Wall time per simulated second, by part of the loop", (FONT, 19))
        .margin(14)
        .x_label_area_size(44)
        .y_label_area_size(64)
        .build_cartesian_2d(-0.6..points.len() as f64 - 0.4, 0.0..top.max(1e-3))
        .map_err(chart_error)?;
    chart
        .configure_mesh()
        .disable_x_mesh()
        .y_desc("wall time [ms] per simulated s")
        .label_style((FONT, 10))
        .axis_desc_style((FONT, 13))
        .x_labels(points.len())
        .x_label_formatter(&|v| {
            let k = v.round();
            if (v - k).abs() > 1e-6 || k < 0.0 {
                return String::new();
            }
            points.get(k as usize).map_or_else(String::new, |p| p.name.clone())
        })
        .y_label_formatter(&|v| format!("{v:.0}"))
        .draw()
        .map_err(chart_error)?;
    for (k, part) in PARTS.into_iter().enumerate() {
        let colour = PALETTE[k];
        let bars = points.iter().enumerate().map(move |(i, p)| {
            let below: f64 = p.ms_per_s[..k].iter().sum();
            let x = i as f64;
            Rectangle::new([(x - 0.3, below), (x + 0.3, below + p.ms_per_s[k])], colour.mix(0.85).filled())
        });
        chart
            .draw_series(bars)
            .map_err(chart_error)?
            .label(part)
            .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 14, y + 5)], colour.mix(0.85).filled()));
    }
    chart
        .draw_series(points.iter().enumerate().map(|(i, p)| {
            let total: f64 = p.ms_per_s.iter().sum();
            Text::new(format!("{:.0}x", p.realtime_factor), (i as f64 - 0.15, total + top * 0.01), (FONT, 12))
        }))
        .map_err(chart_error)?;
    legend(&mut chart, SeriesLabelPosition::UpperLeft).map_err(chart_error)?;
    root.present().map_err(chart_error)
}
