//! Hidden-effect tests: a synthetic set is made from a ground truth with one effect hidden in
//! it (or none), and the diagnosis, told nothing about it, must name it.

use yarnhom_artifacts::report::Report;
use yarnhom_calib::auto_model::fit_shell;
use yarnhom_calib::cause::CauseId;
use yarnhom_calib::data::set::MeasurementSet;
use yarnhom_calib::diagnosis::diagnose;
use yarnhom_calib::diagnosis::report::Diagnosis;
use yarnhom_calib::diagnosis::settings::DiagnoseSettings;
use yarnhom_calib::experiments::synth::{BendingPlan, HiddenEffect, SynthPlan, ground_truth, synthesize};
use yarnhom_calib::shell::fit::ShellFitSettings;
use yarnhom_calib::shell::membrane::MembraneModel;

/// Relative noise: force and compression noise as this fraction of their mean clean values.
const NOISE: f64 = 0.02;

/// A set made from `effect` hidden at `strength`, with bending tests if `bending`.
fn hidden_set(effect: HiddenEffect, strength: f64, seed: u64, bending: bool) -> MeasurementSet {
    let truth = ground_truth(effect, strength);
    let mut clean_plan = SynthPlan {
        readings: 120,
        spacing_m: 0.006,
        unload: true,
        bending: bending.then(|| BendingPlan { noise: NOISE, ..BendingPlan::default() }),
        ..SynthPlan::new("hidden", 0.4)
    };
    clean_plan.fabric.swatch.areal_density_kg_m2 = Some(0.25);
    let clean = synthesize(&truth, &clean_plan).expect("simulates");
    let n = clean.stretch.len() as f64;
    let mean_force = clean.stretch.iter().map(|p| p.force_n.abs()).sum::<f64>() / n;
    let mean_compression = clean.stretch.iter().filter_map(|p| p.compression).map(f64::abs).sum::<f64>() / n;
    let plan = SynthPlan {
        force_noise_n: NOISE * mean_force,
        compression_noise: NOISE * mean_compression,
        seed,
        ..clean_plan
    };
    synthesize(&truth, &plan).expect("simulates")
}

/// Diagnose a set made from `effect` hidden at `strength`, with bending tests if `bending`.
fn hidden(effect: HiddenEffect, strength: f64, seed: u64, bending: bool) -> Diagnosis {
    let set = hidden_set(effect, strength, seed, bending);
    let settings = DiagnoseSettings { spacing_m: 0.01, ..DiagnoseSettings::default() };
    let d = diagnose(&set, &settings).expect("diagnoses");
    eprintln!("{effect:?} x{strength}: {} ({:.1} s)", d.cause.id.as_str(), d.wall_time_s);
    for c in &d.candidates {
        eprintln!("  {} {:?} {:?}", c.id, c.heldout_error, c.params);
    }
    for line in &d.cause.evidence {
        eprintln!("  {line}");
    }
    d
}

#[test]
fn clean_data_of_the_base_model_is_diagnosed_none_on_both_tracks() {
    let d = hidden(HiddenEffect::None, 1.0, 11, true);
    assert_eq!(d.cause.id, CauseId::None, "{:#?}", d.cause);
    assert!(d.extended.is_none());
    assert_eq!(d.gain.heldout_error_after, d.gain.heldout_error_before);
    let json = serde_json::to_string(&d).expect("serializes");
    assert_eq!(serde_json::from_str::<Diagnosis>(&json).expect("reads back"), d, "report.json round-trips");
    let track = d.bending.as_ref().expect("a bending track");
    assert!(track.base.heldout_error.expect("held out") < 3.0 * track.noise.max(0.01), "{track:?}");
    for id in ["rest-curvature", "anisotropic-bending"] {
        assert!(d.candidates.iter().any(|c| c.id == id && c.testable), "{id} is tested");
    }
}

#[test]
fn a_hidden_curl_is_found_as_rest_curvature_by_the_two_faces_of_the_cantilever() {
    let d = hidden(HiddenEffect::RestCurvature, 1.0, 15, true);
    assert_eq!(d.cause.id, CauseId::RestCurvature, "{:#?}", d.cause);
    let extended = d.extended.as_ref().expect("extended");
    let curl = extended.params.iter().find(|p| p.0 == "rest_curvature_weft").expect("weft curl").1;
    assert!((curl / 25.0 - 1.0).abs() < 0.3, "recovered curl {curl} 1/m vs 25 hidden");
    assert!(d.gain.heldout_error_after < 0.5 * d.gain.heldout_error_before, "{:?}", d.gain);
}

#[test]
fn a_hidden_bending_anisotropy_is_found() {
    let d = hidden(HiddenEffect::AnisotropicBending, 1.0, 16, true);
    assert_eq!(d.cause.id, CauseId::AnisotropicBending, "{:#?}", d.cause);
    let params = &d.extended.as_ref().expect("extended").params;
    let k = |name: &str| params.iter().find(|p| p.0 == name).expect("a stiffness").1;
    let ratio = k("k_weft") / k("k_warp");
    assert!((ratio / 4.0 - 1.0).abs() < 0.3, "weft/warp stiffness {ratio} vs 4 hidden");
}

#[test]
fn without_bending_tests_the_bending_causes_say_why_not() {
    let d = hidden(HiddenEffect::AreaPreservation, 1.0, 12, false);
    assert_eq!(d.cause.id, CauseId::AreaPreservation, "{:#?}", d.cause);
    assert!(d.gain.heldout_error_after < 0.75 * d.gain.heldout_error_before);
    assert!(d.bending.is_none());
    for id in ["rest-curvature", "anisotropic-bending"] {
        let c = d.candidates.iter().find(|c| c.id == id).expect("every catalog candidate is reported");
        assert!(!c.testable && c.note.as_ref().is_some_and(|n| !n.is_empty()), "{c:?}");
    }
}

#[test]
fn a_hidden_stiffening_is_found_as_biphasic_stretch() {
    let d = hidden(HiddenEffect::BiphasicStretch, 1.0, 13, false);
    assert_eq!(d.cause.id, CauseId::BiphasicStretch, "{:#?}", d.cause);
}

#[test]
fn a_hidden_jamming_is_found_as_two_phase_contact() {
    let d = hidden(HiddenEffect::TwoPhaseContact, 1.0, 17, false);
    assert_eq!(d.cause.id, CauseId::TwoPhaseContact, "{:#?}", d.cause);
    let params = &d.extended.as_ref().expect("extended").params;
    let onset = params.iter().find(|p| p.0 == "jamming_onset").expect("an onset").1;
    assert!((onset / 0.02 - 1.0).abs() < 0.5, "jamming onset {onset} vs 0.02 hidden");
    assert!(d.gain.heldout_error_after < 0.5 * d.gain.heldout_error_before, "{:?}", d.gain);
}

/// A softening is off the catalog. It moves the contraction as well as the force, so area
/// preservation may explain part of it (the contraction's share) and be confirmed; what no
/// catalog cause explains is left, flagged, and never named a stiffening.
#[test]
fn an_effect_outside_the_catalog_leaves_an_unexplained_remainder() {
    let d = hidden(HiddenEffect::Softening, 1.0, 18, false);
    assert!(d.base.heldout_error.expect("held out") > 3.0 * d.noise, "structured residuals: {:?}", d.base);
    assert!(d.cause.id == CauseId::Unexplained || d.unexplained_remainder, "{:#?}", d.cause);
    assert!(d.gain.heldout_error_after > 3.0 * d.noise, "{:?} at noise {}", d.gain, d.noise);
    assert!(d.causes.iter().all(|c| c.id != CauseId::BiphasicStretch), "{:?}", d.causes);
    assert!(d.summary().contains("unexplained"), "{}", d.summary());
    assert!(d.markdown().contains("`unexplained`"));
}

#[test]
fn hidden_hysteresis_is_found_on_the_unloading_readings() {
    let d = hidden(HiddenEffect::FrictionHysteresis, 1.0, 14, false);
    assert_eq!(d.cause.id, CauseId::FrictionHysteresis, "{:#?}", d.cause);
    let h =
        d.extended.as_ref().expect("extended").params.iter().find(|p| p.0 == "hysteresis_h").expect("h").1;
    assert!(h > 0.0, "unloading below loading: h = {h}");
}

#[test]
fn the_auto_model_fits_the_stiffening_the_diagnosis_confirms() {
    let set = hidden_set(HiddenEffect::BiphasicStretch, 1.0, 13, false);
    let settings =
        ShellFitSettings { model: MembraneModel::Auto, spacing_m: 0.01, ..ShellFitSettings::default() };
    let auto = fit_shell(&set, &settings).expect("fits");
    let chosen = auto.auto.as_ref().expect("the choice is recorded");
    assert!(chosen.fitted.contains(&CauseId::BiphasicStretch), "{chosen:?}");
    assert!(auto.material.stiffening.is_some(), "{:?}", auto.material);
    let plain = ShellFitSettings { model: MembraneModel::StvkNeoHookean, ..settings };
    let plain = fit_shell(&set, &plain).expect("fits");
    assert!(plain.auto.is_none());
    assert!(auto.errors.force < 0.5 * plain.errors.force, "{:?} vs {:?}", auto.errors, plain.errors);
    assert!(auto.summary().contains("auto: the diagnosis confirmed biphasic-stretch"), "{}", auto.summary());
}
