//! Time correlations of every particle's motion over many time origins at log-spaced lags:
//! the multiple-tau scheme that [`msd`](super::msd) and [`vacf`](super::vacf) share.
//!
//! # Scheme
//!
//! Samples arrive every `Δ` time units (the observable's `every`), each a row of `W` numbers
//! per particle (positions for the MSD; velocity and position for the VACF). Level 0 keeps the
//! last [`POINTS`] samples of every particle; level `l ≥ 1` keeps the last [`POINTS`] of the
//! samples whose index is a multiple of `2^l` — exact samples, not block averages, since an
//! event-driven trajectory is known exactly at every instant. A new sample at level `l` is
//! correlated with the level's stored ones `j` places back: lags `j·2^l·Δ`, `j = 0 … 7` at
//! level 0 (0: the sample with itself) and `j = 4 … 7` above (the shorter lags are the finer levels'), four lags per
//! octave, each averaged over every time origin of its level (origins `2^l·Δ` apart). The
//! memory is `8·W` numbers per particle per level and the levels end at `max_lag`: it does
//! not grow with the run, and a sample costs about `12·W` multiply-adds per particle (8 at
//! level 0, 4/2 + 4/4 + … above).
//!
//! # Estimates and errors
//!
//! For each lag, species and channel the sums over particles and origins are kept per time
//! block (the block of the later sample; at most [`BLOCKS`] blocks, pairs merged and the
//! block length doubled when they fill), with the number of origins. A value is the total sum
//! over `origins · N_s`; its error, and the error of anything computed from the sums (a
//! slope, a difference), is the delete-one-block jackknife's: blocks long against the
//! correlation of the products make it honest, which holds for lags short against the run's
//! length over [`BLOCKS`].

use crate::engine::{Particle, SimBox};
use serde::{Deserialize, Serialize};

/// Samples kept per level.
pub const POINTS: usize = 8;
/// The most time blocks the sums are kept in.
pub const BLOCKS: usize = 32;
/// The most levels (lags up to `7·2^39·Δ`).
const MAX_LEVELS: usize = 40;

/// What is correlated.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Kind {
    /// Rows: positions. Channels: `|Δr|²` and `|Δr|⁴`.
    Displacement,
    /// Rows: velocity, then position. Channels: `v(0)·v(τ)` and `v(0)·(r(τ) − r(0))`.
    Velocity,
}

impl Kind {
    /// Numbers per particle per sample in `d` dimensions.
    pub fn width(self, d: usize) -> usize {
        match self {
            Kind::Displacement => d,
            Kind::Velocity => 2 * d,
        }
    }

    /// The particles' rows at `t`, into `out`.
    fn rows<const D: usize>(self, particles: &[Particle<D>], t: f64, out: &mut [f64]) {
        match self {
            Kind::Displacement => {
                for (p, row) in particles.iter().zip(out.chunks_exact_mut(D)) {
                    row.copy_from_slice(p.position_at(t).as_slice());
                }
            }
            Kind::Velocity => {
                for (p, row) in particles.iter().zip(out.chunks_exact_mut(2 * D)) {
                    row[..D].copy_from_slice(p.velocity.as_slice());
                    row[D..].copy_from_slice(p.position_at(t).as_slice());
                }
            }
        }
    }
}

/// Sums channels over particles.
pub const CHANNELS: usize = 2;

/// The multiple-tau correlator (see the module documentation).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Correlator {
    /// What it correlates.
    pub kind: Kind,
    /// The dimension.
    pub dimension: usize,
    /// Time between samples.
    pub every: f64,
    /// Levels at most.
    pub levels: usize,
    /// Each particle's species.
    pub species: Vec<u32>,
    /// Particles per species.
    pub counts: Vec<u64>,
    /// Samples received at each level so far.
    pub received: Vec<u64>,
    /// Per level: the last [`POINTS`] samples, slot `k mod POINTS` for its `k`-th, each a
    /// row per particle.
    pub rings: Vec<Vec<f64>>,
    /// Level-0 samples per block.
    pub block_length: u64,
    /// Per block: sums, indexed `(lag · species + s) · CHANNELS + c`.
    pub sums: Vec<Vec<f64>>,
    /// Per block: time origins per lag.
    pub origins: Vec<Vec<u64>>,
}

/// One lag's value per species and channel, with errors.
#[derive(Clone, Debug, PartialEq)]
pub struct Lag {
    /// The lag.
    pub tau: f64,
    /// Time origins averaged over.
    pub origins: u64,
    /// Per species, per channel: mean over particles and origins, and its error.
    pub values: Vec<[(f64, f64); CHANNELS]>,
}

impl Correlator {
    /// A correlator of `particles` sampled every `every` up to lags of `max_lag`.
    pub fn new<const D: usize>(kind: Kind, particles: &[Particle<D>], every: f64, max_lag: f64) -> Correlator {
        let species: Vec<u32> = particles.iter().map(|p| p.species).collect();
        let mut counts = vec![0u64; species.iter().map(|&s| s as usize + 1).max().unwrap_or(0)];
        for &s in &species {
            counts[s as usize] += 1;
        }
        let levels = levels(every, max_lag);
        Correlator {
            kind,
            dimension: D,
            every,
            levels,
            species,
            counts,
            received: Vec::new(),
            rings: Vec::new(),
            block_length: 1,
            sums: Vec::new(),
            origins: Vec::new(),
        }
    }

    /// The lags' count: 8 at level 0, 4 at each level above.
    pub fn lag_count(&self) -> usize {
        POINTS + (self.levels - 1) * (POINTS / 2)
    }

    /// Lag `k`'s level and its distance in that level's samples.
    fn lag(k: usize) -> (usize, usize) {
        if k < POINTS { (0, k) } else { (1 + (k - POINTS) / (POINTS / 2), POINTS / 2 + (k - POINTS) % (POINTS / 2)) }
    }

    /// Lag `k` in time.
    pub fn tau(&self, k: usize) -> f64 {
        let (level, j) = Self::lag(k);
        (j << level) as f64 * self.every
    }

    /// Level-0 samples taken.
    pub fn samples(&self) -> u64 {
        self.received.first().copied().unwrap_or(0)
    }

    /// Takes the sample of `particles` at `t` (each in free flight from its last update to
    /// `t`).
    pub fn sample<const D: usize>(&mut self, particles: &[Particle<D>], t: f64) {
        let len = particles.len() * self.kind.width(D);
        let block = self.block();
        let mut level = 0;
        loop {
            if self.rings.len() == level {
                self.rings.push(vec![0.0; POINTS * len]);
                self.received.push(0);
            }
            let n = self.received[level];
            let slot = (n % POINTS as u64) as usize;
            if level == 0 {
                self.kind.rows(particles, t, &mut self.rings[0][slot * len..(slot + 1) * len]);
            } else {
                // The sample the level below took last, its slot (n_below − 1) mod POINTS.
                let below = ((self.received[level - 1] - 1) % POINTS as u64) as usize;
                let (lower, upper) = self.rings.split_at_mut(level);
                upper[0][slot * len..(slot + 1) * len]
                    .copy_from_slice(&lower[level - 1][below * len..(below + 1) * len]);
            }
            // The lags this sample closes, (lag index, slot of the older sample).
            let first = if level == 0 { 0 } else { POINTS / 2 };
            let lags: Vec<(usize, usize)> = (first..POINTS)
                .take_while(|&j| j as u64 <= n)
                .map(|j| {
                    let k = if level == 0 { j } else { POINTS + (level - 1) * (POINTS / 2) + (j - POINTS / 2) };
                    (k, ((n - j as u64) % POINTS as u64) as usize)
                })
                .collect();
            let species = self.counts.len();
            correlate::<D>(
                self.kind,
                &self.rings[level],
                len,
                slot,
                &lags,
                &self.species,
                species,
                &mut self.sums[block],
            );
            for &(k, _) in &lags {
                self.origins[block][k] += 1;
            }
            self.received[level] += 1;
            if n % 2 != 0 || level + 1 == self.levels {
                break;
            }
            level += 1;
        }
    }

    /// The block the next sample's sums go to, merging pairs of blocks when they are full.
    fn block(&mut self) -> usize {
        let mut block = (self.samples() / self.block_length) as usize;
        if block == BLOCKS {
            for b in 0..BLOCKS / 2 {
                let (a, c) = (2 * b, 2 * b + 1);
                let sums: Vec<f64> = self.sums[a].iter().zip(&self.sums[c]).map(|(x, y)| x + y).collect();
                let origins: Vec<u64> = self.origins[a].iter().zip(&self.origins[c]).map(|(x, y)| x + y).collect();
                self.sums[b] = sums;
                self.origins[b] = origins;
            }
            self.sums.truncate(BLOCKS / 2);
            self.origins.truncate(BLOCKS / 2);
            self.block_length *= 2;
            block = BLOCKS / 2;
        }
        if self.sums.len() == block {
            let lags = self.lag_count();
            self.sums.push(vec![0.0; lags * self.counts.len() * CHANNELS]);
            self.origins.push(vec![0; lags]);
        }
        block
    }

    /// Every lag with at least one origin: its values and jackknife errors.
    pub fn lags(&self) -> Vec<Lag> {
        (0..self.lag_count())
            .filter(|&k| self.origins.iter().any(|o| o[k] > 0))
            .map(|k| {
                let values = (0..self.counts.len())
                    .map(|s| std::array::from_fn(|c| self.estimate(|mean| mean(k, s, c))))
                    .collect();
                Lag { tau: self.tau(k), origins: self.origins.iter().map(|o| o[k]).sum(), values }
            })
            .collect()
    }

    /// A quantity `f` of the means (`mean(lag, species, channel)`), over all blocks, and its
    /// delete-one-block jackknife error (NaN with fewer than two blocks holding its lags).
    pub fn estimate(&self, f: impl Fn(&dyn Fn(usize, usize, usize) -> f64) -> f64) -> (f64, f64) {
        self.estimate_with(self, |m, _| f(m))
    }

    /// A quantity `f` of the means of this correlator and of `other`, which took its samples
    /// at the same instants (so that their blocks hold the same stretches of the run), and
    /// its delete-one-block jackknife error: the error of a difference between the MSD and
    /// the VACF, say, with their correlation accounted for.
    pub fn estimate_with(
        &self,
        other: &Correlator,
        f: impl Fn(&dyn Fn(usize, usize, usize) -> f64, &dyn Fn(usize, usize, usize) -> f64) -> f64,
    ) -> (f64, f64) {
        fn mean_without(of: &Correlator, skip: Option<usize>) -> impl Fn(usize, usize, usize) -> f64 + '_ {
            let species = of.counts.len();
            move |k: usize, s: usize, c: usize| {
                let (mut sum, mut origins) = (0.0, 0u64);
                for b in 0..of.sums.len() {
                    if Some(b) != skip {
                        sum += of.sums[b][(k * species + s) * CHANNELS + c];
                        origins += of.origins[b][k];
                    }
                }
                sum / (origins as f64 * of.counts[s] as f64)
            }
        }
        let blocks = if self.block_length == other.block_length { self.sums.len().min(other.sums.len()) } else { 0 };
        let all = f(&mean_without(self, None), &mean_without(other, None));
        let partial: Vec<f64> = (0..blocks)
            .map(|b| f(&mean_without(self, Some(b)), &mean_without(other, Some(b))))
            .filter(|x| x.is_finite())
            .collect();
        (all, super::blocks::jackknife_error(&partial))
    }

    /// The lag index of the longest lag a value is read at: averaged over at least `origins`
    /// origins, and no longer than a block (`block_length · every`), so that the blocks of
    /// its jackknife are nearly independent (None: no lag is).
    pub fn longest_lag(&self, origins: u64) -> Option<usize> {
        let block = self.block_length as f64 * self.every;
        (1..self.lag_count())
            .rev()
            .find(|&k| self.tau(k) <= block && self.origins.iter().map(|o| o[k]).sum::<u64>() >= origins)
    }
}

/// The levels that reach lags of `max_lag` with samples `every` apart: until the longest
/// lag, `7·2^(L−1)·every`, reaches `max_lag`.
fn levels(every: f64, max_lag: f64) -> usize {
    let mut levels = 1;
    while levels < MAX_LEVELS && (POINTS - 1) as f64 * 2f64.powi(levels as i32 - 1) * every < max_lag {
        levels += 1;
    }
    levels
}

/// The bytes a correlator of `kind` stores per particle in `d` dimensions, sampling every
/// `every` up to lags of `max_lag`: [`POINTS`] rows a level (and as much again in a
/// checkpoint's text, about 20 bytes a number).
pub fn bytes_per_particle(kind: Kind, d: usize, every: f64, max_lag: f64) -> f64 {
    (levels(every, max_lag) * POINTS * kind.width(d) * size_of::<f64>()) as f64
}

/// Adds, per particle, the channels of each lag's older sample (`lags`: lag index and slot)
/// against the new one (slot `new`) of `ring` (slots of `len` numbers) to the lag's sums of
/// the particle's species (`sums[(k·species + s)·CHANNELS + c]`). One pass over the
/// particles for all the lags: the new rows are read once.
#[allow(clippy::too_many_arguments)]
#[inline]
fn correlate<const D: usize>(
    kind: Kind,
    ring: &[f64],
    len: usize,
    new: usize,
    lags: &[(usize, usize)],
    species: &[u32],
    kinds: usize,
    sums: &mut [f64],
) {
    let width = kind.width(D);
    let channels = |x: &[f64], y: &[f64]| -> [f64; CHANNELS] {
        match kind {
            Kind::Displacement => {
                let r2: f64 = (0..D).map(|a| (y[a] - x[a]) * (y[a] - x[a])).sum();
                [r2, r2 * r2]
            }
            Kind::Velocity => {
                let vv: f64 = (0..D).map(|a| x[a] * y[a]).sum();
                let vr: f64 = (0..D).map(|a| x[a] * (y[D + a] - x[D + a])).sum();
                [vv, vr]
            }
        }
    };
    let row = |slot: usize, i: usize| &ring[slot * len + i * width..slot * len + (i + 1) * width];
    if kinds == 1 {
        // One species: the sums of every lag in registers.
        let mut acc = [[0.0; CHANNELS]; POINTS];
        for i in 0..len / width {
            let y = row(new, i);
            for (q, &(_, slot)) in lags.iter().enumerate() {
                let c = channels(row(slot, i), y);
                acc[q][0] += c[0];
                acc[q][1] += c[1];
            }
        }
        for (q, &(k, _)) in lags.iter().enumerate() {
            sums[k * CHANNELS] += acc[q][0];
            sums[k * CHANNELS + 1] += acc[q][1];
        }
    } else {
        for i in 0..len / width {
            let y = row(new, i);
            let s = species[i] as usize;
            for &(k, slot) in lags {
                let c = channels(row(slot, i), y);
                let at = (k * kinds + s) * CHANNELS;
                sums[at] += c[0];
                sums[at + 1] += c[1];
            }
        }
    }
}

/// The mean free time `1/Γ`, Γ Enskog's collision rate per particle
/// ([`enskog_rate`](crate::theory::enskog_rate)) at the particles' number density and packing
/// fraction (the contact value from the equation of state of the dimension,
/// [`contact_value`](crate::theory::contact_value)), the largest contact distance, their kT
/// and mean mass: the time between the samples of the MSD and the VACF by default. 1 for
/// particles at rest.
pub fn mean_free_time<const D: usize>(particles: &[Particle<D>], sim_box: &SimBox<D>) -> f64 {
    let n = particles.len() as f64;
    let volume = sim_box.volume();
    let sigma = particles.iter().map(|p| 2.0 * p.radius).fold(0.0, f64::max);
    let eta: f64 = particles.iter().map(|p| crate::engine::init::ball_volume::<D>(p.radius)).sum::<f64>() / volume;
    let kinetic: f64 = particles.iter().map(|p| 0.5 * p.mass * p.velocity.norm_squared()).sum();
    let kt = 2.0 * kinetic / (D as f64 * n);
    let mass = particles.iter().map(|p| p.mass).sum::<f64>() / n;
    let g = crate::theory::contact_value(D, eta.min(0.7));
    let time = 1.0 / crate::theory::enskog_rate(D, n / volume, sigma, g, kt, mass);
    if time.is_finite() && time > 0.0 { time } else { 1.0 }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::SVector;
    use rand::{RngExt, SeedableRng};

    fn particle(x: [f64; 2], v: [f64; 2], species: u32) -> Particle<2> {
        Particle {
            position: SVector::from(x),
            velocity: SVector::from(v),
            time: 0.0,
            radius: 0.5,
            mass: 1.0,
            species,
            events: 0,
        }
    }

    /// Every lag's mean against the direct average over all origins it should hold (random
    /// walks; level l uses the samples at multiples of 2^l as origins), errors finite, and the
    /// block merging keeping the totals.
    #[test]
    fn lags_average_exactly_the_origins_of_their_level() {
        let mut rng = rand::rngs::StdRng::seed_from_u64(7);
        let n = 5;
        let steps = 300;
        // x[t][i]: positions; velocities random too.
        let mut x = vec![vec![[0.0f64; 2]; n]];
        let v: Vec<Vec<[f64; 2]>> =
            (0..=steps).map(|_| (0..n).map(|_| [rng.random(), rng.random()]).collect()).collect();
        for t in 1..=steps {
            let prev = x[t - 1].clone();
            x.push(prev.iter().map(|p| [p[0] + rng.random::<f64>() - 0.5, p[1] + rng.random::<f64>() - 0.5]).collect());
        }
        let particles: Vec<Particle<2>> = (0..n).map(|i| particle(x[0][i], v[0][i], (i % 2) as u32)).collect();
        let mut msd = Correlator::new(Kind::Displacement, &particles, 1.0, 1000.0);
        let mut vacf = Correlator::new(Kind::Velocity, &particles, 1.0, 1000.0);
        for t in 0..=steps {
            let now: Vec<Particle<2>> = (0..n).map(|i| particle(x[t][i], v[t][i], (i % 2) as u32)).collect();
            msd.sample(&now, 0.0);
            vacf.sample(&now, 0.0);
        }
        assert!(msd.block_length > 1, "the blocks were merged");
        for (c, lags) in [(&msd, msd.lags()), (&vacf, vacf.lags())] {
            for (k, lag) in lags.iter().enumerate() {
                let (level, j) = Correlator::lag(k);
                let step = 1usize << level;
                let d = j * step;
                assert_eq!(lag.tau, d as f64);
                for s in 0..2 {
                    let (mut sum, mut count) = (0.0, 0.0);
                    for t0 in (0..=steps - d).step_by(step) {
                        for i in (0..n).filter(|i| i % 2 == s) {
                            let (a, b) = (x[t0][i], x[t0 + d][i]);
                            let f = match c.kind {
                                Kind::Displacement => (b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2),
                                Kind::Velocity => v[t0][i][0] * v[t0 + d][i][0] + v[t0][i][1] * v[t0 + d][i][1],
                            };
                            sum += f;
                            count += 1.0;
                        }
                    }
                    let got = lag.values[s][0].0;
                    assert!(
                        (got - sum / count).abs() <= 1e-12 * sum.abs() / count,
                        "lag {d} species {s}: {got} vs {}",
                        sum / count
                    );
                    assert!(lag.values[s][0].1.is_finite());
                }
            }
        }
    }

    /// The levels end at the first lag reaching max_lag.
    #[test]
    fn levels_reach_max_lag() {
        let particles = vec![particle([0.0; 2], [1.0, 0.0], 0)];
        let c = Correlator::new(Kind::Velocity, &particles, 0.5, 100.0);
        let last = c.tau(c.lag_count() - 1);
        assert!(last >= 100.0 && last / 2.0 < 100.0, "{last}");
    }
}
