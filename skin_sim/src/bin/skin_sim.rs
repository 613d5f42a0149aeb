//! `skin_sim`: the papers' scenarios in MuJoCo, closed-loop with the skin_core controller.
//!
//! `skin_sim list` names the scenarios; `skin_sim run <scenario|scene file>` runs one, prints a
//! summary and writes `metrics.json` and `summary.txt` into `--out`; the exit code is non-zero
//! when an outcome check fails. `skin_sim sweep` runs the speed/accuracy study and generates
//! `docs/tradeoffs.md` (`make study`); `skin_sim performance` generates `docs/performance.md` from
//! the benchmark results (`make performance`).

use std::io::{IsTerminal, Write};
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use clap::{Parser, Subcommand};
use skin_sim::outputs::artifacts::{FigurePng, KeyFrames, RunBag};
use skin_sim::outputs::report::{write_all, MetricsJson, RunOutput, SummaryText};
use skin_sim::run::runner::RunTarget;
use skin_sim::run::scenario::SCENARIOS;
use skin_sim::scene::RunOverrides;
use skin_sim::study::{self, StudyResults, StudyScenario};

#[derive(Parser)]
#[command(version, about = "Closed-loop MuJoCo scenarios of skin_control (intentional-contact and interactive-force-control papers)", long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// List the scenarios with what each reproduces.
    List,
    /// Run a scenario (by name) or a scene file; exit code 1 when an outcome check fails.
    Run {
        /// Scenario name (see `skin_sim list`) or a scene file (`config/scenes/*.yaml`).
        target: String,
        /// Output directory for metrics.json and summary.txt [default: out/<name>].
        #[arg(long)]
        out: Option<PathBuf>,
        /// Controller setup file (required for a scene file that is no scenario's).
        #[arg(long)]
        controller: Option<PathBuf>,
        /// Simulated duration [s] instead of the scene's `duration_s`.
        #[arg(long)]
        duration: Option<f64>,
        /// Control rate [Hz] instead of the scene's `control_rate_hz` (its period must be a
        /// whole number of timesteps).
        #[arg(long)]
        control_rate: Option<f64>,
        /// MuJoCo timestep [s] instead of the scene's `timestep_s`.
        #[arg(long)]
        dt: Option<f64>,
        /// Seed of the sensor noise instead of the scene's `seed`.
        #[arg(long)]
        seed: Option<u64>,
        /// No progress line on stderr.
        #[arg(long)]
        quiet: bool,
        /// Also render a video of the run (run.mp4 through ffmpeg, else run.gif) with the skin
        /// and contact overlay, at the scene's view.fps.
        #[arg(long)]
        video: bool,
    },
    /// Run the speed/accuracy study over control rate, timestep, skin density and the inverse's
    /// damping; write results.json and generate the document with its figures.
    Sweep(SweepArgs),
    /// Generate the performance document (cost curves of `Controller::update` over cells, active
    /// cells and joints, and the simulation's speed per scenario, with their figures) from the
    /// benchmark results of `make bench`.
    Performance {
        /// The benchmark medians.
        #[arg(long, default_value = "out/bench/summary.json")]
        summary: PathBuf,
        /// The points' sizes and stage shares (written by skin_core's controller benchmarks).
        #[arg(long, default_value = "out/bench/stages.json")]
        stages: PathBuf,
        /// The generated document; its figures go into the directory of the same name beside it.
        #[arg(long, default_value = "docs/performance.md")]
        doc: PathBuf,
    },
    /// Run the randomized scene campaign: scenes varied from a seed, judged for safety and
    /// success; writes results.json and summary.json, and with --doc the page and its figures
    /// (`make campaign`: docs/robustness.md). Exit code 1 when a scene has a safety violation.
    Campaign(CampaignArgs),
}

#[derive(clap::Args)]
struct CampaignArgs {
    /// Number of scenes (they cycle through the families).
    #[arg(long, default_value_t = 200)]
    scenes: usize,
    /// Seed of the campaign: the same seed gives the same scenes.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Worker threads [default: the machine's cores].
    #[arg(long)]
    jobs: Option<usize>,
    /// Run only the scenes of this family (planar_contact, tomm_reach, force_tracking,
    /// tactile_guidance), with the ids they have in the whole campaign.
    #[arg(long)]
    family: Option<String>,
    /// Run only this scene (its full outputs go into <out>/<id>/).
    #[arg(long)]
    only: Option<usize>,
    /// Output directory: results.json, summary.json.
    #[arg(long, default_value = "out/campaign")]
    out: PathBuf,
    /// Also write this page, its figures in a folder of the same name beside it (`make campaign`:
    /// docs/robustness.md); none by default, so a family's or a seed's run leaves the committed
    /// page alone.
    #[arg(long)]
    doc: Option<PathBuf>,
    /// No progress lines on stderr.
    #[arg(long)]
    quiet: bool,
}

#[derive(clap::Args)]
struct SweepArgs {
    /// The full cross product of the axes instead of the default grid (long: ~1000 runs).
    #[arg(long)]
    full: bool,
    /// Scenarios to study, comma-separated [default: intentional_contact, tomm_movable_obstacles,
    /// force_tracking_base_motion].
    #[arg(long, value_delimiter = ',')]
    scenarios: Vec<String>,
    /// Simulated duration of every run [s] instead of each scenario's study duration.
    #[arg(long)]
    duration: Option<f64>,
    /// Worker threads [default: the machine's cores].
    #[arg(long)]
    jobs: Option<usize>,
    /// Output directory: results.json and the variant setup files.
    #[arg(long, default_value = "out/study")]
    out: PathBuf,
    /// The generated document; its figures go into the directory of the same name beside it.
    #[arg(long, default_value = "docs/tradeoffs.md")]
    doc: PathBuf,
    /// Do not run: regenerate the document from this results.json.
    #[arg(long)]
    from: Option<PathBuf>,
    /// No progress lines on stderr.
    #[arg(long)]
    quiet: bool,
}

/// The products of a run (`skin_sim::outputs::artifacts::ALL`), the video when asked for.
fn outputs(video: bool) -> Vec<Box<dyn RunOutput>> {
    vec![
        Box::new(MetricsJson),
        Box::new(SummaryText),
        Box::new(FigurePng),
        Box::new(RunBag),
        Box::new(KeyFrames { video }),
    ]
}

/// A progress line on stderr, redrawn at most every 2 % of the run on a terminal (every 25 %
/// in a log, where carriage returns do not redraw).
fn progress_line(name: String, duration_s: Option<f64>) -> impl FnMut(f64) {
    let mut shown = -1.0;
    let step = if std::io::stderr().is_terminal() { 0.02 } else { 0.25 };
    move |done: f64| {
        if done - shown < step && done < 1.0 {
            return;
        }
        shown = done;
        let width = 30;
        let bar = (done * width as f64) as usize;
        let sim = duration_s.map_or(String::new(), |d| format!(" {:.1}/{d:.0} s", done * d));
        let end = if done >= 1.0 || step > 0.02 { "\n" } else { "" };
        eprint!("\r{name} [{}{}] {:3.0} %{sim}{end}", "#".repeat(bar), " ".repeat(width - bar), 100.0 * done);
        let _ = std::io::stderr().flush();
    }
}

/// The study's scenarios: the named ones (or the default set) with their durations.
fn study_scenarios(args: &SweepArgs) -> anyhow::Result<Vec<StudyScenario>> {
    let named: Vec<(String, f64)> = if args.scenarios.is_empty() {
        study::grid::DEFAULT_SCENARIOS.iter().map(|&(n, d)| (n.to_string(), d)).collect()
    } else {
        let default = |n: &str| study::grid::DEFAULT_SCENARIOS.iter().find(|s| s.0 == n).map(|s| s.1);
        args.scenarios.iter().map(|n| (n.clone(), default(n).unwrap_or(20.0))).collect()
    };
    named
        .into_iter()
        .map(|(name, duration)| {
            let target = RunTarget::resolve(&name, None).map_err(anyhow::Error::msg)?;
            Ok(StudyScenario { target, duration_s: args.duration.unwrap_or(duration) })
        })
        .collect()
}

fn sweep(args: SweepArgs) -> anyhow::Result<bool> {
    let results_file = args.out.join("results.json");
    let results = match &args.from {
        Some(from) => StudyResults::load(from)?,
        None => {
            let scenarios = study_scenarios(&args)?;
            let points = study::grid_points(&scenarios, args.full)?;
            let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
            let jobs = args.jobs.unwrap_or(cores).max(1);
            eprintln!(
                "study: {} points over {} scenarios on {jobs} threads ({} build)",
                points.len(),
                scenarios.len(),
                study::profile()
            );
            let started = Instant::now();
            let points = study::run(&scenarios, &points, jobs, &args.out.join("variants"), |done, total, r| {
                if !args.quiet {
                    eprintln!("{}", study::progress_line(done, total, r, started));
                }
            })?;
            let command =
                std::iter::once("skin_sim".to_string()).chain(std::env::args().skip(1)).collect::<Vec<_>>().join(" ");
            let results = StudyResults {
                command,
                grid: if args.full { "full" } else { "default" }.into(),
                profile: study::profile().into(),
                jobs,
                cores,
                wall_time_s: started.elapsed().as_secs_f64(),
                points,
            };
            results.save(&results_file)?;
            println!("wrote {}", results_file.display());
            results
        }
    };
    let shown = args.from.as_deref().unwrap_or(&results_file);
    let files = study::doc::write(&results, shown, &args.doc)?;
    let names: Vec<String> = files.iter().map(|f| f.display().to_string()).collect();
    println!("wrote {}", names.join(", "));
    let failed = results.points.iter().filter(|p| matches!(p.outcome, study::Outcome::Failed { .. })).count();
    if failed > 0 {
        eprintln!("study: {failed} points failed to run (see the document)");
    }
    Ok(failed == 0)
}

fn run(args: Command) -> anyhow::Result<bool> {
    let (target, out, controller, duration, control_rate, dt, seed, quiet, video) = match args {
        Command::List => {
            for s in &SCENARIOS {
                println!("{:28} {}", s.name, s.description);
            }
            return Ok(true);
        }
        Command::Sweep(args) => return sweep(args),
        Command::Campaign(args) => return campaign(args),
        Command::Performance { summary, stages, doc } => {
            let measured = skin_sim::performance::load(&summary, &stages)?;
            let files = skin_sim::performance::write(&measured, [&summary, &stages], &doc)?;
            let names: Vec<String> = files.iter().map(|f| f.display().to_string()).collect();
            println!("wrote {}", names.join(", "));
            return Ok(true);
        }
        Command::Run { target, out, controller, duration, control_rate, dt, seed, quiet, video } => {
            (target, out, controller, duration, control_rate, dt, seed, quiet, video)
        }
    };
    let target = RunTarget::resolve(&target, controller).map_err(anyhow::Error::msg)?;
    let overrides = RunOverrides { duration_s: duration, timestep_s: dt, control_rate_hz: control_rate, seed };
    let mut progress = (!quiet).then(|| progress_line(target.name.clone(), duration));
    let report = target.run(&overrides, |done| {
        if let Some(p) = &mut progress {
            p(done)
        }
    })?;
    let dir = out.unwrap_or_else(|| PathBuf::from("out").join(&target.name));
    let outputs = outputs(video);
    let outputs: Vec<&dyn RunOutput> = outputs.iter().map(|o| o.as_ref()).collect();
    let files = write_all(&report, &dir, &outputs)?;
    print!("{}", report.summary());
    let names: Vec<String> = files.iter().map(|f| f.display().to_string()).collect();
    println!("  wrote {}", names.join(", "));
    Ok(report.passed())
}

/// `skin_sim campaign`: the whole campaign, or one scene of it (`--only`).
fn campaign(args: CampaignArgs) -> anyhow::Result<bool> {
    use skin_sim::campaign;
    if let Some(id) = args.only {
        let s = campaign::scene(args.seed, id).map_err(anyhow::Error::msg)?;
        let dir = args.out.join(id.to_string());
        let r = campaign::run_scene(&s, Some(&dir));
        println!("scene {id} ({}): drawn {}", r.family, r.drawn);
        let failures = campaign::failures(&r);
        println!(
            "{} (outputs in {})",
            if failures.is_empty() { "ok".to_string() } else { failures.join("; ") },
            dir.display()
        );
        return Ok(failures.is_empty());
    }
    let jobs = args.jobs.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
    if let Some(f) = args.family.as_deref().filter(|f| !campaign::families::FAMILIES.iter().any(|x| x.name == *f)) {
        anyhow::bail!("--family {f}: no such family (skin_sim/src/campaign/families.rs)");
    }
    let families = campaign::families::FAMILIES;
    let total = (0..args.scenes)
        .filter(|id| args.family.as_deref().is_none_or(|f| families[id % families.len()].name == f))
        .count();
    let (results, summary) = campaign::run(args.seed, args.scenes, jobs, args.family.as_deref(), |done, r| {
        if !args.quiet {
            let failures = campaign::failures(r);
            let status = if failures.is_empty() { "ok".to_string() } else { failures.join("; ") };
            eprintln!("[{done}/{total}] scene {} ({}) {:.1} s: {status}", r.id, r.family, r.wall_s);
        }
    });
    let files = campaign::write(&args.out, args.doc.as_deref(), &results, &summary)?;
    println!("{}", serde_json::to_string_pretty(&summary)?);
    for f in files {
        println!("wrote {}", f.display());
    }
    Ok(summary.safety_violations == 0 && summary.errors == 0)
}

fn main() -> ExitCode {
    match run(Cli::parse().command) {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::from(1),
        Err(e) => {
            eprintln!("skin_sim: {e:#}");
            ExitCode::from(2)
        }
    }
}
