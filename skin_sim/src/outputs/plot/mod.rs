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
mod figure;
mod layouts;

// The charts of the study, the benchmarks and the campaign draw with the same font, colours and errors.
pub(crate) use draw::{chart_error, font, legend, FONT, PALETTE};
pub use figure::{intervals_where, Figure, Panel, PlotError, Tint};
pub use layouts::{
    force_tracking_figure, guidance_figure, intentional_contact_figure, ForceTrackingSignals, GuidanceSignals,
    IntentionalContactSignals,
};

#[cfg(test)]
mod tests;
