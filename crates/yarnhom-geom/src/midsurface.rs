//! The RVE midsurface of a macroscale deformation (I, II) (Sec. 3.2.2, App. A.1.1).
//!
//! - `S̄ = [√I; 0 0]` (A.11), the in-plane stretch with `S̄ᵀS̄ = I` (3.15);
//! - the normal derivatives `[n̄_{i,α}] = -(√I)^{-T} II` (A.12);
//! - the rotation field `R(X) = exp W(X)`, `W` skew with `W_13 = a`, `W_23 = b`,
//!   `a = Σ n̄_{1,α} X_α`, `b = Σ n̄_{2,α} X_α` (A.6-A.10), evaluated with robust sinc terms;
//! - the midsurface `φ(X) = ∫₀¹ R(tX) S̄ X dt = [I + (1 - cos r)/r² W + (r - sin r)/r³ W²] S̄ X`,
//!   the integral of `∇φ = R S̄` (3.14) along straight lines from the RVE centre. Because
//!   `W(tX) = t W(X)`, this is closed form. For singly curved deformations (rank II <= 1: all
//!   that the sampling of Sec. 4.1.1 uses) `R S̄` is a gradient field and `φ` matches I and II
//!   exactly, as the least-squares Poisson solve (3.17-3.18) would; for doubly curved ones it is
//!   the same straight-line approximation that (A.10) makes for `R`.

use nalgebra::{Matrix2, Matrix3, Matrix3x2, Vector2, Vector3};

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

/// The macroscale deformation of an RVE: everything needed to place yarns on the deformed
/// midsurface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Midsurface {
    /// `S̄` (3x2), (A.11).
    pub stretch: Matrix3x2<f64>,
    /// `[n̄_{i,α}]` (2x2), (A.12): row `i` = component, column `α` = derivative direction.
    pub normal_derivatives: Matrix2<f64>,
}

impl Midsurface {
    /// The midsurface of a sampled macro strain.
    pub fn new(strain: &MacroStrain) -> Self {
        let root = sqrt_spd2(&strain.s.first_fundamental_form());
        let inverse_transpose = root.try_inverse().unwrap_or_else(Matrix2::zeros).transpose();
        let mut stretch = Matrix3x2::zeros();
        stretch.fixed_view_mut::<2, 2>(0, 0).copy_from(&root);
        Midsurface { stretch, normal_derivatives: -inverse_transpose * strain.second_fundamental_form() }
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

    /// The deformed midsurface point `φ(X)`, with `φ(0) = 0`.
    pub fn position(&self, x: &Vector2<f64>) -> Vector3<f64> {
        let w = self.w(x);
        let r = self.tilt(x).norm();
        let integral = Matrix3::identity() + w * one_minus_cos_over_r2(r) + w * w * r_minus_sin_over_r3(r);
        integral * (self.stretch * x)
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
