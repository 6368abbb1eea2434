//! The radial distribution function `g(r)`, per pair of species, and its contact value.
//!
//! # Estimator
//!
//! At every `every` time units of the production (the particles' positions at that instant,
//! [`Observable::due`](super::Observable::due)), every pair of particles closer than `r_max`
//! is counted into the histogram of its species pair `(a, b)` (`a ≤ b`), bins `Δr =
//! r_max/bins` wide from 0. After `M` samples
//!
//! `g_ab(r_k) = n_ab(k) / (M · I_ab(k))`,
//!
//! `n_ab(k)` the pairs counted in bin `k`, `I_ab(k)` the pairs an ideal gas of the same
//! numbers in the same box would put there: with every axis periodic, `I = P_ab·V_k/V`
//! (`V_k` the bin's shell volume, exact; `P_ab = N_a·N_b`, or `N_a(N_a − 1)/2` for `a = b`),
//! so that `g → 1` at large `r` for any `N`. Between walls the centres of species `a` fill
//! the accessible box `A_a` (`L − 2R_a` along a walled axis), and
//!
//! `I_ab(k) = P_ab/(|A_a||A_b|) · ∫_{bin k} dr ∫_{|h| = r} C_ab(h) dS`,
//!
//! `C_ab(h) = |A_a ∩ (A_b − h)|` the overlap of the two accessible boxes shifted by `h`: the
//! product over axes of `L` (periodic) or `min(a, b, (a + b)/2 − |h_i|)⁺` (walled, `a`, `b`
//! the accessible lengths). The integral is taken by quadrature (Gauss–Legendre in three
//! radii a bin; midpoint rules over a quarter circle in 256 angles, an octant in 64 × 64), to
//! relative errors below 10⁻⁵ — far below a histogram's statistics. So a walled box's `g(r)` is the pair density relative to
//! an ideal gas in that box, and its layering at the walls shows as structure, not as a
//! deficit at large `r`.
//!
//! # Contact value
//!
//! `g_ab(σ_ab⁺)`, `σ_ab = R_a + R_b`: a quadratic in `u = r − σ_ab` fitted by least squares
//! (faer's QR) to `ln g` of the bins that lie wholly in `[σ_ab, σ_ab + w]`, `w` the larger of
//! `0.1·σ_ab` and five bins, its value at `u = 0` exponentiated. Near contact a dense
//! fluid's `g` falls off nearly exponentially, so `ln g` is nearly linear and its quadratic
//! nearly exact, where a quadratic in `g` itself is not: fitted to the same bins it fell
//! 0.3 % below the pressure route at disks' η = 0.65 and spheres' η = 0.45 (ten standard
//! errors of 2·10⁷-collision runs of 4 000 particles, where the fit of `ln g` agreed within
//! 0.05 %). Its error is the delete-one-block jackknife over 20 blocks of consecutive
//! samples (samples close in time are correlated): each block's window counts are kept,
//! the fit repeated on the counts without each block in turn, and `σ² = (B−1)/B·Σ(θ₍ᵦ₎ − θ̄)²`.
//! Should a window bin hold no pair without some block (a dilute or tiny system), the
//! quadratic is fitted to `g` instead. In equilibrium the pressure route
//! `Z = 1 + 2^(d−1)·η·g(σ⁺)` (equal particles) gives the same number exactly, which tests
//! the extrapolation.
//!
//! # Options and output
//!
//! `[observe.rdf]`: `r_max` (default the smaller of five largest contact distances and half
//! the shortest periodic box length — one image per pair), `bins` (default 500), `every`
//! (default 10 ideal-gas collision times for disks, 15 for spheres, [`default_every`]: 3.2
//! for disks at η = 0.7 and 2.5 for spheres at η = 0.45, with kT = m = σ = 1). `collide run` writes `rdf.csv`: `r` (the bin centre) and `g` for one
//! species, or one column `g_<a>_<b>` per species pair; `summary.json` gets the options, the
//! number of samples and the contact values.

use super::Observer;
use crate::engine::{Boundary, Outcome, Particle, SimBox, Simulation};
use nalgebra::SVector;
use serde::{Deserialize, Serialize};

/// What the observable is asked for.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Options {
    /// The largest distance histogrammed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub r_max: Option<f64>,
    /// The number of bins.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bins: Option<usize>,
    /// Time between samples.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub every: Option<f64>,
}

/// Default bins.
pub const BINS: usize = 500;
/// Time between samples when the default cannot be formed (particles at rest).
pub const EVERY: f64 = 1.0;
/// Default `r_max`, in largest contact distances.
pub const REACH: f64 = 5.0;
/// Samples' blocks for the contact value's error.
const BLOCKS: usize = 20;

impl Options {
    /// Checks the options (the configuration's `[observe.rdf]`): the key, its value and what
    /// is allowed.
    pub fn check(&self) -> Result<(), super::Refusal> {
        super::positive("rdf", "r_max", self.r_max, "length")?;
        super::count_within("rdf", "bins", self.bins, 1_000_000)?;
        super::positive("rdf", "every", self.every, "time")
    }
}

/// One species as the histogram knows it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Kind {
    /// Its particles.
    pub count: u64,
    /// Their radius.
    pub radius: f64,
}

/// The contact value of one species pair.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Contact {
    /// The pair `[a, b]`.
    pub species: [u32; 2],
    /// `σ_ab = R_a + R_b`.
    pub sigma: f64,
    /// `g_ab(σ_ab⁺)` (NaN when the window holds fewer than 3 bins).
    pub g: f64,
    /// Its standard error.
    pub error: f64,
}

/// The g(r) observable (see the module documentation).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Rdf {
    /// The dimension.
    pub dimension: usize,
    /// What was asked for.
    pub options: Options,
    /// The largest distance histogrammed.
    pub r_max: f64,
    /// Bins.
    pub bins: usize,
    /// Time between samples.
    pub every: f64,
    /// The next sampling instant.
    pub next: f64,
    /// Samples taken.
    pub samples: u64,
    /// The species present (indexed by species number; absent ones have count 0).
    pub kinds: Vec<Kind>,
    /// The species pairs `[a, b]`, `a ≤ b`, with particles.
    pub pairs: Vec<[u32; 2]>,
    /// Pairs counted, per species pair, per bin.
    pub counts: Vec<Vec<u64>>,
    /// Per species pair, the counts of its contact window's bins, sample after sample
    /// (a window's worth per sample; empty without a window).
    pub window_counts: Vec<Vec<u64>>,
    /// Per species pair, the contact window: its first bin, the fit's weights and the bins'
    /// ideal counts (None: fewer than 3 bins in the window).
    pub windows: Vec<Option<Window>>,
    /// The box (its lengths and walls set the ideal-gas counts).
    pub lengths: Vec<f64>,
    /// Which axes are periodic.
    pub periodic: Vec<bool>,
}

/// The bins of a contact fit.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Window {
    /// The first bin.
    pub first: usize,
    /// One weight per bin: the least-squares quadratic's value at contact is `Σ wⱼ·yⱼ` for
    /// the values `yⱼ` (`ln g` or `g`) of the window's bins.
    pub weights: Vec<f64>,
    /// The bins' ideal-gas counts per sample.
    pub ideal: Vec<f64>,
}

impl Window {
    /// The contact value from the window's `counts` summed over `samples` samples: the fit
    /// of `ln g` when `log`, else of `g`.
    fn contact(&self, counts: &[u64], samples: u64, log: bool) -> f64 {
        let g = counts.iter().zip(&self.ideal).map(|(&n, i)| n as f64 / (samples as f64 * i));
        if log {
            g.zip(&self.weights).map(|(g, w)| w * g.ln()).sum::<f64>().exp()
        } else {
            g.zip(&self.weights).map(|(g, w)| w * g).sum()
        }
    }

    /// The contact value from `per_sample` (the window's counts, one sample after another)
    /// and its delete-one-block jackknife error over `blocks` blocks of consecutive samples.
    fn estimate(&self, per_sample: &[u64], blocks: usize) -> (f64, f64) {
        let n = self.weights.len();
        let samples = per_sample.len() / n;
        if samples == 0 {
            return (f64::NAN, f64::NAN);
        }
        let blocks = blocks.min(samples);
        let mut sums = vec![vec![0u64; n]; blocks];
        for (s, counts) in per_sample.chunks(n).enumerate() {
            for (total, &c) in sums[s * blocks / samples].iter_mut().zip(counts) {
                *total += c;
            }
        }
        let totals: Vec<u64> = (0..n).map(|j| sums.iter().map(|b| b[j]).sum()).collect();
        let size = |b: usize| ((b + 1) * samples).div_ceil(blocks) - (b * samples).div_ceil(blocks);
        let without: Vec<Vec<u64>> =
            sums.iter().map(|block| totals.iter().zip(block).map(|(t, s)| t - s).collect()).collect();
        // The logarithm needs every bin to hold pairs in every leave-one-out total.
        let log = blocks >= 2 && without.iter().all(|counts| counts.iter().all(|&c| c > 0));
        let value = self.contact(&totals, samples as u64, log);
        let theta: Vec<f64> = without
            .iter()
            .enumerate()
            .map(|(b, counts)| self.contact(counts, (samples - size(b)) as u64, log))
            .collect();
        (value, super::blocks::jackknife_error(&theta))
    }
}

/// What `summary.json` holds of it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Results {
    /// The largest distance histogrammed.
    pub r_max: f64,
    /// Bins.
    pub bins: usize,
    /// Time between samples.
    pub every: f64,
    /// Samples taken.
    pub samples: u64,
    /// The contact values, one per species pair.
    pub contact: Vec<Contact>,
}

impl Rdf {
    /// Starts observing `sim`: the first sample at `now + every`.
    pub fn new<const D: usize>(sim: &Simulation<D>, options: Options) -> Rdf {
        Rdf::of(sim.particles(), sim.sim_box(), sim.time(), options)
    }

    /// Starts observing `particles` (their species and radii) in `sim_box` at time `now`.
    pub fn of<const D: usize>(particles: &[Particle<D>], sim_box: &SimBox<D>, now: f64, options: Options) -> Rdf {
        let mut kinds: Vec<Kind> = Vec::new();
        for p in particles {
            let s = p.species as usize;
            if kinds.len() <= s {
                kinds.resize(s + 1, Kind { count: 0, radius: 0.0 });
            }
            kinds[s].count += 1;
            kinds[s].radius = kinds[s].radius.max(p.radius);
        }
        let largest = kinds.iter().map(|k| 2.0 * k.radius).fold(0.0, f64::max);
        let half = (0..D)
            .filter(|&a| sim_box.boundary[a] == Boundary::Periodic)
            .map(|a| 0.5 * sim_box.lengths[a])
            .fold(f64::INFINITY, f64::min);
        let diagonal = sim_box.lengths.norm();
        let r_max = options.r_max.unwrap_or(REACH * largest).min(half).min(diagonal);
        let bins = options.bins.unwrap_or(BINS);
        let every = options.every.unwrap_or_else(|| default_every(particles, sim_box, largest));
        let mut pairs = Vec::new();
        for a in 0..kinds.len() {
            for b in a..kinds.len() {
                if kinds[a].count > 0 && kinds[b].count > 0 && (a != b || kinds[a].count > 1) {
                    pairs.push([a as u32, b as u32]);
                }
            }
        }
        let mut rdf = Rdf {
            dimension: D,
            options,
            r_max,
            bins,
            every,
            next: now + every,
            samples: 0,
            counts: vec![vec![0; bins]; pairs.len()],
            window_counts: vec![Vec::new(); pairs.len()],
            kinds,
            pairs,
            lengths: sim_box.lengths.iter().copied().collect(),
            periodic: sim_box.boundary.iter().map(|b| *b == Boundary::Periodic).collect(),
            windows: Vec::new(),
        };
        rdf.windows = rdf.contact_windows();
        rdf
    }

    /// The next sampling instant.
    pub fn due(&self) -> f64 {
        self.next
    }

    /// Samples `particles` (in `sim_box`) at the instant `t` (every particle in free flight
    /// from its last update to `t`), and schedules the next sample.
    pub fn sample<const D: usize>(&mut self, particles: &[Particle<D>], sim_box: &SimBox<D>, t: f64) {
        let positions: Vec<(u32, SVector<f64, D>)> = particles.iter().map(|p| (p.species, p.position_at(t))).collect();
        // One histogram per ordered species pair (no lookup of the unordered pair per pair).
        let (s, width, bins) = (self.kinds.len(), self.bins, self.bins);
        let scale = self.bins as f64 / self.r_max;
        let mut ordered = vec![0u64; s * s * width];
        for_pairs_within(&positions, sim_box, self.r_max, |a, b, r2| {
            let k = ((r2.sqrt() * scale) as usize).min(bins - 1);
            ordered[(a as usize * s + b as usize) * width + k] += 1;
        });
        let this: Vec<Vec<u64>> = self
            .pairs
            .iter()
            .map(|&[a, b]| {
                let (ab, ba) = ((a as usize * s + b as usize) * width, (b as usize * s + a as usize) * width);
                (0..bins).map(|k| if a == b { ordered[ab + k] } else { ordered[ab + k] + ordered[ba + k] }).collect()
            })
            .collect();
        for (q, counts) in this.iter().enumerate() {
            if let Some(w) = &self.windows[q] {
                let window = &counts[w.first..w.first + w.weights.len()];
                self.window_counts[q].extend_from_slice(window);
            }
            for (total, c) in self.counts[q].iter_mut().zip(counts) {
                *total += c;
            }
        }
        self.samples += 1;
        self.next = t + self.every;
    }

    /// Bin `k`'s inner and outer radius.
    fn edges(&self, k: usize) -> (f64, f64) {
        let dr = self.r_max / self.bins as f64;
        (k as f64 * dr, (k + 1) as f64 * dr)
    }

    /// The ideal-gas pair counts of species pair `q`, bin by bin (see the module docs).
    pub fn ideal(&self, q: usize) -> Vec<f64> {
        self.ideal_bins(q, 0..self.bins)
    }

    /// [`ideal`](Self::ideal) for the bins `bins` only (a contact window's, at the start).
    fn ideal_bins(&self, q: usize, bins: std::ops::Range<usize>) -> Vec<f64> {
        let [a, b] = self.pairs[q];
        let (ka, kb) = (self.kinds[a as usize], self.kinds[b as usize]);
        let pairs =
            if a == b { ka.count as f64 * (ka.count as f64 - 1.0) / 2.0 } else { ka.count as f64 * kb.count as f64 };
        let d = self.dimension;
        let accessible = |r: f64| -> Vec<f64> {
            self.lengths.iter().zip(&self.periodic).map(|(l, p)| if *p { *l } else { l - 2.0 * r }).collect()
        };
        let (la, lb) = (accessible(ka.radius), accessible(kb.radius));
        let volume = |l: &[f64]| l.iter().product::<f64>();
        let norm = pairs / (volume(&la) * volume(&lb));
        let walled = self.periodic.iter().any(|p| !p);
        bins.map(|k| {
            let (r0, r1) = self.edges(k);
            if !walled {
                let unit = unit_ball(d);
                return pairs * unit * (r1.powi(d as i32) - r0.powi(d as i32)) / volume(&la);
            }
            norm * shell_integral(d, r0, r1, |h| {
                (0..d)
                    .map(|i| {
                        if self.periodic[i] {
                            self.lengths[i]
                        } else {
                            let (x, y) = (la[i], lb[i]);
                            x.min(y).min(0.5 * (x + y) - h[i].abs()).max(0.0)
                        }
                    })
                    .product()
            })
        })
        .collect()
    }

    /// `g` of species pair `q`, bin by bin (NaN before the first sample).
    pub fn g(&self, q: usize) -> Vec<f64> {
        let ideal = self.ideal(q);
        self.counts[q].iter().zip(&ideal).map(|(&n, &i)| n as f64 / (self.samples as f64 * i)).collect()
    }

    /// Per species pair: the contact window (see [`Window`]).
    fn contact_windows(&self) -> Vec<Option<Window>> {
        use faer::linalg::solvers::SolveLstsq;
        let dr = self.r_max / self.bins as f64;
        self.pairs
            .iter()
            .enumerate()
            .map(|(q, [a, b])| {
                let sigma = self.kinds[*a as usize].radius + self.kinds[*b as usize].radius;
                let first = (sigma / dr).ceil() as usize;
                let width = (0.1 * sigma).max(5.0 * dr);
                let last = (((sigma + width) / dr).floor() as usize).min(self.bins);
                let n = last.saturating_sub(first);
                if n < 3 {
                    return None;
                }
                let x = faer::Mat::<f64>::from_fn(n, 3, |i, j| {
                    let u = ((first + i) as f64 + 0.5) * dr - sigma;
                    (u / width).powi(j as i32)
                });
                let identity = faer::Mat::<f64>::from_fn(n, n, |i, j| if i == j { 1.0 } else { 0.0 });
                // Column j of the solution: the quadratic fitted to the unit vector e_j;
                // its value at contact (u = 0) is its constant term.
                let fitted = x.qr().solve_lstsq(&identity);
                let ideal = self.ideal_bins(q, first..first + n);
                Some(Window { first, weights: (0..n).map(|j| fitted[(0, j)]).collect(), ideal })
            })
            .collect()
    }

    /// What `summary.json` holds.
    pub fn results(&self) -> Results {
        let contact = self
            .pairs
            .iter()
            .enumerate()
            .map(|(q, [a, b])| {
                let sigma = self.kinds[*a as usize].radius + self.kinds[*b as usize].radius;
                let (g, error) = self.windows[q]
                    .as_ref()
                    .map_or((f64::NAN, f64::NAN), |w| w.estimate(&self.window_counts[q], BLOCKS));
                Contact { species: [*a, *b], sigma, g, error }
            })
            .collect();
        Results { r_max: self.r_max, bins: self.bins, every: self.every, samples: self.samples, contact }
    }

    /// `rdf.csv`: `r` and `g` (one species pair) or `g_<a>_<b>` (several).
    pub fn csv(&self) -> String {
        let g: Vec<Vec<f64>> = (0..self.pairs.len()).map(|q| self.g(q)).collect();
        let mut text = String::from("r");
        if self.pairs.len() == 1 {
            text += ",g";
        } else {
            for [a, b] in &self.pairs {
                text += &format!(",g_{a}_{b}");
            }
        }
        text.push('\n');
        for k in 0..self.bins {
            let (r0, r1) = self.edges(k);
            text += &format!("{}", 0.5 * (r0 + r1));
            for column in &g {
                text += &format!(",{}", column[k]);
            }
            text.push('\n');
        }
        text
    }
}

impl<const D: usize> Observer<D> for Rdf {
    /// Nothing per event: it samples at its own instants ([`Rdf::sample`]).
    fn observe(&mut self, _: &Simulation<D>, _: &Outcome<D>) {}
}

/// The default time between samples: [`IDEAL_TIMES`] ideal-gas collision times (10 for
/// disks, 15 for spheres), `1/Γ₀` with
/// `Γ₀` Enskog's rate with `g = 1` ([`enskog_rate`](crate::theory::enskog_rate)) at the
/// particles' number density, the largest contact distance, their kT and mean mass — so
/// that a sample costs about as much, against the collisions between samples, at any
/// density (the real rate is `g(σ)` times higher: dense fluids are sampled every `10·g(σ)`
/// or `15·g(σ)` collisions per particle). [`EVERY`] for particles at rest.
pub fn default_every<const D: usize>(particles: &[Particle<D>], sim_box: &SimBox<D>, sigma: f64) -> f64 {
    let n = particles.len() as f64;
    let kinetic: f64 = particles.iter().map(|p| 0.5 * p.mass * p.velocity.norm_squared()).sum();
    let kt = 2.0 * kinetic / (D as f64 * n);
    let mass = particles.iter().map(|p| p.mass).sum::<f64>() / n;
    let rate = crate::theory::enskog_rate(D, n / sim_box.volume(), sigma, 1.0, kt, mass);
    let every = IDEAL_TIMES[D.min(3) - 2] / rate;
    if every.is_finite() && every > 0.0 { every } else { EVERY }
}

/// The default time between samples in ideal-gas collision times ([`default_every`]), for
/// disks and for spheres: a sphere's sample walks about three times the neighbours a disk's
/// does against the collisions between samples, so spheres are sampled more sparsely. At these
/// rates, with `r_max` = 5σ, the samples take 2–3 % of a run's time for disks (η = 0.3 and
/// 0.7, N = 10⁴) and 4–9 % for spheres (η = 0.45 with N = 10⁴, η = 0.2 with N = 4000).
pub const IDEAL_TIMES: [f64; 2] = [10.0, 15.0];

/// The volume of the unit ball in `d` dimensions (π, 4π/3).
fn unit_ball(d: usize) -> f64 {
    use std::f64::consts::PI;
    if d == 2 { PI } else { 4.0 / 3.0 * PI }
}

/// `∫_{r0}^{r1} dr ∫_{|h| = r} f(h) dS` for `f` even in every component (a product of
/// functions of `|h_i|`): Gauss–Legendre in r (three radii per bin), midpoint rules over the
/// first quadrant (256 angles) or octant (64 × 64 in the polar angle's cosine and the
/// azimuth) times its copies.
fn shell_integral(d: usize, r0: f64, r1: f64, f: impl Fn(&[f64]) -> f64) -> f64 {
    use std::f64::consts::FRAC_PI_2;
    // Three-point Gauss–Legendre in r: exact for the polynomials of degree ≤ 5 that the
    // integrand is between its kinks (r^(d−1) times a product of d linear factors).
    let (mid, half) = (0.5 * (r0 + r1), 0.5 * (r1 - r0));
    let node = (0.6f64).sqrt();
    let mut total = 0.0;
    for (x, w) in [(-node, 5.0 / 9.0), (0.0, 8.0 / 9.0), (node, 5.0 / 9.0)] {
        let (r, dr) = (mid + x * half, w * half);
        let surface = if d == 2 {
            const N: usize = 256;
            let dphi = FRAC_PI_2 / N as f64;
            (0..N)
                .map(|i| {
                    let phi = (i as f64 + 0.5) * dphi;
                    f(&[r * phi.cos(), r * phi.sin()])
                })
                .sum::<f64>()
                * dphi
                * 4.0
                * r
        } else {
            // dS = r² d(cos θ) dφ: uniform in cos θ over [0, 1] and φ over [0, π/2].
            const N: usize = 64;
            let (dc, dphi) = (1.0 / N as f64, FRAC_PI_2 / N as f64);
            let mut sum = 0.0;
            for i in 0..N {
                let c = (i as f64 + 0.5) * dc;
                let s = (1.0 - c * c).sqrt();
                for j in 0..N {
                    let phi = (j as f64 + 0.5) * dphi;
                    sum += f(&[r * s * phi.cos(), r * s * phi.sin(), r * c]);
                }
            }
            sum * dc * dphi * 8.0 * r * r
        };
        total += surface * dr;
    }
    total
}

/// Calls `f(species_a, species_b, r²)` for every unordered pair of `positions` closer than
/// `r_max` (in no particular order), the nearest image along periodic axes (`r_max` is at most
/// half of every periodic length, so it is the only one in range): a grid of cells at least
/// `r_max/m` wide, each cell against itself and half of its neighbours up to `m` cells away.
///
/// The positions are wrapped into the box and copied cell by cell into one array, so that a
/// cell's members are contiguous; the image of a neighbouring cell is the box length added
/// where its index wrapped, once per cell pair — no rounding per pair, but along an axis of a
/// single cell (a box too short to split), where each pair takes its nearest image.
pub(crate) fn for_pairs_within<const D: usize>(
    positions: &[(u32, SVector<f64, D>)],
    sim_box: &SimBox<D>,
    r_max: f64,
    mut f: impl FnMut(u32, u32, f64),
) {
    let periodic: [bool; D] = std::array::from_fn(|a| sim_box.boundary[a] == Boundary::Periodic);
    let lengths: [f64; D] = std::array::from_fn(|a| sim_box.lengths[a]);
    // Cells at least r_max/m wide, searched m cells to either side; a periodic axis with
    // fewer than 2m + 1 cells is one cell (every pair along it compared, nearest image). Of
    // m = 1, 2, 3 the one that searches the least volume around a particle: finer cells
    // follow the sphere of r_max more closely, and fit small boxes that m = 1 cannot split.
    let counts_for = |m: usize| -> [usize; D] {
        std::array::from_fn(|a| {
            let n = ((lengths[a] * m as f64 / r_max).floor() as usize).max(1);
            if n < 2 * m + 1 && (periodic[a] || n < m + 1) { 1 } else { n }
        })
    };
    let searched = |m: usize| -> f64 {
        let counts = counts_for(m);
        (0..D)
            .map(|a| if counts[a] == 1 { lengths[a] } else { (2 * m + 1) as f64 * lengths[a] / counts[a] as f64 })
            .product()
    };
    // The work of a walk: the pairs it compares (the searched volume at the particles'
    // density, half of it per particle) and, per occupied cell, its half of the neighbour
    // offsets, each some divisions — about four pairs' worth. Dense fluids choose by the
    // volume alone; a dilute one, whose finest cells are mostly empty or single, takes the
    // coarsest (η = 0.05: 3375 spheres, m = 3 cost 5.7 ms a sample, m = 1 0.5 ms).
    let n = positions.len() as f64;
    let density = n / lengths.iter().product::<f64>();
    let work = |m: usize| -> f64 {
        let cells = counts_for(m).iter().product::<usize>() as f64;
        let offsets = ((2 * m + 1).pow(D as u32) - 1) as f64 / 2.0;
        0.5 * n * density * searched(m) + 4.0 * n.min(cells) * (offsets + 1.0)
    };
    let reach = (1..=3).min_by(|&x, &y| work(x).total_cmp(&work(y))).expect("three choices");
    let counts = counts_for(reach);
    let single: [bool; D] = std::array::from_fn(|a| counts[a] == 1);
    let wrap = |x: f64, a: usize| if periodic[a] { x - (x / lengths[a]).floor() * lengths[a] } else { x };
    let flat = |m: &[usize; D]| m.iter().zip(&counts).fold(0, |acc, (m, n)| acc * n + m);
    let total: usize = counts.iter().product();
    // Counting sort of the wrapped positions into cells.
    let wrapped: Vec<[f64; D]> = positions.iter().map(|(_, x)| std::array::from_fn(|a| wrap(x[a], a))).collect();
    let cells: Vec<usize> = wrapped
        .iter()
        .map(|x| {
            let m: [usize; D] = std::array::from_fn(|a| {
                (((x[a] / lengths[a]) * counts[a] as f64).floor().max(0.0) as usize).min(counts[a] - 1)
            });
            flat(&m)
        })
        .collect();
    let mut start = vec![0usize; total + 1];
    for &c in &cells {
        start[c + 1] += 1;
    }
    for c in 0..total {
        start[c + 1] += start[c];
    }
    let mut fill = start.clone();
    let mut xs = vec![[0.0; D]; positions.len()];
    let mut species = vec![0u32; positions.len()];
    for (i, &c) in cells.iter().enumerate() {
        xs[fill[c]] = wrapped[i];
        species[fill[c]] = positions[i].0;
        fill[c] += 1;
    }
    let any_single = single.iter().any(|&s| s);
    // One pair's squared distance, `shift` the image of the second's cell.
    let apart = |xi: &[f64; D], xj: &[f64; D], shift: &[f64; D]| -> f64 {
        let mut r2 = 0.0;
        for a in 0..D {
            let mut d = xj[a] + shift[a] - xi[a];
            if any_single && single[a] && periodic[a] {
                d -= (d / lengths[a]).round() * lengths[a];
            }
            r2 += d * d;
        }
        r2
    };
    // Half of the (2m + 1)^D neighbour offsets (lexicographically positive); the cell itself
    // apart. Along an axis of one cell only the offset 0.
    let side = 2 * reach + 1;
    let offsets: Vec<[i64; D]> = (0..side.pow(D as u32))
        .map(|k| std::array::from_fn(|a| ((k / side.pow((D - 1 - a) as u32)) % side) as i64 - reach as i64))
        .filter(|o: &[i64; D]| o.iter().find(|&&x| x != 0).is_some_and(|&x| x > 0))
        .filter(|o: &[i64; D]| (0..D).all(|a| counts[a] > 1 || o[a] == 0))
        .collect();
    let none = [0.0; D];
    // The pairs in range are gathered without a branch (a third of those walked are in range:
    // a coin toss for the branch predictor) and handed to `f` in batches.
    const BATCH: usize = 256;
    let r2_max = r_max * r_max;
    let mut batch = [(0u32, 0u32, 0.0f64); BATCH + 1];
    let mut len = 0usize;
    let mut offer = |a: u32, b: u32, r2: f64, f: &mut dyn FnMut(u32, u32, f64)| {
        batch[len] = (a, b, r2);
        len += (r2 < r2_max) as usize;
        if len == BATCH {
            for &(a, b, r2) in &batch[..len] {
                f(a, b, r2);
            }
            len = 0;
        }
    };
    for c in 0..total {
        // A dilute fluid leaves most cells empty: walking their offsets cost a fluid at
        // η = 0.05 (3375 spheres, 59 319 cells) 55 ms a sample.
        if start[c] == start[c + 1] {
            continue;
        }
        let mut m = [0usize; D];
        let mut rest = c;
        for a in (0..D).rev() {
            m[a] = rest % counts[a];
            rest /= counts[a];
        }
        let here = start[c]..start[c + 1];
        for i in here.clone() {
            for j in i + 1..here.end {
                offer(species[i], species[j], apart(&xs[i], &xs[j], &none), &mut f);
            }
        }
        'offsets: for o in &offsets {
            let mut n = [0usize; D];
            let mut shift = [0.0; D];
            for a in 0..D {
                let k = m[a] as i64 + o[a];
                let count = counts[a] as i64;
                if k < 0 || k >= count {
                    if !periodic[a] {
                        continue 'offsets;
                    }
                    // Wrapped: the neighbour cell's image lies one box length over.
                    shift[a] = if k < 0 { -lengths[a] } else { lengths[a] };
                }
                n[a] = k.rem_euclid(count) as usize;
            }
            let other = flat(&n);
            for i in here.clone() {
                let xi = &xs[i];
                for j in start[other]..start[other + 1] {
                    offer(species[i], species[j], apart(xi, &xs[j], &shift), &mut f);
                }
            }
        }
    }
    let rest = len;
    for &(a, b, r2) in &batch[..rest] {
        f(a, b, r2);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};

    /// Every pair within r_max is visited once, periodic or walled, in 2D and 3D (against
    /// all pairs by the nearest image).
    #[test]
    fn the_cell_walk_visits_every_pair_in_range_once() {
        fn check<const D: usize>(boundary: [Boundary; D], lengths: [f64; D], r_max: f64, n: usize, seed: u64) {
            let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
            let sim_box = SimBox { lengths: SVector::from(lengths), boundary };
            let positions: Vec<(u32, SVector<f64, D>)> = (0..n)
                .map(|i| (i as u32, SVector::from(std::array::from_fn(|a| rng.random::<f64>() * lengths[a]))))
                .collect();
            let mut seen = Vec::new();
            for_pairs_within(&positions, &sim_box, r_max, |a, b, r2| {
                assert!(r2 < r_max * r_max);
                seen.push((a.min(b), a.max(b)));
            });
            let mut expected = Vec::new();
            for i in 0..n {
                for j in i + 1..n {
                    let d = positions[j].1 - positions[i].1
                        + sim_box.minimum_image_shift(&(positions[j].1 - positions[i].1));
                    if d.norm_squared() < r_max * r_max {
                        expected.push((i as u32, j as u32));
                    }
                }
            }
            seen.sort();
            expected.sort();
            assert_eq!(seen, expected);
        }
        use Boundary::{Periodic as P, Wall as W};
        check([P, P], [10.0, 7.0], 2.0, 300, 1);
        check([P, W], [10.0, 7.0], 2.0, 300, 2);
        check([P, P], [10.0, 5.0], 2.4, 200, 3); // two cells' width on one axis: one cell
        check([P, P, P], [8.0, 8.0, 9.0], 2.0, 400, 4);
        check([W, P, W], [8.0, 5.0, 9.0], 2.5, 400, 5);
        // Boxes that m = 2 and 3 fit (2.8 and 3.8 r_max across, as 4000 and 10 000
        // spheres at η = 0.45 with r_max = 5), and a wall axis of under two cells.
        check([P, P, P], [14.0, 14.0, 14.0], 5.0, 600, 6);
        check([P, P, P], [19.0, 19.0, 19.0], 5.0, 600, 7);
        check([P, W, P], [19.0, 6.0, 14.0], 5.0, 600, 8);
        check([P, P], [40.0, 12.0], 5.0, 500, 9);
    }

    /// The contact value's fit of `ln g` is exact for `g = A·e^(−κu)` (in counts that
    /// large, to 10⁻⁶), where the quadratic in `g` it replaced falls short by more than the
    /// error (the bias this fit exists to remove); its jackknife error is zero for identical
    /// samples and, for Poisson noise, within a third of the scatter of 200 repetitions; a
    /// window bin empty without some block falls back to the fit of `g`.
    #[test]
    fn the_contact_fit_of_ln_g_is_exact_for_an_exponential_and_its_error_honest() {
        use rand_distr::{Distribution, Poisson};
        let particles: Vec<Particle<2>> =
            (0..2).map(|i| super::super::test_particle([i as f64, 0.0], [0.0; 2])).collect();
        let sim_box = SimBox { lengths: SVector::from([20.0, 20.0]), boundary: [Boundary::Periodic; 2] };
        let rdf = Rdf::of(&particles, &sim_box, 0.0, Options { r_max: Some(5.0), bins: Some(500), every: Some(1.0) });
        let w = rdf.windows[0].clone().expect("a window");
        let n = w.weights.len();
        assert_eq!(n, 10, "bins wholly within 0.1σ of contact");
        let (a, kappa, dr) = (5.7, 6.0, 0.01);
        // Expected counts per sample: the ideal count times g at the bin's centre.
        let mean: Vec<f64> =
            (0..n).map(|j| w.ideal[j] * a * (-kappa * ((w.first + j) as f64 + 0.5 - 100.0) * dr).exp()).collect();
        let scale = 1e9 / mean[0];
        let exact: Vec<u64> = (0..40).flat_map(|_| mean.iter().map(|m| (m * scale).round() as u64)).collect();
        let scaled = Window { ideal: w.ideal.iter().map(|i| i * scale).collect(), ..w.clone() };
        let (g, error) = scaled.estimate(&exact, 20);
        assert!((g / a - 1.0).abs() < 1e-6, "ln-g fit {g} for {a}");
        assert!(error < 1e-9, "identical samples: {error}");
        let linear = scaled.contact(&exact[..n], 1, false);
        assert!(a - linear > 5e-3, "the quadratic in g: {linear} (no bias to remove?)");
        // Poisson counts at a realistic scale: about 400 pairs per bin per sample.
        let scale = 400.0 / mean[0];
        let scaled = Window { ideal: w.ideal.iter().map(|i| i * scale).collect(), ..w.clone() };
        let mut rng = rand::rngs::StdRng::seed_from_u64(7);
        let runs: Vec<(f64, f64)> = (0..200)
            .map(|_| {
                let counts: Vec<u64> = (0..100)
                    .flat_map(|_| {
                        mean.iter()
                            .map(|m| Poisson::new(m * scale).unwrap().sample(&mut rng) as u64)
                            .collect::<Vec<_>>()
                    })
                    .collect();
                scaled.estimate(&counts, 20)
            })
            .collect();
        let values: Vec<f64> = runs.iter().map(|r| r.0).collect();
        let m = values.iter().sum::<f64>() / 200.0;
        let spread = (values.iter().map(|v| (v - m).powi(2)).sum::<f64>() / 199.0).sqrt();
        let quoted = runs.iter().map(|r| r.1).sum::<f64>() / 200.0;
        assert!((quoted / spread - 1.0).abs() < 0.33, "jackknife {quoted} against scatter {spread}");
        assert!((m - a).abs() < 4.0 * spread / 200f64.sqrt() + 1e-3 * a, "mean {m} against {a}");
        // One bin with pairs in a single sample only: the logarithm is refused, g is fitted.
        let mut sparse = exact.clone();
        for s in 1..40 {
            sparse[s * n + 3] = 0;
        }
        let (g, _) = scaled.estimate(&sparse, 20);
        let by_g =
            scaled.contact(&(0..n).map(|j| (0..40).map(|s| sparse[s * n + j]).sum()).collect::<Vec<_>>(), 40, false);
        assert_eq!(g, by_g);
    }

    /// Uniformly random points of two species (an ideal gas, overlaps allowed) give g = 1 in
    /// every bin within its Poisson error — in a periodic box, and between walls, where the
    /// centres fill the accessible box of their radius. The naive normalisation of a walled
    /// box (the density of the accessible volume, shells taken whole: the bug the walled one
    /// exists to avoid) fails the same test.
    #[test]
    fn an_ideal_gas_has_g_one_in_periodic_and_walled_boxes() {
        fn check<const D: usize>(boundary: [Boundary; D], lengths: [f64; D], seed: u64) {
            use Boundary::Periodic;
            let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
            let sim_box = SimBox { lengths: SVector::from(lengths), boundary };
            let radii = [0.5, 0.7];
            let draw = |rng: &mut rand::rngs::StdRng| -> Vec<Particle<D>> {
                (0..600)
                    .map(|i| {
                        let species = (i % 3 == 0) as u32;
                        let r = radii[species as usize];
                        let position = SVector::from(std::array::from_fn(|a| {
                            if boundary[a] == Periodic {
                                rng.random::<f64>() * lengths[a]
                            } else {
                                r + rng.random::<f64>() * (lengths[a] - 2.0 * r)
                            }
                        }));
                        Particle {
                            position,
                            velocity: SVector::zeros(),
                            time: 0.0,
                            radius: r,
                            mass: 1.0,
                            species,
                            events: 0,
                        }
                    })
                    .collect()
            };
            let options = Options { r_max: Some(3.0), bins: Some(30), every: Some(1.0) };
            let mut rdf = Rdf::of(&draw(&mut rng), &sim_box, 0.0, options);
            assert_eq!(rdf.pairs, [[0, 0], [0, 1], [1, 1]]);
            for m in 0..200 {
                rdf.sample(&draw(&mut rng), &sim_box, m as f64);
            }
            let walled = boundary.contains(&Boundary::Wall);
            for q in 0..rdf.pairs.len() {
                let ideal = rdf.ideal(q);
                let mut worst = 0.0f64;
                let (mut counted, mut expected, mut expected_periodic) = (0.0, 0.0, 0.0);
                for k in 5..rdf.bins {
                    let e = rdf.samples as f64 * ideal[k];
                    let n = rdf.counts[q][k] as f64;
                    worst = worst.max((n - e).abs() / e.sqrt());
                    let (r0, r1) = rdf.edges(k);
                    counted += n;
                    expected += e;
                    expected_periodic += ideal_periodic(&rdf, q, r0, r1) * rdf.samples as f64;
                }
                // 25 bins: the largest of 25 |z| passes 4.5 with probability 1 − 2·10⁻⁴; the
                // pooled count is one z. (Pair counts of independent points are very nearly
                // Poisson at these densities.)
                assert!(worst < 4.5, "{boundary:?} pair {q}: largest |z| = {worst}");
                let pooled = (counted - expected) / expected.sqrt();
                assert!(pooled.abs() < 4.0, "{boundary:?} pair {q}: pooled z = {pooled}");
                if walled {
                    let wrong = (counted - expected_periodic) / expected_periodic.sqrt();
                    assert!(wrong < -6.0, "{boundary:?} pair {q}: the periodic norm passes too (pooled z = {wrong})");
                }
            }
        }
        /// The naive normalisation: the density of the accessible volume, the shell whole
        /// (no pair lost beyond a wall).
        fn ideal_periodic(rdf: &Rdf, q: usize, r0: f64, r1: f64) -> f64 {
            let [a, b] = rdf.pairs[q];
            let (ka, kb) = (rdf.kinds[a as usize], rdf.kinds[b as usize]);
            let (na, nb) = (ka.count as f64, kb.count as f64);
            let pairs = if a == b { na * (na - 1.0) / 2.0 } else { na * nb };
            let d = rdf.dimension as i32;
            let volume = |r: f64| -> f64 {
                rdf.lengths.iter().zip(&rdf.periodic).map(|(l, p)| if *p { *l } else { l - 2.0 * r }).product()
            };
            pairs * unit_ball(rdf.dimension) * (r1.powi(d) - r0.powi(d))
                / (volume(ka.radius) * volume(kb.radius)).sqrt()
        }
        use Boundary::{Periodic as P, Wall as W};
        check([P, P], [30.0, 25.0], 11);
        check([W, P], [30.0, 25.0], 12);
        check([W, W], [30.0, 25.0], 13);
        check([P, P, P], [9.0, 9.0, 10.0], 14);
        check([W, W, P], [9.0, 9.0, 10.0], 15);
    }

    /// The walled ideal-gas counts match the closed form for equal radii in 2D between
    /// walls on both axes: `∫_{|h|=r} (a − |h_x|)(b − |h_y|) dS = r(2πab − 4r(a + b) + 2r²)`.
    #[test]
    fn the_walled_shell_integral_matches_its_closed_form() {
        let (a, b) = (9.0, 6.0);
        for (r0, r1) in [(0.5, 0.51), (1.0, 1.02), (2.9, 3.0)] {
            let numeric = shell_integral(2, r0, r1, |h| (a - h[0].abs()) * (b - h[1].abs()));
            let exact_at = |r: f64| {
                // ∫ r(2πab − 4r(a+b) + 2r²) dr
                std::f64::consts::PI * a * b * r * r - 4.0 / 3.0 * r.powi(3) * (a + b) + 0.5 * r.powi(4)
            };
            let exact = exact_at(r1) - exact_at(r0);
            assert!((numeric / exact - 1.0).abs() < 1e-5, "[{r0}, {r1}]: {numeric} vs {exact}");
        }
        // 3D, all periodic-like (f = 1): the shell's volume.
        let v = shell_integral(3, 1.0, 1.1, |_| 1.0);
        assert!((v / (4.0 / 3.0 * std::f64::consts::PI * (1.1f64.powi(3) - 1.0)) - 1.0).abs() < 1e-4);
    }
}
