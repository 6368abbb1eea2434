//! The lab: physics experiments that check consequences of the dynamics against theory,
//! each writing `result.json` (parameters, data, checks with verdicts) and SVG plots.
//!
//! Every experiment takes [`Options`] (`quick` for a CI-sized run, a seed, an output
//! directory), returns an [`ExperimentResult`], and is also a binary
//! (`cargo run --release --bin <name>`) through [`main_for`].

pub mod bench;
pub mod check;
pub mod collision_rate;
pub mod equation_of_state;
pub mod equipartition;
pub mod floor;
pub mod maxwell_boltzmann;
pub mod plot;
pub mod report;
pub mod stats;
pub mod wall_pressure;

pub use check::Check;

use crate::io::output::{OutputError, write_atomic};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// How to run an experiment.
#[derive(Clone, Debug, PartialEq)]
pub struct Options {
    /// CI-sized run (seconds) instead of report quality (minutes).
    pub quick: bool,
    /// Seed of the initial states.
    pub seed: u64,
    /// Where `<name>/result.json` and the plots go.
    pub out: PathBuf,
}

/// What an experiment produced.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ExperimentResult {
    /// The experiment's name (its binary and directory).
    pub name: String,
    /// Whether this was the quick version.
    pub quick: bool,
    /// The seed.
    pub seed: u64,
    /// The parameters used.
    pub parameters: serde_json::Value,
    /// The measured data.
    pub data: serde_json::Value,
    /// The checks and their verdicts.
    pub checks: Vec<Check>,
    /// SVG files written beside `result.json`.
    pub plots: Vec<String>,
}

impl ExperimentResult {
    /// Whether every check passed.
    pub fn passed(&self) -> bool {
        self.checks.iter().all(|c| c.pass)
    }

    /// The experiment's own directory under `out`.
    pub fn dir(out: &Path, name: &str) -> PathBuf {
        out.join(name)
    }

    /// Writes `result.json` (atomically) into the experiment's directory.
    pub fn write(&self, out: &Path) -> Result<(), OutputError> {
        let dir = ExperimentResult::dir(out, &self.name);
        std::fs::create_dir_all(&dir).map_err(crate::io::rundir::at(&dir))?;
        let text = serde_json::to_string_pretty(self).expect("results serialise");
        write_atomic(&dir.join("result.json"), text.as_bytes())
    }
}

/// An experiment's entry point.
pub type Experiment = fn(&Options) -> Result<ExperimentResult, String>;

/// The options of an experiment on the command line (`--quick`, `--seed`, `--out`): the
/// experiment binaries and `collide experiment` take the same.
#[derive(clap::Args, Clone, Debug)]
pub struct ExperimentArgs {
    /// CI-sized run (seconds) instead of report quality.
    #[arg(long)]
    pub quick: bool,
    /// Seed of the initial states.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Output directory.
    #[arg(long, default_value = "lab-out")]
    pub out: PathBuf,
}

impl From<ExperimentArgs> for Options {
    fn from(args: ExperimentArgs) -> Options {
        Options { quick: args.quick, seed: args.seed, out: args.out }
    }
}

/// `main` of an experiment binary: parses `--quick`, `--seed`, `--out`, runs, writes, prints
/// the verdict table, and exits 1 if a check fails (2 on an error).
pub fn main_for(name: &str, experiment: Experiment) -> ExitCode {
    use clap::Parser;
    #[derive(Parser)]
    struct Args {
        #[command(flatten)]
        options: ExperimentArgs,
    }
    run_one(name, experiment, &Args::parse().options.into())
}

/// Runs one experiment, writes its results, prints the verdict table, and says how it went:
/// 0 if every check passes, 1 if one fails, 2 on an error.
pub fn run_one(name: &str, experiment: Experiment, options: &Options) -> ExitCode {
    match experiment(options).and_then(|r| r.write(&options.out).map(|_| r).map_err(|e| e.to_string())) {
        Ok(result) => {
            // Writes that fail (stdout closed, e.g. piped into `head`) are not errors of the run.
            use std::io::Write as _;
            let mut stdout = std::io::stdout();
            let _ = write!(stdout, "{}", check::table(name, &result.checks));
            let _ = writeln!(stdout, "results in {}", ExperimentResult::dir(&options.out, name).display());
            if result.passed() { ExitCode::SUCCESS } else { ExitCode::FAILURE }
        }
        Err(e) => {
            eprintln!("{name}: {e}");
            ExitCode::from(2)
        }
    }
}
