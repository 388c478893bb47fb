//! HDF5 export of the published HYLC patterns: exact round trip through yarnhom's importer, and
//! an independent read with h5py + numpy (`tools/h5py_read_pattern.py`).

#![allow(clippy::unwrap_used)]

use std::path::{Path, PathBuf};
use std::process::Command;

use yarnhom_artifacts::container::{self, InputRef, Provenance};
use yarnhom_artifacts::{AnyArtifact, Header, Pattern, hdf5, pyp};

const PATTERNS: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../shared/data/hylc-patterns");
const TOOL: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../tools/h5py_read_pattern.py");

/// One test at a time in this binary: a Python child forked while another test's thread holds an
/// HDF5 file open inherits that descriptor (HDF5 opens files without close-on-exec) and with it
/// the file's lock, so an import racing the child failed with "unable to lock file".
static ONE_AT_A_TIME: std::sync::Mutex<()> = std::sync::Mutex::new(());

fn serialized() -> std::sync::MutexGuard<'static, ()> {
    ONE_AT_A_TIME.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// Every published pattern, parsed, with the header an import would give it.
fn published() -> Vec<(String, Header, Pattern)> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(PATTERNS)
        .unwrap_or_else(|e| panic!("cannot list {PATTERNS}: {e}"))
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "pyp"))
        .collect();
    files.sort();
    assert!(files.len() >= 6, "expected the 6 published patterns in {PATTERNS}");
    files
        .iter()
        .map(|path| {
            let name = path.file_stem().unwrap().to_string_lossy().into_owned();
            let bytes = std::fs::read(path).unwrap();
            let text = String::from_utf8(bytes.clone()).unwrap();
            let pattern =
                pyp::parse_pyp(&text, &name, None).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            let provenance = Provenance {
                inputs: vec![InputRef {
                    kind: "pyp".into(),
                    content_hash: container::content_hash(&bytes),
                    path: path.display().to_string(),
                }],
                ..Provenance::default()
            };
            let payload = container::payload_of(&pattern).unwrap();
            let header = container::header_for::<Pattern>(&payload, &provenance);
            (name, header, pattern)
        })
        .collect()
}

/// The variants exported per published pattern: as published, and without its rest state.
fn variants(pattern: &Pattern) -> Vec<(&'static str, Pattern)> {
    let mut out = vec![("as published", pattern.clone())];
    if pattern.rest.is_some() {
        out.push(("without rest state", Pattern { rest: None, ..pattern.clone() }));
    }
    out
}

fn export(dir: &Path, file: &str, header: &Header, pattern: &Pattern) -> PathBuf {
    let path = dir.join(file);
    hdf5::export(&path, header, &AnyArtifact::Pattern(pattern.clone()))
        .unwrap_or_else(|e| panic!("export {file}: {e}"));
    path
}

#[test]
fn published_patterns_round_trip_exactly() {
    let _guard = serialized();
    let dir = tempfile::tempdir().unwrap();
    for (name, header, pattern) in published() {
        for (variant, p) in variants(&pattern) {
            let file = format!("{name}-{}.h5", p.rest.is_some());
            let path = export(dir.path(), &file, &header, &p);
            let (h, back) = hdf5::import(&path).unwrap_or_else(|e| panic!("import {file}: {e}"));
            let AnyArtifact::Pattern(back) = back else { panic!("{file}: imported a {}", back.kind()) };
            assert_eq!(back, p, "{name} ({variant})");
            // msgpack stores every f64 bit for bit: equal payloads mean bit-identical floats
            // (-0.0 included), which `==` on f64 does not check.
            assert_eq!(
                container::payload_of(&back).unwrap(),
                container::payload_of(&p).unwrap(),
                "{name} ({variant}): not bit-identical"
            );
            assert_eq!(h.content_hash, container::content_hash(&container::payload_of(&p).unwrap()));
            assert_eq!(
                (&h.producer, &h.created_utc, &h.inputs),
                (&header.producer, &header.created_utc, &header.inputs),
                "{name} ({variant}): header"
            );
            if variant == "as published" {
                assert_eq!(h, header, "{name}: header");
            }
        }
    }
}

/// Make h5py importable (one `pip install` attempt); `Err(reason)` when it cannot be.
fn h5py_available() -> Result<(), String> {
    let probe = || Command::new("python3").args(["-c", "import h5py, numpy"]).output();
    match probe() {
        Ok(out) if out.status.success() => return Ok(()),
        Ok(_) => {}
        Err(e) => return Err(format!("cannot run python3: {e}")),
    }
    let install = Command::new("python3").args(["-m", "pip", "install", "--quiet", "h5py", "numpy"]).output();
    match probe() {
        Ok(out) if out.status.success() => Ok(()),
        Ok(out) => Err(format!(
            "{} (pip: {})",
            String::from_utf8_lossy(&out.stderr).trim(),
            match install {
                Ok(i) => String::from_utf8_lossy(&i.stderr).trim().to_string(),
                Err(e) => e.to_string(),
            }
        )),
        Err(e) => Err(format!("cannot run python3: {e}")),
    }
}

/// Run the h5py reader; its JSON summary, or its exit status and message.
fn h5py_read(path: &Path) -> Result<serde_json::Value, String> {
    let out = Command::new("python3").arg(TOOL).arg(path).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr).trim().to_string();
    if !out.status.success() {
        return Err(format!("exit {:?}: {stderr}", out.status.code()));
    }
    let stdout = String::from_utf8(out.stdout).unwrap();
    assert_eq!(stdout.lines().count(), 1, "one line of JSON: {stdout}");
    serde_json::from_str(&stdout).map_err(|e| format!("bad JSON {stdout:?}: {e}"))
}

/// `a` and `b` agree to the last bit or so (serde_json's default float parser may be one ULP off).
fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 4.0 * f64::EPSILON * a.abs().max(b.abs())
}

fn floats(v: &serde_json::Value) -> Vec<f64> {
    v.as_array().unwrap_or_else(|| panic!("not an array: {v}")).iter().map(|x| x.as_f64().unwrap()).collect()
}

#[test]
fn h5py_reads_published_patterns() {
    let _guard = serialized();
    if let Err(reason) = h5py_available() {
        println!("SKIPPED: h5py cannot be installed: {reason}");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    for (name, header, pattern) in published() {
        for (variant, p) in variants(&pattern) {
            let file = format!("{name}-{}.h5", p.rest.is_some());
            let path = export(dir.path(), &file, &header, &p);
            let summary = h5py_read(&path).unwrap_or_else(|e| panic!("{file}: {e}"));
            let what = format!("{name} ({variant}): {summary}");
            assert_eq!(summary["kind"], "pattern", "{what}");
            assert_eq!(summary["vertices"], p.vertex_count(), "{what}");
            assert_eq!(summary["yarns"], p.yarns.len(), "{what}");
            assert_eq!(summary["has_rest"], p.rest.is_some(), "{what}");
            let period = floats(&summary["period_m"]);
            assert_eq!(period.len(), 2, "{what}");
            assert!(period.iter().zip(&p.period_m).all(|(&a, &b)| close(a, b)), "{what}");
            let radius = floats(&summary["radius_m"]);
            assert_eq!(radius.len(), p.yarns.len(), "{what}");
            assert!(radius.iter().zip(&p.yarns).all(|(&a, y)| close(a, y.radius_m)), "{what}");
        }
    }
}

/// The h5py reader is an independent check: it refuses a file whose yarns reuse a vertex, and so
/// does yarnhom's importer.
#[test]
fn h5py_and_importer_refuse_a_corrupted_export() {
    let _guard = serialized();
    if let Err(reason) = h5py_available() {
        println!("SKIPPED: h5py cannot be installed: {reason}");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let (_, header, pattern) = published().swap_remove(0);
    let path = export(dir.path(), "corrupt.h5", &header, &pattern);
    h5py_read(&path).unwrap();
    let script = "import sys, h5py\n\
                  with h5py.File(sys.argv[1], 'r+') as f:\n    \
                  v = f['yarns/vertices']\n    v[0] = v[1]\n";
    let status = Command::new("python3").args(["-c", script]).arg(&path).status().unwrap();
    assert!(status.success());
    let e = h5py_read(&path).unwrap_err();
    assert!(e.contains("used 2 times"), "{e}");
    let e = hdf5::import(&path).unwrap_err();
    assert!(e.to_string().contains("already used"), "{e}");
}
