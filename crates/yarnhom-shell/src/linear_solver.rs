//! The linear system of each Newton iteration, `A Δx = -∇Φ`, by sparse Cholesky or by
//! Jacobi-preconditioned conjugate gradients, chosen per solve ([`LinearSolver::Auto`]).
//!
//! `A = C + K` with `C` the diagonal inertia term (`m_i/h² + α m_i/h` per DOF) and `K` positive
//! semidefinite (element matrices, stiffness damping and contact blocks all are). Two bounds
//! follow, and with them everything the choice needs, without an eigensolver:
//!
//! - `λ_min(A) ≥ min_i c_i`: a residual `r` leaves an error `|Δx_CG - Δx| ≤ |r|₂ / min_i c_i` in
//!   every component, so conjugate gradients stop when that bound is a small share
//!   ([`CG_ERROR_SHARE`]) of the Newton tolerance;
//! - with `D = diag(A)`, the Jacobi-scaled `D^-½ A D^-½` has eigenvalues in
//!   `[min_i c_i/d_i, max_i Σ_j |a_ij|/√(d_i d_j)]` (`A ⪰ C`, and Gershgorin), so its condition
//!   number `κ` is bounded and conjugate gradients need about `√κ/2 · ln(2√κ/ρ)` iterations to
//!   reduce the residual by `ρ`.
//!
//! Short time steps make `C` dominate (`h = 0.209 ms`, the published scenes': `κ` at most
//! 20-100, 12-20 products with `A` instead of a factorization with 8 times `A`'s nonzeros); long
//! ones make `K` dominate (4.2 ms: bounds of 1600-21000), where the factorization wins. The choice compares the predicted
//! iterations with the cost of a factorization counted in products with `A`.

use serde::{Deserialize, Serialize};

use crate::newton_matrix::HessianPattern;

/// Conjugate gradients stop when the error bound `|r|₂ / min_i c_i` of the update is below this
/// share of the Newton tolerance.
pub const CG_ERROR_SHARE: f64 = 1e-4;

/// How many times faster a flop of the supernodal factorization (dense kernels) runs than a flop
/// of the sparse product with `A` (memory bound): a 50 x 50 cloth's factorization takes
/// 4.24e8 flops in 21-26 ms, a conjugate gradient iteration 0.91e6 flops in about 0.2 ms
/// (2-core dev VM, one thread): a break-even at 116 iterations.
const FACTORIZATION_FLOP_SPEEDUP: f64 = 4.0;

/// How the Newton system is solved.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum LinearSolver {
    /// Jacobi-preconditioned conjugate gradients where their bound iteration count costs less
    /// than a factorization (short time steps), else sparse Cholesky; also Cholesky when
    /// conjugate gradients exceed that cost after all. The default.
    #[default]
    Auto,
    /// Sparse Cholesky (faer, supernodal, on the pattern's symbolic analysis) for every solve.
    Cholesky,
    /// Jacobi-preconditioned conjugate gradients for every solve, up to as many iterations as
    /// DOFs; Cholesky only where they fail (an indefinite matrix, or no convergence).
    ConjugateGradient,
}

/// What the linear solves of a step did.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct LinearSolves {
    /// Conjugate gradient iterations (products with `A`).
    pub cg_iterations: u32,
    /// Cholesky factorizations.
    pub factorizations: u32,
}

/// What a conjugate gradient solve did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct CgRun {
    /// Iterations (products with `A`).
    pub iterations: u32,
    /// Whether the residual met its tolerance (not when the budget ran out, or a search
    /// direction had non-positive curvature: `A` is not positive definite).
    pub converged: bool,
}

/// The bound on the condition number of the Jacobi-scaled `A` (lower-triangle `values` on
/// `pattern`) given `A ⪰ diag(inertia)` (module docs).
pub(crate) fn jacobi_condition_bound(pattern: &HessianPattern, values: &[f64], inertia: &[f64]) -> f64 {
    let diagonal: Vec<f64> = (0..inertia.len()).map(|dof| values[pattern.diagonal_slot(dof)]).collect();
    let scale: Vec<f64> = diagonal.iter().map(|d| 1.0 / d.sqrt()).collect();
    let mut row_sums = vec![0.0; inertia.len()];
    pattern.for_each_entry(values, |row, col, a| {
        let scaled = a.abs() * scale[row] * scale[col];
        row_sums[row] += scaled;
        if row != col {
            row_sums[col] += scaled;
        }
    });
    let largest = row_sums.iter().fold(0.0_f64, |m, s| m.max(*s));
    let smallest = inertia.iter().zip(&diagonal).fold(f64::INFINITY, |m, (c, d)| m.min(c / d));
    largest / smallest
}

/// Conjugate gradient iterations that reduce the residual by `reduction` at condition number
/// `kappa` (the A-norm bound `2 ((√κ-1)/(√κ+1))^k`, with `√κ` between the A-norm and the
/// residual).
pub(crate) fn predicted_iterations(kappa: f64, reduction: f64) -> f64 {
    let root = kappa.max(1.0).sqrt();
    (0.5 * root * (2.0 * root / reduction).ln()).max(1.0).ceil()
}

/// Conjugate gradient iterations that cost as much as a factorization and its solve.
pub(crate) fn factorization_cost_in_iterations(pattern: &HessianPattern) -> f64 {
    let product_flops = 4.0 * pattern.len() as f64 + 10.0 * pattern.dofs() as f64;
    pattern.factorization_flops() / FACTORIZATION_FLOP_SPEEDUP / product_flops
}

/// Jacobi-preconditioned conjugate gradients for `A x = b` from the guess in `x`, until
/// `|r|₂ <= residual_tolerance` or `max_iterations`. `A` is the symmetric matrix with
/// lower-triangle `values` on `pattern`.
pub(crate) fn conjugate_gradient(
    pattern: &HessianPattern,
    values: &[f64],
    b: &[f64],
    x: &mut [f64],
    residual_tolerance: f64,
    max_iterations: u32,
) -> CgRun {
    let n = b.len();
    let inverse_diagonal: Vec<f64> = (0..n).map(|dof| 1.0 / values[pattern.diagonal_slot(dof)]).collect();
    let mut q = vec![0.0; n];
    pattern.symmetric_product_into(values, x, &mut q);
    let mut r: Vec<f64> = b.iter().zip(&q).map(|(b, q)| b - q).collect();
    let mut z: Vec<f64> = r.iter().zip(&inverse_diagonal).map(|(r, d)| r * d).collect();
    let mut p = z.clone();
    let mut rz = dot(&r, &z);
    let mut iterations = 0;
    loop {
        if dot(&r, &r).sqrt() <= residual_tolerance {
            return CgRun { iterations, converged: true };
        }
        if iterations == max_iterations {
            return CgRun { iterations, converged: false };
        }
        pattern.symmetric_product_into(values, &p, &mut q);
        iterations += 1;
        let curvature = dot(&p, &q);
        if curvature.is_nan() || curvature <= 0.0 {
            return CgRun { iterations, converged: false };
        }
        let alpha = rz / curvature;
        for i in 0..n {
            x[i] += alpha * p[i];
            r[i] -= alpha * q[i];
            z[i] = r[i] * inverse_diagonal[i];
        }
        let rz_next = dot(&r, &z);
        let beta = rz_next / rz;
        rz = rz_next;
        for (p, z) in p.iter_mut().zip(&z) {
            *p = z + beta * *p;
        }
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(a, b)| a * b).sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::elastic::{ElementSink, SplitHessian};
    use crate::newton_matrix::NewtonAssembly;
    use crate::test_support::XorShift;
    use nalgebra::{DMatrix, DVector, SMatrix, SVector};

    /// A random `A = C + K` on a pattern of overlapping 3-vertex elements over 8 vertices: `K`
    /// sums positive semidefinite element matrices `B Bᵀ` of rank 4, `C` is a random positive
    /// diagonal. Returns the pattern, `A`'s values, `C`, and `A` dense.
    fn random_system(
        rng: &mut XorShift,
        inertia_scale: f64,
    ) -> (HessianPattern, Vec<f64>, Vec<f64>, DMatrix<f64>) {
        let elements: Vec<Vec<Option<u32>>> =
            (0..6).map(|e| vec![Some(e), Some(e + 1), Some((e + 3) % 8)]).collect();
        let pattern = HessianPattern::new(8, &elements);
        let mut a = NewtonAssembly::new(&pattern);
        a.clear();
        let mut dense = DMatrix::zeros(24, 24);
        for (index, element) in elements.iter().enumerate() {
            let b = SMatrix::<f64, 9, 4>::from_fn(|_, _| rng.uniform(-1.0, 1.0));
            let h = SplitHessian { matrix: b * b.transpose(), negative: None };
            a.add(index, element, 0.0, &SVector::<f64, 9>::zeros(), Some(&h));
            for (i, vi) in element.iter().flatten().enumerate() {
                for (j, vj) in element.iter().flatten().enumerate() {
                    let mut block = dense.view_mut((3 * *vi as usize, 3 * *vj as usize), (3, 3));
                    block += h.matrix.fixed_view::<3, 3>(3 * i, 3 * j);
                }
            }
        }
        let inertia: Vec<f64> = (0..24).map(|_| inertia_scale * rng.uniform(0.5, 2.0)).collect();
        for (dof, c) in inertia.iter().enumerate() {
            a.matrix[pattern.diagonal_slot(dof)] += c;
            dense[(dof, dof)] += c;
        }
        let values = std::mem::take(&mut a.matrix);
        drop(a);
        (pattern, values, inertia, dense)
    }

    #[test]
    fn the_condition_bound_holds_and_conjugate_gradients_meet_their_error_bound() {
        let mut rng = XorShift::new(7);
        for inertia_scale in [100.0, 1.0, 0.01] {
            let (pattern, values, inertia, dense) = random_system(&mut rng, inertia_scale);
            let scale = DMatrix::from_diagonal(&dense.diagonal().map(|d| 1.0 / d.sqrt()));
            let eigenvalues = (&scale * &dense * &scale).symmetric_eigenvalues();
            let kappa = eigenvalues.max() / eigenvalues.min();
            let bound = jacobi_condition_bound(&pattern, &values, &inertia);
            assert!(kappa <= bound, "κ {kappa} above its bound {bound}");
            assert!(bound < 20.0 * kappa, "bound {bound} far above κ {kappa}");

            let b: Vec<f64> = (0..24).map(|_| rng.uniform(-1.0, 1.0)).collect();
            let exact =
                dense.clone().cholesky().expect("positive definite").solve(&DVector::from_column_slice(&b));
            let smallest = inertia.iter().fold(f64::INFINITY, |m, c| m.min(*c));
            let tolerance = 1e-9;
            let mut x = vec![0.0; 24];
            let run = conjugate_gradient(&pattern, &values, &b, &mut x, tolerance, 1000);
            assert!(run.converged && run.iterations > 1, "{run:?}");
            let residual = DVector::from_column_slice(&b) - &dense * DVector::from_column_slice(&x);
            assert!(residual.norm() <= tolerance * (1.0 + 1e-6), "residual {}", residual.norm());
            let error = (DVector::from_column_slice(&x) - &exact).amax();
            assert!(error <= tolerance / smallest, "error {error} above its bound {}", tolerance / smallest);
            eprintln!(
                "inertia x{inertia_scale}: κ {kappa:.1} (bound {bound:.1}), {} iterations",
                run.iterations
            );
        }
    }

    #[test]
    fn conjugate_gradients_stop_on_an_indefinite_matrix_and_at_their_budget() {
        let mut rng = XorShift::new(3);
        let (pattern, mut values, _, _) = random_system(&mut rng, 1.0);
        let b: Vec<f64> = (0..24).map(|_| rng.uniform(-1.0, 1.0)).collect();
        let mut x = vec![0.0; 24];
        let run = conjugate_gradient(&pattern, &values, &b, &mut x, 1e-12, 2);
        assert_eq!(run, CgRun { iterations: 2, converged: false });
        values[pattern.diagonal_slot(5)] = -1e3;
        let mut x = vec![0.0; 24];
        assert!(!conjugate_gradient(&pattern, &values, &b, &mut x, 1e-12, 1000).converged);
    }

    #[test]
    fn predictions_grow_with_the_condition_number_and_the_reduction() {
        assert_eq!(predicted_iterations(1.0, 0.5), 1.0);
        assert!(predicted_iterations(100.0, 1e-6) > predicted_iterations(10.0, 1e-6));
        assert!(predicted_iterations(100.0, 1e-8) > predicted_iterations(100.0, 1e-6));
        // √κ/2 ln(2√κ/ρ) at κ = 100, ρ = 1e-6: 5 · ln(2e7) = 84.1.
        assert_eq!(predicted_iterations(100.0, 1e-6), 85.0);
    }

    #[test]
    fn a_dense_patterns_factorization_costs_the_sum_of_its_squared_column_counts() {
        // One element over every vertex: the factor is dense, its columns hold n, n-1, ..., 1.
        let vertices = 5;
        let pattern = HessianPattern::new(vertices, &[(0..vertices as u32).map(Some).collect()]);
        let n = 3.0 * vertices as f64;
        let expected = n * (n + 1.0) * (2.0 * n + 1.0) / 6.0 + 4.0 * n * (n + 1.0) / 2.0;
        assert_eq!(pattern.factorization_flops(), expected);
    }
}
