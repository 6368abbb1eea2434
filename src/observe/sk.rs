//! The static structure factor `S(k)` of a periodic box, averaged over directions, and its
//! long-wavelength limit.
//!
//! # Estimator
//!
//! Every `every` time units of the production, for wave vectors `k = 2π(n₁/L₁, …, n_d/L_d)`
//! (integers `n`, the only ones the periodic box allows),
//!
//! `S(k) = |Σ_j exp(i k·r_j)|² / N`,
//!
//! all particles counted alike (a mixture's number–number structure factor). The vectors are
//! binned by `|k|` (bins `k_max/bins` wide); a bin holds all its vectors of the half-space
//! (`k` and `−k` give the same `S`), or `vectors` of them evenly spread in `|k|` where it has
//! more (the fluid is isotropic; the shortest vectors, few to a bin, are all kept). A bin's
//! value is the mean over its vectors and the samples, its `k` the mean `|k|` of its vectors.
//! The phases are built per particle from `exp(2πi·x_a/L_a)` by repeated products, one
//! complex product per particle and vector in 2D (two in 3D).
//!
//! # Long-wavelength limit
//!
//! `S(0) = kT·(∂n/∂P)_T` — the compressibility route (in a box of fixed `N`, approached as
//! `k → 0` but never at 0). It is extrapolated by least squares (faer's QR) of
//! `S = a + b·k² + c·k⁴` over the bins with `k ≤` [`FIT_K`]`/σ` (`σ` the largest contact
//! distance), applied to every sample so that the error is a block average's (20 blocks), as
//! for g(r)'s contact value.
//!
//! # Options and output
//!
//! `[observe.sk]`, periodic boxes only: `k_max` (default [`K_MAX`]`/σ`, past the first
//! peak and its minimum), `bins` (default [`BINS`]), `vectors` (per bin at most, default [`VECTORS`]),
//! `every` (default [`IDEAL_TIMES`] ideal-gas collision times, as g(r)'s
//! [`default_every`](super::rdf::default_every)). `sk.csv`: `k`, `vectors`, `s`; `summary.json`:
//! the options, the samples and `S(0)` with its error.

use super::Observer;
use crate::engine::{Boundary, Outcome, Particle, SimBox, Simulation};
use serde::{Deserialize, Serialize};
use std::f64::consts::TAU;

/// What the observable is asked for.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Options {
    /// The largest `|k|`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub k_max: Option<f64>,
    /// The number of bins.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bins: Option<usize>,
    /// Wave vectors per bin at most.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub vectors: Option<usize>,
    /// Time between samples.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub every: Option<f64>,
}

/// Default `k_max`, over the largest contact distance.
pub const K_MAX: f64 = 12.0;
/// Default bins.
pub const BINS: usize = 60;
/// Default wave vectors per bin at most.
pub const VECTORS: usize = 12;
/// The fit of `S(0)` uses the bins with `k ≤ FIT_K/σ`.
pub const FIT_K: f64 = 2.5;
/// Default time between samples, in ideal-gas collision times.
pub const IDEAL_TIMES: f64 = 40.0;
/// Blocks of the `S(0)` error.
const BLOCKS: usize = 20;

impl Options {
    /// Checks the options (`[observe.sk]`) for a box `periodic` along every axis or not.
    pub fn check(&self, periodic: bool) -> Result<(), super::Refusal> {
        if !periodic {
            return Err((
                "observe.sk".into(),
                "asked for".into(),
                "S(k) needs a periodic box (box.boundary = \"periodic\" on every axis): walls allow no plane waves"
                    .into(),
            ));
        }
        super::positive("sk", "k_max", self.k_max, "wave number")?;
        super::count_within("sk", "bins", self.bins, 100_000)?;
        super::count_within("sk", "vectors", self.vectors, 100_000)?;
        super::positive("sk", "every", self.every, "time")
    }
}

/// The S(k) observable (see the module documentation).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Sk {
    /// The dimension.
    pub dimension: usize,
    /// What was asked for.
    pub options: Options,
    /// The largest `|k|`.
    pub k_max: f64,
    /// Bins.
    pub bins: usize,
    /// Time between samples.
    pub every: f64,
    /// The next sampling instant.
    pub next: f64,
    /// Samples taken.
    pub samples: u64,
    /// The box lengths.
    pub lengths: Vec<f64>,
    /// The wave vectors (integers `n`), bin by bin.
    pub vectors: Vec<Vec<i64>>,
    /// Each vector's bin.
    pub bin_of: Vec<usize>,
    /// Vectors per bin.
    pub counts: Vec<usize>,
    /// Per bin: the sum over samples of the bin's mean `S`.
    pub sums: Vec<f64>,
    /// The weights of the bins' `S` in `S(0)` (empty: too few bins below the fit's end).
    pub weights: Vec<f64>,
    /// Per sample, its `S(0)`.
    pub s0_samples: Vec<f64>,
}

/// What `summary.json` holds of it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Results {
    /// The largest `|k|`.
    pub k_max: f64,
    /// Bins.
    pub bins: usize,
    /// Time between samples.
    pub every: f64,
    /// Samples taken.
    pub samples: u64,
    /// `S(k → 0)`.
    pub s0: f64,
    /// Its standard error.
    pub s0_error: f64,
}

impl Sk {
    /// Starts observing `sim`: the first sample at `now + every`.
    pub fn new<const D: usize>(sim: &Simulation<D>, options: Options) -> Sk {
        Sk::of(sim.particles(), sim.sim_box(), sim.time(), options)
    }

    /// Starts observing `particles` in `sim_box` (periodic along every axis) at `now`.
    pub fn of<const D: usize>(particles: &[Particle<D>], sim_box: &SimBox<D>, now: f64, options: Options) -> Sk {
        debug_assert!(sim_box.boundary.iter().all(|b| *b == Boundary::Periodic));
        let sigma = particles.iter().map(|p| 2.0 * p.radius).fold(0.0, f64::max);
        let k_max = options.k_max.unwrap_or(K_MAX / sigma);
        let bins = options.bins.unwrap_or(BINS);
        let most = options.vectors.unwrap_or(VECTORS);
        let every = options.every.unwrap_or_else(|| {
            super::rdf::default_every(particles, sim_box, sigma) / super::rdf::IDEAL_TIMES[D.min(3) - 2] * IDEAL_TIMES
        });
        let lengths: Vec<f64> = sim_box.lengths.iter().copied().collect();
        // Every vector of the half-space (first nonzero component positive) within k_max.
        let reach: Vec<i64> = lengths.iter().map(|l| (k_max * l / TAU).floor() as i64).collect();
        let mut all: Vec<(f64, Vec<i64>)> = Vec::new();
        let mut n = vec![0i64; D];
        let mut walk = |n: &[i64]| {
            let first = n.iter().find(|&&x| x != 0);
            if first.is_some_and(|&x| x > 0) {
                let k = n.iter().zip(&lengths).map(|(&x, l)| (TAU * x as f64 / l).powi(2)).sum::<f64>().sqrt();
                if k < k_max {
                    all.push((k, n.to_vec()));
                }
            }
        };
        loop {
            walk(&n);
            // The next integer vector in [−reach, reach]^D.
            let mut a = 0;
            loop {
                if a == D {
                    break;
                }
                if n[a] < reach[a] {
                    n[a] += 1;
                    break;
                }
                n[a] = -reach[a];
                a += 1;
            }
            if a == D {
                break;
            }
        }
        all.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
        let width = k_max / bins as f64;
        let mut vectors = Vec::new();
        let mut bin_of = Vec::new();
        let mut counts = vec![0; bins];
        let mut start = 0;
        while start < all.len() {
            let bin = ((all[start].0 / width) as usize).min(bins - 1);
            let end = start + all[start..].iter().take_while(|v| ((v.0 / width) as usize).min(bins - 1) == bin).count();
            let here = end - start;
            let take = here.min(most);
            for i in 0..take {
                // Evenly spread over the bin's vectors, sorted by |k|.
                let pick = start + (i * here) / take;
                vectors.push(all[pick].1.clone());
                bin_of.push(bin);
            }
            counts[bin] = take;
            start = end;
        }
        let mut sk = Sk {
            dimension: D,
            options,
            k_max,
            bins,
            every,
            next: now + every,
            samples: 0,
            lengths,
            vectors,
            bin_of,
            counts,
            sums: vec![0.0; bins],
            weights: Vec::new(),
            s0_samples: Vec::new(),
        };
        sk.weights = sk.fit_weights(FIT_K / sigma);
        sk
    }

    /// The mean `|k|` of bin `b`'s vectors.
    fn k_of(&self, b: usize) -> f64 {
        let (mut sum, mut n) = (0.0, 0.0);
        for (v, &bin) in self.vectors.iter().zip(&self.bin_of) {
            if bin == b {
                sum += self.k(v);
                n += 1.0;
            }
        }
        sum / n
    }

    /// `|k|` of the integer vector `v`.
    fn k(&self, v: &[i64]) -> f64 {
        v.iter().zip(&self.lengths).map(|(&x, l)| (TAU * x as f64 / l).powi(2)).sum::<f64>().sqrt()
    }

    /// The weights that turn the bins' `S` into `S(0)`: the constant of `a + b·k² + c·k⁴`
    /// fitted to the bins (with vectors) whose `k ≤ end` (none with fewer than 4 such bins).
    fn fit_weights(&self, end: f64) -> Vec<f64> {
        use faer::linalg::solvers::SolveLstsq;
        let used: Vec<(usize, f64)> = (0..self.bins)
            .filter(|&b| self.counts[b] > 0)
            .map(|b| (b, self.k_of(b)))
            .filter(|&(_, k)| k <= end)
            .collect();
        if used.len() < 4 {
            return Vec::new();
        }
        let n = used.len();
        let x = faer::Mat::<f64>::from_fn(n, 3, |i, j| (used[i].1 / end).powi(2 * j as i32));
        let identity = faer::Mat::<f64>::from_fn(n, n, |i, j| if i == j { 1.0 } else { 0.0 });
        let fitted = x.qr().solve_lstsq(&identity);
        let mut weights = vec![0.0; self.bins];
        for (j, &(b, _)) in used.iter().enumerate() {
            weights[b] = fitted[(0, j)];
        }
        weights
    }

    /// The next sampling instant.
    pub fn due(&self) -> f64 {
        self.next
    }

    /// Samples `particles` at `t` (each in free flight to `t`) and schedules the next.
    pub fn sample<const D: usize>(&mut self, particles: &[Particle<D>], t: f64) {
        let reach: [usize; D] =
            std::array::from_fn(|a| self.vectors.iter().map(|v| v[a].unsigned_abs() as usize).max().unwrap_or(0));
        let mut re = vec![0.0; self.vectors.len()];
        let mut im = vec![0.0; self.vectors.len()];
        // Per axis, exp(2πi·m·x/L) for m = 0 ..= reach.
        let mut powers: [Vec<(f64, f64)>; D] = std::array::from_fn(|a| vec![(1.0, 0.0); reach[a] + 1]);
        // Per vector: its powers' indices and whether each is conjugated.
        let terms: Vec<[(usize, f64); D]> = self
            .vectors
            .iter()
            .map(|v| std::array::from_fn(|a| (v[a].unsigned_abs() as usize, if v[a] < 0 { -1.0 } else { 1.0 })))
            .collect();
        for p in particles {
            let r = p.position_at(t);
            for a in 0..D {
                let (s, c) = (TAU * r[a] / self.lengths[a]).sin_cos();
                let table = &mut powers[a];
                for m in 1..table.len() {
                    let (x, y) = table[m - 1];
                    table[m] = (x * c - y * s, x * s + y * c);
                }
            }
            for (q, term) in terms.iter().enumerate() {
                let (mut x, mut y) = (1.0, 0.0);
                for a in 0..D {
                    let (u, w) = powers[a][term[a].0];
                    let w = term[a].1 * w;
                    (x, y) = (x * u - y * w, x * w + y * u);
                }
                re[q] += x;
                im[q] += y;
            }
        }
        let n = particles.len() as f64;
        let mut bins = vec![0.0; self.bins];
        for (q, &b) in self.bin_of.iter().enumerate() {
            bins[b] += (re[q] * re[q] + im[q] * im[q]) / n / self.counts[b] as f64;
        }
        for (sum, s) in self.sums.iter_mut().zip(&bins) {
            *sum += s;
        }
        if !self.weights.is_empty() {
            self.s0_samples.push(self.weights.iter().zip(&bins).map(|(w, s)| w * s).sum());
        }
        self.samples += 1;
        self.next = t + self.every;
    }

    /// Per bin with vectors: `(k, vectors, S)`.
    pub fn curve(&self) -> Vec<(f64, usize, f64)> {
        (0..self.bins)
            .filter(|&b| self.counts[b] > 0)
            .map(|b| (self.k_of(b), self.counts[b], self.sums[b] / self.samples as f64))
            .collect()
    }

    /// What `summary.json` holds.
    pub fn results(&self) -> Results {
        let (s0, s0_error) = if self.s0_samples.is_empty() {
            (f64::NAN, f64::NAN)
        } else {
            super::block_error(&self.s0_samples, BLOCKS)
        };
        Results { k_max: self.k_max, bins: self.bins, every: self.every, samples: self.samples, s0, s0_error }
    }

    /// `sk.csv`: `k`, `vectors`, `s`.
    pub fn csv(&self) -> String {
        let mut text = String::from("k,vectors,s\n");
        for (k, n, s) in self.curve() {
            text += &format!("{k},{n},{s}\n");
        }
        text
    }
}

impl<const D: usize> Observer<D> for Sk {
    /// Nothing per event: it samples at its own instants.
    fn observe(&mut self, _: &Simulation<D>, _: &Outcome<D>) {}
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::SVector;
    use rand::{RngExt, SeedableRng};

    /// An ideal gas (uniform random points) has S(k) = 1 at every k (each vector's `S` is
    /// exponentially distributed with mean 1): bin by bin within 4.5 standard errors, and
    /// S(0) = 1 within 4.5 of its error; a lattice gives S = 0 off its reciprocal lattice
    /// (the phases are exact: a wrong sign or power fails it).
    #[test]
    fn an_ideal_gas_has_s_equal_to_one_and_a_lattice_zero() {
        fn points<const D: usize>(seed: u64, n: usize, l: f64) -> Vec<Particle<D>> {
            let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
            (0..n)
                .map(|_| super::super::test_particle(std::array::from_fn(|_| rng.random::<f64>() * l), [0.0; D]))
                .collect()
        }
        fn check<const D: usize>(l: f64) {
            let sim_box = SimBox { lengths: SVector::from([l; D]), boundary: [Boundary::Periodic; D] };
            let options = Options { k_max: Some(8.0), bins: Some(40), vectors: Some(12), every: Some(1.0) };
            let mut sk = Sk::of(&points::<D>(0, 300, l), &sim_box, 0.0, options.clone());
            let samples = 200;
            for s in 0..samples {
                sk.sample(&points::<D>(s + 1, 300, l), 0.0);
            }
            for (k, vectors, s) in sk.curve() {
                let error = 1.0 / ((vectors * samples as usize) as f64).sqrt();
                assert!((s - 1.0).abs() < 4.5 * error, "{D}D k = {k}: S = {s} ± {error}");
            }
            let r = sk.results();
            assert!((r.s0 - 1.0).abs() < 4.5 * r.s0_error && r.s0_error < 0.2, "{D}D S(0) = {} ± {}", r.s0, r.s0_error);
            // A square (cubic) lattice of spacing 1: S = 0 at every k that is not a
            // multiple of 2π on every axis (k_max = 6 < 2π: all of them).
            let m = l as usize;
            let lattice: Vec<Particle<D>> = (0..m.pow(D as u32))
                .map(|i| {
                    let mut p = points::<D>(0, 1, l).remove(0);
                    p.position = SVector::from(std::array::from_fn(|a| ((i / m.pow(a as u32)) % m) as f64 + 0.25));
                    p
                })
                .collect();
            let mut sk = Sk::of(&lattice, &sim_box, 0.0, Options { k_max: Some(6.0), ..options });
            sk.sample(&lattice, 0.0);
            assert!(sk.curve().iter().all(|&(_, _, s)| s < 1e-20), "{D}D lattice");
        }
        check::<2>(12.0);
        check::<3>(6.0);
    }
}
