//! Model-discrepancy diagnosis: what the base model gets wrong about a measured fabric, which
//! cause from a fixed catalog explains it, and how much an extension for that cause gains on
//! points it was not fitted to.
//!
//! The screening runs at the shell level, on the clamped swatches of the stretch tests
//! ([`crate::shell_fit`]):
//!
//! 1. Targets: `n` stretches per direction (default 10) from the loading readings; the even
//!    ones are fitted, the odd ones held out. Unloading readings, where the set has enough, give
//!    unloading targets split the same way.
//! 2. Base: plain anisotropic StVK (no area terms, no stiffening; unloading predicted as
//!    loading), fitted by simulation in the loop.
//! 3. Candidates, each a nested extension of the base, fitted from it:
//!    `area-preservation` (the Neo-Hookean area terms of (6.1)), `biphasic-stretch`
//!    ([`yarnhom_shell::Stiffening`]: stiffening past an onset strain), `friction-hysteresis`
//!    (unloading force `(1 - h)` times the loading force at the same stretch, `h` fitted on the
//!    even unloading targets), `two-phase-contact` (jamming, [`StvkNeoHookean::jamming`]: the
//!    compression across the pull stiffens past an onset, the shell-level trace of the soft
//!    then hard yarn contact of (6.7), as stiffening is of the biphasic yarn stretch (6.5)).
//!    The bending causes form a second track on the set's bending tests
//!    ([`crate::bending_fit`], the even readings of each test, direction and face fitted, the
//!    odd held out): base isotropic flat bending (one `k_θ`), `anisotropic-bending` (`k_θ` per
//!    direction) and `rest-curvature` (one `k_θ` and a rest curvature per direction, seen only
//!    by the cantilever tests on both faces); without the tests (or the areal density) they are
//!    not testable, with the reason.
//! 4. Choice: a candidate is significant when its held-out error is below 75% of its track's
//!    base's and below it by more than twice the track's noise, and its Akaike criterion
//!    `n ln(RSS/n) + 2k` on the fitted targets is lower by more than 4; it is accepted when it
//!    also fixes the discrepancy: it leaves at most half ([`MAX_EXCESS_LEFT`]) of the base's
//!    held-out error above the noise (a significant candidate that leaves more is reported as
//!    a partial explanation, not as the cause). The accepted candidate
//!    with the lowest held-out error relative to its base is the cause. Without one, the cause
//!    is `none` when every track's base held-out error is within `max(3 x noise, 3%)`, else
//!    `unexplained`.
//! 5. Confirmation (separate, [`crate::yarn_confirm`], run by `calibrate diagnose` unless
//!    `--budget quick`): a cause with a mechanism in the yarn model is confirmed on the
//!    periodic tile by nested yarn-level fits to the extended shell's uniform targets
//!    ([`Diagnosis::extended_material`]); the result goes to [`Diagnosis::yarn_level`].
//!
//! Errors are RMS values of the normalized residuals of (6.2) (force over the direction's mean
//! force, compression over its mean compression), pooled over the fitted or the held-out
//! targets; the noise is the pooled standard error of the targets (their readings' scatter
//! about the local line over the square root of their count). On the bending track the errors
//! are those of [`crate::bending_fit`] (each reading over its group's mean), and the noise is
//! the readings' scatter about a cubic in the abscissa fitted to each test group, pooled
//! over the residual degrees of freedom (an upper bound where a curve is not cubic).

use std::time::Instant;

use nalgebra::{DMatrix, DVector};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use yarnhom_shell::{Stiffening, StvkNeoHookean};

use crate::bending_fit::{BendingFit, BendingFitError, BendingModel, BendingTest, BendingTests, fit_bending};
use crate::lm::LmSettings;
use crate::measure::{MeasurementSet, Phase};
use crate::shell_fit::{
    DirectionData, Problem, ShellFitError, Terms, fit_membrane, forces_and_compressions, rms,
    starting_material,
};
use crate::swatch::SimulatedReading;
use crate::targets::{Target, TargetPlan, targets};
use crate::yarn_confirm::YarnLevel;

/// The catalog of causes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum CauseId {
    /// The yarn stiffens past an onset strain (e.g. plated yarns).
    BiphasicStretch,
    /// Soft then hard yarn compression.
    TwoPhaseContact,
    /// Stronger transverse contraction than the base shell can give.
    AreaPreservation,
    /// The fabric curls: an offset bending response.
    RestCurvature,
    /// Bending stiffness differs by direction.
    AnisotropicBending,
    /// Loading and unloading curves differ.
    FrictionHysteresis,
    /// Nothing significant at the noise level.
    None,
    /// Structured residuals that no candidate fixes.
    Unexplained,
}

impl CauseId {
    /// The id as written in reports.
    pub fn as_str(self) -> &'static str {
        match self {
            CauseId::BiphasicStretch => "biphasic-stretch",
            CauseId::TwoPhaseContact => "two-phase-contact",
            CauseId::AreaPreservation => "area-preservation",
            CauseId::RestCurvature => "rest-curvature",
            CauseId::AnisotropicBending => "anisotropic-bending",
            CauseId::FrictionHysteresis => "friction-hysteresis",
            CauseId::None => "none",
            CauseId::Unexplained => "unexplained",
        }
    }

    /// What the cause means physically.
    pub fn explanation(self) -> &'static str {
        match self {
            CauseId::BiphasicStretch => {
                "the fabric stiffens past an onset strain, as yarns do whose fibres or plies straighten and then \
                 stretch (plated yarns, Sec. 6.4.1): the force grows faster at large stretch than one \
                 strain-independent membrane allows"
            }
            CauseId::TwoPhaseContact => {
                "the fabric contracts freely across the pull and then jams: its yarn contacts are soft and then \
                 hard under compression (two-phase contact, (6.7)), so the transverse contraction stops growing \
                 once the soft outer layers are pressed onto the hard cores, and the force rises with it"
            }
            CauseId::AreaPreservation => {
                "the fabric contracts across the pull more than a plain anisotropic StVK membrane can while \
                 matching the force: it preserves area (the Neo-Hookean terms of (6.1))"
            }
            CauseId::RestCurvature => "the fabric curls at rest: its bending response is offset",
            CauseId::AnisotropicBending => "the bending stiffness differs between directions",
            CauseId::FrictionHysteresis => {
                "unloading takes less force than loading at the same stretch: inter-yarn friction dissipates \
                 energy (hysteresis, Sec. 6.2.3)"
            }
            CauseId::None => "the base model reproduces the held-out measurements within their noise",
            CauseId::Unexplained => {
                "the base model misses the held-out measurements by more than their noise, and no candidate \
                 in the catalog fixes it"
            }
        }
    }

    /// The candidates screened, in report order.
    pub const CANDIDATES: [CauseId; 6] = [
        CauseId::AreaPreservation,
        CauseId::BiphasicStretch,
        CauseId::FrictionHysteresis,
        CauseId::TwoPhaseContact,
        CauseId::RestCurvature,
        CauseId::AnisotropicBending,
    ];
}

/// How to diagnose.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct DiagnoseSettings {
    /// Targets per direction (even ones fitted, odd ones held out).
    pub targets_per_direction: usize,
    /// The stretch range ends where the measured force reaches this (N).
    pub force_cap_n: f64,
    /// Mesh edge length of the simulated swatches (m).
    pub spacing_m: f64,
    /// The simulation-in-the-loop iterations per model.
    pub lm: LmSettings,
}

impl Default for DiagnoseSettings {
    fn default() -> Self {
        Self {
            targets_per_direction: 10,
            force_cap_n: 5.0,
            spacing_m: 0.005,
            lm: LmSettings { max_iterations: 30, ..LmSettings::default() },
        }
    }
}

/// One model's fit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct ModelResult {
    /// `base` or a cause id.
    pub id: String,
    /// Whether it could be tested on this set.
    pub testable: bool,
    /// Why not, or what was done.
    pub note: Option<String>,
    /// The fitted parameters by name.
    pub params: Vec<(String, f64)>,
    /// Parameters fitted.
    pub parameter_count: usize,
    /// RMS normalized residual on the fitted targets (absent when not testable).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error: Option<f64>,
    /// RMS normalized residual on the held-out targets (absent when not testable).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub heldout_error: Option<f64>,
    /// Akaike criterion on the fitted targets, `n ln(RSS/n) + 2k` (absent when not testable).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub criterion: Option<f64>,
}

/// The cause named.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct Cause {
    /// Catalog id.
    pub id: CauseId,
    /// What it means.
    pub explanation: String,
    /// The numbers behind the choice.
    pub evidence: Vec<String>,
}

/// The held-out gain of the extension.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct Gain {
    /// The held-out error of the chosen extension's base (the bending base for a bending
    /// cause, else the stretch base).
    pub heldout_error_before: f64,
    /// The chosen model's held-out error (the base's when the cause is `none`/`unexplained`).
    pub heldout_error_after: f64,
}

/// A candidate fixes its track's discrepancy only if it leaves at most this fraction of the
/// base's held-out error above the noise.
pub const MAX_EXCESS_LEFT: f64 = 0.5;

/// The fraction of the base's held-out error above `noise` that a candidate's held-out error
/// leaves (0: down to the noise; 1: nothing removed).
fn excess_fraction_left(heldout: f64, base_heldout: f64, noise: f64) -> f64 {
    (heldout - noise).max(0.0) / (base_heldout - noise).max(1e-300)
}

/// A model's predictions at every loading (and unloading) target, for figures.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct Prediction {
    /// `base` or a cause id.
    pub id: String,
    /// At the loading targets, in target order.
    pub load: Vec<SimulatedReading>,
    /// At the unloading targets, in target order.
    pub unload: Vec<SimulatedReading>,
}

/// `report.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct Diagnosis {
    /// Format tag, `yarnhom.diagnosis`.
    pub format: String,
    /// Layout version.
    pub version: u32,
    /// The fabric's name.
    pub fabric: String,
    /// The settings used.
    pub settings: DiagnoseSettings,
    /// The cause.
    pub cause: Cause,
    /// The base model.
    pub base: ModelResult,
    /// The chosen extension, if a candidate was accepted.
    pub extended: Option<ModelResult>,
    /// Held-out errors before and after.
    pub gain: Gain,
    /// Every candidate of the catalog.
    pub candidates: Vec<ModelResult>,
    /// The noise level of the held-out targets (RMS normalized standard error).
    pub noise: f64,
    /// Loading targets.
    pub load_targets: Vec<Target>,
    /// Unloading targets (empty when the set has too few unloading readings).
    pub unload_targets: Vec<Target>,
    /// Whether each loading target was fitted (else held out).
    pub load_fitted: Vec<bool>,
    /// Predictions of the base and of the chosen extension.
    pub predictions: Vec<Prediction>,
    /// The bending track, when the set has bending tests.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bending: Option<BendingTrack>,
    /// The fitted membrane of the chosen stretch-track extension (absent for `none`,
    /// `unexplained` and the bending causes): a material to simulate, and the source of the
    /// yarn-level confirmation's targets.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub extended_material: Option<StvkNeoHookean>,
    /// The yarn-level confirmation of the cause ([`crate::yarn_confirm`]); absent until it is
    /// run.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub yarn_level: Option<YarnLevel>,
    /// Wall time (s).
    pub wall_time_s: f64,
}

/// The bending track of a diagnosis.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct BendingTrack {
    /// Base: isotropic flat bending.
    pub base: ModelResult,
    /// Noise level of the readings (RMS normalized, difference-based).
    pub noise: f64,
    /// The tests, in file order (pear loops, then cantilevers).
    pub tests: Vec<BendingTest>,
    /// The measured readings.
    pub measured: Vec<f64>,
    /// Whether each reading was fitted (else held out).
    pub fitted: Vec<bool>,
    /// Simulated readings of the base and of the chosen bending extension (if one is chosen).
    pub predictions: Vec<(String, Vec<f64>)>,
}

/// Format tag of [`Diagnosis`] files.
pub const DIAGNOSIS_FORMAT: &str = "yarnhom.diagnosis";
/// Layout version of [`Diagnosis`] files (v3 adds `extended_material` and `yarn_level`).
pub const DIAGNOSIS_VERSION: u32 = 3;

/// The JSON Schema of `report.json`.
pub fn diagnosis_schema() -> schemars::Schema {
    schemars::schema_for!(Diagnosis)
}

/// The tests of a diagnosis: the loading and unloading problems, each with its held-out targets.
struct Phases {
    load: Problem,
    unload: Option<Problem>,
}

/// Residuals of a model's predictions: `(fitted, held out)`, pooled over both phases.
fn residuals(
    phases: &Phases,
    load: &[Vec<SimulatedReading>],
    unload: &[Vec<SimulatedReading>],
    unload_factor: f64,
) -> (Vec<f64>, Vec<f64>) {
    let mut fitted = Vec::new();
    let mut heldout = Vec::new();
    let mut add = |problem: &Problem, readings: &[Vec<SimulatedReading>], factor: f64| {
        for (d, r) in problem.data.iter().zip(readings) {
            let (f, c) = forces_and_compressions(r);
            let f: Vec<f64> = f.iter().map(|x| x * factor).collect();
            fitted.extend(d.residuals(&f, &c, true));
            heldout.extend(d.residuals(&f, &c, false));
        }
    };
    add(&phases.load, load, 1.0);
    if let Some(u) = &phases.unload {
        add(u, unload, unload_factor);
    }
    (fitted, heldout)
}

/// The Akaike criterion of residuals `r` of a model with `parameters` fitted parameters,
/// `n ln(RSS/n) + 2k`.
pub(crate) fn criterion(r: &[f64], parameters: usize) -> f64 {
    let n = r.len().max(1) as f64;
    n * (r.iter().map(|x| x * x).sum::<f64>() / n).max(1e-300).ln() + 2.0 * parameters as f64
}

/// A fitted model: its material, unloading factor and predictions.
struct Fitted {
    material: StvkNeoHookean,
    unload_factor: f64,
    parameter_count: usize,
    load: Vec<Vec<SimulatedReading>>,
    unload: Vec<Vec<SimulatedReading>>,
}

impl Fitted {
    fn result(&self, id: &str, phases: &Phases, note: Option<String>) -> ModelResult {
        let (fitted, heldout) = residuals(phases, &self.load, &self.unload, self.unload_factor);
        let m = &self.material;
        let mut params = vec![
            ("k_xx".to_string(), m.k_xx),
            ("k_xy".to_string(), m.k_xy),
            ("k_yy".to_string(), m.k_yy),
            ("k_ss".to_string(), m.k_ss),
        ];
        if m.k_n1 > 0.0 || m.k_n2 > 0.0 {
            params.extend([("k_n1".to_string(), m.k_n1), ("k_n2".to_string(), m.k_n2)]);
        }
        if let Some(b) = m.stiffening {
            params.extend([
                ("stiffening_k_weft".to_string(), b.k_weft),
                ("stiffening_k_warp".to_string(), b.k_warp),
                ("stiffening_onset".to_string(), b.onset),
            ]);
        }
        if let Some(b) = m.jamming {
            params.extend([
                ("jamming_k_weft".to_string(), b.k_weft),
                ("jamming_k_warp".to_string(), b.k_warp),
                ("jamming_onset".to_string(), b.onset),
            ]);
        }
        if self.unload_factor != 1.0 {
            params.push(("hysteresis_h".to_string(), 1.0 - self.unload_factor));
        }
        ModelResult {
            id: id.into(),
            testable: true,
            note,
            params,
            parameter_count: self.parameter_count,
            error: Some(rms(&fitted)),
            heldout_error: Some(rms(&heldout)),
            criterion: Some(criterion(&fitted, self.parameter_count)),
        }
    }

    fn prediction(&self, id: &str) -> Prediction {
        let scale = |r: &SimulatedReading| SimulatedReading { force_n: r.force_n * self.unload_factor, ..*r };
        Prediction {
            id: id.into(),
            load: self.load.iter().flatten().copied().collect(),
            unload: self.unload.iter().flatten().map(scale).collect(),
        }
    }
}

/// Fit the membrane with `terms` from `start`, simulating both phases.
fn fit_model(
    phases: &Phases,
    terms: Terms,
    start: StvkNeoHookean,
    lm: &LmSettings,
) -> Result<Fitted, ShellFitError> {
    let fitted = fit_membrane(&phases.load, terms, Some(start), lm)?;
    let (material, parameter_count) = (fitted.material, fitted.optimizer.params.len());
    let load = phases.load.simulate(&material).ok_or(ShellFitError::Start(material))?;
    let unload = match &phases.unload {
        Some(u) => u.simulate(&material).ok_or(ShellFitError::Start(material))?,
        None => Vec::new(),
    };
    Ok(Fitted { material, unload_factor: 1.0, parameter_count, load, unload })
}

/// The unloading factor `1 - h` fitting the even unloading targets' forces by least squares.
fn hysteresis_factor(phases: &Phases, unload: &[Vec<SimulatedReading>]) -> Option<f64> {
    let u = phases.unload.as_ref()?;
    let (mut num, mut den) = (0.0, 0.0);
    for (d, r) in u.data.iter().zip(unload) {
        for ((t, reading), fitted) in d.targets.iter().zip(r).zip(&d.fitted) {
            if *fitted {
                num += reading.force_n * t.force_n;
                den += reading.force_n * reading.force_n;
            }
        }
    }
    (den > 0.0).then(|| num / den)
}

fn untestable(id: CauseId, note: &str) -> ModelResult {
    ModelResult {
        id: id.as_str().into(),
        testable: false,
        note: Some(note.into()),
        params: Vec::new(),
        parameter_count: 0,
        error: None,
        heldout_error: None,
        criterion: None,
    }
}

/// The noise level: the pooled RMS of the held-out targets' normalized standard errors.
fn noise_level(phases: &Phases) -> f64 {
    let mut errors = Vec::new();
    for problem in std::iter::once(&phases.load).chain(phases.unload.as_ref()) {
        for d in &problem.data {
            let forces: Vec<f64> =
                d.targets.iter().map(|t| t.force_n + t.force_noise_n / (t.readings as f64).sqrt()).collect();
            let compressions: Vec<f64> = d
                .targets
                .iter()
                .map(|t| {
                    t.compression.unwrap_or(0.0)
                        + t.compression_noise.unwrap_or(0.0) / (t.readings as f64).sqrt()
                })
                .collect();
            errors.extend(d.residuals(&forces, &compressions, false));
        }
    }
    rms(&errors)
}

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
struct BendingOutcome {
    track: Option<BendingTrack>,
    candidates: Vec<(CauseId, ModelResult, Option<BendingFit>)>,
}

fn bending_track(
    set: &MeasurementSet,
    membrane: &StvkNeoHookean,
    settings: &DiagnoseSettings,
) -> BendingOutcome {
    let ids = [CauseId::AnisotropicBending, CauseId::RestCurvature];
    let untestable_all = |note: &str| BendingOutcome {
        track: None,
        candidates: ids.iter().map(|&id| (id, untestable(id, note), None)).collect(),
    };
    let tests = match BendingTests::of_set(set, |k| k.is_multiple_of(2)) {
        Ok(t) => t,
        Err(BendingFitError::NoTests) => return untestable_all("no bending tests in the set"),
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
                return (id, untestable(id, note), None);
            }
            match fit_bending(&tests, membrane, model, Some(&base.bending), &settings.lm) {
                Ok(fit) => (id, bending_result(id.as_str(), &fit, &tests, None), Some(fit)),
                Err(e) => (id, untestable(id, &e.to_string()), None),
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

/// Diagnose `set`.
pub fn diagnose(set: &MeasurementSet, settings: &DiagnoseSettings) -> Result<Diagnosis, ShellFitError> {
    let started = Instant::now();
    let plan = TargetPlan {
        per_direction: settings.targets_per_direction,
        force_cap_n: settings.force_cap_n,
        phase: Phase::Load,
    };
    let load_targets = targets(set, &plan)?;
    let even = |k: usize| k.is_multiple_of(2);
    let unload_targets = targets(set, &TargetPlan { phase: Phase::Unload, ..plan }).ok();
    let unload_note = match &unload_targets {
        Some(_) => None,
        None => Some("too few unloading readings to test".to_string()),
    };
    let phases = Phases {
        load: Problem::new(DirectionData::group(set, &load_targets, even), settings.spacing_m),
        unload: unload_targets
            .as_ref()
            .map(|t| Problem::new(DirectionData::group(set, t, even), settings.spacing_m)),
    };
    let noise = noise_level(&phases);

    let base_terms = Terms::default();
    let base_fit =
        fit_model(&phases, base_terms, starting_material(&phases.load.data, base_terms), &settings.lm)?;
    let base = base_fit.result("base", &phases, Some("anisotropic StVK, unloading as loading".into()));

    let mut bending = bending_track(set, &base_fit.material, settings);
    let mut fits: Vec<(CauseId, Fitted)> = Vec::new();
    let mut bending_fits: Vec<(CauseId, BendingFit)> = Vec::new();
    let mut candidates = Vec::new();
    for id in CauseId::CANDIDATES {
        if let Some(k) = bending.candidates.iter().position(|(c, _, _)| *c == id) {
            let (_, result, fit) = bending.candidates.swap_remove(k);
            bending_fits.extend(fit.map(|f| (id, f)));
            candidates.push(result);
            continue;
        }
        let extended = match id {
            CauseId::AreaPreservation | CauseId::BiphasicStretch | CauseId::TwoPhaseContact => {
                let terms = Terms {
                    area: id == CauseId::AreaPreservation,
                    stiffening: id == CauseId::BiphasicStretch,
                    jamming: id == CauseId::TwoPhaseContact,
                };
                // Nested: start at the base's fit with the new terms a thousandth of their
                // usual starting size, so the extension starts where the base ended.
                let seed = starting_material(&phases.load.data, terms);
                let start = StvkNeoHookean {
                    k_n1: 1e-3 * seed.k_n1,
                    k_n2: 1e-3 * seed.k_n2,
                    stiffening: seed.stiffening.map(Stiffening::faint),
                    jamming: seed.jamming.map(Stiffening::faint),
                    ..base_fit.material
                };
                fit_model(&phases, terms, start, &settings.lm).ok()
            }
            CauseId::FrictionHysteresis => {
                hysteresis_factor(&phases, &base_fit.unload).map(|factor| Fitted {
                    material: base_fit.material,
                    unload_factor: factor,
                    parameter_count: base_fit.parameter_count + 1,
                    load: base_fit.load.clone(),
                    unload: base_fit.unload.clone(),
                })
            }
            _ => None,
        };
        let result = match (id, extended) {
            (_, Some(f)) => {
                let r = f.result(id.as_str(), &phases, None);
                fits.push((id, f));
                r
            }
            (CauseId::FrictionHysteresis, None) => {
                untestable(id, unload_note.as_deref().unwrap_or("no unloading data"))
            }
            (_, None) => untestable(id, "the extended swatch has no equilibrium from the base fit"),
        };
        candidates.push(result);
    }

    // The scores of a tested model (the base and every testable candidate have them).
    let score = |m: &ModelResult| {
        (m.error.unwrap_or(f64::NAN), m.heldout_error.unwrap_or(f64::NAN), m.criterion.unwrap_or(f64::NAN))
    };
    let is_bending =
        |id: &str| id == CauseId::AnisotropicBending.as_str() || id == CauseId::RestCurvature.as_str();
    // A candidate's track: its base and noise.
    let track_of = |c: &ModelResult| match (&bending.track, is_bending(&c.id)) {
        (Some(t), true) => (&t.base, t.noise),
        _ => (&base, noise),
    };
    let (base_error, base_heldout, _) = score(&base);
    // Significant: the held-out and Akaike tests. Fixing: significant, and at most half of the
    // base's held-out error above the noise left.
    let significant: Vec<&ModelResult> = candidates
        .iter()
        .filter(|c| c.testable)
        .filter(|c| {
            let (track_base, track_noise) = track_of(c);
            let (_, heldout, criterion) = score(c);
            let (_, base_heldout, base_criterion) = score(track_base);
            heldout < 0.75 * base_heldout
                && heldout < base_heldout - 2.0 * track_noise
                && criterion < base_criterion - 4.0
        })
        .collect();
    let excess_left = |c: &ModelResult| {
        let (track_base, track_noise) = track_of(c);
        excess_fraction_left(score(c).1, score(track_base).1, track_noise)
    };
    let passing: Vec<&ModelResult> =
        significant.iter().copied().filter(|c| excess_left(c) <= MAX_EXCESS_LEFT).collect();
    let relative = |c: &ModelResult| score(c).1 / score(track_of(c).0).1;
    let accepted = passing.iter().min_by(|a, b| relative(a).total_cmp(&relative(b))).copied();
    let mut evidence = vec![format!(
        "base (anisotropic StVK): fitted error {base_error:.4}, held-out error {base_heldout:.4}, noise {noise:.4}"
    )];
    if let Some(t) = &bending.track {
        let (e, h, _) = score(&t.base);
        evidence.push(format!(
            "bending base (isotropic flat hinges, {} bending readings): fitted error {e:.4}, held-out error {h:.4}, noise {:.4}",
            t.tests.len(),
            t.noise
        ));
    }
    for c in candidates.iter().filter(|c| c.testable) {
        let (_, heldout, criterion) = score(c);
        let (track_base, _) = track_of(c);
        evidence.push(format!(
            "{}: held-out error {heldout:.4} ({:+.1}% vs {}), criterion {:+.1} vs {}",
            c.id,
            100.0 * (relative(c) - 1.0),
            track_base.id,
            criterion - score(track_base).2,
            track_base.id
        ));
    }
    let bases_within_noise = std::iter::once((score(&base).1, noise))
        .chain(bending.track.iter().map(|t| (score(&t.base).1, t.noise)))
        .all(|(heldout, noise)| heldout <= (3.0 * noise).max(0.03));
    let (id, extended) = match accepted {
        Some(c) => {
            let id = CauseId::CANDIDATES.into_iter().find(|i| i.as_str() == c.id).expect("a catalog id");
            (id, Some(c.clone()))
        }
        None if bases_within_noise => (CauseId::None, None),
        None => (CauseId::Unexplained, None),
    };
    for c in significant.iter().filter(|c| excess_left(c) > MAX_EXCESS_LEFT) {
        evidence.push(format!(
            "{}: significant, but it leaves {:.0}% of its base's held-out error above the noise (more than {:.0}%): a partial explanation",
            c.id,
            100.0 * excess_left(c),
            100.0 * MAX_EXCESS_LEFT
        ));
    }
    evidence.push(match id {
        CauseId::None => "no candidate passes the tests (held-out error below 75% of its base's, by more than 2 x noise, criterion lower by 4, at most half of the base's held-out error above the noise left), and every base's held-out error is within max(3 x noise, 0.03) of its track".to_string(),
        CauseId::Unexplained => "no candidate passes the tests, and a base's held-out error exceeds max(3 x noise, 0.03) of its track".to_string(),
        _ => format!(
            "chosen: {} (lowest held-out error relative to its base among the candidates that pass the tests)",
            id.as_str()
        ),
    });
    let also: Vec<&str> = passing.iter().map(|c| c.id.as_str()).filter(|c| *c != id.as_str()).collect();
    if !also.is_empty() {
        evidence.push(format!(
            "also passing: {} (a combination may explain more; only single causes are screened)",
            also.join(", ")
        ));
    }
    let heldout_before = match &extended {
        Some(c) => score(track_of(c).0).1,
        None => base_heldout,
    };
    let mut bending_track = bending.track;
    if let (Some(t), Some((cid, f))) = (bending_track.as_mut(), bending_fits.iter().find(|(c, _)| *c == id)) {
        t.predictions.push((cid.as_str().into(), f.simulated.clone()));
    }
    let mut predictions = vec![base_fit.prediction("base")];
    let chosen = fits.iter().find(|(c, _)| *c == id);
    if let Some((cid, f)) = chosen {
        predictions.push(f.prediction(cid.as_str()));
    }
    let load_fitted = phases.load.data.iter().flat_map(|d| d.fitted.iter().copied()).collect();
    Ok(Diagnosis {
        format: DIAGNOSIS_FORMAT.into(),
        version: DIAGNOSIS_VERSION,
        fabric: set.fabric.name.clone(),
        settings: *settings,
        cause: Cause { id, explanation: id.explanation().into(), evidence },
        gain: Gain {
            heldout_error_before: heldout_before,
            heldout_error_after: extended.as_ref().map_or(base_heldout, |e| score(e).1),
        },
        base,
        extended,
        candidates,
        noise,
        load_targets,
        unload_targets: unload_targets.unwrap_or_default(),
        load_fitted,
        predictions,
        bending: bending_track,
        extended_material: chosen.map(|(_, f)| f.material),
        yarn_level: None,
        wall_time_s: started.elapsed().as_secs_f64(),
    })
}
