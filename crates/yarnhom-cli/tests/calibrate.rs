//! `yarnhom calibrate` on synthetic sets whose truth is known, and on bad input.

use std::path::Path;
use std::process::{Command, Output};

use yarnhom_calib::data::set::Direction;
use yarnhom_calib::experiments::synth::{BendingPlan, GroundTruth, SynthPlan, synthesize};
use yarnhom_shell::{HingeBending, StvkNeoHookean};

fn yarnhom(args: &[&str], cwd: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_yarnhom")).args(args).current_dir(cwd).output().expect("run yarnhom")
}

/// The membrane behind the synthetic sets.
fn known_membrane() -> StvkNeoHookean {
    StvkNeoHookean {
        k_xx: 80.0,
        k_xy: 10.0,
        k_yy: 30.0,
        k_ss: 12.0,
        k_n1: 3.0,
        k_n2: 1.0,
        stiffening: None,
        jamming: None,
    }
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

#[test]
fn calibrate_shell_recovers_a_known_membrane_and_bending_and_writes_its_report_and_figures() {
    let dir = tempfile::tempdir().expect("tempdir");
    let truth = GroundTruth {
        bending: HingeBending::anisotropic(3e-6, 2e-6, 1e-6),
        ..GroundTruth::of_membrane(known_membrane())
    };
    let mut plan = SynthPlan {
        directions: vec![Direction::Weft, Direction::Warp],
        max_stretch: vec![0.25, 0.4],
        force_noise_n: 0.01,
        compression_noise: 0.001,
        spacing_m: 0.01,
        bending: Some(BendingPlan {
            clamp_distances_m: vec![0.003, 0.013, 0.024, 0.034],
            overhangs_m: vec![0.01, 0.018, 0.026],
            noise: 0.0,
        }),
        ..SynthPlan::new("synthetic", 0.3)
    };
    plan.fabric.swatch.areal_density_kg_m2 = Some(0.25);
    synthesize(&truth, &plan).expect("simulates").write(&dir.path().join("set")).expect("writes");
    let o = yarnhom(
        &["calibrate", "shell", "set", "-o", "out", "--spacing", "0.01", "--targets", "4"],
        dir.path(),
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
    let summary = text(&o.stdout);
    for expected in ["weft", "warp", "mean", "not constrained by the data (held): k_ss", "17.6%", "5.61%"] {
        assert!(summary.contains(expected), "missing '{expected}' in:\n{summary}");
    }
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("out/shell-fit.json")).expect("json"))
            .expect("parses");
    assert_eq!(report["format"], "yarnhom.shell-fit");
    assert!(report["errors"]["force"].as_f64().expect("number") < 0.03, "{}", report["errors"]);
    let k_xx = report["material"]["k_xx"].as_f64().expect("number");
    assert!((k_xx / 80.0 - 1.0).abs() < 0.1, "k_xx {k_xx}");
    let svg = std::fs::read_to_string(dir.path().join("out/shell-fit.svg")).expect("svg");
    assert!(svg.contains("synthetic warp: compression"), "figure has a panel per direction and quantity");
    let bending = &report["bending"]["fit"];
    let k = |name: &str| bending["bending"][name].as_f64().expect("a stiffness");
    assert!((k("k_weft") / 3e-6 - 1.0).abs() < 0.1 && (k("k_warp") / 1e-6 - 1.0).abs() < 0.1, "{bending}");
    assert!(bending["error"].as_f64().expect("error") < 0.02, "{bending}");
    let targets = report["bending"]["uniform_targets"].as_array().expect("targets");
    assert_eq!(targets.len(), 14, "7 {{κ, σ_κ}} targets per tested direction");
    let svg = std::fs::read_to_string(dir.path().join("out/bending.svg")).expect("bending figure");
    assert!(svg.contains("synthetic weft: cantilever, face down"), "a panel per test, face and direction");
}

#[test]
fn bad_calibration_input_is_refused_with_a_reason() {
    let dir = tempfile::tempdir().expect("tempdir");
    let o = yarnhom(&["calibrate", "shell", "missing", "-o", "out"], dir.path());
    assert_eq!(o.status.code(), Some(2));
    assert!(text(&o.stderr).contains("missing/fabric.toml"), "{}", text(&o.stderr));
    let o = yarnhom(&["calibrate", "shell", "missing", "-o", "out", "--force-cap=-1"], dir.path());
    let stderr = text(&o.stderr);
    assert!(stderr.contains("'--force-cap") && stderr.contains("must be a positive"), "{stderr}");
}

#[test]
fn synth_then_diagnose_names_the_hidden_effect_and_writes_the_report() {
    let dir = tempfile::tempdir().expect("tempdir");
    let o = yarnhom(
        &[
            "calibrate",
            "synth",
            "-o",
            "set",
            "--effect",
            "friction-hysteresis",
            "--seed",
            "3",
            "--truth",
            "truth.json",
        ],
        dir.path(),
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(dir.path().join("truth.json").exists());
    let o = yarnhom(&["calibrate", "diagnose", "set", "-o", "out", "--budget", "quick"], dir.path());
    assert!(o.status.success(), "{}", text(&o.stderr));
    // The targets chosen come first, then the verdict.
    let stdout = text(&o.stdout);
    assert!(stdout.starts_with("targets: weft load: 10 targets"), "{stdout}");
    assert!(stdout.lines().any(|l| l.starts_with("cause: friction-hysteresis")), "{stdout}");
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("out/report.json")).expect("json"))
            .expect("parses");
    for field in [
        "/cause/id",
        "/cause/explanation",
        "/cause/evidence",
        "/base/error",
        "/extended/error",
        "/extended/params",
        "/gain/heldout_error_before",
        "/gain/heldout_error_after",
        "/candidates/0/id",
        "/candidates/0/error",
        "/candidates/0/criterion",
        "/extended_material/k_xx",
    ] {
        assert!(report.pointer(field).is_some(), "report.json lacks {field}");
    }
    // The quick budget screens only; the report says so.
    assert_eq!(report.pointer("/yarn_level/status").and_then(|v| v.as_str()), Some("not-run"));
    assert!(
        report
            .pointer("/yarn_level/reason")
            .and_then(|v| v.as_str())
            .is_some_and(|r| r.contains("--budget quick")),
        "{report}"
    );
    let before = report.pointer("/gain/heldout_error_before").and_then(|v| v.as_f64()).expect("number");
    let after = report.pointer("/gain/heldout_error_after").and_then(|v| v.as_f64()).expect("number");
    assert!(after < before, "{after} vs {before}");
    let md = std::fs::read_to_string(dir.path().join("out/report.md")).expect("md");
    assert!(
        md.contains("**Cause: `friction-hysteresis`**")
            && md.contains("| two-phase-contact | yes |")
            && md.contains("| rest-curvature | no |"),
        "{md}"
    );
    for figure in ["fit.svg", "residuals.svg"] {
        assert!(std::fs::read_to_string(dir.path().join("out").join(figure)).expect("svg").contains("<svg"));
    }
    let o = yarnhom(&["calibrate", "synth", "-o", "bad", "--effect", "none", "--noise=-1"], dir.path());
    assert_eq!(o.status.code(), Some(2));
    let stderr = text(&o.stderr);
    assert!(stderr.contains("'--noise") && stderr.contains("must be a number >= 0"), "{stderr}");
}

#[test]
fn pear_loop_prints_a_loop_per_clamp_distance_and_refuses_impossible_ones() {
    let dir = tempfile::tempdir().expect("tempdir");
    let args = ["calibrate", "pear-loop", "--density", "0.25", "--bending", "1e-6"];
    let o = yarnhom(&[&args[..], &["--distances", "0.005,0.03"]].concat(), dir.path());
    assert!(o.status.success(), "{}", text(&o.stderr));
    let out = text(&o.stdout);
    let rows: Vec<Vec<f64>> =
        out.lines().skip(1).map(|l| l.split(',').map(|x| x.parse().expect("number")).collect()).collect();
    assert_eq!(out.lines().next(), Some("clamp_distance_m,height_m,width_m,aspect_ratio"));
    assert_eq!(rows.len(), 2);
    // Closer clamps: a narrower loop of about the same depth, so a larger aspect ratio.
    assert!(rows[0][2] < rows[1][2] && rows[0][3] > rows[1][3], "{out}");
    let o = yarnhom(&[&args[..], &["--distances", "0.2"]].concat(), dir.path());
    assert_eq!(o.status.code(), Some(2));
    assert!(text(&o.stderr).contains("does not form a loop"), "{}", text(&o.stderr));
}

#[test]
fn calibrate_yarn_estimates_a_yarn_model_in_shards_and_writes_its_artifacts() {
    let dir = tempfile::tempdir().expect("tempdir");
    let plan = SynthPlan {
        directions: vec![Direction::Weft, Direction::Warp],
        max_stretch: vec![0.4, 0.4],
        spacing_m: 0.01,
        ..SynthPlan::new("synthetic", 0.3)
    };
    let truth = known_membrane();
    synthesize(&GroundTruth::of_membrane(truth), &plan)
        .expect("simulates")
        .write(&dir.path().join("set"))
        .expect("writes");
    let small =
        ["--generations", "1", "--swarm-targets", "3", "--local-targets", "3", "--yarn-stiffness", "200"];
    // Two shards of a 4-particle swarm, then the local step from the better one.
    for shard in ["0/2", "1/2"] {
        let out = format!("shard{}", &shard[..1]);
        let mut args = vec!["calibrate", "yarn", "set", "-o", &out, "--particles", "4", "--shard", shard];
        args.extend(small);
        let o = yarnhom(&args, dir.path());
        assert!(o.status.success(), "{}", text(&o.stderr));
    }
    let mut args = vec!["calibrate", "yarn", "set", "-o", "out", "--budget", "3"];
    args.extend(small);
    args.extend(["--start-from", "shard0/yarn-fit.json", "shard1/yarn-fit.json"]);
    let o = yarnhom(&args, dir.path());
    assert!(o.status.success(), "{}", text(&o.stderr));
    let summary = text(&o.stdout);
    for expected in ["comfort stress", "weft", "warp", "local (Cobyla)"] {
        assert!(summary.contains(expected), "missing '{expected}' in:\n{summary}");
    }
    let fit: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("out/yarn-fit.json")).expect("json"))
            .expect("parses");
    assert_eq!(fit["format"], "yarnhom.yarn-fit");
    assert_eq!(fit["params"]["k_s2_n"], 200.0);
    assert!(fit["swarm"].is_null(), "the local step started from the shards");
    for file in ["yarn.yarnmodel.yh", "rest.pattern.yh", "yarn-fit.svg", "shell-fit.json"] {
        assert!(dir.path().join("out").join(file).is_file(), "{file}");
    }
    let o = yarnhom(&["inspect", "out/yarn.yarnmodel.yh"], dir.path());
    assert!(text(&o.stdout).contains("biphasic"), "{}", text(&o.stdout));
    let o = yarnhom(&["calibrate", "yarn", "set", "-o", "x", "--shard", "2/2"], dir.path());
    assert_eq!(o.status.code(), Some(2));
    assert!(text(&o.stderr).contains("need 0 <= K < N"), "{}", text(&o.stderr));
    let o = yarnhom(&["calibrate", "yarn", "set", "-o", "x", "--yarn-stiffness=-1"], dir.path());
    let stderr = text(&o.stderr);
    assert!(stderr.contains("'--yarn-stiffness") && stderr.contains("must be a positive"), "{stderr}");
}
