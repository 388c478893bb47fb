//! Model-discrepancy diagnosis: what the base model gets wrong about a measured fabric, which
//! cause from a fixed catalog ([`crate::cause`]) explains it, and how much an extension for
//! that cause gains on points it was not fitted to.
//!
//! The screening runs at the shell level, on the clamped swatches of the stretch tests
//! ([`crate::shell::membrane`]), in stages ([`diagnose`]):
//!
//! 1. Targets and split ([`stretch`]): `n` stretches per direction (default 10) from the
//!    loading readings; the even ones are fitted, the odd ones held out. Unloading readings,
//!    where the set has enough, give unloading targets split the same way.
//! 2. Base fit: plain anisotropic StVK (no area terms, no stiffening; unloading predicted as
//!    loading), fitted by simulation in the loop.
//! 3. Candidate fits, each a nested extension of the base, fitted from it:
//!    `area-preservation` (the Neo-Hookean area terms of (6.1)), `biphasic-stretch`
//!    ([`yarnhom_shell::Stiffening`]: stiffening past an onset strain), `friction-hysteresis`
//!    (unloading force `(1 - h)` times the loading force at the same stretch, `h` fitted on the
//!    even unloading targets), `two-phase-contact` (jamming,
//!    [`StvkNeoHookean::jamming`](yarnhom_shell::StvkNeoHookean::jamming): the compression
//!    across the pull stiffens past an onset, the shell-level trace of the soft then hard yarn
//!    contact of (6.7), as stiffening is of the biphasic yarn stretch (6.5)). The bending causes
//!    form a second track ([`bending`]) on the set's bending tests (the even readings of each
//!    test, direction and face fitted, the odd held out): base isotropic flat bending (one
//!    `k_θ`), `anisotropic-bending` (`k_θ` per direction) and `rest-curvature` (one `k_θ` and a
//!    rest curvature per direction, seen only by the cantilever tests on both faces); without
//!    the tests (or the areal density) they are not testable, with the reason.
//! 4. Choice: the [`DecisionRule`] (held-out error against the track's
//!    base and noise, the Akaike criterion, the share of the discrepancy fixed; `none` and
//!    `unexplained` when no candidate passes) names the cause.
//! 5. Evidence: the numbers behind the choice, worded from the same rule.
//! 6. Confirmation (separate, [`confirm`], run by `calibrate diagnose` unless `--budget
//!    quick`): a cause with a mechanism in the yarn model is confirmed on the periodic tile by
//!    nested yarn-level fits to the extended shell's uniform targets
//!    ([`Diagnosis::extended_material`]); the result
//!    goes to [`Diagnosis::yarn_level`].
//!
//! Errors are RMS values of the normalized residuals of (6.2) (force over the direction's mean
//! force, compression over its mean compression), pooled over the fitted or the held-out
//! targets; the noise is the pooled standard error of the targets (their readings' scatter
//! about the local line over the square root of their count). On the bending track the errors
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
pub mod stretch;

use std::time::Instant;

use bending::bending_track;
use report::{Cause, DIAGNOSIS_FORMAT, DIAGNOSIS_VERSION, Diagnosis, ModelResult};
use rule::{DecisionRule, Tracks};
use settings::DiagnoseSettings;
use stretch::{Fitted, Phases, fit_base, fit_candidate, noise_level};

use crate::cause::CauseId;
use crate::data::set::MeasurementSet;
use crate::optimize::lm::LmSettings;
use crate::shell::bending::BendingFit;
use crate::shell::membrane::ShellFitError;

/// Diagnose `set`: targets and split, base fit, candidate fits, choice and evidence by the
/// default [`DecisionRule`], and the report (without its yarn-level step, [`confirm`]).
pub fn diagnose(set: &MeasurementSet, settings: &DiagnoseSettings) -> Result<Diagnosis, ShellFitError> {
    let started = Instant::now();
    let phases = Phases::of_set(set, settings)?;
    let noise = noise_level(&phases);
    let base_fit = fit_base(&phases, &settings.lm)?;
    let base = base_fit.result("base", &phases, Some("anisotropic StVK, unloading as loading".into()));
    let bending = bending_track(set, &base_fit.material, settings);
    let screened = fit_candidates(&phases, &base_fit, bending.candidates, &settings.lm);
    let rule = DecisionRule::default();
    let tracks = Tracks { base: &base, noise, bending: bending.track.as_ref() };
    let choice = rule.choose(&tracks, &screened.results);
    let cause = Cause {
        id: choice.cause,
        explanation: choice.cause.explanation().into(),
        evidence: rule.evidence(&tracks, &screened.results, &choice),
    };
    let (gain, extended) = (choice.gain(&tracks), choice.extended.cloned());
    let id = cause.id;
    let mut bending_track = bending.track;
    if let (Some(t), Some((cid, f))) =
        (bending_track.as_mut(), screened.bending_fits.iter().find(|(c, _)| *c == id))
    {
        t.predictions.push((cid.as_str().into(), f.simulated.clone()));
    }
    let chosen = screened.fits.iter().find(|(c, _)| *c == id);
    let predictions = std::iter::once(base_fit.prediction("base"))
        .chain(chosen.map(|(cid, f)| f.prediction(cid.as_str())))
        .collect();
    Ok(Diagnosis {
        format: DIAGNOSIS_FORMAT.into(),
        version: DIAGNOSIS_VERSION,
        fabric: set.fabric.name.clone(),
        settings: *settings,
        cause,
        gain,
        base,
        extended,
        candidates: screened.results,
        noise,
        load_fitted: phases.load_fitted(),
        load_targets: phases.load_targets,
        unload_targets: phases.unload_targets.unwrap_or_default(),
        predictions,
        bending: bending_track,
        extended_material: chosen.map(|(_, f)| f.material),
        yarn_level: None,
        wall_time_s: started.elapsed().as_secs_f64(),
    })
}

/// Every candidate of the catalog, fitted or untestable, in catalog order.
struct Screened {
    /// Their results.
    results: Vec<ModelResult>,
    /// The fitted stretch-track candidates.
    fits: Vec<(CauseId, Fitted)>,
    /// The fitted bending-track candidates.
    bending_fits: Vec<(CauseId, BendingFit)>,
}

/// The candidate fits: the bending track's as `bending_track` made them, the stretch track's
/// fitted nested from `base` now.
fn fit_candidates(
    phases: &Phases,
    base: &Fitted,
    mut bending: Vec<(CauseId, ModelResult, Option<BendingFit>)>,
    lm: &LmSettings,
) -> Screened {
    let mut screened = Screened { results: Vec::new(), fits: Vec::new(), bending_fits: Vec::new() };
    for id in CauseId::CANDIDATES {
        if let Some(k) = bending.iter().position(|(c, _, _)| *c == id) {
            let (_, result, fit) = bending.swap_remove(k);
            screened.bending_fits.extend(fit.map(|f| (id, f)));
            screened.results.push(result);
            continue;
        }
        let result = match (id, fit_candidate(id, phases, base, lm)) {
            (_, Some(f)) => {
                let r = f.result(id.as_str(), phases, None);
                screened.fits.push((id, f));
                r
            }
            (CauseId::FrictionHysteresis, None) => {
                ModelResult::untestable(id, phases.unload_note().unwrap_or("no unloading data"))
            }
            (_, None) => {
                ModelResult::untestable(id, "the extended swatch has no equilibrium from the base fit")
            }
        };
        screened.results.push(result);
    }
    screened
}
