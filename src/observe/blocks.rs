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

#[cfg(test)]
mod tests {
    use super::block_error;

    #[test]
    fn block_error_of_known_series() {
        // Blocks of two: means 1.5, 3.5, 5.5, 7.5 → mean 4.5, sd 2.582, error 1.291.
        let (m, e) = block_error(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0], 4);
        assert_eq!(m, 4.5);
        assert!((e - (20.0f64 / 3.0).sqrt() / 2.0).abs() < 1e-12, "{e}");
        assert!(block_error(&[1.0], 4).1.is_nan());
    }
}
