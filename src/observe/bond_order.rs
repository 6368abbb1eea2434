//! Bond-orientational order along a run: the hexatic order `Ψ₆` of disks and its correlation
//! `g₆(r)`, Steinhardt's `Q₆` of spheres.
//!
//! # Estimators
//!
//! Every `every` time units of the production, two particles are *bonded* when closer than
//! `cutoff` times their contact distance (default [`CUTOFF`] = 1.4: the first minimum of a
//! dense fluid's g(r), so that a particle of the fluid or of the crystal near melting has its
//! six-or-so nearest neighbours). With `b̂` a bond's unit vector (minimum image):
//!
//! * **disks**: each particle's `ψ₆,j = (1/n_j) Σ_k exp(6iθ_jk)` over its `n_j` bonds (0
//!   without one), θ the bond's angle to the x axis; the sample's global order
//!   `Ψ₆ = |(1/N) Σ_j ψ₆,j|` (Bernard & Krauth, PRL 107, 155704 (2011)), and the
//!   correlation `g₆(r) = Σ Re(ψ₆,j ψ₆,k*) / Σ 1` over the pairs `j < k` at distance `r`
//!   (bins `r_max/bins` wide), accumulated over the samples: about `|Ψ₆|²` at large `r` in a
//!   crystal, algebraic decay (exponent ≤ 1/4) in the hexatic phase, exponential in the
//!   liquid;
//! * **spheres**: `Q₆² = (4π/13) Σ_m |(1/B) Σ_b Y₆ₘ(b̂)|²` over the sample's `B` bonds
//!   (Steinhardt, Nelson & Ronchetti, PRB 28, 784 (1983)), with the associated Legendre
//!   functions `P₆ᵐ` written out: 0.5745 for fcc, about `1/√B` for a fluid — the same number
//!   as [`order::bond_order`](super::order::bond_order) gives by the addition theorem.
//!
//! The mean over samples and its 20-block error are reported, with the susceptibility
//! `χ = N(⟨Ψ²⟩ − ⟨Ψ⟩²)` of the order's fluctuations.
//!
//! # Options and output
//!
//! `[observe.bond_order]`: `cutoff` (in contact distances, default [`CUTOFF`]), `r_max`
//! (disks' `g₆`: default the smaller of [`REACH`] largest contact distances and half the
//! shortest periodic length), `bins` (default [`BINS`]), `every` (default [`SPARSER`] times g(r)'s,
//! [`default_every`](super::rdf::default_every)). `bond_order.csv`: `t` and `psi6` (disks) or
//! `q6` (spheres), one row per sample; `g6.csv` (disks): `r`, `pairs`, `g6`.

use super::Observer;
use super::rdf::for_pairs_within;
use crate::engine::{Boundary, Outcome, Particle, SimBox, Simulation};
use nalgebra::SVector;
use serde::{Deserialize, Serialize};

/// Default bond cutoff, in contact distances.
pub const CUTOFF: f64 = 1.4;
/// Default `r_max` of `g₆`, in largest contact distances.
pub const REACH: f64 = 10.0;
/// Default bins of `g₆`.
pub const BINS: usize = 200;
/// Default samples are this many times sparser than g(r)'s: a sample walks the pairs within
/// `r_max` (twice g(r)'s reach) besides the bonds, and at g(r)'s rate took a fifth of the
/// engine's time (10⁴ disks, η = 0.3; `cargo bench --bench observers`).
pub const SPARSER: f64 = 4.0;
/// Blocks of the errors.
const BLOCKS: usize = 20;

/// What the observable is asked for.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Options {
    /// The bond cutoff, in contact distances.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cutoff: Option<f64>,
    /// The largest distance of `g₆`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub r_max: Option<f64>,
    /// Bins of `g₆`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bins: Option<usize>,
    /// Time between samples.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub every: Option<f64>,
}

impl Options {
    /// Checks the options (`[observe.bond_order]`): the key, its value and what is allowed.
    pub fn check(&self) -> Result<(), super::Refusal> {
        if let Some(c) = self.cutoff
            && !(c.is_finite() && (1.0..=3.0).contains(&c))
        {
            return Err((
                "observe.bond_order.cutoff".into(),
                c.to_string(),
                "must lie in [1, 3] contact distances".into(),
            ));
        }
        super::positive("bond_order", "r_max", self.r_max, "length")?;
        super::count_within("bond_order", "bins", self.bins, 1_000_000)?;
        super::positive("bond_order", "every", self.every, "time")
    }
}

/// The bond-order observable (see the module documentation).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BondOrder {
    /// The dimension.
    pub dimension: usize,
    /// The particles.
    pub particles: usize,
    /// What was asked for.
    pub options: Options,
    /// The bond cutoff, in contact distances.
    pub cutoff: f64,
    /// The largest distance of `g₆`.
    pub r_max: f64,
    /// Bins of `g₆`.
    pub bins: usize,
    /// Time between samples.
    pub every: f64,
    /// The next sampling instant.
    pub next: f64,
    /// Each sample's time and order (`Ψ₆` or `Q₆`).
    pub series: Vec<[f64; 2]>,
    /// Disks: per bin, `Σ Re(ψ₆,j ψ₆,k*)` over pairs and samples.
    pub g6_sums: Vec<f64>,
    /// Disks: per bin, the pairs counted.
    pub g6_pairs: Vec<u64>,
}

/// What `summary.json` holds of it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Results {
    /// `"psi6"` (disks) or `"q6"` (spheres).
    pub parameter: &'static str,
    /// The bond cutoff, in contact distances.
    pub cutoff: f64,
    /// Time between samples.
    pub every: f64,
    /// Samples taken.
    pub samples: usize,
    /// The mean order.
    pub value: f64,
    /// Its standard error.
    pub error: f64,
    /// `N(⟨X²⟩ − ⟨X⟩²)`.
    pub susceptibility: f64,
}

impl BondOrder {
    /// Starts observing `sim`: the first sample at `now + every`.
    pub fn new<const D: usize>(sim: &Simulation<D>, options: Options) -> BondOrder {
        BondOrder::of(sim.particles(), sim.sim_box(), sim.time(), options)
    }

    /// Starts observing `particles` in `sim_box` at `now`.
    pub fn of<const D: usize>(particles: &[Particle<D>], sim_box: &SimBox<D>, now: f64, options: Options) -> BondOrder {
        let largest = particles.iter().map(|p| 2.0 * p.radius).fold(0.0, f64::max);
        let half = (0..D)
            .filter(|&a| sim_box.boundary[a] == Boundary::Periodic)
            .map(|a| 0.5 * sim_box.lengths[a])
            .fold(f64::INFINITY, f64::min);
        let r_max = options.r_max.unwrap_or(REACH * largest).min(half).min(sim_box.lengths.norm());
        let bins = options.bins.unwrap_or(BINS);
        let every = options.every.unwrap_or_else(|| SPARSER * super::rdf::default_every(particles, sim_box, largest));
        let g6 = if D == 2 { bins } else { 0 };
        BondOrder {
            dimension: D,
            particles: particles.len(),
            cutoff: options.cutoff.unwrap_or(CUTOFF),
            options,
            r_max,
            bins,
            every,
            next: now + every,
            series: Vec::new(),
            g6_sums: vec![0.0; g6],
            g6_pairs: vec![0; g6],
        }
    }

    /// The next sampling instant.
    pub fn due(&self) -> f64 {
        self.next
    }

    /// Samples `particles` in `sim_box` at `t` and schedules the next sample.
    pub fn sample<const D: usize>(&mut self, particles: &[Particle<D>], sim_box: &SimBox<D>, t: f64) {
        let positions: Vec<(u32, SVector<f64, D>)> =
            particles.iter().enumerate().map(|(i, p)| (i as u32, p.position_at(t))).collect();
        let largest = particles.iter().map(|p| 2.0 * p.radius).fold(0.0, f64::max);
        // The bonds: pairs within cutoff·σ_ij (the walk labels each position by its index).
        let mut bonds: Vec<(u32, u32, SVector<f64, D>)> = Vec::new();
        for_pairs_within(&positions, sim_box, self.cutoff * largest, |i, j, r2| {
            let sigma = particles[i as usize].radius + particles[j as usize].radius;
            if r2 < (self.cutoff * sigma).powi(2) {
                let d = positions[j as usize].1 - positions[i as usize].1;
                let d = d + sim_box.minimum_image_shift(&d);
                bonds.push((i, j, d / r2.sqrt()));
            }
        });
        let value = if D == 2 { self.hexatic(particles.len(), &bonds, &positions, sim_box) } else { q6(&bonds) };
        self.series.push([t, value]);
        self.next = t + self.every;
    }

    /// Disks: `Ψ₆` of the sample, and its pairs' `Re(ψ₆,j ψ₆,k*)` into `g₆`.
    fn hexatic<const D: usize>(
        &mut self,
        n: usize,
        bonds: &[(u32, u32, SVector<f64, D>)],
        positions: &[(u32, SVector<f64, D>)],
        sim_box: &SimBox<D>,
    ) -> f64 {
        let mut psi = vec![(0.0f64, 0.0f64); n];
        let mut count = vec![0u32; n];
        for &(i, j, u) in bonds {
            let (s, c) = (6.0 * u[1].atan2(u[0])).sin_cos();
            // The bond seen from j points the other way: θ + π, the same 6θ.
            for k in [i as usize, j as usize] {
                psi[k].0 += c;
                psi[k].1 += s;
                count[k] += 1;
            }
        }
        for (p, &c) in psi.iter_mut().zip(&count) {
            if c > 0 {
                *p = (p.0 / c as f64, p.1 / c as f64);
            }
        }
        let (sx, sy) = psi.iter().fold((0.0, 0.0), |(x, y), p| (x + p.0, y + p.1));
        let scale = self.bins as f64 / self.r_max;
        let (sums, pairs, bins) = (&mut self.g6_sums, &mut self.g6_pairs, self.bins);
        for_pairs_within(positions, sim_box, self.r_max, |i, j, r2| {
            let k = ((r2.sqrt() * scale) as usize).min(bins - 1);
            let (a, b) = (psi[i as usize], psi[j as usize]);
            sums[k] += a.0 * b.0 + a.1 * b.1;
            pairs[k] += 1;
        });
        sx.hypot(sy) / n as f64
    }

    /// What `summary.json` holds.
    pub fn results(&self) -> Results {
        let n = self.particles;
        let values: Vec<f64> = self.series.iter().map(|s| s[1]).collect();
        let (value, error) = if values.is_empty() { (f64::NAN, f64::NAN) } else { super::block_error(&values, BLOCKS) };
        let m = values.len() as f64;
        let mean = values.iter().sum::<f64>() / m;
        let susceptibility = n as f64 * (values.iter().map(|x| x * x).sum::<f64>() / m - mean * mean);
        Results {
            parameter: if self.dimension == 2 { "psi6" } else { "q6" },
            cutoff: self.cutoff,
            every: self.every,
            samples: values.len(),
            value,
            error,
            susceptibility,
        }
    }

    /// `bond_order.csv`: `t` and the order per sample.
    pub fn csv(&self) -> String {
        let mut text = format!("t,{}\n", if self.dimension == 2 { "psi6" } else { "q6" });
        for [t, x] in &self.series {
            text += &format!("{t},{x}\n");
        }
        text
    }

    /// `g6.csv` (disks): `r`, `pairs`, `g6` per bin (NaN where no pair fell).
    pub fn g6_csv(&self) -> String {
        let mut text = String::from("r,pairs,g6\n");
        let dr = self.r_max / self.bins as f64;
        for (k, (s, &n)) in self.g6_sums.iter().zip(&self.g6_pairs).enumerate() {
            text += &format!("{},{n},{}\n", (k as f64 + 0.5) * dr, s / n as f64);
        }
        text
    }
}

/// Steinhardt's `Q₆` of the bonds (0 without one): `Q₆² = (1/B²) Σ_m w_m |Σ_b P₆ᵐ(cos θ_b)
/// e^{imφ_b}|²` over `m = 0 … 6`, `w₀ = 1`, `w_m = 2·(6 − m)!/(6 + m)!` (the `±m` pair and
/// `Y₆ₘ`'s normalisation times 4π/13).
fn q6<const D: usize>(bonds: &[(u32, u32, SVector<f64, D>)]) -> f64 {
    if bonds.is_empty() {
        return 0.0;
    }
    let mut sums = [(0.0f64, 0.0f64); 7];
    for (_, _, u) in bonds {
        let x = u[D - 1];
        let s = (1.0 - x * x).max(0.0).sqrt();
        let (x2, x4) = (x * x, x * x * x * x);
        let p = [
            (231.0 * x4 * x2 - 315.0 * x4 + 105.0 * x2 - 5.0) / 16.0,
            21.0 / 8.0 * x * (33.0 * x4 - 30.0 * x2 + 5.0) * s,
            105.0 / 8.0 * (33.0 * x4 - 18.0 * x2 + 1.0) * s * s,
            315.0 / 2.0 * x * (11.0 * x2 - 3.0) * s.powi(3),
            945.0 / 2.0 * (11.0 * x2 - 1.0) * s.powi(4),
            10395.0 * x * s.powi(5),
            10395.0 * s.powi(6),
        ];
        let phi = u[1].atan2(u[0]);
        for (m, (sum, p)) in sums.iter_mut().zip(p).enumerate() {
            let (sin, cos) = (m as f64 * phi).sin_cos();
            sum.0 += p * cos;
            sum.1 += p * sin;
        }
    }
    let mut total = 0.0;
    let mut ratio = 1.0; // (6 − m)!/(6 + m)!
    for (m, (re, im)) in sums.iter().enumerate() {
        if m > 0 {
            ratio /= ((6 + m) * (7 - m)) as f64;
        }
        let w = if m == 0 { 1.0 } else { 2.0 * ratio };
        total += w * (re * re + im * im);
    }
    total.sqrt() / bonds.len() as f64
}

impl<const D: usize> Observer<D> for BondOrder {
    /// Nothing per event: it samples at its own instants.
    fn observe(&mut self, _: &Simulation<D>, _: &Outcome<D>) {}
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::observe::order::order_of;
    use rand::{RngExt, SeedableRng};

    /// `Q₆` by the spherical harmonics written out equals the addition theorem's double sum
    /// (the crystal's 0.5745 among them) on random bonds and fcc's twelve: a wrong `P₆ᵐ` or
    /// weight fails it.
    #[test]
    fn q6_equals_the_addition_theorem() {
        let mut rng = rand::rngs::StdRng::seed_from_u64(5);
        for count in [1, 3, 12, 40] {
            let units: Vec<SVector<f64, 3>> = (0..count)
                .map(|_| SVector::<f64, 3>::from(std::array::from_fn(|_| rng.random::<f64>() - 0.5)).normalize())
                .collect();
            let bonds: Vec<_> = units.iter().map(|&u| (0, 1, u)).collect();
            assert!((q6(&bonds) - order_of(&units)).abs() < 1e-12, "{count}: {} vs {}", q6(&bonds), order_of(&units));
        }
        let mut fcc = Vec::new();
        for (a, b) in [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)] {
            for u in [[a, b, 0.0], [a, 0.0, b], [0.0, a, b]] {
                fcc.push((0, 1, SVector::<f64, 3>::from(u).normalize()));
            }
        }
        assert!((q6(&fcc) - 0.57452).abs() < 1e-4);
    }

    /// A perfect triangular crystal: Ψ₆ = 1 and g₆ = 1 at every occupied distance; rotated
    /// by 10°, still 1 (|Ψ₆| does not see the orientation); a square lattice Ψ₆ = 0.
    #[test]
    fn crystals_have_their_order() {
        fn lattice(rows: usize, cols: usize, triangular: bool) -> (Vec<Particle<2>>, SimBox<2>) {
            let dy = if triangular { 3f64.sqrt() / 2.0 } else { 1.0 };
            let particles = (0..rows * cols)
                .map(|k| {
                    let (i, j) = (k % cols, k / cols);
                    let shift = if triangular && j % 2 == 1 { 0.5 } else { 0.0 };
                    super::super::test_particle([i as f64 + shift + 0.1, j as f64 * dy + 0.1], [0.0; 2])
                })
                .collect();
            let lengths = SVector::from([cols as f64, rows as f64 * dy]);
            (particles, SimBox { lengths, boundary: [Boundary::Periodic; 2] })
        }
        let (p, b) = lattice(12, 12, true);
        let mut order = BondOrder::of(&p, &b, 0.0, Options { every: Some(1.0), ..Options::default() });
        order.sample(&p, &b, 0.0);
        assert!((order.series[0][1] - 1.0).abs() < 1e-12, "{:?}", order.series);
        for (s, &n) in order.g6_sums.iter().zip(&order.g6_pairs) {
            if n > 0 {
                assert!((s / n as f64 - 1.0).abs() < 1e-12);
            }
        }
        let (p, b) = lattice(12, 12, false);
        let mut order = BondOrder::of(&p, &b, 0.0, Options { cutoff: Some(1.2), ..Options::default() });
        order.sample(&p, &b, 0.0);
        assert!(order.series[0][1] < 1e-12, "{:?}", order.series);
        let r = order.results();
        assert_eq!((r.parameter, r.samples), ("psi6", 1));
    }
}
