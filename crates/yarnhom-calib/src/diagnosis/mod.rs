//! Model-discrepancy diagnosis: what the base model gets wrong about a measured fabric, which
//! cause from a fixed catalog ([`crate::cause`]) explains it, and how much an extension for
//! that cause gains on points it was not fitted to.
//!
//! The screening runs at the shell level, on the clamped swatches of the stretch tests
//! ([`crate::shell::membrane`]), in stages ([`diagnose`]):
//!
//! 1. Targets and split ([`stretch`]): up to `n` stretches per direction (default 10) chosen
//!    from the loading readings the set has ([`crate::data::targets`]: local lines over even
//!    windows, or means of consecutive groups where readings are few); the even ones are
//!    fitted, the odd ones held out. Unloading readings, where the set has enough, give
//!    unloading targets split the same way.
//! 2. Base fit: plain anisotropic StVK (no area terms, no stiffening; unloading predicted as
//!    loading), fitted by simulation in the loop.
//! 3. Stepwise explanation of the stretch track: every remaining candidate is fitted on top of
//!    the model so far, from several starts ([`stretch::fit_candidate`]): `area-preservation`
//!    (the Neo-Hookean area terms of (6.1)), `biphasic-stretch` ([`yarnhom_shell::Stiffening`]:
//!    stiffening past an onset strain), `friction-hysteresis` (the unloading force
//!    `F - h F_ref (F / F_ref)^p`, `p` profiled, `h` fitted on the even unloading targets),
//!    `two-phase-contact` (jamming,
//!    [`StvkNeoHookean::jamming`](yarnhom_shell::StvkNeoHookean::jamming): the compression
//!    across the pull stiffens past an onset, the shell-level trace of the soft then hard yarn
//!    contact of (6.7)). Each is judged by the [`DecisionRule`] on the held-out targets and on
//!    its own signature ([`signature`]); the passing one with the lowest held-out error is
//!    added, and the others are fitted again on top of it, until none passes or the held-out
//!    error is at the noise. The bending causes form a second track ([`bending`]) on the set's
//!    bending tests (the even readings of each test, direction and face fitted, the odd held
//!    out): base isotropic flat bending (one `k_θ`), `anisotropic-bending` (`k_θ` per
//!    direction) and `rest-curvature` (one `k_θ` and a rest curvature per direction, seen only
//!    by the cantilever tests on both faces), alternatives in one step; without the tests (or
//!    the areal density) they are not testable, with the reason.
//! 4. Causes: every confirmed cause in order of relative held-out gain (`causes`, the first is
//!    `cause`), else `none` or `unexplained` by the rule; an unexplained remainder is flagged.
//! 5. Evidence: every step's numbers, worded from the same rule.
//! 6. Confirmation (separate, [`confirm`], run by `calibrate diagnose` unless `--budget
//!    quick`): the first cause, if it has a mechanism in the yarn model, is confirmed on the
//!    periodic tile by nested yarn-level fits to the extended shell's uniform targets
//!    ([`Diagnosis::extended_material`]); the result goes to [`Diagnosis::yarn_level`].
//!
//! Errors are RMS values of the normalized residuals of (6.2) (force over the direction's mean
//! force, compression over its mean compression), pooled over the fitted or the held-out
//! targets; the noise is the pooled standard error of the targets (their readings' scatter
//! about the local line over the square root of their count, or the spread between repeats
//! over the square root of the repeats where larger). On the bending track the errors
//! are those of the bending tests ([`crate::experiments::bending_tests`]: each reading over its
//! group's mean), and the noise is the readings' scatter about a cubic in the abscissa fitted
//! to each test group, pooled over the residual degrees of freedom (an upper bound where a
//! curve is not cubic).
//!
//! The report ([`Diagnosis`], `report.json`) and its Markdown rendering
//! ([`markdown`], `report.md`) hold every number; [`settings`] says how to diagnose.

pub mod bending;
pub mod confirm;
pub mod markdown;
pub mod report;
pub mod rule;
pub mod settings;
mod signature;
pub mod stretch;

use std::time::Instant;

use bending::bending_track;
use report::{
    Cause, ConfirmedCause, DIAGNOSIS_FORMAT, DIAGNOSIS_VERSION, Diagnosis, Gain, ModelResult, SignatureScore,
    Step,
};
use rule::DecisionRule;
use settings::DiagnoseSettings;
use stretch::{Fitted, Phases, STRETCH_CAUSES, fit_base, fit_candidate, noise_level};

use crate::cause::CauseId;
use crate::data::set::MeasurementSet;
use crate::optimize::lm::LmSettings;
use crate::shell::bending::BendingFit;
use crate::shell::membrane::ShellFitError;

/// Diagnose `set`: targets and split, base fit, the stepwise explanation of each track by the
/// default [`DecisionRule`], and the report (without its yarn-level step, [`confirm`]).
pub fn diagnose(set: &MeasurementSet, settings: &DiagnoseSettings) -> Result<Diagnosis, ShellFitError> {
    let started = Instant::now();
    let rule = DecisionRule::default();
    let phases = Phases::of_set(set, settings)?;
    let noise = noise_level(&phases);
    let base_fit = fit_base(&phases, &settings.lm)?;
    let base = base_fit.result("base", &phases, Some("anisotropic StVK, unloading as loading".into()));
    let stretch = explain_stretch(&phases, &base_fit, &base, noise, &rule, &settings.lm);
    let bending = bending_track(set, &base_fit.material, settings);
    let mut bending_track = bending.track;
    let bend = explain_bending(bending_track.as_ref().map(|t| (&t.base, t.noise)), bending.candidates, &rule);
    let mut causes: Vec<ConfirmedCause> = stretch.causes.iter().cloned().chain(bend.cause.clone()).collect();
    causes.sort_by(|a, b| relative_gain(b).total_cmp(&relative_gain(a)));
    let mut evidence = base_evidence(&base, noise, bending_track.as_ref());
    evidence.extend(stretch.evidence.iter().cloned().chain(bend.evidence.iter().cloned()));
    let final_stretch = stretch.causes.last().map_or(&base, |c| &c.model);
    let final_bending = bend.cause.as_ref().map(|c| &c.model).or(bending_track.as_ref().map(|t| &t.base));
    let remainder = !rule.within_noise(final_stretch.scores().1, noise)
        || bending_track
            .as_ref()
            .zip(final_bending)
            .is_some_and(|(t, m)| !rule.within_noise(m.scores().1, t.noise));
    let id = match causes.first() {
        Some(c) => c.id,
        None if remainder => CauseId::Unexplained,
        None => CauseId::None,
    };
    evidence.push(match causes.is_empty() {
        true => rule.verdict(id),
        false => rule.remainder(final_stretch.scores().1, noise),
    });
    let (extended, gain) = match (stretch.causes.last(), &bend.cause) {
        (Some(c), _) => (Some(c.model.clone()), Gain { heldout_error_before: base.scores().1, ..c.gain }),
        (None, Some(c)) => (Some(c.model.clone()), c.gain),
        (None, None) => {
            (None, Gain { heldout_error_before: base.scores().1, heldout_error_after: base.scores().1 })
        }
    };
    if let (Some(t), Some((cid, f))) = (bending_track.as_mut(), &bend.fit) {
        t.predictions.push((cid.as_str().into(), f.simulated.clone()));
    }
    let final_fit = stretch.causes.last().map(|c| (&c.model.id, &stretch.fit));
    let predictions = std::iter::once(base_fit.prediction("base"))
        .chain(final_fit.map(|(id, f)| f.prediction(id)))
        .collect();
    let mut steps = stretch.steps;
    steps.extend(bend.step);
    Ok(Diagnosis {
        format: DIAGNOSIS_FORMAT.into(),
        version: DIAGNOSIS_VERSION,
        fabric: set.fabric.name.clone(),
        settings: *settings,
        cause: Cause { id, explanation: id.explanation().into(), evidence },
        causes,
        unexplained_remainder: remainder,
        gain,
        base,
        extended,
        candidates: first_step_candidates(&steps),
        steps,
        target_choices: phases.choices.clone(),
        noise,
        load_fitted: phases.load_fitted(),
        load_targets: phases.load_targets.clone(),
        unload_targets: phases.unload_targets.clone().unwrap_or_default(),
        predictions,
        bending: bending_track,
        extended_material: final_fit.map(|(_, f)| f.material),
        yarn_level: None,
        wall_time_s: started.elapsed().as_secs_f64(),
    })
}

/// A cause's held-out gain relative to the model it extends.
fn relative_gain(c: &ConfirmedCause) -> f64 {
    1.0 - c.gain.heldout_error_after / c.gain.heldout_error_before
}

/// The candidates of the first step of each track, in catalog order.
fn first_step_candidates(steps: &[Step]) -> Vec<ModelResult> {
    let first: Vec<&ModelResult> = steps
        .iter()
        .filter(|s| s.model == "base" || s.model == BENDING_BASE)
        .flat_map(|s| &s.candidates)
        .collect();
    CauseId::CANDIDATES
        .into_iter()
        .filter_map(|id| first.iter().find(|c| c.id == id.as_str()).map(|c| (*c).clone()))
        .collect()
}

/// The id of the bending track's base in steps.
const BENDING_BASE: &str = "bending base";

/// The stretch track explained step by step.
struct StretchExplanation {
    steps: Vec<Step>,
    causes: Vec<ConfirmedCause>,
    evidence: Vec<String>,
    /// The model of every confirmed cause (the base without one).
    fit: Fitted,
}

/// Explain the stretch track: fit every remaining candidate on top of the model so far, add the
/// one the rule passes with the lowest held-out error, and repeat until none passes or the
/// held-out error is at the noise.
fn explain_stretch(
    phases: &Phases,
    base_fit: &Fitted,
    base: &ModelResult,
    noise: f64,
    rule: &DecisionRule,
    lm: &LmSettings,
) -> StretchExplanation {
    let mut out = StretchExplanation {
        steps: Vec::new(),
        causes: Vec::new(),
        evidence: Vec::new(),
        fit: base_fit.clone(),
    };
    let mut model = base.clone();
    for step in 1..=STRETCH_CAUSES.len() {
        if step > 1 && rule.within_noise(model.scores().1, noise) {
            break;
        }
        let remaining = STRETCH_CAUSES.into_iter().filter(|id| out.causes.iter().all(|c| c.id != *id));
        let fits: Vec<(CauseId, Option<Fitted>)> =
            remaining.map(|id| (id, fit_candidate(id, phases, &out.fit, lm))).collect();
        let results: Vec<ModelResult> =
            fits.iter().map(|(id, f)| candidate_result(*id, f.as_ref(), phases, &out.fit)).collect();
        out.evidence.extend(rule.step_evidence(step, &model, noise, &results));
        let added = rule.best(&model, noise, &results).map(|c| id_of(&c.id));
        out.steps.push(Step { model: model.id.clone(), candidates: results, added });
        let Some((id, Some(fit))) = added.and_then(|a| fits.into_iter().find(|(id, _)| *id == a)) else {
            break;
        };
        let name = if step == 1 { id.as_str().to_string() } else { format!("{}+{}", model.id, id.as_str()) };
        let result = fit.result(&name, phases, None);
        out.evidence.push(format!("step {step}: added {}: the model is now {name}", id.as_str()));
        out.causes.push(ConfirmedCause {
            id,
            explanation: id.explanation().into(),
            step,
            gain: Gain { heldout_error_before: model.scores().1, heldout_error_after: result.scores().1 },
            model: result.clone(),
        });
        model = result;
        out.fit = fit;
    }
    out
}

/// A stretch candidate's result on top of `model`: fitted with its signature, else untestable
/// with the reason.
fn candidate_result(id: CauseId, fit: Option<&Fitted>, phases: &Phases, model: &Fitted) -> ModelResult {
    match fit {
        Some(f) => ModelResult {
            signature: signature::score(id, phases, model, f),
            ..f.result(id.as_str(), phases, None)
        },
        None if id == CauseId::FrictionHysteresis => {
            ModelResult::untestable(id, phases.unload_note().unwrap_or("no unloading data"))
        }
        None => {
            ModelResult::untestable(id, "the extended swatch has no equilibrium from the model fitted so far")
        }
    }
}

/// The catalog id named `name`.
fn id_of(name: &str) -> CauseId {
    CauseId::CANDIDATES.into_iter().find(|i| i.as_str() == name).expect("a catalog id")
}

/// The bending track explained: its candidates are alternatives on its base (one step).
struct BendingExplanation {
    step: Option<Step>,
    cause: Option<ConfirmedCause>,
    fit: Option<(CauseId, BendingFit)>,
    evidence: Vec<String>,
}

/// Explain the bending track (its base and noise, if the set has one): the candidates'
/// signature is the track's held-out readings; the passing one with the lowest held-out error
/// is a cause.
fn explain_bending(
    track: Option<(&ModelResult, f64)>,
    candidates: Vec<(CauseId, ModelResult, Option<BendingFit>)>,
    rule: &DecisionRule,
) -> BendingExplanation {
    let mut results = Vec::new();
    let mut fits = Vec::new();
    for (id, mut result, fit) in candidates {
        if let (Some((base, noise)), true) = (track, result.testable) {
            result.signature = Some(SignatureScore {
                measure: "held-out bending readings".into(),
                before: base.scores().1,
                after: result.scores().1,
                noise,
            });
        }
        fits.extend(fit.map(|f| (id, f)));
        results.push(result);
    }
    let Some((base, noise)) = track else {
        let step = (!results.is_empty()).then(|| Step {
            model: BENDING_BASE.into(),
            candidates: results,
            added: None,
        });
        return BendingExplanation { step, cause: None, fit: None, evidence: Vec::new() };
    };
    let evidence = rule.step_evidence(1, base, noise, &results);
    let best = rule.best(base, noise, &results).cloned();
    let added = best.as_ref().map(|c| id_of(&c.id));
    let cause = best.map(|model| ConfirmedCause {
        id: id_of(&model.id),
        explanation: id_of(&model.id).explanation().into(),
        step: 1,
        gain: Gain { heldout_error_before: base.scores().1, heldout_error_after: model.scores().1 },
        model,
    });
    let fit = added.and_then(|a| fits.into_iter().find(|(id, _)| *id == a));
    BendingExplanation {
        step: Some(Step { model: BENDING_BASE.into(), candidates: results, added }),
        cause,
        fit,
        evidence,
    }
}

/// The bases' lines of the evidence.
fn base_evidence(base: &ModelResult, noise: f64, bending: Option<&report::BendingTrack>) -> Vec<String> {
    let (base_error, base_heldout, _) = base.scores();
    let mut evidence = vec![format!(
        "base (anisotropic StVK): fitted error {base_error:.4}, held-out error {base_heldout:.4}, noise {noise:.4}"
    )];
    if let Some(t) = bending {
        let (e, h, _) = t.base.scores();
        evidence.push(format!(
            "bending base (isotropic flat hinges, {} bending readings): fitted error {e:.4}, held-out error {h:.4}, noise {:.4}",
            t.tests.len(),
            t.noise
        ));
    }
    evidence
}
