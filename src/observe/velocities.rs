//! The velocity distribution: at the start and at every sample, the particles' speeds against
//! the Maxwell–Boltzmann distribution of the dimension — how far a gas is from equilibrium,
//! and whether it has relaxed.
//!
//! Speeds are reduced, `u = |v|/√(kT/m)`, with kT from the kinetic energy (`2K/dof`, not
//! fitted). For a Maxwellian in `d` dimensions `u` has the χ density with `d` degrees of
//! freedom, and the kinetic energy `x = u²/2` is Gamma(d/2, 1) distributed: exponential in
//! 2D, where the speed density is Rayleigh's `u·e^(−u²/2)` (physics reference sheet). Each
//! snapshot ([`Snapshot`]) holds
//!
//! * the Kolmogorov–Smirnov distance between the energies and Gamma(d/2, 1) ([`ks_distance`];
//!   a monotone map of the speeds, so the same statistic);
//! * `H − H_eq`, the Kullback–Leibler divergence of the speed histogram (bins 0.1 wide up to
//!   `u = 5`, the tail folded into the last) from the Maxwellian's, less the histogram bias
//!   `(K − 1)/(2N)`, with the standard deviation `√(2(K − 1))/(2N)` a Maxwellian's would have
//!   (`2N·KL` is asymptotically χ² with `K − 1` degrees of freedom). The asymptotics hold
//!   where every bin expects at least 5 speeds, so sparse bins at either end are merged with
//!   their neighbours first, and K counts the merged bins ([`h_function`]);
//! * the Sonine coefficient `a₂ = d/(d + 2)·⟨u⁴⟩/⟨u²⟩² − 1` (0 for a Maxwellian, −½ for
//!   equal speeds in 2D) with its standard error for a Maxwellian by the delta method
//!   (`1/√N` in 2D) ([`sonine_a2`]);
//! * the kurtosis `⟨c⁴⟩/⟨c²⟩²` of the pooled velocity components (3 for a Gaussian) with its
//!   standard error `√(24/n)` for `n` components ([`kurtosis`]).
//!
//! Options (`[observe.velocities]` in a configuration): `histograms_at`, the snapshots whose
//! whole histograms are kept (0 is the start, `k` the `k`-th sample).

use super::Observer;
use crate::engine::{Outcome, Simulation};
use serde::{Deserialize, Serialize};
use statrs::distribution::{Exp, Gamma};
use statrs::function::gamma::gamma_lr;
use statrs::stats_tests::NaNPolicy;
use statrs::stats_tests::ks_test::{KSOneSampleAlternativeMethod, ks_onesample};

/// What the observable is asked for.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Options {
    /// The snapshots whose histograms are kept: 0 is the start, `k` the `k`-th sample.
    #[serde(default)]
    pub histograms_at: Vec<u64>,
}

/// The distribution's distance from the Maxwellian at one instant.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Snapshot {
    /// When.
    pub t: f64,
    /// Kolmogorov–Smirnov distance to the Maxwellian's CDF.
    pub ks: f64,
    /// `H − H_eq` (bias-corrected KL divergence, nats).
    pub h: f64,
    /// Its standard deviation for a Maxwellian.
    pub h_error: f64,
    /// Sonine coefficient a₂.
    pub sonine_a2: f64,
    /// Its standard error for a Maxwellian.
    pub sonine_a2_error: f64,
    /// Kurtosis of the velocity components.
    pub kurtosis: f64,
    /// Its standard error for a Gaussian.
    pub kurtosis_error: f64,
}

/// A kept histogram of reduced speeds.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Histogram {
    /// When.
    pub t: f64,
    /// Counts per bin of [`Velocities::edges`] (the last bin open to +∞).
    pub counts: Vec<usize>,
}

/// The velocity-distribution observable (see the module documentation).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Velocities {
    /// The dimension.
    pub dimension: usize,
    /// What was asked for.
    pub options: Options,
    /// Bin edges of the reduced-speed histograms ([`speed_bins`]).
    pub edges: Vec<f64>,
    /// One per snapshot: the start, then every sample.
    pub snapshots: Vec<Snapshot>,
    /// The histograms kept ([`Options::histograms_at`]).
    pub histograms: Vec<Histogram>,
}

impl Velocities {
    /// Starts observing `sim` now: the first snapshot is taken at once.
    pub fn new<const D: usize>(sim: &Simulation<D>, options: Options) -> Velocities {
        let mut v =
            Velocities { dimension: D, options, edges: speed_bins(), snapshots: Vec::new(), histograms: Vec::new() };
        v.snapshot(sim);
        v
    }

    /// Takes the snapshot of `sim` now.
    fn snapshot<const D: usize>(&mut self, sim: &Simulation<D>) {
        let (speeds, components) = reduced(sim);
        let number = self.snapshots.len() as u64;
        self.snapshots.push(Snapshot::of(sim.time(), D, &speeds, &components));
        if self.options.histograms_at.contains(&number) {
            self.histograms.push(Histogram { t: sim.time(), counts: histogram(&speeds, &self.edges) });
        }
    }
}

impl<const D: usize> Observer<D> for Velocities {
    fn observe(&mut self, sim: &Simulation<D>, outcome: &Outcome<D>) {
        if let Outcome::Sample = outcome {
            self.snapshot(sim);
        }
    }
}

impl Snapshot {
    /// The statistics of reduced speeds `u` and components `c` in `d` dimensions at `t`.
    pub fn of(t: f64, d: usize, speeds: &[f64], components: &[f64]) -> Snapshot {
        let (h, h_error) = h_function(speeds, d);
        let (sonine_a2, sonine_a2_error) = sonine_a2(speeds, d);
        let (kurtosis, kurtosis_error) = kurtosis(components);
        Snapshot { t, ks: ks_distance(speeds, d), h, h_error, sonine_a2, sonine_a2_error, kurtosis, kurtosis_error }
    }
}

/// The reduced speeds `|v|/√(kT/m)` and components `v/√(kT/m)` of `sim`'s particles, kT from
/// the kinetic energy.
pub fn reduced<const D: usize>(sim: &Simulation<D>) -> (Vec<f64>, Vec<f64>) {
    let kt = sim.kt();
    let mut speeds = Vec::with_capacity(sim.particles().len());
    let mut components = Vec::with_capacity(D * sim.particles().len());
    for p in sim.particles() {
        let s = (kt / p.mass).sqrt();
        let mut v2 = 0.0;
        for a in 0..D {
            v2 += p.velocity[a] * p.velocity[a];
        }
        speeds.push(v2.sqrt() / s);
        components.extend((0..D).map(|a| p.velocity[a] / s));
    }
    (speeds, components)
}

/// Kolmogorov–Smirnov distance between the reduced speeds `u` and the Maxwellian of `d`
/// dimensions, through the energies `u²/2` against Gamma(d/2, 1) (Exp(1) in 2D), kT known.
pub fn ks_distance(u: &[f64], d: usize) -> f64 {
    let energies: Vec<f64> = u.iter().map(|x| 0.5 * x * x).collect();
    let ks = |result: Result<(f64, f64), _>| result.expect("finite samples").0;
    let method = KSOneSampleAlternativeMethod::TwoSidedAsymptotic;
    if d == 2 {
        let exp = Exp::new(1.0).expect("rate 1 is valid");
        ks(ks_onesample(energies, &exp, method, NaNPolicy::Error))
    } else {
        let gamma = Gamma::new(0.5 * d as f64, 1.0).expect("a valid shape");
        ks(ks_onesample(energies, &gamma, method, NaNPolicy::Error))
    }
}

/// Bin edges for speed histograms: width 0.1 up to u = 5 (the tail beyond, 3.7·10⁻⁶ of a 2D
/// Maxwellian, is folded into the last bin).
pub fn speed_bins() -> Vec<f64> {
    (0..=50).map(|k| k as f64 * 0.1).collect()
}

/// Histogram counts of `u` over `edges` (the last bin open to +∞).
pub fn histogram(u: &[f64], edges: &[f64]) -> Vec<usize> {
    let mut counts = vec![0; edges.len() - 1];
    for &x in u {
        let k = edges.partition_point(|&e| e <= x).saturating_sub(1).min(counts.len() - 1);
        counts[k] += 1;
    }
    counts
}

/// The Maxwellian's probability of each speed bin in `d` dimensions (the last bin open to
/// +∞): differences of the χ CDF `P(d/2, u²/2)`, which is `1 − e^(−u²/2)` in 2D.
pub fn maxwell_bin_probabilities(edges: &[f64], d: usize) -> Vec<f64> {
    let cdf = |u: f64| match d {
        2 => 1.0 - (-0.5 * u * u).exp(),
        _ if u <= 0.0 => 0.0,
        _ => gamma_lr(0.5 * d as f64, 0.5 * u * u),
    };
    let k = edges.len() - 1;
    (0..k).map(|i| if i + 1 == k { 1.0 - cdf(edges[i]) } else { cdf(edges[i + 1]) - cdf(edges[i]) }).collect()
}

/// The fewest speeds a merged bin of [`h_function`] expects.
pub const MIN_EXPECTED: f64 = 5.0;

/// `H − H_eq = KL(p ‖ Maxwellian)` from a histogram of the reduced speeds `u` in `d`
/// dimensions, corrected for the histogram bias `(K − 1)/(2N)`, and its standard deviation
/// `√(2(K − 1))/(2N)` for a true Maxwellian. The bins of [`speed_bins`] are merged in order
/// until each expects at least [`MIN_EXPECTED`] speeds (a short remainder joins the last
/// group): K is the number of merged bins. (Sparse bins — the slow end in 3D, the tail in
/// both dimensions — otherwise bias the plug-in divergence upwards by more than (K − 1)/(2N).)
pub fn h_function(u: &[f64], d: usize) -> (f64, f64) {
    let edges = speed_bins();
    let counts = histogram(u, &edges);
    let q = maxwell_bin_probabilities(&edges, d);
    let n = u.len() as f64;
    let mut groups: Vec<(usize, f64)> = Vec::new();
    let mut open = (0usize, 0.0);
    for (c, q) in counts.iter().zip(&q) {
        open = (open.0 + c, open.1 + q);
        if open.1 * n >= MIN_EXPECTED {
            groups.push(open);
            open = (0, 0.0);
        }
    }
    match groups.last_mut() {
        Some(last) => *last = (last.0 + open.0, last.1 + open.1),
        None => groups.push(open),
    }
    let mut kl = 0.0;
    for &(c, q) in &groups {
        if c > 0 {
            let p = c as f64 / n;
            kl += p * (p / q).ln();
        }
    }
    let k = groups.len() as f64;
    (kl - (k - 1.0) / (2.0 * n), (2.0 * (k - 1.0)).sqrt() / (2.0 * n))
}

/// The Sonine coefficient `a₂ = d/(d + 2)·⟨u⁴⟩/⟨u²⟩² − 1` of reduced speeds in `d`
/// dimensions and its standard error for a Maxwellian.
///
/// The error by the delta method: with `y = u²` (χ²_d: moments `E yᵏ = d(d+2)…(d+2k−2)`),
/// `R = ⟨y²⟩/⟨y⟩²` has `N·Var R ≈ Var(y²)/μ₁⁴ + 4μ₂²·Var(y)/μ₁⁶ − 4μ₂·Cov(y, y²)/μ₁⁵`; that
/// is 4 in 2D (an error of `1/√N` on a₂) and 1.48 in 3D (`0.73/√N`).
pub fn sonine_a2(u: &[f64], d: usize) -> (f64, f64) {
    let n = u.len() as f64;
    let m2 = u.iter().map(|x| x * x).sum::<f64>() / n;
    let m4 = u.iter().map(|x| x.powi(4)).sum::<f64>() / n;
    let c = d as f64 / (d as f64 + 2.0);
    let df = d as f64;
    let (e1, e2) = (df, df * (df + 2.0));
    let (e3, e4) = (e2 * (df + 4.0), e2 * (df + 4.0) * (df + 6.0));
    let var_r = (e4 - e2 * e2) / e1.powi(4) + 4.0 * e2 * e2 * (e2 - e1 * e1) / e1.powi(6)
        - 4.0 * e2 * (e3 - e1 * e2) / e1.powi(5);
    (c * m4 / (m2 * m2) - 1.0, c * var_r.sqrt() / n.sqrt())
}

/// Kurtosis ⟨c⁴⟩/⟨c²⟩² of the pooled velocity components `c` (3 for a Gaussian) and its
/// standard error √(24/n) for n components.
pub fn kurtosis(c: &[f64]) -> (f64, f64) {
    let n = c.len() as f64;
    let mean = c.iter().sum::<f64>() / n;
    let m2 = c.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n;
    let m4 = c.iter().map(|x| (x - mean).powi(4)).sum::<f64>() / n;
    (m4 / (m2 * m2), (24.0 / n).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;
    use statrs::distribution::ContinuousCDF;

    #[test]
    fn equal_speeds_are_far_from_maxwellian() {
        let u = vec![2f64.sqrt(); 1000];
        assert!(ks_distance(&u, 2) > 0.3);
        assert!((sonine_a2(&u, 2).0 + 0.5).abs() < 1e-12);
        assert!(h_function(&u, 2).0 > 1.0);
    }

    #[test]
    fn rayleigh_quantiles_look_maxwellian() {
        // u at the mid-quantiles of the Rayleigh distribution: KS distance 1/(2n).
        let n = 2000;
        let u: Vec<f64> = (0..n).map(|i| (-2.0 * (1.0 - (i as f64 + 0.5) / n as f64).ln()).sqrt()).collect();
        assert!((ks_distance(&u, 2) - 0.5 / n as f64).abs() < 1e-9);
        assert!(sonine_a2(&u, 2).0.abs() < 0.02);
        assert!(h_function(&u, 2).0.abs() < 0.01);
    }

    /// The error formulas at the numbers the delta method gives in closed form (1/√N in 2D),
    /// and the 3D statistics against the χ₃ quantiles (a wrong shape or CDF fails these).
    #[test]
    fn the_statistics_hold_in_three_dimensions() {
        let n = 4000;
        assert_eq!(sonine_a2(&[1.0; 4], 2).1, 0.5);
        // χ₃ quantiles: the energies u²/2 are Gamma(3/2, 1).
        let energy = Gamma::new(1.5, 1.0).unwrap();
        let quantile = |q: f64| (2.0 * energy.inverse_cdf(q)).sqrt();
        let u: Vec<f64> = (0..n).map(|i| quantile((i as f64 + 0.5) / n as f64)).collect();
        assert!((ks_distance(&u, 3) - 0.5 / n as f64).abs() < 1e-6, "{}", ks_distance(&u, 3));
        let (a2, err) = sonine_a2(&u, 3);
        assert!(a2.abs() < 0.02 && (err * (n as f64).sqrt() - 0.7303).abs() < 1e-3, "{a2} {err}");
        assert!(h_function(&u, 3).0.abs() < 0.01);
        // The 2D CDF would call these far from equilibrium.
        assert!(ks_distance(&u, 2) > 0.1);
    }

    /// H − H_eq is calibrated: over 300 seeded Maxwellian samples of N = 4000 speeds in 2D and
    /// in 3D, its mean in units of its stated standard deviation is 0 within 4 standard errors
    /// (4/√300 = 0.23) and its spread is 1 within 25 %. (Without the merging of sparse bins the
    /// 3D mean sits at about +1.2 standard deviations: a relaxed gas would fail a 3σ check one
    /// time in ten.)
    #[test]
    fn the_h_function_is_calibrated_for_maxwellian_samples() {
        use rand::SeedableRng;
        use rand::rngs::Xoshiro256PlusPlus;
        use rand_distr::{Distribution, Normal};
        let normal = Normal::<f64>::new(0.0, 1.0).unwrap();
        for d in [2usize, 3] {
            let mut rng = Xoshiro256PlusPlus::seed_from_u64(11 + d as u64);
            let z: Vec<f64> = (0..300)
                .map(|_| {
                    let u: Vec<f64> = (0..4000)
                        .map(|_| (0..d).map(|_| normal.sample(&mut rng).powi(2)).sum::<f64>().sqrt())
                        .collect();
                    let (h, sd) = h_function(&u, d);
                    h / sd
                })
                .collect();
            let mean = z.iter().sum::<f64>() / z.len() as f64;
            let spread = (z.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (z.len() - 1) as f64).sqrt();
            assert!(mean.abs() < 4.0 / (z.len() as f64).sqrt(), "{d}D: mean {mean}");
            assert!((spread - 1.0).abs() < 0.25, "{d}D: spread {spread}");
        }
    }
}
