//! `calibrate shell --model auto`: the membrane of plain anisotropic StVK plus the extensions a
//! diagnosis of the set confirms ([`crate::diagnosis`]), fitted to every target, so a user gets
//! the extended model and not only its name.
//!
//! The diagnosis runs at its default settings (the shell fit's force cap and mesh), its
//! confirmed stretch-track causes map to membrane terms (`area-preservation`: the Neo-Hookean
//! area terms of (6.1); `biphasic-stretch`: [`yarnhom_shell::Stiffening`]; `two-phase-contact`:
//! jamming), and the membrane with those terms is fitted to the shell fit's targets from the
//! diagnosis' extended material (fitted on half of them; without an extension, from the default
//! start). `friction-hysteresis` is an unloading effect and the bending causes belong
//! to the bending fit: they are listed as not fitted, with the reason.

use crate::cause::CauseId;
use crate::data::set::MeasurementSet;
use crate::diagnosis::diagnose;
use crate::diagnosis::settings::DiagnoseSettings;
use crate::shell::fit::{AutoModel, ShellFit, ShellFitSettings, fit_shell_with};
use crate::shell::membrane::{ShellFitError, Terms};

/// Fit `settings.model` to `set`: a fixed model as [`crate::shell::fit::fit_shell`] does, `auto`
/// as the module docs say.
pub fn fit_shell(set: &MeasurementSet, settings: &ShellFitSettings) -> Result<ShellFit, ShellFitError> {
    if let Some(terms) = settings.model.terms() {
        return fit_shell_with(set, settings, terms, &[], None);
    }
    let diagnosis_settings = DiagnoseSettings {
        force_cap_n: settings.plan.force_cap_n,
        spacing_m: settings.spacing_m,
        ..DiagnoseSettings::default()
    };
    let d = diagnose(set, &diagnosis_settings)?;
    let confirmed: Vec<CauseId> = d.causes.iter().map(|c| c.id).collect();
    let mut terms = Terms::default();
    let mut auto = AutoModel {
        confirmed: confirmed.clone(),
        fitted: Vec::new(),
        not_fitted: Vec::new(),
        heldout_error: (d.gain.heldout_error_before, d.gain.heldout_error_after),
        diagnosis_wall_time_s: d.wall_time_s,
    };
    for id in confirmed {
        match id {
            CauseId::AreaPreservation => terms.area = true,
            CauseId::BiphasicStretch => terms.stiffening = true,
            CauseId::TwoPhaseContact => terms.jamming = true,
            CauseId::FrictionHysteresis => {
                auto.not_fitted
                    .push((id, "an unloading effect: the shell fit fits the loading targets".into()));
                continue;
            }
            _ => {
                auto.not_fitted.push((id, "a bending cause: see the bending fit".into()));
                continue;
            }
        }
        auto.fitted.push(id);
    }
    let starts: Vec<_> = d.extended_material.filter(|_| !auto.fitted.is_empty()).into_iter().collect();
    fit_shell_with(set, settings, terms, &starts, Some(auto))
}
