//! Yarn-level estimation (thesis Sec. 6.5): the parameters of the Ch. 6 yarn model whose periodic
//! tile reproduces the uniform targets of the fitted shell.
//!
//! Every evaluation of the objective first estimates the yarns' rest shape for the candidate
//! parameters (Sec. 6.5.2: rest-shape resets with rest lengths within 20% of the input geometry,
//! [`yarnhom_rve::relax()`]), then simulates the tile along every tested direction
//! ([`crate::yarn_objective`]) and scores it by (6.11): rest shapes and mechanical parameters
//! alternate, as the thesis prescribes. The global step is a particle swarm
//! ([`crate::swarm`], 64 particles x 10 generations on 7 targets per direction); the local step
//! refines its best point on 20 targets per direction with COBYLA (as the thesis) or with
//! Levenberg-Marquardt on the residuals (forward-difference Jacobian, columns in parallel).

use std::time::Instant;

use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use yarnhom_artifacts::{Pattern, YarnModel};
use yarnhom_geom::MacroStrain;
use yarnhom_rve::assembly::RveState;
use yarnhom_rve::homogenize::solve_at;
use yarnhom_rve::{RelaxMethod, RelaxOptions, RveModel, SolveOptions, relax};
use yarnhom_shell::StvkNeoHookean;

use crate::lm::{LmSettings, minimize as levenberg_marquardt, minimize_with_jacobian};
use crate::measure::{Direction, MeasurementSet};
use crate::shell_fit::ShellFit;
use crate::swarm::{SwarmReport, SwarmSettings, minimize as swarm};
use crate::yarn_objective::{
    COMFORT_FORCE_N, DirectionTargets, SimulatedCurve, YarnErrors, errors, residual_jacobian, residuals,
    simulate, simulate_direction_with_sensitivity,
};

/// Coordinate step of the parameter sensitivities ([`YarnProblem::evaluate_with_jacobian`]).
pub const SENSITIVITY_STEP: f64 = 1e-4;

/// Rounds of rest-shape estimation and Gauss-Newton in the Gauss-Newton local step.
const GAUSS_NEWTON_ROUNDS: usize = 4;
use crate::yarn_params::{YarnBasis, YarnParams};

/// The local optimizer.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum LocalSolver {
    /// COBYLA (Powell 1994), derivative-free, as the thesis.
    Cobyla,
    /// Levenberg-Marquardt on the residuals of (6.11), Jacobian by finite differences of whole
    /// evaluations.
    LevenbergMarquardt,
    /// Gauss-Newton / Levenberg-Marquardt with the Jacobian from the parameter sensitivities of
    /// the tile's equilibrium ([`YarnProblem::evaluate_with_jacobian`]), alternated with the
    /// rest-shape estimation: each round holds the rest shape estimated at its start.
    GaussNewton,
    /// No local step (the swarm's best is the result).
    None,
}

/// Rest-shape estimation within each evaluation (Sec. 6.5.2).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct RestShapeSettings {
    /// Bound on the relative change of a rest length (0.2 in the thesis).
    pub max_length_change: f64,
    /// Rest-shape resets at most.
    pub max_resets: usize,
}

/// How to fit.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct YarnFitSettings {
    /// The global step.
    pub swarm: SwarmSettings,
    /// Targets per direction during the swarm (7 in the thesis).
    pub swarm_targets: usize,
    /// Targets per direction during the local step and for the reported errors (20).
    pub local_targets: usize,
    /// The local optimizer.
    pub local: LocalSolver,
    /// Objective evaluations of the local step at most (COBYLA) or Jacobians (LM).
    pub local_budget: usize,
    /// Rest shapes.
    pub rest: RestShapeSettings,
    /// Clamp force bounding the comfort range (N).
    pub comfort_force_n: f64,
}

impl Default for YarnFitSettings {
    fn default() -> Self {
        YarnFitSettings {
            swarm: SwarmSettings::default(),
            swarm_targets: 7,
            local_targets: 20,
            local: LocalSolver::Cobyla,
            local_budget: 60,
            rest: RestShapeSettings { max_length_change: 0.2, max_resets: 8 },
            comfort_force_n: COMFORT_FORCE_N,
        }
    }
}

/// Why a yarn-level fit failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum YarnFitError {
    /// The rest-shape estimation failed.
    #[error("rest-shape estimation: {0}")]
    RestShape(String),
    /// The tile has no equilibrium at some target.
    #[error("yarn tile: {0}")]
    Tile(String),
    /// The shell fit has no measured direction.
    #[error("the shell fit has no measured direction to fit")]
    NoTargets,
    /// The cause has no mechanism in the yarn model.
    #[error("no yarn-level mechanism: {0}")]
    NoMechanism(String),
    /// No parameter set could be evaluated.
    #[error("no parameter set of the swarm could be evaluated ({0} tried)")]
    NothingEvaluable(usize),
}

/// Where the targets come from.
#[derive(Debug, Clone, PartialEq)]
pub enum TargetSource {
    /// The uniform tests of a fitted shell (6.3): the thesis' route from measurements.
    Shell(StvkNeoHookean),
    /// The tile itself with known parameters: a ground truth that the estimation must
    /// recover (identifiability and optimizer checks).
    Yarn(YarnParams),
}

/// The estimation problem: the input geometry, the fixed quantities, and the uniform targets
/// along the tested directions.
#[derive(Debug, Clone)]
pub struct YarnProblem {
    /// Input yarn geometry (generated or registered).
    pub pattern: Pattern,
    /// Fixed quantities.
    pub basis: YarnBasis,
    /// The targets' origin.
    pub source: TargetSource,
    /// Tested directions: `(direction, largest tested stretch, swatch width in m)`.
    pub directions: Vec<(Direction, f64, f64)>,
    /// Rest-shape estimation.
    pub rest: RestShapeSettings,
    /// Comfort force (N).
    pub comfort_force_n: f64,
}

/// One evaluated parameter set.
#[derive(Debug, Clone)]
pub struct Evaluation {
    /// The parameters.
    pub params: YarnParams,
    /// The tile's responses.
    pub curves: Vec<SimulatedCurve>,
    /// Residuals of (6.11).
    pub residuals: Vec<f64>,
    /// `g` of (6.11).
    pub cost: f64,
    /// The estimated rest shape (the input geometry relaxed for these parameters).
    pub rest_pattern: Pattern,
}

impl YarnProblem {
    /// The problem of a shell fit of `set`, on the input geometry `pattern`.
    pub fn from_shell_fit(
        pattern: Pattern,
        basis: YarnBasis,
        shell: &ShellFit,
        set: &MeasurementSet,
        settings: &YarnFitSettings,
    ) -> Result<Self, YarnFitError> {
        let directions: Vec<_> = Direction::ALL
            .into_iter()
            .filter_map(|d| {
                let largest =
                    shell.targets.iter().filter(|t| t.direction == d).map(|t| t.stretch).fold(0.0, f64::max);
                (largest > 0.0).then(|| (d, largest, set.fabric.swatch.specimen(d).width_m))
            })
            .collect();
        if directions.is_empty() {
            return Err(YarnFitError::NoTargets);
        }
        Ok(YarnProblem {
            pattern,
            basis,
            source: TargetSource::Shell(shell.material),
            directions,
            rest: settings.rest,
            comfort_force_n: settings.comfort_force_n,
        })
    }

    /// `n` targets per tested direction, evenly spaced in stretch.
    pub fn targets(&self, n: usize) -> Result<Vec<DirectionTargets>, YarnFitError> {
        match &self.source {
            TargetSource::Shell(material) => Ok(self
                .directions
                .iter()
                .map(|&(d, s, w)| DirectionTargets::of_shell(material, d, s, w, n, self.comfort_force_n))
                .collect()),
            TargetSource::Yarn(truth) => {
                let stretches: Vec<DirectionTargets> = self
                    .directions
                    .iter()
                    .map(|&(direction, s_max, _)| DirectionTargets {
                        direction,
                        comfort_stretch: s_max,
                        stretch: (1..=n).map(|i| s_max * i as f64 / n as f64).collect(),
                        compression: vec![0.0; n],
                        stress_n_m: vec![0.0; n],
                        comfort_stress_n_m: 1.0,
                        comfort_compression: 0.0,
                    })
                    .collect();
                let rest_pattern = self.rest_shape_of(&self.yarn_model(truth))?;
                let curves = self.evaluate_params(&rest_pattern, truth, &stretches)?.0.curves;
                Ok(curves
                    .iter()
                    .zip(&self.directions)
                    .map(|(c, &(_, _, w))| DirectionTargets::of_curve(c, w, self.comfort_force_n))
                    .collect())
            }
        }
    }

    /// `n` held-out targets per tested direction: the midpoints between those of
    /// [`YarnProblem::targets`]`(n)`.
    pub fn heldout_targets(&self, n: usize) -> Result<Vec<DirectionTargets>, YarnFitError> {
        Ok(self.targets(2 * n)?.iter().map(|t| t.subset(|i| i.is_multiple_of(2))).collect())
    }

    /// The yarn model at search point `x`.
    pub fn model(&self, x: &[f64]) -> (YarnParams, YarnModel) {
        let params = self.basis.params(x);
        (params, self.yarn_model(&params))
    }

    /// The yarn model of `params`.
    fn yarn_model(&self, params: &YarnParams) -> YarnModel {
        params.model(&format!("{} (estimated)", self.pattern.name), &self.basis)
    }

    /// Estimate the rest shape for the parameters at `x`, then simulate the tile at `targets`.
    pub fn evaluate(&self, x: &[f64], targets: &[DirectionTargets]) -> Result<Evaluation, YarnFitError> {
        let (evaluation, _, _) = self.evaluate_on(&self.rest_shape(x)?, x, targets)?;
        Ok(evaluation)
    }

    /// The rest shape estimated for the parameters at `x` (Sec. 6.5.2).
    pub fn rest_shape(&self, x: &[f64]) -> Result<Pattern, YarnFitError> {
        self.rest_shape_of(&self.model(x).1)
    }

    /// The rest shape estimated for `model` (Sec. 6.5.2).
    fn rest_shape_of(&self, model: &YarnModel) -> Result<Pattern, YarnFitError> {
        let options = RelaxOptions {
            method: RelaxMethod::Estimation { max_length_change: self.rest.max_length_change },
            max_resets: self.rest.max_resets,
            ..RelaxOptions::default()
        };
        let (rest_pattern, _) = relax(&self.pattern, model, &options, &mut |_| {})
            .map_err(|e| YarnFitError::RestShape(e.to_string()))?;
        Ok(rest_pattern)
    }

    /// The evaluation at `x` on the rest shape `rest_pattern` with the Jacobian of the residuals
    /// by the coordinates, from the sensitivities of the tile's equilibrium to each parameter
    /// ([`simulate_direction_with_sensitivity`]: the tile with each coordinate moved by
    /// [`SENSITIVITY_STEP`], on the same rest shape).
    pub fn evaluate_with_jacobian(
        &self,
        rest_pattern: &Pattern,
        x: &[f64],
        targets: &[DirectionTargets],
    ) -> Result<(Evaluation, Vec<Vec<f64>>), YarnFitError> {
        let (evaluation, tile, rest) = self.evaluate_on(rest_pattern, x, targets)?;
        let bounds = self.basis.bounds();
        // Step inwards at the upper bound.
        let steps: Vec<f64> = x
            .iter()
            .zip(&bounds)
            .map(|(v, (_, hi))| if v + SENSITIVITY_STEP > *hi { -SENSITIVITY_STEP } else { SENSITIVITY_STEP })
            .collect();
        let perturbed = steps
            .iter()
            .enumerate()
            .map(|(j, h)| {
                let mut moved = x.to_vec();
                moved[j] += h;
                RveModel::new(&evaluation.rest_pattern, &self.model(&moved).1)
                    .map_err(|e| YarnFitError::RestShape(e.to_string()))
            })
            .collect::<Result<Vec<_>, _>>()?;
        // The sensitivities come out per step `h_j`; a backward step flips the sign back.
        let sensitivities = targets
            .par_iter()
            .map(|t| {
                simulate_direction_with_sensitivity(&tile, &perturbed, SENSITIVITY_STEP, &rest, t)
                    .map(|(_, mut d)| {
                        for row in d.compression.iter_mut().chain(d.stress_n_m.iter_mut()) {
                            for (v, h) in row.iter_mut().zip(&steps) {
                                *v *= h.signum();
                            }
                        }
                        d
                    })
                    .map_err(|e| YarnFitError::Tile(e.to_string()))
            })
            .collect::<Result<Vec<_>, _>>()?;
        Ok((evaluation, residual_jacobian(targets, &sensitivities)))
    }

    /// The evaluation at `x` on the rest shape `rest_pattern`, with its tile and the tile's
    /// zero-strain equilibrium.
    pub fn evaluate_on(
        &self,
        rest_pattern: &Pattern,
        x: &[f64],
        targets: &[DirectionTargets],
    ) -> Result<(Evaluation, RveModel, RveState), YarnFitError> {
        self.evaluate_params(rest_pattern, &self.basis.params(x), targets)
    }

    /// [`YarnProblem::evaluate_on`] at the parameters `params`.
    fn evaluate_params(
        &self,
        rest_pattern: &Pattern,
        params: &YarnParams,
        targets: &[DirectionTargets],
    ) -> Result<(Evaluation, RveModel, RveState), YarnFitError> {
        let (params, model) = (*params, self.yarn_model(params));
        let tile = RveModel::new(rest_pattern, &model).map_err(|e| YarnFitError::RestShape(e.to_string()))?;
        let zero = MacroStrain::new(0.0, 0.0, 0.0, 0.0, 0.0).expect("zero strain is valid");
        let (report, rest) = solve_at(&tile, &zero, None, &SolveOptions::default());
        if !report.converged {
            return Err(YarnFitError::Tile("no equilibrium at zero strain".into()));
        }
        let curves = simulate(&tile, &rest, targets).map_err(|e| YarnFitError::Tile(e.to_string()))?;
        let residuals = residuals(targets, &curves);
        let cost = residuals.iter().map(|r| r * r).sum();
        Ok((Evaluation { params, curves, residuals, cost, rest_pattern: rest_pattern.clone() }, tile, rest))
    }

    /// The point `x` moved into the search box.
    fn clamped(&self, x: &[f64]) -> Vec<f64> {
        x.iter().zip(self.basis.bounds()).map(|(v, (lo, hi))| v.clamp(lo, hi)).collect()
    }
}

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

/// Progress of a fit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum YarnFitEvent {
    /// A swarm generation finished: generation and best cost.
    Generation(usize, f64),
    /// A local evaluation finished: count and its cost (infinite if it failed).
    LocalEvaluation(usize, f64),
}

/// The result of a yarn-level fit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct YarnFit {
    /// Format tag of the JSON file.
    pub format: String,
    /// Layout version of the JSON file.
    pub version: u32,
    /// The fabric's name.
    pub fabric: String,
    /// The input geometry's pattern name.
    pub pattern: String,
    /// Fixed quantities.
    pub basis: YarnBasis,
    /// Settings used.
    pub settings: YarnFitSettings,
    /// Names of the search coordinates.
    pub coordinate_names: Vec<String>,
    /// The global step.
    pub swarm: Option<SwarmReport>,
    /// The local step.
    pub local: Option<LocalReport>,
    /// Search point reached.
    pub coordinates: Vec<f64>,
    /// The estimated parameters.
    pub params: YarnParams,
    /// The targets (local resolution).
    pub targets: Vec<DirectionTargets>,
    /// The tile's responses there.
    pub simulated: Vec<SimulatedCurve>,
    /// `g` of (6.11).
    pub cost: f64,
    /// Errors per direction (Fig. 6.15).
    pub errors: Vec<YarnErrors>,
    /// Wall time of the whole fit (s).
    pub wall_time_s: f64,
}

/// Format tag of [`YarnFit`] files.
pub const YARN_FIT_FORMAT: &str = "yarnhom.yarn-fit";

/// Layout version of [`YarnFit`] files (`schemas/yarn-fit.v2.schema.json`; v2 adds
/// `basis.mechanisms`, and v1 files read as the thesis' mechanisms).
pub const YARN_FIT_VERSION: u32 = 2;

/// The JSON schema of [`YarnFit`] files.
pub fn yarn_fit_schema() -> schemars::Schema {
    schemars::schema_for!(YarnFit)
}

/// The fit's result and the estimated rest shape.
pub struct Fitted {
    /// The result.
    pub fit: YarnFit,
    /// The input geometry relaxed for the estimated parameters.
    pub rest_pattern: Pattern,
    /// The estimated yarn model.
    pub model: YarnModel,
}

/// Fit `problem`: the swarm from scratch (or `start` if given: no swarm), then the local step.
pub fn fit_yarn(
    problem: &YarnProblem,
    fabric: &str,
    settings: &YarnFitSettings,
    start: Option<&[f64]>,
    progress: &(dyn Fn(YarnFitEvent) + Sync),
) -> Result<Fitted, YarnFitError> {
    let started = Instant::now();
    let (swarm_report, mut x) = match start {
        Some(x) => (None, problem.clamped(x)),
        None => {
            let report = global_step(problem, settings, &[], progress)?;
            let best = report.best.clone();
            (Some(report), best)
        }
    };
    let targets = problem.targets(settings.local_targets)?;
    let local = match settings.local {
        LocalSolver::None => None,
        solver => {
            let (report, best) = local_step(problem, solver, &x, &targets, settings.local_budget, progress)?;
            x = best;
            Some(report)
        }
    };
    let evaluation = problem.evaluate(&x, &targets)?;
    let (_, model) = problem.model(&x);
    let fit = YarnFit {
        format: YARN_FIT_FORMAT.into(),
        version: YARN_FIT_VERSION,
        fabric: fabric.into(),
        pattern: problem.pattern.name.clone(),
        basis: problem.basis,
        settings: *settings,
        coordinate_names: problem.basis.coordinate_names().into_iter().map(String::from).collect(),
        swarm: swarm_report,
        local,
        coordinates: x,
        params: evaluation.params,
        errors: errors(&targets, &evaluation.curves),
        targets,
        simulated: evaluation.curves,
        cost: evaluation.cost,
        wall_time_s: started.elapsed().as_secs_f64(),
    };
    Ok(Fitted { fit, rest_pattern: evaluation.rest_pattern, model })
}

/// The particle swarm on `settings.swarm_targets` targets per direction, particles starting at
/// `seeds` first.
pub fn global_step(
    problem: &YarnProblem,
    settings: &YarnFitSettings,
    seeds: &[Vec<f64>],
    progress: &(dyn Fn(YarnFitEvent) + Sync),
) -> Result<SwarmReport, YarnFitError> {
    let coarse = problem.targets(settings.swarm_targets)?;
    let report = swarm(
        |x| problem.evaluate(x, &coarse).ok().map(|e| e.cost),
        &problem.basis.bounds(),
        &settings.swarm,
        seeds,
        &|g, best| progress(YarnFitEvent::Generation(g, best)),
    );
    if !report.best_cost.is_finite() {
        return Err(YarnFitError::NothingEvaluable(report.evaluations));
    }
    Ok(report)
}

/// The local step from `x`: the report and the point reached.
fn local_step(
    problem: &YarnProblem,
    solver: LocalSolver,
    x: &[f64],
    targets: &[DirectionTargets],
    budget: usize,
    progress: &(dyn Fn(YarnFitEvent) + Sync),
) -> Result<(LocalReport, Vec<f64>), YarnFitError> {
    let started = Instant::now();
    let start_cost = problem.evaluate(x, targets)?.cost;
    let count = std::sync::atomic::AtomicUsize::new(1);
    let evaluate = |x: &[f64]| {
        let e = problem.evaluate(&problem.clamped(x), targets).ok();
        let n = count.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
        progress(YarnFitEvent::LocalEvaluation(n, e.as_ref().map_or(f64::INFINITY, |e| e.cost)));
        e
    };
    let bounds = problem.basis.bounds();
    let (best, cost, stop) = match solver {
        LocalSolver::Cobyla => {
            // A failed evaluation costs far more than the start: COBYLA needs a number.
            let penalty = 1e3 * start_cost.max(1.0);
            let objective = |x: &[f64], _: &mut ()| evaluate(x).map_or(penalty, |e| e.cost);
            let rho: Vec<f64> = bounds.iter().map(|(lo, hi)| 0.1 * (hi - lo)).collect();
            let xtol: Vec<f64> = bounds.iter().map(|(lo, hi)| 1e-3 * (hi - lo)).collect();
            let tolerances =
                cobyla::StopTols { ftol_rel: 1e-4, xtol_abs: xtol, ..cobyla::StopTols::default() };
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
        LocalSolver::LevenbergMarquardt => {
            let settings = LmSettings { max_iterations: budget, difference_step: 2e-2, cost_tolerance: 1e-3 };
            let report = levenberg_marquardt(|x| evaluate(x).map(|e| e.residuals), x, &settings)
                .ok_or_else(|| YarnFitError::Tile("the local step's start has no equilibrium".into()))?;
            let stop = if report.converged { "converged" } else { "iteration limit" };
            (problem.clamped(&report.params), 2.0 * report.cost, stop.to_string())
        }
        LocalSolver::GaussNewton => {
            // Alternate as the thesis does (Sec. 6.5.2): on the rest shape estimated at the
            // current point, Gauss-Newton / LM with the sensitivity Jacobian (consistent with its
            // residuals); then re-estimate the rest shape there. `budget` Jacobians in all.
            let settings = LmSettings {
                max_iterations: budget.div_ceil(GAUSS_NEWTON_ROUNDS),
                cost_tolerance: 1e-3,
                ..LmSettings::default()
            };
            let mut current = x.to_vec();
            let mut stops = Vec::new();
            for _ in 0..GAUSS_NEWTON_ROUNDS {
                let Ok(rest_pattern) = problem.rest_shape(&current) else { break };
                let on_rest = |p: &[f64]| {
                    let e = problem.evaluate_on(&rest_pattern, &problem.clamped(p), targets).ok();
                    let n = count.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
                    progress(YarnFitEvent::LocalEvaluation(
                        n,
                        e.as_ref().map_or(f64::INFINITY, |e| e.0.cost),
                    ));
                    e.map(|e| e.0.residuals)
                };
                let jacobian = |p: &DVector<f64>, _: &DVector<f64>| {
                    let n = count.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
                    let j = problem
                        .evaluate_with_jacobian(&rest_pattern, &problem.clamped(p.as_slice()), targets)
                        .ok();
                    progress(YarnFitEvent::LocalEvaluation(
                        n,
                        j.as_ref().map_or(f64::INFINITY, |(e, _)| e.cost),
                    ));
                    (j.map(|(_, rows)| DMatrix::from_fn(rows.len(), p.len(), |r, c| rows[r][c])), 0)
                };
                let Some(report) = minimize_with_jacobian(on_rest, jacobian, &current, &settings) else {
                    break;
                };
                let stop = if report.converged { "converged" } else { "iteration limit" };
                stops.push(format!("{stop} at g = {:.4} on its rest shape", 2.0 * report.cost));
                current = problem.clamped(&report.params);
            }
            let cost = evaluate(&current).map_or(f64::INFINITY, |e| e.cost);
            (current, cost, format!("{} rounds: {}", stops.len(), stops.join(", ")))
        }
        LocalSolver::None => (x.to_vec(), start_cost, "no local step".to_string()),
    };
    let (best, cost) = if cost <= start_cost { (best, cost) } else { (x.to_vec(), start_cost) };
    let report = LocalReport {
        solver,
        start_cost,
        cost,
        evaluations: count.load(std::sync::atomic::Ordering::Relaxed),
        stop,
        wall_time_s: started.elapsed().as_secs_f64(),
    };
    Ok((report, best))
}
