//! Static equilibrium: the cloth's elastic energy minimized over its free DOFs with the others
//! held (clamped swatches in the stretch tests of thesis Sec. 6.2.3 and the simulation-in-the-
//! loop fits of Sec. 6.3). Newton on the PSD-clamped Hessian with backtracking line search;
//! no inertia, gravity or contact.

use nalgebra::Vector3;
use yarnhom_sparse::SpdSolver;

use crate::elastic::{Assembly, ElasticModel, NewtonMatrix};
use crate::line_search::backtrack;

/// When to stop.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StaticSettings {
    /// Newton iterations at most.
    pub max_iterations: u32,
    /// Converged when the largest position update is below this (m).
    pub tolerance_m: f64,
}

impl Default for StaticSettings {
    fn default() -> Self {
        Self { max_iterations: 100, tolerance_m: 1e-10 }
    }
}

/// How a static solve went.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StaticStats {
    /// Newton iterations taken.
    pub iterations: u32,
    /// Largest free-DOF force at the last assembly (N).
    pub residual_n: f64,
    /// Whether the update fell below the tolerance.
    pub converged: bool,
}

/// Why a static solve failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum StaticError {
    /// The Newton matrix could not be factored even when regularized.
    #[error("static solve: the Newton matrix is not positive definite even with a diagonal shift")]
    Factorization,
    /// Positions became non-finite.
    #[error("static solve diverged (non-finite positions)")]
    Diverged,
}

/// Minimize the elastic energy of `model` minus the work of the constant vertex `loads` (N;
/// empty for none, e.g. weights `m g` for gravity) over the DOFs of `x` not marked `fixed`
/// (one flag per DOF, `3 n`), starting from `x` and leaving the equilibrium in it. `solver`
/// keeps its symbolic analysis across calls on the same mesh.
pub fn solve_static(
    model: &ElasticModel,
    x: &mut [Vector3<f64>],
    fixed: &[bool],
    loads: &[Vector3<f64>],
    settings: StaticSettings,
    solver: &mut SpdSolver,
) -> Result<StaticStats, StaticError> {
    let potential =
        |x: &[Vector3<f64>]| model.energy(x) - loads.iter().zip(x).map(|(f, p)| f.dot(p)).sum::<f64>();
    let mut a = Assembly::new(3 * x.len());
    let mut stats = StaticStats { iterations: 0, residual_n: f64::INFINITY, converged: false };
    let mut energy = potential(x);
    for iteration in 0..settings.max_iterations {
        a.clear();
        model.assemble(x, Some(NewtonMatrix::Projected), &mut a);
        for (v, f) in loads.iter().enumerate() {
            for k in 0..3 {
                a.gradient[3 * v + k] -= f[k];
            }
        }
        a.pin(fixed);
        stats.residual_n = a.gradient.iter().fold(0.0_f64, |m, g| m.max(g.abs()));
        stats.iterations = iteration + 1;
        let mut dx: Vec<f64> = a.gradient.iter().map(|g| -g).collect();
        factor_regularized(solver, &a)?;
        solver.solve_in_place(&mut dx, 1);
        let slope: f64 = a.gradient.iter().zip(&dx).map(|(g, d)| g * d).sum();
        let (alpha, _, accepted) = backtrack(x, &dx, energy, slope, potential);
        let largest = alpha * dx.iter().fold(0.0_f64, |m, d| m.max(d.abs()));
        for (p, d) in x.iter_mut().zip(dx.chunks_exact(3)) {
            *p += alpha * Vector3::new(d[0], d[1], d[2]);
        }
        if x.iter().any(|p| !p.iter().all(|c| c.is_finite())) {
            return Err(StaticError::Diverged);
        }
        energy = accepted.unwrap_or_else(|| potential(x));
        if largest < settings.tolerance_m {
            stats.converged = true;
            break;
        }
    }
    Ok(stats)
}

/// Factor the assembled Newton matrix, adding a diagonal shift (growing tenfold from a
/// millionth of the largest diagonal entry) when the clamped Hessian is singular.
fn factor_regularized(solver: &mut SpdSolver, a: &Assembly) -> Result<(), StaticError> {
    let n = a.gradient.len();
    if solver.factor(n, &a.triplets, 0.0).is_ok() {
        return Ok(());
    }
    let largest = a.triplets.iter().filter(|t| t.0 == t.1).fold(0.0_f64, |m, t| m.max(t.2));
    let mut shift = 1e-6 * largest.max(1e-12);
    for _ in 0..8 {
        if solver.factor(n, &a.triplets, shift).is_ok() {
            return Ok(());
        }
        shift *= 10.0;
    }
    Err(StaticError::Factorization)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::{ShellMaterial, StvkNeoHookean};
    use crate::mesh::ShellMesh;

    /// A planar isotropic StVK strip pulled by its clamped ends: with the lateral edges free the
    /// equilibrium is close to uniaxial stress, and the reaction force must balance.
    #[test]
    fn a_pulled_strip_reaches_equilibrium_with_balanced_clamp_forces() {
        let mesh = ShellMesh::rectangle(0.1, 0.02, 21, 5).expect("mesh");
        let material = ShellMaterial {
            areal_density_kg_m2: 0.2,
            forms: crate::material::FormsEnergy::Stvk(StvkNeoHookean {
                k_xx: 100.0,
                k_xy: 20.0,
                k_yy: 100.0,
                k_ss: 40.0,
                k_n1: 0.0,
                k_n2: 0.0,
                stiffening: None,
                jamming: None,
            }),
            hinge_bending: None,
        };
        let model = ElasticModel::new(mesh.clone(), material);
        let mut x = mesh.flat_positions();
        let mut fixed = vec![false; 3 * x.len()];
        for (v, m) in mesh.material.iter().enumerate() {
            fixed[3 * v + 2] = true;
            if m.x.abs() > 0.0499 {
                fixed[3 * v] = true;
                fixed[3 * v + 1] = true;
                x[v].x *= 1.1;
            }
        }
        let stats =
            solve_static(&model, &mut x, &fixed, &[], StaticSettings::default(), &mut SpdSolver::default())
                .expect("solves");
        assert!(stats.converged, "{stats:?}");
        let mut a = Assembly::new(3 * x.len());
        model.assemble(&x, None, &mut a);
        let (mut left, mut right) = (0.0, 0.0);
        for (v, m) in mesh.material.iter().enumerate() {
            if !fixed[3 * v] {
                assert!(a.gradient[3 * v].abs() < 1e-8 && a.gradient[3 * v + 1].abs() < 1e-8);
            } else if m.x > 0.0 {
                right += a.gradient[3 * v];
            } else {
                left += a.gradient[3 * v];
            }
        }
        assert!(right > 0.0 && (right + left).abs() < 1e-9 * right, "{right} {left}");
        // The middle narrows (Poisson effect of k_xy > 0).
        let mid_width = x
            .iter()
            .zip(&mesh.material)
            .filter(|(_, m)| m.x.abs() < 1e-9)
            .map(|(p, _)| p.y)
            .fold(f64::NEG_INFINITY, f64::max);
        assert!(mid_width < 0.01, "{mid_width}");
    }
}
