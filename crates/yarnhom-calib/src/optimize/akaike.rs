//! The Akaike information criterion of a least-squares fit, `n ln(RSS/n) + 2k`: the diagnosis
//! and the yarn-level confirmation compare a nested extension with its base by it, so that a
//! parameter must buy a lower residual to pay off.

/// The Akaike criterion of residuals `r` of a model with `parameters` fitted parameters,
/// `n ln(RSS/n) + 2k`.
pub fn criterion(r: &[f64], parameters: usize) -> f64 {
    let n = r.len().max(1) as f64;
    n * (r.iter().map(|x| x * x).sum::<f64>() / n).max(1e-300).ln() + 2.0 * parameters as f64
}
