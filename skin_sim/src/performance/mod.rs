//! `docs/performance.md` and its figures, generated from the benchmark results (`make bench`:
//! `out/bench/summary.json` for the medians, `out/bench/stages.json` for each point's sizes and
//! stage shares): how the cost of `Controller::update` grows with the number of cells, of active
//! cells and of joints, and which stage dominates where; and the simulation's own speed per
//! scenario, part by part (`skin_sim performance`).

mod charts;
mod doc;
mod measurements;
pub mod simulator;

use std::path::{Path, PathBuf};

use anyhow::Context;

pub use measurements::{load, poly_fit, BenchPoint, Measurements, Series};

/// Writes the figures into the directory named after `doc` beside it (`docs/performance/`) and
/// the document; returns the files written.
pub fn write(measured: &Measurements, sources: [&Path; 2], doc: &Path) -> anyhow::Result<Vec<PathBuf>> {
    let stem = doc.file_stem().context("the document path has no file name")?.to_string_lossy().into_owned();
    let images = doc.with_file_name(&stem);
    std::fs::create_dir_all(&images).with_context(|| format!("creating {}", images.display()))?;
    let mut files = Vec::new();
    for s in &measured.series {
        let path = images.join(format!("{}.png", s.key));
        charts::stacked(s, &path).with_context(|| format!("drawing {}", path.display()))?;
        files.push(path);
    }
    if !measured.simulator.is_empty() {
        let path = images.join(format!("{}.png", doc::SIMULATOR_FIGURE));
        charts::loop_parts(&measured.simulator, &path).with_context(|| format!("drawing {}", path.display()))?;
        files.push(path);
    }
    let text = doc::render(measured, sources, &stem);
    std::fs::write(doc, text).with_context(|| format!("writing {}", doc.display()))?;
    files.push(doc.to_path_buf());
    Ok(files)
}
