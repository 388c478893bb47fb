//! Damping of non-rigid motion (Kaldor et al. 2008, Sec. 5.2 "damping"): over windows of `w`
//! consecutive vertices along each yarn, the part of the step's displacement that no rigid
//! motion of the window explains is damped, so that yarns tumble and slide freely while their
//! local wiggles die out.
//!
//! For a window with masses `m_i` and positions `p_i` at the start of the step (mass centre
//! `c`, `r_i = p_i - c`), the best rigid motion of a displacement `Δ` in the mass-weighted least
//! squares sense is `a + ω × r_i` with `a = Σ m_i Δ_i / Σ m_i` and `ω = J⁺ Σ m_i r_i × Δ_i`,
//! `J = Σ m_i (|r_i|² I - r_i r_iᵀ)` the window's inertia tensor (pseudo-inverted: a straight
//! window cannot see spin about its own axis). That fit is a projection `P_w`, orthogonal in the
//! mass metric and fixed for the step, and the dissipation potential is
//!
//! `D(x) = c / (2h) Σ_w |(I - P_w)(x - x_n)|²_M = c / (2h) Σ_w Δ_wᵀ K_w Δ_w`,
//! `K_w = M_w (I - P_w) = M_w - M_w B_w G_w⁺ B_wᵀ M_w`,
//!
//! with `B_w` the window's rigid motions (translations and rotations about `c`) and
//! `G_w = B_wᵀ M_w B_w`. `D` is quadratic with the positive semidefinite Hessian `(c/h) K_w`
//! per window; its force `-(c/h) K_w Δ = -c M (I - P) v_{n+1}` damps the non-rigid velocity at
//! the rate `c` (1/s). Windows: every run of `w` consecutive vertices (stride 1, overlapping;
//! wrapping around a closed yarn); a yarn shorter than `w` is one window.

use nalgebra::{DMatrix, DVector, Matrix3, SymmetricEigen, Vector3};
use rayon::prelude::*;

use super::input::InputError;

/// The damping of non-rigid motion.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Damping {
    /// Vertices per window `w` (at least 2; 5 in [`Damping::kaldor`]).
    pub window_vertices: usize,
    /// Damping rate `c` of the non-rigid velocity (1/s).
    pub rate_per_s: f64,
}

impl Damping {
    /// Windows of 5 vertices, the damping rate `rate_per_s`.
    pub fn kaldor(rate_per_s: f64) -> Damping {
        Damping { window_vertices: 5, rate_per_s }
    }

    pub(crate) fn validate(&self) -> Result<(), InputError> {
        if self.window_vertices < 2 {
            return Err(InputError::Parameter {
                what: "damping window".into(),
                range: "at least 2 vertices",
                value: self.window_vertices as f64,
            });
        }
        super::input::non_negative("damping rate", self.rate_per_s)
    }
}

/// The windows of `w` consecutive vertices of a yarn whose vertices are `first..first + n`.
pub(crate) fn yarn_windows(first: usize, n: usize, closed: bool, w: usize) -> Vec<Vec<usize>> {
    if n < 2 {
        return vec![];
    }
    if n <= w {
        return vec![(first..first + n).collect()];
    }
    let starts = if closed { n } else { n - w + 1 };
    (0..starts).map(|s| (0..w).map(|k| first + (s + k) % n).collect()).collect()
}

/// `[r]×`, the matrix of `v ↦ r × v`.
fn cross_matrix(r: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -r.z, r.y, r.z, 0.0, -r.x, -r.y, r.x, 0.0)
}

/// Relative eigenvalue below which the inertia tensor's pseudo-inverse drops a direction.
const INERTIA_CUTOFF: f64 = 1e-10;

/// `J⁺` for the symmetric positive semidefinite inertia tensor `J`.
fn pseudo_inverse(j: &Matrix3<f64>) -> Matrix3<f64> {
    let eigen = SymmetricEigen::new(*j);
    let largest = eigen.eigenvalues.amax();
    let mut inverse = Matrix3::zeros();
    for k in 0..3 {
        let lambda = eigen.eigenvalues[k];
        if lambda > INERTIA_CUTOFF * largest {
            let u = eigen.eigenvectors.column(k);
            inverse += u * u.transpose() / lambda;
        }
    }
    inverse
}

/// `K = M (I - P)` of one window with vertex masses `masses` at `points`: `3k x 3k`, symmetric
/// positive semidefinite, zero on the window's rigid motions. Block `(i, j)`:
/// `m_i δ_ij I - m_i m_j / Σm I + m_i m_j [r_i]× J⁺ [r_j]×` (the translations and the rotations
/// about the mass centre are orthogonal in the mass metric, so their projections add).
pub(crate) fn non_rigid_metric(points: &[Vector3<f64>], masses: &[f64]) -> DMatrix<f64> {
    let total: f64 = masses.iter().sum();
    let centre = points.iter().zip(masses).map(|(p, &m)| p * m).sum::<Vector3<f64>>() / total;
    let arms: Vec<Matrix3<f64>> = points.iter().map(|p| cross_matrix(&(p - centre))).collect();
    let inertia: Matrix3<f64> = arms.iter().zip(masses).map(|(a, &m)| -(a * a) * m).sum();
    let inertia_inverse = pseudo_inverse(&inertia);
    let k = points.len();
    let mut metric = DMatrix::zeros(3 * k, 3 * k);
    for i in 0..k {
        for j in 0..=i {
            let (mi, mj) = (masses[i], masses[j]);
            let mut block =
                arms[i] * inertia_inverse * arms[j] * (mi * mj) - Matrix3::identity() * (mi * mj / total);
            if i == j {
                block += Matrix3::identity() * mi;
            }
            metric.fixed_view_mut::<3, 3>(3 * i, 3 * j).copy_from(&block);
            metric.fixed_view_mut::<3, 3>(3 * j, 3 * i).copy_from(&block.transpose());
        }
    }
    metric
}

/// The dissipation potential of one step: the windows and their fixed metrics `(c/h) K_w`.
pub(crate) struct DampingTerm {
    windows: Vec<(Vec<usize>, DMatrix<f64>)>,
}

/// The position displacement `x - x_n` of the window's vertices.
fn window_displacement(vertices: &[usize], q: &DVector<f64>, q_n: &DVector<f64>) -> DVector<f64> {
    DVector::from_iterator(
        3 * vertices.len(),
        vertices.iter().flat_map(|&v| (0..3).map(move |k| q[3 * v + k] - q_n[3 * v + k])),
    )
}

impl DampingTerm {
    /// The term of a step of `time_step_s` from DOFs `q_n` (positions first), damping rate
    /// `rate_per_s`, with the windows' metrics computed in parallel.
    pub(crate) fn new(
        windows: &[Vec<usize>],
        masses_kg: &[f64],
        q_n: &DVector<f64>,
        rate_per_s: f64,
        time_step_s: f64,
    ) -> DampingTerm {
        let coefficient = rate_per_s / time_step_s;
        let windows = windows
            .par_iter()
            .map(|vertices| {
                let points: Vec<Vector3<f64>> =
                    vertices.iter().map(|&v| q_n.fixed_rows::<3>(3 * v).into()).collect();
                let masses: Vec<f64> = vertices.iter().map(|&v| masses_kg[v]).collect();
                (vertices.clone(), non_rigid_metric(&points, &masses) * coefficient)
            })
            .collect();
        DampingTerm { windows }
    }

    /// Number of windows.
    pub(crate) fn len(&self) -> usize {
        self.windows.len()
    }

    /// `D_w = Δᵀ (c/h) K_w Δ / 2` of window `w`.
    pub(crate) fn energy(&self, w: usize, q: &DVector<f64>, q_n: &DVector<f64>) -> f64 {
        let (vertices, metric) = &self.windows[w];
        let delta = window_displacement(vertices, q, q_n);
        0.5 * delta.dot(&(metric * &delta))
    }

    /// Energy, the position DOFs, gradient `(c/h) K_w Δ` and Hessian `(c/h) K_w` of window `w`.
    pub(crate) fn element(
        &self,
        w: usize,
        q: &DVector<f64>,
        q_n: &DVector<f64>,
    ) -> (f64, Vec<usize>, DVector<f64>, &DMatrix<f64>) {
        let (vertices, metric) = &self.windows[w];
        let delta = window_displacement(vertices, q, q_n);
        let gradient = metric * &delta;
        let dofs = vertices.iter().flat_map(|&v| (0..3).map(move |k| 3 * v + k)).collect();
        (0.5 * delta.dot(&gradient), dofs, gradient, metric)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn window() -> (Vec<Vector3<f64>>, Vec<f64>) {
        let points =
            (0..5).map(|i| Vector3::new(0.3 * i as f64, 0.1 * (i as f64).powi(2), 0.05 * i as f64)).collect();
        (points, vec![1.0, 2.0, 1.5, 0.7, 1.2])
    }

    fn flatten(v: &[Vector3<f64>]) -> DVector<f64> {
        DVector::from_iterator(3 * v.len(), v.iter().flat_map(|p| p.iter().copied()))
    }

    #[test]
    fn rigid_motions_are_not_damped() {
        for (points, masses) in
            [window(), ((0..5).map(|i| Vector3::new(0.2 * i as f64, 0.0, 0.0)).collect(), vec![1.0; 5])]
        {
            let k = non_rigid_metric(&points, &masses);
            let scale = k.amax();
            // A translation, and an infinitesimal rotation about a point away from the window.
            let translation = flatten(&[Vector3::new(0.3, -1.0, 2.0); 5]);
            let (omega, pivot) = (Vector3::new(0.4, -0.2, 0.9), Vector3::new(1.0, 2.0, -0.5));
            let rotation = flatten(&points.iter().map(|p| omega.cross(&(p - pivot))).collect::<Vec<_>>());
            for motion in [translation, rotation] {
                assert!((&k * &motion).amax() < 1e-12 * scale * motion.amax(), "{}", (&k * &motion).amax());
            }
        }
    }

    #[test]
    fn the_metric_is_the_mass_weighted_least_squares_residual_of_a_rigid_fit() {
        // Against a dense least-squares fit of (a, ω) by SVD, weighted by sqrt(m).
        let (points, masses) = window();
        let k = non_rigid_metric(&points, &masses);
        let delta = DVector::from_fn(15, |i, _| ((i * 7 + 3) % 11) as f64 / 11.0 - 0.4);
        let mut basis = DMatrix::zeros(15, 6);
        for (i, p) in points.iter().enumerate() {
            let w = masses[i].sqrt();
            basis.fixed_view_mut::<3, 3>(3 * i, 0).copy_from(&(Matrix3::identity() * w));
            basis.fixed_view_mut::<3, 3>(3 * i, 3).copy_from(&(-cross_matrix(p) * w));
        }
        let weighted = DVector::from_fn(15, |i, _| delta[i] * masses[i / 3].sqrt());
        let fit = basis.clone().svd(true, true).solve(&weighted, 1e-12).expect("svd");
        let residual = weighted - basis * fit;
        let expected = residual.norm_squared();
        let got = delta.dot(&(&k * &delta));
        assert!((got - expected).abs() < 1e-12 * expected, "{got} vs {expected}");
        // Symmetric positive semidefinite.
        assert!((&k - k.transpose()).amax() < 1e-14);
        assert!(SymmetricEigen::new(k).eigenvalues.min() > -1e-12);
    }

    #[test]
    fn windows_are_runs_of_consecutive_vertices() {
        assert_eq!(yarn_windows(10, 6, false, 5), vec![vec![10, 11, 12, 13, 14], vec![11, 12, 13, 14, 15]]);
        assert_eq!(yarn_windows(0, 6, true, 5).len(), 6);
        assert_eq!(yarn_windows(0, 6, true, 5)[5], vec![5, 0, 1, 2, 3]);
        assert_eq!(yarn_windows(3, 3, false, 5), vec![vec![3, 4, 5]]);
    }
}
