//! The summary of a run (`summary.json`): the estimates with their block-average errors,
//! the event counts, the conservation checks, how the run ended, and the configuration
//! echoed. Every field is specified in `docs/outputs.md`.

use super::{Equilibration, Phase, Run, Stall, Status};
use crate::engine::init::particle_volume;
use crate::engine::{EventCounts, OverlapAudit};
use crate::observe::block_error;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

impl<const D: usize> Run<D> {
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
        if let (Some(c), Some(compress)) = (&self.compression, &self.config.compress) {
            if c.jammed && !compress.to_jamming() {
                warnings.push(format!(
                    "the packing jammed at φ = {:.6} before compress.target_packing_fraction = {}: the run ended at the jammed packing",
                    c.packing_fraction,
                    compress.target_packing_fraction.unwrap_or(f64::NAN)
                ));
            } else if c.jammed && c.rattlers == Some(self.sim.particles().len()) {
                warnings.push(format!(
                    "the pressure limit was reached at φ = {:.6} with no contact network holding any particle: a pressure of the compression itself (growth faster than the particles can follow), not a jammed packing; use a smaller compress.rate",
                    c.packing_fraction
                ));
            } else if c.done && compress.to_jamming() && !c.jammed {
                warnings.push(format!(
                    "the box cannot hold larger particles: the compression stopped at φ = {:.6} without jamming",
                    c.packing_fraction
                ));
            }
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
            dimension: D,
            n_particles: n,
            packing_fraction: match &self.compression {
                Some(_) => sim.packing_fraction(),
                None => particle_volume::<D>(&self.config.species) / sim_box.volume(),
            },
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
            compression: self.compression.clone(),
            observables: self.observables.iter().map(|o| (o.name().to_string(), o.results())).collect(),
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

/// What `summary.json` holds (each field is specified in `docs/outputs.md`). `status`, `stall`, `phase`
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
    /// 2 (disks) or 3 (spheres).
    pub dimension: usize,
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
    /// The compression, with `[compress]` (absent without).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub compression: Option<super::Compression>,
    /// What the observables the configuration names measured, by name (absent: none).
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub observables: BTreeMap<String, serde_json::Value>,
    /// The configuration, echoed.
    pub config: super::Config,
}

impl Summary {
    /// What is wrong with a run that ended but did not complete — the watchdog stopped it,
    /// it filled its samples, its compression jammed early — as `collide run` and a sweep's
    /// `failed.json` say it (`None`: it completed, or was interrupted and continues).
    pub fn problem(&self) -> Option<String> {
        match self.status {
            Status::Complete | Status::Interrupted => None,
            Status::Stalled => {
                Some(format!("stopped: {}", self.stall.as_ref().map_or_else(String::new, |s| s.to_string())))
            }
            Status::TooManySamples => Some(format!(
                "stopped at {} samples, the most a run keeps: use a larger run.sample_interval",
                self.samples
            )),
            Status::Jammed => Some("the packing jammed before its target packing fraction".to_string()),
        }
    }
}

fn production() -> Phase {
    Phase::Production
}
