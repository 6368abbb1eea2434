//! The lab: physics experiments that check consequences of the dynamics against theory,
//! each writing `result.json` (parameters, data, checks with verdicts) and SVG plots.
//!
//! An experiment is one file: a [`Run`](crate::run::Run) (or several) of a configuration it
//! writes, observed by the run's own observers and its own ([`crate::observe::Observer`]),
//! turned into [`Check`]s against the formulas of [`crate::theory`] with tolerances that say
//! why. Every experiment takes [`Options`] (`quick` for a CI-sized run, a seed, an output
//! directory, the dimension: 2 for disks, 3 for spheres) and returns an [`ExperimentResult`]
//! of the same layout in both dimensions; `collide validate` runs them all, in both dimensions
//! ([`report`]), `collide experiment NAME` one, and each registered in Cargo.toml is also a
//! binary (`cargo run --release --bin <name>`, through [`main_for`]). What each checks, and
//! against which reference, is specified in `docs/experiments.md`.
//!
//! # Adding an experiment
//!
//! Its file here, with `NAME` and `run(&Options)`; then its line in [`EXPERIMENTS`] below
//! (and `pub mod`): `collide experiment <name>` and `collide validate` then run it. A binary of
//! its own, if wanted, is a three-line `src/bin/<name>.rs` calling [`main_for`].

pub mod check;
pub mod collision_rate;
pub mod diffusion;
pub mod equation_of_state;
pub mod equipartition;
pub mod hexatic;
pub mod jamming;
pub mod long_time_tail;
pub mod maxwell_boltzmann;
pub mod plot;
pub mod report;
pub mod stats;
pub mod structure;
pub mod wall_pressure;

pub use check::Check;

use crate::engine::SetupError;
use crate::engine::init::InitError;
use crate::run::output::{OutputError, write_atomic};
use crate::run::{ConfigError, Invalid, RunError, Stall};
use serde::{Deserialize, Serialize};
use std::fmt;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Every experiment, in report order: its name (its directory, its binary) and its entry
/// point.
pub const EXPERIMENTS: &[(&str, Experiment)] = &[
    (maxwell_boltzmann::NAME, maxwell_boltzmann::run),
    (wall_pressure::NAME, wall_pressure::run),
    (equation_of_state::NAME, equation_of_state::run),
    (collision_rate::NAME, collision_rate::run),
    (equipartition::NAME, equipartition::run),
    (jamming::NAME, jamming::run),
    (structure::NAME, structure::run),
    (diffusion::NAME, diffusion::run),
    (long_time_tail::NAME, long_time_tail::run),
    (hexatic::NAME, hexatic::run),
];

/// Why an experiment could not finish (its checks failing is not an error: they are in the
/// result).
#[non_exhaustive]
#[derive(Debug)]
pub enum ExperimentError {
    /// A configuration it wrote is invalid.
    Config(ConfigError),
    /// A production plan is invalid.
    Plan(Invalid),
    /// A run could not start.
    Run(RunError),
    /// An initial state could not be built.
    Init(InitError),
    /// A prepared state is not valid.
    Setup(SetupError),
    /// Nothing could happen any more before the run's length (at simulated time `at`).
    Stopped {
        /// The clock when the gas stopped.
        at: f64,
    },
    /// The watchdog stopped a run.
    Stalled(Stall),
    /// A file could not be written.
    Output(OutputError),
    /// A plot could not be drawn.
    Plot(plot::PlotError),
    /// A result it needs is missing.
    Missing(&'static str),
}

impl fmt::Display for ExperimentError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ExperimentError::Config(e) => write!(f, "{e}"),
            ExperimentError::Plan(e) => write!(f, "{e}"),
            ExperimentError::Run(e) => write!(f, "{e}"),
            ExperimentError::Init(e) => write!(f, "{e}"),
            ExperimentError::Setup(e) => write!(f, "{e}"),
            ExperimentError::Stopped { at } => write!(f, "the gas stopped at t = {at} before the run's length"),
            ExperimentError::Stalled(stall) => write!(f, "{stall}"),
            ExperimentError::Output(e) => write!(f, "{e}"),
            ExperimentError::Plot(e) => write!(f, "{e}"),
            ExperimentError::Missing(what) => write!(f, "{what}"),
        }
    }
}

impl std::error::Error for ExperimentError {}

macro_rules! from {
    ($($source:ty => $variant:ident),*) => {
        $(impl From<$source> for ExperimentError {
            fn from(e: $source) -> Self {
                ExperimentError::$variant(e)
            }
        })*
    };
}
from!(ConfigError => Config, Invalid => Plan, RunError => Run, InitError => Init, SetupError => Setup,
      OutputError => Output, plot::PlotError => Plot);

/// Runs `run` to the end of its production with `sink` and says whether it got there: a run
/// stopped by its watchdog, or one in which nothing can happen any more, is an error.
pub fn run_to_end<const D: usize, S: crate::run::Sink<D, Error = std::convert::Infallible>>(
    run: &mut crate::run::Run<D>,
    sink: &mut S,
) -> Result<(), ExperimentError> {
    let Ok(status) = run.complete(sink);
    if let (crate::run::Status::Stalled, Some(stall)) = run.ended() {
        return Err(ExperimentError::Stalled(stall.clone()));
    }
    if status == crate::run::Status::Complete && !run.done() {
        return Err(ExperimentError::Stopped { at: run.sim.time() });
    }
    Ok(())
}

/// A run of `config` taken to its end without output: the experiments' way of measuring a
/// state through the observers it configures (`run.observables`, in `[observe]`'s order).
pub fn finished_run<const D: usize>(config: crate::run::Config) -> Result<crate::run::Run<D>, ExperimentError> {
    let mut run = crate::run::Run::<D>::new(config)?;
    run_to_end(&mut run, &mut crate::run::Discard)?;
    Ok(run)
}

/// The configuration of a fluid of `n` unit-diameter particles of unit mass at packing
/// fraction `eta` in a periodic box (`d` = 2: from the triangular lattice; 3: from the simple
/// cubic one, which melts at once), `equilibration` collisions then `production`, followed
/// by `observe` (TOML: the `[observe.*]` tables an experiment asks for).
pub fn fluid_config(
    d: usize,
    eta: f64,
    n: usize,
    equilibration: u64,
    production: u64,
    seed: u64,
    observe: &str,
) -> String {
    let placement = if d == 2 { "triangular" } else { "simple_cubic" };
    format!(
        "dimension = {d}\nseed = {seed}\n[box]\npacking_fraction = {eta}\nboundary = \"periodic\"\n\
         [[species]]\ncount = {n}\nradius = 0.5\nmass = 1.0\n[init]\nplacement = \"{placement}\"\n\
         [equilibration]\ncollisions = {equilibration}\n[run]\ncollisions = {production}\n{observe}"
    )
}

/// How long an experiment runs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Size {
    /// CI-sized (seconds): the checks still bite, with wider statistical tolerances.
    Quick,
    /// Report quality (minutes): what `collide validate` runs and the manual quotes.
    #[default]
    Report,
    /// Longer runs (up to an hour or more on two cores) for the experiments that have them
    /// (`structure`, `diffusion`, `long_time_tail`, `hexatic`); the others run at report size.
    Long,
}

impl Size {
    /// The size the flags `--quick` and `--long` ask for (clap refuses both at once).
    pub fn of(quick: bool, long: bool) -> Size {
        if quick {
            Size::Quick
        } else if long {
            Size::Long
        } else {
            Size::Report
        }
    }

    /// `"quick"`, `"report size"` or `"long"`.
    pub fn label(self) -> &'static str {
        match self {
            Size::Quick => "quick",
            Size::Report => "report size",
            Size::Long => "long",
        }
    }
}

/// How to run an experiment.
#[derive(Clone, Debug, PartialEq)]
pub struct Options {
    /// How long.
    pub size: Size,
    /// Seed of the initial states.
    pub seed: u64,
    /// Where `<name>/result.json` (`<name>_3d/` in 3D) and the plots go.
    pub out: PathBuf,
    /// 2 (disks) or 3 (spheres).
    pub dimension: usize,
}

impl Options {
    /// Disks, report size, seed 1, into `out`.
    pub fn new(out: impl Into<PathBuf>) -> Options {
        Options { size: Size::Report, seed: 1, out: out.into(), dimension: 2 }
    }

    /// Whether this is the CI-sized version.
    pub fn quick(&self) -> bool {
        self.size == Size::Quick
    }

    /// The directory name of experiment `name` in this dimension: `name` for disks,
    /// `name_3d` for spheres.
    pub fn slug(&self, name: &str) -> String {
        slug(name, self.dimension)
    }

    /// The experiment's own directory under `out`, created for its plots.
    pub fn plot_dir(&self, name: &str) -> Result<PathBuf, ExperimentError> {
        Ok(ExperimentResult::made_dir(&self.out, &self.slug(name))?)
    }

    /// A result of experiment `name` run with these options.
    pub fn result(
        &self,
        name: &str,
        parameters: serde_json::Value,
        data: serde_json::Value,
        checks: Vec<Check>,
        plots: Vec<String>,
    ) -> ExperimentResult {
        ExperimentResult {
            name: name.into(),
            dimension: self.dimension,
            quick: self.quick(),
            size: self.size,
            seed: self.seed,
            parameters,
            data,
            checks,
            plots,
        }
    }
}

/// The directory name of experiment `name` in dimension `d` (see [`Options::slug`]).
pub fn slug(name: &str, d: usize) -> String {
    if d == 2 { name.to_string() } else { format!("{name}_{d}d") }
}

/// What an experiment produced.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ExperimentResult {
    /// The experiment's name (its binary; its directory in 2D).
    pub name: String,
    /// 2 (disks) or 3 (spheres).
    #[serde(default = "two")]
    pub dimension: usize,
    /// Whether this was the quick version.
    pub quick: bool,
    /// Its size (`quick`, `report` or `long`).
    #[serde(default)]
    pub size: Size,
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

    /// The experiment's own directory under `out` (named by its [`slug`]).
    pub fn dir(out: &Path, slug: &str) -> PathBuf {
        out.join(slug)
    }

    /// Its directory name: the experiment's, with `_3d` for spheres.
    pub fn slug(&self) -> String {
        slug(&self.name, self.dimension)
    }

    /// The experiment's own directory under `out`, created.
    fn made_dir(out: &Path, name: &str) -> Result<PathBuf, OutputError> {
        let dir = ExperimentResult::dir(out, name);
        std::fs::create_dir_all(&dir).map_err(crate::run::rundir::at(&dir))?;
        Ok(dir)
    }

    /// Writes `result.json` (atomically) into the experiment's directory.
    pub fn write(&self, out: &Path) -> Result<(), OutputError> {
        let dir = ExperimentResult::made_dir(out, &self.slug())?;
        let text = serde_json::to_string_pretty(self).expect("results serialise");
        write_atomic(&dir.join("result.json"), text.as_bytes())
    }
}

fn two() -> usize {
    2
}

/// An experiment's entry point.
pub type Experiment = fn(&Options) -> Result<ExperimentResult, ExperimentError>;

/// Runs `job(0)`, …, `job(jobs − 1)` on `workers` threads (at least one), each taking the
/// next job as it finishes one; the results in the jobs' order, or the first error in that
/// order once every job has ended. The jobs are independent, so the results do not depend
/// on `workers`.
pub fn in_parallel<T: Send, F>(jobs: usize, workers: usize, job: F) -> Result<Vec<T>, ExperimentError>
where
    F: Fn(usize) -> Result<T, ExperimentError> + Sync,
{
    use std::sync::Mutex;
    use std::sync::atomic::{AtomicUsize, Ordering};
    let next = AtomicUsize::new(0);
    let results: Mutex<Vec<Option<Result<T, ExperimentError>>>> = Mutex::new((0..jobs).map(|_| None).collect());
    std::thread::scope(|scope| {
        for _ in 0..workers.clamp(1, jobs.max(1)) {
            scope.spawn(|| {
                loop {
                    let k = next.fetch_add(1, Ordering::Relaxed);
                    if k >= jobs {
                        break;
                    }
                    let result = job(k);
                    results.lock().expect("no worker panics")[k] = Some(result);
                }
            });
        }
    });
    results.into_inner().expect("no worker panics").into_iter().map(|r| r.expect("every job ran")).collect()
}

/// The options of an experiment on the command line (`--quick`, `--seed`, `--out`): the
/// experiment binaries and `collide experiment` take the same.
#[derive(clap::Args, Clone, Debug)]
pub struct ExperimentArgs {
    /// CI-sized run (seconds) instead of report quality.
    #[arg(long)]
    pub quick: bool,
    /// Longer runs than report quality, for the experiments that have them (structure,
    /// diffusion, long_time_tail, hexatic); the others run at report size.
    #[arg(long, conflicts_with = "quick")]
    pub long: bool,
    /// Seed of the initial states.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Output directory.
    #[arg(long, default_value = "lab-out")]
    pub out: PathBuf,
    /// 2 (disks) or 3 (spheres).
    #[arg(long, default_value_t = 2, value_parser = clap::value_parser!(u8).range(2..=3))]
    pub dimension: u8,
}

impl From<ExperimentArgs> for Options {
    fn from(args: ExperimentArgs) -> Options {
        Options {
            size: Size::of(args.quick, args.long),
            seed: args.seed,
            out: args.out,
            dimension: args.dimension as usize,
        }
    }
}

/// `main` of an experiment binary: parses `--quick`, `--seed`, `--out`, `--dimension`, runs, writes, prints
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
    match experiment(options).and_then(|r| r.write(&options.out).map(|_| r).map_err(ExperimentError::Output)) {
        Ok(result) => {
            // Writes that fail (stdout closed, e.g. piped into `head`) are not errors of the run.
            use std::io::Write as _;
            let mut stdout = std::io::stdout();
            let _ = write!(stdout, "{}", check::table(&result.slug(), &result.checks));
            let _ = writeln!(stdout, "results in {}", ExperimentResult::dir(&options.out, &result.slug()).display());
            if result.passed() { ExitCode::SUCCESS } else { ExitCode::FAILURE }
        }
        Err(e) => {
            eprintln!("{name}: {e}");
            ExitCode::from(2)
        }
    }
}
