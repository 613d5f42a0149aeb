//! What the results say: per scenario the points that ran stably with an accuracy figure, the
//! Pareto front of accuracy against cost, and the recommended settings.

use super::figures::Figures;
use super::grid::Density;
use super::variant::PointResult;

/// The accurate run may cost more only for an error this much smaller than the cheaper
/// near-best points' (relative): within it, the cheapest wins.
pub const ACCURATE_MARGIN: f64 = 0.05;
/// The fast preview: the cheapest stable point whose error is at most this multiple of the
/// accurate run's.
pub const PREVIEW_FACTOR: f64 = 2.0;

/// Errors closer than this count as equal: goal errors \[m\] (a tenth of the usual 1 cm tolerance)…
pub const GOAL_RESOLUTION_M: f64 = 1e-3;
/// …and RMS force errors \[N\].
pub const FORCE_RESOLUTION_N: f64 = 0.01;

/// A point that ran stably and measured its accuracy: (result, cost \[s/s\], error).
#[derive(Debug, Clone, Copy)]
pub struct Candidate<'a> {
    /// The point.
    pub result: &'a PointResult,
    /// [`Figures::cost`] \[s/s\].
    pub cost: f64,
    /// [`Figures::error`].
    pub error: f64,
    /// Errors closer than this count as equal ([`GOAL_RESOLUTION_M`], [`FORCE_RESOLUTION_N`]).
    pub resolution: f64,
}

/// Scenario names in the order they first appear.
pub fn scenarios(points: &[PointResult]) -> Vec<&str> {
    let mut out: Vec<&str> = Vec::new();
    for p in points {
        if !out.contains(&p.point.scenario.as_str()) {
            out.push(&p.point.scenario);
        }
    }
    out
}

/// The points of `scenario`.
pub fn of<'a>(points: &'a [PointResult], scenario: &str) -> Vec<&'a PointResult> {
    points.iter().filter(|p| p.point.scenario == scenario).collect()
}

/// The stable points with an accuracy figure.
pub fn candidates<'a>(points: &[&'a PointResult]) -> Vec<Candidate<'a>> {
    points
        .iter()
        .filter_map(|&result| {
            let f: &Figures = result.figures()?;
            let error = f.error()?;
            let resolution = if f.goal_error_m.is_some() { GOAL_RESOLUTION_M } else { FORCE_RESOLUTION_N };
            f.unstable.is_none().then_some(Candidate { result, cost: f.cost(), error, resolution })
        })
        .collect()
}

/// The Pareto front: candidates no other one beats on both cost and error, by cost.
pub fn pareto<'a>(candidates: &[Candidate<'a>]) -> Vec<Candidate<'a>> {
    let mut sorted = candidates.to_vec();
    sorted.sort_by(|a, b| a.cost.total_cmp(&b.cost).then(a.error.total_cmp(&b.error)));
    let mut best = f64::INFINITY;
    sorted
        .into_iter()
        .filter(|c| {
            let keep = c.error < best;
            best = best.min(c.error);
            keep
        })
        .collect()
}

/// The recommended settings of one scenario.
#[derive(Debug, Clone, Copy)]
pub struct Recommendation<'a> {
    /// The cheapest point within [`PREVIEW_FACTOR`] (or the resolution) of the accurate run's
    /// error.
    pub preview: Candidate<'a>,
    /// The most accurate point (the cheapest within [`ACCURATE_MARGIN`] or the resolution of the
    /// best error).
    pub accurate: Candidate<'a>,
}

/// The recommendation among `candidates` with the full skin (None: no such point measured its
/// accuracy). A reduced density changes what the robot senses, not how faithfully it is
/// simulated: with fewer cells the arm sees less of an obstacle and may reach its goal more
/// directly, which the goal error would reward. Densities are measured, not recommended.
pub fn recommend<'a>(candidates: &[Candidate<'a>]) -> Option<Recommendation<'a>> {
    let full: Vec<Candidate> =
        candidates.iter().filter(|c| c.result.point.setting.density == Density::Full).copied().collect();
    let candidates = &full[..];
    let best = candidates.iter().map(|c| c.error).fold(f64::INFINITY, f64::min);
    let cheapest_within =
        |limit: f64| candidates.iter().filter(|c| c.error <= limit).min_by(|a, b| a.cost.total_cmp(&b.cost)).copied();
    let resolution = candidates.first()?.resolution;
    let accurate = cheapest_within((best * (1.0 + ACCURATE_MARGIN)).max(best + resolution))?;
    let preview = cheapest_within((accurate.error * PREVIEW_FACTOR).max(accurate.error + resolution))?;
    Some(Recommendation { preview, accurate })
}
