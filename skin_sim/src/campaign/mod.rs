//! `skin_sim campaign`: hundreds of randomized scenes ([`families`]) from one seed, run in
//! parallel, judged for safety and success ([`verdict`]), written to `results.json`,
//! `summary.json` and `docs/robustness.md` (every failure with the seed and the command that
//! reruns it).

pub mod charts;
pub mod families;
mod result;
pub mod verdict;

#[cfg(test)]
mod tests;

use std::path::{Path, PathBuf};
use std::time::Instant;

use serde::Serialize;
use serde_json::Value;

use crate::outputs::artifacts::FigurePng;
use crate::outputs::metrics::TOPPLED_DEG;
use crate::outputs::report::{write_all, MetricsJson, SummaryText};
use crate::run::runner::RunTarget;
use crate::run::scenario;
use crate::scene::spec::SceneSpec;
use crate::scene::Scene;
use crate::study::pool;
use crate::world::noise::Noise;
use families::{Family, EPS_C_N, FAMILIES};
pub use result::SceneResult;
use verdict::{judge, overshoot_ok};

/// One generated scene.
#[derive(Debug, Clone)]
pub struct CampaignScene {
    /// Index in the campaign.
    pub id: usize,
    /// Its family.
    pub family: Family,
    /// What was drawn.
    pub drawn: Value,
    /// The largest friction a push must overcome \[N\] ([`families::resistance_n`]).
    pub resistance_n: f64,
    /// Whether the goal can be reached by pushing under `ε_c`.
    pub feasible: bool,
    /// The scene file it varies, and the scene.
    target: RunTarget,
    spec: SceneSpec,
}

/// Scene `id` of the campaign with `seed`: the same pair always gives the same scene.
pub fn scene(seed: u64, id: usize) -> Result<CampaignScene, String> {
    let family = FAMILIES[id % FAMILIES.len()];
    let sc = scenario::find(family.scenario).ok_or_else(|| format!("no scenario {}", family.scenario))?;
    let target = RunTarget::from(sc);
    let (text, file) = skin_core::param_file::yaml::read_text(&target.scene).map_err(|e| e.to_string())?;
    let mut spec: SceneSpec = skin_core::param_file::yaml::parse_str(&text, &file).map_err(|e| e.to_string())?;
    let mut rng = Noise::new(seed, id as u64 + 1);
    let drawn = (family.vary)(&mut rng, &mut spec);
    let resistance_n = families::resistance_n(&spec, family.obstacles);
    let feasible = !spec.goals.is_empty() && resistance_n < EPS_C_N;
    Ok(CampaignScene { id, family, drawn, resistance_n, feasible, target, spec })
}

impl CampaignScene {
    /// The same scene with another controller setup file (a changed controller measured on it).
    pub fn with_controller(mut self, controller: PathBuf) -> Self {
        self.target.controller = controller;
        self
    }
}

/// Runs `s`; `out`: also write the run's own outputs there.
pub fn run_scene(s: &CampaignScene, out: Option<&Path>) -> SceneResult {
    let start = Instant::now();
    let mut result = SceneResult {
        id: s.id,
        family: s.family.name,
        drawn: s.drawn.clone(),
        resistance_n: s.resistance_n,
        feasible: s.feasible,
        error: None,
        verdict: None,
        metrics: None,
        wall_s: 0.0,
    };
    let text = serde_json::to_string(&s.spec).expect("a scene spec serializes"); // JSON is YAML
    let dir = s.target.scene.parent().unwrap_or(Path::new("."));
    let run = Scene::from_yaml_str(&text, &format!("campaign scene {} ({})", s.id, s.family.name), dir)
        .map_err(|e| e.to_string())
        .and_then(|scene| s.target.run_scene(scene, |_| {}).map_err(|e| e.to_string()));
    match run {
        Ok(report) => {
            result.verdict = Some(judge(&report));
            result.metrics = serde_json::to_value(&report.metrics).ok();
            if let Some(dir) = out {
                if let Err(e) = write_all(&report, dir, &[&MetricsJson, &SummaryText, &FigurePng]) {
                    result.error = Some(format!("writing {}: {e}", dir.display()));
                }
            }
        }
        Err(e) => result.error = Some(e),
    }
    result.wall_s = start.elapsed().as_secs_f64();
    result
}

/// The flat figures of `summary.json`.
#[derive(Debug, Clone, Serialize)]
pub struct Summary {
    /// Seed of the campaign.
    pub seed: u64,
    /// Scenes run.
    pub scenes: usize,
    /// Scenes that could not run (scene errors).
    pub errors: usize,
    /// Scenes with at least one safety violation.
    pub safety_violations: usize,
    /// Feasible goal scenes (the obstacles slide under `ε_c`) whose goal was reached, fraction.
    pub goal_success_rate_feasible: f64,
    /// Force scenes whose interactive-force-control paper Table 3 checks held, fraction.
    pub force_table3_rate: f64,
    /// Largest first-contact overshoot of the hand force over its reference \[N\].
    pub first_contact_overshoot_max_n: f64,
    /// Goal scenes in which a movable object toppled ([`verdict::Verdict::toppled`]); in the
    /// planar family such a scene left what it models (TOMM's arm acts in space, where a block
    /// it pushes may tip over).
    pub toppled_scenes: usize,
    /// Scenes per hour of wall-clock time on the cores used.
    pub campaign_scenes_per_hour: f64,
    /// Worker threads.
    pub jobs: usize,
}

fn rate(hits: impl Iterator<Item = bool>) -> f64 {
    let (n, k) = hits.fold((0usize, 0usize), |(n, k), h| (n + 1, k + h as usize));
    if n == 0 {
        f64::NAN
    } else {
        k as f64 / n as f64
    }
}

/// The summary of `results`, run on `jobs` threads in `wall_s` seconds.
pub fn summarize(seed: u64, results: &[SceneResult], wall_s: f64, jobs: usize) -> Summary {
    let verdicts = || results.iter().filter_map(|r| r.verdict.as_ref().map(|v| (r, v)));
    Summary {
        seed,
        scenes: results.len(),
        errors: results.iter().filter(|r| r.error.is_some()).count(),
        safety_violations: verdicts().filter(|(_, v)| !v.violations.is_empty()).count(),
        goal_success_rate_feasible: rate(verdicts().filter(|(r, _)| r.feasible).filter_map(|(_, v)| v.goal_reached)),
        force_table3_rate: rate(verdicts().filter_map(|(_, v)| v.force_table3)),
        first_contact_overshoot_max_n: verdicts()
            .filter_map(|(_, v)| v.first_contact_overshoot_n)
            .filter(|x| x.is_finite())
            .fold(f64::NEG_INFINITY, f64::max),
        toppled_scenes: verdicts().filter(|(_, v)| v.toppled()).count(),
        campaign_scenes_per_hour: results.len() as f64 / wall_s * 3600.0,
        jobs,
    }
}

/// Runs scenes `0..n` of the campaign `seed` on `jobs` threads, only those of the family named
/// `family` if given (the same ids as in the whole campaign); `done(finished, result)` after each.
pub fn run(
    seed: u64,
    n: usize,
    jobs: usize,
    family: Option<&str>,
    mut done: impl FnMut(usize, &SceneResult),
) -> (Vec<SceneResult>, Summary) {
    let start = Instant::now();
    let ids: Vec<usize> = (0..n).filter(|id| family.is_none_or(|f| FAMILIES[id % FAMILIES.len()].name == f)).collect();
    let mut finished = 0;
    let results = pool::map(
        &ids,
        jobs,
        |_, &id| match scene(seed, id) {
            Ok(s) => run_scene(&s, None),
            Err(e) => SceneResult {
                id,
                family: FAMILIES[id % FAMILIES.len()].name,
                drawn: Value::Null,
                resistance_n: f64::NAN,
                feasible: false,
                error: Some(e),
                verdict: None,
                metrics: None,
                wall_s: 0.0,
            },
        },
        |_, r| {
            finished += 1;
            done(finished, r)
        },
    );
    let summary = summarize(seed, &results, start.elapsed().as_secs_f64(), jobs);
    (results, summary)
}

/// Why a scene failed, one line (empty: it passed).
pub fn failures(r: &SceneResult) -> Vec<String> {
    let mut out: Vec<String> = r.error.iter().map(|e| format!("error: {e}")).collect();
    if let Some(v) = &r.verdict {
        out.extend(v.violations.iter().map(|x| format!("safety: {x}")));
        if r.feasible && v.goal_reached == Some(false) {
            let late = r.metrics.as_ref().and_then(|m| m.get("goal_reached")).and_then(Value::as_bool) == Some(true);
            out.push(
                if late { "goal reached only after the push (feasible)" } else { "goal not reached (feasible)" }.into(),
            );
        }
        if v.force_table3 == Some(false) {
            out.push("Table 3 force error exceeded".into());
        }
        if v.first_contact_overshoot_n.is_some_and(|x| !overshoot_ok(x)) {
            out.push(format!("first-contact overshoot {:.2} N", v.first_contact_overshoot_n.unwrap_or(f64::NAN)));
        }
    }
    out
}

/// The class of a failure line: its text before any `:` and without a trailing value
/// ("first-contact overshoot 2.31 N" → "first-contact overshoot").
fn failure_class(line: &str) -> String {
    let head = line.split(':').next().unwrap_or(line);
    let words: Vec<&str> = head.split_whitespace().collect();
    let value_at = words.iter().rposition(|w| w.parse::<f64>().is_ok()).filter(|&k| k + 2 >= words.len());
    words[..value_at.unwrap_or(words.len())].join(" ")
}

/// The toppled scenes of each family with obstacles, `planar_contact 2, tomm_reach 37`.
fn toppled_by_family(results: &[SceneResult]) -> String {
    let toppled = |f: &Family| {
        let of = |r: &&SceneResult| r.family == f.name && r.verdict.as_ref().is_some_and(|v| v.toppled());
        format!("{} {}", f.name, results.iter().filter(of).count())
    };
    FAMILIES.iter().filter(|f| !f.obstacles.is_empty()).map(toppled).collect::<Vec<_>>().join(", ")
}

/// `docs/robustness.md`: the summary, the failure classes per family, the figures (in
/// `figures`, relative to the page) and every failing scene with the command that reruns it.
pub fn robustness_md(results: &[SceneResult], s: &Summary, figures: &str) -> String {
    let mut md = format!(
        "# Robustness: the randomized scene campaign\n\n\
         Generated by `make campaign` (`skin_sim campaign --scenes {} --seed {} --jobs {}`); do not edit by\n\
         hand. {} scenes from four families, each a shipped scenario's scene varied from the seed\n\
         (`skin_sim/src/campaign/families.rs`): planar intentional contact (obstacle position, size,\n\
         mass 0.2-3 kg or fixed, friction under 80 % of the limit where the arm's push would tip the\n\
         obstacle instead of sliding it, a second obstacle, start posture, goal, skin noise), TOMM\n\
         reaching over a table (obstacle shifts, masses, friction), force tracking (reference mean\n\
         2-8 N, amplitude, period 2-8 s, board tilt ±10° about its point in front of the palm, base\n\
         circle radius) and tactile guidance (touched link, force, time).\n\n\
         A safety violation (`skin_sim::outputs::safety`, the definition every scene check uses) is a\n\
         non-finite command, a safe-stop cycle, an arm joint over its URDF velocity limit, a contact\n\
         above eps_c (in a force scene's contact phase: above the reference + 2 N) for more than\n\
         0.5 s in one event, or chatter (one arrangement switch more than twice within 10 s). A goal\n\
         scene is feasible when every obstacle slides under eps_c (mu m g < 5 N) and none is fixed;\n\
         an infeasible one may end `blocked` (the arm gave up the push and holds) if it is safe. A goal\n\
         counts as reached when it is within the tolerance at the end and, in a scene with a scripted\n\
         push on an obstacle (the planar family's at 15 s: a hand pushing it into the arm, as in\n\
         `config/scenes/intentional_contact.yaml`), already when the push starts: a goal that only the\n\
         push cleared the way to was not reached by the controller. An obstacle toppled when it tilted over 45°: the planar arm cannot\n\
         act out of its plane, so a planar scene whose obstacle toppled left what it models (TOMM's\n\
         arm acts in space, where a block it pushes may tip over).\n\n\
         | Figure | Value |\n|---|---|\n\
         | scenes | {} |\n| scenes that could not run | {} |\n| scenes with a safety violation | {} |\n\
         | goal success, feasible scenes | {:.1} % |\n| force scenes within Table 3 | {:.1} % |\n\
         | largest first-contact overshoot | {:.2} N |\n| goal scenes whose obstacle toppled (tilted over {TOPPLED_DEG}°) | {} ({}) |\n\
         | scenes per hour ({} threads) | {:.0} |\n\n\
         ## Failure classes\n\n| Family | Scenes | Failing | Classes |\n|---|---|---|---|\n",
        s.scenes,
        s.seed,
        s.jobs,
        s.scenes,
        s.scenes,
        s.errors,
        s.safety_violations,
        100.0 * s.goal_success_rate_feasible,
        100.0 * s.force_table3_rate,
        s.first_contact_overshoot_max_n,
        s.toppled_scenes,
        toppled_by_family(results),
        s.jobs,
        s.campaign_scenes_per_hour
    );
    for f in FAMILIES {
        let rows: Vec<&SceneResult> = results.iter().filter(|r| r.family == f.name).collect();
        let failing: Vec<Vec<String>> = rows.iter().map(|r| failures(r)).filter(|x| !x.is_empty()).collect();
        let mut classes: Vec<String> = failing.iter().flatten().map(|x| failure_class(x)).collect();
        classes.sort();
        classes.dedup();
        md += &format!("| {} | {} | {} | {} |\n", f.name, rows.len(), failing.len(), classes.join(", "));
    }
    md += &format!(
        "\n## Figures\n\nEvery scene is a point: green passed, red failed, orange gave up an infeasible push and \
         held (safe), a black ring broke a safety rule. Goal scenes against the friction their push had to \
         overcome: left of ε_c they are feasible and must end within the tolerance.\n\n\
         ![Goal scenes]({figures}/goals.png)\n\n\
         Force scenes: the Table 3 errors against what drives them, and the first-touch overshoot.\n\n\
         ![Force scenes]({figures}/forces.png)\n"
    );
    md += "\n## Failing scenes\n\nRerun one with `skin_sim campaign --seed <seed> --only <id>` (outputs in `out/campaign/<id>/`), one family with `--family <name>` (the same ids).\n\n";
    let mut any = false;
    for r in results {
        let f = failures(r);
        if !f.is_empty() {
            any = true;
            let toppled = match &r.verdict {
                Some(v) if v.toppled() => {
                    format!(" (its obstacle toppled: {:.0}°)", v.object_tilt_max_deg.unwrap_or(f64::NAN))
                }
                _ => String::new(),
            };
            md += &format!(
                "- scene {} ({}, seed {}): {}{toppled}; drawn `{}`\n",
                r.id,
                r.family,
                s.seed,
                f.join("; "),
                r.drawn
            );
        }
    }
    if !any {
        md += "None.\n";
    }
    md
}

/// A figure of the campaign's results drawn to a path.
type Chart = fn(&[SceneResult], &Path) -> anyhow::Result<()>;

/// Writes `results.json` and `summary.json` into `dir`, and the page to `doc` with its figures
/// beside it (`docs/robustness/`) if given.
pub fn write(dir: &Path, doc: Option<&Path>, results: &[SceneResult], s: &Summary) -> std::io::Result<Vec<PathBuf>> {
    std::fs::create_dir_all(dir)?;
    let mut files = vec![dir.join("results.json"), dir.join("summary.json")];
    std::fs::write(&files[0], serde_json::to_string_pretty(results).expect("results serialize") + "\n")?;
    std::fs::write(&files[1], serde_json::to_string_pretty(s).expect("summary serializes") + "\n")?;
    if let Some(doc) = doc {
        let stem = doc.file_stem().and_then(|x| x.to_str()).unwrap_or("robustness");
        let figures = doc.with_file_name(stem);
        std::fs::create_dir_all(&figures)?;
        for (name, draw) in [("goals.png", charts::goals as Chart), ("forces.png", charts::forces)] {
            let path = figures.join(name);
            draw(results, &path).map_err(|e| std::io::Error::other(format!("{}: {e}", path.display())))?;
            files.push(path);
        }
        std::fs::write(doc, robustness_md(results, s, stem))?;
        files.push(doc.to_path_buf());
    }
    Ok(files)
}
