//! The thermodynamics of a run: temperature and pressures, accumulated on the fly from what
//! each resolved event reports.
//!
//! [`Thermo`] is fed every [`Outcome`]: pair collisions add their virial term `σ·|Δp|`,
//! wall collisions their impulse to their wall, sampling events close a *sample* (one row
//! of the time series: kinetic energy, temperature and the pressures over the interval).
//! The estimates of a run use the totals; their error bars come from block averages over
//! the samples ([`block_error`](super::block_error)).
//!
//! # Estimators (d = dimension, A = volume, N particles)
//!
//! * Temperature: `kT = 2K/dof`, `dof = d·N − (number of periodic axes)` — the total
//!   momentum along each periodic axis is conserved (and zeroed initially), so it carries no
//!   thermal energy: `2K/(d(N−1))` in a periodic box, `2K/(dN)` between walls.
//! * Collision virial: `P·A_acc = N·kT + (1/(d·t))·Σ σ|Δp|`, the sum over pair collisions in
//!   time `t`, `|Δp|` one partner's momentum change, `σ` the contact distance.
//!   `A_acc = Π (L − σ̄)` over walled axes and `L` over periodic ones (so `A_acc = A` in a
//!   periodic box; between walls this is the walled-box virial identity).
//! * Wall pressure: impulse on one wall per time per *accessible* wall length (area): for
//!   the wall normal to `x`, `P = Σ|Δp| / (t·(L_y − σ̄))` (2D). For mixtures σ̄ is the
//!   number-averaged diameter (a convention: each species really has its own accessible
//!   length `L − σ_s`).

use super::Observer;
use crate::engine::{Boundary, Outcome, Simulation};
use serde::{Deserialize, Serialize};

/// Sums over an interval of time.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Totals {
    /// Pair collisions.
    pub pair_collisions: u64,
    /// Wall collisions.
    pub wall_collisions: u64,
    /// Σ σ|Δp| over pair collisions.
    pub virial: f64,
    /// Impulse received by each wall: `[axis][0 = lower, 1 = upper]`.
    pub wall_impulse: Vec<[f64; 2]>,
}

/// One row of the time series: an interval between sampling events.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Sample {
    /// Time at the end of the interval.
    pub t: f64,
    /// Kinetic energy at `t`.
    pub kinetic_energy: f64,
    /// kT at `t`.
    pub kt: f64,
    /// Pair collisions since the start of the production run.
    pub collisions: u64,
    /// Collision-virial pressure over the interval.
    pub pressure_virial: f64,
    /// Wall pressures over the interval: `[axis]` → `[lower, upper]`, `None` along periodic
    /// axes (empty without walls).
    pub pressure_walls: Vec<Option<[f64; 2]>>,
}

/// The thermodynamic observer: totals since the start, the current interval, and the samples.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Thermo {
    /// Dimension.
    pub dimension: usize,
    /// Number-averaged diameter σ̄ (for accessible lengths).
    pub mean_diameter: f64,
    /// When the observation started.
    pub start_time: f64,
    /// Kinetic energy when it started.
    pub start_kinetic_energy: f64,
    /// Totals since the start.
    pub total: Totals,
    /// Totals since the last sample.
    pub interval: Totals,
    /// Start of the current interval.
    pub interval_start: f64,
    /// The time series so far.
    pub samples: Vec<Sample>,
}

impl Thermo {
    /// Starts observing `sim` now.
    pub fn new<const D: usize>(sim: &Simulation<D>) -> Self {
        let n = sim.particles().len() as f64;
        let mean_diameter = sim.particles().iter().map(|p| 2.0 * p.radius).sum::<f64>() / n;
        let empty = Totals { wall_impulse: vec![[0.0; 2]; D], ..Totals::default() };
        Thermo {
            dimension: D,
            mean_diameter,
            start_time: sim.time(),
            start_kinetic_energy: sim.kinetic_energy(),
            total: empty.clone(),
            interval: empty,
            interval_start: sim.time(),
            samples: Vec::new(),
        }
    }

    /// Collision-virial pressure for totals `w` over `dt` at temperature `kt`.
    pub fn virial_pressure<const D: usize>(&self, sim: &Simulation<D>, w: &Totals, dt: f64, kt: f64) -> f64 {
        let n = sim.particles().len() as f64;
        (n * kt + w.virial / (D as f64 * dt)) / sim.sim_box().accessible_volume(self.mean_diameter)
    }

    /// Wall pressures for totals `w` over `dt`: `[axis]` → `[lower, upper]`, `None` along
    /// periodic axes.
    pub fn wall_pressures<const D: usize>(&self, sim: &Simulation<D>, w: &Totals, dt: f64) -> Vec<Option<[f64; 2]>> {
        let b = sim.sim_box();
        (0..D)
            .map(|a| {
                if b.boundary[a] != Boundary::Wall {
                    return None;
                }
                let area: f64 =
                    (0..D).filter(|&c| c != a).map(|c| b.accessible_length(c, self.mean_diameter)).product();
                Some([w.wall_impulse[a][0] / (dt * area), w.wall_impulse[a][1] / (dt * area)])
            })
            .collect()
    }
}

impl<const D: usize> Observer<D> for Thermo {
    fn observe(&mut self, sim: &Simulation<D>, outcome: &Outcome<D>) {
        match outcome {
            Outcome::Pair { impulse, .. } => {
                let v = impulse.virial();
                for t in [&mut self.total, &mut self.interval] {
                    t.pair_collisions += 1;
                    t.virial += v;
                }
            }
            Outcome::Wall { axis, upper, impulse, .. } => {
                for t in [&mut self.total, &mut self.interval] {
                    t.wall_collisions += 1;
                    t.wall_impulse[*axis][usize::from(*upper)] += impulse;
                }
            }
            Outcome::Sample => {
                let now = sim.time();
                let dt = now - self.interval_start;
                let kt = sim.kt();
                let pressure_virial = self.virial_pressure(sim, &self.interval, dt, kt);
                let pressure_walls = if sim.sim_box().boundary.contains(&Boundary::Wall) {
                    self.wall_pressures(sim, &self.interval, dt)
                } else {
                    Vec::new()
                };
                self.samples.push(Sample {
                    t: now,
                    kinetic_energy: sim.kinetic_energy(),
                    kt,
                    collisions: self.total.pair_collisions,
                    pressure_virial,
                    pressure_walls,
                });
                self.interval = Totals { wall_impulse: vec![[0.0; 2]; D], ..Totals::default() };
                self.interval_start = now;
            }
            // Bookkeeping; the end of a growth moves no momentum across the walls or between
            // particles (the radii stop growing).
            Outcome::Rebuild { .. } | Outcome::GrowthEnd => {}
        }
    }
}
