//! One scene's row of `results.json`.

use serde::Serialize;
use serde_json::Value;

use super::verdict::Verdict;

/// One scene's row of `results.json`.
#[derive(Debug, Clone, Serialize)]
pub struct SceneResult {
    /// Index in the campaign.
    pub id: usize,
    /// Family name.
    pub family: &'static str,
    /// What was drawn.
    pub drawn: Value,
    /// The largest friction a push must overcome \[N\] (null: a fixed obstacle).
    pub resistance_n: f64,
    /// Whether the goal can be reached by pushing under `ε_c`.
    pub feasible: bool,
    /// The run failed to start (a scene error) or ran.
    pub error: Option<String>,
    /// What it showed.
    pub verdict: Option<Verdict>,
    /// Its metrics.
    pub metrics: Option<Value>,
    /// Wall-clock time of the run \[s\].
    pub wall_s: f64,
}
