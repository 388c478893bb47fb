//! Yarn-level estimation (thesis Sec. 6.5): the parameters of the Ch. 6 yarn model whose periodic
//! tile reproduces the uniform targets of the fitted shell, and `yarn-fit.json`.
//!
//! Every evaluation of the objective first estimates the yarns' rest shape for the candidate
//! parameters, then simulates the tile along every tested direction and scores it by (6.11)
//! ([`super::problem`]): rest shapes and mechanical parameters alternate, as the thesis
//! prescribes. The global step is a particle swarm ([`crate::optimize::swarm`], 64 particles x
//! 10 generations on 7 targets per direction); the local step ([`super::local`]) refines its
//! best point on 20 targets per direction.

use std::path::PathBuf;
use std::time::Instant;

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use yarnhom_artifacts::report::{Report, read_report};
use yarnhom_artifacts::{Pattern, YarnModel};

use super::local::{LocalReport, local_step};
use super::objective::{DirectionTargets, SimulatedCurve, YarnErrors, errors};
use super::params::{InnerContact, YarnBasis, YarnParams};
use super::problem::{TargetSource, YarnFitError, YarnFitEvent, YarnProblem};
use super::settings::{LocalSolver, YarnFitSettings};
use crate::data::set::{Direction, MeasurementSet};
use crate::optimize::swarm::{SwarmReport, minimize as swarm};
use crate::shell::fit::ShellFit;

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

/// Layout version of [`YarnFit`] files (`schemas/yarn-fit.v3.schema.json`; v2 adds
/// `basis.mechanisms`, and v1 files read as the thesis' mechanisms; v3 adds `basis.stitch` and
/// `basis.tile_length_per_stitch_m`, absent in v1 and v2 files, which were fitted on the
/// generators' default stitches with the thesis' `R_2`).
pub const YARN_FIT_VERSION: u32 = 3;

/// The JSON schema of [`YarnFit`] files.
pub fn yarn_fit_schema() -> schemars::Schema {
    schemars::schema_for!(YarnFit)
}

impl Report for YarnFit {
    const FORMAT: &'static str = YARN_FIT_FORMAT;
    const VERSION: u32 = YARN_FIT_VERSION;

    /// Version 1 had no `basis.mechanisms`: it was written when the thesis' mechanisms were the
    /// only ones, and reads as them
    /// ([`YarnMechanisms::THESIS`](super::params::YarnMechanisms::THESIS), the field's default).
    /// Versions 1 and 2 had no `basis.stitch` nor `basis.tile_length_per_stitch_m`: they were
    /// fitted before a set's `[stitch]` was used, and read with both absent (the fields'
    /// default: the generator's default stitch, the thesis' `R_2`).
    fn migrate(version: u32, document: serde_json::Value) -> Result<Self, yarnhom_artifacts::Error> {
        let what = match version {
            1 => "yarn-fit v1",
            2 => "yarn-fit v2",
            _ => {
                return Err(yarnhom_artifacts::Error::NoMigration {
                    kind: YARN_FIT_FORMAT.into(),
                    found: version,
                    supported: YARN_FIT_VERSION,
                });
            }
        };
        let fit: YarnFit = serde_json::from_value(document)
            .map_err(|e| yarnhom_artifacts::Error::Decode { what, message: e.to_string() })?;
        Ok(YarnFit { version: YARN_FIT_VERSION, ..fit })
    }

    /// The cost, the estimated parameters, the errors per direction, the swarm and the local
    /// step.
    fn summary(&self) -> String {
        let p = &self.params;
        let mut lines = vec![
            format!(
                "yarn model of {} ({}), g = {:.5}, {:.1} s",
                self.fabric, self.pattern, self.cost, self.wall_time_s
            ),
            format!(
                "  k_s1 {:.4} N, k_s2 {:.4} N, eps_bar {:.4}, k_b {:.3e} N m², R_1 {:.4} mm, k_c1 {:.3e} N/m (R_2 {:.4} mm, k_c2 {:.3e} N/m)",
                p.k_s1_n,
                p.k_s2_n,
                p.eps_bar,
                p.k_b_nm2,
                p.r1_m * 1e3,
                p.k_c1_n_m,
                p.r2_m * 1e3,
                p.k_c2_n_m
            ),
            stitch_line(&self.basis),
            "  direction  comfort stress  power stress  compression".into(),
        ];
        for e in &self.errors {
            lines.push(format!(
                "  {:<9}  {:>13.1}%  {:>12}  {:>10.1}%",
                e.direction.as_str(),
                100.0 * e.comfort_stress,
                e.power_stress.map_or("-".into(), |x| format!("{:.1}%", 100.0 * x)),
                100.0 * e.compression
            ));
        }
        if let Some(s) = &self.swarm {
            lines.push(format!(
                "  swarm: {} evaluations ({} failed), best g = {:.5}",
                s.evaluations, s.failures, s.best_cost
            ));
        }
        if let Some(l) = &self.local {
            lines.push(format!(
                "  local ({:?}): g {:.5} -> {:.5} in {} evaluations, {:.1} s ({})",
                l.solver, l.start_cost, l.cost, l.evaluations, l.wall_time_s, l.stop
            ));
        }
        lines.join("\n")
    }
}

/// The summary line on the stitch the fit used: the set's `[stitch]` or the generator's default,
/// the tile's yarn length per stitch where known, and the rule that held `R_2`.
fn stitch_line(basis: &YarnBasis) -> String {
    let tile = basis.tile_length_per_stitch_m.map(|l| format!("{:.4} mm per stitch", l * 1e3));
    let stitch = match (&basis.stitch, tile) {
        (Some(stitch), Some(tile)) => format!("the set's, {stitch}; tile {tile}"),
        (Some(stitch), None) => format!("the set's, {stitch}; tile from a pattern file, as it is"),
        (None, Some(tile)) => format!("the generator's default, {tile}"),
        (None, None) => "not recorded (a pattern file, or a fit written before v3)".to_string(),
    };
    let core = basis.stitch.and_then(|s| s.core_radius_m.map(|c| c / s.yarn_radius_m));
    let r2 = match (basis.mechanisms.inner_contact, core) {
        (InnerContact::Fitted, _) => String::new(),
        (_, Some(fraction)) => format!(" (R_2 = {fraction:.4} R_1, the core's fraction of the yarn)"),
        (_, None) => " (R_2 = 0.25 R_est)".to_string(),
    };
    format!("  stitch: {stitch}{r2}")
}

/// The search point of the lowest-cost fit among `yarn-fit.json` files (e.g. the shards' of a
/// split swarm), if any are given: where the local step starts instead of a swarm.
pub fn best_start(paths: &[PathBuf]) -> Result<Option<Vec<f64>>, yarnhom_artifacts::Error> {
    let mut best: Option<YarnFit> = None;
    for path in paths {
        let fit: YarnFit = read_report(path)?;
        if best.as_ref().is_none_or(|b| fit.cost < b.cost) {
            best = Some(fit);
        }
    }
    Ok(best.map(|b| b.coordinates))
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
