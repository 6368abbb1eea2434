//! Error bars from block averages: the standard error of a correlated series' mean, from the
//! scatter of the means of consecutive blocks long enough to be nearly independent.

/// Mean and standard error of `values` from `blocks` consecutive blocks of equal length
/// (the first `len % blocks` values are dropped). The standard error of the block means,
/// `s/√B`, is honest when a block is longer than the correlation time of the series;
/// returns NaN for the error with fewer than two blocks.
pub fn block_error(values: &[f64], blocks: usize) -> (f64, f64) {
    let blocks = blocks.min(values.len());
    if blocks < 2 {
        let mean = values.iter().sum::<f64>() / values.len().max(1) as f64;
        return (mean, f64::NAN);
    }
    let size = values.len() / blocks;
    let used = &values[values.len() - size * blocks..];
    let means: Vec<f64> = used.chunks(size).map(|c| c.iter().sum::<f64>() / size as f64).collect();
    let mean = means.iter().sum::<f64>() / blocks as f64;
    let var = means.iter().map(|m| (m - mean).powi(2)).sum::<f64>() / (blocks - 1) as f64;
    (mean, (var / blocks as f64).sqrt())
}

/// The delete-one-block jackknife's standard error from the `B` estimates `θ₍ₖ₎`, each made
/// with block `k` left out: `σ² = (B − 1)/B · Σₖ(θ₍ₖ₎ − θ̄)²`. For a plain mean it is the
/// standard error of the block means, `s/√B`; for a nonlinear estimator (a ratio, a fitted
/// root, an exponentiated fit) it carries the error through without derivatives. NaN for
/// fewer than two estimates.
pub fn jackknife_error(leave_one_out: &[f64]) -> f64 {
    let b = leave_one_out.len() as f64;
    if leave_one_out.len() < 2 {
        return f64::NAN;
    }
    let mean = leave_one_out.iter().sum::<f64>() / b;
    ((b - 1.0) / b * leave_one_out.iter().map(|x| (x - mean).powi(2)).sum::<f64>()).sqrt()
}

#[cfg(test)]
mod tests {
    use super::{block_error, jackknife_error};

    /// For a mean, leaving out one block of equal length gives the block standard error
    /// exactly; one estimate gives NaN.
    #[test]
    fn jackknife_of_a_mean_is_the_block_error() {
        let values = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0];
        let (b, size) = (4, 2);
        let total: f64 = values.iter().sum();
        let leave: Vec<f64> = (0..b)
            .map(|k| (total - values[k * size..(k + 1) * size].iter().sum::<f64>()) / (values.len() - size) as f64)
            .collect();
        let (_, expected) = block_error(&values, b);
        assert!((jackknife_error(&leave) - expected).abs() < 1e-12, "{} vs {expected}", jackknife_error(&leave));
        assert!(jackknife_error(&[3.0]).is_nan());
    }

    #[test]
    fn block_error_of_known_series() {
        // Blocks of two: means 1.5, 3.5, 5.5, 7.5 → mean 4.5, sd 2.582, error 1.291.
        let (m, e) = block_error(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0], 4);
        assert_eq!(m, 4.5);
        assert!((e - (20.0f64 / 3.0).sqrt() / 2.0).abs() < 1e-12, "{e}");
        assert!(block_error(&[1.0], 4).1.is_nan());
    }
}
