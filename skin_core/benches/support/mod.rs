//! What the controller benchmarks share: the shipped setups, readings with a chosen number of
//! live cells, the timed loop and the stage shares written for `docs/performance.md`.

use std::collections::BTreeMap;
use std::hint::black_box;
use std::path::{Path, PathBuf};

use criterion::Criterion;
use nalgebra::Vector2;
use skin_core::controller::{Controller, ControllerConfig, ControllerInput, Stage};
use skin_core::skin::layout::ResolvedLayout;
use skin_core::skin::signals::CellReading;
use skin_core::supervisor::Policy;

/// The repository root.
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// The shipped controller setup of `robot` (`config/controller/<robot>.yaml`).
pub fn config(robot: &str) -> ControllerConfig {
    ControllerConfig::load(&root().join(format!("config/controller/{robot}.yaml"))).unwrap()
}

pub fn names(list: &[&str]) -> Vec<String> {
    list.iter().map(|s| s.to_string()).collect()
}

/// A reading in range of an obstacle (proximity only: an avoidance row, intentional-contact
/// paper eq. 3).
pub const IN_RANGE: CellReading = CellReading { force: [0.0; 3], proximity: 0.6 };
/// A reading of a touch (force and proximity at contact).
pub const IN_CONTACT: CellReading = CellReading { force: [0.3; 3], proximity: 1.0 };

/// TOMM's setup with the precontact arrangement of four levels (skin avoidance, hand distance,
/// wrist, tactile guidance) plus the posture torque with body compliance and base avoidance.
pub fn tomm_config() -> ControllerConfig {
    let mut cfg = config("tomm");
    cfg.supervisor.policy = Policy::Phases;
    cfg.supervisor.arrangements.precontact =
        names(&["avoidance", "hand_distance", "wrist", "tactile_guidance", "base_avoidance", "compliance", "posture"]);
    cfg
}

/// Readings with `in_range` cells in range spread evenly over the whole skin and `in_contact`
/// touched cells spread evenly over the patches of `touched` (layout patch ids).
pub fn readings(layout: &ResolvedLayout, in_range: usize, in_contact: usize, touched: &[u32]) -> Vec<CellReading> {
    let n = layout.num_cells();
    let mut cells = vec![CellReading::default(); n];
    for k in 0..in_range {
        cells[k * n / in_range.max(1)] = IN_RANGE;
    }
    let pool: Vec<usize> =
        layout.patches().iter().filter(|p| touched.contains(&p.id)).flat_map(|p| p.cells.clone()).collect();
    for k in 0..in_contact {
        cells[pool[k * pool.len() / in_contact.max(1)]] = IN_CONTACT;
    }
    cells
}

/// The 360-point LIDAR scan of the TOMM benchmarks (a wavy ring 0.4-0.8 m around the base).
pub fn scan() -> Vec<Vector2<f64>> {
    (0..360)
        .map(|k| {
            let a = (k as f64).to_radians();
            Vector2::new(a.cos(), a.sin()) * (0.6 + 0.2 * (3.0 * a).cos())
        })
        .collect()
}

/// One benchmark point: the controller, its state and readings.
pub struct Point {
    /// Benchmark id (`<id>_ns` in `out/bench/summary.json`).
    pub id: String,
    /// The controller, built.
    pub ctl: Controller,
    /// Joint positions (joint velocities are a fixed small pattern).
    pub q: Vec<f64>,
    /// One reading per cell.
    pub cells: Vec<CellReading>,
    /// Laser points.
    pub scan: Vec<Vector2<f64>>,
}

impl Point {
    /// A point with the setup's posture as state.
    pub fn new(id: impl Into<String>, ctl: Controller, cells: Vec<CellReading>, scan: Vec<Vector2<f64>>) -> Self {
        let q = ctl.config().setup.posture.clone();
        Point { id: id.into(), ctl, q, cells, scan }
    }
}

/// Timed batches of [`BATCH`] cycles for the stage shares.
const BATCHES: usize = 301;
const BATCH: usize = 8;

/// Benchmarks `Controller::update` at `p` and, when run by `cargo bench`, records the point's
/// stage shares (each stage's median over timed batches of cycles) and sizes in
/// `out/bench/stages.json`.
pub fn bench(c: &mut Criterion, p: Point) {
    let Point { id, mut ctl, q, cells, scan } = p;
    let qd: Vec<f64> = (0..q.len()).map(|i| 0.02 * ((i as f64) * 0.7).sin()).collect();
    // each controller with its own clock: the timed copy's cycles do not move the measured one's
    let step = |ctl: &mut Controller, t: &mut f64| {
        *t += 0.008;
        let out = ctl.update(&ControllerInput { t_s: *t, dt_s: 0.008, q: &q, qd: &qd, cells: &cells, scan: &scan });
        assert!(out.fault.is_none(), "{id}: {:?}", out.fault);
        black_box(out.commands.joint_velocities[0]);
    };
    let args: Vec<String> = std::env::args().collect();
    // not in criterion's profiling mode (`--profile-time`, e.g. under callgrind): only the cycles
    let measuring = args.iter().any(|a| a == "--bench") && !args.iter().any(|a| a == "--profile-time");
    if measuring && selected(&id) {
        // a second controller from the same setup, with the same goal
        let mut timed = Controller::new(ctl.config().clone(), 0.0).expect("the point's setup builds");
        timed.set_goal(ctl.goal().copied()).expect("the point's goal is finite");
        let mut t = 0.0;
        for _ in 0..200 {
            step(&mut timed, &mut t);
        }
        // per stage the median over batches of cycles: a batch the scheduler interrupted (a
        // busy machine) counts once, not with its whole pause
        let mut batches: Vec<[f64; 5]> = (0..BATCHES)
            .map(|_| {
                timed.set_stage_timing(true);
                for _ in 0..BATCH {
                    step(&mut timed, &mut t);
                }
                let times = timed.stage_times().unwrap();
                Stage::ALL.map(|s| times.total_ns(s) as f64)
            })
            .collect();
        let median: Vec<f64> = (0..Stage::ALL.len())
            .map(|k| {
                batches.sort_by(|a, b| a[k].total_cmp(&b[k]));
                batches[BATCHES / 2][k]
            })
            .collect();
        let total: f64 = median.iter().sum();
        let rows: usize = timed.level_diagnostics().iter().map(|d| d.rows).sum();
        let cfg = timed.config();
        let mut entry = BTreeMap::new();
        entry.insert("cells".to_string(), cfg.layout.num_cells() as f64);
        entry.insert("live_cells".to_string(), cells.iter().filter(|r| !r.is_silent()).count() as f64);
        entry.insert("joints".to_string(), cfg.model.nv() as f64);
        entry.insert("levels".to_string(), timed.level_diagnostics().len() as f64);
        entry.insert("level_rows".to_string(), rows as f64);
        entry.insert("load_average".to_string(), load_average());
        for (s, m) in Stage::ALL.iter().zip(&median) {
            entry.insert(format!("share_{}", s.name()), m / total);
        }
        record_stages(&id, entry);
    }
    let mut t = 0.0;
    c.bench_function(&id, |b| b.iter(|| step(&mut ctl, &mut t)));
}

/// Whether criterion's name filter (the first free argument) selects `id` (a substring; no
/// filter selects all): the points' setup and stage timing are skipped for the others.
pub fn selected(id: &str) -> bool {
    let filter = std::env::args().skip(1).find(|a| !a.starts_with('-') && a.parse::<f64>().is_err());
    filter.is_none_or(|f| id.contains(&f))
}

/// The machine's 1-minute load average (`/proc/loadavg`; NaN where there is none): a busy
/// machine's figures are not comparable with a quiet one's.
fn load_average() -> f64 {
    let text = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    text.split_whitespace().next().and_then(|v| v.parse().ok()).unwrap_or(f64::NAN)
}

/// Merges one point into `out/bench/stages.json` (point id -> figure -> value).
fn record_stages(id: &str, entry: BTreeMap<String, f64>) {
    let dir = root().join("out/bench");
    std::fs::create_dir_all(&dir).unwrap();
    let path: &Path = &dir.join("stages.json");
    let mut all: BTreeMap<String, BTreeMap<String, f64>> =
        std::fs::read_to_string(path).ok().and_then(|t| serde_json::from_str(&t).ok()).unwrap_or_default();
    all.insert(id.to_string(), entry);
    std::fs::write(path, serde_json::to_string_pretty(&all).unwrap() + "\n").unwrap();
}
