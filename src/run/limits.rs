//! What a run may cost, checked before it allocates or loops: particles, memory, collisions
//! and samples — the last two estimated from the configuration with Enskog's collision
//! rate — and the tunables of the watchdog that stops a run whose clock no longer moves.
//!
//! # The estimate
//!
//! With `n = N/V`, the packing fraction `η`, the mean diameter `σ̄`, the mean mass `m̄` and
//! the contact value `g` of the dimension's equation of state (Henderson's in 2D,
//! Carnahan–Starling's in 3D; [`crate::theory`]), Enskog's rate of collisions per particle
//! is `Γ = 2nσ̄·g·√(πkT/m̄)` in 2D (`4nσ̄²·g·√(πkT/m̄)` in 3D), and a run of `C` pair
//! collisions lasts about `T = 2C/(NΓ)`. It is a scheduling estimate — within a few
//! per cent for a fluid, an overestimate of `T` near close packing where `g` grows faster —
//! used only to refuse runs that are out of reach by orders of magnitude (10¹⁵⁰ collisions
//! at `kT = 10³⁰⁰`, 10¹¹ samples at `sample_interval = 10⁻⁹`).

use super::config::Config;
use crate::engine::MAX_PARTICLES;
use crate::text::num;
use crate::theory::{contact_value, enskog_rate};
use std::fmt;

/// Tunables of the limits and the watchdog, with automatic defaults
/// ([`Limits::for_this_machine`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Limits {
    /// The most particles.
    pub max_particles: usize,
    /// The most samples a run keeps (each a row of timeseries.csv, held in memory and in
    /// every checkpoint).
    pub max_samples: usize,
    /// The most pair collisions a run or its equilibration may ask for, or be estimated to
    /// need (10¹⁴: about two years at 10⁶ collisions per second).
    pub max_collisions: f64,
    /// The memory a run may take, bytes (`None`: unchecked).
    pub memory: Option<u64>,
    /// Events between two looks of the watchdog.
    pub watchdog_events: u64,
    /// The watchdog stops a run that, at its pace over the last look, would need more
    /// events than this to finish.
    pub max_projected_events: f64,
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            max_particles: MAX_PARTICLES,
            max_samples: 10_000_000,
            max_collisions: 1e14,
            memory: None,
            watchdog_events: 1 << 20,
            max_projected_events: 1e15,
        }
    }
}

impl Limits {
    /// The defaults, with the memory limit set to what this machine has available
    /// (`MemAvailable` in `/proc/meminfo`; unchecked where that cannot be read).
    pub fn for_this_machine() -> Limits {
        Limits { memory: available_memory(), ..Limits::default() }
    }
}

impl Limits {
    /// The memory `n` particles and `samples` samples take ([`BYTES_PER_PARTICLE`],
    /// [`BYTES_PER_SAMPLE`]), if this machine has it; `field` names what asks for them.
    pub fn check_memory(&self, field: &'static str, n: usize, samples: f64) -> Result<f64, LimitError> {
        self.check_memory_with(field, n, samples, 0.0)
    }

    /// [`check_memory`](Self::check_memory) with `observers` more bytes per particle (the
    /// observables' own: the MSD's and VACF's stored samples).
    pub fn check_memory_with(
        &self,
        field: &'static str,
        n: usize,
        samples: f64,
        observers: f64,
    ) -> Result<f64, LimitError> {
        let per_particle = BYTES_PER_PARTICLE as f64 + observers;
        let needed = n as f64 * per_particle + samples * BYTES_PER_SAMPLE as f64;
        match self.memory {
            Some(available) if needed > available as f64 => {
                Err(LimitError::Memory { field, n, samples, needed, available, per_particle })
            }
            _ => Ok(needed),
        }
    }
}

/// `MemAvailable` from `/proc/meminfo`, in bytes.
fn available_memory() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    kib.checked_mul(1024)
}

/// Bytes of memory per particle at the peak of a run (the particle records and their copy
/// while the initial state is built, lattice sites or the placement grids, the queue, the
/// cell grid and the lists, and the state copied into a checkpoint as it is written),
/// rounded up from the peak resident memory of `collide run` at N = 10⁶: 280–300 bytes per
/// disk (triangular at η = 0.5 and 0.7, random at 0.3; `/usr/bin/time -v`).
pub const BYTES_PER_PARTICLE: u64 = 400;

/// Bytes per sample: one in memory (about 100) and its text in each checkpoint written.
pub const BYTES_PER_SAMPLE: u64 = 250;

/// What a configuration is expected to cost.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Estimate {
    /// Enskog's collision rate per particle.
    pub rate_per_particle: f64,
    /// The expected simulated time of the production run.
    pub production_time: f64,
    /// The expected pair collisions of the production run.
    pub production_collisions: f64,
    /// The expected samples.
    pub samples: f64,
    /// The expected memory, bytes.
    pub memory: f64,
}

/// A run that is out of reach.
#[non_exhaustive]
#[derive(Clone, Debug, PartialEq)]
pub enum LimitError {
    /// More particles than the engine indexes.
    TooManyParticles {
        /// Asked for.
        n: usize,
        /// The most.
        max: usize,
    },
    /// More memory than is available.
    Memory {
        /// What asks for the particles (`species`, or a command-line option).
        field: &'static str,
        /// Particles.
        n: usize,
        /// Expected samples.
        samples: f64,
        /// Bytes needed.
        needed: f64,
        /// Bytes available.
        available: u64,
        /// Bytes per particle (the engine's and the observables').
        per_particle: f64,
    },
    /// A run length that asks for, or would take, too many collisions.
    Collisions {
        /// The configuration key.
        field: &'static str,
        /// Its value.
        value: f64,
        /// The collisions it asks for or implies.
        collisions: f64,
        /// The most.
        max: f64,
    },
    /// More samples than are kept.
    Samples {
        /// The expected number.
        samples: f64,
        /// The expected production time.
        time: f64,
        /// The sampling interval.
        interval: f64,
        /// The most.
        max: usize,
    },
}

impl fmt::Display for LimitError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            LimitError::TooManyParticles { n, max } => {
                write!(f, "species: {n} particles in all; the engine takes at most {max}")
            }
            LimitError::Memory { field, n, samples, needed, available, per_particle } => {
                write!(f, "{field}: {n} particles")?;
                if *samples >= 1.0 {
                    write!(f, " and about {samples:.3e} samples")?;
                }
                write!(
                    f,
                    " need about {:.3} GB of memory ({per_particle:.0} bytes per particle{}, {BYTES_PER_SAMPLE} per sample); this machine has {:.3} GB available",
                    needed / 1e9,
                    if *per_particle > BYTES_PER_PARTICLE as f64 {
                        " with the observables' stored samples"
                    } else {
                        ""
                    },
                    *available as f64 / 1e9
                )
            }
            LimitError::Collisions { field, value, collisions, max } => write!(
                f,
                "{field} = {}: that is about {collisions:.3e} pair collisions (Enskog's rate), more than the {max:.0e} a run may take; ask for less",
                num(*value)
            ),
            LimitError::Samples { samples, time, interval, max } => write!(
                f,
                "run.sample_interval = {}: the run is expected to last about {time:.4e} time units (Enskog's collision rate), which is about {samples:.3e} samples, more than the {max} a run keeps; use a larger interval",
                num(*interval)
            ),
        }
    }
}

impl std::error::Error for LimitError {}

/// Checks `config` (already valid) in a box of volume `volume` (an area in 2D) against
/// `limits`.
pub fn check<const D: usize>(config: &Config, volume: f64, limits: &Limits) -> Result<Estimate, LimitError> {
    let n = config.n_particles();
    if n > limits.max_particles {
        return Err(LimitError::TooManyParticles { n, max: limits.max_particles });
    }
    let nf = n as f64;
    let sigma = config.species.iter().map(|s| s.count as f64 * 2.0 * s.radius).sum::<f64>() / nf;
    let mass = config.species.iter().map(|s| s.count as f64 * s.mass).sum::<f64>() / nf;
    let eta = crate::engine::init::particle_volume::<D>(&config.species) / volume;
    // The contact values are only a rough guide near close packing: capped there.
    let cap = if D == 2 { 0.9 } else { 0.7 };
    let rate = enskog_rate(D, nf / volume, sigma, contact_value(D, eta.min(cap)), config.init.kt, mass);
    let collisions_in = |t: f64| 0.5 * nf * rate * t;
    let time_for = |c: f64| 2.0 * c / (nf * rate);
    let too_many = |field, value: f64, collisions: f64| {
        (collisions > limits.max_collisions).then_some(LimitError::Collisions {
            field,
            value,
            collisions,
            max: limits.max_collisions,
        })
    };
    let (run, eq) = (&config.run, &config.equilibration);
    for (field, c) in [("run.collisions", run.collisions), ("equilibration.collisions", eq.collisions)] {
        if let Some(c) = c
            && let Some(e) = too_many(field, c as f64, c as f64)
        {
            return Err(e);
        }
    }
    if let Some(t) = eq.time
        && let Some(e) = too_many("equilibration.time", t, collisions_in(t))
    {
        return Err(e);
    }
    // Production stops at whichever length comes first.
    let production_time = match (run.collisions, run.time) {
        (Some(c), Some(t)) => time_for(c as f64).min(t),
        (Some(c), None) => time_for(c as f64),
        (None, Some(t)) => t,
        (None, None) => 0.0,
    };
    let production_collisions = collisions_in(production_time);
    if run.collisions.is_none()
        && let Some(t) = run.time
        && let Some(e) = too_many("run.time", t, production_collisions)
    {
        return Err(e);
    }
    let samples = production_time / run.sample_interval;
    if !(samples <= limits.max_samples as f64) {
        return Err(LimitError::Samples {
            samples,
            time: production_time,
            interval: run.sample_interval,
            max: limits.max_samples,
        });
    }
    // The MSD's and VACF's stored samples, at their default or asked-for rates.
    let observers: f64 = [
        (config.observe.msd.as_ref(), crate::observe::correlator::Kind::Displacement),
        (config.observe.vacf.as_ref(), crate::observe::correlator::Kind::Velocity),
    ]
    .into_iter()
    .filter_map(|(options, kind)| {
        let options = options?;
        let every = options.every.unwrap_or(1.0 / rate);
        let max_lag = options.max_lag.unwrap_or(crate::observe::msd::LAGS * every);
        Some(crate::observe::correlator::bytes_per_particle(kind, D, every, max_lag))
    })
    .sum();
    let memory = limits.check_memory_with("species", n, samples, observers)?;
    Ok(Estimate { rate_per_particle: rate, production_time, production_collisions, samples, memory })
}
