//! A run: configuration → initial state → equilibration → production with observers →
//! summary. No files here (see [`crate::io::output`]); a [`Checkpoint`] holds everything
//! needed to continue bit-identically.

use crate::engine::init::{InitError, box_for_packing_fraction, disk_area, initial_particles};
use crate::engine::{EventCounts, OverlapAudit, SetupError, SimBox, Simulation, SimulationState};
use crate::io::config::Config;
use crate::observe::{Observer, Thermo, block_error};
use nalgebra::Vector2;
use serde::{Deserialize, Serialize};
use std::fmt;

/// Why a run could not start.
#[non_exhaustive]
#[derive(Clone, Debug, PartialEq)]
pub enum RunError {
    /// The initial state could not be built.
    Init(InitError),
    /// The initial state is not a valid configuration (overlap, box too small, …).
    Setup(SetupError),
    /// A checkpoint from another version or a different configuration.
    Checkpoint(String),
}

impl fmt::Display for RunError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            RunError::Init(e) => write!(f, "initial state: {e}"),
            RunError::Setup(e) => write!(f, "initial state: {e}"),
            RunError::Checkpoint(e) => write!(f, "checkpoint: {e}"),
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

/// Everything needed to continue a run bit-identically.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Checkpoint {
    /// The version that wrote it.
    pub collide_version: String,
    /// The configuration.
    pub config: Config,
    /// The simulation.
    pub state: SimulationState<2>,
    /// The observer.
    pub thermo: Thermo,
    /// The equilibration that preceded production.
    pub equilibration: Equilibration,
    /// Event counts when production started.
    pub start_counts: EventCounts,
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
    start_counts: EventCounts,
    production: bool,
}

/// The box a configuration describes.
pub fn box_of(config: &Config) -> SimBox<2> {
    let boundary = config.boundaries();
    match (&config.sim_box.size, config.sim_box.packing_fraction) {
        (Some(size), _) => SimBox { lengths: Vector2::new(size[0], size[1]), boundary },
        (None, Some(eta)) => box_for_packing_fraction(
            &config.species,
            eta,
            boundary,
            config.init.placement,
            config.sim_box.aspect.unwrap_or(1.0),
        ),
        (None, None) => unreachable!("validated: size or packing fraction"),
    }
}

impl Run {
    /// Builds the initial state (not yet equilibrated).
    pub fn new(config: Config) -> Result<Run, RunError> {
        let sim_box = box_of(&config);
        let init = &config.init;
        let particles =
            initial_particles(&config.species, &sim_box, init.placement, init.velocities, init.kt, config.seed)
                .map_err(RunError::Init)?;
        let sim = Simulation::new(particles, sim_box).map_err(RunError::Setup)?;
        let thermo = Thermo::new(&sim);
        Ok(Run {
            config,
            start_counts: sim.counts(),
            sim,
            thermo,
            equilibration: Equilibration::default(),
            production: false,
        })
    }

    /// Continues from a checkpoint.
    pub fn resume(checkpoint: Checkpoint) -> Result<Run, RunError> {
        if checkpoint.collide_version != env!("CARGO_PKG_VERSION") {
            return Err(RunError::Checkpoint(format!(
                "written by collide {}, this is {}: a resumed run would not be bit-identical",
                checkpoint.collide_version,
                env!("CARGO_PKG_VERSION")
            )));
        }
        let sim_box = box_of(&checkpoint.config);
        let sim = Simulation::restore(checkpoint.state, sim_box).map_err(RunError::Setup)?;
        Ok(Run {
            config: checkpoint.config,
            sim,
            thermo: checkpoint.thermo,
            equilibration: checkpoint.equilibration,
            start_counts: checkpoint.start_counts,
            production: true,
        })
    }

    /// The state to save.
    pub fn checkpoint(&self) -> Checkpoint {
        Checkpoint {
            collide_version: env!("CARGO_PKG_VERSION").to_string(),
            config: self.config.clone(),
            state: self.sim.state(),
            thermo: self.thermo.clone(),
            equilibration: self.equilibration,
            start_counts: self.start_counts,
        }
    }

    /// Runs the equilibration (`progress` is called now and then with the fraction done),
    /// then starts production: observers reset, sampling scheduled.
    pub fn equilibrate(&mut self, mut progress: impl FnMut(f64)) {
        let target = &self.config.equilibration;
        let (c0, t0) = (self.sim.counts().pair, self.sim.time());
        let collisions = target.collisions.unwrap_or(0);
        let time = target.time.unwrap_or(0.0);
        while self.sim.counts().pair - c0 < collisions || self.sim.time() - t0 < time {
            if self.sim.step().is_none() {
                break;
            }
            if self.sim.counts().pair % 4096 == 0 && collisions > 0 {
                progress((self.sim.counts().pair - c0) as f64 / collisions as f64);
            }
        }
        self.equilibration = Equilibration { collisions: self.sim.counts().pair - c0, time: self.sim.time() - t0 };
        self.thermo = Thermo::new(&self.sim);
        self.start_counts = self.sim.counts();
        self.sim.sample_every(self.config.run.sample_interval);
        self.production = true;
    }

    /// Production pair collisions so far.
    pub fn collisions(&self) -> u64 {
        self.thermo.total.pair_collisions
    }

    /// Fraction of the production run done.
    pub fn progress(&self) -> f64 {
        let by_collisions = self.config.run.collisions.map_or(0.0, |c| self.collisions() as f64 / c as f64);
        let by_time = self.config.run.time.map_or(0.0, |t| (self.sim.time() - self.thermo.start_time) / t);
        by_collisions.max(by_time).min(1.0)
    }

    /// Whether the production run has reached its length.
    pub fn done(&self) -> bool {
        self.progress() >= 1.0
    }

    /// One event of the production run, observed; `None` when nothing can happen any more.
    pub fn step(&mut self) -> Option<crate::engine::Outcome<2>> {
        debug_assert!(self.production, "equilibrate() starts production");
        let outcome = self.sim.step()?;
        self.thermo.observe(&self.sim, &outcome);
        Some(outcome)
    }

    /// The results so far.
    pub fn summary(&self, wall_time_s: f64) -> Summary {
        let sim = &self.sim;
        let n = sim.particles().len();
        let t = sim.time() - self.thermo.start_time;
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
        let pair = self.thermo.total.pair_collisions;
        let k0 = self.thermo.start_kinetic_energy;
        let max_energy_deviation = samples.iter().map(|s| ((s.kinetic_energy - k0) / k0).abs()).fold(0.0, f64::max);
        let audit = sim.check_overlaps();
        let sim_box = sim.sim_box();
        Summary {
            collide_version: env!("CARGO_PKG_VERSION").into(),
            n_particles: n,
            packing_fraction: disk_area(&self.config.species) / sim_box.volume(),
            seed: self.config.seed,
            box_lengths: sim_box.lengths.iter().copied().collect(),
            collisions: pair,
            wall_collisions: self.thermo.total.wall_collisions,
            events: counts.total() - self.start_counts.total(),
            events_by_kind: counts.since(&self.start_counts),
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

/// What `summary.json` holds (see the README for each field).
#[allow(non_snake_case)]
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Summary {
    /// The version that wrote it.
    pub collide_version: String,
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
    /// Wall-clock time of the production run, seconds (the one non-reproducible field).
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
