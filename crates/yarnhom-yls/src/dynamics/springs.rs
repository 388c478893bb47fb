//! Glue springs between two vertices: `W = k (|x_a - x_b| - L)² / 2`, closed-form gradient and
//! Hessian in the DOFs `(x_a, x_b)`.

use nalgebra::{Matrix3, SMatrix, SVector, Vector3};

/// Energy, gradient and Hessian of a spring of stiffness `k` (N/m) and rest length `L` (m)
/// between `xa` and `xb`; DOFs ordered `(xa, xb)`. With `d = xa - xb`, `l = |d|`, `t = d / l`:
/// `∂W/∂xa = k (l - L) t`, `∂²W/∂xa² = k t tᵀ + k (l - L) / l (I - t tᵀ)` (for `L = 0`,
/// `W = k |d|² / 2` and `∂²W/∂xa² = k I`, also at `l = 0`).
pub(crate) fn glue_energy(
    stiffness_n_m: f64,
    rest_length_m: f64,
    xa: &Vector3<f64>,
    xb: &Vector3<f64>,
) -> (f64, SVector<f64, 6>, SMatrix<f64, 6, 6>) {
    let d = xa - xb;
    let k = stiffness_n_m;
    let (energy, force, block) = if rest_length_m == 0.0 {
        (0.5 * k * d.norm_squared(), d * k, Matrix3::identity() * k)
    } else {
        let length = d.norm();
        let t = d / length;
        let stretch = length - rest_length_m;
        let tt = t * t.transpose();
        (
            0.5 * k * stretch * stretch,
            t * (k * stretch),
            tt * k + (Matrix3::identity() - tt) * (k * stretch / length),
        )
    };
    let mut gradient = SVector::<f64, 6>::zeros();
    gradient.fixed_rows_mut::<3>(0).copy_from(&force);
    gradient.fixed_rows_mut::<3>(3).copy_from(&(-force));
    let mut hessian = SMatrix::<f64, 6, 6>::zeros();
    hessian.fixed_view_mut::<3, 3>(0, 0).copy_from(&block);
    hessian.fixed_view_mut::<3, 3>(3, 3).copy_from(&block);
    hessian.fixed_view_mut::<3, 3>(0, 3).copy_from(&(-block));
    hessian.fixed_view_mut::<3, 3>(3, 0).copy_from(&(-block));
    (energy, gradient, hessian)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn glue_derivatives_match_finite_differences() {
        for rest in [0.0, 0.3, 2.0] {
            let q = SVector::<f64, 6>::from_column_slice(&[0.1, 0.2, -0.3, 0.7, -0.4, 0.5]);
            let f = |q: &SVector<f64, 6>| {
                glue_energy(5.0, rest, &q.fixed_rows::<3>(0).into(), &q.fixed_rows::<3>(3).into())
            };
            let (_, g, h) = f(&q);
            let step = 1e-6;
            for i in 0..6 {
                let (mut up, mut down) = (q, q);
                up[i] += step;
                down[i] -= step;
                let fd = (f(&up).0 - f(&down).0) / (2.0 * step);
                assert!((fd - g[i]).abs() < 1e-7 * g.amax(), "rest {rest}, gradient {i}");
                let column = (f(&up).1 - f(&down).1) / (2.0 * step);
                assert!((column - h.column(i)).amax() < 1e-7 * h.amax(), "rest {rest}, hessian column {i}");
            }
        }
    }

    #[test]
    fn a_glue_spring_at_its_rest_length_is_free() {
        let (e, g, _) = glue_energy(5.0, 0.5, &Vector3::new(0.3, 0.0, 0.4), &Vector3::zeros());
        assert!(e.abs() < 1e-30 && g.amax() < 1e-15);
    }
}
