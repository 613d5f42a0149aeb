//! What a run produced: the per-cycle [`record`] and the rendered [`view`], reduced to
//! [`metrics`] (`metrics.json`), judged by [`safety`] and the scene's [`outcome`] checks,
//! summarised in a [`report`], drawn by [`plot`] and written as files by [`artifacts`]
//! (`figure.png`, `run.mcap` with the `skin_bag` crate's writer, `keyframes.json` and frames).

pub mod artifacts;
pub mod metrics;
pub mod outcome;
pub mod plot;
pub mod record;
pub mod report;
pub mod safety;
pub mod view;
