//! The yarn-level estimation problem (thesis Sec. 6.5): the input geometry, the fixed
//! quantities and the uniform targets along the tested directions, and the evaluation of a
//! parameter set: the rest shape estimated for it (Sec. 6.5.2, [`yarnhom_rve::relax()`]), then the
//! tile simulated along every direction ([`super::objective`]) and scored by (6.11).

use rayon::prelude::*;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use yarnhom_artifacts::{Pattern, YarnModel};
use yarnhom_geom::MacroStrain;
use yarnhom_rve::assembly::RveState;
use yarnhom_rve::homogenize::solve_at;
use yarnhom_rve::{RelaxMethod, RelaxOptions, RveModel, SolveOptions, relax};
use yarnhom_shell::StvkNeoHookean;

use super::objective::{
    DirectionTargets, SimulatedCurve, residual_jacobian, residuals, simulate,
    simulate_direction_with_sensitivity,
};
use super::params::{YarnBasis, YarnParams};
use crate::data::set::Direction;

/// Coordinate step of the parameter sensitivities ([`YarnProblem::evaluate_with_jacobian`]).
pub const SENSITIVITY_STEP: f64 = 1e-4;

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

/// Progress of a fit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum YarnFitEvent {
    /// A swarm generation finished: generation and best cost.
    Generation(usize, f64),
    /// A local evaluation finished: count and its cost (infinite if it failed).
    LocalEvaluation(usize, f64),
}

/// Rest-shape estimation within each evaluation (Sec. 6.5.2).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct RestShapeSettings {
    /// Bound on the relative change of a rest length (0.2 in the thesis).
    pub max_length_change: f64,
    /// Rest-shape resets at most.
    pub max_resets: usize,
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
    pub(crate) fn clamped(&self, x: &[f64]) -> Vec<f64> {
        x.iter().zip(self.basis.bounds()).map(|(v, (lo, hi))| v.clamp(lo, hi)).collect()
    }
}
