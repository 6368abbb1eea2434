//! A run: configuration → limits → initial state → (compression) → equilibration →
//! production with observers → summary, in `D` dimensions. [`Run`] owns the one loop of both phases
//! ([`Run::advance`]): after every event it feeds the run's own observers (in production)
//! and a [`Sink`] given by the caller — the files of `collide run`, an experiment's own
//! observers — stops at the next event when asked (a signal), and stops a run that no longer
//! advances ([`watchdog`]). A [`Checkpoint`] holds everything needed to continue
//! bit-identically; the [`Summary`] is what the run measured.
//!
//! * [`config`]: the TOML configuration and its validation;
//! * [`limits`], [`watchdog`]: what a run may cost, and the stop for one that is stuck;
//! * [`checkpoint`]: the saved state, sealed by a digest;
//! * [`summary`]: estimates, error bars, status;
//! * [`output`], [`rundir`]: the files of `collide run` and the directory that holds them.

pub mod checkpoint;
pub mod compression;
pub mod config;
pub mod limits;
pub mod output;
pub mod rundir;
pub mod summary;
pub mod watchdog;

pub use checkpoint::{Checkpoint, CheckpointError, Saved, StateError};
pub use compression::Compression;
pub use config::{Config, ConfigError, Invalid};
pub use limits::{Estimate, LimitError, Limits};
pub use summary::{Summary, WallPressure};
pub use watchdog::Stall;

use crate::engine::init::{InitError, Placement, box_for_packing_fraction, initial_particles, lattice_limit};
use crate::engine::{EventCounts, Outcome, Particle, SetupError, SimBox, Simulation, check_box};
use crate::observe::{Observable, Observer, Thermo};
use nalgebra::SVector;
use serde::{Deserialize, Serialize};
use std::fmt;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;
use watchdog::Watchdog;

/// Why a run could not start.
#[non_exhaustive]
#[derive(Clone, Debug, PartialEq)]
pub enum RunError {
    /// The configuration is invalid.
    Config(Invalid),
    /// The box the configuration describes cannot hold its particles.
    Box {
        /// Why not.
        error: SetupError,
        /// The keys the box comes from, and their values.
        from: String,
    },
    /// The run is out of reach (particles, memory, collisions, samples).
    Limit(LimitError),
    /// The initial state could not be built.
    Init(InitError),
    /// A lattice of a mixture puts neighbours closer than the largest contact distance.
    LatticeOverlap {
        /// The overlap found.
        error: SetupError,
        /// The packing fraction up to which the densest lattice of the dimension holds
        /// these species ([`lattice_limit`]).
        fits_up_to: f64,
        /// That lattice: "triangular" (2D) or "fcc" (3D).
        lattice: &'static str,
    },
    /// The initial state is not a valid configuration (overlap, box too small, …).
    Setup(SetupError),
    /// The particles handed to [`Run::from_particles`] are not those of the configuration's
    /// species (count, radius or mass).
    Particles(StateError),
    /// A checkpoint that cannot be continued.
    Checkpoint(CheckpointError),
}

impl fmt::Display for RunError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            RunError::Config(e) => write!(f, "{e}"),
            RunError::Box { error, from } => write!(f, "{error} ({from})"),
            RunError::Limit(e) => write!(f, "{e}"),
            RunError::Init(e) => write!(f, "initial state: {e}"),
            RunError::LatticeOverlap { error, fits_up_to, lattice } => write!(
                f,
                "initial state: {error}: the lattice's sites are closer than the largest contact distance; a perfect {lattice} lattice holds these species up to η ≈ {fits_up_to:.4}"
            ),
            RunError::Setup(e) => write!(f, "initial state: {e}"),
            RunError::Particles(e) => write!(f, "the particles given: {e}"),
            RunError::Checkpoint(e) => write!(f, "{e}"),
        }
    }
}

impl std::error::Error for RunError {}

/// What the equilibration did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Equilibration {
    /// Pair collisions.
    pub collisions: u64,
    /// Simulated time.
    pub time: f64,
}

/// The phases of a run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Phase {
    /// With `[compress]`, first: until the compression is over; nothing is measured.
    Compression,
    /// Until both of `[equilibration]`'s lengths are reached; nothing is measured.
    Equilibration,
    /// Until either of `[run]`'s lengths is reached, observed.
    Production,
}

impl Phase {
    /// The configuration's name of the phase (as in summary.json's progress messages).
    pub fn name(&self) -> &'static str {
        match self {
            Phase::Compression => "compression",
            Phase::Equilibration => "equilibration",
            Phase::Production => "production",
        }
    }

    fn is_production(&self) -> bool {
        *self == Phase::Production
    }
}

/// The earliest instant any of `observables` samples at.
fn next_due(observables: &[Observable]) -> Option<f64> {
    observables.iter().filter_map(Observable::due).reduce(f64::min)
}

/// How a run ended.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Status {
    /// It reached its length (or nothing could happen any more).
    #[default]
    Complete,
    /// Stopped when asked (SIGINT, SIGTERM); the checkpoint continues it.
    Interrupted,
    /// Stopped by the watchdog: its clock no longer moved (see the summary's `stall`).
    Stalled,
    /// Stopped when it held [`Limits::max_samples`] samples.
    TooManySamples,
    /// Its compression jammed before the packing fraction it asked for: the run ended at the
    /// jammed packing (see the summary's `compression`).
    Jammed,
}

impl Status {
    fn is_complete(&self) -> bool {
        *self == Status::Complete
    }
}

/// What a run feeds each event besides its own observers, with the whole run in view: the
/// files of `collide run` (trajectory frames, checkpoints), an experiment's observers.
///
/// Every [`Observer`] is a sink that sees the production events ([`Sink::event`] hands it
/// the simulation and the outcome); a sink of its own sees both phases.
pub trait Sink<const D: usize> {
    /// What can go wrong (a sink's error stops the run, and [`Run::advance`] returns it).
    type Error;
    /// Called after every event of both phases, with the run as the event left it.
    fn event(&mut self, run: &Run<D>, outcome: &Outcome<D>) -> Result<(), Self::Error>;
    /// Called now and then with the phase and the fraction of it done.
    fn progress(&mut self, _phase: Phase, _done: f64) {}
}

impl<const D: usize, O: Observer<D>> Sink<D> for O {
    type Error = std::convert::Infallible;
    #[inline]
    fn event(&mut self, run: &Run<D>, outcome: &Outcome<D>) -> Result<(), Self::Error> {
        if run.phase.is_production() {
            self.observe(&run.sim, outcome);
        }
        Ok(())
    }
}

/// A sink that does nothing.
pub struct Discard;

impl<const D: usize> Sink<D> for Discard {
    type Error = std::convert::Infallible;
    #[inline]
    fn event(&mut self, _: &Run<D>, _: &Outcome<D>) -> Result<(), Self::Error> {
        Ok(())
    }
}

/// A run in progress.
#[derive(Clone, Debug)]
pub struct Run<const D: usize> {
    /// The configuration.
    pub config: Config,
    /// The simulation.
    pub sim: Simulation<D>,
    /// The thermodynamics (started afresh when production starts).
    pub thermo: Thermo,
    /// The observables the configuration names (started when production starts).
    pub observables: Vec<Observable>,
    /// The earliest instant an observable samples at (`None`: none samples at instants of its
    /// own), kept so that a run without one pays nothing per event.
    next_due: Option<f64>,
    /// What the equilibration did.
    pub equilibration: Equilibration,
    /// The compression, with `[compress]`.
    pub compression: Option<Compression>,
    /// What the run may cost, and the watchdog's tunables.
    pub limits: Limits,
    /// What the configuration is expected to cost.
    pub estimate: Estimate,
    start_counts: EventCounts,
    phase: Phase,
    /// Production wall-clock seconds of earlier processes (checkpoints) and finished
    /// stretches of this one.
    wall_before: f64,
    /// When the current stretch of production began in this process.
    wall_since: Option<Instant>,
    /// How the last [`advance`](Self::advance) ended, and why if stalled.
    ended: (Status, Option<Stall>),
}

/// The box a configuration (checked for `D`) describes.
pub fn box_of<const D: usize>(config: &Config) -> SimBox<D> {
    let boundary = config.boundaries::<D>();
    match (&config.sim_box.size, config.sim_box.packing_fraction) {
        (Some(size), _) => SimBox { lengths: SVector::from_fn(|a, _| size[a]), boundary },
        (None, Some(eta)) => {
            let edges = config.sim_box.aspect.as_ref().map(|a| a.edges::<D>());
            box_for_packing_fraction(&config.species, eta, boundary, config.placement(), edges)
        }
        (None, None) => unreachable!("validated: size or packing fraction"),
    }
}

/// Checks a configuration, its box and its limits: everything that can be said before any
/// particle exists.
fn admit<const D: usize>(config: &Config, limits: &Limits) -> Result<(SimBox<D>, Estimate), RunError> {
    config.check_for(D).map_err(RunError::Config)?;
    let sim_box = box_of::<D>(config);
    let reach = 2.0 * config.species.iter().map(|s| s.radius).fold(0.0, f64::max);
    check_box(&sim_box, reach).map_err(|error| {
        let b = &config.sim_box;
        let from = match (b.packing_fraction, &b.aspect) {
            (Some(eta), Some(aspect)) => {
                format!("the box comes from box.packing_fraction = {eta} and box.aspect = {aspect}")
            }
            (Some(eta), None) => format!("the box comes from box.packing_fraction = {eta}"),
            _ => "box.size".to_string(),
        };
        RunError::Box { error, from }
    })?;
    let estimate = limits::check::<D>(config, sim_box.volume(), limits).map_err(RunError::Limit)?;
    Ok((sim_box, estimate))
}

/// Checks that `particles` are those `config`'s species ask for: as many of each species, with
/// its radius and mass.
/// With `scaled` (a compression), every radius may be its species' times one common factor
/// (to rounding, 10⁻¹²), at least 1.
fn check_particles<const D: usize>(config: &Config, particles: &[Particle<D>], scaled: bool) -> Result<(), StateError> {
    let bad = |field: &'static str, found: String, expected: String| Err(StateError { field, found, expected });
    let n = config.n_particles();
    if particles.len() != n {
        return bad(
            "run.state.particles",
            format!("{} particles", particles.len()),
            format!("the species ask for {n}"),
        );
    }
    let mut counts = vec![0usize; config.species.len()];
    let scale = match (scaled, particles.first()) {
        (true, Some(p)) => config.species.get(p.species as usize).map_or(1.0, |s| p.radius / s.radius),
        _ => 1.0,
    };
    for (i, p) in particles.iter().enumerate() {
        let Some(s) = config.species.get(p.species as usize) else {
            return bad(
                "run.state.particles.species",
                format!("particle {i} is of species {}", p.species),
                format!("there are {}", config.species.len()),
            );
        };
        let radius_fits = if scaled {
            scale >= 1.0 && ((p.radius / s.radius) / scale - 1.0).abs() <= 1e-12
        } else {
            p.radius == s.radius
        };
        if !radius_fits || p.mass != s.mass {
            return bad(
                "run.state.particles",
                format!("particle {i} (species {}) has radius {} and mass {}", p.species, p.radius, p.mass),
                format!("its species {} and {}", s.radius, s.mass),
            );
        }
        counts[p.species as usize] += 1;
    }
    if let Some(k) = (0..counts.len()).find(|&k| counts[k] != config.species[k].count) {
        return bad(
            "run.state.particles",
            format!("{} particles of species {k}", counts[k]),
            format!("it asks for {}", config.species[k].count),
        );
    }
    Ok(())
}

impl<const D: usize> Run<D> {
    /// Builds the initial state (not yet equilibrated), with the limits of this machine.
    pub fn new(config: Config) -> Result<Run<D>, RunError> {
        Run::with_limits(config, Limits::for_this_machine())
    }

    /// [`new`](Self::new) with the limits given.
    pub fn with_limits(config: Config, limits: Limits) -> Result<Run<D>, RunError> {
        let (sim_box, estimate) = admit::<D>(&config, &limits)?;
        let init = &config.init;
        let particles =
            initial_particles(&config.species, &sim_box, config.placement(), init.velocities, init.kt, config.seed)
                .map_err(RunError::Init)?;
        let sim = Simulation::new(particles, sim_box).map_err(|error| match error {
            // On a lattice of a mixture, neighbours closer than the largest contact distance
            // can overlap: say so, and what would fit.
            SetupError::Overlap { .. } if config.placement() != Placement::Random => {
                match lattice_limit::<D>(&config.species) {
                    Some(fits_up_to) => RunError::LatticeOverlap {
                        error,
                        fits_up_to,
                        lattice: if D == 3 { "fcc" } else { "triangular" },
                    },
                    None => RunError::Setup(error),
                }
            }
            error => RunError::Setup(error),
        })?;
        Run::started(config, sim, limits, estimate)
    }

    /// A run of `config` from the given particles instead of its `[init]` (an experiment that
    /// prepares a state of its own), with the limits of this machine: the particles must be
    /// those of its species, inside its box, without overlaps.
    pub fn from_particles(config: Config, particles: Vec<Particle<D>>) -> Result<Run<D>, RunError> {
        let limits = Limits::for_this_machine();
        let (sim_box, estimate) = admit::<D>(&config, &limits)?;
        check_particles(&config, &particles, false).map_err(RunError::Particles)?;
        let sim = Simulation::new(particles, sim_box).map_err(RunError::Setup)?;
        Run::started(config, sim, limits, estimate)
    }

    /// A run about to compress (with `[compress]`) or equilibrate `sim`.
    fn started(config: Config, mut sim: Simulation<D>, limits: Limits, estimate: Estimate) -> Result<Run<D>, RunError> {
        let compression = match config.compress {
            Some(_) => Some(
                Compression::start(&mut sim, &config).map_err(|e| RunError::Box { error: e.error, from: e.from })?,
            ),
            None => None,
        };
        Ok(Run {
            phase: if compression.is_some() { Phase::Compression } else { Phase::Equilibration },
            config,
            start_counts: sim.counts(),
            thermo: Thermo::new(&sim),
            sim,
            observables: Vec::new(),
            next_due: None,
            equilibration: Equilibration::default(),
            compression,
            limits,
            estimate,
            wall_before: 0.0,
            wall_since: None,
            ended: (Status::Complete, None),
        })
    }

    /// Runs the compression, if any, to its end; `Some` when the run ends with it (jammed,
    /// or stopped), else the equilibration starts.
    fn compress<S: Sink<D>>(&mut self, stop: &AtomicBool, sink: &mut S) -> Result<Option<Status>, S::Error> {
        if self.phase != Phase::Compression {
            return Ok(None);
        }
        if let Some(status) = self.drive(Phase::Compression, stop, sink)? {
            return Ok(Some(status));
        }
        let to_jamming = self.config.compress.as_ref().is_some_and(|c| c.to_jamming());
        match &self.compression {
            Some(c) if to_jamming || !c.done => Ok(Some(Status::Complete)),
            Some(c) if c.jammed => Ok(Some(Status::Jammed)),
            _ => {
                self.phase = Phase::Equilibration;
                Ok(None)
            }
        }
    }

    /// The clock and the pair collisions when the equilibration started (after any
    /// compression).
    fn equilibration_start(&self) -> (f64, u64) {
        self.compression.as_ref().map_or((0.0, 0), Compression::end_mark)
    }

    /// Runs the equilibration alone (the same loop as [`advance`](Self::advance)), then
    /// starts production, so that its length and sampling can be planned from what the
    /// equilibration found ([`plan_production`](Self::plan_production)) before
    /// [`advance`](Self::advance) runs it. Nothing stops it but the watchdog.
    pub fn equilibrate<S: Sink<D>>(&mut self, sink: &mut S) -> Result<Status, S::Error> {
        if let Some(status) = self.compress(&AtomicBool::new(false), sink)? {
            return Ok(status);
        }
        if self.phase == Phase::Equilibration {
            if let Some(status) = self.drive(Phase::Equilibration, &AtomicBool::new(false), sink)? {
                return Ok(status);
            }
            self.start_production();
        }
        Ok(Status::Complete)
    }

    /// Sets the production's length (collisions and/or time) and sampling interval, before
    /// any production event: validated as the configuration's `[run]` would be.
    pub fn plan_production(
        &mut self,
        collisions: Option<u64>,
        time: Option<f64>,
        sample_interval: f64,
    ) -> Result<(), Invalid> {
        let mut config = self.config.clone();
        config.run.collisions = collisions;
        config.run.time = time;
        config.run.sample_interval = sample_interval;
        config.check_for(D)?;
        self.config = config;
        if self.phase.is_production() {
            self.sim.sample_every(sample_interval);
        }
        Ok(())
    }

    /// Makes the production end `collisions` pair collisions and/or `time` time units from
    /// now (from its start while it has not started), whichever comes first, without
    /// touching anything else (the sampling goes on as it was): how the Python package runs
    /// "this much more". Validated as the configuration's `[run]` would be; at least one
    /// length must be given.
    pub fn extend_production(&mut self, collisions: Option<u64>, time: Option<f64>) -> Result<(), Invalid> {
        let (done, elapsed) = match self.phase.is_production() {
            true => (self.collisions(), self.sim.time() - self.thermo.start_time),
            false => (0, 0.0),
        };
        let mut config = self.config.clone();
        config.run.collisions = collisions.map(|c| done.saturating_add(c));
        config.run.time = time.map(|t| elapsed + t);
        config.check_for(D)?;
        self.config = config;
        Ok(())
    }

    /// Continues from a checkpoint, with the limits of this machine.
    pub fn resume(checkpoint: Checkpoint<D>) -> Result<Run<D>, RunError> {
        Run::resume_with_limits(checkpoint, Limits::for_this_machine())
    }

    /// [`resume`](Self::resume) with the limits given. The checkpoint is verified
    /// ([`Checkpoint::verify`]), its configuration validated exactly like a fresh start,
    /// and its state checked against that configuration: the particles of every species
    /// with their radii and masses, the box, no overlap, the bookkeeping of the phase.
    pub fn resume_with_limits(checkpoint: Checkpoint<D>, limits: Limits) -> Result<Run<D>, RunError> {
        checkpoint.verify().map_err(RunError::Checkpoint)?;
        let Saved {
            config,
            phase,
            state,
            thermo,
            observables,
            equilibration,
            compression,
            start_counts,
            wall_time_s,
            trajectory_bytes: _,
        } = checkpoint.run;
        if compression.is_some() != config.compress.is_some()
            || (phase == Phase::Compression) != compression.as_ref().is_some_and(|c| !c.done)
        {
            return Err(RunError::Checkpoint(CheckpointError::State(StateError {
                field: "run.compression",
                found: format!("a compression {:?} in phase {phase:?}", compression.as_ref().map(|c| c.done)),
                expected: "one under way exactly in the compression phase, and only with [compress]".into(),
            })));
        }
        let (sim_box, estimate) =
            admit::<D>(&config, &limits).map_err(|e| RunError::Checkpoint(CheckpointError::Config(Box::new(e))))?;
        let bad = |field: &'static str, found: String, expected: String| {
            Err(RunError::Checkpoint(CheckpointError::State(StateError { field, found, expected })))
        };
        if let Err(e) = check_particles(&config, &state.particles, compression.is_some()) {
            return Err(RunError::Checkpoint(CheckpointError::State(e)));
        }
        let c = &state.counts;
        if !c.at_least(&start_counts) {
            return bad(
                "run.start_counts",
                format!("production started at event counts {start_counts:?}"),
                format!("after the current {c:?}"),
            );
        }
        let sampling = match phase {
            Phase::Compression | Phase::Equilibration => None,
            Phase::Production => Some(config.run.sample_interval),
        };
        if state.sampling != sampling {
            return bad(
                "run.state.sampling",
                format!("sampling every {:?} in {phase:?}", state.sampling),
                format!("the configuration says {sampling:?}"),
            );
        }
        let walls_per_sample = |w: usize| w == 0 || w == D;
        if thermo.dimension != D
            || thermo.total.wall_impulse.len() != D
            || thermo.interval.wall_impulse.len() != D
            || thermo.samples.iter().any(|s| !walls_per_sample(s.pressure_walls.len()))
        {
            return bad("run.thermo", format!("the observer is of a {}D run", thermo.dimension), format!("not {D}D"));
        }
        let observed = thermo.total.pair_collisions;
        let production = if phase.is_production() { c.pair - start_counts.pair } else { 0 };
        if observed != production {
            return bad(
                "run.thermo.total.pair_collisions",
                format!("the observer saw {observed} pair collisions"),
                format!("the counts say {production}"),
            );
        }
        let names: Vec<&str> = observables.iter().map(Observable::name).collect();
        let asked = if phase.is_production() { config.observe.names() } else { Vec::new() };
        if names != asked || observables.iter().any(|o| o.dimension() != D) {
            return bad(
                "run.observables",
                format!("observables {names:?}"),
                format!("the configuration asks for {asked:?} in {D}D"),
            );
        }
        if thermo.samples.len() > limits.max_samples {
            return bad(
                "run.thermo.samples",
                format!("{} samples", thermo.samples.len()),
                format!("more than a run keeps ({})", limits.max_samples),
            );
        }
        if !(wall_time_s.is_finite() && wall_time_s >= 0.0) {
            return bad("run.wall_time_s", format!("wall_time_s = {wall_time_s}"), "a finite number ≥ 0".into());
        }
        let sim = Simulation::restore(state, sim_box).map_err(|e| RunError::Checkpoint(CheckpointError::Setup(e)))?;
        Ok(Run {
            config,
            sim,
            thermo,
            next_due: next_due(&observables),
            observables,
            equilibration,
            compression,
            limits,
            estimate,
            start_counts,
            phase,
            wall_before: wall_time_s,
            wall_since: None,
            ended: (Status::Complete, None),
        })
    }

    /// The state to save; `trajectory_bytes` is the length of the trajectory written so far.
    pub fn checkpoint(&self, trajectory_bytes: u64) -> Checkpoint<D> {
        Checkpoint::seal(Saved {
            config: self.config.clone(),
            phase: self.phase,
            state: self.sim.state(),
            thermo: self.thermo.clone(),
            observables: self.observables.clone(),
            equilibration: self.equilibration,
            compression: self.compression.clone(),
            start_counts: self.start_counts,
            wall_time_s: self.wall_time(),
            trajectory_bytes,
        })
    }

    /// The phase the run is in.
    pub fn phase(&self) -> Phase {
        self.phase
    }

    /// Event counts when production started (zero before).
    pub fn start_counts(&self) -> EventCounts {
        self.start_counts
    }

    /// How the last [`advance`](Self::advance) ended, and the watchdog's reason if stalled.
    pub fn ended(&self) -> (Status, Option<&Stall>) {
        (self.ended.0, self.ended.1.as_ref())
    }

    /// Whether both lengths of the equilibration are reached (an absent one counts as
    /// reached): an equilibration is at least this long.
    fn equilibrated(&self) -> bool {
        let target = &self.config.equilibration;
        let (t0, c0) = self.equilibration_start();
        self.sim.counts().pair - c0 >= target.collisions.unwrap_or(0)
            && self.sim.time() - t0 >= target.time.unwrap_or(0.0)
    }

    /// The fraction of the equilibration done (the smaller of the two).
    fn equilibration_done(&self) -> f64 {
        let target = &self.config.equilibration;
        let (t0, c0) = self.equilibration_start();
        let by_collisions = target.collisions.map_or(1.0, |c| (self.sim.counts().pair - c0) as f64 / c.max(1) as f64);
        let by_time = target.time.map_or(1.0, |t| if t > 0.0 { (self.sim.time() - t0) / t } else { 1.0 });
        by_collisions.min(by_time).min(1.0)
    }

    /// Starts production: the equilibration is recorded, the observers started afresh,
    /// sampling scheduled.
    fn start_production(&mut self) {
        let (t0, c0) = self.equilibration_start();
        self.equilibration = Equilibration { collisions: self.sim.counts().pair - c0, time: self.sim.time() - t0 };
        self.thermo = Thermo::new(&self.sim);
        self.observables = self.config.observe.start(&self.sim);
        self.next_due = next_due(&self.observables);
        self.start_counts = self.sim.counts();
        self.sim.sample_every(self.config.run.sample_interval);
        self.phase = Phase::Production;
    }

    /// Hands the observables that sample at instants of their own every instant up to
    /// [`Simulation::quiet_until`] (the particles in free flight until then), earliest first.
    fn sample_due(&mut self) {
        let quiet = self.sim.quiet_until();
        while let Some(t) = self.next_due
            && t <= quiet
        {
            for observable in &mut self.observables {
                if observable.due() == Some(t) {
                    observable.sample(&self.sim, t);
                }
            }
            self.next_due = next_due(&self.observables);
        }
    }

    /// Production pair collisions so far.
    pub fn collisions(&self) -> u64 {
        self.thermo.total.pair_collisions
    }

    /// Fraction of the production run done (0 during equilibration).
    pub fn progress(&self) -> f64 {
        if !self.phase.is_production() {
            return 0.0;
        }
        let by_collisions = self.config.run.collisions.map_or(0.0, |c| self.collisions() as f64 / c as f64);
        let by_time = self.config.run.time.map_or(0.0, |t| (self.sim.time() - self.thermo.start_time) / t);
        by_collisions.max(by_time).min(1.0)
    }

    /// Whether the production run has reached its length: `progress() >= 1`, without its
    /// divisions where they are not needed (this is asked after every event). For the
    /// collisions, `c/C ≥ 1` exactly when `c ≥ C` (both below 2⁵³); the time keeps the
    /// division, whose rounding decides the last event.
    #[inline]
    pub fn done(&self) -> bool {
        if !self.phase.is_production() {
            return false;
        }
        let run = &self.config.run;
        run.collisions.is_some_and(|c| self.collisions() >= c)
            || run.time.is_some_and(|t| (self.sim.time() - self.thermo.start_time) / t >= 1.0)
    }

    /// Production wall-clock seconds so far, over every process that ran it.
    pub fn wall_time(&self) -> f64 {
        self.wall_before + self.wall_since.map_or(0.0, |t| t.elapsed().as_secs_f64())
    }

    /// Runs both phases to the end of production, feeding every event to `sink`, and says
    /// how the run ended. It stops early, with the state intact, at the first event after
    /// `stop` is set ([`Status::Interrupted`]), when the watchdog finds the clock stuck
    /// ([`Status::Stalled`]), or when the run holds [`Limits::max_samples`] samples.
    pub fn advance<S: Sink<D>>(&mut self, stop: &AtomicBool, sink: &mut S) -> Result<Status, S::Error> {
        let status = self.advance_inner(stop, sink);
        if let Some(since) = self.wall_since.take() {
            self.wall_before += since.elapsed().as_secs_f64();
        }
        // A stall has already recorded itself, with its reason.
        if let Ok(status) = status
            && status != Status::Stalled
        {
            self.ended = (status, None);
        }
        status
    }

    /// [`advance`](Self::advance) to the end, unstoppable but by the watchdog (for
    /// experiments and tests).
    pub fn complete<S: Sink<D>>(&mut self, sink: &mut S) -> Result<Status, S::Error> {
        self.advance(&AtomicBool::new(false), sink)
    }

    fn advance_inner<S: Sink<D>>(&mut self, stop: &AtomicBool, sink: &mut S) -> Result<Status, S::Error> {
        if let Some(status) = self.compress(stop, sink)? {
            return Ok(status);
        }
        if self.phase == Phase::Equilibration {
            if let Some(status) = self.drive(Phase::Equilibration, stop, sink)? {
                return Ok(status);
            }
            self.start_production();
        }
        self.wall_since = Some(Instant::now());
        Ok(self.drive(Phase::Production, stop, sink)?.unwrap_or(Status::Complete))
    }

    /// Runs one phase until it is over, or nothing can happen any more (`None`), or the
    /// run must stop (`Some`: interrupted, stalled, too many samples). Both phases take the
    /// same steps: the phase only says when it is over, how far it is, and whether the
    /// observers see the events (production).
    fn drive<S: Sink<D>>(&mut self, phase: Phase, stop: &AtomicBool, sink: &mut S) -> Result<Option<Status>, S::Error> {
        let production = phase.is_production();
        let compressing = phase == Phase::Compression;
        let done = |run: &Run<D>| match (phase, &run.compression) {
            (Phase::Production, _) => run.progress(),
            (Phase::Compression, Some(c)) => c.progress(&run.sim, &run.config),
            _ => run.equilibration_done(),
        };
        let limits = self.limits;
        let mut dog = Watchdog::new(&limits, self.sim.time(), done(self), self.sim.counts());
        let mut events = 0u64;
        while !(match phase {
            Phase::Production => self.done(),
            Phase::Equilibration => self.equilibrated(),
            Phase::Compression => self.compression.as_ref().is_none_or(|c| c.done),
        }) {
            if stop.load(Ordering::Relaxed) {
                return Ok(Some(Status::Interrupted));
            }
            if production && self.thermo.samples.len() >= limits.max_samples {
                return Ok(Some(Status::TooManySamples));
            }
            if production && self.next_due.is_some() {
                self.sample_due();
            }
            let Some(outcome) = self.sim.step() else { break };
            if compressing && let Some(c) = self.compression.as_mut() {
                // The compression watches its own pressure and ends itself (the engine's
                // stall guard ends a growth at jamming): no watchdog.
                c.observe(&mut self.sim, &self.config, &outcome);
                c.over(&mut self.sim, &self.config);
            }
            if production {
                self.thermo.observe(&self.sim, &outcome);
                for observable in &mut self.observables {
                    observable.observe(&self.sim, &outcome);
                }
            }
            if !compressing
                && dog.due()
                && let Some(stall) = dog.look(&limits, self.sim.time(), done(self), self.sim.counts(), &outcome)
            {
                self.ended = (Status::Stalled, Some(stall));
                return Ok(Some(Status::Stalled));
            }
            sink.event(self, &outcome)?;
            events += 1;
            if events % 4096 == 0 {
                sink.progress(phase, done(self));
            }
        }
        Ok(None)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::init::{Velocities, initial_particles};

    /// An experiment's own particles must be those of its configuration's species; a count
    /// or a radius off is refused as the particles' fault, naming what differs.
    #[test]
    fn particles_handed_in_must_be_the_species() {
        let config = Config::default_config();
        let sim_box = box_of::<2>(&config);
        let particles =
            initial_particles(&config.species, &sim_box, Placement::Triangular, Velocities::Maxwell, 1.0, 1).unwrap();
        assert!(Run::<2>::from_particles(config.clone(), particles.clone()).is_ok());

        let fewer = particles[1..].to_vec();
        let Err(RunError::Particles(e)) = Run::<2>::from_particles(config.clone(), fewer) else {
            panic!("one particle short is refused")
        };
        assert!(e.found.contains("999 particles"), "{e}");

        let mut other = particles;
        other[7].radius *= 0.9;
        let Err(RunError::Particles(e)) = Run::<2>::from_particles(config, other) else {
            panic!("a particle of another radius is refused")
        };
        assert!(e.found.contains("particle 7"), "{e}");
    }
}
