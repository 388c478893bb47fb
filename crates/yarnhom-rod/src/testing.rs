//! Test helpers: finite-difference checks of element derivatives.

use nalgebra::{SMatrix, SVector};

/// A reproducible pseudo-random vector with entries in `[-scale, scale]` (xorshift).
pub fn random_vector<const N: usize>(state: &mut u64, scale: f64) -> SVector<f64, N> {
    SVector::from_fn(|_, _| {
        *state ^= *state << 13;
        *state ^= *state >> 7;
        *state ^= *state << 17;
        scale * (2.0 * (*state >> 11) as f64 / (1u64 << 53) as f64 - 1.0)
    })
}

/// An element's energy, gradient and Hessian as a function of its DOFs.
pub type ElementFn<'a, const N: usize> =
    dyn Fn(&SVector<f64, N>) -> (f64, SVector<f64, N>, SMatrix<f64, N, N>) + 'a;

/// Central differences of energy and gradient against the analytic gradient (relative error
/// below 1e-5) and Hessian (below 1e-4), with a step of 1e-6 of the DOF scale.
pub fn check_derivatives<const N: usize>(f: &ElementFn<'_, N>, q: &SVector<f64, N>) {
    let (_, g, h) = f(q);
    let h_step = 1e-6 * q.amax().max(1e-3);
    let mut g_fd = SVector::<f64, N>::zeros();
    let mut h_fd = SMatrix::<f64, N, N>::zeros();
    for i in 0..N {
        let mut qp = *q;
        let mut qm = *q;
        qp[i] += h_step;
        qm[i] -= h_step;
        let (ep, gp, _) = f(&qp);
        let (em, gm, _) = f(&qm);
        g_fd[i] = (ep - em) / (2.0 * h_step);
        h_fd.set_column(i, &((gp - gm) / (2.0 * h_step)));
    }
    let rel = |a: f64, b: f64, scale: f64| (a - b).abs() / scale.max(1e-12);
    let g_scale = g.amax();
    let h_scale = h.amax();
    for i in 0..N {
        assert!(rel(g[i], g_fd[i], g_scale) < 1e-5, "gradient[{i}]: analytic {} vs fd {}", g[i], g_fd[i]);
        for j in 0..N {
            assert!(
                rel(h[(i, j)], h_fd[(i, j)], h_scale) < 1e-4,
                "hessian[{i},{j}]: analytic {} vs fd {}",
                h[(i, j)],
                h_fd[(i, j)]
            );
        }
    }
}
