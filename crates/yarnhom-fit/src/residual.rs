//! Residualization of fitted terms (thesis App. A.3.6, (A.37), (A.38); Alg. 4 line 20; Alg. 5
//! lines 27-34) on Hermite nodal data.
//!
//! The regularized fit `f*` of a term is converted to the residual that enters the sum (A.34a):
//! in 1D `f(θ) = f*(θ) - f*(0)`, in 2D
//! `f(θ_i, θ_j) = f*(θ_i, θ_j) - f*(θ_i, 0) - f*(0, θ_j) + f*(0, 0)`, so that fitting a term does
//! not change the terms fitted before (A.3.2). Both need a knot at 0 on every axis. Nodal
//! arrays in 2D are row-major with `v` outer (`[j * nu + i]`).

use crate::march::zero_knot_index;
use std::fmt;

/// An axis of a 2D term.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Axis {
    /// The first argument (`u`, the text's `x`).
    U,
    /// The second argument (`v`, the text's `y`).
    V,
}

/// Residualization needs a knot at 0 (A.3.2) and the axis has none.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct NoZeroKnot(pub Axis);

impl fmt::Display for NoZeroKnot {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "residualization needs a knot at 0 on axis {:?}", self.0)
    }
}

impl std::error::Error for NoZeroKnot {}

/// (A.37), Alg. 4 line 20: subtracts the value at the knot 0 from all values (slopes are
/// unchanged, the subtracted function being constant).
pub fn residualize_1d(knots: &[f64], values: &mut [f64]) -> Result<(), NoZeroKnot> {
    let i0 = zero_knot_index(knots).ok_or(NoZeroKnot(Axis::U))?;
    let at_zero = values[i0];
    values.iter_mut().for_each(|p| *p -= at_zero);
    Ok(())
}

/// (A.38), Alg. 5 lines 27-30: `r(u, v) = f(u, v) - f(u, 0) - f(0, v) + f(0, 0)` on the nodal data,
/// with `i0`, `j0` the knots at 0:
/// `p ← p_{i,j} - p_{i,j0} - p_{i0,j} + p_{i0,j0}`, `p^u ← p^u_{i,j} - p^u_{i,j0}`,
/// `p^v ← p^v_{i,j} - p^v_{i0,j}`, `p^{uv}` unchanged.
///
/// Alg. 5 lines 29-30 as printed subtract values from derivatives; the derivatives above are
/// the mathematically correct ones: `f(u, 0)` does not depend on `v` and `f(0, v)` not on `u`.
/// Because the bicubic Hermite patch is linear in its nodal data and reproduces functions of one
/// variable (with zero derivative in the other), the patch of the result is exactly the residual
/// of the patch, linear extrapolation included: it vanishes on `u = 0` and on `v = 0`.
pub fn residualize_2d(
    u_knots: &[f64],
    v_knots: &[f64],
    values: &mut [f64],
    du: &mut [f64],
    dv: &mut [f64],
) -> Result<(), NoZeroKnot> {
    let i0 = zero_knot_index(u_knots).ok_or(NoZeroKnot(Axis::U))?;
    let j0 = zero_knot_index(v_knots).ok_or(NoZeroKnot(Axis::V))?;
    let nu = u_knots.len();
    let row = |a: &[f64]| a[j0 * nu..(j0 + 1) * nu].to_vec();
    let column = |a: &[f64]| a.iter().skip(i0).step_by(nu).copied().collect::<Vec<_>>();
    let (p_row, p_column, du_row, dv_column) = (row(values), column(values), row(du), column(dv));
    let origin = values[j0 * nu + i0];
    for j in 0..v_knots.len() {
        for i in 0..nu {
            let n = j * nu + i;
            values[n] += origin - p_row[i] - p_column[j];
            du[n] -= du_row[i];
            dv[n] -= dv_column[j];
        }
    }
    Ok(())
}

/// The 0-compression residual (Alg. 5 lines 31-34, end of A.3.6): zeroes all nodal data
/// (`p`, `p^u`, `p^v`, `p^{uv}`) at nodes where an in-plane axis flagged as compressible (`s_x` or
/// `s_y`) is compressed, i.e. its knot is negative.
#[allow(clippy::too_many_arguments)]
pub fn zero_compressed(
    u_knots: &[f64],
    v_knots: &[f64],
    values: &mut [f64],
    du: &mut [f64],
    dv: &mut [f64],
    duv: &mut [f64],
    compressible_u: bool,
    compressible_v: bool,
) {
    let nu = u_knots.len();
    for (j, &v) in v_knots.iter().enumerate() {
        for (i, &u) in u_knots.iter().enumerate() {
            if (compressible_u && u < 0.0) || (compressible_v && v < 0.0) {
                let n = j * nu + i;
                for a in [&mut *values, &mut *du, &mut *dv, &mut *duv] {
                    a[n] = 0.0;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hermite::{Bicubic, Cubic};
    use crate::monotone_cubic::test_util::{Rng, linspace};

    fn random_patch(rng: &mut Rng) -> Bicubic {
        let u_knots = vec![-0.9, -0.45, 0.0, 0.3, 0.6, 0.9];
        let v_knots = vec![-0.8, 0.0, 0.25, 0.5];
        let n = u_knots.len() * v_knots.len();
        let mut wild = |s: f64| (0..n).map(|_| s * rng.normal()).collect::<Vec<f64>>();
        let (values, du, dv, duv) = (wild(1.0), wild(2.0), wild(2.0), wild(4.0));
        Bicubic { u_knots, v_knots, values, du, dv, duv }
    }

    #[test]
    fn residual_1d_vanishes_at_zero() {
        let knots = vec![-1.0, -0.4, 0.0, 0.5];
        let mut values = vec![3.0, 1.0, 0.7, 2.0];
        residualize_1d(&knots, &mut values).expect("zero knot");
        assert_eq!(values, vec![2.3, 1.0 - 0.7, 0.0, 2.0 - 0.7]);
        let f = Cubic { knots, values, slopes: vec![-1.0, -0.5, 0.1, 2.0] };
        assert_eq!(f.value(0.0), 0.0);
        assert_eq!(residualize_1d(&[-1.0, 0.5], &mut [0.0, 1.0]), Err(NoZeroKnot(Axis::U)));
    }

    #[test]
    fn residual_2d_vanishes_on_both_axes() {
        let mut rng = Rng::new(83);
        for _ in 0..10 {
            let f = random_patch(&mut rng);
            let mut r = f.clone();
            residualize_2d(&r.u_knots, &r.v_knots, &mut r.values, &mut r.du, &mut r.dv).expect("zero knots");
            for t in linspace(-2.0, 2.0, 401) {
                let (on_u, on_v) = (r.jet(t, 0.0), r.jet(0.0, t));
                assert!(on_u.value.abs() < 1e-12 && on_u.d1[0].abs() < 1e-11, "r({t}, 0) = {on_u:?}");
                assert!(on_v.value.abs() < 1e-12 && on_v.d1[1].abs() < 1e-11, "r(0, {t}) = {on_v:?}");
            }
            // f - r = f(u, 0) + f(0, v) - f(0, 0) has no mixed part
            let diff = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x - y).collect::<Vec<_>>();
            let s = Bicubic {
                u_knots: f.u_knots.clone(),
                v_knots: f.v_knots.clone(),
                values: diff(&f.values, &r.values),
                du: diff(&f.du, &r.du),
                dv: diff(&f.dv, &r.dv),
                duv: diff(&f.duv, &r.duv),
            };
            let h = 1e-4;
            for _ in 0..200 {
                let (u, v) = (rng.range(-1.5, 1.5), rng.range(-1.5, 1.5));
                let mixed = (s.value(u + h, v + h) - s.value(u + h, v - h) - s.value(u - h, v + h)
                    + s.value(u - h, v - h))
                    / (4.0 * h * h);
                assert!(mixed.abs() < 1e-6, "({u}, {v}): {mixed}");
                assert!(s.jet(u, v).d2[1].abs() < 1e-12);
                // and f - r really is f(u, 0) + f(0, v) - f(0, 0)
                let sep = f.value(u, 0.0) + f.value(0.0, v) - f.value(0.0, 0.0);
                assert!((s.value(u, v) - sep).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn residual_2d_needs_zero_knots() {
        let (u, v) = ([-1.0, 0.0, 1.0], [0.5, 1.0]);
        let mut a = [0.0; 6];
        let (mut b, mut c) = (a, a);
        assert_eq!(residualize_2d(&u, &v, &mut a, &mut b, &mut c), Err(NoZeroKnot(Axis::V)));
        assert_eq!(residualize_2d(&v, &u, &mut a, &mut b, &mut c), Err(NoZeroKnot(Axis::U)));
    }

    #[test]
    fn compressed_nodes_are_zeroed() {
        let mut rng = Rng::new(89);
        let f = random_patch(&mut rng);
        let nu = f.u_knots.len();
        for (cu, cv) in [(true, false), (false, true), (true, true), (false, false)] {
            let mut r = f.clone();
            zero_compressed(&r.u_knots, &r.v_knots, &mut r.values, &mut r.du, &mut r.dv, &mut r.duv, cu, cv);
            for (j, &v) in f.v_knots.iter().enumerate() {
                for (i, &u) in f.u_knots.iter().enumerate() {
                    let n = j * nu + i;
                    let zeroed = (cu && u < 0.0) || (cv && v < 0.0);
                    let data = [r.values[n], r.du[n], r.dv[n], r.duv[n]];
                    let original = [f.values[n], f.du[n], f.dv[n], f.duv[n]];
                    assert_eq!(data, if zeroed { [0.0; 4] } else { original });
                }
            }
        }
    }
}
