//! The curvature split of thesis Sec. 4.1.2 and App. A.4, (A.39)-(A.41), in a form whose
//! derivatives stay bounded at umbilic points (`II` a multiple of the identity, flat cloth
//! included).
//!
//! A bending term `φ` is evaluated on the principal curvatures `λ1,2 = m ± S` of `II` and blended
//! by the squared cosine `c²` of the first principal direction (A.41):
//! `T = c² φ(λ1) + (1 - c²) φ(λ2)` (x-bending; y-bending swaps `λ1` and `λ2`). With
//! `m = (II11 + II22)/2`, `B = (II11 - II22)/2`, `b = II12`, `S = √(B² + b² + ε)` (A.39c) and
//! `c² - 1/2 = B / 2S` (the cosine of twice the principal angle), the blend is
//!
//! `T = E(m, t) ± B D(m, t)`, `E = (φ(λ1) + φ(λ2)) / 2`, `D = (φ(λ1) - φ(λ2)) / 2S`, `t = S²`,
//!
//! and `E`, `D` are even in `S`, so smooth functions of `t`: the value is the thesis' blend (up to
//! the regularization: (A.40c)'s `c²` and `1/2 + B/2S` differ by `O(ε/S²)`), and the derivatives
//! are taken in `(m, t, B)`. Written with `λ1,2` and `c²` as in ARCSim-HYLC, each of `∂²λ/∂II²`
//! and `∂²c²/∂II²` grows like `1/S` or `1/ε` towards an umbilic and they cancel only in exact
//! arithmetic; at a flat triangle (`S = √ε ≈ 3e-8`) that left element Hessians with eigenvalues
//! of ±1e10 N/m on the published stockinette.

use nalgebra::{Matrix4, Vector4};

/// Regularizes the square root at an umbilic point (`ε` of (A.39c)); ARCSim-HYLC uses the same.
const EPSILON: f64 = 1e-15;

/// Below this half-gap `S` (in the term's normalized curvature), the divided differences of
/// `D` in `t` are taken from their Taylor series (exact within a cubic piece): evaluated
/// directly they cancel catastrophically, with rounding errors growing like `1/S³`.
const SMALL_GAP: f64 = 1e-3;

/// `II` in the coordinates of the split.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CurvatureSplit {
    /// Mean curvature `m = (II11 + II22) / 2`.
    pub mean: f64,
    /// `B = (II11 - II22) / 2` (A.39b).
    pub half_difference: f64,
    /// `b = II12`.
    pub twist: f64,
    /// `S = √(B² + b² + ε)` (A.39c): half the gap between the principal curvatures.
    pub half_gap: f64,
}

impl CurvatureSplit {
    /// The split of `II = (II11, II12, II22)`.
    pub fn new(second: [f64; 3]) -> Self {
        let [a, b, c] = second;
        let half_difference = 0.5 * (a - c);
        let half_gap = (half_difference * half_difference + b * b + EPSILON).sqrt();
        Self { mean: 0.5 * (a + c), half_difference, twist: b, half_gap }
    }

    /// The principal curvatures `λ1 = m + S ≥ λ2 = m - S` (A.40a-b).
    pub fn principal_curvatures(&self) -> [f64; 2] {
        [self.mean + self.half_gap, self.mean - self.half_gap]
    }

    /// `c²`, the squared cosine between the first principal direction and the x-axis, as the
    /// blend uses it: `1/2 + B / 2S`.
    pub fn squared_cosine(&self) -> f64 {
        0.5 + 0.5 * self.half_difference / self.half_gap
    }
}

/// A term `φ(x, λ)` at one curvature `λ`, with its derivatives in an in-plane strain `x` (zero
/// for a 1D bending term) and in `λ`, all in physical units.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct TermJet {
    /// `φ`.
    pub value: f64,
    /// `∂φ/∂x`.
    pub x: f64,
    /// `∂φ/∂λ`.
    pub l: f64,
    /// `∂²φ/∂x²`.
    pub xx: f64,
    /// `∂²φ/∂x∂λ`.
    pub xl: f64,
    /// `∂²φ/∂λ²`.
    pub ll: f64,
}

/// Which principal curvature a term's `c²` weighs (4.3).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BendingAxis {
    /// x-bending: `c² φ(λ1) + (1 - c²) φ(λ2)`.
    X,
    /// y-bending: `c² φ(λ2) + (1 - c²) φ(λ1)`.
    Y,
}

impl BendingAxis {
    /// `+1` for x-bending, `-1` for y-bending: the sign of `B` in `E ± B D`.
    fn sign(self) -> f64 {
        match self {
            BendingAxis::X => 1.0,
            BendingAxis::Y => -1.0,
        }
    }
}

/// `E = (φ+ + φ-)/2` and `D = (φ+ - φ-)/2S` of a term's values at `λ1` and `λ2`.
fn blend_parts(split: &CurvatureSplit, first: f64, second: f64) -> (f64, f64) {
    (0.5 * (first + second), (first - second) / (2.0 * split.half_gap))
}

/// The value of the blend (A.41) of a term valued `first` at `λ1` and `second` at `λ2`: the
/// same as [`blend`]'s, to the last bit.
pub fn blend_value(split: &CurvatureSplit, axis: BendingAxis, first: f64, second: f64) -> f64 {
    let (e, d) = blend_parts(split, first, second);
    e + axis.sign() * split.half_difference * d
}

/// The blend (A.41) of a term evaluated at `λ1` (`at_first`) and `λ2` (`at_second`), with its
/// gradient and Hessian in `(x, II11, II12, II22)`. `scale` is the term's curvature scale (its
/// normalization), which sets what counts as a small gap.
pub fn blend(
    split: &CurvatureSplit,
    axis: BendingAxis,
    at_first: &TermJet,
    at_second: &TermJet,
    scale: f64,
) -> (f64, Vector4<f64>, Matrix4<f64>) {
    let (p, q) = (at_first, at_second);
    let u = split.half_gap;
    let sign = axis.sign();
    let sb = sign * split.half_difference;
    // E = (φ+ + φ-)/2 and its derivatives in (x, m, t); ∂/∂t = ∂/∂S / 2S.
    let (e_x, e_m) = (0.5 * (p.x + q.x), 0.5 * (p.l + q.l));
    let (e_xx, e_xm, e_mm) = (0.5 * (p.xx + q.xx), 0.5 * (p.xl + q.xl), 0.5 * (p.ll + q.ll));
    let e_t = (p.l - q.l) / (4.0 * u);
    let e_xt = (p.xl - q.xl) / (4.0 * u);
    let e_mt = (p.ll - q.ll) / (4.0 * u);
    let e_tt = (u * (p.ll + q.ll) - (p.l - q.l)) / (8.0 * u * u * u);
    // D = (φ+ - φ-)/2S and its derivatives.
    let (e, d) = blend_parts(split, p.value, q.value);
    let (d_x, d_m) = ((p.x - q.x) / (2.0 * u), (p.l - q.l) / (2.0 * u));
    let (d_xx, d_xm, d_mm) =
        ((p.xx - q.xx) / (2.0 * u), (p.xl - q.xl) / (2.0 * u), (p.ll - q.ll) / (2.0 * u));
    let d_xt = (u * (p.xl + q.xl) - (p.x - q.x)) / (4.0 * u * u * u);
    let d_mt = (u * (p.ll + q.ll) - (p.l - q.l)) / (4.0 * u * u * u);
    let (d_t, d_tt) = if u < SMALL_GAP * scale {
        // Within a cubic piece φ''' = (φ''+ - φ''-)/2S exactly, D_t = φ'''/6 and D_tt = 0.
        ((p.ll - q.ll) / (12.0 * u), 0.0)
    } else {
        let n = u * (p.l + q.l) - (p.value - q.value);
        (n / (4.0 * u * u * u), (p.ll - q.ll) / (8.0 * u * u * u) - 3.0 * n / (8.0 * u.powi(5)))
    };
    // T = F(x, m, t, B) = E ± B D, over w = (x, m, t, B).
    let value = e + sb * d;
    let f_w = Vector4::new(e_x + sb * d_x, e_m + sb * d_m, e_t + sb * d_t, sign * d);
    let f_ww = Matrix4::new(
        e_xx + sb * d_xx,
        e_xm + sb * d_xm,
        e_xt + sb * d_xt,
        sign * d_x, //
        e_xm + sb * d_xm,
        e_mm + sb * d_mm,
        e_mt + sb * d_mt,
        sign * d_m, //
        e_xt + sb * d_xt,
        e_mt + sb * d_mt,
        e_tt + sb * d_tt,
        sign * d_t, //
        sign * d_x,
        sign * d_m,
        sign * d_t,
        0.0,
    );
    // w as a function of v = (x, II11, II12, II22): m = (II11 + II22)/2, B = (II11 - II22)/2,
    // t = B² + II12² + ε.
    let (bh, b) = (split.half_difference, split.twist);
    let w_v = Matrix4::new(
        1.0,
        0.0,
        0.0,
        0.0, //
        0.0,
        0.5,
        0.0,
        0.5, //
        0.0,
        bh,
        2.0 * b,
        -bh, //
        0.0,
        0.5,
        0.0,
        -0.5,
    );
    // ∂²t/∂v² = 2 ∂B ∂Bᵀ + 2 e_b e_bᵀ.
    let t_vv = Matrix4::new(
        0.0, 0.0, 0.0, 0.0, //
        0.0, 0.5, 0.0, -0.5, //
        0.0, 0.0, 2.0, 0.0, //
        0.0, -0.5, 0.0, 0.5,
    );
    let gradient = w_v.transpose() * f_w;
    let hessian = w_v.transpose() * f_ww * w_v + f_w[2] * t_vv;
    (value, gradient, hessian)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A cubic `φ(x, λ) = λ³/6 + 2λ² - 3λ + xλ + x²` as a term jet.
    fn term(x: f64, l: f64) -> TermJet {
        TermJet {
            value: l * l * l / 6.0 + 2.0 * l * l - 3.0 * l + x * l + x * x,
            x: l + 2.0 * x,
            l: 0.5 * l * l + 4.0 * l - 3.0 + x,
            xx: 2.0,
            xl: 1.0,
            ll: l + 4.0,
        }
    }

    fn blended(v: [f64; 4], axis: BendingAxis) -> (f64, Vector4<f64>, Matrix4<f64>) {
        let split = CurvatureSplit::new([v[1], v[2], v[3]]);
        let [l1, l2] = split.principal_curvatures();
        blend(&split, axis, &term(v[0], l1), &term(v[0], l2), 1.0)
    }

    #[test]
    fn eigenvalues_and_direction_of_known_forms() {
        // diag(3, 1): λ1 = 3 along x.
        let s = CurvatureSplit::new([3.0, 0.0, 1.0]);
        let [a, b] = s.principal_curvatures();
        assert!((a - 3.0).abs() < 1e-12 && (b - 1.0).abs() < 1e-12);
        assert!((s.squared_cosine() - 1.0).abs() < 1e-12);
        // diag(1, 3): λ1 = 3 along y, so c² = 0.
        let s = CurvatureSplit::new([1.0, 0.0, 3.0]);
        assert!((s.principal_curvatures()[0] - 3.0).abs() < 1e-12 && s.squared_cosine().abs() < 1e-12);
        // A rotation by θ of diag(λ1, λ2): c² = cos² θ.
        let (theta, l1, l2) = (0.4_f64, 2.0, -1.0);
        let (cs, sn) = (theta.cos(), theta.sin());
        let s = CurvatureSplit::new([
            l1 * cs * cs + l2 * sn * sn,
            (l1 - l2) * cs * sn,
            l1 * sn * sn + l2 * cs * cs,
        ]);
        let [a, b] = s.principal_curvatures();
        assert!((a - l1).abs() < 1e-12 && (b - l2).abs() < 1e-12);
        assert!((s.squared_cosine() - cs * cs).abs() < 1e-12);
    }

    #[test]
    fn the_blend_is_the_weighted_sum_of_a41() {
        for v in [[0.3, 2.0, 0.7, -1.0], [-0.2, -1.0, -0.4, 0.5], [0.0, 5.0, 0.0, 5.0]] {
            let split = CurvatureSplit::new([v[1], v[2], v[3]]);
            let ([l1, l2], c2) = (split.principal_curvatures(), split.squared_cosine());
            let (f1, f2) = (term(v[0], l1).value, term(v[0], l2).value);
            assert!((blended(v, BendingAxis::X).0 - (c2 * f1 + (1.0 - c2) * f2)).abs() < 1e-12);
            assert!((blended(v, BendingAxis::Y).0 - (c2 * f2 + (1.0 - c2) * f1)).abs() < 1e-12);
        }
    }

    #[test]
    fn derivatives_match_finite_differences() {
        let h = 1e-5;
        for axis in [BendingAxis::X, BendingAxis::Y] {
            for v in [
                [0.3, 2.0, 0.3, -1.0],
                [-0.5, -1.0, 0.7, 0.5],
                [0.2, 0.2, -0.4, 0.2],
                [1.0, 30.0, 12.0, -80.0],
            ] {
                let (_, g, hess) = blended(v, axis);
                for j in 0..4 {
                    let (mut plus, mut minus) = (v, v);
                    plus[j] += h;
                    minus[j] -= h;
                    let (p, m) = (blended(plus, axis), blended(minus, axis));
                    let fd = (p.0 - m.0) / (2.0 * h);
                    assert!((g[j] - fd).abs() < 1e-6 * (1.0 + fd.abs()), "{v:?} dT/d{j}: {} vs {fd}", g[j]);
                    for i in 0..4 {
                        let fd2 = (p.1[i] - m.1[i]) / (2.0 * h);
                        assert!(
                            (hess[(i, j)] - fd2).abs() < 1e-5 * (1.0 + fd2.abs()),
                            "{v:?} d2T/d{i}d{j}: {} vs {fd2}",
                            hess[(i, j)]
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn derivatives_stay_bounded_and_continuous_at_an_umbilic() {
        // A cubic term on a flat and a near-flat II: the blend is a smooth function of II (a
        // cubic in the principal curvatures, linear at first order: f'(0) II11 for x-bending),
        // so its Hessian approaches the smooth one instead of growing like 1/S.
        let at = |v: [f64; 4]| blended(v, BendingAxis::X);
        let flat = at([0.1, 0.0, 0.0, 0.0]);
        for e in [1e-2, 1e-5, 1e-9] {
            for v in [[0.1, e, 0.0, 0.0], [0.1, 0.0, e, 0.0], [0.1, -e, 0.3 * e, e]] {
                let near = at(v);
                assert!((near.1 - flat.1).amax() < 1e3 * e + 1e-8, "gradient at {v:?}");
                assert!((near.2 - flat.2).amax() < 10.0 * e.sqrt() + 1e-6, "Hessian at {v:?}: {}", near.2);
            }
        }
        // φ = λ³/6 + 2λ² - 3λ + xλ + x²: at II = 0 the x-bending blend is
        // φ(II11) + (II12² terms) and its Hessian in (II11, II12, II22) is diag(4, 4, 0) + ...
        assert!(flat.2.amax() < 10.0, "{}", flat.2);
    }
}
