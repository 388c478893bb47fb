//! Levenberg-Marquardt for small nonlinear least-squares problems whose residuals come from
//! simulations: the Jacobian by forward differences, its columns evaluated in parallel, and a
//! failed evaluation (a simulation without equilibrium) treated as a rejected step.
//!
//! (The `levenberg-marquardt` crate would do the iteration, but it is built on an older
//! nalgebra than the workspace's and cannot take failing residual evaluations.)

use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// When to stop.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct LmSettings {
    /// Iterations (Jacobians) at most.
    pub max_iterations: usize,
    /// Forward-difference step in each parameter.
    pub difference_step: f64,
    /// Stop when an accepted step lowers the cost by less than this fraction.
    pub cost_tolerance: f64,
}

impl Default for LmSettings {
    fn default() -> Self {
        Self { max_iterations: 40, difference_step: 1e-4, cost_tolerance: 1e-6 }
    }
}

/// The result of a minimization.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct LmReport {
    /// The parameters reached.
    pub params: Vec<f64>,
    /// `½ Σ r²` there.
    pub cost: f64,
    /// Iterations (Jacobians) taken.
    pub iterations: usize,
    /// Residual evaluations, Jacobian columns included.
    pub evaluations: usize,
    /// Whether a stopping test (not the iteration cap) ended it.
    pub converged: bool,
}

/// Minimize `½ |r(p)|²` from `start`. `residuals` returns `None` where it cannot be evaluated;
/// it must be evaluable at `start`. The Jacobian is taken by forward differences.
pub fn minimize<F>(residuals: F, start: &[f64], settings: &LmSettings) -> Option<LmReport>
where
    F: Fn(&[f64]) -> Option<Vec<f64>> + Sync,
{
    let jacobian =
        |p: &DVector<f64>, r: &DVector<f64>| forward_jacobian(&residuals, p, r, settings.difference_step);
    minimize_with_jacobian(&residuals, jacobian, start, settings)
}

/// [`minimize`] with the Jacobian from `jacobian(p, r(p))`: the matrix (`None` if it cannot be
/// had) and the residual evaluations it took (counted in the report).
pub fn minimize_with_jacobian<F, J>(
    residuals: F,
    jacobian: J,
    start: &[f64],
    settings: &LmSettings,
) -> Option<LmReport>
where
    F: Fn(&[f64]) -> Option<Vec<f64>>,
    J: Fn(&DVector<f64>, &DVector<f64>) -> (Option<DMatrix<f64>>, usize),
{
    let mut p = DVector::from_column_slice(start);
    let mut r = DVector::from_vec(residuals(p.as_slice())?);
    let mut report = LmReport {
        params: start.to_vec(),
        cost: 0.5 * r.norm_squared(),
        iterations: 0,
        evaluations: 1,
        converged: false,
    };
    let mut damping = 1e-3;
    while report.iterations < settings.max_iterations {
        report.iterations += 1;
        let (jacobian, evaluations) = jacobian(&p, &r);
        report.evaluations += evaluations;
        let Some(jacobian) = jacobian else { break };
        let normal = jacobian.transpose() * &jacobian;
        let gradient = jacobian.transpose() * &r;
        let step = DampedStep { normal: &normal, gradient: &gradient, cost: report.cost };
        let Some((trial, rt, cost)) = step.accept(&residuals, &p, &mut damping, &mut report.evaluations)
        else {
            report.converged = true;
            break;
        };
        let decrease = (report.cost - cost) / report.cost.max(1e-300);
        (p, r, report.cost) = (trial, rt, cost);
        if decrease < settings.cost_tolerance {
            report.converged = true;
            break;
        }
    }
    report.params = p.as_slice().to_vec();
    Some(report)
}

/// The normal equations of one iteration and the cost to beat.
struct DampedStep<'a> {
    normal: &'a DMatrix<f64>,
    gradient: &'a DVector<f64>,
    cost: f64,
}

impl DampedStep<'_> {
    /// The first damped Gauss-Newton step from `p` that lowers the cost, with its residuals and
    /// cost: the damping grows (x10 where the damped matrix is not positive definite, x4 where
    /// the step fails or does not lower the cost) until a step is accepted, then shrinks by 3;
    /// `None` once it passes 1e10. `evaluations` counts the residual evaluations.
    fn accept<F>(
        &self,
        residuals: &F,
        p: &DVector<f64>,
        damping: &mut f64,
        evaluations: &mut usize,
    ) -> Option<(DVector<f64>, DVector<f64>, f64)>
    where
        F: Fn(&[f64]) -> Option<Vec<f64>>,
    {
        let normal = self.normal;
        let floor = 1e-12 * normal.diagonal().max().max(1e-300);
        loop {
            let mut damped = normal.clone();
            for i in 0..p.len() {
                damped[(i, i)] += *damping * normal[(i, i)].max(floor);
            }
            let Some(step) = damped.cholesky().map(|c| c.solve(&(-self.gradient))) else {
                *damping *= 10.0;
                continue;
            };
            let trial = p + &step;
            *evaluations += 1;
            if let Some(rt) = residuals(trial.as_slice()).map(DVector::from_vec) {
                let cost = 0.5 * rt.norm_squared();
                if cost < self.cost {
                    *damping = (*damping / 3.0).max(1e-9);
                    return Some((trial, rt, cost));
                }
            }
            *damping *= 4.0;
            if *damping > 1e10 {
                return None;
            }
        }
    }
}

/// Forward differences `(r(p + h e_j) - r(p)) / h`, columns in parallel (a column whose
/// forward point fails is taken backwards); `None` if both fail. Also the evaluations made.
fn forward_jacobian<F>(
    residuals: &F,
    p: &DVector<f64>,
    r: &DVector<f64>,
    h: f64,
) -> (Option<DMatrix<f64>>, usize)
where
    F: Fn(&[f64]) -> Option<Vec<f64>> + Sync,
{
    let columns: Vec<(Option<Vec<f64>>, usize)> = (0..p.len())
        .into_par_iter()
        .map(|j| {
            for (sign, evaluations) in [(1.0, 1), (-1.0, 2)] {
                let mut q = p.clone();
                q[j] += sign * h;
                if let Some(rq) = residuals(q.as_slice()) {
                    let column = rq.iter().zip(r.iter()).map(|(a, b)| (a - b) / (sign * h)).collect();
                    return (Some(column), evaluations);
                }
            }
            (None, 2)
        })
        .collect();
    let evaluations = columns.iter().map(|c| c.1).sum();
    let mut jacobian = DMatrix::zeros(r.len(), p.len());
    for (j, (column, _)) in columns.into_iter().enumerate() {
        let Some(column) = column else { return (None, evaluations) };
        jacobian.set_column(j, &DVector::from_vec(column));
    }
    (Some(jacobian), evaluations)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fits_an_exponential_decay_from_a_poor_start() {
        // y = 3 exp(-0.7 t) + 0.5 sampled exactly: the minimum is at (3, 0.7, 0.5) with zero cost.
        let t: Vec<f64> = (0..20).map(|k| k as f64 * 0.3).collect();
        let data: Vec<f64> = t.iter().map(|t| 3.0 * (-0.7 * t).exp() + 0.5).collect();
        let residuals =
            |p: &[f64]| Some(t.iter().zip(&data).map(|(t, y)| p[0] * (-p[1] * t).exp() + p[2] - y).collect());
        let report = minimize(
            residuals,
            &[1.0, 0.1, 0.0],
            &LmSettings { difference_step: 1e-7, ..Default::default() },
        )
        .expect("evaluable at the start");
        assert!(report.cost < 1e-12, "{report:?}");
        for (p, want) in report.params.iter().zip([3.0, 0.7, 0.5]) {
            assert!((p - want).abs() < 1e-5, "{report:?}");
        }
    }

    #[test]
    fn failed_evaluations_are_rejected_steps_not_errors() {
        // r = atan(p - 2), evaluable for p <= 2.5 only: the first Gauss-Newton step from 0
        // overshoots to 5.5 (r' = 1/5 there), fails, and the damped steps then reach 2. From
        // 4 (not evaluable) there is nothing to start from.
        let residuals = |p: &[f64]| (p[0] <= 2.5).then(|| vec![(p[0] - 2.0).atan()]);
        let report = minimize(residuals, &[0.0], &LmSettings::default()).expect("start ok");
        assert!((report.params[0] - 2.0).abs() < 1e-4, "{report:?}");
        assert!(minimize(residuals, &[4.0], &LmSettings::default()).is_none());
    }
}
