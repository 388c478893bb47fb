//! The yarn-level step of a diagnosis: the diagnosed cause confirmed on the periodic tile
//! ([`crate::yarn::confirm`]) with the extended shell's uniform tests as targets, or the reason
//! it is not.

use std::fmt::Display;

use yarnhom_artifacts::Pattern;
use yarnhom_shell::StvkNeoHookean;

use super::report::Diagnosis;
use super::settings::Budget;
use crate::data::set::{Direction, MeasurementSet};
use crate::yarn::confirm::{YarnLevel, confirm, skipped};
use crate::yarn::params::YarnBasis;
use crate::yarn::problem::{TargetSource, YarnFitEvent, YarnProblem};
use crate::yarn::settings::YarnFitSettings;

/// Why a `quick` diagnosis has no yarn-level step.
const QUICK: &str =
    "--budget quick screens at the shell level only (normal or thorough confirm on the yarn tile)";

/// The yarn-level step of `diagnosis` of `set` under `budget`: none for `quick`, a skip for a
/// cause without a yarn mechanism, else the confirmation on the set's input geometry (loaded
/// by `pattern` only then; its error becomes the reason) with `yarn_stiffness` as `k_s2` if
/// given ([`YarnBasis::of_set`]).
pub fn yarn_level<E: Display>(
    set: &MeasurementSet,
    diagnosis: &Diagnosis,
    budget: Budget,
    yarn_stiffness: Option<f64>,
    pattern: impl FnOnce() -> Result<Pattern, E>,
    progress: &(dyn Fn(YarnFitEvent) + Sync),
) -> YarnLevel {
    let Some(settings) = budget.confirmation() else { return YarnLevel::NotRun { reason: QUICK.into() } };
    if let Some(skipped) = skipped(diagnosis.cause.id) {
        return skipped;
    }
    match pattern() {
        Err(e) => YarnLevel::NotRun { reason: format!("the set's pattern: {e:#}") },
        Ok(pattern) => {
            let basis = YarnBasis::of_set(set, &pattern, yarn_stiffness);
            confirm_diagnosis(set, diagnosis, pattern, basis, &settings, progress)
        }
    }
}

/// The confirmation of `diagnosis`'s cause on `pattern`: targets from the extended shell's
/// uniform tests along the set's tested directions, up to the largest target stretch of each.
pub fn confirm_diagnosis(
    set: &MeasurementSet,
    diagnosis: &Diagnosis,
    pattern: Pattern,
    basis: YarnBasis,
    settings: &YarnFitSettings,
    progress: &(dyn Fn(YarnFitEvent) + Sync),
) -> YarnLevel {
    let cause = diagnosis.cause.id;
    if let Some(skipped) = skipped(cause) {
        return skipped;
    }
    let Some(material) = diagnosis.extended_material else {
        return YarnLevel::NotRun { reason: "the diagnosis has no extended shell material".into() };
    };
    let problem = shell_problem(set, diagnosis, pattern, basis, material, settings);
    match confirm(&problem, cause, settings, progress) {
        Ok(c) => YarnLevel::Confirmation(Box::new(c)),
        Err(e) => YarnLevel::NotRun { reason: format!("the yarn-level fit failed: {e}") },
    }
}

/// The yarn-level problem of the extended shell `material` along the diagnosis's directions.
fn shell_problem(
    set: &MeasurementSet,
    diagnosis: &Diagnosis,
    pattern: Pattern,
    basis: YarnBasis,
    material: StvkNeoHookean,
    settings: &YarnFitSettings,
) -> YarnProblem {
    let directions = Direction::ALL
        .into_iter()
        .filter_map(|d| {
            let largest = diagnosis
                .load_targets
                .iter()
                .filter(|t| t.direction == d)
                .map(|t| t.stretch)
                .fold(0.0, f64::max);
            (largest > 0.0).then(|| (d, largest, set.fabric.swatch.specimen(d).width_m))
        })
        .collect();
    YarnProblem {
        pattern,
        basis,
        source: TargetSource::Shell(material),
        directions,
        rest: settings.rest,
        comfort_force_n: settings.comfort_force_n,
    }
}
