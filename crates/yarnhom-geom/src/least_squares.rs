//! Least-squares integration of a gradient field on a regular grid: the discrete form of the
//! vector Poisson problem (3.17)-(3.18) that defines the midsurface of a doubly curved RVE.
//!
//! Given a target gradient `G(X)` (3x2; `R S̄` of (3.14)) and a reference map `φ₀` (the
//! straight-line midsurface), we minimize `∫ |∇(φ₀ + ψ) - G|²` over the correction `ψ` on a
//! rectangle. Its Euler-Lagrange equations are `∇²φ = ∇·G` (3.17) with the natural boundary
//! condition `N·∇φ = N·G` (3.18); the minimizer is the same whatever `φ₀` is, which only serves
//! to keep the interpolated field `ψ` small and smooth.
//!
//! Discretization (standard least squares on grid edges): nodes `X_ij = lower + (i hx, j hy)`; each
//! edge contributes `w_e |ψ_j - ψ_i - d_e|²` with `d_e = ∫_e G e - (φ₀_j - φ₀_i)` (forward
//! difference against the edge integral of `G`, by [`GAUSS_3`]) and weight `w_e = (h_⊥/h) t`, `t` the trapezoidal
//! weight (1/2 for edges on the boundary, which bound half a cell strip). The normal equations
//! `A ψ = b` are a weighted graph Laplacian, i.e. the 5-point Laplacian with natural boundary
//! conditions, built in. `A = (hy/hx) Lx ⊗ Dy + (hx/hy) Dx ⊗ Ly` (`L` the path-graph Laplacian,
//! `D = diag(1/2, 1, …, 1, 1/2)`) is separable, and `L u = λ D u` is solved by the DCT-I vectors
//! `u_k(i) = cos(π k i / n)`, `λ_k = 2 - 2 cos(π k / n)`: the solve is exact (four dense
//! transforms per component), its constant null space fixed afterwards by pinning.

use nalgebra::{DMatrix, DVector, Matrix3x2, Vector2, Vector3};

/// Axes narrower than this fraction of the widest one are widened to it (a grid needs cells of
/// non-zero size in both directions).
const MIN_ASPECT: f64 = 1e-3;

/// A regular grid of `cells[0] x cells[1]` cells of size `spacing`, from `lower`.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Grid {
    lower: Vector2<f64>,
    spacing: Vector2<f64>,
    cells: [usize; 2],
}

impl Grid {
    /// `cells` cells per axis (at least 2) over the bounding box of `lower`, `upper` and the origin,
    /// axes narrower than [`MIN_ASPECT`] of the widest widened symmetrically. `None` for a box with
    /// non-finite bounds or no extent.
    pub(crate) fn covering(lower: &Vector2<f64>, upper: &Vector2<f64>, cells: usize) -> Option<Grid> {
        if !lower.iter().chain(upper.iter()).all(|v| v.is_finite()) {
            return None;
        }
        let (lower, upper) = (lower.inf(&Vector2::zeros()), upper.sup(&Vector2::zeros()));
        let widest = (upper - lower).max();
        if widest <= 0.0 {
            return None;
        }
        let pad = (Vector2::repeat(widest * MIN_ASPECT) - (upper - lower)).sup(&Vector2::zeros()) / 2.0;
        let cells = cells.max(2);
        let spacing = (upper - lower + pad * 2.0) / cells as f64;
        Some(Grid { lower: lower - pad, spacing, cells: [cells, cells] })
    }

    /// The node `(i, j)`.
    fn node(&self, i: usize, j: usize) -> Vector2<f64> {
        self.lower + Vector2::new(i as f64 * self.spacing.x, j as f64 * self.spacing.y)
    }

    /// `f` at every node, as an `(nx + 1) x (ny + 1)` matrix.
    fn sample<T: nalgebra::Scalar>(&self, f: impl Fn(&Vector2<f64>) -> T) -> DMatrix<T> {
        DMatrix::from_fn(self.cells[0] + 1, self.cells[1] + 1, |i, j| f(&self.node(i, j)))
    }
}

/// A vector field on the nodes of a grid, interpolated with Catmull-Rom splines.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct GridField {
    grid: Grid,
    values: DMatrix<Vector3<f64>>,
}

impl GridField {
    /// The bicubic Catmull-Rom interpolant at `x` (ghost nodes beyond the grid linearly
    /// extrapolated). Outside the grid, the value at the nearest point of the grid rectangle.
    pub(crate) fn value(&self, x: &Vector2<f64>) -> Vector3<f64> {
        let t = (x - self.grid.lower).component_div(&self.grid.spacing);
        let (sx, sy) = (stencil(t.x, self.grid.cells[0]), stencil(t.y, self.grid.cells[1]));
        sx.iter().flat_map(|&(i, wx)| sy.iter().map(move |&(j, wy)| self.values[(i, j)] * (wx * wy))).sum()
    }
}

/// The correction `ψ` minimizing `∫ |∇(φ₀ + ψ) - G|²` over the grid rectangle, with `ψ(0) = 0`.
pub(crate) fn least_squares_correction(
    grid: Grid,
    target: impl Fn(&Vector2<f64>) -> Matrix3x2<f64>,
    reference: impl Fn(&Vector2<f64>) -> Vector3<f64>,
) -> GridField {
    let b = right_hand_side(&grid, target, reference);
    let (x, y) = (Dct1::new(grid.cells[0]), Dct1::new(grid.cells[1]));
    let [c0, c1, c2] = [0, 1, 2].map(|c| solve_normal_equations(&b.map(|v| v[c]), &grid.spacing, &x, &y));
    let values =
        DMatrix::from_fn(c0.nrows(), c0.ncols(), |i, j| Vector3::new(c0[(i, j)], c1[(i, j)], c2[(i, j)]));
    let mut field = GridField { grid, values };
    let origin = field.value(&Vector2::zeros());
    field.values.apply(|v| *v -= origin);
    field
}

/// Three-point Gauss-Legendre rule on `[0, 1]` (nodes, weights): exact for quintics. Edge
/// integrals of `G` to this order make `d_e` vanish to round-off wherever `G` is the gradient of
/// the reference (singly curved strains), so the midsurface is continuous as a second
/// curvature appears; a midpoint rule left an `O(h²)` correction there, a jump of the tile
/// energy at `ky = 0⁺` that the strain derivatives (3.23c) saw.
const GAUSS_3: [(f64, f64); 3] = [
    (0.5 - 0.387_298_334_620_741_7, 5.0 / 18.0),
    (0.5, 8.0 / 18.0),
    (0.5 + 0.387_298_334_620_741_7, 5.0 / 18.0),
];

/// Trapezoidal weight of node `i` of `0..=n`.
fn trapezoid(i: usize, n: usize) -> f64 {
    if i == 0 || i == n { 0.5 } else { 1.0 }
}

/// `b` of the normal equations `A ψ = b` of `Σ_e w_e |ψ_j - ψ_i - d_e|²` (module docs).
fn right_hand_side(
    grid: &Grid,
    target: impl Fn(&Vector2<f64>) -> Matrix3x2<f64>,
    reference: impl Fn(&Vector2<f64>) -> Vector3<f64>,
) -> DMatrix<Vector3<f64>> {
    let reference = grid.sample(reference);
    let [nx, ny] = grid.cells;
    let h = grid.spacing;
    let mut b = DMatrix::from_element(nx + 1, ny + 1, Vector3::zeros());
    let mut add_edge = |from: (usize, usize), to: (usize, usize), axis: usize, weight: f64| {
        let (start, end) = (grid.node(from.0, from.1), grid.node(to.0, to.1));
        let integral = GAUSS_3.iter().fold(Vector3::zeros(), |sum, &(t, w)| {
            sum + target(&(start + (end - start) * t)).column(axis) * (w * h[axis])
        });
        let d = integral - (reference[to] - reference[from]);
        b[to] += d * weight;
        b[from] -= d * weight;
    };
    for j in 0..=ny {
        for i in 0..nx {
            add_edge((i, j), (i + 1, j), 0, h.y / h.x * trapezoid(j, ny));
        }
    }
    for i in 0..=nx {
        for j in 0..ny {
            add_edge((i, j), (i, j + 1), 1, h.x / h.y * trapezoid(i, nx));
        }
    }
    b
}

/// The DCT-I eigenbasis of `L u = λ D u` on `n + 1` nodes (module docs).
struct Dct1 {
    /// `C[(i, k)] = cos(π k i / n)`.
    basis: DMatrix<f64>,
    /// `Cᵀ`.
    transposed: DMatrix<f64>,
    /// `λ_k = 2 - 2 cos(π k / n)`.
    eigenvalues: DVector<f64>,
    /// `uₖᵀ D uₖ`: `n` for `k = 0, n`, else `n / 2`.
    norms: DVector<f64>,
}

impl Dct1 {
    fn new(n: usize) -> Self {
        // cos(π k i / n) depends on k i mod 2n only.
        let cosines = DVector::from_fn(2 * n, |p, _| (std::f64::consts::PI * p as f64 / n as f64).cos());
        let basis = DMatrix::from_fn(n + 1, n + 1, |i, k| cosines[(i * k) % (2 * n)]);
        Dct1 {
            transposed: basis.transpose(),
            basis,
            eigenvalues: DVector::from_fn(n + 1, |k, _| 2.0 - 2.0 * cosines[k]),
            norms: DVector::from_fn(n + 1, |k, _| n as f64 / (2.0 * trapezoid(k, n))),
        }
    }
}

/// Solves `A ψ = b` for one component (`b` summing to zero; `x`, `y` the bases of its axes),
/// returning the solution with zero trapezoidal mean: `ψ = Cx Γ Cyᵀ` with
/// `Γ_km = (Cxᵀ b Cy)_km / (‖u_k‖² ‖v_m‖² ((hy/hx) λ_k + (hx/hy) μ_m))` and `Γ_00 = 0`.
fn solve_normal_equations(b: &DMatrix<f64>, h: &Vector2<f64>, x: &Dct1, y: &Dct1) -> DMatrix<f64> {
    let mut coefficients = &x.transposed * b * &y.basis;
    for m in 0..b.ncols() {
        for k in 0..b.nrows() {
            let eigenvalue = h.y / h.x * x.eigenvalues[k] + h.x / h.y * y.eigenvalues[m];
            let scale = if k == 0 && m == 0 { 0.0 } else { 1.0 / (x.norms[k] * y.norms[m] * eigenvalue) };
            coefficients[(k, m)] *= scale;
        }
    }
    &x.basis * coefficients * &y.transposed
}

/// Catmull-Rom weights of the nodes `i - 1 ..= i + 2` at `u ∈ [0, 1]` in cell `i`.
fn catmull_rom(u: f64) -> [f64; 4] {
    let v = 1.0 - u;
    [
        -0.5 * u * v * v,
        0.5 * (3.0 * u * u * u - 5.0 * u * u + 2.0),
        0.5 * (-3.0 * u * u * u + 4.0 * u * u + u),
        -0.5 * u * u * v,
    ]
}

/// `(node, weight)` of the Catmull-Rom interpolant at grid coordinate `t` (clamped to `[0, n]`,
/// `n >= 2` cells), with ghost nodes `-1`, `n + 1` linearly extrapolated from the two nearest.
fn stencil(t: f64, n: usize) -> [(usize, f64); 4] {
    let t = t.clamp(0.0, n as f64);
    let i = (t.floor() as usize).min(n - 1);
    let [a, b, c, d] = catmull_rom(t - i as f64);
    if i == 0 {
        [(0, b + 2.0 * a), (1, c - a), (2, d), (0, 0.0)]
    } else if i == n - 1 {
        [(i - 1, a), (i, b - d), (n, c + 2.0 * d), (n, 0.0)]
    } else {
        [(i - 1, a), (i, b), (i + 1, c), (i + 2, d)]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `A ψ` for the operator of the module docs, applied edge by edge.
    fn apply(psi: &DMatrix<f64>, h: &Vector2<f64>) -> DMatrix<f64> {
        let (nx, ny) = (psi.nrows() - 1, psi.ncols() - 1);
        let mut out = DMatrix::zeros(nx + 1, ny + 1);
        let mut edge = |from: (usize, usize), to: (usize, usize), weight: f64| {
            let flux = (psi[to] - psi[from]) * weight;
            out[to] += flux;
            out[from] -= flux;
        };
        for j in 0..=ny {
            for i in 0..nx {
                edge((i, j), (i + 1, j), h.y / h.x * trapezoid(j, ny));
            }
        }
        for i in 0..=nx {
            for j in 0..ny {
                edge((i, j), (i, j + 1), h.x / h.y * trapezoid(i, nx));
            }
        }
        out
    }

    #[test]
    fn the_transform_solve_satisfies_the_normal_equations() {
        let h = Vector2::new(0.3, 0.7);
        let mut b = DMatrix::from_fn(6, 9, |i, j| ((i * 7 + j * 3) as f64).sin());
        b.add_scalar_mut(-b.mean());
        let psi = solve_normal_equations(&b, &h, &Dct1::new(5), &Dct1::new(8));
        assert!(
            (apply(&psi, &h) - &b).norm() < 1e-12 * b.norm(),
            "residual {}",
            (apply(&psi, &h) - &b).norm()
        );
        // The null space (constants) is removed: zero trapezoidal mean.
        let mean: f64 = (0..6)
            .flat_map(|i| (0..9).map(move |j| (i, j)))
            .map(|(i, j)| psi[(i, j)] * trapezoid(i, 5) * trapezoid(j, 8))
            .sum();
        assert!(mean.abs() < 1e-14, "mean {mean}");
    }

    #[test]
    fn an_exact_gradient_field_is_integrated_exactly() {
        // G = ∇f for linear f: the edge data are exact differences, so ψ = f - f(0) at the nodes.
        let grid = Grid::covering(&Vector2::new(-1.0, -0.5), &Vector2::new(2.0, 1.0), 8).expect("grid");
        let f = |x: &Vector2<f64>| Vector3::new(x.x + 2.0 * x.y, -x.y, 0.5 * x.x);
        let g = Matrix3x2::new(1.0, 2.0, 0.0, -1.0, 0.5, 0.0);
        let field = least_squares_correction(grid, |_| g, |_| Vector3::zeros());
        for x in [Vector2::new(0.3, 0.2), Vector2::new(-1.0, 1.0), Vector2::new(1.9, -0.4)] {
            assert!((field.value(&x) - f(&x)).norm() < 1e-13, "at {x}");
        }
    }

    #[test]
    fn interpolation_reproduces_quadratics_inside_and_lines_everywhere() {
        let grid = Grid::covering(&Vector2::new(-1.0, -1.0), &Vector2::new(1.0, 1.0), 8).expect("grid");
        let line = |x: &Vector2<f64>| Vector3::new(x.x - 3.0 * x.y, 1.0, 2.0 * x.y);
        let quadratic = |x: &Vector2<f64>| Vector3::new(x.x * x.y, x.x * x.x, x.y * x.y - x.x);
        let interpolant = |f: &dyn Fn(&Vector2<f64>) -> Vector3<f64>| GridField {
            grid: grid.clone(),
            values: grid.sample(f),
        };
        let (linear, quad) = (interpolant(&line), interpolant(&quadratic));
        for x in [Vector2::new(-0.97, 0.99), Vector2::new(0.93, -0.8), Vector2::new(0.1, 0.33)] {
            assert!((linear.value(&x) - line(&x)).norm() < 1e-14, "line at {x}");
        }
        for x in [Vector2::new(-0.7, 0.6), Vector2::new(0.1, 0.33), Vector2::new(0.74, -0.74)] {
            assert!((quad.value(&x) - quadratic(&x)).norm() < 1e-14, "quadratic at {x}");
        }
        // Outside: the value at the nearest point of the rectangle.
        let (outside, nearest) = (Vector2::new(3.0, -0.2), Vector2::new(1.0, -0.2));
        assert!((linear.value(&outside) - line(&nearest)).norm() < 1e-14);
        assert!(linear.value(&Vector2::new(f64::NAN, 0.0)).x.is_nan());
    }

    #[test]
    fn grids_cover_the_origin_and_survive_degenerate_boxes() {
        let grid = Grid::covering(&Vector2::new(0.1, 0.2), &Vector2::new(0.3, 0.4), 4).expect("grid");
        assert_eq!((grid.lower, grid.spacing), (Vector2::zeros(), Vector2::new(0.075, 0.1)));
        let strip = Grid::covering(&Vector2::new(-1.0, 0.0), &Vector2::new(1.0, 0.0), 4).expect("grid");
        assert_eq!(strip.lower, Vector2::new(-1.0, -MIN_ASPECT));
        assert!(Grid::covering(&Vector2::zeros(), &Vector2::zeros(), 4).is_none());
        assert!(Grid::covering(&Vector2::new(f64::NAN, 0.0), &Vector2::new(1.0, 1.0), 4).is_none());
        assert_eq!(
            Grid::covering(&-Vector2::repeat(1.0), &Vector2::repeat(1.0), 0).expect("grid").cells,
            [2, 2]
        );
    }
}
