//! A run's files and how `collide run` writes them: `summary.json`, `timeseries.csv`,
//! `trajectory.xyz` (extended XYZ), `checkpoint.json`, in a directory that holds one run
//! ([`super::rundir`]: the policy, the lock, the atomic writes). The formats are specified
//! in `docs/outputs.md`.
//!
//! [`Writer`] is the [`Sink`] of a run: it appends a trajectory frame every
//! `trajectory_every` samples and writes a checkpoint every `checkpoint_every` production
//! collisions. When the run ends — complete, interrupted or stopped — `finish` flushes the
//! trajectory, writes the final checkpoint (not for a stalled run, whose state would stall
//! again), the time series and, last, the summary.

use super::config::Config;
pub use super::rundir::{OutputError, write_atomic};
use super::rundir::{RunDir, Trajectory};
use super::{Checkpoint, Phase, Run, RunError, Sink, Status, Summary};
use crate::engine::{Boundary, Outcome, Simulation};
use std::fmt::Write as _;
use std::path::Path;
use std::sync::atomic::AtomicBool;

/// The time series as CSV: one row per sample.
pub fn timeseries_csv<const D: usize>(run: &Run<D>) -> String {
    let walls: Vec<usize> = (0..D).filter(|&a| run.sim.sim_box().boundary[a] == Boundary::Wall).collect();
    let mut out = String::from("t,kinetic_energy,kT,collisions,pressure_virial");
    for &a in &walls {
        let axis = ["x", "y", "z"][a];
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

/// The chemical symbols by atomic number, from 1: species `k` is written as element `k + 1`
/// (`H`, `He`, `Li`, …), so that OVITO shows each species as its own particle type and ASE
/// reads the names as symbols it knows.
const ELEMENTS: [&str; 118] = [
    "H", "He", "Li", "Be", "B", "C", "N", "O", "F", "Ne", "Na", "Mg", "Al", "Si", "P", "S", "Cl", "Ar", "K", "Ca",
    "Sc", "Ti", "V", "Cr", "Mn", "Fe", "Co", "Ni", "Cu", "Zn", "Ga", "Ge", "As", "Se", "Br", "Kr", "Rb", "Sr", "Y",
    "Zr", "Nb", "Mo", "Tc", "Ru", "Rh", "Pd", "Ag", "Cd", "In", "Sn", "Sb", "Te", "I", "Xe", "Cs", "Ba", "La", "Ce",
    "Pr", "Nd", "Pm", "Sm", "Eu", "Gd", "Tb", "Dy", "Ho", "Er", "Tm", "Yb", "Lu", "Hf", "Ta", "W", "Re", "Os", "Ir",
    "Pt", "Au", "Hg", "Tl", "Pb", "Bi", "Po", "At", "Rn", "Fr", "Ra", "Ac", "Th", "Pa", "U", "Np", "Pu", "Am", "Cm",
    "Bk", "Cf", "Es", "Fm", "Md", "No", "Lr", "Rf", "Db", "Sg", "Bh", "Hs", "Mt", "Ds", "Rg", "Cn", "Nh", "Fl", "Mc",
    "Lv", "Ts", "Og",
];

/// The symbol species `k` is written as (`X`, the dummy element, past the 118th).
pub fn species_symbol(k: u32) -> &'static str {
    ELEMENTS.get(k as usize).copied().unwrap_or("X")
}

/// One extended-XYZ frame (OVITO and ASE read it): positions wrapped into the box, with
/// z = 0 in 2D; the `species` column names each species by a chemical symbol
/// ([`species_symbol`]: OVITO makes it the particle type, ASE the symbols), then the radius
/// and the species index (`species_index`, a column of its own that neither reads as a type).
pub fn xyz_frame<const D: usize>(sim: &Simulation<D>) -> String {
    let b = sim.sim_box();
    let length = |a: usize| if a < D { b.lengths[a] } else { 1.0 };
    let pbc = |a: usize| if a < D && b.boundary[a] == Boundary::Periodic { "T" } else { "F" };
    let mut out = String::new();
    writeln!(out, "{}", sim.particles().len()).unwrap();
    writeln!(
        out,
        "Lattice=\"{} 0.0 0.0 0.0 {} 0.0 0.0 0.0 {}\" Properties=species:S:1:pos:R:3:radius:R:1:species_index:I:1 Time={} pbc=\"{} {} {}\"",
        length(0),
        length(1),
        if D > 2 { length(2).to_string() } else { "1.0".to_string() },
        sim.time(),
        pbc(0),
        pbc(1),
        pbc(2)
    )
    .unwrap();
    for (p, r) in sim.particles().iter().zip(sim.wrapped_positions()) {
        let z = if D > 2 { r[2].to_string() } else { "0.0".to_string() };
        writeln!(out, "{} {} {} {z} {} {}", species_symbol(p.species), r[0], r[1], p.radius, p.species).unwrap();
    }
    out
}

/// Reads a checkpoint file (verified: see [`Checkpoint::load`]).
pub fn load_checkpoint<const D: usize>(path: &Path) -> Result<Checkpoint<D>, super::CheckpointError> {
    Checkpoint::load(path)
}

/// A checkpoint file read, of the dimension its run has.
pub enum AnyCheckpoint {
    /// Of disks.
    Disks(Checkpoint<2>),
    /// Of spheres.
    Spheres(Checkpoint<3>),
}

/// Reads a checkpoint file of either dimension (verified: see [`Checkpoint::load`]).
pub fn load_any_checkpoint(path: &Path) -> Result<AnyCheckpoint, super::CheckpointError> {
    use super::CheckpointError;
    let bytes = std::fs::read(path).map_err(|e| CheckpointError::Read(e.to_string()))?;
    match super::checkpoint::dimension_of(&bytes) {
        2 => Ok(AnyCheckpoint::Disks(Checkpoint::from_json(&bytes)?)),
        3 => Checkpoint::from_json(&bytes).map(AnyCheckpoint::Spheres).map_err(|e| match e {
            CheckpointError::Format(e) => CheckpointError::Format(format!(
                "{e} (run.config.dimension = 3: every position and velocity has 3 entries)"
            )),
            e => e,
        }),
        d => Err(CheckpointError::Format(format!("run.config.dimension = {d}: collide runs in 2 or 3 dimensions"))),
    }
}

/// The [`Sink`] of `collide run`: the trajectory and the checkpoints, while the run goes.
pub struct Writer<'a, P: FnMut(Phase, f64)> {
    dir: &'a RunDir,
    stop: &'a AtomicBool,
    interrupt_after: Option<u64>,
    trajectory: Option<Trajectory>,
    trajectory_every: u64,
    checkpoint_every: u64,
    next_checkpoint: u64,
    progress: P,
}

impl<P: FnMut(Phase, f64)> Writer<'_, P> {
    /// The trajectory's length now, flushed to the disk (0 without one).
    fn flush(&mut self) -> Result<u64, OutputError> {
        self.trajectory.as_mut().map_or(Ok(0), Trajectory::flush)
    }
}

impl<const D: usize, P: FnMut(Phase, f64)> Sink<D> for Writer<'_, P> {
    type Error = OutputError;

    fn event(&mut self, run: &Run<D>, outcome: &Outcome<D>) -> Result<(), OutputError> {
        if run.phase() == Phase::Compression && run.compression.as_ref().is_some_and(|c| c.done) {
            // The compressed (or jammed) packing, once, as it stands at the compression's end.
            self.dir.write("compressed.xyz", xyz_frame(&run.sim).as_bytes())?;
        }
        if run.phase() != Phase::Production {
            return Ok(());
        }
        if let (Outcome::Sample, Some(t)) = (outcome, self.trajectory.as_mut())
            && run.thermo.samples.len() as u64 % self.trajectory_every == 0
        {
            t.append(&xyz_frame(&run.sim))?;
        }
        if self.interrupt_after.is_some_and(|c| run.collisions() >= c) {
            self.stop.store(true, std::sync::atomic::Ordering::Relaxed);
        }
        if run.collisions() >= self.next_checkpoint && !run.done() {
            let bytes = self.flush()?;
            let checkpoint = run.checkpoint(bytes);
            self.dir.write_with("checkpoint.json", |w| checkpoint.write_json(w))?;
            self.next_checkpoint = self.next_checkpoint.saturating_add(self.checkpoint_every);
        }
        Ok(())
    }

    fn progress(&mut self, phase: Phase, done: f64) {
        (self.progress)(phase, done);
    }
}

/// How `collide run` starts.
pub enum Start<'a, const D: usize> {
    /// From a configuration.
    Fresh(Config),
    /// From a checkpoint file, already read.
    Resume {
        /// The checkpoint.
        checkpoint: Checkpoint<D>,
        /// Its file.
        path: &'a Path,
    },
}

/// Either a run that could not start, or an output that could not be written.
#[non_exhaustive]
#[derive(Debug)]
pub enum RunFailure {
    /// Bad configuration, initial state or checkpoint.
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

/// How `collide run` treats its output directory and when it stops early.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RunOptions {
    /// Replace an earlier run's files in the directory.
    pub force: bool,
    /// Stop as if interrupted once production has this many pair collisions (for tests of
    /// interruption at a point known in advance).
    pub interrupt_after: Option<u64>,
}

/// A run of `collide run`: sets it up (nothing is written if that fails), opens `dir`
/// (refusing another run's files unless `options.force`), runs both phases until done,
/// stopped by `stop` or by the watchdog, and writes every file. `progress` is told the
/// phase and the fraction of it done now and then.
pub fn run_into<const D: usize>(
    start: Start<'_, D>,
    dir: &Path,
    options: RunOptions,
    stop: &AtomicBool,
    progress: impl FnMut(Phase, f64),
) -> Result<Summary, RunFailure> {
    let force = options.force;
    let mut warnings = Vec::new();
    let (mut run, continuing, bytes) = match start {
        Start::Fresh(config) => (Run::new(config).map_err(RunFailure::Run)?, None, 0),
        Start::Resume { checkpoint, path } => {
            let bytes = checkpoint.run.trajectory_bytes;
            let run = Run::resume(checkpoint).map_err(RunFailure::Run)?;
            let source = path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
            (run, Some(source.to_path_buf()), bytes)
        }
    };
    let out = RunDir::open(dir, force, continuing.as_deref()).map_err(RunFailure::Output)?;
    let trajectory_every = run.config.output.trajectory_every.unwrap_or(0);
    let trajectory = match (trajectory_every, &continuing) {
        (0, _) => None,
        (_, None) => Some(Trajectory::create(&out).map_err(RunFailure::Output)?),
        (every, Some(source)) => {
            let frames = run.thermo.samples.len() as u64 / every;
            let n = run.sim.particles().len() as u64;
            Some(
                Trajectory::resume(&out, source, (bytes, frames, n), force, &mut warnings)
                    .map_err(RunFailure::Output)?,
            )
        }
    };
    let checkpoint_every = run.config.output.checkpoint_every.unwrap_or(u64::MAX);
    let next_checkpoint = (run.collisions() / checkpoint_every).saturating_add(1).saturating_mul(checkpoint_every);
    let mut writer = Writer {
        dir: &out,
        stop,
        interrupt_after: options.interrupt_after,
        trajectory,
        trajectory_every,
        checkpoint_every,
        next_checkpoint,
        progress,
    };
    let status = run.advance(stop, &mut writer).map_err(RunFailure::Output)?;
    finish(&run, &mut writer, status, warnings).map_err(RunFailure::Output)
}

/// Writes the files of a run that has ended with `status`: the trajectory flushed, the
/// final checkpoint (not after a stall), the time series, and the summary last.
fn finish<const D: usize, P: FnMut(Phase, f64)>(
    run: &Run<D>,
    writer: &mut Writer<'_, P>,
    status: Status,
    warnings: Vec<String>,
) -> Result<Summary, OutputError> {
    (writer.progress)(run.phase(), 1.0);
    let bytes = writer.flush()?;
    let dir = writer.dir;
    if status != Status::Stalled {
        let checkpoint = run.checkpoint(bytes);
        dir.write_with("checkpoint.json", |w| checkpoint.write_json(w))?;
    }
    dir.write("timeseries.csv", timeseries_csv(run).as_bytes())?;
    for observable in &run.observables {
        for (name, contents) in observable.files() {
            dir.write(name, contents.as_bytes())?;
        }
    }
    let mut summary = run.summary();
    summary.warnings.extend(warnings);
    let json = serde_json::to_string_pretty(&summary).expect("a summary serialises");
    dir.write("summary.json", json.as_bytes())?;
    Ok(summary)
}
