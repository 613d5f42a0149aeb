//! Drawing a [`Figure`] with plotters, the same code for every backend.

use std::ops::Range;
use std::path::Path;
use std::sync::OnceLock;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::{register_font, FontStyle};

use super::figure::{Content, Figure, Interval, Panel, PlotError, Tint, TITLE_HEIGHT};

impl Figure {
    /// Draw to a PNG file.
    pub fn save_png(&self, path: &Path) -> Result<(), PlotError> {
        self.check(path)?;
        to_png(self, path).map_err(|message| PlotError::Draw { path: path.into(), message })
    }

    /// Draw to an SVG file (text as `<text>` elements in sans-serif).
    pub fn save_svg(&self, path: &Path) -> Result<(), PlotError> {
        self.check(path)?;
        to_svg(self, path).map_err(|message| PlotError::Draw { path: path.into(), message })
    }

    /// Draw into memory: RGB8 pixels, row-major, [`Figure::pixel_size`] big.
    pub fn render_rgb(&self) -> Result<Vec<u8>, PlotError> {
        let path = Path::new("<memory>");
        self.check(path)?;
        to_rgb(self).map_err(|message| PlotError::Draw { path: path.into(), message })
    }
}

/// Family name the shipped font is registered under (ab_glyph looks fonts up by name).
pub(crate) const FONT: &str = "sans-serif";
static FONT_TTF: &[u8] = include_bytes!("../../../assets/DejaVuSans.ttf");

/// Line colours, in order of the lines of a panel (matplotlib's tab10 start).
pub(crate) const PALETTE: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
];
const THRESHOLD: RGBColor = RGBColor(60, 60, 60);

pub(super) fn to_png(fig: &Figure, path: &Path) -> Result<(), String> {
    let root = BitMapBackend::new(path, fig.pixel_size()).into_drawing_area();
    draw(fig, &root)
}

pub(super) fn to_svg(fig: &Figure, path: &Path) -> Result<(), String> {
    let root = SVGBackend::new(path, fig.pixel_size()).into_drawing_area();
    draw(fig, &root)
}

pub(super) fn to_rgb(fig: &Figure) -> Result<Vec<u8>, String> {
    let (w, h) = fig.pixel_size();
    let mut buf = vec![0u8; w as usize * h as usize * 3];
    draw(fig, &BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area())?;
    Ok(buf)
}

fn err(e: impl std::fmt::Display) -> String {
    e.to_string()
}

/// A plotters error as the `anyhow::Error` the charts of the study, the benchmarks and the
/// campaign return.
pub(crate) fn chart_error(e: impl std::fmt::Display) -> anyhow::Error {
    anyhow::anyhow!("{e}")
}

/// Register the shipped font once per process.
pub(crate) fn font() -> Result<(), String> {
    static REGISTERED: OnceLock<Result<(), String>> = OnceLock::new();
    REGISTERED
        .get_or_init(|| {
            register_font(FONT, FontStyle::Normal, FONT_TTF).map_err(|_| "the shipped font is not a valid TTF".into())
        })
        .clone()
}

fn draw<DB: DrawingBackend>(fig: &Figure, root: &DrawingArea<DB, Shift>) -> Result<(), String> {
    font()?;
    root.fill(&WHITE).map_err(err)?;
    let (top, body) = root.split_vertically(TITLE_HEIGHT);
    top.titled(&fig.title, (FONT, 20)).map_err(err)?;
    let time = time_range(fig);
    let areas = body.split_evenly((fig.panels.len().max(1), 1));
    for (i, (panel, area)) in fig.panels.iter().zip(&areas).enumerate() {
        let shading = Shading { intervals: &fig.intervals, in_legend: i == 0 };
        draw_panel(panel, area, time.clone(), i + 1 == fig.panels.len(), &shading)?;
    }
    root.present().map_err(err)
}

/// The figure's intervals, and whether this panel's legend lists them.
struct Shading<'a> {
    intervals: &'a [Interval],
    in_legend: bool,
}

fn draw_panel<DB: DrawingBackend>(
    panel: &Panel,
    area: &DrawingArea<DB, Shift>,
    time: Range<f64>,
    bottom: bool,
    shading: &Shading,
) -> Result<(), String> {
    let y = y_range(panel);
    let mut chart = ChartBuilder::on(area)
        .caption(&panel.title, (FONT, 14))
        .margin_left(8)
        .margin_right(16)
        .x_label_area_size(if bottom { 34 } else { 18 })
        .y_label_area_size(78)
        .build_cartesian_2d(time.clone(), y.clone())
        .map_err(err)?;

    let categories = match &panel.content {
        Content::Steps { categories, .. } => categories.as_slice(),
        Content::Lines { .. } => &[],
    };
    // Category names at the integer states, nothing elsewhere.
    let category_label = |v: &f64| {
        let k = v.round();
        if (v - k).abs() < 1e-6 && k >= 0.0 {
            categories.get(k as usize).cloned().unwrap_or_default()
        } else {
            String::new()
        }
    };
    let mut mesh = chart.configure_mesh();
    mesh.y_desc(&panel.y_label)
        .label_style((FONT, 12))
        .axis_desc_style((FONT, 12))
        .bold_line_style(BLACK.mix(0.1))
        .light_line_style(BLACK.mix(0.03))
        .x_label_formatter(&tick)
        .y_labels(6)
        .y_label_formatter(&tick);
    if bottom {
        mesh.x_desc("time [s]");
    }
    if !categories.is_empty() {
        mesh.y_labels(2 * categories.len() + 1).y_label_formatter(&category_label);
    }
    mesh.draw().map_err(err)?;

    let mut labelled = false;
    for (k, iv) in shading.intervals.iter().enumerate() {
        let tint = rgb(iv.tint);
        let rect = Rectangle::new([(iv.start, y.start), (iv.end, y.end)], tint.mix(0.15).filled());
        let drawn = chart.draw_series(std::iter::once(rect)).map_err(err)?;
        let first_of_label = shading.intervals[..k].iter().all(|o| o.label != iv.label);
        if shading.in_legend && first_of_label {
            drawn
                .label(&iv.label)
                .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 16, y + 5)], tint.mix(0.4).filled()));
            labelled = true;
        }
    }

    match &panel.content {
        Content::Lines { lines, thresholds } => {
            for (j, line) in lines.iter().enumerate() {
                let style = PALETTE[j % PALETTE.len()].stroke_width(2);
                for (k, segment) in finite_segments(&line.t, &line.y).into_iter().enumerate() {
                    let drawn = chart.draw_series(LineSeries::new(segment, style)).map_err(err)?;
                    if k == 0 {
                        drawn.label(&line.name).legend(move |(x, y)| PathElement::new([(x, y), (x + 16, y)], style));
                        labelled = true;
                    }
                }
            }
            for th in thresholds {
                let style = THRESHOLD.stroke_width(2);
                let points = [(time.start, th.value), (time.end, th.value)];
                chart
                    .draw_series(DashedLineSeries::new(points, 8, 5, style))
                    .map_err(err)?
                    .label(&th.name)
                    .legend(move |(x, y)| PathElement::new([(x, y), (x + 6, y), (x + 10, y), (x + 16, y)], style));
                labelled = true;
            }
        }
        Content::Steps { t, state, .. } => {
            let style = PALETTE[0].stroke_width(2);
            chart.draw_series(LineSeries::new(step_points(t, state), style)).map_err(err)?;
        }
    }

    if labelled {
        legend(&mut chart, SeriesLabelPosition::UpperRight)?;
    }
    Ok(())
}

/// The legend of `chart`'s labelled series at `position`, in the figures' one style.
pub(crate) fn legend<'a, DB: DrawingBackend + 'a, CT: plotters::coord::CoordTranslate>(
    chart: &mut ChartContext<'a, DB, CT>,
    position: SeriesLabelPosition,
) -> Result<(), String> {
    chart
        .configure_series_labels()
        .position(position)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK.mix(0.3))
        .label_font((FONT, 12))
        .draw()
        .map_err(err)
}

/// A tick label without float noise: at most 4 decimals, trailing zeros and a negative zero
/// dropped.
fn tick(v: &f64) -> String {
    let s = format!("{v:.4}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".into()
    } else {
        s.into()
    }
}

/// Runs of consecutive samples with finite time and value: non-finite samples are gaps.
fn finite_segments(t: &[f64], y: &[f64]) -> Vec<Vec<(f64, f64)>> {
    let mut out: Vec<Vec<(f64, f64)>> = vec![Vec::new()];
    for (&ti, &yi) in t.iter().zip(y) {
        if ti.is_finite() && yi.is_finite() {
            out.last_mut().expect("never empty").push((ti, yi));
        } else if !out.last().expect("never empty").is_empty() {
            out.push(Vec::new());
        }
    }
    out.retain(|s| !s.is_empty());
    out
}

/// A state held until the next sample: a vertical edge at each change.
fn step_points(t: &[f64], state: &[usize]) -> Vec<(f64, f64)> {
    let mut out = Vec::with_capacity(2 * t.len());
    for (k, (&ti, &s)) in t.iter().zip(state).enumerate() {
        if k > 0 {
            out.push((ti, state[k - 1] as f64));
        }
        out.push((ti, s as f64));
    }
    out
}

/// The time span of every series of the figure (0..1 when there is none).
fn time_range(fig: &Figure) -> Range<f64> {
    let times = fig.panels.iter().flat_map(|p| match &p.content {
        Content::Lines { lines, .. } => lines.iter().flat_map(|l| l.t.iter()).collect::<Vec<_>>(),
        Content::Steps { t, .. } => t.iter().collect(),
    });
    span(times.copied(), 0.0)
}

fn y_range(panel: &Panel) -> Range<f64> {
    match &panel.content {
        Content::Lines { lines, thresholds } => {
            let values = lines.iter().flat_map(|l| l.y.iter().copied()).chain(thresholds.iter().map(|t| t.value));
            span(values, 0.06)
        }
        Content::Steps { categories, .. } => -0.5..categories.len() as f64 - 0.5,
    }
}

/// min..max of the finite values, widened by `pad` of the span on each side; never empty.
fn span(values: impl Iterator<Item = f64>, pad: f64) -> Range<f64> {
    let (lo, hi) =
        values.filter(|v| v.is_finite()).fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| (lo.min(v), hi.max(v)));
    if lo > hi {
        return 0.0..1.0;
    }
    if hi - lo < 1e-12 {
        let half = (lo.abs() * 0.1).max(0.5);
        return lo - half..hi + half;
    }
    let margin = (hi - lo) * pad;
    lo - margin..hi + margin
}

fn rgb(tint: Tint) -> RGBColor {
    match tint {
        Tint::Green => RGBColor(44, 160, 44),
        Tint::Red => RGBColor(214, 39, 40),
        Tint::Yellow => RGBColor(230, 180, 0),
        Tint::Blue => RGBColor(31, 119, 180),
        Tint::Gray => RGBColor(128, 128, 128),
    }
}
