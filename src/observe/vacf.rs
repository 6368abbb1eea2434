//! The velocity autocorrelation `C(τ) = ⟨v(t₀)·v(t₀ + τ)⟩` per species, over every time
//! origin, at log-spaced lags, and its Green–Kubo integral, the diffusion coefficient.
//!
//! # Estimator
//!
//! Velocities (and positions) sampled every `every` time units of the production, lags and
//! origins by the multiple-tau scheme of [`correlator`](super::correlator), as for the
//! [`msd`](super::msd). The Green–Kubo integral `∫₀^τ C(s) ds` is not a quadrature of the
//! sampled `C`: along a trajectory of free flights it is exactly
//! `⟨v(t₀)·(r(t₀ + τ) − r(t₀))⟩`, which the correlator accumulates beside `C` — no
//! discretisation error however coarse the samples. So
//!
//! `D_GK(τ) = (1/d)·⟨v(t₀)·Δr(τ)⟩ → D`,
//!
//! read at the longest lag averaged over at least [`MIN_ORIGINS`] origins and no longer than
//! one of the jackknife's time blocks (in 2D it grows
//! like `ln τ`: the long-time tail). The MSD's `D` is the same limit by another estimator
//! (`⟨Δr²⟩ = 2d∫₀^τ (τ − s) C(s) ds`). `C(0) = ⟨v²⟩ = d·kT/m`.
//!
//! # Options and output
//!
//! `[observe.vacf]`: `every` (default: one mean free time), `max_lag` (default
//! [`LAGS`] × `every`). `vacf.csv`: `t`, `origins`, then per species `vacf`, `vacf_error`,
//! `integral`, `integral_error` (`⟨v(0)·Δr(t)⟩`; suffixed `_<s>` with several species);
//! `summary.json`: the options, the samples, per species `C(0)` and `D_GK` with its error
//! and lag.

use super::Observer;
use super::correlator::{Correlator, Kind};
pub use super::msd::{Diffusion, LAGS, MIN_ORIGINS, Options};
use crate::engine::{Outcome, Particle, SimBox, Simulation};
use serde::{Deserialize, Serialize};

/// The VACF observable (see the module documentation).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Vacf {
    /// The dimension.
    pub dimension: usize,
    /// What was asked for.
    pub options: Options,
    /// The next sampling instant.
    pub next: f64,
    /// The correlations.
    pub correlator: Correlator,
}

/// `C(0)` of one species.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Start {
    /// The species.
    pub species: u32,
    /// `⟨v²⟩`.
    pub c0: f64,
    /// Its standard error.
    pub error: f64,
}

/// What `summary.json` holds of it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Results {
    /// Time between samples.
    pub every: f64,
    /// The longest lag.
    pub max_lag: f64,
    /// Samples taken.
    pub samples: u64,
    /// Per species: `C(0)`.
    pub start: Vec<Start>,
    /// Per species: `D` from the Green–Kubo integral.
    pub diffusion: Vec<Diffusion>,
}

impl Vacf {
    /// Starts observing `sim`: the first sample now.
    pub fn new<const D: usize>(sim: &Simulation<D>, options: Options) -> Vacf {
        Vacf::of(sim.particles(), sim.sim_box(), sim.time(), options)
    }

    /// Starts observing `particles` in `sim_box` at time `now` (the first sample then).
    pub fn of<const D: usize>(particles: &[Particle<D>], sim_box: &SimBox<D>, now: f64, options: Options) -> Vacf {
        let correlator = options.correlator(Kind::Velocity, particles, sim_box);
        Vacf { dimension: D, options, next: now, correlator }
    }

    /// The next sampling instant.
    pub fn due(&self) -> f64 {
        self.next
    }

    /// Samples `particles` at `t` and schedules the next sample.
    pub fn sample<const D: usize>(&mut self, particles: &[Particle<D>], t: f64) {
        self.correlator.sample(particles, t);
        self.next = t + self.correlator.every;
    }

    /// The species with particles.
    fn species(&self) -> Vec<usize> {
        (0..self.correlator.counts.len()).filter(|&s| self.correlator.counts[s] > 0).collect()
    }

    /// Per species, `D_GK` at the longest lag with [`MIN_ORIGINS`] origins.
    pub fn diffusion(&self) -> Vec<Diffusion> {
        let c = &self.correlator;
        let d = self.dimension as f64;
        let Some(k) = c.longest_lag(MIN_ORIGINS) else { return Vec::new() };
        self.species()
            .into_iter()
            .map(|s| {
                let (value, error) = c.estimate(|m| m(k, s, 1) / d);
                Diffusion { species: s as u32, lag: c.tau(k), d: value, error }
            })
            .collect()
    }

    /// What `summary.json` holds.
    pub fn results(&self) -> Results {
        let c = &self.correlator;
        let start = if c.samples() == 0 {
            Vec::new()
        } else {
            self.species()
                .into_iter()
                .map(|s| {
                    let (c0, error) = c.estimate(|m| m(0, s, 0));
                    Start { species: s as u32, c0, error }
                })
                .collect()
        };
        Results {
            every: c.every,
            max_lag: c.tau(c.lag_count() - 1),
            samples: c.samples(),
            start,
            diffusion: self.diffusion(),
        }
    }

    /// `vacf.csv` (see the module docs).
    pub fn csv(&self) -> String {
        let species = self.species();
        let mut text = String::from("t,origins");
        for &s in &species {
            let x = if species.len() == 1 { String::new() } else { format!("_{s}") };
            text += &format!(",vacf{x},vacf{x}_error,integral{x},integral{x}_error");
        }
        text.push('\n');
        for lag in self.correlator.lags() {
            text += &format!("{},{}", lag.tau, lag.origins);
            for &s in &species {
                let [(c, ce), (i, ie)] = lag.values[s];
                text += &format!(",{c},{ce},{i},{ie}");
            }
            text.push('\n');
        }
        text
    }
}

impl<const D: usize> Observer<D> for Vacf {
    /// Nothing per event: it samples at its own instants.
    fn observe(&mut self, _: &Simulation<D>, _: &Outcome<D>) {}
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::SVector;

    /// Free flight: C(τ) = ⟨v²⟩ at every lag and the integral ⟨v²⟩τ — the exact running
    /// integral, not a quadrature; two species kept apart.
    #[test]
    fn free_flight_keeps_its_velocity() {
        let particles: Vec<Particle<3>> = (0..6)
            .map(|i| Particle {
                position: SVector::from([i as f64, 0.0, 1.0]),
                velocity: SVector::from([1.0 + i as f64, 0.5, -0.25]),
                time: 0.0,
                radius: 0.5,
                mass: 1.0,
                species: (i % 2) as u32,
                events: 0,
            })
            .collect();
        let v2 = |s: usize| {
            particles.iter().filter(|p| p.species as usize == s).map(|p| p.velocity.norm_squared()).sum::<f64>() / 3.0
        };
        let sim_box = SimBox { lengths: SVector::from([50.0; 3]), boundary: [crate::engine::Boundary::Wall; 3] };
        let mut vacf = Vacf::of(&particles, &sim_box, 0.0, Options { every: Some(0.5), max_lag: Some(20.0) });
        while vacf.due() <= 500.0 {
            let t = vacf.due();
            vacf.sample(&particles, t);
        }
        for lag in vacf.correlator.lags() {
            for s in 0..2 {
                let [(c, _), (i, _)] = lag.values[s];
                assert!((c - v2(s)).abs() < 1e-12 * v2(s), "{c}");
                assert!((i - v2(s) * lag.tau).abs() < 1e-9 * v2(s) * lag.tau.max(1.0), "{i}");
            }
        }
        let r = vacf.results();
        assert_eq!(r.start.len(), 2);
        assert!((r.diffusion[1].d - v2(1) * r.diffusion[1].lag / 3.0).abs() < 1e-9 * r.diffusion[1].d);
        assert!(vacf.csv().starts_with("t,origins,vacf_0,vacf_0_error,integral_0,integral_0_error,vacf_1,"));
    }
}
