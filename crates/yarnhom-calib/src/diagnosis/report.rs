//! `report.json` of a diagnosis ([`Diagnosis`]): the cause and the numbers behind it, every
//! model's fit, the targets, the predictions, the bending track and the yarn-level
//! confirmation.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use yarnhom_artifacts::report::Report;
use yarnhom_shell::StvkNeoHookean;

use super::settings::DiagnoseSettings;
use crate::cause::CauseId;
use crate::data::targets::{Target, TargetChoice};
use crate::experiments::bending_tests::BendingTest;
use crate::experiments::swatch::SimulatedReading;
use crate::yarn::confirm::YarnLevel;

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
    /// A candidate's signature before and after it (v4; absent for bases and untested models).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub signature: Option<SignatureScore>,
}

/// What a cause changes in the data, measured before and after a candidate for it: RMS of the
/// normalized residuals of the signature's quantities, and the RMS of their standard errors.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct SignatureScore {
    /// What is measured (`paired load/unload force difference`, ...).
    pub measure: String,
    /// Its error with the model the candidate extends.
    pub before: f64,
    /// Its error with the candidate.
    pub after: f64,
    /// Its noise.
    pub noise: f64,
}

/// A confirmed cause, in the order of its relative held-out gain.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct ConfirmedCause {
    /// Catalog id.
    pub id: CauseId,
    /// What it means.
    pub explanation: String,
    /// The step (1-based) that added it.
    pub step: usize,
    /// The model with it added (its id: the causes so far, joined by `+`).
    pub model: ModelResult,
    /// Held-out errors of the model it extends and of the model with it.
    pub gain: Gain,
}

/// One step of the stepwise explanation: the candidates fitted on top of a model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct Step {
    /// The id of the model the candidates extend.
    pub model: String,
    /// The candidates, fitted on top of it.
    pub candidates: Vec<ModelResult>,
    /// The candidate added, if one passed.
    pub added: Option<CauseId>,
}

impl ModelResult {
    /// A candidate that could not be tested on this set, and why.
    pub fn untestable(id: CauseId, note: &str) -> Self {
        ModelResult {
            id: id.as_str().into(),
            testable: false,
            note: Some(note.into()),
            params: Vec::new(),
            parameter_count: 0,
            error: None,
            heldout_error: None,
            criterion: None,
            signature: None,
        }
    }

    /// Its scores `(fitted error, held-out error, criterion)`, NaN where absent (a tested
    /// model has all three).
    pub fn scores(&self) -> (f64, f64, f64) {
        (
            self.error.unwrap_or(f64::NAN),
            self.heldout_error.unwrap_or(f64::NAN),
            self.criterion.unwrap_or(f64::NAN),
        )
    }
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
    /// The cause: the first of `causes`, else `none` or `unexplained`.
    pub cause: Cause,
    /// Every confirmed cause, in order of relative held-out gain (v4).
    #[serde(default)]
    pub causes: Vec<ConfirmedCause>,
    /// Whether the confirmed causes leave a held-out error above the noise (v4).
    #[serde(default)]
    pub unexplained_remainder: bool,
    /// The base model.
    pub base: ModelResult,
    /// The extended model: the stretch base with every confirmed stretch-track cause (else
    /// the confirmed bending cause), if a cause was confirmed.
    pub extended: Option<ModelResult>,
    /// Held-out errors of the base and of the extended model (the first cause's track).
    pub gain: Gain,
    /// Every candidate of the catalog, fitted on the bases (the first step).
    pub candidates: Vec<ModelResult>,
    /// Every step of the stepwise explanation, the first included (v4).
    #[serde(default)]
    pub steps: Vec<Step>,
    /// How the targets were chosen, per direction and phase (v4).
    #[serde(default)]
    pub target_choices: Vec<TargetChoice>,
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
    /// The yarn-level confirmation of the cause ([`crate::yarn::confirm`]); absent until it is
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
/// Layout version of [`Diagnosis`] files (v3 adds `extended_material` and `yarn_level`; v4
/// `causes`, `steps`, `target_choices`, `unexplained_remainder`, the candidates' signatures and
/// the targets' standard errors).
pub const DIAGNOSIS_VERSION: u32 = 4;

/// The JSON Schema of `report.json`.
pub fn diagnosis_schema() -> schemars::Schema {
    schemars::schema_for!(Diagnosis)
}

impl Diagnosis {
    /// What the verdict says of a remainder the confirmed causes leave, if they leave one.
    pub(super) fn remainder_words(&self) -> Option<&'static str> {
        (self.unexplained_remainder && !self.causes.is_empty()).then_some(
            "the confirmed causes leave a held-out error above the noise: the rest is off the catalog",
        )
    }
}

impl Report for Diagnosis {
    const FORMAT: &'static str = DIAGNOSIS_FORMAT;
    const VERSION: u32 = DIAGNOSIS_VERSION;

    /// Version 1 was written before the bending track, version 2 before the yarn-level
    /// confirmation and version 3 before the stepwise explanation: all read with the fields
    /// they did not have absent (v1: `bending`, `extended_material`, `yarn_level`; v2:
    /// `extended_material`, `yarn_level`; v1-v3: `steps`, `target_choices`, signatures). Their
    /// single cause, if a catalog candidate, becomes the one entry of `causes` (step 1, the
    /// report's `extended` model and `gain`). A v1 `gain.heldout_error_before` is the stretch
    /// base's held-out error, which is what later versions say for every cause of a set without
    /// bending tests.
    fn migrate(version: u32, document: serde_json::Value) -> Result<Self, yarnhom_artifacts::Error> {
        let what = match version {
            1 => "diagnosis v1",
            2 => "diagnosis v2",
            3 => "diagnosis v3",
            _ => {
                return Err(yarnhom_artifacts::Error::NoMigration {
                    kind: DIAGNOSIS_FORMAT.into(),
                    found: version,
                    supported: DIAGNOSIS_VERSION,
                });
            }
        };
        let diagnosis: Diagnosis = serde_json::from_value(document)
            .map_err(|e| yarnhom_artifacts::Error::Decode { what, message: e.to_string() })?;
        let causes = match (&diagnosis.extended, CauseId::CANDIDATES.contains(&diagnosis.cause.id)) {
            (Some(model), true) => vec![ConfirmedCause {
                id: diagnosis.cause.id,
                explanation: diagnosis.cause.explanation.clone(),
                step: 1,
                model: model.clone(),
                gain: diagnosis.gain,
            }],
            _ => Vec::new(),
        };
        Ok(Diagnosis { version: DIAGNOSIS_VERSION, causes, ..diagnosis })
    }

    /// How the targets were chosen, the causes with their gains, the evidence, the held-out
    /// gain, the yarn-level verdict.
    fn summary(&self) -> String {
        let mut lines: Vec<String> = self.target_choices.iter().map(|c| format!("targets: {c}")).collect();
        lines.push(format!("cause: {} ({})", self.cause.id.as_str(), self.cause.explanation));
        for c in self.causes.iter().skip(1) {
            lines.push(format!("also: {} ({})", c.id.as_str(), c.explanation));
        }
        if let Some(remainder) = self.remainder_words() {
            lines.push(format!("also: unexplained ({remainder})"));
        }
        for c in &self.causes {
            lines.push(format!(
                "  {}: held-out error {:.4} -> {:.4} (step {})",
                c.id.as_str(),
                c.gain.heldout_error_before,
                c.gain.heldout_error_after,
                c.step
            ));
        }
        lines.extend(self.cause.evidence.iter().map(|line| format!("  {line}")));
        lines.push(format!(
            "held-out error {:.4} -> {:.4}; {:.1} s",
            self.gain.heldout_error_before, self.gain.heldout_error_after, self.wall_time_s
        ));
        match &self.yarn_level {
            Some(YarnLevel::Confirmation(c)) => {
                lines.push(format!("yarn level: {} ({:.1} s)", c.verdict, c.wall_time_s))
            }
            Some(YarnLevel::NotRun { reason }) => lines.push(format!("yarn level: not run: {reason}")),
            None => {}
        }
        lines.join("\n")
    }
}
