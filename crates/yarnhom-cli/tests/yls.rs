//! `yarnhom yls`: a swatch cut from the published stockinette, a built-in scene simulated on
//! it, the trace read back; bad input refused in one line.

use std::path::Path;
use std::process::{Command, Output};

use yarnhom_trace::{TraceMessage, TraceReader};

const STOCK: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data/hylc-patterns/stock.pyp");

fn yarnhom(args: &[&str], cwd: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_yarnhom")).args(args).current_dir(cwd).output().expect("run yarnhom")
}

fn ok(args: &[&str], cwd: &Path) -> String {
    let o = yarnhom(args, cwd);
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(o.status.success(), "yarnhom {args:?} failed: {err}");
    err
}

fn fails_with(args: &[&str], cwd: &Path, problem: &str) {
    let o = yarnhom(args, cwd);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "yarnhom {args:?}: {err}");
    assert_eq!(err.trim_end().lines().count(), 1, "not one line: {err}");
    assert!(err.contains(problem), "yarnhom {args:?}: expected '{problem}' in: {err}");
}

#[test]
fn a_swatch_is_cut_and_a_stretch_is_simulated_on_it() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    let report =
        ok(&["yls", "swatch", STOCK, "--model", "table4.1:stock", "--tiles", "2x2", "-o", "s.swatch.yh"], d);
    assert!(report.contains("yarns") && report.contains("glue springs"), "{report}");
    let inspected = String::from_utf8_lossy(&yarnhom(&["inspect", "s.swatch.yh"], d).stdout).into_owned();
    assert!(inspected.contains("swatch"), "{inspected}");

    ok(&["yls", "simulate", "stretch-x", "--swatch", "s.swatch.yh", "--frames", "1", "-o", "run.mcap"], d);
    let mut frames = Vec::new();
    for message in TraceReader::new(std::fs::File::open(d.join("run.mcap")).expect("the trace")) {
        if let TraceMessage::Yarns(f) = message.expect("reads") {
            frames.push(f);
        }
    }
    assert_eq!(frames.iter().map(|f| f.frame).collect::<Vec<_>>(), vec![0, 1]);
    assert!(frames[1].positions_m.iter().all(|p| p.iter().all(|x| x.is_finite())));

    // `diff` compares yarn-level traces frame by frame: a rerun is equal, another scene is not.
    ok(&["yls", "simulate", "stretch-x", "--swatch", "s.swatch.yh", "--frames", "1", "-o", "again.mcap"], d);
    assert_eq!(yarnhom(&["diff", "run.mcap", "again.mcap"], d).status.code(), Some(0));
    ok(&["yls", "simulate", "stretch-y", "--swatch", "s.swatch.yh", "--frames", "1", "-o", "y.mcap"], d);
    let differs = yarnhom(&["diff", "run.mcap", "y.mcap"], d);
    assert_eq!(differs.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&differs.stdout).contains("/yarn/frame"));
    // `rerun` draws it (yarns as line strips, the held vertices as points); the rerun CLI, where
    // installed, checks the recording.
    let logged = yarnhom(&["rerun", "run.mcap", "--save", "run.rrd"], d);
    assert!(logged.status.success(), "{}", String::from_utf8_lossy(&logged.stderr));
    if let Ok(verify) = Command::new("rerun").args(["rrd", "verify", "run.rrd"]).current_dir(d).output() {
        assert!(verify.status.success(), "{}", String::from_utf8_lossy(&verify.stderr));
    }

    fails_with(
        &["yls", "swatch", STOCK, "--model", "table4.1:stock", "--size", "0.001x0.3", "-o", "x.yh"],
        d,
        "tile",
    );
    fails_with(
        &["yls", "simulate", "drape", "--swatch", "s.swatch.yh", "-o", "x.mcap"],
        d,
        "holds no yarn vertex",
    );
    fails_with(&["yls", "simulate", "stretch-x", "--swatch", STOCK, "-o", "x.mcap"], d, "swatch");
}

#[test]
fn record_writes_one_trace_per_sequence_shard_by_shard_and_resumes() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    ok(&["yls", "swatch", STOCK, "--model", "table4.1:stock", "--tiles", "2x2", "-o", "s.swatch.yh"], d);
    let record = |shard: &str| {
        let args =
            ["yls", "record", "stretch-x", "--swatch", "s.swatch.yh", "--variations", "2", "--seed", "5"];
        let mut args = args.to_vec();
        args.extend(["--frames", "2", "--shard", shard, "-o", "data"]);
        ok(&args, d)
    };
    record("1/2");
    assert!(!d.join("data/seq_000000.mcap").exists() && d.join("data/seq_000001.mcap").exists());
    record("0/2");
    let again = record("1/2");
    assert!(again.contains("seq_000001.mcap exists: kept"), "{again}");
    let metadata = |name: &str| {
        let bytes = std::fs::read(d.join("data").join(name)).expect("the trace");
        yarnhom_trace::read_metadata(&bytes).expect("metadata").remove(0)
    };
    let first = metadata("seq_000000.mcap");
    let second = metadata("seq_000001.mcap");
    let variation = |m: &yarnhom_trace::TraceMetadata| m.entries["variation"].clone();
    assert!(variation(&first).contains("\"motion_scale\":1.0"), "{}", variation(&first));
    assert!(variation(&second).contains("\"variation\":1"), "{}", variation(&second));
    assert_ne!(variation(&first), variation(&second));

    // The sequences as a training set: the bars' vertices are handles.
    ok(
        &[
            "trace",
            "export",
            "--format",
            "training",
            "data/seq_000000.mcap",
            "data/seq_000001.mcap",
            "-o",
            "set",
        ],
        d,
    );
    let meta: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.join("set/meta.json")).expect("meta.json"))
            .expect("JSON");
    assert_eq!(meta["trajectory_length"], 3, "{meta}");
    assert_eq!(meta["sequences"].as_array().map(Vec::len), Some(2), "{meta}");
}
