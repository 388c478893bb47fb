//! The calibration's reports as files: `shell-fit.json` ([`ShellFit`]), `yarn-fit.json`
//! ([`YarnFit`]) and `report.json` ([`Diagnosis`]), versioned JSON under
//! [`yarnhom_artifacts::report`]. Each type reads (migrating older versions) and writes itself
//! through [`read_report`](yarnhom_artifacts::report::read_report) and
//! [`write_report`](yarnhom_artifacts::report::write_report); [`CalibrationReport`] is any of
//! the three, for tools that dispatch on the `format` (`yarnhom inspect`, `yarnhom diff`).

use yarnhom_artifacts::diff::{Diff, Tolerance, diff_documents};
use yarnhom_artifacts::report::{Report, decode_report, report_format};
use yarnhom_artifacts::{Error, Result};

use crate::diagnosis::report::{DIAGNOSIS_FORMAT, Diagnosis};
use crate::shell::fit::{SHELL_FIT_FORMAT, ShellFit};
use crate::yarn::fit::{YARN_FIT_FORMAT, YarnFit};

/// A calibration report of any kind.
#[derive(Debug, Clone, PartialEq)]
pub enum CalibrationReport {
    /// `shell-fit.json` of `calibrate shell`.
    ShellFit(Box<ShellFit>),
    /// `yarn-fit.json` of `calibrate yarn`.
    YarnFit(Box<YarnFit>),
    /// `report.json` of `calibrate diagnose`.
    Diagnosis(Box<Diagnosis>),
}

impl CalibrationReport {
    /// Decode a report document of any kind by its `format` (migrating older versions).
    pub fn decode(document: serde_json::Value) -> Result<Self> {
        let format = report_format(&document).map(|(format, _)| format.to_string());
        match format.as_deref() {
            Some(SHELL_FIT_FORMAT) => Ok(Self::ShellFit(Box::new(decode_report(document)?))),
            Some(YARN_FIT_FORMAT) => Ok(Self::YarnFit(Box::new(decode_report(document)?))),
            Some(DIAGNOSIS_FORMAT) => Ok(Self::Diagnosis(Box::new(decode_report(document)?))),
            Some(other) => Err(Error::Decode {
                what: "calibration report",
                message: format!(
                    "unknown format '{other}' (known: {SHELL_FIT_FORMAT}, {YARN_FIT_FORMAT}, {DIAGNOSIS_FORMAT})"
                ),
            }),
            None => Err(Error::Decode {
                what: "calibration report",
                message: "no `format` and `version` fields: not a yarnhom report".into(),
            }),
        }
    }

    /// The report's `format`.
    pub fn format(&self) -> &'static str {
        match self {
            Self::ShellFit(_) => SHELL_FIT_FORMAT,
            Self::YarnFit(_) => YARN_FIT_FORMAT,
            Self::Diagnosis(_) => DIAGNOSIS_FORMAT,
        }
    }

    /// A human summary.
    pub fn summary(&self) -> String {
        match self {
            Self::ShellFit(r) => r.summary(),
            Self::YarnFit(r) => r.summary(),
            Self::Diagnosis(r) => r.summary(),
        }
    }

    /// The report as a JSON document of the current version.
    pub fn to_document(&self) -> Result<serde_json::Value> {
        let document = match self {
            Self::ShellFit(r) => serde_json::to_value(r),
            Self::YarnFit(r) => serde_json::to_value(r),
            Self::Diagnosis(r) => serde_json::to_value(r),
        };
        document.map_err(|e| Error::Encode { what: self.format(), message: e.to_string() })
    }

    /// Field-by-field comparison with a report of the same kind, both in the current version
    /// (an older file compares as its migration), within `tol`.
    pub fn diff(&self, other: &Self, tol: Tolerance) -> Result<Diff> {
        if self.format() != other.format() {
            return Err(Error::WrongKind { expected: self.format(), found: other.format().into() });
        }
        Ok(diff_documents(self.format(), &self.to_document()?, &other.to_document()?, tol))
    }
}
