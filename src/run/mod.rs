//! A run: configuration → limits → initial state → equilibration → production with
//! observers → summary. No files here (see [`crate::io::output`]); a [`Checkpoint`] holds
//! everything needed to continue bit-identically.
//!
//! [`Run::advance`] owns the loop of both phases: it feeds each event's [`Outcome`] to a
//! [`Sink`] (the files of `collide run`), stops at the next event when asked (a signal),
//! and stops a run that no longer advances ([`watchdog`]). It returns how the run ended
//! ([`Status`]), which the summary carries.

pub mod checkpoint;
pub mod limits;
pub mod watchdog;

pub use checkpoint::{Checkpoint, CheckpointError, Saved};
pub use limits::{Estimate, LimitError, Limits};
pub use watchdog::Stall;

use crate::engine::init::{InitError, Placement, box_for_packing_fraction, disk_area, initial_particles};
use crate::engine::{EventCounts, Outcome, OverlapAudit, SetupError, SimBox, Simulation, check_box};
use crate::io::config::Config;
use crate::observe::{Observer, Thermo, block_error};
use nalgebra::Vector2;
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
    Config(String),
    /// The run is out of reach (particles, memory, collisions, samples).
    Limit(LimitError),
    /// The initial state could not be built.
    Init(InitError),
    /// The initial state is not a valid configuration (overlap, box too small, …).
    Setup(SetupError),
    /// A checkpoint that cannot be continued.
    Checkpoint(CheckpointError),
}

impl fmt::Display for RunError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            RunError::Config(e) => write!(f, "{e}"),
            RunError::Limit(e) => write!(f, "{e}"),
            RunError::Init(e) => write!(f, "initial state: {e}"),
            RunError::Setup(e) => write!(f, "initial state: {e}"),
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

/// The two phases of a run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Phase {
    /// Until both of `[equilibration]`'s lengths are reached; nothing is measured.
    Equilibration,
    /// Until either of `[run]`'s lengths is reached, observed.
    Production,
}

impl Phase {
    fn is_production(&self) -> bool {
        *self == Phase::Production
    }
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
}

impl Status {
    fn is_complete(&self) -> bool {
        *self == Status::Complete
    }
}

/// What a run does with each event besides observing it: `collide run` writes its files.
pub trait Sink {
    /// What can go wrong.
    type Error;
    /// Called after every event of both phases, with the run as the event left it.
    fn event(&mut self, run: &Run, outcome: &Outcome<2>) -> Result<(), Self::Error>;
    /// Called now and then with the phase and the fraction of it done.
    fn progress(&mut self, _phase: Phase, _done: f64) {}
}

/// A sink that does nothing.
pub struct Discard;

impl Sink for Discard {
    type Error = std::convert::Infallible;
    fn event(&mut self, _: &Run, _: &Outcome<2>) -> Result<(), Self::Error> {
        Ok(())
    }
}

/// A run in progress (2D).
#[derive(Clone, Debug)]
pub struct Run {
    /// The configuration.
    pub config: Config,
    /// The simulation.
    pub sim: Simulation<2>,
    /// The observer (replaced at the start of production).
    pub thermo: Thermo,
    /// What the equilibration did.
    pub equilibration: Equilibration,
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

/// The box a configuration describes.
pub fn box_of(config: &Config) -> SimBox<2> {
    let boundary = config.boundaries();
    match (&config.sim_box.size, config.sim_box.packing_fraction) {
        (Some(size), _) => SimBox { lengths: Vector2::new(size[0], size[1]), boundary },
        (None, Some(eta)) => {
            box_for_packing_fraction(&config.species, eta, boundary, config.init.placement, config.sim_box.aspect)
        }
        (None, None) => unreachable!("validated: size or packing fraction"),
    }
}

/// Checks a configuration, its box and its limits: everything that can be said before any
/// particle exists.
fn admit(config: &Config, limits: &Limits) -> Result<(SimBox<2>, Estimate), RunError> {
    config.check().map_err(RunError::Config)?;
    let sim_box = box_of(config);
    let reach = 2.0 * config.species.iter().map(|s| s.radius).fold(0.0, f64::max);
    check_box(&sim_box, reach).map_err(|e| {
        let b = &config.sim_box;
        let from = match (b.packing_fraction, b.aspect) {
            (Some(eta), Some(aspect)) => {
                format!(" (the box comes from box.packing_fraction = {eta} and box.aspect = {aspect})")
            }
            (Some(eta), None) => format!(" (the box comes from box.packing_fraction = {eta})"),
            _ => " (box.size)".to_string(),
        };
        RunError::Config(format!("{e}{from}"))
    })?;
    let estimate = limits::check(config, sim_box.volume(), limits).map_err(RunError::Limit)?;
    Ok((sim_box, estimate))
}

impl Run {
    /// Builds the initial state (not yet equilibrated), with the limits of this machine.
    pub fn new(config: Config) -> Result<Run, RunError> {
        Run::with_limits(config, Limits::for_this_machine())
    }

    /// [`new`](Self::new) with the limits given.
    pub fn with_limits(config: Config, limits: Limits) -> Result<Run, RunError> {
        let (sim_box, estimate) = admit(&config, &limits)?;
        let init = &config.init;
        let particles =
            initial_particles(&config.species, &sim_box, init.placement, init.velocities, init.kt, config.seed)
                .map_err(RunError::Init)?;
        let sim = Simulation::new(particles, sim_box).map_err(|e| match e {
            // On a lattice of a mixture, neighbours closer than the largest contact distance
            // can overlap: say so, and what would fit.
            SetupError::Overlap { .. } if config.init.placement != Placement::Random => {
                let fits = crate::engine::init::lattice_limit(&config.species);
                RunError::Config(format!(
                    "initial state: {e}: the lattice's sites are closer than the largest contact distance; a triangular lattice holds these species up to η ≈ {fits:.4}"
                ))
            }
            e => RunError::Setup(e),
        })?;
        let thermo = Thermo::new(&sim);
        Ok(Run {
            config,
            start_counts: sim.counts(),
            sim,
            thermo,
            equilibration: Equilibration::default(),
            limits,
            estimate,
            phase: Phase::Equilibration,
            wall_before: 0.0,
            wall_since: None,
            ended: (Status::Complete, None),
        })
    }

    /// Continues from a checkpoint, with the limits of this machine.
    pub fn resume(checkpoint: Checkpoint) -> Result<Run, RunError> {
        Run::resume_with_limits(checkpoint, Limits::for_this_machine())
    }

    /// [`resume`](Self::resume) with the limits given. The checkpoint is verified
    /// ([`Checkpoint::verify`]), its configuration validated exactly like a fresh start,
    /// and its state checked against that configuration: the particles of every species
    /// with their radii and masses, the box, no overlap, the bookkeeping of the phase.
    pub fn resume_with_limits(checkpoint: Checkpoint, limits: Limits) -> Result<Run, RunError> {
        checkpoint.verify().map_err(RunError::Checkpoint)?;
        let Saved { config, phase, state, thermo, equilibration, start_counts, wall_time_s, trajectory_bytes: _ } =
            checkpoint.run;
        let (sim_box, estimate) =
            admit(&config, &limits).map_err(|e| RunError::Checkpoint(CheckpointError::Config(e.to_string())))?;
        let bad = |what: String| Err(RunError::Checkpoint(CheckpointError::State(what)));
        let n = config.n_particles();
        if state.particles.len() != n {
            return bad(format!("{} particles, the species ask for {n}", state.particles.len()));
        }
        let mut counts = vec![0usize; config.species.len()];
        for (i, p) in state.particles.iter().enumerate() {
            let Some(s) = config.species.get(p.species as usize) else {
                return bad(format!("particle {i} is of species {}, there are {}", p.species, config.species.len()));
            };
            if p.radius != s.radius || p.mass != s.mass {
                return bad(format!(
                    "particle {i} (species {}) has radius {} and mass {}, its species {} and {}",
                    p.species, p.radius, p.mass, s.radius, s.mass
                ));
            }
            counts[p.species as usize] += 1;
        }
        if let Some(k) = (0..counts.len()).find(|&k| counts[k] != config.species[k].count) {
            return bad(format!("{} particles of species {k}, it asks for {}", counts[k], config.species[k].count));
        }
        let c = &state.counts;
        let s = &start_counts;
        if s.pair > c.pair || s.wall > c.wall || s.rebuild > c.rebuild || s.sample > c.sample || s.stale > c.stale {
            return bad(format!("production started at event counts {s:?}, after the current {c:?}"));
        }
        let sampling = match phase {
            Phase::Equilibration => None,
            Phase::Production => Some(config.run.sample_interval),
        };
        if state.sampling != sampling {
            return bad(format!(
                "sampling every {:?} in {phase:?}, the configuration says {sampling:?}",
                state.sampling
            ));
        }
        if thermo.dimension != 2
            || thermo.total.wall_impulse.len() != 2
            || thermo.interval.wall_impulse.len() != 2
            || thermo.samples.iter().any(|s| !matches!(s.pressure_walls.len(), 0 | 2))
        {
            return bad("the observer is not of a 2D run".into());
        }
        let observed = thermo.total.pair_collisions;
        let production = if phase.is_production() { c.pair - s.pair } else { 0 };
        if observed != production {
            return bad(format!("the observer saw {observed} pair collisions, the counts say {production}"));
        }
        if thermo.samples.len() > limits.max_samples {
            return bad(format!("{} samples, more than a run keeps ({})", thermo.samples.len(), limits.max_samples));
        }
        if !(wall_time_s.is_finite() && wall_time_s >= 0.0) {
            return bad(format!("wall_time_s = {wall_time_s}"));
        }
        let sim = Simulation::restore(state, sim_box)
            .map_err(|e| RunError::Checkpoint(CheckpointError::State(e.to_string())))?;
        Ok(Run {
            config,
            sim,
            thermo,
            equilibration,
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
    pub fn checkpoint(&self, trajectory_bytes: u64) -> Checkpoint {
        Checkpoint::seal(Saved {
            config: self.config.clone(),
            phase: self.phase,
            state: self.sim.state(),
            thermo: self.thermo.clone(),
            equilibration: self.equilibration,
            start_counts: self.start_counts,
            wall_time_s: self.wall_time(),
            trajectory_bytes,
        })
    }

    /// The phase the run is in.
    pub fn phase(&self) -> Phase {
        self.phase
    }

    /// Whether both lengths of the equilibration are reached (an absent one counts as
    /// reached): an equilibration is at least this long.
    fn equilibrated(&self) -> bool {
        let target = &self.config.equilibration;
        self.sim.counts().pair >= target.collisions.unwrap_or(0) && self.sim.time() >= target.time.unwrap_or(0.0)
    }

    /// The fraction of the equilibration done (the smaller of the two).
    fn equilibration_done(&self) -> f64 {
        let target = &self.config.equilibration;
        let by_collisions = target.collisions.map_or(1.0, |c| self.sim.counts().pair as f64 / c.max(1) as f64);
        let by_time = target.time.map_or(1.0, |t| if t > 0.0 { self.sim.time() / t } else { 1.0 });
        by_collisions.min(by_time).min(1.0)
    }

    /// Starts production: the equilibration is recorded, the observer reset, sampling
    /// scheduled.
    fn start_production(&mut self) {
        self.equilibration = Equilibration { collisions: self.sim.counts().pair, time: self.sim.time() };
        self.thermo = Thermo::new(&self.sim);
        self.start_counts = self.sim.counts();
        self.sim.sample_every(self.config.run.sample_interval);
        self.phase = Phase::Production;
    }

    /// Runs the equilibration (`progress` is called now and then with the fraction done),
    /// then starts production: observers reset, sampling scheduled. For experiments that
    /// drive production themselves with [`step`](Self::step). The watchdog watches it as it
    /// watches [`advance`](Self::advance); a stall ends it, and the summary says so.
    pub fn equilibrate(&mut self, progress: impl FnMut(f64)) {
        struct Progress<F>(F);
        impl<F: FnMut(f64)> Sink for Progress<F> {
            type Error = std::convert::Infallible;
            fn event(&mut self, _: &Run, _: &Outcome<2>) -> Result<(), Self::Error> {
                Ok(())
            }
            fn progress(&mut self, _: Phase, done: f64) {
                (self.0)(done);
            }
        }
        if self.phase == Phase::Equilibration {
            let never = AtomicBool::new(false);
            // Nothing stops it but a stall, which records itself.
            let Ok(_) = self.drive(Phase::Equilibration, &never, &mut Progress(progress));
            self.start_production();
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

    /// One event of the production run, observed; `None` when nothing can happen any more.
    pub fn step(&mut self) -> Option<Outcome<2>> {
        debug_assert!(self.phase.is_production(), "equilibrate() starts production");
        let outcome = self.sim.step()?;
        self.thermo.observe(&self.sim, &outcome);
        Some(outcome)
    }

    /// Production wall-clock seconds so far, over every process that ran it.
    pub fn wall_time(&self) -> f64 {
        self.wall_before + self.wall_since.map_or(0.0, |t| t.elapsed().as_secs_f64())
    }

    /// Runs both phases to the end of production, feeding every event to `sink`, and says
    /// how the run ended. It stops early, with the state intact, at the first event after
    /// `stop` is set ([`Status::Interrupted`]), when the watchdog finds the clock stuck
    /// ([`Status::Stalled`]), or when the run holds [`Limits::max_samples`] samples.
    pub fn advance<S: Sink>(&mut self, stop: &AtomicBool, sink: &mut S) -> Result<Status, S::Error> {
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

    fn advance_inner<S: Sink>(&mut self, stop: &AtomicBool, sink: &mut S) -> Result<Status, S::Error> {
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
    /// observer sees the events (production).
    fn drive<S: Sink>(&mut self, phase: Phase, stop: &AtomicBool, sink: &mut S) -> Result<Option<Status>, S::Error> {
        let production = phase.is_production();
        let done = |run: &Run| if production { run.progress() } else { run.equilibration_done() };
        let limits = self.limits;
        let mut dog = Watchdog::new(&limits, self.sim.time(), done(self), self.sim.counts());
        let mut events = 0u64;
        while !(if production { self.done() } else { self.equilibrated() }) {
            if stop.load(Ordering::Relaxed) {
                return Ok(Some(Status::Interrupted));
            }
            if production && self.thermo.samples.len() >= limits.max_samples {
                return Ok(Some(Status::TooManySamples));
            }
            let Some(outcome) = (if production { self.step() } else { self.sim.step() }) else { break };
            if dog.due()
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

    /// The results so far (with production's wall-clock time over every process), marked
    /// with how the last [`advance`](Self::advance) ended.
    pub fn summary(&self) -> Summary {
        let sim = &self.sim;
        let n = sim.particles().len();
        let production = self.phase.is_production();
        let t = if production { sim.time() - self.thermo.start_time } else { 0.0 };
        let kt = sim.kt();
        let blocks = self.config.run.blocks;
        let samples = &self.thermo.samples;
        let pressure = self.thermo.virial_pressure(sim, &self.thermo.total, t, kt);
        let (_, pressure_err) = block_error(&samples.iter().map(|s| s.pressure_virial).collect::<Vec<_>>(), blocks);
        let density = n as f64 / sim.sim_box().accessible_volume(self.thermo.mean_diameter);
        let walls = self.thermo.wall_pressures(sim, &self.thermo.total, t);
        let mut wall_pressures = Vec::new();
        for (axis, pair) in walls.iter().enumerate() {
            let Some(pair) = pair else { continue };
            for (side, name) in [(0, "lower"), (1, "upper")] {
                let series: Vec<f64> = samples.iter().filter_map(|s| s.pressure_walls[axis].map(|w| w[side])).collect();
                let (_, error) = block_error(&series, blocks);
                wall_pressures.push(WallPressure { axis, side: name.into(), pressure: pair[side], error });
            }
        }
        let counts = sim.counts();
        let since = if production { counts.since(&self.start_counts) } else { EventCounts::default() };
        let pair = self.thermo.total.pair_collisions;
        let k0 = self.thermo.start_kinetic_energy;
        let max_energy_deviation = samples.iter().map(|s| ((s.kinetic_energy - k0) / k0).abs()).fold(0.0, f64::max);
        let audit = sim.check_overlaps();
        let sim_box = sim.sim_box();
        let wall_time_s = self.wall_time();
        let mut warnings = Vec::new();
        if production && samples.len() < 2 {
            warnings.push(format!(
                "{} sample(s): the error bars need at least 2 (use a smaller run.sample_interval or a longer run)",
                samples.len()
            ));
        } else if production && samples.len() < blocks {
            warnings.push(format!(
                "{} samples for run.blocks = {blocks}: the error bars use {} blocks of one sample each",
                samples.len(),
                samples.len()
            ));
        }
        if production && self.ended.0 == Status::Complete && !self.done() {
            warnings
                .push(format!("nothing can happen any more: the run ended at t = {} before its length", sim.time()));
        }
        Summary {
            collide_version: env!("CARGO_PKG_VERSION").into(),
            status: self.ended.0,
            stall: self.ended.1.clone(),
            phase: self.phase,
            warnings,
            n_particles: n,
            packing_fraction: disk_area(&self.config.species) / sim_box.volume(),
            seed: self.config.seed,
            box_lengths: sim_box.lengths.iter().copied().collect(),
            collisions: pair,
            wall_collisions: self.thermo.total.wall_collisions,
            events: since.total(),
            events_by_kind: since,
            sim_time: t,
            wall_time_s,
            collisions_per_second: pair as f64 / wall_time_s,
            kT: kt,
            pressure_virial: pressure,
            pressure_virial_error: pressure_err,
            compressibility: pressure / (density * kt),
            compressibility_error: pressure_err / (density * kt),
            wall_pressures,
            collision_rate_per_particle: 2.0 * pair as f64 / (n as f64 * t),
            energy_relative_drift: (sim.kinetic_energy() - k0) / k0,
            max_energy_deviation,
            max_overlap: audit,
            samples: samples.len(),
            equilibration: self.equilibration,
            config: self.config.clone(),
        }
    }
}

/// One wall's pressure.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct WallPressure {
    /// Axis normal to the wall.
    pub axis: usize,
    /// "lower" (at 0) or "upper" (at L).
    pub side: String,
    /// Impulse per time per accessible wall length.
    pub pressure: f64,
    /// Block-average standard error.
    pub error: f64,
}

fn is_production(phase: &Phase) -> bool {
    phase.is_production()
}

/// What `summary.json` holds (see the README for each field). `status`, `stall`, `phase`
/// and `warnings` appear only when they say something: a run that completed its
/// production without a warning has none of them.
#[allow(non_snake_case)]
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Summary {
    /// The version that wrote it.
    pub collide_version: String,
    /// How the run ended (absent: complete).
    #[serde(default, skip_serializing_if = "Status::is_complete")]
    pub status: Status,
    /// Why the watchdog stopped it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stall: Option<Stall>,
    /// The phase it ended in (absent: production).
    #[serde(default = "production", skip_serializing_if = "is_production")]
    pub phase: Phase,
    /// What the numbers below should be read with.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub warnings: Vec<String>,
    /// N.
    pub n_particles: usize,
    /// η = Σπ Rᵢ² / A.
    pub packing_fraction: f64,
    /// The seed.
    pub seed: u64,
    /// Box edge lengths.
    pub box_lengths: Vec<f64>,
    /// Production pair collisions.
    pub collisions: u64,
    /// Production wall collisions.
    pub wall_collisions: u64,
    /// Production events of every kind (stale ones excluded).
    pub events: u64,
    /// Production events by kind.
    pub events_by_kind: EventCounts,
    /// Production simulated time.
    pub sim_time: f64,
    /// Wall-clock time of the production run, seconds, over every process that ran it (with
    /// `collisions_per_second`, the only non-reproducible fields).
    pub wall_time_s: f64,
    /// Pair collisions per wall-clock second.
    pub collisions_per_second: f64,
    /// kT = 2K/dof at the end.
    pub kT: f64,
    /// Collision-virial pressure.
    pub pressure_virial: f64,
    /// Its block-average standard error.
    pub pressure_virial_error: f64,
    /// Z = P/(n kT), n = N/A_acc.
    pub compressibility: f64,
    /// Its standard error.
    pub compressibility_error: f64,
    /// Per-wall pressures (empty without walls).
    pub wall_pressures: Vec<WallPressure>,
    /// Γ = 2·collisions/(N·t).
    pub collision_rate_per_particle: f64,
    /// (K_end − K_start)/K_start over production.
    pub energy_relative_drift: f64,
    /// Largest |K − K_start|/K_start over the samples.
    pub max_energy_deviation: f64,
    /// The overlap audit at the end.
    pub max_overlap: OverlapAudit,
    /// Samples (rows of timeseries.csv).
    pub samples: usize,
    /// The equilibration.
    pub equilibration: Equilibration,
    /// The configuration, echoed.
    pub config: Config,
}

fn production() -> Phase {
    Phase::Production
}
