//! `skin_sim`: the papers' scenarios in MuJoCo, closed-loop with the skin_core controller.
//!
//! `skin_sim list` names the scenarios; `skin_sim run <scenario|scene file>` runs one, prints a
//! summary and writes `metrics.json` and `summary.txt` into `--out`; the exit code is non-zero
//! when an outcome check fails.

use std::io::{IsTerminal, Write};
use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use skin_sim::outputs::{FigurePng, RunBag};
use skin_sim::report::{write_all, MetricsJson, RunOutput, SummaryText};
use skin_sim::runner::RunTarget;
use skin_sim::scenario::SCENARIOS;
use skin_sim::scene::RunOverrides;

#[derive(Parser)]
#[command(version, about = "Closed-loop MuJoCo scenarios of skin_control (papers 000 and 003)", long_about = None)]
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
    },
}

/// The products of a run. The figure and the bag writers are added here.
fn outputs() -> Vec<Box<dyn RunOutput>> {
    vec![Box::new(MetricsJson), Box::new(SummaryText), Box::new(FigurePng), Box::new(RunBag)]
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

fn run(args: Command) -> anyhow::Result<bool> {
    let Command::Run { target, out, controller, duration, control_rate, dt, seed, quiet } = args else {
        for s in &SCENARIOS {
            println!("{:28} {}", s.name, s.description);
        }
        return Ok(true);
    };
    let target = RunTarget::resolve(&target, controller).map_err(anyhow::Error::msg)?;
    let overrides = RunOverrides {
        duration_s: duration,
        timestep_s: dt,
        control_rate_hz: control_rate,
        seed,
    };
    let mut progress = (!quiet).then(|| progress_line(target.name.clone(), duration));
    let report = target.run(&overrides, |done| {
        if let Some(p) = &mut progress {
            p(done)
        }
    })?;
    let dir = out.unwrap_or_else(|| PathBuf::from("out").join(&target.name));
    let outputs = outputs();
    let outputs: Vec<&dyn RunOutput> = outputs.iter().map(|o| o.as_ref()).collect();
    let files = write_all(&report, &dir, &outputs)?;
    print!("{}", report.summary());
    let names: Vec<String> = files.iter().map(|f| f.display().to_string()).collect();
    println!("  wrote {}", names.join(", "));
    Ok(report.passed())
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
