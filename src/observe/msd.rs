//! The mean squared displacement `⟨|r(t₀ + τ) − r(t₀)|²⟩` per species, over every time origin,
//! at log-spaced lags, and the self-diffusion coefficient from its slope.
//!
//! # Estimator
//!
//! Positions are the particles' unwrapped ones (a particle crossing a periodic face keeps
//! going), sampled every `every` time units of the production; the lags and origins are the
//! multiple-tau scheme of [`correlator`](super::correlator): lags `j·2^l·every`, four per
//! octave, each averaged over all origins `2^l·every` apart, memory fixed by `max_lag`.
//! Besides the MSD, the non-Gaussian parameter
//! `α₂(τ) = d/(d + 2)·⟨Δr⁴⟩/⟨Δr²⟩² − 1` (0 for Gaussian displacements).
//!
//! The diffusion coefficient is the slope of the MSD over the last two octaves it holds
//! well, `D = [M(τ) − M(τ/4)] / (2d·(3τ/4))`, `τ` the longest lag averaged over at least
//! [`MIN_ORIGINS`] origins and no longer than one of the jackknife's time blocks
//! ([`Correlator::longest_lag`]): the linear regime's slope, free of the ballistic start's offset
//! (in 2D, where `D(t)` grows like `ln t`, the value at that `τ`). Errors are the
//! correlator's block jackknife. With the total momentum at zero the centre of mass does not
//! move, so nothing is subtracted.
//!
//! # Options and output
//!
//! `[observe.msd]`: `every` (default: one mean free time, [`mean_free_time`]), `max_lag`
//! (default [`LAGS`] × `every`). `msd.csv`: `t`, `origins`, then per species `msd`,
//! `msd_error`, `alpha2` (suffixed `_<s>` with several species); `summary.json`: the options,
//! the samples and per species `D` with its error and lag.

use super::Observer;
use super::correlator::{Correlator, Kind, mean_free_time};
use crate::engine::{Outcome, Particle, SimBox, Simulation};
use serde::{Deserialize, Serialize};

/// What the observable is asked for (shared with [`vacf`](super::vacf)).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Options {
    /// Time between samples.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub every: Option<f64>,
    /// The longest lag.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_lag: Option<f64>,
}

/// Default `max_lag` in sampling intervals.
pub const LAGS: f64 = 1000.0;
/// The fewest time origins of the lag a diffusion coefficient is read at.
pub const MIN_ORIGINS: u64 = 64;

impl Options {
    /// Checks the options of `[observe.<name>]`: the key, its value and what is allowed.
    pub fn check(&self, name: &str) -> Result<(), super::Refusal> {
        super::positive(name, "every", self.every, "time")?;
        super::positive(name, "max_lag", self.max_lag, "time")?;
        if let (Some(every), Some(max_lag)) = (self.every, self.max_lag)
            && max_lag < every
        {
            return Err((
                format!("observe.{name}.max_lag"),
                max_lag.to_string(),
                format!("must be at least observe.{name}.every ({every})"),
            ));
        }
        Ok(())
    }

    /// The correlator these options ask for, of `particles` in `sim_box`.
    pub fn correlator<const D: usize>(&self, kind: Kind, particles: &[Particle<D>], sim_box: &SimBox<D>) -> Correlator {
        let every = self.every.unwrap_or_else(|| mean_free_time(particles, sim_box));
        let max_lag = self.max_lag.unwrap_or(LAGS * every).max(every);
        Correlator::new(kind, particles, every, max_lag)
    }
}

/// A diffusion coefficient read at one lag.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Diffusion {
    /// The species.
    pub species: u32,
    /// The lag it is read at.
    pub lag: f64,
    /// `D`.
    pub d: f64,
    /// Its standard error.
    pub error: f64,
}

/// The MSD observable (see the module documentation).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Msd {
    /// The dimension.
    pub dimension: usize,
    /// What was asked for.
    pub options: Options,
    /// The next sampling instant.
    pub next: f64,
    /// The correlations.
    pub correlator: Correlator,
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
    /// Per species: `D` from the MSD's slope.
    pub diffusion: Vec<Diffusion>,
}

impl Msd {
    /// Starts observing `sim`: the first sample now.
    pub fn new<const D: usize>(sim: &Simulation<D>, options: Options) -> Msd {
        Msd::of(sim.particles(), sim.sim_box(), sim.time(), options)
    }

    /// Starts observing `particles` in `sim_box` at time `now` (the first sample then).
    pub fn of<const D: usize>(particles: &[Particle<D>], sim_box: &SimBox<D>, now: f64, options: Options) -> Msd {
        let correlator = options.correlator(Kind::Displacement, particles, sim_box);
        Msd { dimension: D, options, next: now, correlator }
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

    /// The lags `(k, q)` (indices) that `D` is read between: `τ_k` the longest lag with
    /// enough origins whose quarter `τ_q = τ_k/4` is a lag too (None before there is one).
    pub fn diffusion_lags(&self) -> Option<(usize, usize)> {
        let c = &self.correlator;
        let longest = c.longest_lag(MIN_ORIGINS)?;
        (0..=longest).rev().find_map(|k| (0..k).find(|&q| c.tau(q) * 4.0 == c.tau(k)).map(|q| (k, q)))
    }

    /// Per species, `D` from the slope over the last two octaves (see the module docs).
    pub fn diffusion(&self) -> Vec<Diffusion> {
        let c = &self.correlator;
        let d = self.dimension as f64;
        let Some((k, q)) = self.diffusion_lags() else { return Vec::new() };
        let tau = c.tau(k);
        (0..c.counts.len())
            .filter(|&s| c.counts[s] > 0)
            .map(|s| {
                let (value, error) = c.estimate(|m| (m(k, s, 0) - m(q, s, 0)) / (2.0 * d * 0.75 * tau));
                Diffusion { species: s as u32, lag: tau, d: value, error }
            })
            .collect()
    }

    /// What `summary.json` holds.
    pub fn results(&self) -> Results {
        let c = &self.correlator;
        Results { every: c.every, max_lag: c.tau(c.lag_count() - 1), samples: c.samples(), diffusion: self.diffusion() }
    }

    /// `msd.csv` (see the module docs).
    pub fn csv(&self) -> String {
        let c = &self.correlator;
        let d = self.dimension as f64;
        let species: Vec<usize> = (0..c.counts.len()).filter(|&s| c.counts[s] > 0).collect();
        let mut text = String::from("t,origins");
        for &s in &species {
            let suffix = if species.len() == 1 { String::new() } else { format!("_{s}") };
            text += &format!(",msd{suffix},msd{suffix}_error,alpha2{suffix}");
        }
        text.push('\n');
        for lag in c.lags() {
            text += &format!("{},{}", lag.tau, lag.origins);
            for &s in &species {
                let [(m2, e2), (m4, _)] = lag.values[s];
                let alpha2 = if m2 > 0.0 { d / (d + 2.0) * m4 / (m2 * m2) - 1.0 } else { 0.0 };
                text += &format!(",{m2},{e2},{alpha2}");
            }
            text.push('\n');
        }
        text
    }
}

impl<const D: usize> Observer<D> for Msd {
    /// Nothing per event: it samples at its own instants.
    fn observe(&mut self, _: &Simulation<D>, _: &Outcome<D>) {}
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::SVector;

    /// Free flight: MSD(τ) = ⟨v²⟩τ² exactly, α₂ that of the velocities, and D from a
    /// ballistic MSD is the slope's 5/4·⟨v²⟩τ/(2d) — the estimator is what its docs say.
    #[test]
    fn free_flight_is_ballistic() {
        let particles: Vec<Particle<2>> =
            (0..4).map(|i| super::super::test_particle([i as f64, 0.0], [1.0 + i as f64, 0.5])).collect();
        let v2 = particles.iter().map(|p| p.velocity.norm_squared()).sum::<f64>() / 4.0;
        let mut msd = Msd::of(
            &particles,
            &SimBox { lengths: SVector::from([100.0, 100.0]), boundary: [crate::engine::Boundary::Periodic; 2] },
            0.0,
            Options { every: Some(0.25), max_lag: Some(40.0) },
        );
        while msd.due() <= 2000.0 {
            let t = msd.due();
            msd.sample(&particles, t);
        }
        for lag in msd.correlator.lags() {
            let expected = v2 * lag.tau * lag.tau;
            assert!(
                (lag.values[0][0].0 - expected).abs() <= 1e-9 * expected.max(1.0),
                "{} {}",
                lag.tau,
                lag.values[0][0].0
            );
        }
        let d = &msd.diffusion()[0];
        let expected = v2 * (d.lag * d.lag - d.lag * d.lag / 16.0) / (2.0 * 2.0 * 0.75 * d.lag);
        assert!((d.d / expected - 1.0).abs() < 1e-9, "{} vs {expected}", d.d);
        assert!(msd.csv().starts_with("t,origins,msd,msd_error,alpha2\n0,"));
    }
}
