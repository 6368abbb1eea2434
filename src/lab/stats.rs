//! The statistics of the checks: how wide a tolerance must be for a true hypothesis to pass
//! with a stated probability, given an error estimated from the data. (The velocity
//! statistics themselves — KS distance, H-function, a₂, kurtosis — are the estimators of the
//! [`velocities`](crate::observe::velocities) observable.)

use statrs::distribution::{ContinuousCDF, StudentsT};

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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn three_sigma_factor_tends_to_three() {
        assert!((three_sigma_factor(20) - 3.447).abs() < 0.001, "{}", three_sigma_factor(20));
        assert!((three_sigma_factor(100_000) - 3.0).abs() < 0.01);
    }
}
