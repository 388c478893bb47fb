//! Summary statistics shared by every stage: root mean square, mean, Pearson correlation.
//!
//! One definition each, so that a figure printed by one command (a fit's relative RMS error, a
//! calibration's error per direction, a mirror distance) means what the same word means in
//! another. Sums run in the order of the values, so results are bit-identical wherever the same
//! values come in the same order.

/// Root mean square `sqrt(Σ x² / n)` of `values`; 0 for none.
pub fn root_mean_square(values: impl IntoIterator<Item = f64>) -> f64 {
    let (sum, n) = values.into_iter().fold((0.0, 0usize), |(sum, n), x| (sum + x * x, n + 1));
    (sum / n.max(1) as f64).sqrt()
}

/// Arithmetic mean of `values`; NaN for none.
pub fn mean(values: &[f64]) -> f64 {
    values.iter().sum::<f64>() / values.len() as f64
}

/// Pearson correlation of two equally long series: 1 for the same shape up to a positive
/// scale and offset, -1 for a mirrored one; NaN when either is constant.
pub fn correlation(a: &[f64], b: &[f64]) -> f64 {
    let (ma, mb) = (mean(a), mean(b));
    let cov: f64 = a.iter().zip(b).map(|(x, y)| (x - ma) * (y - mb)).sum();
    let va: f64 = a.iter().map(|x| (x - ma).powi(2)).sum();
    let vb: f64 = b.iter().map(|y| (y - mb).powi(2)).sum();
    cov / (va * vb).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn root_mean_square_of_a_constant_is_its_magnitude_and_of_nothing_zero() {
        assert_eq!(root_mean_square([-3.0; 7]), 3.0);
        assert_eq!(root_mean_square([3.0, 4.0].iter().copied()), (12.5_f64).sqrt());
        assert_eq!(root_mean_square(std::iter::empty()), 0.0);
    }

    #[test]
    fn correlation_ignores_scale_and_offset_and_sees_mirrors() {
        let a = [0.0, 1.0, 4.0, 9.0];
        let b: Vec<f64> = a.iter().map(|x| 2.5 * x - 7.0).collect();
        let c: Vec<f64> = a.iter().map(|x| -x).collect();
        assert!((correlation(&a, &b) - 1.0).abs() < 1e-15);
        assert!((correlation(&a, &c) + 1.0).abs() < 1e-15);
        assert!(correlation(&a, &[1.0; 4]).is_nan());
    }
}
