//! The yarn-level confirmation of a diagnosed cause: the diagnosis screens its catalog
//! ([`crate::cause`]) cheaply at the shell level, then a cause that has a mechanism in the Ch. 6
//! yarn model is confirmed on the periodic tile with the yarn-level fit of Sec. 6.5.
//!
//! 1. Targets: the problem's, in the diagnosis the uniform tests (6.3) of the **extended**
//!    shell, the membrane with the diagnosed extension, along every tested direction (the
//!    thesis' route from measurements to the yarn level); `n` fitted targets per direction, and
//!    `n` held out at the midpoints between them.
//! 2. Models, nested: the base of Sec. 6.4 (linear yarn stretch `k_s1 = k_s2`, single-phase
//!    contact `k_c2 = 0`, [`YarnMechanisms::BASE`]) and the base plus the cause's mechanism:
//!    the biphasic stretch (6.5) for `biphasic-stretch`, a fitted inner contact barrier (6.7)
//!    for `two-phase-contact`.
//! 3. Fits, with the same swarm and local budget for both: the base by swarm and local step; the
//!    extension by a swarm seeded with the base's optimum (its new mechanism switched on at no
//!    effect, [`super::params::YarnBasis::embed`]: a nested local start alone stays in the base's basin, where
//!    e.g. a stiff linear yarn is compensated by soft contacts), then a local step; then the
//!    base once more, by a local step from the extension's optimum with the mechanism off, so
//!    that a better basin found by the extension's search is open to the base as well and only
//!    the mechanism is credited with the gain.
//! 4. Verdict: the mechanism is confirmed when the base misses the held-out targets by more than
//!    [`MIN_BASE_ERROR`] (else the stitch geometry already explains the effect), the extension's
//!    held-out error is below [`CONFIRM_RATIO`] of the base's, and its Akaike criterion on the
//!    fitted targets is lower by more than [`MIN_CRITERION_DROP`]: the shell-level rules, without
//!    a noise term (the targets are a smooth model's).
//!
//! The other causes have no counterpart in the yarn model (area preservation and bending
//! anisotropy emerge from the stitch geometry, rest curvature from the rest shape, and the
//! yarns have no friction), so they are confirmed at the shell level only, and the report says
//! why.

use std::time::Instant;

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use yarnhom_geom::stats::root_mean_square;

use super::fit::{fit_yarn, global_step};
use super::objective::{DirectionTargets, YarnErrors, errors, residuals};
use super::params::{InnerContact, YarnMechanisms, YarnParams};
use super::problem::{YarnFitError, YarnFitEvent, YarnProblem};
use super::settings::{LocalSolver, YarnFitSettings};
use crate::cause::CauseId;
use crate::optimize::akaike::criterion;
use crate::optimize::swarm::SwarmSettings;

/// The extension must bring the base's held-out error below this fraction of it.
pub const CONFIRM_RATIO: f64 = 0.75;

/// Below this held-out RMS error the base yarn model already reproduces the targets.
pub const MIN_BASE_ERROR: f64 = 0.03;

/// The Akaike criterion must drop by more than this.
pub const MIN_CRITERION_DROP: f64 = 4.0;

/// How large the confirmation's search is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SearchSize {
    /// Swarm 16 x 3 on 5 targets per direction, Gauss-Newton 8 Jacobians on 8.
    Reduced,
    /// The thesis' swarm, 64 x 10 on 7 targets, Gauss-Newton 20 Jacobians on 20.
    Full,
}

impl SearchSize {
    /// The fit settings of this size (both models get them).
    pub fn settings(self) -> YarnFitSettings {
        let (particles, generations, swarm_targets, local_targets, local_budget) = match self {
            SearchSize::Reduced => (16, 3, 5, 8, 8),
            SearchSize::Full => (64, 10, 7, 20, 20),
        };
        YarnFitSettings {
            swarm: SwarmSettings { particles, generations, ..SwarmSettings::default() },
            swarm_targets,
            local_targets,
            local: LocalSolver::GaussNewton,
            local_budget,
            ..YarnFitSettings::default()
        }
    }
}

/// The yarn-level mechanism of a cause, as the mechanisms of the extended yarn model.
pub fn yarn_mechanism(cause: CauseId) -> Option<YarnMechanisms> {
    match cause {
        CauseId::BiphasicStretch => Some(YarnMechanisms { biphasic_stretch: true, ..YarnMechanisms::BASE }),
        CauseId::TwoPhaseContact => {
            Some(YarnMechanisms { inner_contact: InnerContact::Fitted, ..YarnMechanisms::BASE })
        }
        _ => None,
    }
}

/// Why a cause has no yarn-level confirmation.
fn no_mechanism_reason(cause: CauseId) -> &'static str {
    match cause {
        CauseId::AreaPreservation | CauseId::AnisotropicBending => {
            "the yarn model has no separate mechanism for it: the stitch geometry gives it, so it is confirmed at \
             the shell level only"
        }
        CauseId::RestCurvature => {
            "the yarn model has no separate mechanism for it: it comes from the yarns' rest shape, so it is \
             confirmed at the shell level only"
        }
        CauseId::FrictionHysteresis => {
            "the yarn model has no friction (the thesis' Sec. 6.7 leaves it out), so it is confirmed at the shell \
             level only"
        }
        CauseId::None | CauseId::Unexplained => "no cause from the catalog to confirm",
        CauseId::BiphasicStretch | CauseId::TwoPhaseContact => "",
    }
}

/// One yarn model of the confirmation, fitted and scored.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct YarnLevelModel {
    /// The mechanisms fitted.
    pub mechanisms: YarnMechanisms,
    /// Names of its search coordinates.
    pub coordinate_names: Vec<String>,
    /// The search point reached.
    pub coordinates: Vec<f64>,
    /// The fitted parameters.
    pub params: YarnParams,
    /// RMS of the residuals of (6.11) on the fitted targets.
    pub error: f64,
    /// RMS of the residuals of (6.11) on the held-out targets.
    pub heldout_error: f64,
    /// Akaike criterion on the fitted targets, `n ln(RSS/n) + 2k`.
    pub criterion: f64,
    /// Errors per direction on the fitted targets (Fig. 6.15).
    pub errors: Vec<YarnErrors>,
    /// Objective evaluations of its local steps.
    pub evaluations: usize,
}

/// The yarn-level confirmation of a cause.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct YarnConfirmation {
    /// The cause confirmed.
    pub cause: CauseId,
    /// The input geometry's pattern name.
    pub pattern: String,
    /// Settings of the fits (swarm and local step, the same for both models).
    pub settings: YarnFitSettings,
    /// Objective evaluations of the two swarms.
    pub swarm_evaluations: usize,
    /// The base yarn model.
    pub base: YarnLevelModel,
    /// The base plus the cause's mechanism.
    pub extended: YarnLevelModel,
    /// Whether the mechanism is confirmed.
    pub confirmed: bool,
    /// The verdict, with its numbers.
    pub verdict: String,
    /// Wall time (s).
    pub wall_time_s: f64,
}

/// The yarn-level step of a diagnosis.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "kebab-case", tag = "status")]
pub enum YarnLevel {
    /// The confirmation ran.
    Confirmation(Box<YarnConfirmation>),
    /// It did not, and why.
    NotRun {
        /// Why.
        reason: String,
    },
}

/// Confirm `cause` on `problem`'s targets (its mechanisms are replaced by the base's and the
/// cause's extension).
pub fn confirm(
    problem: &YarnProblem,
    cause: CauseId,
    settings: &YarnFitSettings,
    progress: &(dyn Fn(YarnFitEvent) + Sync),
) -> Result<YarnConfirmation, YarnFitError> {
    let started = Instant::now();
    let extension = yarn_mechanism(cause).ok_or_else(|| {
        YarnFitError::NoMechanism(format!("{}: {}", cause.as_str(), no_mechanism_reason(cause)))
    })?;
    let base = YarnProblem { basis: problem.basis.with_mechanisms(YarnMechanisms::BASE), ..problem.clone() };
    let extended = YarnProblem { basis: problem.basis.with_mechanisms(extension), ..problem.clone() };
    let heldout = base.heldout_targets(settings.local_targets)?;
    let base_swarm = global_step(&base, settings, &[], progress)?;
    let first_base = fit_and_score(&base, &base_swarm.best, settings, &heldout, progress)?;
    let extended_swarm =
        global_step(&extended, settings, &[extended.basis.embed(&first_base.params)], progress)?;
    let extended_model = fit_and_score(&extended, &extended_swarm.best, settings, &heldout, progress)?;
    // The base's second chance: a better basin found by the extension's search, with the
    // mechanism off (kept if its fitted error is lower; a failed one changes nothing).
    let second_base =
        fit_and_score(&base, &base.basis.embed(&extended_model.params), settings, &heldout, progress).ok();
    let local_evaluations = first_base.evaluations + second_base.as_ref().map_or(0, |m| m.evaluations);
    let base_model = match second_base {
        Some(second) if second.error < first_base.error => second,
        _ => first_base,
    };
    let base_model = YarnLevelModel { evaluations: local_evaluations, ..base_model };
    let (confirmed, verdict) = verdict(cause, &base_model, &extended_model);
    Ok(YarnConfirmation {
        cause,
        pattern: problem.pattern.name.clone(),
        settings: *settings,
        swarm_evaluations: base_swarm.evaluations + extended_swarm.evaluations,
        base: base_model,
        extended: extended_model,
        confirmed,
        verdict,
        wall_time_s: started.elapsed().as_secs_f64(),
    })
}

/// The local step of `problem` from `start`, scored on its targets and on `heldout`.
fn fit_and_score(
    problem: &YarnProblem,
    start: &[f64],
    settings: &YarnFitSettings,
    heldout: &[DirectionTargets],
    progress: &(dyn Fn(YarnFitEvent) + Sync),
) -> Result<YarnLevelModel, YarnFitError> {
    let fitted = fit_yarn(problem, "confirmation", settings, Some(start), progress)?;
    let fit = &fitted.fit;
    let on_heldout = problem.evaluate(&fit.coordinates, heldout)?;
    let fitted_residuals = residuals(&fit.targets, &fit.simulated);
    Ok(YarnLevelModel {
        mechanisms: problem.basis.mechanisms,
        coordinate_names: fit.coordinate_names.clone(),
        coordinates: fit.coordinates.clone(),
        params: fit.params,
        error: root_mean_square(fitted_residuals.iter().copied()),
        heldout_error: root_mean_square(residuals(heldout, &on_heldout.curves)),
        criterion: criterion(&fitted_residuals, fit.coordinates.len()),
        errors: errors(&fit.targets, &fit.simulated),
        evaluations: fit.local.as_ref().map_or(0, |l| l.evaluations),
    })
}

/// Whether the extension confirms `cause`, and the sentence saying so.
fn verdict(cause: CauseId, base: &YarnLevelModel, extended: &YarnLevelModel) -> (bool, String) {
    let mechanism = match cause {
        CauseId::BiphasicStretch => "biphasic yarn stretch (6.5)",
        _ => "inner contact barrier (6.7)",
    };
    let numbers = format!(
        "held-out RMS error {:.4} with the {mechanism} against {:.4} for the base yarn model ({:+.1}%), \
         criterion {:+.1}",
        extended.heldout_error,
        base.heldout_error,
        100.0 * (extended.heldout_error / base.heldout_error.max(1e-300) - 1.0),
        extended.criterion - base.criterion
    );
    if base.heldout_error <= MIN_BASE_ERROR {
        let text = format!(
            "not confirmed: the base yarn model (linear stretch, single-phase contact) already reproduces the \
             extended shell within {MIN_BASE_ERROR} on held-out targets, so the stitch geometry explains the \
             effect without the {mechanism}; {numbers}"
        );
        return (false, text);
    }
    let gains = extended.heldout_error < CONFIRM_RATIO * base.heldout_error;
    let simpler = extended.criterion < base.criterion - MIN_CRITERION_DROP;
    if gains && simpler {
        (true, format!("confirmed at the yarn level: {numbers}"))
    } else {
        let why = if gains {
            format!("the criterion does not drop by more than {MIN_CRITERION_DROP}")
        } else {
            format!("the held-out error does not drop below {:.0}% of the base's", 100.0 * CONFIRM_RATIO)
        };
        (false, format!("not confirmed at the yarn level ({why}): {numbers}"))
    }
}

/// The report of a cause that has no yarn-level mechanism to confirm (`None` if it has one).
pub fn skipped(cause: CauseId) -> Option<YarnLevel> {
    yarn_mechanism(cause)
        .is_none()
        .then(|| YarnLevel::NotRun { reason: format!("{}: {}", cause.as_str(), no_mechanism_reason(cause)) })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::yarn::params::YarnBasis;

    fn model(heldout_error: f64, criterion: f64) -> YarnLevelModel {
        let basis = YarnBasis {
            radius_m: 1e-3,
            r_est_m: 1e-3,
            k_s2_n: Some(100.0),
            density_kg_m3: 1.0,
            mechanisms: YarnMechanisms::BASE,
            stitch: None,
            tile_length_per_stitch_m: None,
        };
        YarnLevelModel {
            mechanisms: YarnMechanisms::BASE,
            coordinate_names: Vec::new(),
            coordinates: Vec::new(),
            params: basis.params(&[0.0, 1.0, 0.0]),
            error: heldout_error,
            heldout_error,
            criterion,
            errors: Vec::new(),
            evaluations: 0,
        }
    }

    #[test]
    fn the_verdict_needs_a_base_error_a_quarter_less_and_a_lower_criterion() {
        let cause = CauseId::BiphasicStretch;
        assert!(verdict(cause, &model(0.2, -10.0), &model(0.1, -20.0)).0);
        // Not enough gain, or not enough criterion drop.
        assert!(!verdict(cause, &model(0.2, -10.0), &model(0.16, -20.0)).0);
        assert!(!verdict(cause, &model(0.2, -10.0), &model(0.1, -13.0)).0);
        // The base already reproduces the targets: nothing to confirm, however large the gain.
        let (confirmed, text) = verdict(cause, &model(0.02, -10.0), &model(0.001, -90.0));
        assert!(!confirmed && text.contains("already reproduces"), "{text}");
    }

    #[test]
    fn only_yarn_level_causes_are_confirmed_and_the_others_say_why() {
        for cause in CauseId::CANDIDATES.into_iter().chain([CauseId::None, CauseId::Unexplained]) {
            let has_mechanism = matches!(cause, CauseId::BiphasicStretch | CauseId::TwoPhaseContact);
            assert_eq!(yarn_mechanism(cause).is_some(), has_mechanism, "{cause:?}");
            match skipped(cause) {
                Some(YarnLevel::NotRun { reason }) => {
                    assert!(!has_mechanism && reason.starts_with(cause.as_str()), "{reason}")
                }
                Some(YarnLevel::Confirmation(_)) => unreachable!("skipping never confirms"),
                None => assert!(has_mechanism),
            }
        }
    }
}
