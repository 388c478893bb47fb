//! How a yarn-level fit runs (thesis Sec. 6.5.3): the swarm, the local step, the targets per
//! direction, and the problem's rest-shape estimation and comfort force.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::objective::COMFORT_FORCE_N;
use super::problem::RestShapeSettings;
#[cfg(doc)]
use super::problem::YarnProblem;
use crate::optimize::swarm::SwarmSettings;

/// The local optimizer.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "kebab-case")]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum LocalSolver {
    /// COBYLA (Powell 1994), derivative-free, as the thesis.
    Cobyla,
    /// Levenberg-Marquardt on the residuals of (6.11), Jacobian by finite differences of whole
    /// evaluations.
    #[cfg_attr(feature = "clap", value(name = "lm"))]
    LevenbergMarquardt,
    /// Gauss-Newton / Levenberg-Marquardt with the Jacobian from the parameter sensitivities of
    /// the tile's equilibrium (one evaluation per Jacobian instead of one per parameter),
    /// alternated with the rest-shape estimation: each round holds the rest shape estimated at
    /// its start.
    ///
    /// See [`YarnProblem::evaluate_with_jacobian`].
    GaussNewton,
    /// No local step (the swarm's best is the result).
    None,
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
