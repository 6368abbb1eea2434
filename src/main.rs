//! The `collide` command line: argument parsing and error display only; the work is in the
//! library.

use anyhow::{Context, Result, bail};
use clap::{Args, Parser, Subcommand};
use collide::engine::Neighbourhood;
use collide::quadratic::Roots;
use collide::query::numbers::{NumberFormat, format_text, parse_text};
use collide::query::{DynBall, Query, answer_lines, contact_time_dyn};
use std::io::{self, BufWriter, IsTerminal};
use std::path::PathBuf;
use std::process::ExitCode;

/// `println!` that stops quietly when stdout is closed (e.g. piped into `head`) instead of
/// panicking.
macro_rules! say {
    ($($t:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stdout(), $($t)*);
    }};
}

#[derive(Parser)]
#[command(
    name = "collide",
    version,
    about = "Event-driven dynamics of hard disks and spheres on verified collision numerics",
    disable_help_subcommand = true,
    after_help = "Exit status: 0 success; 1 a check failed, a run was stopped by its watchdog, or a JSON line could not be answered; 2 bad input (arguments, configuration, checkpoint, output directory); 130 interrupted (SIGINT or SIGTERM: the run saved a checkpoint and a summary)."
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand)]
enum Command {
    /// Runs a simulation: `collide run [CONFIG.toml] [--out DIR]`, or `--resume CHECKPOINT`.
    /// Without a file, runs the embedded default (`collide run --print-default` shows it).
    Run(RunArgs),
    /// Runs a sweep: one run configuration with values varied (`[base]`, `[vary]`,
    /// `[[zip]]`), each task a run in DIR/tasks/NNNN/, on this machine's cores (`--jobs`) or
    /// as a Slurm job array (`--emit slurm`), collected into DIR/results.csv. Rerunning skips
    /// finished tasks and continues interrupted ones.
    Sweep(SweepArgs),
    /// Runs every physics experiment and writes a validation report (`index.html`,
    /// `report.md`); the default when no command is given. Exits non-zero if a check fails.
    Validate(ValidateArgs),
    /// Benchmark report: steady-state collisions per second over N × packing fraction, and
    /// the hardware's floor beside each point, written to DIR/bench.json, bench.md and
    /// collisions_per_second.svg.
    Bench(BenchArgs),
    /// One benchmark point in a process of its own (used by `collide bench`).
    #[command(hide = true)]
    BenchPoint {
        #[arg(long, default_value_t = 2, value_parser = clap::value_parser!(u8).range(2..=3))]
        dimension: u8,
        #[arg(long)]
        n: usize,
        #[arg(long)]
        eta: f64,
        #[arg(long)]
        warmup: u64,
        #[arg(long)]
        timed: u64,
        #[arg(long, default_value_t = 1)]
        seed: u64,
        #[arg(long, default_value_t = Neighbourhood::Auto)]
        neighbourhood: Neighbourhood,
        /// 1: the whole box in one thread; 2: two slabs, a thread each, in the order of
        /// time (the same events), timed to the end time `--timed` collisions take at the
        /// rate of the warm-up's second half.
        #[arg(long, default_value_t = 1)]
        threads: usize,
    },
    /// The hardware's floor for one point, without and with its lookahead (JSON lines).
    #[command(hide = true)]
    BenchFloor {
        #[arg(long, default_value_t = 2, value_parser = clap::value_parser!(u8).range(2..=3))]
        dimension: u8,
        #[arg(long)]
        n: usize,
        #[arg(long)]
        eta: f64,
        #[arg(long)]
        timed: u64,
        #[arg(long, default_value_t = 1)]
        seed: u64,
    },
    /// Checks the numerics on this machine against the built-in edge-case reference;
    /// exits non-zero on any mismatch.
    Check,
    /// Real roots of a·x² + b·x + c = 0: prints them ascending on one line, "none", or "all".
    Roots(RootsArgs),
    /// Earliest contact time of two disks (or spheres), optionally with growing radii: prints
    /// the time, or "never".
    ContactTime(ContactArgs),
    /// Runs one physics experiment and writes DIR/NAME/result.json and its plots; exits 1
    /// if a check fails. `collide validate` runs them all.
    Experiment(ExperimentArgs),
    /// Prints the help of collide, or of one of its commands.
    Help {
        /// The command.
        command: Option<String>,
    },
}

#[derive(Args)]
struct ExperimentArgs {
    /// Which experiment.
    #[arg(value_parser = clap::builder::PossibleValuesParser::new(collide::lab::EXPERIMENTS.iter().map(|(name, _)| *name)))]
    name: String,
    #[command(flatten)]
    options: collide::lab::ExperimentArgs,
}

#[derive(Args)]
struct ValidateArgs {
    /// CI-sized experiments (seconds) instead of report quality (minutes).
    #[arg(long)]
    quick: bool,
    /// Longer runs than report quality for the experiments that have them (structure,
    /// diffusion, long_time_tail, hexatic: up to hours on two cores); the others run at
    /// report size.
    #[arg(long, conflicts_with = "quick")]
    long: bool,
    /// Experiments run at once (default: the number of cores); the results do not depend
    /// on it.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024))]
    jobs: Option<u32>,
    /// Seed of the initial states.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Output directory for the report and each experiment's results.
    #[arg(long, default_value = "validation")]
    out: PathBuf,
}

impl Default for ValidateArgs {
    fn default() -> Self {
        ValidateArgs { quick: false, long: false, jobs: None, seed: 1, out: PathBuf::from("validation") }
    }
}

#[derive(Args)]
struct BenchArgs {
    /// A small matrix that finishes in under a minute (N = 10³, 10⁴).
    #[arg(long)]
    quick: bool,
    /// Output directory.
    #[arg(long, default_value = "bench")]
    out: PathBuf,
    /// How particles find their neighbours: `auto` (lists from packing fraction 0.63 on,
    /// the grid below), `grid` or `lists`.
    #[arg(long, default_value_t = Neighbourhood::Auto)]
    neighbourhood: Neighbourhood,
}

#[derive(Args)]
struct RunArgs {
    /// The configuration (TOML). Omit it to run the embedded default.
    config: Option<PathBuf>,
    /// Output directory (created if needed). It holds one run: one that holds another run's
    /// files is refused, unless --force.
    #[arg(long, default_value = "collide-out")]
    out: PathBuf,
    /// Replace the files of an earlier run in the output directory (only those:
    /// summary.json, timeseries.csv, trajectory.xyz, checkpoint.json and the observables'
    /// files: rdf.csv, msd.csv, vacf.csv, sk.csv, bond_order.csv, g6.csv).
    #[arg(long)]
    force: bool,
    /// No progress bar (it is drawn only on a terminal, and never when CI is set).
    #[arg(long)]
    quiet: bool,
    /// Stop as SIGINT would once production has this many collisions (tests).
    #[arg(long, hide = true)]
    interrupt_after: Option<u64>,
    /// Continue from a checkpoint written by an earlier run (instead of a configuration).
    #[arg(long, conflicts_with = "config")]
    resume: Option<PathBuf>,
    /// Print the embedded default configuration and exit.
    #[arg(long, conflicts_with_all = ["config", "resume"])]
    print_default: bool,
}

#[derive(Args)]
struct SweepArgs {
    /// The sweep file (TOML: [base], [vary], [[zip]], optional [plot] and [slurm]).
    sweep: PathBuf,
    /// Output directory: manifest.json, tasks/NNNN/ (one run each), results.csv,
    /// results.json, results.svg.
    #[arg(long, default_value = "sweep-out")]
    out: PathBuf,
    /// Tasks run at once, each a process of its own (default: the number of cores).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=4096))]
    jobs: Option<u32>,
    /// Run the failed tasks again (a rerun otherwise skips them, as it skips finished ones).
    #[arg(long)]
    retry_failed: bool,
    /// Run task K alone (what each array task of a scheduler runs), then exit.
    #[arg(long, value_name = "K", conflicts_with_all = ["emit", "collect", "jobs"])]
    task: Option<usize>,
    /// Write DIR/sweep.sbatch, a job array of the unfinished tasks, instead of running them.
    #[arg(long, value_parser = ["slurm"], conflicts_with = "collect")]
    emit: Option<String>,
    /// Only build the tables from the tasks that have finished, naming what is missing or
    /// failed (exit 1 unless every task finished).
    #[arg(long, conflicts_with = "jobs")]
    collect: bool,
    /// Slurm: time limit per task (sbatch --time), instead of [slurm] time.
    #[arg(long, requires = "emit")]
    time: Option<String>,
    /// Slurm: memory per task (sbatch --mem), instead of [slurm] mem.
    #[arg(long, requires = "emit")]
    mem: Option<String>,
    /// Slurm: partition (sbatch --partition), instead of [slurm] partition.
    #[arg(long, requires = "emit")]
    partition: Option<String>,
    /// Slurm: account (sbatch --account), instead of [slurm] account.
    #[arg(long, requires = "emit")]
    account: Option<String>,
    /// Slurm: the most array tasks running at once (--array=…%K), instead of [slurm] throttle.
    #[arg(long, requires = "emit", value_parser = clap::value_parser!(u32).range(1..))]
    throttle: Option<u32>,
    /// No progress line (it is drawn only on a terminal, and never when CI is set).
    #[arg(long)]
    quiet: bool,
}

#[derive(Args)]
struct Output {
    /// Read JSON lines on stdin, answer one line each on stdout.
    #[arg(long)]
    jsonl: bool,
    /// Write numbers as exact C99 hex floats (0x1.8p+1) instead of shortest decimals.
    #[arg(long)]
    hex: bool,
}

impl Output {
    fn format(&self) -> NumberFormat {
        if self.hex { NumberFormat::Hex } else { NumberFormat::Shortest }
    }
}

#[derive(Args)]
struct RootsArgs {
    #[command(flatten)]
    output: Output,
    /// The coefficients a b c (decimal or hex float; omit with --jsonl).
    #[arg(allow_hyphen_values = true, num_args = 3, value_names = ["A", "B", "C"])]
    coefficients: Vec<String>,
}

#[derive(Args)]
struct ContactArgs {
    #[command(flatten)]
    output: Output,
    /// Position of disk 1, "x,y" (or "x,y,z").
    #[arg(long, allow_hyphen_values = true)]
    r1: Option<String>,
    /// Velocity of disk 1.
    #[arg(long, allow_hyphen_values = true)]
    v1: Option<String>,
    /// Radius of disk 1.
    #[arg(long = "R1", allow_hyphen_values = true)]
    radius1: Option<String>,
    /// Position of disk 2.
    #[arg(long, allow_hyphen_values = true)]
    r2: Option<String>,
    /// Velocity of disk 2.
    #[arg(long, allow_hyphen_values = true)]
    v2: Option<String>,
    /// Radius of disk 2.
    #[arg(long = "R2", allow_hyphen_values = true)]
    radius2: Option<String>,
    /// Growth rate of radius 1 (the radius is R1 + g1·t; default 0, must be ≥ 0).
    #[arg(long, allow_hyphen_values = true)]
    g1: Option<String>,
    /// Growth rate of radius 2.
    #[arg(long, allow_hyphen_values = true)]
    g2: Option<String>,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(cli) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("collide: {e:#}");
            ExitCode::from(2)
        }
    }
}

fn run(cli: Cli) -> Result<ExitCode> {
    match cli.command.unwrap_or(Command::Validate(ValidateArgs::default())) {
        Command::Validate(args) => validate(args),
        Command::Check => check(),
        Command::Bench(args) => bench(args),
        Command::BenchPoint { dimension, n, eta, warmup, timed, seed, neighbourhood, threads } => {
            let point =
                collide::bench::measure(dimension as usize, n, eta, neighbourhood, warmup, timed, seed, threads)?;
            say!("{}", serde_json::to_string(&point)?);
            Ok(ExitCode::SUCCESS)
        }
        Command::BenchFloor { dimension, n, eta, timed, seed } => {
            let points = match dimension {
                3 => collide::bench::floor::measure_both::<3>(n, eta, 2 * n as u64, timed, seed)?,
                _ => collide::bench::floor::measure_both::<2>(n, eta, 2 * n as u64, timed, seed)?,
            };
            for point in points {
                say!("{}", serde_json::to_string(&point)?);
            }
            Ok(ExitCode::SUCCESS)
        }
        Command::Run(args) => run_simulation(args),
        Command::Sweep(args) => sweep(args),
        Command::Roots(args) => roots(args),
        Command::ContactTime(args) => contact(args),
        Command::Experiment(args) => {
            let (name, experiment) =
                collide::lab::EXPERIMENTS.iter().find(|(name, _)| *name == args.name).expect("clap checked the name");
            Ok(collide::lab::run_one(name, *experiment, &args.options.into()))
        }
        Command::Help { command } => help(command.as_deref()),
    }
}

fn help(command: Option<&str>) -> Result<ExitCode> {
    use clap::CommandFactory;
    let mut cli = Cli::command();
    cli.build();
    match command {
        None => cli.print_long_help()?,
        Some(name) => match cli.find_subcommand_mut(name) {
            Some(sub) => sub.print_long_help()?,
            None => {
                let names: Vec<String> =
                    cli.get_subcommands().filter(|c| !c.is_hide_set()).map(|c| c.get_name().to_string()).collect();
                bail!("help: there is no command '{}' (commands: {})", collide::text::excerpt(name), names.join(", "));
            }
        },
    }
    Ok(ExitCode::SUCCESS)
}

/// Whether to draw a progress bar on stderr: on a terminal, unless asked not to or under CI
/// (`CI` set to anything but empty, `0` or `false`).
fn progress_wanted(quiet: bool) -> bool {
    draw_progress(quiet, std::env::var("CI").ok().as_deref(), io::stderr().is_terminal())
}

/// A progress bar of `len` steps drawn with `template` when `wanted`, else a hidden one.
fn progress_bar(wanted: bool, len: u64, template: &str) -> indicatif::ProgressBar {
    if !wanted {
        return indicatif::ProgressBar::hidden();
    }
    let bar = indicatif::ProgressBar::new(len);
    bar.set_style(indicatif::ProgressStyle::with_template(template).expect("a valid template").progress_chars("=> "));
    bar
}

/// [`progress_wanted`] given `--quiet`, the value of `CI` and whether stderr is a terminal.
fn draw_progress(quiet: bool, ci: Option<&str>, terminal: bool) -> bool {
    let ci = ci.is_some_and(|v| !matches!(v.trim(), "" | "0" | "false"));
    !quiet && !ci && terminal
}

#[cfg(test)]
mod tests {
    use super::draw_progress;

    /// The bar is for a person at a terminal: never in a pipe, under CI (`CI=true` on a
    /// terminal once drew it), or with --quiet.
    #[test]
    fn the_progress_bar_is_drawn_only_for_a_person_at_a_terminal() {
        assert!(draw_progress(false, None, true));
        assert!(draw_progress(false, Some("false"), true) && draw_progress(false, Some(""), true));
        assert!(!draw_progress(false, Some("true"), true));
        assert!(!draw_progress(false, Some("1"), true));
        assert!(!draw_progress(true, None, true));
        assert!(!draw_progress(false, None, false));
    }
}

fn check() -> Result<ExitCode> {
    let report = collide::quadratic::reference::check_all();
    say!("{}", report.text.trim_end());
    if report.failures == 0 {
        say!("all {} reference cases agree with the exact answers", report.cases);
        Ok(ExitCode::SUCCESS)
    } else {
        eprintln!("collide: {} of {} reference cases disagree with the exact answers", report.failures, report.cases);
        Ok(ExitCode::FAILURE)
    }
}

/// Runs the JSON-lines protocol; exit status 1 if any line could not be answered.
fn jsonl(query: Query, format: NumberFormat) -> Result<ExitCode> {
    let stdin = io::stdin().lock();
    let stdout = BufWriter::new(io::stdout().lock());
    let failed =
        answer_lines(query, stdin, stdout, io::stderr().lock(), format).context("reading stdin or writing stdout")?;
    if failed > 0 {
        eprintln!("collide: {failed} line(s) could not be answered");
        return Ok(ExitCode::FAILURE);
    }
    Ok(ExitCode::SUCCESS)
}

fn roots(args: RootsArgs) -> Result<ExitCode> {
    let format = args.output.format();
    if args.output.jsonl {
        if !args.coefficients.is_empty() {
            bail!("give either --jsonl or the coefficients A B C, not both");
        }
        return jsonl(Query::Roots, format);
    }
    let [a, b, c] = match args.coefficients.as_slice() {
        [a, b, c] => [a, b, c],
        _ => bail!("expected three coefficients A B C (or --jsonl); see collide roots --help"),
    };
    let num = |name: &str, s: &str| parse_text(s).with_context(|| format!("coefficient {name}"));
    let roots = collide::quadratic::solve(num("A", a)?, num("B", b)?, num("C", c)?)?;
    say!(
        "{}",
        match roots {
            Roots::None => "none".to_string(),
            Roots::All => "all".to_string(),
            other => other.as_vec().iter().map(|&x| format_text(x, format)).collect::<Vec<_>>().join(" "),
        }
    );
    Ok(ExitCode::SUCCESS)
}

fn contact(args: ContactArgs) -> Result<ExitCode> {
    let format = args.output.format();
    let given = [&args.r1, &args.v1, &args.radius1, &args.r2, &args.v2, &args.radius2, &args.g1, &args.g2];
    if args.output.jsonl {
        if given.iter().any(|x| x.is_some()) {
            bail!("give either --jsonl or the options --r1 --v1 --R1 --r2 --v2 --R2 (--g1 --g2), not both");
        }
        return jsonl(Query::ContactTime, format);
    }
    let need = |value: &Option<String>, name: &str| -> Result<String> {
        value
            .clone()
            .with_context(|| format!("missing --{name} (all of --r1 --v1 --R1 --r2 --v2 --R2 are needed, or --jsonl)"))
    };
    let vector = |value: &Option<String>, name: &str| -> Result<Vec<f64>> {
        need(value, name)?
            .split(',')
            .enumerate()
            .map(|(i, s)| parse_text(s).with_context(|| format!("--{name} component {i}")))
            .collect()
    };
    let scalar = |value: &Option<String>, name: &str| -> Result<f64> {
        parse_text(&need(value, name)?).with_context(|| format!("--{name}"))
    };
    let first = DynBall {
        position: vector(&args.r1, "r1")?,
        velocity: vector(&args.v1, "v1")?,
        radius: scalar(&args.radius1, "R1")?,
    };
    let second = DynBall {
        position: vector(&args.r2, "r2")?,
        velocity: vector(&args.v2, "v2")?,
        radius: scalar(&args.radius2, "R2")?,
    };
    let rate = |value: &Option<String>, name: &str| -> Result<f64> {
        value.as_deref().map_or(Ok(0.0), |s| parse_text(s).with_context(|| format!("--{name}")))
    };
    let t = contact_time_dyn(&first, &second, [rate(&args.g1, "g1")?, rate(&args.g2, "g2")?])?;
    say!("{}", t.map_or_else(|| "never".to_string(), |t| format_text(t, format)));
    Ok(ExitCode::SUCCESS)
}

fn run_simulation(args: RunArgs) -> Result<ExitCode> {
    use collide::run::config::{Config, DEFAULT_CONFIG};
    use collide::run::output::{AnyCheckpoint, RunFailure, RunOptions, Start, load_any_checkpoint, run_into};
    use collide::run::{Phase, Status};
    if args.print_default {
        say!("{}", DEFAULT_CONFIG.trim_end());
        return Ok(ExitCode::SUCCESS);
    }
    let bar = progress_bar(
        progress_wanted(args.quiet),
        1000,
        "{prefix} [{bar:40}] {percent:>3}% {elapsed_precise} (eta {eta})",
    );
    let mut shown = None;
    let progress = |phase: Phase, done: f64| {
        if shown != Some(phase) {
            // A new phase starts its bar (and its estimate) from zero.
            shown = Some(phase);
            bar.reset();
            bar.set_prefix(match phase {
                Phase::Compression => "compressing",
                Phase::Equilibration => "equilibrating",
                Phase::Production => "running",
            });
        }
        bar.set_position((done.clamp(0.0, 1.0) * 1000.0) as u64);
    };
    let stop = stop_on_signals()?;
    let options = RunOptions { force: args.force, interrupt_after: args.interrupt_after };
    // The run's dimension decides the engine's: a configuration's `dimension`, or that of the
    // run a checkpoint holds.
    let (summary, source) = if let Some(path) = &args.resume {
        let source = path.display().to_string();
        let summary = match load_any_checkpoint(path).map_err(|e| anyhow::anyhow!("{source}: {e}"))? {
            AnyCheckpoint::Disks(checkpoint) => {
                run_into::<2>(Start::Resume { checkpoint, path }, &args.out, options, &stop, progress)
            }
            AnyCheckpoint::Spheres(checkpoint) => {
                run_into::<3>(Start::Resume { checkpoint, path }, &args.out, options, &stop, progress)
            }
        };
        (summary, source)
    } else {
        let (config, source) = match &args.config {
            Some(path) => (Config::load(path)?, path.display().to_string()),
            None => (Config::default_config(), "the embedded default".to_string()),
        };
        let summary = match config.dimension {
            3 => run_into::<3>(Start::Fresh(config), &args.out, options, &stop, progress),
            _ => run_into::<2>(Start::Fresh(config), &args.out, options, &stop, progress),
        };
        (summary, source)
    };
    let summary = summary.map_err(|e| match e {
        // A bad configuration, initial state or checkpoint: name where it came from.
        RunFailure::Run(e) => anyhow::anyhow!("{source}: {e}"),
        RunFailure::Output(e) => anyhow::anyhow!("{e}"),
        e => anyhow::anyhow!("{e}"),
    })?;
    bar.finish_and_clear();
    for warning in &summary.warnings {
        eprintln!("collide: warning: {warning}");
    }
    let out = args.out.display();
    match summary.status {
        Status::Interrupted => {
            eprintln!(
                "collide: interrupted at t = {} ({} production collisions); results so far in {out} (summary.json says \"interrupted\"); continue with: collide run --resume {} --out {out}",
                summary.sim_time,
                summary.collisions,
                args.out.join("checkpoint.json").display()
            );
            return Ok(ExitCode::from(130));
        }
        Status::Stalled | Status::TooManySamples => {
            let problem = summary.problem().unwrap_or_default();
            eprintln!("collide: {source}: {problem}; results so far in {out}");
            return Ok(ExitCode::FAILURE);
        }
        _ => {}
    }
    if let Some(c) = &summary.compression {
        let jammed = match (c.contacts_per_particle, c.rattlers) {
            (Some(z), Some(r)) => format!("; jammed: {z:.4} contacts per particle without its {r} rattlers"),
            _ if c.jammed => "; jammed".to_string(),
            _ => String::new(),
        };
        say!(
            "compressed to φ = {:.6} in {} collisions (t = {:.6}); Z = {:.4e}; max overlap {:.2e}{jammed}",
            c.packing_fraction,
            c.collisions,
            c.sim_time,
            c.reduced_pressure.unwrap_or(f64::NAN),
            c.max_overlap
        );
        if summary.status == Status::Jammed {
            eprintln!("collide: {source}: {}; results in {out}", summary.problem().unwrap_or_default());
            return Ok(ExitCode::FAILURE);
        }
        if summary.config.compress.as_ref().is_some_and(|c| c.to_jamming()) {
            say!("results in {out}");
            return Ok(ExitCode::SUCCESS);
        }
    }
    say!(
        "{} collisions in {:.2} s ({:.3} M/s); kT = {:.6}; P = {:.6} ± {:.6}; Z = {:.5} ± {:.5}; max overlap {:.2e}; energy drift {:.2e}",
        summary.collisions,
        summary.wall_time_s,
        summary.collisions_per_second / 1e6,
        summary.kT,
        summary.pressure_virial,
        summary.pressure_virial_error,
        summary.compressibility,
        summary.compressibility_error,
        summary.max_overlap.fraction,
        summary.energy_relative_drift
    );
    say!("results in {out}");
    Ok(ExitCode::SUCCESS)
}

/// A flag that SIGINT and SIGTERM set: a run stops at its next event and saves itself.
fn stop_on_signals() -> Result<std::sync::Arc<std::sync::atomic::AtomicBool>> {
    use std::sync::Arc;
    use std::sync::atomic::AtomicBool;
    let stop = Arc::new(AtomicBool::new(false));
    for signal in [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM] {
        signal_hook::flag::register(signal, Arc::clone(&stop)).context("installing the signal handlers")?;
    }
    Ok(stop)
}

fn sweep(args: SweepArgs) -> Result<ExitCode> {
    use collide::sweep::local::{self, Ended, Progress};
    use collide::sweep::task::{self, Outcome, State};
    use collide::sweep::{Sweep, slurm, table};
    let sweep = Sweep::load(&args.sweep)?;
    let tasks = sweep.tasks()?;
    let n = tasks.len();
    let out = &args.out;
    let stop = stop_on_signals()?;
    if let Some(k) = args.task {
        let Some(t) = tasks.get(k) else {
            bail!("--task {k}: {} makes {n} tasks, numbered 0 to {}", sweep.source, n - 1);
        };
        task::check_manifest(out, t, n)?;
        let dir = task::dir(out, t, n);
        let name =
            if t.parameters.is_empty() { format!("task {k} (the base)") } else { format!("task {k} ({})", t.label()) };
        return Ok(match task::run(t, &dir, args.retry_failed, &stop)? {
            Outcome::AlreadyFinished => {
                say!("{name}: finished before; results in {}", dir.display());
                ExitCode::SUCCESS
            }
            Outcome::AlreadyFailed(error) => {
                eprintln!("collide: {name}: failed before ({error}); --retry-failed runs it again");
                ExitCode::FAILURE
            }
            Outcome::Finished(s) => {
                say!(
                    "{name}: {} collisions in {:.2} s; Z = {:.5} ± {:.5}; results in {}",
                    s.collisions,
                    s.wall_time_s,
                    s.compressibility,
                    s.compressibility_error,
                    dir.display()
                );
                ExitCode::SUCCESS
            }
            Outcome::Failed(error) => {
                eprintln!("collide: {name}: {error}");
                ExitCode::FAILURE
            }
            Outcome::Interrupted => {
                eprintln!(
                    "collide: {name}: interrupted; its checkpoint is in {}; running the task again continues it",
                    dir.display()
                );
                ExitCode::from(130)
            }
        });
    }
    task::write_manifest(out, &sweep.source, &sweep.keys(), &tasks)?;
    let states: Vec<State> = tasks.iter().map(|t| task::state(&task::dir(out, t, n), t)).collect();
    let todo: Vec<usize> = states
        .iter()
        .enumerate()
        .filter(|(_, s)| match s {
            State::Finished => false,
            State::Failed(_) => args.retry_failed,
            _ => true,
        })
        .map(|(k, _)| k)
        .collect();
    let done_before = states.iter().filter(|s| **s == State::Finished).count();
    if args.emit.is_some() {
        if todo.is_empty() {
            say!("all {n} tasks of {} have finished (or failed: --retry-failed); nothing to submit", sweep.source);
            return Ok(ExitCode::SUCCESS);
        }
        let absolute = |p: &std::path::Path| std::path::absolute(p).with_context(|| p.display().to_string());
        let mut options = sweep.slurm.clone();
        for (value, slot) in [
            (&args.time, &mut options.time),
            (&args.mem, &mut options.mem),
            (&args.partition, &mut options.partition),
            (&args.account, &mut options.account),
        ] {
            if value.is_some() {
                slot.clone_from(value);
            }
        }
        options.throttle = args.throttle.or(options.throttle);
        let exe = std::env::current_exe().context("locating the collide binary")?;
        let script = slurm::emit(&exe, &absolute(&args.sweep)?, &absolute(out)?, &todo, &options, args.retry_failed)?;
        say!(
            "{} tasks of {n} in the array ({}); submit with: sbatch {}",
            script.tasks,
            script.array,
            script.path.display()
        );
        if todo.last().is_some_and(|&k| k >= 1001) {
            eprintln!(
                "collide: note: Slurm's default MaxArraySize is 1001 (indices up to 1000); a larger array needs it raised, or the sweep split"
            );
        }
        return Ok(ExitCode::SUCCESS);
    }
    if !args.collect && !todo.is_empty() {
        let cores = std::thread::available_parallelism().map_or(1, |c| c.get());
        let jobs = args.jobs.map_or(cores, |j| j as usize);
        eprintln!(
            "{n} tasks: {done_before} finished before, {} to run, {} at a time",
            todo.len(),
            jobs.min(todo.len())
        );
        let exe = std::env::current_exe().context("locating the collide binary")?;
        let terminal = progress_wanted(args.quiet);
        let bar = progress_bar(terminal, todo.len() as u64, "sweep [{bar:30}] {pos}/{len} {msg} {elapsed_precise}");
        let (mut running, mut failed) = (0usize, 0usize);
        let width = tasks[0].dir_name(n).len();
        let report = |p: Progress| {
            match &p {
                Progress::Started { .. } => running += 1,
                Progress::Ended { index, ended, seconds } => {
                    running -= 1;
                    bar.inc(1);
                    let how = match ended {
                        Ended::Finished => "finished".to_string(),
                        Ended::Failed(e) => {
                            failed += 1;
                            format!("failed: {e}")
                        }
                        Ended::Interrupted => "interrupted (its checkpoint continues it)".to_string(),
                    };
                    let line = format!("task {index:0width$} {how} ({seconds:.1} s)");
                    if terminal { bar.println(line) } else { eprintln!("{line}") }
                }
            }
            bar.set_message(format!("· {running} running · {failed} failed"));
        };
        local::run(&exe, &args.sweep, out, &tasks, &todo, jobs, args.retry_failed, &stop, report)?;
        bar.finish_and_clear();
    }
    let collected = table::collect(&sweep, &tasks, out)?;
    let count = |name: &str| collected.with(name).len();
    say!(
        "{n} tasks: {} finished, {} failed, {} interrupted, {} missing",
        count("finished"),
        count("failed"),
        count("interrupted"),
        count("missing")
    );
    for row in collected.with("failed") {
        if let State::Failed(e) = &row.state {
            eprintln!("collide: task {} failed: {e} ({})", row.index, out.join(&row.dir).display());
        }
    }
    let list = |name: &str| collected.with(name).iter().map(|r| r.index.to_string()).collect::<Vec<_>>().join(", ");
    if count("missing") > 0 {
        eprintln!("collide: not finished (not run, running, or killed): tasks {}", list("missing"));
    }
    if count("interrupted") > 0 {
        eprintln!("collide: interrupted, continued by the next run: tasks {}", list("interrupted"));
    }
    if let Some(why) = &collected.no_plot {
        eprintln!("collide: no results.svg: {why}");
    }
    for file in &collected.files {
        say!("wrote {}", file.display());
    }
    Ok(if collected.complete() {
        ExitCode::SUCCESS
    } else if stop.load(std::sync::atomic::Ordering::Relaxed) || count("interrupted") > 0 && count("failed") == 0 {
        ExitCode::from(130)
    } else {
        ExitCode::FAILURE
    })
}

fn validate(args: ValidateArgs) -> Result<ExitCode> {
    use collide::lab::{Options, Size, check::table, report::validate};
    let options = Options { size: Size::of(args.quick, args.long), seed: args.seed, out: args.out, dimension: 2 };
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let jobs = args.jobs.map_or(cores, |j| j as usize);
    let results = validate(&options, jobs, |line| eprintln!("{line}"))?;
    for r in &results {
        say!("{}", table(&r.slug(), &r.checks).trim_end());
    }
    let failed: Vec<String> = results.iter().filter(|r| !r.passed()).map(|r| r.slug()).collect();
    say!("report: {}", options.out.join("index.html").display());
    if failed.is_empty() {
        say!("all checks pass");
        Ok(ExitCode::SUCCESS)
    } else {
        eprintln!("collide: checks fail in {}", failed.join(", "));
        Ok(ExitCode::FAILURE)
    }
}

fn bench(args: BenchArgs) -> Result<ExitCode> {
    use collide::bench::{BenchPoint, chart, markdown, matrix};
    use collide::run::output::write_atomic;
    let (points, warmup, timed) = matrix(args.quick);
    let exe = std::env::current_exe().context("locating the collide binary")?;
    let mut results = Vec::new();
    for (d, n, eta) in points {
        eprintln!("{d}D, N = {n}, η = {eta} …");
        let output = std::process::Command::new(&exe)
            .args(["bench-point", "--dimension", &d.to_string(), "--n", &n.to_string(), "--eta", &eta.to_string()])
            .args(["--warmup", &warmup.to_string(), "--timed", &timed(n).to_string()])
            .args(["--neighbourhood", args.neighbourhood.name()])
            .output()
            .context("running a benchmark point")?;
        if !output.status.success() {
            bail!("benchmark point {d}D, N = {n}, η = {eta} failed: {}", String::from_utf8_lossy(&output.stderr));
        }
        let point: BenchPoint = serde_json::from_slice(&output.stdout).context("reading a benchmark point")?;
        results.push(point);
    }
    std::fs::create_dir_all(&args.out).with_context(|| args.out.display().to_string())?;
    let mut command = String::from(if args.quick { "collide bench --quick" } else { "collide bench" });
    if args.neighbourhood != Neighbourhood::Auto {
        command += &format!(" --neighbourhood {}", args.neighbourhood);
    }
    let md = markdown(&results, &command, &collide::lab::report::machine());
    write_atomic(&args.out.join("bench.json"), serde_json::to_string_pretty(&results)?.as_bytes())?;
    write_atomic(&args.out.join("bench.md"), md.as_bytes())?;
    collide::lab::plot::draw(&chart(&results), &args.out.join("collisions_per_second.svg"))?;
    say!("{}", md.trim_end());
    say!("results in {}", args.out.display());
    Ok(ExitCode::SUCCESS)
}
