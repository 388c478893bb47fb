//! Quasiconvex marching (thesis App. A.3.4, (A.36); Alg. 4 lines 9-19; Alg. 5 lines 10-25) and
//! the boundary clamps for increasing extrapolation (App. A.3.5).
//!
//! Starting from the minimum node, values and first derivatives are projected outward so that
//! the data increases away from the minimum by at least `p_min` per unit strain and the slopes
//! point away from it with magnitude at least `p_min`. After the monotone cubic/bicubic step the
//! interpolant then has a single minimum (per grid line in 2D) and increases outward, also in
//! linear extrapolation.
//!
//! Nodal arrays in 2D are row-major with `v` outer (`[j * nu + i]`); the text's `x`/`y` are
//! `u`/`v`.

use crate::monotone_cubic::limit_slopes_monotone;

/// `p_min^x` of Alg. 4 line 9 / Alg. 5 line 11 for all patterns but stockinette.
pub const MIN_SLOPE: f64 = 0.001;

/// `p_min^x` for the stockinette pattern (Alg. 4 line 9 / Alg. 5 line 11).
pub const MIN_SLOPE_STOCKINETTE: f64 = 0.01;

/// Relative tolerance (to the largest knot magnitude) for recognising the knot at 0.
const ZERO_KNOT_TOLERANCE: f64 = 1e-12;

/// The index of the smallest value (the first on ties; NaN is skipped), the bending minimum of
/// Alg. 4 line 13. 0 for empty or all-NaN input.
pub fn bending_minimum_index(values: &[f64]) -> usize {
    let mut best = 0;
    for (i, &p) in values.iter().enumerate() {
        if p < values[best] || values[best].is_nan() {
            best = i;
        }
    }
    best
}

/// The bending minimum along the line `u = u_{i_min}` of a grid with `nu` nodes per row:
/// `argmin_j p(x_{i_min}, y_j)` (Alg. 5 line 16).
pub fn bending_minimum_row(values: &[f64], nu: usize, i_min: usize) -> usize {
    let column: Vec<f64> = values.iter().skip(i_min).step_by(nu.max(1)).copied().collect();
    bending_minimum_index(&column)
}

/// The index of the knot at 0 (`x_{i_min} = 0`, Alg. 4 line 11 / Alg. 5 lines 12, 14; required
/// by A.3.2): the knot nearest 0 if it is 0 up to rounding (`1e-12` of the largest knot
/// magnitude), else `None`.
pub fn zero_knot_index(knots: &[f64]) -> Option<usize> {
    let scale = knots.iter().fold(0.0_f64, |m, t| m.max(t.abs()));
    let nearest = bending_minimum_index(&knots.iter().map(|t| t.abs()).collect::<Vec<_>>());
    knots.get(nearest).filter(|t| t.abs() <= ZERO_KNOT_TOLERANCE * scale).map(|_| nearest)
}

/// The slope projection of (A.36b): at least `min_slope` away from the minimum in direction
/// `side` (`+1` beyond it, `-1` before it, `0` at it, where the slope becomes 0).
fn slope_away(slope: f64, side: i32, min_slope: f64) -> f64 {
    match side {
        1 => slope.max(min_slope),
        -1 => slope.min(-min_slope),
        _ => 0.0,
    }
}

/// Which side of `i_min` index `i` is on: `+1`, `-1` or `0`.
fn side(i: usize, i_min: usize) -> i32 {
    (i as i32 - i_min as i32).signum()
}

/// Quasiconvex marching in 1D (Alg. 4 lines 15-17, (A.36)): marching outward from `i_min`,
/// `p_{i+1} ≥ p_i + (x_{i+1} - x_i) p_min` to the right and `p_{i-1} ≥ p_i + (x_i - x_{i-1}) p_min`
/// to the left; `p^x_i ≥ p_min` for `i > i_min` and `p^x_i ≤ -p_min` for `i < i_min`.
///
/// The slope at the minimum knot is set to 0: the monotone cubic step forces that anyway, its
/// two secants having opposite signs after marching. Finally the boundary slopes are made to
/// point outward ([`clamp_boundary_for_extrapolation_1d`]); this only matters if `i_min` is an
/// end knot, and must be repeated after [`limit_slopes_monotone`], which zeroes an outward
/// slope at a minimum end knot (Alg. 4 orders it so: line 19 after line 18; see
/// [`quasiconvexify_1d`]).
pub fn march_1d(knots: &[f64], values: &mut [f64], slopes: &mut [f64], i_min: usize, min_slope: f64) {
    let n = knots.len();
    for i in i_min..n.saturating_sub(1) {
        raise_from(values, i + 1, i, (knots[i + 1] - knots[i]) * min_slope);
    }
    for i in (1..=i_min.min(n.saturating_sub(1))).rev() {
        raise_from(values, i - 1, i, (knots[i] - knots[i - 1]) * min_slope);
    }
    for (i, slope) in slopes.iter_mut().enumerate() {
        *slope = slope_away(*slope, side(i, i_min), min_slope);
    }
    clamp_boundary_for_extrapolation_1d(slopes, min_slope);
}

/// Increasing linear extrapolation in 1D (Alg. 4 line 19, A.3.5): the first slope at most
/// `-p_min`, the last at least `p_min`, so the energy grows outward on both sides.
///
/// If the minimum is the first (last) knot, the first (last) interval then dips slightly below
/// the minimum knot before rising; its derivative changes sign once there, so the spline still
/// has a single minimum.
pub fn clamp_boundary_for_extrapolation_1d(slopes: &mut [f64], min_slope: f64) {
    if let Some(first) = slopes.first_mut() {
        *first = first.min(-min_slope);
    }
    if let Some(last) = slopes.last_mut() {
        *last = last.max(min_slope);
    }
}

/// The QUASICONVEXIFY block of Alg. 4 (lines 15-19): [`march_1d`], the monotone cubic
/// algorithm ([`limit_slopes_monotone`]) and the boundary clamp, in this order.
pub fn quasiconvexify_1d(
    knots: &[f64],
    values: &mut [f64],
    slopes: &mut [f64],
    i_min: usize,
    min_slope: f64,
) {
    march_1d(knots, values, slopes, i_min, min_slope);
    limit_slopes_monotone(knots, values, slopes);
    clamp_boundary_for_extrapolation_1d(slopes, min_slope);
}

/// Indices of `0..n` ordered outward from `start`: `start, start+1, …, n-1, start-1, …, 0`.
fn outward(start: usize, n: usize) -> impl Iterator<Item = usize> {
    (start..n).chain((0..start.min(n)).rev())
}

/// Quasiconvex marching in 2D (Alg. 5 lines 18-22): marching outward from `(i_min, j_min)`,
/// every node is raised to exceed its inward neighbour along `u` by `h p_min` and along `v` by
/// `k p_min`, with `h`, `k` the spacing along the marching direction; `p^u ≥ p_min` right of
/// `i_min`, `≤ -p_min` left of it, and `p^v` likewise about `j_min`.
///
/// Alg. 5 as printed pairs line 19 (`p_{i+1,j}`, a step in `x`) with the `y` spacing and line 20
/// with the `x` spacing, and the sign conditions of lines 21-22 with the other axis' index; we
/// implement the evident intent: spacing and sign along the marching direction.
///
/// Every row and column is marched (not only the two through the minimum), in an order in
/// which each node's inward neighbours are final when it is visited, so one pass satisfies all
/// constraints. `p^u` on the column `i = i_min` and `p^v` on the row `j = j_min` are set to 0
/// (the monotone bicubic step would force this for an interior minimum). `p^{uv}` is left to
/// the monotone bicubic step.
#[allow(clippy::too_many_arguments)]
pub fn march_2d(
    u_knots: &[f64],
    v_knots: &[f64],
    values: &mut [f64],
    du: &mut [f64],
    dv: &mut [f64],
    i_min: usize,
    j_min: usize,
    min_slope: f64,
) {
    let nu = u_knots.len();
    for j in outward(j_min, v_knots.len()) {
        for i in outward(i_min, nu) {
            let n = j * nu + i;
            let (si, sj) = (side(i, i_min), side(j, j_min));
            if si != 0 {
                let inner = if si > 0 { i - 1 } else { i + 1 };
                raise_from(values, n, j * nu + inner, (u_knots[i] - u_knots[inner]).abs() * min_slope);
            }
            if sj != 0 {
                let inner = if sj > 0 { j - 1 } else { j + 1 };
                raise_from(values, n, inner * nu + i, (v_knots[j] - v_knots[inner]).abs() * min_slope);
            }
            du[n] = slope_away(du[n], si, min_slope);
            dv[n] = slope_away(dv[n], sj, min_slope);
        }
    }
}

/// The value projection (A.36a) for one node: `p[n] ← max(p[n], p[inner] + step)`.
fn raise_from(values: &mut [f64], n: usize, inner: usize, step: f64) {
    values[n] = values[n].max(values[inner] + step);
}

/// Increasing extrapolation in 2D (Alg. 5 lines 23-25, A.3.5): on the boundary the outward
/// normal derivative points outward-increasing (`p^u ≤ -p_min` on the first column, `≥ p_min` on
/// the last; `p^v` likewise on the first and last rows) and `p^{uv} = 0` on all boundary nodes,
/// so that the linear extrapolation is consistent with the interpolation.
///
/// Pass `min_slope = 0` for merely non-decreasing extrapolation (e.g. `f_13`, A.3.5). The
/// monotone bicubic step (applied afterwards, Alg. 5 line 26) keeps these slopes where the data
/// rises towards the boundary, as after marching about an interior minimum; where it does not
/// (the minimum on that boundary, or unmarched data such as `f_13`), (B.2) flattens them to 0,
/// and extrapolation there is constant in the outward direction.
pub fn clamp_boundary_for_extrapolation_2d(
    u_knots: &[f64],
    v_knots: &[f64],
    du: &mut [f64],
    dv: &mut [f64],
    duv: &mut [f64],
    min_slope: f64,
) {
    let (nu, nv) = (u_knots.len(), v_knots.len());
    for j in 0..nv {
        for i in 0..nu {
            let n = j * nu + i;
            if i == 0 {
                du[n] = du[n].min(-min_slope);
            }
            if i + 1 == nu {
                du[n] = du[n].max(min_slope);
            }
            if j == 0 {
                dv[n] = dv[n].min(-min_slope);
            }
            if j + 1 == nv {
                dv[n] = dv[n].max(min_slope);
            }
            if i == 0 || j == 0 || i + 1 == nu || j + 1 == nv {
                duv[n] = 0.0;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hermite::{Bicubic, Cubic};
    use crate::monotone_bicubic::make_monotone_bicubic;
    use crate::monotone_cubic::test_util::{Rng, linspace, random_knots};

    /// Whether `samples` (ordered) decrease, then increase, with one turn; strictly beyond `tol`.
    fn is_unimodal(samples: &[f64], tol: f64) -> bool {
        let diffs: Vec<f64> = samples.windows(2).map(|w| w[1] - w[0]).collect();
        let turn = diffs.iter().position(|&d| d > tol).unwrap_or(diffs.len());
        diffs[turn..].iter().all(|&d| d >= -tol) && diffs[..turn].iter().all(|&d| d <= tol)
    }

    /// Values of `f` on a dense sample of `[a, b]`.
    fn dense(f: impl Fn(f64) -> f64, a: f64, b: f64) -> Vec<f64> {
        linspace(a, b, 2000).into_iter().map(f).collect()
    }

    #[test]
    fn zero_and_minimum_indices() {
        assert_eq!(zero_knot_index(&[-1.0, -0.5, 0.0, 0.7]), Some(2));
        assert_eq!(zero_knot_index(&[-1.0, 1e-17, 0.7]), Some(1));
        assert_eq!(zero_knot_index(&[-1.0, 0.1, 0.7]), None);
        assert_eq!(bending_minimum_index(&[3.0, 1.0, 2.0, 1.0]), 1);
        assert_eq!(bending_minimum_index(&[f64::NAN, 2.0, 5.0]), 1);
        // 3 × 2 grid: column i = 1 holds 4.0 (j = 0) and 2.0 (j = 1)
        assert_eq!(bending_minimum_row(&[0.0, 4.0, 0.0, 0.0, 2.0, 0.0], 3, 1), 1);
    }

    #[test]
    fn marching_enforces_a36() {
        let mut rng = Rng::new(61);
        for trial in 0..100 {
            let n = 2 + trial % 9;
            let knots = random_knots(&mut rng, n, (-3.0, 0.0));
            let mut values: Vec<f64> = (0..n).map(|_| rng.range(-1.0, 1.0)).collect();
            let mut slopes: Vec<f64> = (0..n).map(|_| rng.normal()).collect();
            let i_min = (rng.unit() * n as f64) as usize;
            let p_min = 0.05;
            march_1d(&knots, &mut values, &mut slopes, i_min, p_min);
            for i in 0..n - 1 {
                let step = (knots[i + 1] - knots[i]) * p_min;
                if i >= i_min {
                    assert!(values[i + 1] >= values[i] + step - 1e-15);
                } else {
                    assert!(values[i] >= values[i + 1] + step - 1e-15);
                }
            }
            for (i, &m) in slopes.iter().enumerate() {
                assert!(i == i_min || (i > i_min && m >= p_min) || (i < i_min && m <= -p_min));
            }
        }
    }

    #[test]
    fn quasiconvex_cubic_has_one_minimum_and_grows_outward() {
        let mut rng = Rng::new(67);
        for trial in 0..200 {
            let n = 2 + trial % 11;
            let knots = random_knots(&mut rng, n, (-4.0, 0.0));
            let mut values: Vec<f64> = (0..n).map(|_| rng.range(-1.0, 1.0)).collect();
            let mut slopes: Vec<f64> = (0..n).map(|_| 3.0 * rng.normal()).collect();
            let i_min = match trial % 4 {
                0 => 0,
                1 => n - 1,
                _ => bending_minimum_index(&values),
            };
            let p_min = if trial % 2 == 0 { MIN_SLOPE } else { MIN_SLOPE_STOCKINETTE };
            quasiconvexify_1d(&knots, &mut values, &mut slopes, i_min, p_min);
            let f = Cubic { knots: knots.clone(), values, slopes };
            let (a, b) = (knots[0] - 2.0, knots[n - 1] + 2.0);
            let samples = dense(|x| f.value(x), a, b);
            assert!(is_unimodal(&samples, 1e-13), "trial {trial}: {f:?}");
            assert!(f.jet(a).d1 <= -p_min && f.jet(b).d1 >= p_min, "trial {trial}");
            let lowest = samples.iter().cloned().fold(f64::INFINITY, f64::min);
            assert!(samples[0] > lowest && samples[samples.len() - 1] > lowest);
        }
    }

    /// A random grid with an interior node `(i_min, j_min)`, marched, clamped and monotonized as
    /// in Alg. 5 lines 18-26.
    fn quasiconvex_patch(rng: &mut Rng, nu: usize, nv: usize, p_min: f64) -> (Bicubic, usize, usize) {
        let u_knots = random_knots(rng, nu, (-3.0, -1.0));
        let v_knots = random_knots(rng, nv, (-3.0, -1.0));
        let n = nu * nv;
        let mut values: Vec<f64> = (0..n).map(|_| rng.range(-1.0, 1.0)).collect();
        let mut wild = |s: f64| (0..n).map(|_| s * rng.normal()).collect::<Vec<f64>>();
        let (mut du, mut dv, mut duv) = (wild(2.0), wild(2.0), wild(5.0));
        let i_min = 1 + (rng.unit() * (nu - 2) as f64) as usize;
        let j_min = 1 + (rng.unit() * (nv - 2) as f64) as usize;
        march_2d(&u_knots, &v_knots, &mut values, &mut du, &mut dv, i_min, j_min, p_min);
        clamp_boundary_for_extrapolation_2d(&u_knots, &v_knots, &mut du, &mut dv, &mut duv, p_min);
        make_monotone_bicubic(&u_knots, &v_knots, &values, &mut du, &mut dv, &mut duv);
        (Bicubic { u_knots, v_knots, values, du, dv, duv }, i_min, j_min)
    }

    #[test]
    fn marched_patch_increases_away_from_the_minimum_along_grid_lines() {
        let mut rng = Rng::new(71);
        for trial in 0..40 {
            let (nu, nv) = (3 + trial % 5, 3 + (trial / 5) % 4);
            let p_min = 0.01;
            let (f, i_min, j_min) = quasiconvex_patch(&mut rng, nu, nv, p_min);
            let (ua, ub) = (f.u_knots[0] - 2.0, f.u_knots[nu - 1] + 2.0);
            let (va, vb) = (f.v_knots[0] - 2.0, f.v_knots[nv - 1] + 2.0);
            // every line v = const through a node row (and some others), along u
            let mut vs = f.v_knots.clone();
            vs.extend([va, vb, 0.5 * (f.v_knots[0] + f.v_knots[1])]);
            for &v in &vs {
                let samples = dense(|u| f.value(u, v), ua, ub);
                assert!(is_unimodal(&samples, 1e-12), "trial {trial}, v = {v}");
                assert!(f.jet(ua, v).d1[0] < 0.0 && f.jet(ub, v).d1[0] > 0.0, "trial {trial}, v = {v}");
            }
            let mut us = f.u_knots.clone();
            us.extend([ua, ub]);
            for &u in &us {
                let samples = dense(|v| f.value(u, v), va, vb);
                assert!(is_unimodal(&samples, 1e-12), "trial {trial}, u = {u}");
                assert!(f.jet(u, va).d1[1] < 0.0 && f.jet(u, vb).d1[1] > 0.0, "trial {trial}, u = {u}");
            }
            // the lines through the minimum turn exactly at the minimum node
            let (u0, v0) = (f.u_knots[i_min], f.v_knots[j_min]);
            let jet = f.jet(u0, v0);
            assert!(jet.d1[0].abs() < 1e-14 && jet.d1[1].abs() < 1e-14);
            assert!(f.jet(f.u_knots[nu - 1], v0).d1[0] >= p_min - 1e-15);
            assert!(f.jet(u0, f.v_knots[0]).d1[1] <= -p_min + 1e-15);
        }
    }

    #[test]
    fn march_2d_makes_nodal_data_increase_outward() {
        let mut rng = Rng::new(73);
        let (nu, nv, p_min) = (6, 5, 0.02);
        let u_knots = random_knots(&mut rng, nu, (-2.0, 0.0));
        let v_knots = random_knots(&mut rng, nv, (-2.0, 0.0));
        let mut values: Vec<f64> = (0..nu * nv).map(|_| rng.range(-1.0, 1.0)).collect();
        let (mut du, mut dv) = (vec![0.3; nu * nv], vec![-0.3; nu * nv]);
        let (i_min, j_min) = (2, 3);
        march_2d(&u_knots, &v_knots, &mut values, &mut du, &mut dv, i_min, j_min, p_min);
        for j in 0..nv {
            for i in 0..nu {
                let n = j * nu + i;
                if i + 1 < nu {
                    let rise = (values[n + 1] - values[n]) / (u_knots[i + 1] - u_knots[i]);
                    assert!(if i >= i_min { rise >= p_min - 1e-12 } else { rise <= -p_min + 1e-12 });
                }
                if j + 1 < nv {
                    let rise = (values[n + nu] - values[n]) / (v_knots[j + 1] - v_knots[j]);
                    assert!(if j >= j_min { rise >= p_min - 1e-12 } else { rise <= -p_min + 1e-12 });
                }
                assert_eq!(
                    du[n],
                    if i > i_min {
                        0.3
                    } else if i < i_min {
                        -p_min
                    } else {
                        0.0
                    }
                );
                assert_eq!(
                    dv[n],
                    if j > j_min {
                        p_min
                    } else if j < j_min {
                        -0.3
                    } else {
                        0.0
                    }
                );
            }
        }
    }
}
