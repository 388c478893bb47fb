//! `yarnhom trace export`: a simulated drape as OBJ and PLY frames and as an HDF5 training file
//! (read back with h5py when it is installed), yarn-level traces as a training set (loaded by
//! `tools/training_example.py`), truncated inputs, and refused arguments.

use std::path::Path;
use std::process::{Command, Output};

const SATIN: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data/hylc-materials/satin1.json");

fn yarnhom(args: &[&str], cwd: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_yarnhom")).args(args).current_dir(cwd).output().expect("run yarnhom")
}

fn ok(args: &[&str], cwd: &Path) -> Output {
    let o = yarnhom(args, cwd);
    assert!(o.status.success(), "yarnhom {args:?} failed: {}", String::from_utf8_lossy(&o.stderr));
    o
}

/// `t.mcap` in `dir`: a 9 x 9 drape of the published satin, frames 0 to 3.
fn drape_trace(dir: &Path) {
    let args = [
        "shell",
        "simulate",
        "drape",
        "--material",
        SATIN,
        "--trace",
        "t.mcap",
        "--frames",
        "3",
        "--resolution",
        "9",
    ];
    ok(&args, dir);
}

fn sorted_file_names(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .expect("read dir")
        .map(|entry| entry.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

fn drape_files(extension: &str) -> Vec<String> {
    (0..4).map(|frame| format!("drape_{frame:06}.{extension}")).collect()
}

#[test]
fn trace_export_explains_itself() {
    let dir = tempfile::tempdir().expect("tempdir");
    let help = String::from_utf8_lossy(&ok(&["trace", "export", "--help"], dir.path()).stdout).into_owned();
    assert!(help.contains("Usage:") && help.contains("hdf5"), "{help}");
}

#[test]
fn obj_export_writes_one_file_per_frame_with_texture_coordinates() {
    let dir = tempfile::tempdir().expect("tempdir");
    drape_trace(dir.path());
    let o = ok(&["trace", "export", "t.mcap", "--format", "obj", "-o", "objs"], dir.path());
    let summary = String::from_utf8_lossy(&o.stderr);
    assert!(summary.contains("4 files written") && summary.contains("/mesh/drape 4"), "{summary}");
    assert_eq!(sorted_file_names(&dir.path().join("objs")), drape_files("obj"));
    let text = std::fs::read_to_string(dir.path().join("objs/drape_000003.obj")).expect("read obj");
    let count =
        |keyword: &str| text.lines().filter(|line| line.split_whitespace().next() == Some(keyword)).count();
    assert_eq!((count("v"), count("vt"), count("f")), (81, 81, 128));
}

#[test]
fn ply_export_writes_binary_frames_of_the_expected_size() {
    let dir = tempfile::tempdir().expect("tempdir");
    drape_trace(dir.path());
    ok(&["trace", "export", "t.mcap", "--format", "ply", "-o", "plys"], dir.path());
    assert_eq!(sorted_file_names(&dir.path().join("plys")), drape_files("ply"));
    let bytes = std::fs::read(dir.path().join("plys/drape_000000.ply")).expect("read ply");
    let header = "ply\nformat binary_little_endian 1.0\nelement vertex 81\nproperty double x\nproperty double y\n\
                  property double z\nelement face 128\nproperty list uchar uint vertex_indices\nend_header\n";
    assert_eq!(&bytes[..header.len()], header.as_bytes());
    assert_eq!(bytes.len(), header.len() + 81 * 24 + 128 * 13);
}

#[test]
fn a_truncated_trace_is_exported_up_to_the_cut_with_a_warning() {
    let dir = tempfile::tempdir().expect("tempdir");
    drape_trace(dir.path());
    let trace = std::fs::read(dir.path().join("t.mcap")).expect("read trace");
    std::fs::write(dir.path().join("cut.mcap"), &trace[..trace.len() - 1]).expect("write cut");
    let o = ok(&["trace", "export", "cut.mcap", "--format", "obj", "-o", "objs"], dir.path());
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(stderr.contains("warning: cut.mcap: the trace is truncated"), "{stderr}");
    assert_eq!(
        sorted_file_names(&dir.path().join("objs")),
        drape_files("obj"),
        "only the end magic was lost"
    );
}

#[test]
fn bad_inputs_exit_with_2() {
    let dir = tempfile::tempdir().expect("tempdir");
    let o = yarnhom(&["trace", "export", "missing.mcap", "--format", "obj", "-o", "objs"], dir.path());
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("cannot open the trace missing.mcap"));
    std::fs::write(dir.path().join("junk.mcap"), b"not a trace at all").expect("write");
    let o = yarnhom(&["trace", "export", "junk.mcap", "--format", "ply", "-o", "plys"], dir.path());
    assert_eq!(o.status.code(), Some(2), "{}", String::from_utf8_lossy(&o.stderr));
    let o = yarnhom(&["trace", "export", "junk.mcap", "--format", "stl", "-o", "x"], dir.path());
    assert_eq!(o.status.code(), Some(2));
}

#[cfg(not(feature = "hdf5"))]
#[test]
fn hdf5_export_needs_the_feature() {
    let dir = tempfile::tempdir().expect("tempdir");
    let o = yarnhom(&["trace", "export", "-", "--format", "hdf5", "-o", "t.h5"], dir.path());
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("needs the `hdf5` feature"));
}

#[cfg(feature = "hdf5")]
#[test]
fn hdf5_export_is_read_by_h5py_through_its_manifest() {
    let dir = tempfile::tempdir().expect("tempdir");
    drape_trace(dir.path());
    let o = ok(&["trace", "export", "t.mcap", "--format", "hdf5", "-o", "t.h5"], dir.path());
    let summary = String::from_utf8_lossy(&o.stderr);
    assert!(summary.contains("1 file written") && summary.contains("/solver"), "{summary}");
    assert_eq!(sorted_file_names(dir.path()), ["t.h5", "t.mcap"], "no temporary file is left");

    if !python_with_h5py() {
        return;
    }
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/read_training_h5.py");
    let read = Command::new("python3")
        .arg(script)
        .arg("t.h5")
        .current_dir(dir.path())
        .output()
        .expect("run python3");
    assert!(read.status.success(), "{}", String::from_utf8_lossy(&read.stderr));
    let seen: serde_json::Value = serde_json::from_slice(&read.stdout).expect("script output");
    assert_eq!(seen["positions_shape"], serde_json::json!([4, 81, 3]));
    assert_eq!(seen["positions_finite"], true);
    assert_eq!(seen["frames"], serde_json::json!([0, 1, 2, 3]));
    assert_eq!(seen["producers"], serde_json::json!(["yarnhom shell simulate"]));
    assert_eq!(seen["input"], "t.mcap");
    assert!(
        seen["metrics"].as_array().is_some_and(|m| m.contains(&serde_json::json!("elastic_energy_j"))),
        "{seen}"
    );
}

/// Frame spacing of the synthetic yarn traces, in seconds.
#[cfg(feature = "hdf5")]
const DT: f64 = 0.01;

/// A synthetic yarn-level trace at `path`: two yarns of 5 and 7 vertices over 10 frames, the
/// free vertices falling from rest with the constant acceleration `acceleration_m_s2`; with
/// `handles`, a `/yarn/nodes` makes the first vertex of each yarn a handle that stays put.
#[cfg(feature = "hdf5")]
fn falling_yarns(path: &Path, acceleration_m_s2: [f64; 3], handles: bool) {
    use yarnhom_trace::{TraceMetadata, TraceWriter, YarnFrame, YarnNodes};
    let ranges = vec![[0, 5], [5, 7]];
    let rest: Vec<[f64; 3]> =
        (0..12)
            .map(|v| {
                if v < 5 {
                    [0.1 + 0.01 * v as f64, 0.0, 0.2]
                } else {
                    [0.1 + 0.01 * (v - 5) as f64, 0.02, 0.2]
                }
            })
            .collect();
    let handle = |v: usize| handles && (v == 0 || v == 5);
    let mut trace = TraceWriter::create(path).expect("trace");
    trace.write_metadata(&TraceMetadata::new("synthetic fall", "1")).expect("metadata");
    if handles {
        let node_type =
            (0..12).map(|v| if handle(v) { YarnNodes::HANDLE } else { YarnNodes::NORMAL }).collect();
        let edges = YarnNodes::chain_edges(&ranges);
        let nodes = YarnNodes { yarns: "swatch".into(), rest_positions_m: rest.clone(), node_type, edges };
        trace.write(&nodes).expect("nodes");
    }
    for frame in 0..10u64 {
        let t = frame as f64 * DT;
        let positions_m = rest
            .iter()
            .enumerate()
            .map(|(v, p)| {
                let a = if handle(v) { [0.0; 3] } else { acceleration_m_s2 };
                std::array::from_fn(|i| p[i] + 0.5 * a[i] * t * t)
            })
            .collect();
        let yarns = YarnFrame {
            yarns: "swatch".into(),
            frame,
            time_s: t,
            positions_m,
            radii_m: vec![1.5e-4; 12],
            yarn_ranges: ranges.clone(),
            ..YarnFrame::default()
        };
        trace.write(&yarns).expect("frame");
    }
    trace.finish().expect("finish");
}

#[cfg(feature = "hdf5")]
#[test]
fn yarn_traces_become_a_training_set_whose_targets_are_the_simulated_accelerations() {
    let dir = tempfile::tempdir().expect("tempdir");
    let gravity = [0.5, -2.0, -9.81];
    let slower = [0.0, 0.0, -4.9];
    falling_yarns(&dir.path().join("a.mcap"), gravity, true);
    falling_yarns(&dir.path().join("b.mcap"), slower, false);
    let args = ["trace", "export", "--format", "training", "a.mcap", "b.mcap", "-o", "ds"];
    let summary = String::from_utf8_lossy(&ok(&args, dir.path()).stderr).into_owned();
    assert!(summary.contains("2 files written; frames: train/0 10, train/1 10"), "{summary}");
    assert_eq!(sorted_file_names(&dir.path().join("ds")), ["meta.json", "train.h5"]);
    let o = yarnhom(&["trace", "export", "--format", "obj", "a.mcap", "b.mcap", "-o", "objs"], dir.path());
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("only `training` takes several"));

    if !python_with_h5py() {
        return;
    }
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/../../tools/training_example.py");
    let run = |extra: &[&str]| {
        let o = Command::new("python3").arg(script).arg("ds").args(extra).current_dir(dir.path()).output();
        let o = o.expect("run python3");
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        String::from_utf8(o.stdout).expect("utf-8")
    };
    let text = run(&[]);
    assert!(text.contains("train/0 (a.mcap, yarns 'swatch', dt 0.0"), "{text}");
    assert!(text.contains("edges (10, 2) int32, mesh_pos (12, 3) float32"), "{text}");
    let seen: serde_json::Value = serde_json::from_str(&run(&["--json"])).expect("script output");
    let sequences = seen["sequences"].as_array().expect("sequences");
    assert_eq!(sequences.len(), 2);
    // Positions of about 0.2 m rounded to f32: a target x[t+1] - 2 x[t] + x[t-1] is exact to
    // 4 roundings of at most half an f32 ulp of 0.25 m.
    let tolerance_m = 4.0 * 0.5 * f64::from(f32::EPSILON) * 0.25;
    let check = |sequence: &serde_json::Value, node_type: &str, nodes: u64, acceleration: [f64; 3]| {
        let targets = &sequence["targets"][node_type];
        assert_eq!(targets["nodes"], nodes, "{sequence}");
        for bound in ["min_m", "max_m"] {
            for (i, a) in acceleration.iter().enumerate() {
                let found = targets[bound][i].as_f64().expect("number");
                let expected = a * DT * DT;
                assert!(
                    (found - expected).abs() <= tolerance_m,
                    "{node_type} {bound}[{i}]: {found} != {expected}"
                );
            }
        }
    };
    for sequence in sequences {
        assert_eq!(sequence["targets_shape"], serde_json::json!([8, 12, 3]));
        assert_eq!(sequence["targets_finite"], true);
        assert_eq!(sequence["shapes"]["world_pos"], serde_json::json!([10, 12, 3]));
        assert_eq!(sequence["dtypes"]["world_pos"], "float32");
        assert_eq!(sequence["dtypes"]["node_type"], "int32");
        assert_eq!(sequence["shapes"]["edges"], serde_json::json!([10, 2]));
    }
    check(&sequences[0], "0", 10, gravity);
    check(&sequences[0], "3", 2, [0.0; 3]);
    check(&sequences[1], "0", 12, slower);
    assert_eq!(sequences[1]["source"], "b.mcap");
    assert!((seen["dt"].as_f64().expect("dt") - DT).abs() < 1e-15);
}

/// Whether `python3` with h5py and numpy can run here (else the caller skips, saying why).
fn python_with_h5py() -> bool {
    match Command::new("python3").args(["-c", "import h5py, numpy"]).output() {
        Ok(probe) if probe.status.success() => true,
        Ok(probe) => {
            println!("SKIPPED: h5py is not installed: {}", String::from_utf8_lossy(&probe.stderr).trim());
            false
        }
        Err(err) => {
            println!("SKIPPED: python3 cannot be run: {err}");
            false
        }
    }
}
