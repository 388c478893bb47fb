//! `report.json` of a diagnosis ([`Diagnosis`]): the cause and the numbers behind it, every
//! model's fit, the targets, the predictions, the bending track and the yarn-level
//! confirmation.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use yarnhom_artifacts::report::Report;
use yarnhom_shell::StvkNeoHookean;

use super::settings::DiagnoseSettings;
use crate::cause::CauseId;
use crate::data::targets::Target;
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
/// Layout version of [`Diagnosis`] files (v3 adds `extended_material` and `yarn_level`).
pub const DIAGNOSIS_VERSION: u32 = 3;

/// The JSON Schema of `report.json`.
pub fn diagnosis_schema() -> schemars::Schema {
    schemars::schema_for!(Diagnosis)
}

impl Report for Diagnosis {
    const FORMAT: &'static str = DIAGNOSIS_FORMAT;
    const VERSION: u32 = DIAGNOSIS_VERSION;

    /// Version 1 was written before the bending track and version 2 before the yarn-level
    /// confirmation: both read with the fields they did not have absent (v1: `bending`,
    /// `extended_material`, `yarn_level`; v2: `extended_material`, `yarn_level`). A v1
    /// `gain.heldout_error_before` is the stretch base's held-out error, which is what v3 says
    /// for every cause of a set without bending tests.
    fn migrate(version: u32, document: serde_json::Value) -> Result<Self, yarnhom_artifacts::Error> {
        let what = match version {
            1 => "diagnosis v1",
            2 => "diagnosis v2",
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
        Ok(Diagnosis { version: DIAGNOSIS_VERSION, ..diagnosis })
    }

    /// The cause and its evidence, the held-out gain, the yarn-level verdict.
    fn summary(&self) -> String {
        let mut lines = vec![format!("cause: {} ({})", self.cause.id.as_str(), self.cause.explanation)];
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
