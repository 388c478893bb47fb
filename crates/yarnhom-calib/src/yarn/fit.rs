//! Yarn-level estimation (thesis Sec. 6.5): the parameters of the Ch. 6 yarn model whose periodic
//! tile reproduces the uniform targets of the fitted shell, and `yarn-fit.json`.
//!
//! Every evaluation of the objective first estimates the yarns' rest shape for the candidate
//! parameters, then simulates the tile along every tested direction and scores it by (6.11)
//! ([`super::problem`]): rest shapes and mechanical parameters alternate, as the thesis
//! prescribes. The global step is a particle swarm ([`crate::optimize::swarm`], 64 particles x
//! 10 generations on 7 targets per direction); the local step ([`super::local`]) refines its
//! best point on 20 targets per direction.

use std::time::Instant;

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use yarnhom_artifacts::{Pattern, YarnModel};

use super::local::{LocalReport, local_step};
use super::objective::{DirectionTargets, SimulatedCurve, YarnErrors, errors};
use super::params::{YarnBasis, YarnParams};
use super::problem::{YarnFitError, YarnFitEvent, YarnProblem};
use super::settings::{LocalSolver, YarnFitSettings};
use crate::optimize::swarm::{SwarmReport, minimize as swarm};

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

