//! The calibration reports as versioned files (`schemas/README.md`): the committed fixtures of
//! older versions load through their migrations and equal what they must become, current files
//! round-trip byte for byte, and other formats and newer versions are refused.
//!
//! The fixtures were derived from files written by `calibrate diagnose --budget quick` and
//! `calibrate yarn` on synthetic sets, by removing exactly what each version did not have:
//! `diagnosis.v1.json` (no bending tests in its set) lacks `extended_material` and `yarn_level`
//! (and `bending`), `diagnosis.v2.json` (with bending tests) lacks `extended_material` and
//! `yarn_level` (both lack the v4 fields `causes`, `steps`, `target_choices`,
//! `unexplained_remainder` and the targets' standard errors), and `yarn-fit.v1.json` lacks `basis.mechanisms`; each validates against its
//! committed schema. `yarn-fit.v2.json` is `yarn-fit.v1.json` with the `basis.mechanisms` of
//! the thesis (what v1 reads as) and version 2: it lacks the v3 `basis.stitch` and
//! `basis.tile_length_per_stitch_m`.

use std::path::{Path, PathBuf};

use serde_json::{Value, json};
use yarnhom_artifacts::Error;
use yarnhom_artifacts::report::{Report, decode_report, read_report, write_report};
use yarnhom_calib::cause::CauseId;
use yarnhom_calib::diagnosis::report::Diagnosis;
use yarnhom_calib::report::CalibrationReport;
use yarnhom_calib::yarn::fit::{YarnFit, best_start};
use yarnhom_calib::yarn::params::YarnMechanisms;

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures").join(name)
}

fn document(name: &str) -> Value {
    let text = std::fs::read_to_string(fixture(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
    serde_json::from_str(&text).expect("a JSON fixture")
}

/// `document` as the current version must write it: `version` set to `version`, the fields in
/// `added` inserted.
fn upgraded(mut document: Value, version: u32, added: &[(&str, Value)]) -> Value {
    document["version"] = version.into();
    for (pointer, value) in added {
        let (parent, key) = pointer.rsplit_once('/').expect("a JSON pointer");
        document.pointer_mut(parent).expect("the parent exists")[key] = value.clone();
    }
    document
}

/// A v1-v3 diagnosis document as version 4 writes it: its cause (a catalog candidate with an
/// extended model) the one entry of `causes`, no steps, target choices or remainder, and every
/// target with zero standard errors.
fn as_v4(document: Value) -> Value {
    let cause = json!({
        "id": document["cause"]["id"],
        "explanation": document["cause"]["explanation"],
        "step": 1,
        "model": document["extended"],
        "gain": document["gain"],
    });
    let mut v4 = upgraded(
        document,
        4,
        &[
            ("/causes", json!([cause])),
            ("/unexplained_remainder", json!(false)),
            ("/steps", json!([])),
            ("/target_choices", json!([])),
        ],
    );
    for list in ["load_targets", "unload_targets"] {
        for target in v4[list].as_array_mut().expect("targets") {
            target["force_standard_error_n"] = json!(0.0);
        }
    }
    v4
}

#[test]
fn a_v1_diagnosis_reads_without_bending_track_extended_material_and_yarn_level() {
    let v1 = document("diagnosis.v1.json");
    assert_eq!(v1["version"], 1);
    for absent in ["bending", "extended_material", "yarn_level"] {
        assert!(v1.get(absent).is_none(), "{absent}");
    }
    let d: Diagnosis = read_report(&fixture("diagnosis.v1.json")).expect("migrates");
    assert_eq!((d.version, d.cause.id), (4, CauseId::BiphasicStretch));
    assert_eq!((&d.bending, &d.extended_material, &d.yarn_level), (&None, &None, &None));
    assert_eq!(d.causes.len(), 1);
    // Everything else is the file's: the migrated report writes the v1 document as version 4.
    assert_eq!(serde_json::to_value(&d).expect("json"), as_v4(v1));
}

#[test]
fn a_v2_diagnosis_reads_with_its_bending_track_and_without_extended_material_and_yarn_level() {
    let v2 = document("diagnosis.v2.json");
    assert_eq!(v2["version"], 2);
    assert!(v2.get("extended_material").is_none() && v2.get("yarn_level").is_none());
    let d: Diagnosis = decode_report(v2.clone()).expect("migrates");
    assert_eq!(d.version, 4);
    let track = d.bending.as_ref().expect("a bending track");
    assert_eq!(track.tests.len(), track.measured.len());
    assert_eq!((&d.extended_material, &d.yarn_level), (&None, &None));
    assert_eq!(serde_json::to_value(&d).expect("json"), as_v4(v2));
}

#[test]
fn a_v1_yarn_fit_reads_as_the_thesis_mechanisms() {
    let v1 = document("yarn-fit.v1.json");
    assert!(v1["version"] == 1 && v1["basis"].get("mechanisms").is_none());
    let fit: YarnFit = read_report(&fixture("yarn-fit.v1.json")).expect("migrates");
    assert_eq!((fit.version, fit.basis.mechanisms), (3, YarnMechanisms::THESIS));
    assert_eq!((fit.basis.stitch, fit.basis.tile_length_per_stitch_m), (None, None));
    let thesis = json!({ "biphasic_stretch": true, "inner_contact": "held" });
    assert_eq!(serde_json::to_value(&fit).expect("json"), upgraded(v1, 3, &[("/basis/mechanisms", thesis)]));
}

#[test]
fn a_v2_yarn_fit_reads_without_a_stitch() {
    // Fitted before `[stitch]` was used: the generator's default stitch and the thesis' R_2.
    let v2 = document("yarn-fit.v2.json");
    assert!(v2["version"] == 2 && v2["basis"].get("stitch").is_none());
    let fit: YarnFit = read_report(&fixture("yarn-fit.v2.json")).expect("migrates");
    assert_eq!((fit.version, fit.basis.stitch, fit.basis.tile_length_per_stitch_m), (3, None, None));
    assert_eq!(serde_json::to_value(&fit).expect("json"), upgraded(v2, 3, &[]));
    let v1: YarnFit = read_report(&fixture("yarn-fit.v1.json")).expect("migrates");
    assert_eq!(fit, v1, "v1 and v2 of the same fit read the same");
    assert!(
        fit.summary()
            .contains("stitch: not recorded (a pattern file, or a fit written before v3) (R_2 = 0.25 R_est)"),
        "{}",
        fit.summary()
    );
}

#[test]
fn current_reports_round_trip_byte_for_byte() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d: Diagnosis = read_report(&fixture("diagnosis.v2.json")).expect("migrates");
    let fit: YarnFit = read_report(&fixture("yarn-fit.v1.json")).expect("migrates");
    let (d_path, fit_path) = (dir.path().join("report.json"), dir.path().join("yarn-fit.json"));
    write_report(&d_path, &d).expect("writes");
    write_report(&fit_path, &fit).expect("writes");
    let text = std::fs::read_to_string(&d_path).expect("reads");
    assert_eq!(text, serde_json::to_string_pretty(&d).expect("json"));
    assert_eq!(read_report::<Diagnosis>(&d_path).expect("reads"), d);
    assert_eq!(read_report::<YarnFit>(&fit_path).expect("reads"), fit);
}

#[test]
fn newer_versions_and_other_formats_are_refused() {
    let newer = upgraded(document("diagnosis.v2.json"), 5, &[]);
    let error = decode_report::<Diagnosis>(newer).expect_err("newer");
    assert!(matches!(error, Error::NewerSchema { found: 5, supported: 4, .. }), "{error}");
    let error = read_report::<YarnFit>(&fixture("diagnosis.v1.json")).expect_err("a diagnosis");
    assert!(matches!(error.root(), Error::WrongKind { expected: "yarnhom.yarn-fit", .. }), "{error}");
    assert!(error.to_string().contains("diagnosis.v1.json"), "errors name the file: {error}");
    let unversioned = upgraded(document("yarn-fit.v1.json"), 0, &[]);
    let error = decode_report::<YarnFit>(unversioned).expect_err("no version 0");
    assert!(matches!(error, Error::NoMigration { found: 0, .. }), "{error}");
}

#[test]
fn any_calibration_report_is_decoded_by_its_format() {
    let d = CalibrationReport::decode(document("diagnosis.v1.json")).expect("a diagnosis");
    assert_eq!(d.format(), Diagnosis::FORMAT);
    assert!(d.summary().starts_with("cause: biphasic-stretch ("), "{}", d.summary());
    let fit = CalibrationReport::decode(document("yarn-fit.v1.json")).expect("a yarn fit");
    assert!(matches!(&fit, CalibrationReport::YarnFit(f) if f.version == YarnFit::VERSION));
    assert!(fit.summary().starts_with("yarn model of plain"), "{}", fit.summary());
    let other = CalibrationReport::decode(json!({ "format": "yarnhom.other", "version": 1 }));
    assert!(matches!(other, Err(Error::Decode { .. })));
}

#[test]
fn the_best_start_is_the_lowest_cost_shards_search_point() {
    let dir = tempfile::tempdir().expect("tempdir");
    let fit: YarnFit = read_report(&fixture("yarn-fit.v1.json")).expect("migrates");
    let shards = [(2.0, 0.25), (0.5, 0.75), (1.0, 0.5)];
    let paths: Vec<PathBuf> = shards
        .iter()
        .enumerate()
        .map(|(k, &(cost, x))| {
            let path = dir.path().join(format!("shard{k}.json"));
            let coordinates = vec![x; fit.coordinates.len()];
            write_report(&path, &YarnFit { cost, coordinates, ..fit.clone() }).expect("writes");
            path
        })
        .collect();
    assert_eq!(best_start(&paths).expect("reads"), Some(vec![0.75; fit.coordinates.len()]));
    assert_eq!(best_start(&[]).expect("nothing to read"), None);
    assert!(best_start(&[dir.path().join("missing.json")]).is_err());
}
