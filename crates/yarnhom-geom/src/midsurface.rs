//! The RVE midsurface of a macroscale deformation (I, II) (Sec. 3.2.2, App. A.1.1).
//!
//! - `S̄ = [√I; 0 0]` (3.16, A.11), the in-plane stretch with `S̄ᵀS̄ = I` (3.15);
//! - the normal derivatives `[n̄_{i,α}] = -(√I)^{-T} II` (A.12);
//! - the rotation field `R(X) = exp W(X)`, `W` skew with `W_13 = a`, `W_23 = b`,
//!   `a = Σ n̄_{1,α} X_α`, `b = Σ n̄_{2,α} X_α` (A.6-A.10), evaluated with robust sinc terms;
//! - the midsurface `φ`, which should satisfy `∇φ = R S̄` (3.14).
//!
//! The straight-line midsurface `φ_line(X) = ∫₀¹ R(tX) S̄ X dt
//! = [I + (1 - cos r)/r² W + (r - sin r)/r³ W²] S̄ X` integrates (3.14) along straight lines
//! from the RVE centre; because `W(tX) = t W(X)` it is closed form. For singly curved
//! deformations (rank II <= 1) `R S̄` is a gradient field, so `φ_line` solves (3.14) exactly and
//! is what the least-squares solve (3.17)-(3.18) would give. For doubly curved ones `R S̄` is
//! not a gradient (no surface has constant I and II with Gaussian curvature `K ≠ 0`), and
//! [`Midsurface::over_domain`] solves (3.14) in the least-squares sense on a grid over the
//! domain, the Poisson problem (3.17)-(3.18) (discretization: the `least_squares` module).

use nalgebra::{Matrix2, Matrix3, Matrix3x2, Vector2, Vector3};

use crate::least_squares::{Grid, GridField, least_squares_correction};
use crate::strain::MacroStrain;

/// `sin(x) / x`, exact near 0.
fn sinc(x: f64) -> f64 {
    if x.abs() < 1e-4 { 1.0 - x * x / 6.0 } else { x.sin() / x }
}

/// `(1 - cos r) / r²`, exact near 0.
fn one_minus_cos_over_r2(r: f64) -> f64 {
    if r.abs() < 1e-3 { 0.5 - r * r / 24.0 } else { (1.0 - r.cos()) / (r * r) }
}

/// `(r - sin r) / r³`, exact near 0.
fn r_minus_sin_over_r3(r: f64) -> f64 {
    if r.abs() < 1e-2 { 1.0 / 6.0 - r * r / 120.0 + r.powi(4) / 5040.0 } else { (r - r.sin()) / (r * r * r) }
}

/// Principal square root of a symmetric positive definite 2x2 matrix:
/// `√A = (A + √det A · 1) / √(tr A + 2 √det A)`.
pub fn sqrt_spd2(a: &Matrix2<f64>) -> Matrix2<f64> {
    let s = a.determinant().sqrt();
    (a + Matrix2::identity() * s) / (a.trace() + 2.0 * s).sqrt()
}

/// Default number of grid cells per axis of the least-squares midsurface (3.17)-(3.18).
pub const DEFAULT_GRID_CELLS: usize = 64;

/// The macroscale deformation of an RVE: everything needed to place yarns on the deformed
/// midsurface.
#[derive(Debug, Clone, PartialEq)]
pub struct Midsurface {
    /// `S̄` (3x2), (A.11).
    pub stretch: Matrix3x2<f64>,
    /// `[n̄_{i,α}]` (2x2), (A.12): row `i` = component, column `α` = derivative direction.
    pub normal_derivatives: Matrix2<f64>,
    /// `φ - φ_line` of the least-squares midsurface, on a grid; `None`: `φ = φ_line`.
    correction: Option<GridField>,
}

impl Midsurface {
    /// The straight-line midsurface `φ_line` of a macro strain, defined everywhere. Exact for
    /// rank II <= 1 (and then equal to [`Midsurface::over_domain`]); for doubly curved strains
    /// it is the straight-line approximation, not the least-squares solution of (3.17)-(3.18).
    pub fn new(strain: &MacroStrain) -> Self {
        let root = sqrt_spd2(&strain.s.first_fundamental_form());
        let inverse_transpose = root.try_inverse().unwrap_or_else(Matrix2::zeros).transpose();
        let mut stretch = Matrix3x2::zeros();
        stretch.fixed_view_mut::<2, 2>(0, 0).copy_from(&root);
        Midsurface {
            stretch,
            normal_derivatives: -inverse_transpose * strain.second_fundamental_form(),
            correction: None,
        }
    }

    /// The midsurface of (3.17)-(3.18) for material points in the box `[lower, upper]` (m), with
    /// [`DEFAULT_GRID_CELLS`] cells per axis: see [`Midsurface::over_domain_with_cells`].
    pub fn over_domain(strain: &MacroStrain, lower: Vector2<f64>, upper: Vector2<f64>) -> Self {
        Self::over_domain_with_cells(strain, lower, upper, DEFAULT_GRID_CELLS)
    }

    /// The midsurface solving `∇φ = R S̄` (3.14) in the least-squares sense over the box
    /// `[lower, upper]` (m; extended to contain the RVE centre `X = 0`): the Poisson problem
    /// (3.17) with natural boundary conditions (3.18), `φ(0) = 0`. Pass the bounding box of every
    /// material point that will be evaluated, periodic images included: the solution depends on
    /// the domain.
    ///
    /// For rank II <= 1, or a box without extent or finite bounds, this is [`Midsurface::new`]
    /// (exact, no grid). Otherwise `φ = φ_line + ψ`, with the correction `ψ` solved on a regular
    /// grid of `cells` (at least 2) cells per axis and interpolated bicubically (Catmull-Rom).
    /// Outside the box, `ψ` is held at its value on the nearest point of the box, so `φ` stays
    /// continuous and follows `φ_line` there. `R` and `n` remain those of (A.10); for a doubly
    /// curved strain they are close to, but not exactly, the frame of `∇φ` (App. A.1.1).
    pub fn over_domain_with_cells(
        strain: &MacroStrain,
        lower: Vector2<f64>,
        upper: Vector2<f64>,
        cells: usize,
    ) -> Self {
        let line = Self::new(strain);
        let doubly_curved = strain.kx != 0.0 && strain.ky != 0.0;
        let correction = Grid::covering(&lower, &upper, cells).filter(|_| doubly_curved).map(|grid| {
            least_squares_correction(grid, |x| line.rotation(x) * line.stretch, |x| line.line_position(x))
        });
        Midsurface { correction, ..line }
    }

    /// `(a, b)` of (A.7-A.8) at material point `X`.
    fn tilt(&self, x: &Vector2<f64>) -> Vector2<f64> {
        self.normal_derivatives * x
    }

    /// The skew matrix `W(X)` of (A.6) (minimum-norm choice: `W_12 = 0`).
    pub fn w(&self, x: &Vector2<f64>) -> Matrix3<f64> {
        let ab = self.tilt(x);
        Matrix3::new(0.0, 0.0, ab.x, 0.0, 0.0, ab.y, -ab.x, -ab.y, 0.0)
    }

    /// The rotation `R(X)` of (A.10): rotates `n̄ = e3` towards `(a, b)` by `r = |(a, b)|`.
    pub fn rotation(&self, x: &Vector2<f64>) -> Matrix3<f64> {
        let ab = self.tilt(x);
        let (a, b) = (ab.x, ab.y);
        let r = ab.norm();
        let h = 0.5 * sinc(r / 2.0).powi(2);
        let s = sinc(r);
        Matrix3::new(
            1.0 - a * a * h,
            -a * b * h,
            a * s,
            -a * b * h,
            1.0 - b * b * h,
            b * s,
            -a * s,
            -b * s,
            r.cos(),
        )
    }

    /// The straight-line midsurface `φ_line(X)` (module docs).
    fn line_position(&self, x: &Vector2<f64>) -> Vector3<f64> {
        let w = self.w(x);
        let r = self.tilt(x).norm();
        let integral = Matrix3::identity() + w * one_minus_cos_over_r2(r) + w * w * r_minus_sin_over_r3(r);
        integral * (self.stretch * x)
    }

    /// The deformed midsurface point `φ(X)`, with `φ(0) = 0`.
    pub fn position(&self, x: &Vector2<f64>) -> Vector3<f64> {
        let line = self.line_position(x);
        self.correction.as_ref().map_or(line, |c| line + c.value(x))
    }

    /// The deformed normal `n(X) = R(X) e3`.
    pub fn normal(&self, x: &Vector2<f64>) -> Vector3<f64> {
        self.rotation(x).column(2).into()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// `∇φ` by central differences.
    fn gradient(m: &Midsurface, x: &Vector2<f64>) -> Matrix3x2<f64> {
        let h = 1e-6;
        let d = |e: Vector2<f64>| (m.position(&(x + e * h)) - m.position(&(x - e * h))) / (2.0 * h);
        Matrix3x2::from_columns(&[d(Vector2::x()), d(Vector2::y())])
    }

    /// `II_{αβ} = -n_{,α} · a_β` (3.12) by central differences.
    fn second_form(m: &Midsurface, x: &Vector2<f64>) -> Matrix2<f64> {
        let h = 1e-6;
        let grad = gradient(m, x);
        let dn = |e: Vector2<f64>| (m.normal(&(x + e * h)) - m.normal(&(x - e * h))) / (2.0 * h);
        let (n1, n2) = (dn(Vector2::x()), dn(Vector2::y()));
        Matrix2::new(
            -n1.dot(&grad.column(0)),
            -n1.dot(&grad.column(1)),
            -n2.dot(&grad.column(0)),
            -n2.dot(&grad.column(1)),
        )
    }

    fn singly_curved() -> impl Strategy<Value = MacroStrain> {
        (-0.5..1.0f64, -0.6..0.6f64, -0.5..1.0f64, -30.0..30.0f64, any::<bool>()).prop_map(
            |(sx, sa, sy, k, along_x)| {
                let (kx, ky) = if along_x { (k, 0.0) } else { (0.0, k) };
                MacroStrain::new(sx, sa, sy, kx, ky).expect("valid")
            },
        )
    }

    #[test]
    fn square_root_of_an_spd_matrix() {
        let a = Matrix2::new(4.0, 1.0, 1.0, 2.0);
        let r = sqrt_spd2(&a);
        assert!((r * r - a).norm() < 1e-14 && (r - r.transpose()).norm() < 1e-15);
    }

    #[test]
    fn an_unbent_midsurface_is_the_affine_map_s_bar() {
        let m = Midsurface::new(&MacroStrain::new(0.2, 0.3, -0.1, 0.0, 0.0).expect("valid"));
        let x = Vector2::new(0.01, -0.004);
        assert!((m.position(&x) - m.stretch * x).norm() < 1e-17);
        assert_eq!(m.rotation(&x), Matrix3::identity());
    }

    #[test]
    fn rotation_is_orthonormal_and_tilts_the_normal_by_the_integrated_curvature() {
        let m = Midsurface::new(&MacroStrain::new(0.0, 0.0, 0.0, 40.0, -25.0).expect("valid"));
        for x in [
            Vector2::new(0.0, 0.0),
            Vector2::new(1e-9, 0.0),
            Vector2::new(0.01, 0.02),
            Vector2::new(-0.05, 0.03),
        ] {
            let r = m.rotation(&x);
            assert!((r.transpose() * r - Matrix3::identity()).norm() < 1e-14, "orthonormal at {x}");
            assert!((r.determinant() - 1.0).abs() < 1e-14);
            // (A.10) equals the matrix exponential of W.
            assert!((r - m.w(&x).exp()).norm() < 1e-12, "exp W at {x}");
        }
    }

    #[test]
    fn a_bent_strip_lies_on_its_cylinder() {
        // I = identity, II = diag(1/rho, 0): the X1 axis maps onto a circle of radius rho.
        let rho = 0.05;
        let m = Midsurface::new(&MacroStrain::new(0.0, 0.0, 0.0, 1.0 / rho, 0.0).expect("valid"));
        // The centre lies on the normal through the origin, on the side the strip bends to.
        let probe = m.position(&Vector2::new(0.07, 0.0));
        let off = |c: &Vector3<f64>| ((probe - c).norm() - rho).abs();
        let centre = [Vector3::z() * rho, -Vector3::z() * rho]
            .into_iter()
            .min_by(|a, b| off(a).total_cmp(&off(b)))
            .expect("two candidates");
        for s in [-0.1, -0.02, 0.0, 0.03, 0.12] {
            let p = m.position(&Vector2::new(s, 0.0));
            assert!(((p - centre).norm() - rho).abs() < 1e-14, "at X1 = {s}: radius {}", (p - centre).norm());
        }
    }

    /// The 20 mm x 12 mm domain of the tests, centred on the RVE centre.
    fn domain(scale: f64) -> (Vector2<f64>, Vector2<f64>) {
        (Vector2::new(-0.010, -0.006) * scale, Vector2::new(0.010, 0.006) * scale)
    }

    /// `n x n` points spread over the box (cell midpoints).
    fn samples((lower, upper): (Vector2<f64>, Vector2<f64>), n: usize) -> Vec<Vector2<f64>> {
        let cell = (upper - lower) / n as f64;
        (0..n * n)
            .map(|p| lower + Vector2::new(p % n, p / n).cast::<f64>().add_scalar(0.5).component_mul(&cell))
            .collect()
    }

    /// `∫ |∇φ - R S̄|²` over the box, midpoint rule on 40 x 40 cells.
    fn misfit(m: &Midsurface, box_: (Vector2<f64>, Vector2<f64>)) -> f64 {
        let area = (box_.1 - box_.0).product() / 1600.0;
        samples(box_, 40)
            .iter()
            .map(|x| (gradient(m, x) - m.rotation(x) * m.stretch).norm_squared() * area)
            .sum()
    }

    /// `II_{αβ} = n · φ_{,αβ}` with the normal of `φ` itself (3.10), by second differences of step `d`.
    fn second_form_of_the_surface(m: &Midsurface, x: &Vector2<f64>, d: f64) -> Matrix2<f64> {
        let grad = gradient(m, x);
        let n = grad.column(0).cross(&grad.column(1)).normalize();
        let p = |a: f64, b: f64| m.position(&(x + Vector2::new(a, b))).dot(&n);
        let p11 = (p(d, 0.0) - 2.0 * p(0.0, 0.0) + p(-d, 0.0)) / (d * d);
        let p22 = (p(0.0, d) - 2.0 * p(0.0, 0.0) + p(0.0, -d)) / (d * d);
        let p12 = (p(d, d) - p(d, -d) - p(-d, d) + p(-d, -d)) / (4.0 * d * d);
        Matrix2::new(p11, p12, p12, p22)
    }

    fn doubly_curved() -> [MacroStrain; 4] {
        [
            (0.0, 0.0, 0.0, 40.0, 40.0),
            (0.0, 0.0, 0.0, 40.0, -40.0),
            (0.1, 0.2, -0.05, 40.0, 40.0),
            (0.1, 0.2, -0.05, 40.0, -40.0),
        ]
        .map(|(sx, sa, sy, kx, ky)| MacroStrain::new(sx, sa, sy, kx, ky).expect("valid"))
    }

    #[test]
    fn singly_curved_midsurfaces_over_a_domain_are_the_closed_form() {
        let strain = MacroStrain::new(0.1, 0.2, -0.05, 40.0, 0.0).expect("valid");
        let (lower, upper) = domain(1.0);
        let (m, line) = (Midsurface::over_domain(&strain, lower, upper), Midsurface::new(&strain));
        for x in samples((lower * 1.5, upper * 1.5), 9) {
            assert!(
                (m.position(&x) - line.position(&x)).norm() <= 1e-12 * line.position(&x).norm(),
                "at {x}"
            );
            assert_eq!((m.rotation(&x), m.normal(&x)), (line.rotation(&x), line.normal(&x)));
        }
    }

    #[test]
    fn doubly_curved_midsurfaces_are_the_least_squares_solution() {
        for strain in doubly_curved() {
            let box_ = domain(1.0);
            let m = Midsurface::over_domain(&strain, box_.0, box_.1);
            assert!(m.position(&Vector2::zeros()).norm() < 1e-16);
            // φ minimizes ∫ |∇φ - R S̄|² (3.17-3.18); measured: 0.40-0.41 of the straight-line misfit.
            let (least_squares, line) = (misfit(&m, box_), misfit(&Midsurface::new(&strain), box_));
            assert!(least_squares < 0.5 * line, "{strain:?}: misfit {least_squares:e} vs {line:e}");
        }
    }

    /// The largest relative errors of I and II at points near the centre of the box scaled by `scale`,
    /// and `|K| ρ²` (`K = det II / det I`, `ρ` the half diagonal of the box).
    fn centre_errors(strain: &MacroStrain, scale: f64) -> (f64, f64, f64) {
        let box_ = domain(scale);
        let m = Midsurface::over_domain(strain, box_.0, box_.1);
        let (i, ii) = (strain.s.first_fundamental_form(), strain.second_fundamental_form());
        let near = [Vector2::zeros(), Vector2::new(1e-3, 5e-4) * scale, Vector2::new(-1e-3, 1e-3) * scale];
        let error = |f: &dyn Fn(&Vector2<f64>) -> Matrix2<f64>, target: &Matrix2<f64>| {
            near.iter().map(|x| (f(x) - target).norm() / target.norm()).fold(0.0, f64::max)
        };
        let i_error = error(&|x| gradient(&m, x).transpose() * gradient(&m, x), &i);
        let ii_error = error(&|x| second_form_of_the_surface(&m, x, 2e-4 * scale), &ii);
        let rho = (box_.1 - box_.0).norm() / 2.0;
        (i_error, ii_error, (ii.determinant() / i.determinant()).abs() * rho * rho)
    }

    #[test]
    fn doubly_curved_midsurfaces_match_i_and_ii_to_order_k_extent_squared() {
        // No surface has constant I and II with K ≠ 0 (Theorema Egregium), and the least-squares
        // solve spreads the metric defect, O(|K| ρ²), over the whole box, centre included.
        // Measured on the 20 mm x 12 mm box (|K| ρ² = 0.21-0.22): I 1.27-1.40e-2 (0.061-0.064 |K| ρ²),
        // II 0.77-6.3e-3 (0.004-0.030 |K| ρ², largest for the saddles).
        for strain in doubly_curved() {
            let (i_error, ii_error, bound) = centre_errors(&strain, 1.0);
            assert!(i_error < 0.1 * bound, "{strain:?}: I error {i_error:e}, |K| ρ² = {bound}");
            assert!(ii_error < 0.05 * bound, "{strain:?}: II error {ii_error:e}, |K| ρ² = {bound}");
        }
        // ... and it is O(ρ²): halving the box quarters the error (measured ratio 4.00).
        let strain = doubly_curved()[0];
        let ratio = centre_errors(&strain, 1.0).0 / centre_errors(&strain, 0.5).0;
        assert!((3.5..4.5).contains(&ratio), "I error ratio {ratio}");
    }

    #[test]
    fn least_squares_midsurfaces_converge_at_second_order() {
        let strain = doubly_curved()[3];
        let (lower, upper) = domain(1.0);
        let reference = Midsurface::over_domain_with_cells(&strain, lower, upper, 128);
        let error = |cells| {
            let m = Midsurface::over_domain_with_cells(&strain, lower, upper, cells);
            let points = samples((lower, upper), 21);
            points.iter().map(|x| (m.position(x) - reference.position(x)).norm()).fold(0.0, f64::max)
        };
        let (coarse, fine) = (error(16), error(32));
        // Measured: 1.5e-6 m and 3.4e-7 m (ratio 4.3; 64 cells: 9.4e-8 m), for a correction
        // φ - φ_line of up to 7e-5 m.
        assert!(fine < coarse / 3.0, "16 cells: {coarse:e}, 32 cells: {fine:e}");
    }

    #[test]
    fn least_squares_midsurfaces_are_defined_everywhere() {
        let strain = doubly_curved()[1];
        // The box is extended to the centre, where φ = 0.
        let m = Midsurface::over_domain(&strain, Vector2::new(1e-3, 2e-3), Vector2::new(8e-3, 6e-3));
        assert!(m.position(&Vector2::zeros()).norm() < 1e-16);
        // Outside the box: continuous, and never a panic.
        let edge = Vector2::new(8e-3, 3e-3);
        let step = (m.position(&(edge + Vector2::new(1e-9, 0.0))) - m.position(&edge)).norm();
        assert!(step < 2e-9, "jump {step:e} across the boundary");
        assert!(m.position(&Vector2::new(0.5, -0.3)).iter().all(|v| v.is_finite()));
        assert!(m.position(&Vector2::new(f64::NAN, 0.0)).x.is_nan());
        // Degenerate boxes fall back to the straight-line midsurface.
        let point = Midsurface::over_domain(&strain, Vector2::zeros(), Vector2::zeros());
        assert_eq!(point, Midsurface::new(&strain));
    }

    proptest! {
        #[test]
        fn singly_curved_midsurfaces_have_the_requested_fundamental_forms(
            strain in singly_curved(), x1 in -0.03..0.03f64, x2 in -0.03..0.03f64,
        ) {
            let m = Midsurface::new(&strain);
            let x = Vector2::new(x1, x2);
            let grad = gradient(&m, &x);
            // ∇φ = R S̄ (3.14), hence I = S̄ᵀ S̄ (3.15).
            prop_assert!((grad - m.rotation(&x) * m.stretch).norm() < 1e-7);
            prop_assert!((grad.transpose() * grad - strain.s.first_fundamental_form()).norm() < 1e-7);
            let ii = second_form(&m, &x);
            prop_assert!((ii - strain.second_fundamental_form()).norm() < 1e-4 * (1.0 + strain.kx.abs() + strain.ky.abs()));
        }
    }
}
