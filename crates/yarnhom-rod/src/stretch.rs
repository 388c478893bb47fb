//! Stretching of one yarn edge: `W = L ψ(ε)` with rest length `L` and axial strain
//! `ε = |x1 - x0| / L - 1`, for a linear law (discrete elastic rods, Ch. 3) and the biphasic
//! law (6.5) of Ch. 6. Gradient and Hessian are closed form.

use nalgebra::{Matrix3, SMatrix, SVector, Vector3};

/// Strain energy density per unit rest length, as a function of axial strain.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum StretchLaw {
    /// `ψ = k ε² / 2` with `k = E A` (N): the stretching energy of discrete elastic rods.
    Linear {
        /// Axial stiffness (N).
        k_n: f64,
    },
    /// (6.5): stiffness `k_s2` in compression, `k_s1` up to the onset `eps_bar`, `k_s2` beyond,
    /// continuous in force.
    Biphasic {
        /// Low-stretch stiffness (N).
        k_s1_n: f64,
        /// High-stretch and compression stiffness (N).
        k_s2_n: f64,
        /// Onset of high stretch (strain).
        eps_bar: f64,
    },
}

impl StretchLaw {
    /// `(ψ, ψ', ψ'')` at strain `eps`.
    pub fn density(&self, eps: f64) -> (f64, f64, f64) {
        match *self {
            StretchLaw::Linear { k_n } => (0.5 * k_n * eps * eps, k_n * eps, k_n),
            StretchLaw::Biphasic { k_s1_n: k1, k_s2_n: k2, eps_bar: e } => {
                if eps <= 0.0 {
                    (0.5 * k2 * eps * eps, k2 * eps, k2)
                } else if eps <= e {
                    (0.5 * k1 * eps * eps, k1 * eps, k1)
                } else {
                    let d = eps - e;
                    (0.5 * (k2 * d * d + k1 * e * (2.0 * eps - e)), k2 * d + k1 * e, k2)
                }
            }
        }
    }
}

/// Energy, gradient and Hessian of one stretched edge from `x0` to `x1` with rest length
/// `rest_length`; DOFs ordered `(x0, x1)`.
pub fn stretch_energy(
    law: &StretchLaw,
    rest_length: f64,
    x0: &Vector3<f64>,
    x1: &Vector3<f64>,
) -> (f64, SVector<f64, 6>, SMatrix<f64, 6, 6>) {
    let e = x1 - x0;
    let length = e.norm();
    let t = e / length;
    let eps = length / rest_length - 1.0;
    let (psi, dpsi, ddpsi) = law.density(eps);
    let energy = rest_length * psi;
    // dW/dx1 = L ψ' dε/de = ψ' t; d²W/dx1² = ψ''/L t tᵀ + ψ'/|e| (I - t tᵀ).
    let f = t * dpsi;
    let tt = t * t.transpose();
    let k = tt * (ddpsi / rest_length) + (Matrix3::identity() - tt) * (dpsi / length);
    let mut gradient = SVector::<f64, 6>::zeros();
    gradient.fixed_rows_mut::<3>(0).copy_from(&(-f));
    gradient.fixed_rows_mut::<3>(3).copy_from(&f);
    let mut hessian = SMatrix::<f64, 6, 6>::zeros();
    hessian.fixed_view_mut::<3, 3>(0, 0).copy_from(&k);
    hessian.fixed_view_mut::<3, 3>(3, 3).copy_from(&k);
    hessian.fixed_view_mut::<3, 3>(0, 3).copy_from(&(-k));
    hessian.fixed_view_mut::<3, 3>(3, 0).copy_from(&(-k));
    (energy, gradient, hessian)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::{check_derivatives, random_vector};

    const LAWS: [StretchLaw; 2] =
        [StretchLaw::Linear { k_n: 3.0 }, StretchLaw::Biphasic { k_s1_n: 0.5, k_s2_n: 20.0, eps_bar: 0.08 }];

    #[test]
    fn rest_length_edge_has_no_energy_or_force() {
        for law in LAWS {
            let (e, g, _) = stretch_energy(&law, 2.0, &Vector3::zeros(), &Vector3::new(0.0, 2.0, 0.0));
            assert!(e.abs() < 1e-15 && g.norm() < 1e-15);
        }
    }

    #[test]
    fn biphasic_force_is_continuous_and_its_energy_matches_6_5() {
        let law = StretchLaw::Biphasic { k_s1_n: 0.5, k_s2_n: 20.0, eps_bar: 0.08 };
        for at in [0.0, 0.08] {
            let (a, fa, _) = law.density(at - 1e-12);
            let (b, fb, _) = law.density(at + 1e-12);
            assert!((a - b).abs() < 1e-12 && (fa - fb).abs() < 1e-9, "discontinuity at {at}");
        }
        // (6.5), third branch, written out.
        let eps: f64 = 0.2;
        let expected = 0.5 * (20.0 * (eps - 0.08).powi(2) + 0.5 * 0.08 * (2.0 * eps - 0.08));
        assert!((law.density(eps).0 - expected).abs() < 1e-15);
    }

    #[test]
    fn analytic_derivatives_match_finite_differences() {
        let mut rng = 7u64;
        for law in LAWS {
            for _ in 0..50 {
                let q: SVector<f64, 6> = random_vector(&mut rng, 1.0);
                let f = |q: &SVector<f64, 6>| {
                    stretch_energy(&law, 1.3, &q.fixed_rows::<3>(0).into(), &q.fixed_rows::<3>(3).into())
                };
                check_derivatives(&f, &q);
            }
        }
    }
}
