//! The bending fit (thesis Sec. 6.3.2): the hinge bending (6.4) that reproduces a fabric's
//! measured bending tests, by simulation in the loop,
//! `k_bending = argmin Σ_i (r(k_bending, d_i) - r_i)²`, on the set's bending tests
//! ([`BendingTests`]: the pear loop and, beyond the thesis, the cantilever on both faces, which
//! shows a rest curvature the pear loop cannot), with their normalized residuals.
//!
//! Models ([`BendingModel`]), each nested in the next by its parameters:
//! * `Isotropic`: one stiffness `k_θ`, flat at rest (the diagnosis' base: straight bending);
//! * `Anisotropic`: `k_θ` per tested direction, interpolated by the edge direction (the
//!   thesis' `{k_weft, k_bias, k_warp}`); an untested direction takes the geometric mean of
//!   the tested ones;
//! * `RestCurvature`: one `k_θ` and a rest curvature `κ̄` per direction with cantilever tests.
//!
//! Stiffnesses are fitted in `log10 k` (from the best of a coarse scan for the isotropic
//! model), rest curvatures in units of 10 /m, by Levenberg-Marquardt ([`crate::optimize::lm`]).

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use yarnhom_geom::stats::root_mean_square;
use yarnhom_shell::{HingeBending, StvkNeoHookean};

use crate::data::set::Direction;
use crate::experiments::bending_tests::{BendingDirectionError, BendingTests};
use crate::optimize::lm::{LmSettings, minimize};

/// Why a bending fit cannot run.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BendingFitError {
    /// No simulation of the starting model reached equilibrium.
    #[error("no starting bending stiffness gives every bending test an equilibrium")]
    NoStart,
}

/// Which bending parameters are fitted.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum BendingModel {
    /// One stiffness, flat at rest.
    Isotropic,
    /// A stiffness per tested direction, flat at rest.
    Anisotropic,
    /// One stiffness and a rest curvature per direction with cantilever tests.
    RestCurvature,
}

/// The free parameters of a model on a set of tests.
struct Parameterization {
    model: BendingModel,
    stiff: Vec<Direction>,
    curled: Vec<Direction>,
}

/// Units of the fitted rest curvatures (1/m).
const CURVATURE_UNIT: f64 = 10.0;

impl Parameterization {
    fn new(model: BendingModel, tests: &BendingTests) -> Self {
        let stiff = match model {
            BendingModel::Anisotropic => tests.directions(false),
            _ => Vec::new(),
        };
        let curled = match model {
            BendingModel::RestCurvature => tests.directions(true),
            _ => Vec::new(),
        };
        Self { model, stiff, curled }
    }

    fn decode(&self, p: &[f64]) -> HingeBending {
        let mut k = [0.0; 3];
        match self.model {
            BendingModel::Anisotropic => {
                let tested: Vec<f64> = p[..self.stiff.len()].to_vec();
                let mean = tested.iter().sum::<f64>() / tested.len() as f64;
                for (i, d) in Direction::ALL.iter().enumerate() {
                    k[i] = 10f64.powf(self.stiff.iter().position(|s| s == d).map_or(mean, |j| tested[j]));
                }
            }
            _ => k = [10f64.powf(p[0]); 3],
        }
        let mut rest = [0.0; 3];
        for (j, d) in self.curled.iter().enumerate() {
            rest[Direction::ALL.iter().position(|a| a == d).expect("a direction")] =
                CURVATURE_UNIT * p[1 + j];
        }
        HingeBending {
            k_weft: k[0],
            k_bias: k[1],
            k_warp: k[2],
            rest_curvature_weft: rest[0],
            rest_curvature_bias: rest[1],
            rest_curvature_warp: rest[2],
        }
    }

    fn encode(&self, b: &HingeBending) -> Vec<f64> {
        let k = [b.k_weft, b.k_bias, b.k_warp];
        let rest = [b.rest_curvature_weft, b.rest_curvature_bias, b.rest_curvature_warp];
        let index = |d: &Direction| Direction::ALL.iter().position(|a| a == d).expect("a direction");
        match self.model {
            BendingModel::Anisotropic => self.stiff.iter().map(|d| k[index(d)].log10()).collect(),
            _ => {
                let mean = k.iter().map(|k| k.log10()).sum::<f64>() / 3.0;
                std::iter::once(mean)
                    .chain(self.curled.iter().map(|d| rest[index(d)] / CURVATURE_UNIT))
                    .collect()
            }
        }
    }
}

/// A fitted bending model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct BendingFit {
    /// The model fitted.
    pub model: BendingModel,
    /// The fitted hinge bending.
    pub bending: HingeBending,
    /// Parameters fitted.
    pub parameter_count: usize,
    /// RMS normalized error on the fitted readings.
    pub error: f64,
    /// RMS normalized error on the held-out readings (absent when every reading is fitted).
    pub heldout_error: Option<f64>,
    /// Errors per direction over every reading.
    pub by_direction: Vec<BendingDirectionError>,
    /// The simulated reading of every test, in test order.
    pub simulated: Vec<f64>,
    /// Levenberg-Marquardt iterations.
    pub iterations: usize,
    /// Simulations of the whole test set.
    pub evaluations: usize,
}

/// Fit `model` to the fitted readings of `tests`, with `membrane`, from `start` (the isotropic
/// model may start from a scan instead: `None`).
pub fn fit_bending(
    tests: &BendingTests,
    membrane: &StvkNeoHookean,
    model: BendingModel,
    start: Option<&HingeBending>,
    lm: &LmSettings,
) -> Result<BendingFit, BendingFitError> {
    let parameterization = Parameterization::new(model, tests);
    let cost = |p: &[f64]| -> Option<Vec<f64>> {
        let simulated = tests.simulate(membrane, &parameterization.decode(p))?;
        Some(tests.residuals(&simulated, true))
    };
    let (from, scan_evaluations) = match start {
        Some(b) => (parameterization.encode(b), 0),
        None => scan_start(&parameterization, &cost)?,
    };
    let report = minimize(cost, &from, lm).ok_or(BendingFitError::NoStart)?;
    let bending = parameterization.decode(&report.params);
    let simulated = tests.simulate(membrane, &bending).ok_or(BendingFitError::NoStart)?;
    let heldout = tests.residuals(&simulated, false);
    Ok(BendingFit {
        model,
        bending,
        parameter_count: report.params.len(),
        error: root_mean_square(tests.residuals(&simulated, true)),
        heldout_error: (!heldout.is_empty()).then(|| root_mean_square(heldout.iter().copied())),
        by_direction: tests.errors_by_direction(&simulated),
        simulated,
        iterations: report.iterations,
        evaluations: report.evaluations + scan_evaluations + 1,
    })
}

/// The best isotropic, flat stiffness of a scan over `10^-8 .. 10^-3` J (half decades); also
/// the evaluations made.
fn scan_start(
    parameterization: &Parameterization,
    cost: &(impl Fn(&[f64]) -> Option<Vec<f64>> + Sync),
) -> Result<(Vec<f64>, usize), BendingFitError> {
    let candidates: Vec<Vec<f64>> = (0..=10)
        .map(|i| parameterization.encode(&HingeBending::isotropic(10f64.powf(-8.0 + 0.5 * i as f64))))
        .collect();
    let best = candidates
        .iter()
        .filter_map(|p| cost(p).map(|r| (r.iter().map(|x| x * x).sum::<f64>(), p)))
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .ok_or(BendingFitError::NoStart)?;
    Ok((best.1.clone(), candidates.len()))
}
