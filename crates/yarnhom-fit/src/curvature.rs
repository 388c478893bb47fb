//! Principal curvatures and the squared cosine of the first principal direction of a second
//! fundamental form, robust to repeated eigenvalues (thesis App. A.4, (A.39)-(A.41)), with exact
//! first and second derivatives in `(II11, II12, II22)`.

use nalgebra::{Matrix3, Vector3};

/// Guards the square root at an umbilic point (`ε` of (A.39c)); ARCSim-HYLC uses the same.
const EPSILON: f64 = 1e-15;

/// `(λ1, λ2, c²)` and their first and second derivatives in `(II11, II12, II22)`.
#[derive(Debug, Clone, Copy)]
pub struct PrincipalCurvatures {
    /// `(λ1, λ2, c²)` (A.40).
    pub value: Vector3<f64>,
    /// Row `k` is the gradient of component `k`.
    pub gradient: Matrix3<f64>,
    /// The Hessian of each component.
    pub hessian: [Matrix3<f64>; 3],
}

/// Eigenvalues `λ1 ≥ λ2` of `II` and `c²`, the squared cosine between the `λ1` eigenvector and
/// the x-axis, (A.39)-(A.40), with derivatives. The sign `k` of (A.39d) makes the blend (A.41)
/// continuous when the eigenvalues cross; `k = 1` when `II11 = II22`, as in ARCSim-HYLC.
pub fn principal_curvatures(ii: [f64; 3]) -> PrincipalCurvatures {
    let [a, b, c] = ii;
    let half_diff = 0.5 * (a - c); // B (A.39b)
    let k = if a < c { -1.0 } else { 1.0 }; // (A.39d)
    let s = (half_diff * half_diff + b * b + EPSILON).sqrt(); // S (A.39c)
    let d_mean = Vector3::new(0.5, 0.0, 0.5); // ∂A
    let d_half_diff = Vector3::new(0.5, 0.0, -0.5); // ∂B
    let e_b = Vector3::new(0.0, 1.0, 0.0);
    let d_s = (half_diff * d_half_diff + b * e_b) / s;
    // S² = B² + b² + ε with B, b linear: S ∂²S + ∂S ∂Sᵀ = ∂B ∂Bᵀ + e_b e_bᵀ.
    let dd_s = (d_half_diff * d_half_diff.transpose() + e_b * e_b.transpose() - d_s * d_s.transpose()) / s;
    let mean = 0.5 * (a + c);

    // c² = 1/2 + k/2 - k g, g = b² / Q, Q = (B + kS)² + b² ≥ S² > 0 (A.40c).
    let d = half_diff + k * s;
    let dd = d_half_diff + k * d_s;
    let q = d * d + b * b;
    let dq = 2.0 * d * dd + 2.0 * b * e_b;
    let ddq = 2.0 * dd * dd.transpose() + 2.0 * d * k * dd_s + 2.0 * e_b * e_b.transpose();
    let n = b * b;
    let dn = 2.0 * b * e_b;
    let ddn = 2.0 * e_b * e_b.transpose();
    let g = n / q;
    let dg = dn / q - n * dq / (q * q);
    let ddg = ddn / q - (dn * dq.transpose() + dq * dn.transpose()) / (q * q)
        + 2.0 * n * dq * dq.transpose() / (q * q * q)
        - n * ddq / (q * q);

    PrincipalCurvatures {
        value: Vector3::new(mean + s, mean - s, 0.5 + 0.5 * k - k * g),
        gradient: Matrix3::from_rows(&[
            (d_mean + d_s).transpose(),
            (d_mean - d_s).transpose(),
            (-k * dg).transpose(),
        ]),
        hessian: [dd_s, -dd_s, -k * ddg],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn eigenvalues_and_direction_of_known_forms() {
        // diag(3, 1): λ1 = 3 along x.
        let p = principal_curvatures([3.0, 0.0, 1.0]).value;
        assert!((p[0] - 3.0).abs() < 1e-12 && (p[1] - 1.0).abs() < 1e-12 && (p[2] - 1.0).abs() < 1e-12);
        // diag(1, 3): λ1 = 3 along y, so c² = 0.
        let p = principal_curvatures([1.0, 0.0, 3.0]).value;
        assert!((p[0] - 3.0).abs() < 1e-12 && p[2].abs() < 1e-12);
        // A rotation by θ of diag(λ1, λ2): c² = cos² θ.
        let (theta, l1, l2) = (0.4_f64, 2.0, -1.0);
        let (cs, sn) = (theta.cos(), theta.sin());
        let ii = [l1 * cs * cs + l2 * sn * sn, (l1 - l2) * cs * sn, l1 * sn * sn + l2 * cs * cs];
        let p = principal_curvatures(ii).value;
        assert!((p[0] - l1).abs() < 1e-12 && (p[1] - l2).abs() < 1e-12);
        assert!((p[2] - cs * cs).abs() < 1e-12);
    }

    #[test]
    fn the_blend_is_continuous_through_an_umbilic() {
        // (A.41): c²(f(λ1) + g(λ2)) + (1 - c²)(f(λ2) + g(λ1)) with f ≠ g.
        let blend = |ii: [f64; 3]| {
            let p = principal_curvatures(ii).value;
            let (f, g) = (|x: f64| x * x * x + x, |x: f64| 2.0 * x);
            p[2] * (f(p[0]) + g(p[1])) + (1.0 - p[2]) * (f(p[1]) + g(p[0]))
        };
        for e in [1e-3, 1e-6, 1e-9] {
            let (left, right) = (blend([1.0 - e, 0.0, 1.0]), blend([1.0 + e, 0.0, 1.0]));
            // Continuous up to the regularization: S >= sqrt(ε) ≈ 3e-8.
            assert!((left - right).abs() < 10.0 * (e + EPSILON.sqrt()), "jump {} at e = {e}", left - right);
        }
    }

    #[test]
    fn derivatives_match_finite_differences() {
        let h = 1e-6;
        for ii in [[2.0, 0.3, -1.0], [-1.0, 0.7, 0.5], [0.2, -0.4, 0.2], [30.0, 12.0, -80.0]] {
            let p = principal_curvatures(ii);
            for j in 0..3 {
                let (mut plus, mut minus) = (ii, ii);
                plus[j] += h;
                minus[j] -= h;
                let (pp, pm) = (principal_curvatures(plus), principal_curvatures(minus));
                for c in 0..3 {
                    let fd = (pp.value[c] - pm.value[c]) / (2.0 * h);
                    assert!((p.gradient[(c, j)] - fd).abs() < 1e-6 * (1.0 + fd.abs()), "{ii:?} d{c}/d{j}");
                    for i in 0..3 {
                        let fd2 = (pp.gradient[(c, i)] - pm.gradient[(c, i)]) / (2.0 * h);
                        assert!(
                            (p.hessian[c][(i, j)] - fd2).abs() < 1e-5 * (1.0 + fd2.abs()),
                            "{ii:?} d2{c}/d{i}d{j}"
                        );
                    }
                }
            }
        }
    }
}
