//! Writing a run's results: `summary.json`, `timeseries.csv`, `trajectory.xyz` (extended
//! XYZ), `checkpoint.json`. Every file is written to a temporary name in the same directory
//! and renamed into place, so a reader never sees half a file.

use crate::engine::{Boundary, Outcome, Simulation};
use crate::run::{Checkpoint, Run, RunError, Summary};
use std::fmt::Write as _;
use std::fs;
use std::io::{self, Write};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// A failed output operation, with the path involved.
#[derive(Debug)]
pub struct OutputError {
    /// The file or directory.
    pub path: PathBuf,
    /// What went wrong.
    pub error: io::Error,
}

impl std::fmt::Display for OutputError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}: {}", self.path.display(), self.error)
    }
}

impl std::error::Error for OutputError {}

fn at(path: &Path) -> impl FnOnce(io::Error) -> OutputError + '_ {
    move |error| OutputError { path: path.to_path_buf(), error }
}

/// Writes `contents` to `path` atomically (temporary file in the same directory, then rename).
pub fn write_atomic(path: &Path, contents: &[u8]) -> Result<(), OutputError> {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let tmp = path.with_file_name(format!(".{name}.tmp"));
    fs::write(&tmp, contents).map_err(at(&tmp))?;
    fs::rename(&tmp, path).map_err(at(path))
}

/// The time series as CSV: one row per sample.
pub fn timeseries_csv(run: &Run) -> String {
    let walls: Vec<usize> = (0..2).filter(|&a| run.sim.sim_box().boundary[a] == Boundary::Wall).collect();
    let mut out = String::from("t,kinetic_energy,kT,collisions,pressure_virial");
    for &a in &walls {
        let axis = ["x", "y"][a];
        write!(out, ",pressure_wall_{axis}_lower,pressure_wall_{axis}_upper").unwrap();
    }
    out.push('\n');
    for s in &run.thermo.samples {
        write!(out, "{},{},{},{},{}", s.t, s.kinetic_energy, s.kt, s.collisions, s.pressure_virial).unwrap();
        for w in walls.iter().filter_map(|&a| s.pressure_walls[a]) {
            write!(out, ",{},{}", w[0], w[1]).unwrap();
        }
        out.push('\n');
    }
    out
}

/// One extended-XYZ frame (OVITO and ASE read it): 2D positions written with z = 0, every
/// disk as element `X` with its radius and species index (`type`) in their own columns.
pub fn xyz_frame(sim: &Simulation<2>) -> String {
    let b = sim.sim_box();
    let pbc = |a: usize| if b.boundary[a] == Boundary::Periodic { "T" } else { "F" };
    let mut out = String::new();
    writeln!(out, "{}", sim.particles().len()).unwrap();
    writeln!(
        out,
        "Lattice=\"{} 0.0 0.0 0.0 {} 0.0 0.0 0.0 1.0\" Properties=species:S:1:pos:R:3:radius:R:1:type:I:1 Time={} pbc=\"{} {} F\"",
        b.lengths[0],
        b.lengths[1],
        sim.time(),
        pbc(0),
        pbc(1)
    )
    .unwrap();
    for (p, r) in sim.particles().iter().zip(sim.wrapped_positions()) {
        writeln!(out, "X {} {} 0.0 {} {}", r[0], r[1], p.radius, p.species).unwrap();
    }
    out
}

/// Reads a checkpoint file.
pub fn load_checkpoint(path: &Path) -> Result<Checkpoint, String> {
    let text = fs::read_to_string(path).map_err(|e| format!("{}: cannot read the checkpoint: {e}", path.display()))?;
    serde_json::from_str(&text).map_err(|e| format!("{}: not a collide checkpoint ({e})", path.display()))
}

/// Runs the production part of `run` to its end, writing every output into `dir`.
/// `progress` is called about every 10⁴ events with the fraction done.
pub fn execute(run: &mut Run, dir: &Path, mut progress: impl FnMut(f64)) -> Result<Summary, OutputError> {
    fs::create_dir_all(dir).map_err(at(dir))?;
    let trajectory_every = run.config.output.trajectory_every.unwrap_or(0);
    let checkpoint_every = run.config.output.checkpoint_every.unwrap_or(0);
    let trajectory_path = dir.join("trajectory.xyz");
    let trajectory_tmp = dir.join(".trajectory.xyz.tmp");
    let mut trajectory = if trajectory_every > 0 {
        let file = fs::File::create(&trajectory_tmp).map_err(at(&trajectory_tmp))?;
        Some(io::BufWriter::new(file))
    } else {
        None
    };
    let started = Instant::now();
    let mut next_checkpoint =
        if checkpoint_every > 0 { (run.collisions() / checkpoint_every + 1) * checkpoint_every } else { u64::MAX };
    let mut steps = 0u64;
    while !run.done() {
        let Some(outcome) = run.step() else { break };
        steps += 1;
        if steps % 10_000 == 0 {
            progress(run.progress());
        }
        if let (Outcome::Sample, Some(w)) = (outcome, trajectory.as_mut())
            && run.thermo.samples.len() as u64 % trajectory_every == 0
        {
            w.write_all(xyz_frame(&run.sim).as_bytes()).map_err(at(&trajectory_tmp))?;
        }
        if run.collisions() >= next_checkpoint && !run.done() {
            let text = serde_json::to_string(&run.checkpoint()).expect("a checkpoint serialises");
            write_atomic(&dir.join("checkpoint.json"), text.as_bytes())?;
            next_checkpoint += checkpoint_every;
        }
    }
    progress(1.0);
    let wall = started.elapsed().as_secs_f64();
    if let Some(mut w) = trajectory {
        w.flush().map_err(at(&trajectory_tmp))?;
        drop(w);
        fs::rename(&trajectory_tmp, &trajectory_path).map_err(at(&trajectory_path))?;
    }
    let summary = run.summary(wall);
    write_atomic(&dir.join("timeseries.csv"), timeseries_csv(run).as_bytes())?;
    let json = serde_json::to_string_pretty(&summary).expect("a summary serialises");
    write_atomic(&dir.join("summary.json"), json.as_bytes())?;
    Ok(summary)
}

/// Starts a run from a configuration: builds and validates the initial state (nothing is
/// written if that fails), equilibrates, then [`execute`]s it.
/// `equilibrating` and `running` report the fraction done of each phase.
pub fn run_config(
    config: crate::io::config::Config,
    dir: &Path,
    equilibrating: impl FnMut(f64),
    running: impl FnMut(f64),
) -> Result<Summary, RunFailure> {
    let mut run = Run::new(config).map_err(RunFailure::Run)?;
    run.equilibrate(equilibrating);
    execute(&mut run, dir, running).map_err(RunFailure::Output)
}

/// Either a run that could not start, or an output that could not be written.
#[derive(Debug)]
pub enum RunFailure {
    /// Bad initial state or checkpoint.
    Run(RunError),
    /// A file could not be written.
    Output(OutputError),
}

impl std::fmt::Display for RunFailure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            RunFailure::Run(e) => write!(f, "{e}"),
            RunFailure::Output(e) => write!(f, "{e}"),
        }
    }
}

impl std::error::Error for RunFailure {}
