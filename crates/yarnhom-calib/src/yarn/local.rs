//! The local step of the yarn-level estimation: the swarm's best refined on the local targets
//! by COBYLA (as the thesis), by Levenberg-Marquardt on the residuals (forward-difference
//! Jacobian), or by Gauss-Newton with the Jacobian from the tile's parameter sensitivities,
//! alternated with the rest-shape estimation (Sec. 6.5.2).

use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

use nalgebra::{DMatrix, DVector};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use yarnhom_artifacts::Pattern;

use super::objective::DirectionTargets;
use super::problem::{Evaluation, YarnFitError, YarnFitEvent, YarnProblem};
use super::settings::LocalSolver;
use crate::optimize::lm::{LmReport, LmSettings, minimize as levenberg_marquardt, minimize_with_jacobian};

/// Rounds of rest-shape estimation and Gauss-Newton in the Gauss-Newton local step.
const GAUSS_NEWTON_ROUNDS: usize = 4;

/// What the local step did.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct LocalReport {
    /// The optimizer.
    pub solver: LocalSolver,
    /// `g` at its start (on the local targets).
    pub start_cost: f64,
    /// `g` at its end.
    pub cost: f64,
    /// Objective evaluations (each one a rest-shape estimation and all tile solves).
    pub evaluations: usize,
    /// How it stopped.
    pub stop: String,
    /// Wall time (s).
    pub wall_time_s: f64,
}

/// The local step from `x`: the report and the point reached (`x` itself unless the step
/// lowered the cost).
pub(crate) fn local_step(
    problem: &YarnProblem,
    solver: LocalSolver,
    x: &[f64],
    targets: &[DirectionTargets],
    budget: usize,
    progress: &(dyn Fn(YarnFitEvent) + Sync),
) -> Result<(LocalReport, Vec<f64>), YarnFitError> {
    let started = Instant::now();
    let start_cost = problem.evaluate(x, targets)?.cost;
    let local = Local { problem, targets, count: AtomicUsize::new(1), progress };
    let (best, cost, stop) = match solver {
        LocalSolver::Cobyla => local.cobyla(x, budget, start_cost),
        LocalSolver::LevenbergMarquardt => local.levenberg_marquardt(x, budget)?,
        LocalSolver::GaussNewton => local.gauss_newton(x, budget),
        LocalSolver::None => (x.to_vec(), start_cost, "no local step".to_string()),
    };
    let (best, cost) = if cost <= start_cost { (best, cost) } else { (x.to_vec(), start_cost) };
    let report = LocalReport {
        solver,
        start_cost,
        cost,
        evaluations: local.count.load(Ordering::Relaxed),
        stop,
        wall_time_s: started.elapsed().as_secs_f64(),
    };
    Ok((report, best))
}

/// What a local step reached: the point, its cost `g` and how it stopped.
type Reached = (Vec<f64>, f64, String);

/// A local step in progress: the problem, its targets and the evaluations counted so far (the
/// start's included), each reported to `progress`.
struct Local<'a> {
    problem: &'a YarnProblem,
    targets: &'a [DirectionTargets],
    count: AtomicUsize,
    progress: &'a (dyn Fn(YarnFitEvent) + Sync),
}

impl Local<'_> {
    /// Count an evaluation: its number.
    fn next(&self) -> usize {
        self.count.fetch_add(1, Ordering::Relaxed) + 1
    }

    /// Report evaluation `n` and its cost (infinite if it failed).
    fn report(&self, n: usize, cost: Option<f64>) {
        (self.progress)(YarnFitEvent::LocalEvaluation(n, cost.unwrap_or(f64::INFINITY)));
    }

    /// The evaluation at `x` moved into the search box, counted and reported.
    fn evaluate(&self, x: &[f64]) -> Option<Evaluation> {
        let e = self.problem.evaluate(&self.problem.clamped(x), self.targets).ok();
        self.report(self.next(), e.as_ref().map(|e| e.cost));
        e
    }

    /// COBYLA from `x` with `budget` evaluations, a failed evaluation costing a thousand times
    /// the start (COBYLA needs a number).
    fn cobyla(&self, x: &[f64], budget: usize, start_cost: f64) -> Reached {
        let penalty = 1e3 * start_cost.max(1.0);
        let objective = |x: &[f64], _: &mut ()| self.evaluate(x).map_or(penalty, |e| e.cost);
        let bounds = self.problem.basis.bounds();
        let rho: Vec<f64> = bounds.iter().map(|(lo, hi)| 0.1 * (hi - lo)).collect();
        let xtol: Vec<f64> = bounds.iter().map(|(lo, hi)| 1e-3 * (hi - lo)).collect();
        let tolerances = cobyla::StopTols { ftol_rel: 1e-4, xtol_abs: xtol, ..cobyla::StopTols::default() };
        let no_constraints: Vec<&dyn cobyla::Func<()>> = Vec::new();
        let outcome = cobyla::minimize(
            objective,
            x,
            &bounds,
            &no_constraints,
            (),
            budget,
            cobyla::RhoBeg::Set(rho),
            Some(tolerances),
        );
        match outcome {
            Ok((status, best, cost)) => (best, cost, format!("{status:?}")),
            Err((status, best, cost)) => (best, cost, format!("{status:?}")),
        }
    }

    /// Levenberg-Marquardt on the residuals from `x`, `budget` forward-difference Jacobians.
    fn levenberg_marquardt(&self, x: &[f64], budget: usize) -> Result<Reached, YarnFitError> {
        let settings = LmSettings { max_iterations: budget, difference_step: 2e-2, cost_tolerance: 1e-3 };
        let report = levenberg_marquardt(|x| self.evaluate(x).map(|e| e.residuals), x, &settings)
            .ok_or_else(|| YarnFitError::Tile("the local step's start has no equilibrium".into()))?;
        let stop = if report.converged { "converged" } else { "iteration limit" };
        Ok((self.problem.clamped(&report.params), 2.0 * report.cost, stop.to_string()))
    }

    /// Alternate as the thesis does (Sec. 6.5.2): on the rest shape estimated at the current
    /// point, Gauss-Newton / LM with the sensitivity Jacobian (consistent with its residuals);
    /// then re-estimate the rest shape there. `budget` Jacobians in all, over
    /// [`GAUSS_NEWTON_ROUNDS`] rounds.
    fn gauss_newton(&self, x: &[f64], budget: usize) -> Reached {
        let settings = LmSettings {
            max_iterations: budget.div_ceil(GAUSS_NEWTON_ROUNDS),
            cost_tolerance: 1e-3,
            ..LmSettings::default()
        };
        let mut current = x.to_vec();
        let mut stops = Vec::new();
        for _ in 0..GAUSS_NEWTON_ROUNDS {
            let Ok(rest_pattern) = self.problem.rest_shape(&current) else { break };
            let Some(report) = self.gauss_newton_round(&rest_pattern, &current, &settings) else { break };
            let stop = if report.converged { "converged" } else { "iteration limit" };
            stops.push(format!("{stop} at g = {:.4} on its rest shape", 2.0 * report.cost));
            current = self.problem.clamped(&report.params);
        }
        let cost = self.evaluate(&current).map_or(f64::INFINITY, |e| e.cost);
        (current, cost, format!("{} rounds: {}", stops.len(), stops.join(", ")))
    }

    /// One Gauss-Newton round from `current` on the rest shape `rest_pattern`.
    fn gauss_newton_round(
        &self,
        rest_pattern: &Pattern,
        current: &[f64],
        settings: &LmSettings,
    ) -> Option<LmReport> {
        let (problem, targets) = (self.problem, self.targets);
        let on_rest = |p: &[f64]| {
            let e = problem.evaluate_on(rest_pattern, &problem.clamped(p), targets).ok();
            self.report(self.next(), e.as_ref().map(|e| e.0.cost));
            e.map(|e| e.0.residuals)
        };
        let jacobian = |p: &DVector<f64>, _: &DVector<f64>| {
            let n = self.next();
            let j =
                problem.evaluate_with_jacobian(rest_pattern, &problem.clamped(p.as_slice()), targets).ok();
            self.report(n, j.as_ref().map(|(e, _)| e.cost));
            (j.map(|(_, rows)| DMatrix::from_fn(rows.len(), p.len(), |r, c| rows[r][c])), 0)
        };
        minimize_with_jacobian(on_rest, jacobian, current, settings)
    }
}
