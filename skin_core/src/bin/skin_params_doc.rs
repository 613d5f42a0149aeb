//! Writes `docs/parameters.md`: every declared parameter of the shipped parameter files with its
//! value, unit, range and description (`skin_core::param_file::declare`).

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Parser;

/// Generate the parameter reference (docs/parameters.md) from the declarations in the code.
#[derive(Parser)]
#[command(version, about)]
struct Args {
    /// Repository root (the shipped files are read from its config/).
    #[arg(long, default_value = ".")]
    root: PathBuf,
    /// Write here instead of stdout.
    #[arg(long)]
    out: Option<PathBuf>,
}

fn main() -> ExitCode {
    let args = Args::parse();
    match skin_core::params_doc::document(&args.root) {
        Ok(text) => match &args.out {
            Some(path) => match std::fs::write(path, text) {
                Ok(()) => ExitCode::SUCCESS,
                Err(e) => {
                    eprintln!("skin_params_doc: cannot write {}: {e}", path.display());
                    ExitCode::FAILURE
                }
            },
            None => {
                print!("{text}");
                ExitCode::SUCCESS
            }
        },
        Err(e) => {
            eprintln!("skin_params_doc: {e}");
            ExitCode::FAILURE
        }
    }
}
