//! Statistics of velocity samples against the 2D Maxwell–Boltzmann distribution.
//!
//! Speeds are taken in units of √(kT/m): `u = v/√(kT/m)`, whose 2D Maxwellian density is the
//! Rayleigh density `f(u) = u·e^(−u²/2)`, CDF `F(u) = 1 − e^(−u²/2)` (physics reference
//! sheet). The kinetic energy `u²/2` is then exponential with rate 1, which is how the KS
//! test is run (statrs' `Exp`, the same statistic since the map is monotone).

use statrs::distribution::{ContinuousCDF, Exp, StudentsT};
use statrs::stats_tests::NaNPolicy;
use statrs::stats_tests::ks_test::{KSOneSampleAlternativeMethod, ks_onesample};

/// Kolmogorov–Smirnov distance between the speeds `u` (in units of √(kT/m)) and the Rayleigh
/// CDF, kT known (not fitted).
pub fn ks_rayleigh(u: &[f64]) -> f64 {
    let energies: Vec<f64> = u.iter().map(|x| 0.5 * x * x).collect();
    let exp = Exp::new(1.0).expect("rate 1 is valid");
    ks_onesample(energies, &exp, KSOneSampleAlternativeMethod::TwoSidedAsymptotic, NaNPolicy::Error)
        .expect("finite samples")
        .0
}

/// The 95 % critical value of the one-sample KS distance for `n` samples, `1.358/√n`
/// (asymptotic Kolmogorov distribution; physics reference sheet).
pub fn ks_critical_95(n: usize) -> f64 {
    1.358 / (n as f64).sqrt()
}

/// The "3σ" factor for a mean whose standard error was *estimated* from `blocks` block
/// averages: the 99.73 % two-sided quantile of Student's t with `blocks − 1` degrees of
/// freedom (3.45 for 20 blocks), so that a true null hypothesis fails with the
/// same 0.27 % probability as a 3σ test with a known error.
pub fn three_sigma_factor(blocks: usize) -> f64 {
    let t = StudentsT::new(0.0, 1.0, (blocks.max(2) - 1) as f64).expect("valid degrees of freedom");
    t.inverse_cdf(1.0 - 0.0027 / 2.0)
}

/// A conservative 3σ-equivalent tolerance for the mean of a slowly correlated series: the
/// largest of `three_sigma_factor(B)·SE_B` over B = 20, 10 and 5 blocks (a blocking analysis
/// that does not trust a plateau the run may be too short to reach). Returns (mean, tolerance).
pub fn conservative_tolerance(values: &[f64]) -> (f64, f64) {
    let (mean, _) = crate::observe::block_error(values, 20);
    let tolerance = [20, 10, 5]
        .iter()
        .map(|&b| three_sigma_factor(b) * crate::observe::block_error(values, b).1)
        .filter(|t| t.is_finite())
        .fold(0.0, f64::max);
    (mean, tolerance)
}

/// Bin edges for speed histograms: width 0.1 up to u = 5 (the tail beyond 5, where the
/// Rayleigh weight is 3.7·10⁻⁶, is folded into the last bin).
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

/// Rayleigh probability of each bin (the last bin open to +∞).
pub fn rayleigh_bin_probabilities(edges: &[f64]) -> Vec<f64> {
    let cdf = |u: f64| 1.0 - (-0.5 * u * u).exp();
    let k = edges.len() - 1;
    (0..k).map(|i| if i + 1 == k { 1.0 - cdf(edges[i]) } else { cdf(edges[i + 1]) - cdf(edges[i]) }).collect()
}

/// The H-function relative to equilibrium, H − H_eq = KL(p ‖ Rayleigh), from a histogram of
/// `u`, corrected for the histogram bias `(K − 1)/(2N)` (K occupied bins; physics sheet).
/// Its sampling standard deviation for a true Maxwellian is `√(2(K − 1))/(2N)` (2N·KL is
/// asymptotically χ² with K − 1 degrees of freedom).
pub fn h_function(u: &[f64]) -> (f64, f64) {
    let edges = speed_bins();
    let counts = histogram(u, &edges);
    let q = rayleigh_bin_probabilities(&edges);
    let n = u.len() as f64;
    let mut kl = 0.0;
    let mut occupied = 0usize;
    for (c, q) in counts.iter().zip(&q) {
        if *c > 0 {
            let p = *c as f64 / n;
            kl += p * (p / q).ln();
            occupied += 1;
        }
    }
    let k = occupied.max(1) as f64;
    (kl - (k - 1.0) / (2.0 * n), (2.0 * (k - 1.0)).sqrt() / (2.0 * n))
}

/// Sonine coefficient a₂ = ½⟨u⁴⟩/⟨u²⟩² − 1 (0 for a 2D Maxwellian, −½ for equal speeds) and
/// its standard error 1/√N for a Maxwellian (delta method with u² exponential:
/// Var(⟨u⁴⟩/⟨u²⟩²) = 4/N).
pub fn sonine_a2(u: &[f64]) -> (f64, f64) {
    let n = u.len() as f64;
    let m2 = u.iter().map(|x| x * x).sum::<f64>() / n;
    let m4 = u.iter().map(|x| x.powi(4)).sum::<f64>() / n;
    (0.5 * m4 / (m2 * m2) - 1.0, 1.0 / n.sqrt())
}

/// Kurtosis ⟨c⁴⟩/⟨c²⟩² of the pooled velocity components `c` (3 for a Gaussian) and its
/// standard error √(24/n) for n components (physics sheet).
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

    #[test]
    fn three_sigma_factor_tends_to_three() {
        assert!((three_sigma_factor(20) - 3.447).abs() < 0.001, "{}", three_sigma_factor(20));
        assert!((three_sigma_factor(100_000) - 3.0).abs() < 0.01);
    }

    #[test]
    fn equal_speeds_are_far_from_maxwellian() {
        let u = vec![2f64.sqrt(); 1000];
        assert!(ks_rayleigh(&u) > 0.3);
        assert!((sonine_a2(&u).0 + 0.5).abs() < 1e-12);
        assert!(h_function(&u).0 > 1.0);
    }

    #[test]
    fn rayleigh_quantiles_look_maxwellian() {
        // u at the mid-quantiles of the Rayleigh distribution: KS distance 1/(2n).
        let n = 2000;
        let u: Vec<f64> = (0..n).map(|i| (-2.0 * (1.0 - (i as f64 + 0.5) / n as f64).ln()).sqrt()).collect();
        assert!((ks_rayleigh(&u) - 0.5 / n as f64).abs() < 1e-9);
        assert!(sonine_a2(&u).0.abs() < 0.02);
        assert!(h_function(&u).0.abs() < 0.01);
    }
}
