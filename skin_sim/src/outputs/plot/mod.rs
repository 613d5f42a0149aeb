//! Figures of stacked time-series panels sharing one time axis, drawn to PNG or SVG with the
//! shipped DejaVu Sans font (no system fontconfig), in the style of the papers' signal figures.
//!
//! ```no_run
//! use skin_sim::outputs::plot::{Figure, Panel, Tint};
//! let t = [0.0, 0.1, 0.2];
//! Figure::new("run")
//!     .panel(Panel::steps("(a) Arrangement", "", &["(a)", "(b)", "(c)"], &t, &[0, 1, 1]))
//!     .panel(
//!         Panel::lines("(b) Contact force", "[N]")
//!             .line("||F_c||", &t, &[0.0, 2.0, 3.0])
//!             .threshold("eps_c", 5.0),
//!     )
//!     .shade(0.1, 0.2, "intentional contact", Tint::Green)
//!     .save_png("run.png".as_ref())
//!     .unwrap();
//! ```

mod draw;
mod layouts;

use std::path::{Path, PathBuf};

use thiserror::Error;

// The study's charts (`crate::study::charts`) draw with the same font and colours.
pub(crate) use draw::{font, legend, FONT, PALETTE};
pub use layouts::{
    guidance_figure, paper000_figure, paper003_figure, GuidanceSignals, Paper000Signals, Paper003Signals,
};

/// Errors building or writing a figure; each names the output file.
#[derive(Debug, Error)]
pub enum PlotError {
    /// A line or step series whose time and value slices differ in length.
    #[error(
        "{}: panel {panel:?}, series {series:?}: {t} time samples but {values} values",
        path.display()
    )]
    Length {
        /// The output file.
        path: PathBuf,
        /// Panel title.
        panel: String,
        /// Series name.
        series: String,
        /// Length of the time slice.
        t: usize,
        /// Length of the value slice.
        values: usize,
    },
    /// A step panel state that names no category.
    #[error("{}: panel {panel:?}: state {state} but only {categories} categories", path.display())]
    Category {
        /// The output file.
        path: PathBuf,
        /// Panel title.
        panel: String,
        /// The offending state.
        state: usize,
        /// Number of categories.
        categories: usize,
    },
    /// Drawing or encoding failed (I/O included).
    #[error("{}: {message}", path.display())]
    Draw {
        /// The output file.
        path: PathBuf,
        /// What plotters said.
        message: String,
    },
}

/// A named line of a [`Panel`].
#[derive(Debug, Clone)]
struct Line {
    name: String,
    t: Vec<f64>,
    y: Vec<f64>,
}

/// A dashed horizontal line (a threshold such as eps_c).
#[derive(Debug, Clone)]
struct Threshold {
    name: String,
    value: f64,
}

/// What a panel shows.
#[derive(Debug, Clone)]
enum Content {
    /// Continuous signals and thresholds.
    Lines { lines: Vec<Line>, thresholds: Vec<Threshold> },
    /// A categorical state held from one sample to the next (e.g. the active arrangement).
    Steps { categories: Vec<String>, t: Vec<f64>, state: Vec<usize> },
}

/// One panel: a title, a y label with units, and its content.
#[derive(Debug, Clone)]
pub struct Panel {
    title: String,
    y_label: String,
    content: Content,
}

impl Panel {
    /// A panel of lines; add them with [`Panel::line`] and [`Panel::threshold`].
    pub fn lines(title: &str, y_label: &str) -> Self {
        let content = Content::Lines { lines: Vec::new(), thresholds: Vec::new() };
        Self { title: title.into(), y_label: y_label.into(), content }
    }

    /// A step panel: `state[k]` (an index into `categories`) holds from `t[k]` to `t[k + 1]`.
    pub fn steps(title: &str, y_label: &str, categories: &[&str], t: &[f64], state: &[usize]) -> Self {
        let content = Content::Steps {
            categories: categories.iter().map(|c| c.to_string()).collect(),
            t: t.to_vec(),
            state: state.to_vec(),
        };
        Self { title: title.into(), y_label: y_label.into(), content }
    }

    /// Add the line `name` with samples `(t[k], y[k])`; non-finite values leave a gap. No-op on a
    /// step panel.
    pub fn line(mut self, name: &str, t: &[f64], y: &[f64]) -> Self {
        if let Content::Lines { lines, .. } = &mut self.content {
            lines.push(Line { name: name.into(), t: t.to_vec(), y: y.to_vec() });
        }
        self
    }

    /// Add a dashed horizontal line at `value`. No-op on a step panel.
    pub fn threshold(mut self, name: &str, value: f64) -> Self {
        if let Content::Lines { thresholds, .. } = &mut self.content {
            thresholds.push(Threshold { name: name.into(), value });
        }
        self
    }

    fn check(&self, path: &Path) -> Result<(), PlotError> {
        let length = |series: &str, t: usize, values: usize| PlotError::Length {
            path: path.to_path_buf(),
            panel: self.title.clone(),
            series: series.to_string(),
            t,
            values,
        };
        match &self.content {
            Content::Lines { lines, .. } => match lines.iter().find(|l| l.t.len() != l.y.len()) {
                Some(l) => Err(length(&l.name, l.t.len(), l.y.len())),
                None => Ok(()),
            },
            Content::Steps { t, state, .. } if t.len() != state.len() => Err(length("state", t.len(), state.len())),
            Content::Steps { categories, state, .. } => match state.iter().find(|&&s| s >= categories.len()) {
                Some(&s) => Err(PlotError::Category {
                    path: path.to_path_buf(),
                    panel: self.title.clone(),
                    state: s,
                    categories: categories.len(),
                }),
                None => Ok(()),
            },
        }
    }
}

/// Colour of a shaded interval (interactive-force-control paper marks tactile guidance green, base collision avoidance
/// red, object motion yellow).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Tint {
    /// Green.
    Green,
    /// Red.
    Red,
    /// Yellow.
    Yellow,
    /// Blue.
    Blue,
    /// Grey.
    Gray,
}

/// A shaded time interval drawn across every panel.
#[derive(Debug, Clone)]
struct Interval {
    start: f64,
    end: f64,
    label: String,
    tint: Tint,
}

/// A figure: a title over stacked panels that share the time axis.
#[derive(Debug, Clone)]
pub struct Figure {
    title: String,
    width: u32,
    panel_height: u32,
    panels: Vec<Panel>,
    intervals: Vec<Interval>,
}

/// Height of the figure title band \[px\].
const TITLE_HEIGHT: u32 = 36;

impl Figure {
    /// An empty figure, 1000 px wide with 190 px per panel.
    pub fn new(title: &str) -> Self {
        Self { title: title.into(), width: 1000, panel_height: 190, panels: Vec::new(), intervals: Vec::new() }
    }

    /// Set the width and the height of each panel \[px\].
    pub fn size(mut self, width: u32, panel_height: u32) -> Self {
        self.width = width;
        self.panel_height = panel_height;
        self
    }

    /// Append a panel below the others.
    pub fn panel(mut self, panel: Panel) -> Self {
        self.panels.push(panel);
        self
    }

    /// Shade `[start, end]` \[s\] in every panel; the label goes in the top panel's legend (once).
    pub fn shade(mut self, start: f64, end: f64, label: &str, tint: Tint) -> Self {
        self.intervals.push(Interval { start, end, label: label.into(), tint });
        self
    }

    /// Image size \[px\]: (width, title band + one panel height per panel).
    pub fn pixel_size(&self) -> (u32, u32) {
        (self.width, TITLE_HEIGHT + self.panel_height * self.panels.len().max(1) as u32)
    }

    /// Draw to a PNG file.
    pub fn save_png(&self, path: &Path) -> Result<(), PlotError> {
        self.check(path)?;
        draw::to_png(self, path).map_err(|message| PlotError::Draw { path: path.into(), message })
    }

    /// Draw to an SVG file (text as `<text>` elements in sans-serif).
    pub fn save_svg(&self, path: &Path) -> Result<(), PlotError> {
        self.check(path)?;
        draw::to_svg(self, path).map_err(|message| PlotError::Draw { path: path.into(), message })
    }

    /// Draw into memory: RGB8 pixels, row-major, [`Figure::pixel_size`] big.
    pub fn render_rgb(&self) -> Result<Vec<u8>, PlotError> {
        let path = Path::new("<memory>");
        self.check(path)?;
        draw::to_rgb(self).map_err(|message| PlotError::Draw { path: path.into(), message })
    }

    fn check(&self, path: &Path) -> Result<(), PlotError> {
        self.panels.iter().try_for_each(|p| p.check(path))
    }
}

/// The intervals `[t_start, t_end]` where `on` holds, each ending at the first sample where it no
/// longer does (or at the last sample). `t` and `on` are read up to the shorter length.
pub fn intervals_where(t: &[f64], on: &[bool]) -> Vec<(f64, f64)> {
    let n = t.len().min(on.len());
    let mut out = Vec::new();
    let mut start = None;
    for k in 0..n {
        match (start, on[k]) {
            (None, true) => start = Some(t[k]),
            (Some(s), false) => {
                out.push((s, t[k]));
                start = None;
            }
            _ => {}
        }
    }
    if let Some(s) = start {
        out.push((s, t[n - 1]));
    }
    out
}

#[cfg(test)]
mod tests;
