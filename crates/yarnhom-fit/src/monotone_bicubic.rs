//! Piecewise monotone bicubic Hermite interpolation, thesis App. B (after Carlson and Fritsch
//! 1989, modified for data that is monotone only locally), with the extrapolation rule of
//! App. A.3.5.
//!
//! Nodal arrays are row-major with `v` outer (`[j * nu + i]`), as in [`crate::hermite::Bicubic`].
//! The text's `x`/`y` are `u`/`v`. Everything is written for monotonicity in `x` and applied a
//! second time to the transposed problem (a `Layout` that swaps the roles of the axes, with
//! `p^x` and `p^y` swapped), exactly as App. B prescribes.
//!
//! Steps of [`make_monotone_bicubic`]:
//! 1. (B.2): clamp `p^x` per horizontal edge and `p^y` per vertical edge
//!    ([`crate::monotone_cubic`]'s Fritsch–Carlson box).
//! 2. (B.6), (B.7): on every horizontal edge project the pair `(p^y_{i,j}, p^y_{i+1,j})` into the
//!    slab `l ≤ Δ^x p^y ≤ u` ([`project_to_slab`], Figure B.1), sweeping each row forward then
//!    backward; then the same for `Δ^y p^x` on vertical edges, with `b` of (B.7) computed from
//!    the *old* `p^y` (after step 1, before step 2) so that the result does not depend on which
//!    direction is treated first.
//! 3. (B.8): clamp `p^{xy}` at every node to the bounds from each adjacent cell, then likewise
//!    for the transposed problem.

use crate::monotone_cubic::{clamp_between, slope_bound};

/// How the missing cells beyond the boundary enter (B.6) and (B.7).
///
/// App. A.3.5 treats extrapolation "as a cell with an edge at infinity", so that "the
/// extrapolated side of the inequality become\[s\] 0". Our reading: in (B.6)/(B.7) a missing
/// neighbour cell `R_{i,j-1}` (or `R_{i,j}`) has spacing `k_{j-1} = ∞` (or `k_j = ∞`), so its
/// bound `3 Δ^x p / k` (or `b / k`) is 0: along a boundary row, `Δ^x p^y` must have the sense
/// of the edge on the inner side and is bounded by 0 on the outer one. This is exactly what
/// makes the linear extrapolation `f(u, v_top) + (v - v_top) p^y(u, v_top)` monotone in `u`
/// for every `v > v_top`: `∂_u p^y(u, v_top)` must have the sense of the edge. (With
/// `p^{xy} = 0` on the boundary, A.3.5 and Alg. 5 line 25, `p^y(u, v_top)` is then monotone
/// between its nodal values, and it is the caller's job to set that; the limit `k → ∞` of
/// (B.8) would require exactly this Fritsch–Carlson condition of the tangent function, which
/// `p^{xy} = 0` meets.) Cells beyond the boundary impose no (B.8) constraints.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Boundary {
    /// A.3.5: the missing cell's side of (B.6)/(B.7) becomes 0 (monotone linear extrapolation).
    Extrapolated,
    /// No constraint from missing cells (monotone only inside the knots).
    Open,
}

/// Most forward-and-backward sweep pairs per row in step 2. The text makes one pair, which
/// suffices whenever the derivatives along a row share one sign (e.g. globally monotone
/// data, see [`project_row`]); with mixed signs further pairs are made until every edge is
/// feasible. Magnitudes only shrink, so the iteration converges to a feasible point.
const MAX_SWEEP_PAIRS: usize = 64;

/// Relative slack when checking a slab constraint after projection (rounding only).
const SLAB_TOLERANCE: f64 = 1e-12;

/// Index arithmetic for the "monotonicity in x" operations, on the grid or its transpose.
///
/// `x`, `y` are the knots along the operation's `x` and `y`; in the transposed view `x` is the
/// stored `v` axis and node `(i, j)` is stored at `[i * nu + j]`.
#[derive(Debug, Clone, Copy)]
struct Layout<'a> {
    x: &'a [f64],
    y: &'a [f64],
    transposed: bool,
}

impl<'a> Layout<'a> {
    /// The layout for monotonicity in `u` (`transposed = false`) or in `v` (`true`).
    fn new(u_knots: &'a [f64], v_knots: &'a [f64], transposed: bool) -> Self {
        if transposed {
            Layout { x: v_knots, y: u_knots, transposed }
        } else {
            Layout { x: u_knots, y: v_knots, transposed }
        }
    }

    /// Storage index of node `(i, j)` (`i` along `x`).
    fn at(&self, i: usize, j: usize) -> usize {
        if self.transposed { i * self.y.len() + j } else { j * self.x.len() + i }
    }

    /// `h_i = x_{i+1} - x_i`.
    fn h(&self, i: usize) -> f64 {
        self.x[i + 1] - self.x[i]
    }

    /// `k_j = y_{j+1} - y_j`, or `None` (a cell at infinity) outside the grid.
    fn k(&self, j: Option<usize>) -> Option<f64> {
        j.filter(|&j| j + 1 < self.y.len()).map(|j| self.y[j + 1] - self.y[j])
    }

    /// `Δ^x f_{i,j}` (B.1a) of nodal data `f`.
    fn dx(&self, f: &[f64], i: usize, j: usize) -> f64 {
        f[self.at(i + 1, j)] - f[self.at(i, j)]
    }
}

/// Makes the bicubic Hermite patch monotone in every cell where its data is monotone, with
/// monotone linear extrapolation (App. B with [`Boundary::Extrapolated`], see there).
///
/// Only the derivatives are modified; `values` is the data. Set `p^{xy} = 0` on the boundary
/// beforehand (Alg. 5 line 25) for the extrapolated regions to be monotone as well.
pub fn make_monotone_bicubic(
    u_knots: &[f64],
    v_knots: &[f64],
    values: &[f64],
    du: &mut [f64],
    dv: &mut [f64],
    duv: &mut [f64],
) {
    make_monotone_bicubic_with(u_knots, v_knots, values, du, dv, duv, Boundary::Extrapolated);
}

/// [`make_monotone_bicubic`] with a choice of how the boundary enters (B.6)/(B.7).
pub fn make_monotone_bicubic_with(
    u_knots: &[f64],
    v_knots: &[f64],
    values: &[f64],
    du: &mut [f64],
    dv: &mut [f64],
    duv: &mut [f64],
    boundary: Boundary,
) {
    let (in_u, in_v) = (Layout::new(u_knots, v_knots, false), Layout::new(u_knots, v_knots, true));
    clamp_edge_slopes(in_u, values, du);
    clamp_edge_slopes(in_v, values, dv);
    let dv_clamped = dv.to_vec();
    project_mixed_differences(in_u, values, du, dv, boundary);
    project_mixed_differences(in_v, values, &dv_clamped, du, boundary);
    clamp_cross_derivatives(in_u, values, du, dv, duv);
    clamp_cross_derivatives(in_v, values, dv, du, duv);
}

/// (B.2): clamps `px` into `[0, 3 Δ^x p / h]` for both horizontal edges at each node.
fn clamp_edge_slopes(g: Layout, p: &[f64], px: &mut [f64]) {
    for j in 0..g.y.len() {
        for i in 0..g.x.len() - 1 {
            let bound = slope_bound(g.h(i), g.dx(p, i, j));
            for n in [g.at(i, j), g.at(i + 1, j)] {
                px[n] = clamp_between(px[n], 0.0, bound);
            }
        }
    }
}

/// The slab `[lo, hi]` for `Δ^x p^y_{i,j}` on the horizontal edge `E_{i,j}`: the intersection
/// of (B.6) and (B.7), reversed if the edge is decreasing.
///
/// With `c` the smaller in magnitude of `3 Δ^x p` and `b_{i,j} = 3 Δ^x p - h_i absmax(p^x_{i,j},
/// p^x_{i+1,j})` (both have the sense `s` of the edge once (B.2) holds; "absmax" is max for an
/// increasing edge, min for a decreasing one, i.e. the reversed inequality), the cell above
/// (`R_{i,j}`) bounds `Δ^x p^y` by `-c / k_j` and the cell below (`R_{i,j-1}`) by
/// `c / k_{j-1}`. A missing cell gives 0 ([`Boundary::Extrapolated`]) or no bound.
fn slab(g: Layout, p: &[f64], px: &[f64], i: usize, j: usize, boundary: Boundary) -> (f64, f64) {
    let delta = g.dx(p, i, j);
    let (m0, m1) = (px[g.at(i, j)], px[g.at(i + 1, j)]);
    let absmax = if m0.abs() > m1.abs() { m0 } else { m1 };
    let b = 3.0 * delta - g.h(i) * absmax;
    let c = if delta >= 0.0 { (3.0 * delta).min(b) } else { (3.0 * delta).max(b) };
    let sense = if delta >= 0.0 { 1.0 } else { -1.0 };
    let missing = match boundary {
        Boundary::Extrapolated => 0.0,
        Boundary::Open => f64::INFINITY,
    };
    let below = g.k(j.checked_sub(1)).map_or(sense * missing, |k| c / k);
    let above = g.k(Some(j)).map_or(-sense * missing, |k| -c / k);
    (below.min(above), below.max(above))
}

/// Figure B.1: the closest point `(m0*, m1*)` to `(m0, m1)` with `lo ≤ m1* - m0* ≤ hi`,
/// `|m_k*| ≤ |m_k|` and `m_k*` not of opposite sign to `m_k`, for `lo ≤ 0 ≤ hi`.
///
/// Derivation: the admissible set is the box `[0, m0] × [0, m1]` (ends in either order) cut by
/// the slab. A feasible point is returned unchanged. Otherwise exactly one face is violated;
/// say `d = m1 - m0 > hi` (above the slab, `s = m0 + m1`):
/// 1. `|s| ≤ hi`: the orthogonal projection onto the line `m1 - m0 = hi`,
///    `m0* = s/2 - hi/2`, `m1* = s/2 + hi/2`, raises `m0 < 0` and lowers `m1 > 0` without
///    crossing zero, so it is admissible and optimal.
/// 2. `s > hi`: the orthogonal foot would push `m0` past zero (or up, when `m0 ≥ 0`), so the
///    box face `m0* = max(m0, 0)` is active and `m1* = m0* + hi`.
/// 3. `s < -hi`: symmetrically `m1* = min(m1, 0)`, `m0* = m1* - hi`.
///
/// Below the slab (`d < lo`) the mirror images with `lo`: `|s| ≤ -lo` orthogonal projection;
/// `s > -lo`: `m1* = max(m1, 0)`, `m0* = m1* - lo`; `s < lo`: `m0* = min(m0, 0)`,
/// `m1* = m0* + lo`. These are the six arrow bundles of Figure B.1. In each case the result
/// lies on the violated face, inside the box (the problem is convex, so the KKT point found
/// is the closest one).
pub fn project_to_slab(m0: f64, m1: f64, lo: f64, hi: f64) -> (f64, f64) {
    let (d, s) = (m1 - m0, m0 + m1);
    if d > hi {
        if s > hi {
            let a = m0.max(0.0);
            (a, a + hi)
        } else if s < -hi {
            let b = m1.min(0.0);
            (b - hi, b)
        } else {
            (0.5 * (s - hi), 0.5 * (s + hi))
        }
    } else if d < lo {
        if s > -lo {
            let b = m1.max(0.0);
            (b - lo, b)
        } else if s < lo {
            let a = m0.min(0.0);
            (a, a + lo)
        } else {
            (0.5 * (s - lo), 0.5 * (s + lo))
        }
    } else {
        (m0, m1)
    }
}

/// (B.6), (B.7): projects `py` along every row so that each horizontal edge's `Δ^x p^y` lies in
/// its [`slab`]; the slabs depend on `px` and the data only.
fn project_mixed_differences(g: Layout, p: &[f64], px: &[f64], py: &mut [f64], boundary: Boundary) {
    for j in 0..g.y.len() {
        let slabs: Vec<(f64, f64)> = (0..g.x.len() - 1).map(|i| slab(g, p, px, i, j, boundary)).collect();
        project_row(g, j, &slabs, py);
    }
}

/// Sweeps one row forward then backward (Carlson–Fritsch), projecting every edge with
/// [`project_to_slab`], and repeats the pair while an edge is infeasible.
///
/// If all `py` of the row share one sign, one pair suffices: projections then only lower the
/// larger magnitude of a pair, so after the forward sweep every edge's bound towards larger
/// `i` holds and the backward sweep only lowers left ends, which keeps it.
fn project_row(g: Layout, j: usize, slabs: &[(f64, f64)], py: &mut [f64]) {
    for _ in 0..MAX_SWEEP_PAIRS {
        let forward = 0..slabs.len();
        for i in forward.clone().chain(forward.rev()) {
            let (a, b) = (g.at(i, j), g.at(i + 1, j));
            (py[a], py[b]) = project_to_slab(py[a], py[b], slabs[i].0, slabs[i].1);
        }
        if row_is_feasible(g, j, slabs, py) {
            return;
        }
    }
}

/// Whether every edge of row `j` satisfies its slab up to rounding.
fn row_is_feasible(g: Layout, j: usize, slabs: &[(f64, f64)], py: &[f64]) -> bool {
    slabs.iter().enumerate().all(|(i, &(lo, hi))| {
        let (m0, m1) = (py[g.at(i, j)], py[g.at(i + 1, j)]);
        let slack = SLAB_TOLERANCE * m0.abs().max(m1.abs());
        (lo - slack..=hi + slack).contains(&(m1 - m0))
    })
}

/// (B.8): clamps `pxy` at every node between the two bounds of each adjacent cell's constraint
/// (B.8a-d), ordered as given for an increasing edge and reversed for a decreasing one.
///
/// Every interval contains 0 once (B.6), (B.7) hold, so clamping in sequence lands in the
/// intersection of all of them, independent of order (and of doing `x` or `y` first).
fn clamp_cross_derivatives(g: Layout, p: &[f64], px: &[f64], py: &[f64], pxy: &mut [f64]) {
    let (nx, ny) = (g.x.len(), g.y.len());
    for j in 0..ny {
        for i in 0..nx {
            // edges E_{i,j} (right, cells a and c) and E_{i-1,j} (left, cells b and d)
            let edges = [(i + 1 < nx).then_some(i), i.checked_sub(1)];
            // cells above (k_j, σ = +1: a, b) and below (k_{j-1}, σ = -1: c, d)
            let sides = [(g.k(Some(j)), 1.0), (g.k(j.checked_sub(1)), -1.0)];
            for e in edges.into_iter().flatten() {
                for (k, sigma) in sides {
                    if let Some(k) = k {
                        let (a, b) = cross_bounds(g, p, px, py, (e, i, j), k, sigma);
                        let n = g.at(i, j);
                        pxy[n] = clamp_between(pxy[n], a, b);
                    }
                }
            }
        }
    }
}

/// The two bounds of one of (B.8a-d) on `p^{xy}_{i,j}` from edge `E_{e,j}` (`e ∈ {i-1, i}`) and
/// the cell above (`σ = 1`, spacing `k = k_j`) or below (`σ = -1`, `k = k_{j-1}`):
/// `σ (-3 p^x_{i,j} / k)` and `3 (Δ^x p^y_{e,j} / h_e + σ (3 Δ^x p_{e,j} / (h_e k) - p^x_{i,j} / k))`.
fn cross_bounds(
    g: Layout,
    p: &[f64],
    px: &[f64],
    py: &[f64],
    (e, i, j): (usize, usize, usize),
    k: f64,
    sigma: f64,
) -> (f64, f64) {
    let (h, pxij) = (g.h(e), px[g.at(i, j)]);
    let first = -sigma * 3.0 * pxij / k;
    let second = 3.0 * (g.dx(py, e, j) / h + sigma * (3.0 * g.dx(p, e, j) / (h * k) - pxij / k));
    (first, second)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hermite::Bicubic;
    use crate::monotone_cubic::test_util::{Rng, random_knots};

    /// Random data and derivatives on a random grid; `monotone` makes the values increasing in
    /// both directions.
    fn random_patch(rng: &mut Rng, nu: usize, nv: usize, monotone: bool) -> Bicubic {
        let u_knots = random_knots(rng, nu, (-2.0, 0.0));
        let v_knots = random_knots(rng, nv, (-2.0, 0.0));
        let n = nu * nv;
        let mut values: Vec<f64> = (0..n).map(|_| rng.range(-1.0, 1.0)).collect();
        if monotone {
            for j in 0..nv {
                for i in 0..nu {
                    let below = if j > 0 { values[(j - 1) * nu + i] } else { 0.0 };
                    let left = if i > 0 { values[j * nu + i - 1] } else { 0.0 };
                    // occasionally flat steps
                    let step = if rng.unit() < 0.15 { 0.0 } else { rng.range(0.0, 1.0) };
                    values[j * nu + i] = below.max(left) + step;
                }
            }
        }
        let mut wild = |scale: f64| (0..n).map(|_| scale * rng.normal()).collect::<Vec<_>>();
        let (du, dv, duv) = (wild(3.0), wild(3.0), wild(10.0));
        Bicubic { u_knots, v_knots, values, du, dv, duv }
    }

    fn monotonize(f: &mut Bicubic) {
        make_monotone_bicubic(&f.u_knots, &f.v_knots, &f.values, &mut f.du, &mut f.dv, &mut f.duv);
    }

    /// The sense of the data of cell `(i, j)` in `u` (`axis = 0`) or `v` (`axis = 1`):
    /// `Some(±1)` if both edges in that direction agree (0 counts for either), `None` otherwise.
    fn cell_sense(f: &Bicubic, i: usize, j: usize, axis: usize) -> Option<f64> {
        let nu = f.u_knots.len();
        let at = |a: usize, b: usize| f.values[(j + b) * nu + i + a];
        let (d0, d1) = if axis == 0 {
            (at(1, 0) - at(0, 0), at(1, 1) - at(0, 1))
        } else {
            (at(0, 1) - at(0, 0), at(1, 1) - at(1, 0))
        };
        if d0 >= 0.0 && d1 >= 0.0 {
            Some(1.0)
        } else if d0 <= 0.0 && d1 <= 0.0 {
            Some(-1.0)
        } else {
            None
        }
    }

    /// The smallest `sense * ∂f` over a dense sample of `[u0, u1] × [v0, v1]`.
    fn min_directional(
        f: &Bicubic,
        (u0, u1): (f64, f64),
        (v0, v1): (f64, f64),
        axis: usize,
        sense: f64,
    ) -> f64 {
        let n = 24;
        let mut worst = f64::INFINITY;
        for a in 0..=n {
            for b in 0..=n {
                let u = u0 + (u1 - u0) * a as f64 / n as f64;
                let v = v0 + (v1 - v0) * b as f64 / n as f64;
                worst = worst.min(sense * f.jet(u, v).d1[axis]);
            }
        }
        worst
    }

    /// Checks every cell that is monotone in some direction for monotonicity on a dense sample;
    /// returns the number of cells checked.
    fn check_monotone_cells(f: &Bicubic, label: &str) -> usize {
        let (nu, nv) = (f.u_knots.len(), f.v_knots.len());
        let mut checked = 0;
        for j in 0..nv - 1 {
            for i in 0..nu - 1 {
                for axis in 0..2 {
                    if let Some(sense) = cell_sense(f, i, j, axis) {
                        let us = (f.u_knots[i], f.u_knots[i + 1]);
                        let vs = (f.v_knots[j], f.v_knots[j + 1]);
                        let worst = min_directional(f, us, vs, axis, sense);
                        assert!(worst >= -1e-9, "{label}: cell ({i}, {j}) axis {axis}: {worst}");
                        checked += 1;
                    }
                }
            }
        }
        checked
    }

    #[test]
    fn globally_monotone_data_gives_a_monotone_patch_and_extrapolation() {
        let mut rng = Rng::new(11);
        for trial in 0..60 {
            let mut f = random_patch(&mut rng, 2 + trial % 6, 2 + (trial / 6) % 5, true);
            let (nu, nv) = (f.u_knots.len(), f.v_knots.len());
            for j in 0..nv {
                for i in 0..nu {
                    if i == 0 || j == 0 || i + 1 == nu || j + 1 == nv {
                        f.duv[j * nu + i] = 0.0; // Alg. 5 line 25
                    }
                }
            }
            monotonize(&mut f);
            let checked = check_monotone_cells(&f, &format!("trial {trial}"));
            assert_eq!(checked, 2 * (nu - 1) * (nv - 1));
            // extrapolation: the whole plane around the grid, both directions increasing
            let (u0, u1) = (f.u_knots[0] - 3.0, f.u_knots[nu - 1] + 3.0);
            let (v0, v1) = (f.v_knots[0] - 3.0, f.v_knots[nv - 1] + 3.0);
            for axis in 0..2 {
                let worst = min_directional(&f, (u0, u1), (v0, v1), axis, 1.0);
                assert!(worst >= -1e-9, "trial {trial}: extrapolation axis {axis}: {worst}");
            }
        }
    }

    #[test]
    fn every_monotone_cell_of_random_data_is_monotone() {
        let mut rng = Rng::new(5);
        let mut total = 0;
        for trial in 0..80 {
            let mut f = random_patch(&mut rng, 2 + trial % 7, 2 + (trial / 7) % 6, false);
            monotonize(&mut f);
            total += check_monotone_cells(&f, &format!("trial {trial}"));
        }
        assert!(total > 500, "only {total} monotone cells checked");
    }

    #[test]
    fn rows_increasing_in_u_only_give_a_patch_increasing_in_u() {
        let mut rng = Rng::new(3);
        for trial in 0..40 {
            let mut f = random_patch(&mut rng, 3 + trial % 5, 3 + trial % 4, false);
            let nu = f.u_knots.len();
            for row in f.values.chunks_mut(nu) {
                let mut acc = rng.range(-2.0, 2.0);
                for value in row {
                    acc += rng.range(0.0, 1.0);
                    *value = acc;
                }
            }
            monotonize(&mut f);
            let (u0, u1) = (f.u_knots[0], f.u_knots[nu - 1]);
            let (v0, v1) = (f.v_knots[0], *f.v_knots.last().unwrap_or(&0.0));
            let worst = min_directional(&f, (u0, u1), (v0, v1), 0, 1.0);
            assert!(worst >= -1e-9, "trial {trial}: {worst}");
        }
    }

    #[test]
    fn admissible_derivatives_are_untouched_and_the_result_is_a_fixed_point() {
        let mut rng = Rng::new(17);
        for trial in 0..40 {
            let mut f = random_patch(&mut rng, 2 + trial % 6, 2 + trial % 5, trial % 2 == 0);
            // zero derivatives are always admissible
            let mut zero = f.clone();
            zero.du.fill(0.0);
            zero.dv.fill(0.0);
            zero.duv.fill(0.0);
            let before = zero.clone();
            monotonize(&mut zero);
            assert_eq!(zero, before);
            monotonize(&mut f);
            let once = f.clone();
            monotonize(&mut f);
            assert_eq!(f, once, "trial {trial}");
        }
    }

    #[test]
    fn exact_data_of_admissible_functions_is_untouched() {
        // f = u³ + 2v on u > 0 (strictly inside the (B.2) box) and f = 0.5 u - v on any grid: admissible Hermite data
        let (u_knots, v_knots) = (vec![0.1, 0.3, 0.5, 1.2], vec![-1.0, 0.0, 0.4]);
        let nodes: Vec<(f64, f64)> =
            v_knots.iter().flat_map(|&v| u_knots.iter().map(move |&u| (u, v))).collect();
        type Exact = fn(f64, f64) -> [f64; 4];
        let cases: [(Exact, &str); 2] = [
            (|u, v| [u * u * u + 2.0 * v, 3.0 * u * u, 2.0, 0.0], "u³ + 2v"),
            (|u, v| [0.5 * u - v, 0.5, -1.0, 0.0], "0.5u - v"),
        ];
        for (exact, label) in cases {
            let data: Vec<[f64; 4]> = nodes.iter().map(|&(u, v)| exact(u, v)).collect();
            let column = |k: usize| data.iter().map(|d| d[k]).collect::<Vec<f64>>();
            let mut f = Bicubic {
                u_knots: u_knots.clone(),
                v_knots: v_knots.clone(),
                values: column(0),
                du: column(1),
                dv: column(2),
                duv: column(3),
            };
            let before = f.clone();
            monotonize(&mut f);
            assert_eq!(f, before, "{label}");
        }
    }

    /// The patch with `u` and `v` swapped.
    fn transpose(f: &Bicubic) -> Bicubic {
        let (nu, nv) = (f.u_knots.len(), f.v_knots.len());
        let swap = |a: &[f64]| (0..nu * nv).map(|k| a[(k % nv) * nu + k / nv]).collect::<Vec<_>>();
        Bicubic {
            u_knots: f.v_knots.clone(),
            v_knots: f.u_knots.clone(),
            values: swap(&f.values),
            du: swap(&f.dv),
            dv: swap(&f.du),
            duv: swap(&f.duv),
        }
    }

    #[test]
    fn result_does_not_depend_on_which_direction_goes_first() {
        let mut rng = Rng::new(23);
        for trial in 0..60 {
            let mut f = random_patch(&mut rng, 2 + trial % 6, 2 + (trial / 6) % 6, trial % 3 == 0);
            let mut g = transpose(&f);
            monotonize(&mut f);
            monotonize(&mut g);
            let back = transpose(&g);
            for (a, b) in [(&f.du, &back.du), (&f.dv, &back.dv), (&f.duv, &back.duv)] {
                for (x, y) in a.iter().zip(b) {
                    assert!((x - y).abs() <= 1e-12 * x.abs().max(1.0), "trial {trial}: {x} vs {y}");
                }
            }
        }
    }

    #[test]
    fn slab_projection_covers_the_six_cases_of_figure_b1() {
        let (lo, hi) = (-1.0, 2.0);
        let cases = [
            // above the slab
            ((-1.0, 2.0), (-0.5, 1.5)),   // |s| ≤ hi: orthogonal
            ((1.0, 4.0), (1.0, 3.0)),     // s > hi, m0 ≥ 0: keep m0
            ((-0.5, 4.0), (0.0, 2.0)),    // s > hi, m0 < 0: m0 → 0
            ((-4.0, -1.0), (-3.0, -1.0)), // s < -hi, m1 ≤ 0: keep m1
            ((-4.0, 0.5), (-2.0, 0.0)),   // s < -hi, m1 > 0: m1 → 0
            // below the slab
            ((1.0, -1.0), (0.5, -0.5)),   // |s| ≤ -lo: orthogonal
            ((3.0, 1.0), (2.0, 1.0)),     // s > -lo, m1 ≥ 0: keep m1
            ((-1.0, -3.0), (-1.0, -2.0)), // s < lo, m0 ≤ 0: keep m0
            ((0.5, -3.0), (0.0, -1.0)),   // s < lo, m0 > 0: m0 → 0
            ((0.3, 1.1), (0.3, 1.1)),     // feasible
        ];
        for ((m0, m1), expected) in cases {
            let got = project_to_slab(m0, m1, lo, hi);
            assert_eq!(got, expected, "({m0}, {m1})");
            let d = got.1 - got.0;
            assert!(lo - 1e-15 <= d && d <= hi + 1e-15);
            assert!(
                got.0.abs() <= m0.abs() && got.0 * m0 >= 0.0 && got.1.abs() <= m1.abs() && got.1 * m1 >= 0.0
            );
        }
    }

    #[test]
    fn slab_projection_is_the_closest_admissible_point() {
        let mut rng = Rng::new(29);
        for _ in 0..2000 {
            let (m0, m1) = (rng.range(-3.0, 3.0), rng.range(-3.0, 3.0));
            let (lo, hi) = (rng.range(-2.0, 0.0), rng.range(0.0, 2.0));
            let (a, b) = project_to_slab(m0, m1, lo, hi);
            let dist = (a - m0).hypot(b - m1);
            // brute force over a fine grid of the admissible box
            let n = 200;
            let mut best = f64::INFINITY;
            for p in 0..=n {
                for q in 0..=n {
                    let (x, y) = (m0 * p as f64 / n as f64, m1 * q as f64 / n as f64);
                    if (lo..=hi).contains(&(y - x)) {
                        best = best.min((x - m0).hypot(y - m1));
                    }
                }
            }
            assert!(dist <= best + 1e-12, "({m0}, {m1}) in [{lo}, {hi}]: {dist} > {best}");
        }
    }

    #[test]
    fn open_boundary_leaves_boundary_mixed_differences_one_sided() {
        // one row of increasing cells: with Extrapolated the top and bottom rows need
        // Δ^x p^y between 0 and the inner bound; Open only needs the inner bound.
        let (u, v) = ([0.0, 1.0], [0.0, 1.0]);
        let values = [0.0, 1.0, 1.0, 2.0];
        let run = |boundary| {
            let (mut du, mut dv, mut duv) = ([0.0; 4], [0.5, 2.5, 0.0, 0.0], [0.0; 4]);
            make_monotone_bicubic_with(&u, &v, &values, &mut du, &mut dv, &mut duv, boundary);
            dv
        };
        // bottom row: cell above bounds Δ^x p^y ≥ -3, nothing below (Open) or ≤ 0 (Extrapolated)
        assert_eq!(run(Boundary::Open), [0.5, 2.5, 0.0, 0.0]);
        let dv = run(Boundary::Extrapolated);
        assert!((dv[1] - dv[0]).abs() < 1e-15 && dv[0] > 0.0);
    }
}
