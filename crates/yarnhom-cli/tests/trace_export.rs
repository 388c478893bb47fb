//! `yarnhom trace export`: a simulated drape as OBJ and PLY frames and as an HDF5 training file
//! (read back with h5py when it is installed), truncated inputs, and refused arguments.

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

    let probe = Command::new("python3").args(["-c", "import h5py, numpy"]).output();
    match probe {
        Ok(probe) if probe.status.success() => {}
        Ok(probe) => {
            return println!(
                "SKIPPED: h5py is not installed: {}",
                String::from_utf8_lossy(&probe.stderr).trim()
            );
        }
        Err(err) => return println!("SKIPPED: python3 cannot be run: {err}"),
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
