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

/// A straight line `y = a + b·x` fitted by least squares.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LineFit {
    /// The intercept `a`.
    pub intercept: f64,
    /// The slope `b`.
    pub slope: f64,
    /// The number of points.
    pub points: usize,
}

impl LineFit {
    /// Where the line crosses zero, `x₀ = −a/b`.
    pub fn root(&self) -> f64 {
        -self.intercept / self.slope
    }
}

/// The least-squares line through `(x, y)` (faer's QR of the design matrix `[1 x]`; the
/// abscissae are centred first, so that the columns are well conditioned however narrow
/// their range). None with fewer than 3 points or all `x` equal.
pub fn fit_line(points: &[(f64, f64)]) -> Option<LineFit> {
    use faer::linalg::solvers::SolveLstsq;
    let n = points.len();
    if n < 3 {
        return None;
    }
    let centre = points.iter().map(|p| p.0).sum::<f64>() / n as f64;
    if points.iter().all(|p| p.0 == centre) {
        return None;
    }
    let design = faer::Mat::<f64>::from_fn(n, 2, |i, j| if j == 0 { 1.0 } else { points[i].0 - centre });
    let rhs = faer::Mat::<f64>::from_fn(n, 1, |i, _| points[i].1);
    let solution = design.qr().solve_lstsq(&rhs);
    let (a, b) = (solution[(0, 0)], solution[(1, 0)]);
    Some(LineFit { intercept: a - b * centre, slope: b, points: n })
}

/// The root `x₀ = −a/b` of the least-squares line through `points`, with its standard error
/// from the delete-one-block jackknife over `blocks` contiguous blocks (which, unlike the
/// textbook covariance, holds for points whose errors are correlated along the series, as
/// successive pressure windows of one compression are): `σ² = (B−1)/B·Σ(x₀₍ₖ₎ − x̄₀)²`.
/// Returns (the line, x₀, σ).
pub fn line_root_with_error(points: &[(f64, f64)], blocks: usize) -> Option<(LineFit, f64, f64)> {
    let fit = fit_line(points)?;
    let size = points.len() / blocks;
    if blocks < 2 || size == 0 {
        return None;
    }
    let mut roots = Vec::with_capacity(blocks);
    for k in 0..blocks {
        let end = if k + 1 == blocks { points.len() } else { (k + 1) * size };
        let rest: Vec<(f64, f64)> = points[..k * size].iter().chain(&points[end..]).copied().collect();
        roots.push(fit_line(&rest)?.root());
    }
    Some((fit, fit.root(), crate::observe::blocks::jackknife_error(&roots)))
}

/// The mean of independent values and its standard error (sample standard deviation over
/// √n; NaN for fewer than two).
pub fn mean_and_error(values: &[f64]) -> (f64, f64) {
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    if values.len() < 2 {
        return (mean, f64::NAN);
    }
    let variance = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, (variance / n).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An exact line is recovered to rounding, far from the origin too; noise of known size
    /// gives a jackknife error of the size the textbook formula predicts for independent
    /// points.
    #[test]
    fn lines_and_their_roots() {
        let points: Vec<(f64, f64)> = (0..50).map(|i| (0.84 + i as f64 * 1e-4, 2.0 - 3.0 * i as f64)).collect();
        let fit = fit_line(&points).unwrap();
        assert!((fit.slope + 3e4).abs() < 1e-6 * 3e4, "{fit:?}");
        assert!((fit.root() - (0.84 + 2.0 / 3.0 * 1e-4)).abs() < 1e-12, "{}", fit.root());
        assert!(fit_line(&points[..2]).is_none());
        assert!(fit_line(&[(1.0, 1.0), (1.0, 2.0), (1.0, 3.0)]).is_none());
        // y = 1 − x plus independent Gaussian noise of 0.01: the root 1 to within its error,
        // the jackknife error near the textbook σ(x₀) = σ_y/|b|·√(1/n + (x₀ − x̄)²/Sxx).
        use rand::SeedableRng;
        use rand_distr::{Distribution, Normal};
        let mut rng = rand::rngs::Xoshiro256PlusPlus::seed_from_u64(7);
        let normal = Normal::new(0.0, 0.01).unwrap();
        let noisy: Vec<(f64, f64)> =
            (0..400).map(|i| (i as f64 / 800.0, 1.0 - i as f64 / 800.0 + normal.sample(&mut rng))).collect();
        let (_, root, error) = line_root_with_error(&noisy, 10).unwrap();
        let (n, xbar) = (400.0, 399.0 / 1600.0);
        let sxx: f64 = noisy.iter().map(|p| (p.0 - xbar).powi(2)).sum();
        let textbook = 0.01 * (1.0 / n + (1.0 - xbar).powi(2) / sxx).sqrt();
        assert!((root - 1.0).abs() < 3.0 * textbook, "{root}");
        assert!(error > 0.3 * textbook && error < 3.0 * textbook, "{error} vs {textbook}");
    }

    #[test]
    fn three_sigma_factor_tends_to_three() {
        assert!((three_sigma_factor(20) - 3.447).abs() < 0.001, "{}", three_sigma_factor(20));
        assert!((three_sigma_factor(100_000) - 3.0).abs() < 0.01);
    }
}
