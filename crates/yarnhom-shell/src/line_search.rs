//! Backtracking (Armijo) line search along a Newton direction, shared by the implicit Euler
//! steps ([`crate::integrator`]) and the static solves ([`crate::statics`]).

use nalgebra::Vector3;

/// Halve the step from 1 until `value(x + α dx) <= value0 + 1e-4 α slope` (at most 30
/// halvings). Returns the step length, the halvings, and the value at the accepted point
/// (`None` if no step was accepted: then the smallest step tried).
pub(crate) fn backtrack(
    x: &[Vector3<f64>],
    dx: &[f64],
    value0: f64,
    slope: f64,
    value: impl Fn(&[Vector3<f64>]) -> f64,
) -> (f64, u32, Option<f64>) {
    let mut alpha = 1.0;
    for halvings in 0..30 {
        let trial: Vec<_> = x
            .iter()
            .zip(dx.chunks_exact(3))
            .map(|(p, d)| p + alpha * Vector3::new(d[0], d[1], d[2]))
            .collect();
        let v = value(&trial);
        if v.is_finite() && v <= value0 + 1e-4 * alpha * slope {
            return (alpha, halvings, Some(v));
        }
        alpha *= 0.5;
    }
    (alpha, 30, None)
}
