//! The bending track of a diagnosis: the set's bending tests ([`BendingTests`], the even
//! readings of each test kind, direction and face fitted, the odd held out), the isotropic flat
//! base and the bending candidates fitted by [`crate::shell::bending`], and the readings'
//! noise.

use nalgebra::{DMatrix, DVector};
use yarnhom_shell::StvkNeoHookean;

use super::report::{BendingTrack, ModelResult};
use super::settings::DiagnoseSettings;
use crate::cause::CauseId;
use crate::data::set::MeasurementSet;
use crate::experiments::bending_tests::{BendingTest, BendingTests, BendingTestsError};
use crate::optimize::akaike::criterion;
use crate::shell::bending::{BendingFit, BendingModel, fit_bending};

/// A bending model's result, from its fit.
fn bending_result(id: &str, fit: &BendingFit, tests: &BendingTests, note: Option<String>) -> ModelResult {
    let b = &fit.bending;
    let mut params = match fit.model {
        BendingModel::Anisotropic => vec![
            ("k_weft".to_string(), b.k_weft),
            ("k_bias".to_string(), b.k_bias),
            ("k_warp".to_string(), b.k_warp),
        ],
        _ => vec![("k".to_string(), b.k_weft)],
    };
    if fit.model == BendingModel::RestCurvature {
        params.extend([
            ("rest_curvature_weft".to_string(), b.rest_curvature_weft),
            ("rest_curvature_bias".to_string(), b.rest_curvature_bias),
            ("rest_curvature_warp".to_string(), b.rest_curvature_warp),
        ]);
    }
    let fitted = tests.residuals(&fit.simulated, true);
    ModelResult {
        id: id.into(),
        testable: true,
        note,
        params,
        parameter_count: fit.parameter_count,
        error: Some(fit.error),
        heldout_error: fit.heldout_error,
        criterion: Some(criterion(&fitted, fit.parameter_count)),
        signature: None,
    }
}

/// The noise of the bending readings (RMS normalized): the scatter about a cubic in the
/// abscissa, fitted to each test group (degree lowered to keep a residual degree of freedom),
/// pooled over the groups' degrees of freedom.
fn bending_noise(tests: &BendingTests) -> f64 {
    let normalized = tests.normalized_readings();
    let abscissa = tests.abscissas();
    let (mut squares, mut freedom) = (0.0, 0);
    for group in tests.groups() {
        let n = group.len();
        if n < 3 {
            continue;
        }
        let degree = 3.min(n - 2);
        let (lo, hi) = group
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &i| (a.min(abscissa[i]), b.max(abscissa[i])));
        let t = |i: usize| 2.0 * (abscissa[i] - lo) / (hi - lo).max(1e-300) - 1.0;
        let design = DMatrix::from_fn(n, degree + 1, |r, c| t(group[r]).powi(c as i32));
        let y = DVector::from_iterator(n, group.iter().map(|&i| normalized[i]));
        let Ok(coefficients) = design.clone().svd(true, true).solve(&y, 1e-12) else { continue };
        squares += (design * coefficients - y).norm_squared();
        freedom += n - degree - 1;
    }
    if freedom == 0 { 0.0 } else { (squares / freedom as f64).sqrt() }
}

/// The bending track: the base and the two bending candidates, or why it cannot run.
pub(super) struct BendingOutcome {
    pub track: Option<BendingTrack>,
    pub candidates: Vec<(CauseId, ModelResult, Option<BendingFit>)>,
}

/// The bending track of `set` with the base's `membrane`: the isotropic flat base and the two
/// bending candidates fitted from it, or every candidate untestable with the reason.
pub(super) fn bending_track(
    set: &MeasurementSet,
    membrane: &StvkNeoHookean,
    settings: &DiagnoseSettings,
) -> BendingOutcome {
    let ids = [CauseId::AnisotropicBending, CauseId::RestCurvature];
    let untestable_all = |note: &str| BendingOutcome {
        track: None,
        candidates: ids.iter().map(|&id| (id, ModelResult::untestable(id, note), None)).collect(),
    };
    let tests = match BendingTests::of_set(set, |k| k.is_multiple_of(2)) {
        Ok(t) => t,
        Err(BendingTestsError::NoTests) => return untestable_all("no bending tests in the set"),
        Err(e) => return untestable_all(&e.to_string()),
    };
    let Ok(base) = fit_bending(&tests, membrane, BendingModel::Isotropic, None, &settings.lm) else {
        return untestable_all("no isotropic bending stiffness gives the bending tests an equilibrium");
    };
    let has_cantilever = tests.tests.iter().any(|t| matches!(t, BendingTest::Cantilever { .. }));
    let candidates = ids
        .iter()
        .map(|&id| {
            let model = match id {
                CauseId::AnisotropicBending => BendingModel::Anisotropic,
                _ => BendingModel::RestCurvature,
            };
            if model == BendingModel::RestCurvature && !has_cantilever {
                let note = "rest curvature needs cantilever tests on both faces: a clamped pear loop cannot show it \
                            (the clamps fix the end tangents, so a uniform rest curvature does no work)";
                return (id, ModelResult::untestable(id, note), None);
            }
            match fit_bending(&tests, membrane, model, Some(&base.bending), &settings.lm) {
                Ok(fit) => (id, bending_result(id.as_str(), &fit, &tests, None), Some(fit)),
                Err(e) => (id, ModelResult::untestable(id, &e.to_string()), None),
            }
        })
        .collect();
    let track = BendingTrack {
        base: bending_result(
            "bending-base",
            &base,
            &tests,
            Some("isotropic flat hinge bending (6.4)".into()),
        ),
        noise: bending_noise(&tests),
        tests: tests.tests.clone(),
        measured: tests.measured.clone(),
        fitted: tests.fitted.clone(),
        predictions: vec![("bending-base".into(), base.simulated.clone())],
    };
    BendingOutcome { track: Some(track), candidates }
}
