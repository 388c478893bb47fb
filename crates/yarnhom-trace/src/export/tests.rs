//! Tests of the exports on small traces written in memory.

use std::collections::BTreeMap;
use std::io::Cursor;
use std::path::Path;
use std::sync::Arc;

use super::*;
use crate::{
    MeshFrame, MeshTopology, RveSample, Scalars, SolverIteration, SolverStep, TetFrame, TetTopology,
    TraceMetadata, TraceWriter, TraceWriterOptions, YarnFrame,
};

/// Vertex positions of the test mesh at `frame`: not round numbers, so printing must be exact.
fn mesh_positions(frame: u64) -> Vec<[f64; 3]> {
    let t = frame as f64 / 3.0;
    vec![[0.0, 0.0, t], [1.0 / 3.0, 0.0, 0.1 * t], [0.0, 2.0 / 7.0, -t], [1.0 / 3.0, 2.0 / 7.0, 1e-17 + t]]
}

fn mesh_topology() -> MeshTopology {
    MeshTopology {
        triangles: vec![[0, 1, 2], [1, 3, 2]],
        rest_positions_m: vec![[0.0, 0.0, 0.0], [0.5, 0.0, 0.0], [0.0, 0.25, 0.0], [0.5, 0.25, 0.0]],
        name: "cloth".into(),
    }
}

fn yarn_frame(frame: u64) -> YarnFrame {
    YarnFrame {
        yarns: "tile".into(),
        frame,
        time_s: 0.0,
        positions_m: (0..5).map(|k| [k as f64 * 1e-3, frame as f64 * 1e-4, 0.0]).collect(),
        edge_twist_rad: vec![0.1, 0.2, 0.0, 0.3, 0.0],
        radii_m: vec![1e-4; 5],
        yarn_ranges: vec![[0, 3], [3, 2]],
    }
}

fn tet_topology() -> TetTopology {
    TetTopology {
        name: "block".into(),
        tets: vec![[0, 1, 2, 3]],
        rest_positions_m: vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        element_values: BTreeMap::from([("gamma".to_owned(), vec![0.5])]),
    }
}

/// Metrics of frame `frame`: `energy_j` in frames 0 and 1, `kinetic_energy_j` from frame 1.
fn metrics(frame: u64) -> Scalars {
    let mut values = BTreeMap::new();
    if frame < 2 {
        values.insert("energy_j".to_owned(), 1.0 + frame as f64);
    }
    if frame >= 1 {
        values.insert("kinetic_energy_j".to_owned(), 10.0 * frame as f64);
    }
    Scalars { frame, time_s: 0.01 * frame as f64, values }
}

/// Two RVE samples: a converged one with stress, an unconverged one without.
fn rve_samples() -> [RveSample; 2] {
    let converged = RveSample {
        frame: 0,
        term: "sx".into(),
        grid_index: [3, 0],
        strain: [1.1, 0.0, 1.0, 0.0, 0.0],
        converged: true,
        energy_density_j_m2: Some(0.25),
        stress: Some([1.0, 2.0, 3.0, 4.0, 5.0]),
        iterations: 7,
        ..Default::default()
    };
    let failed = RveSample {
        frame: 1,
        term: "sx,sa".into(),
        grid_index: [1, 2],
        iterations: 50,
        ..Default::default()
    };
    [converged, failed]
}

/// An unknown topic's message, copied into the trace undecoded.
fn unknown_message() -> mcap::Message<'static> {
    let channel = mcap::Channel {
        id: 1,
        topic: "/other/thing".into(),
        schema: None,
        message_encoding: "json".into(),
        metadata: BTreeMap::new(),
    };
    mcap::Message {
        channel: Arc::new(channel),
        sequence: 0,
        log_time: 0,
        publish_time: 0,
        data: b"{}".to_vec().into(),
    }
}

/// The test trace: a mesh of 2 triangles and 3 frames, a tet mesh with 1 frame, a yarn frame,
/// metrics with a value appearing from frame 1, solver steps and an unknown topic.
fn sample_trace() -> Vec<u8> {
    let mut writer = TraceWriter::new(Cursor::new(Vec::new())).expect("writer");
    writer
        .write_metadata(&TraceMetadata::new("test", "1.2.3").with_entry("scene", "unit"))
        .expect("metadata");
    writer.write(&mesh_topology()).expect("topology");
    writer.write(&tet_topology()).expect("tet topology");
    for frame in 0..3 {
        let time_s = 0.01 * frame as f64;
        writer
            .write(&MeshFrame { mesh: "cloth".into(), frame, time_s, positions_m: mesh_positions(frame) })
            .expect("frame");
        writer.write(&metrics(frame)).expect("metrics");
        let step = SolverStep {
            frame,
            time_s,
            newton_iterations: 3,
            residual: 1e-9,
            converged: true,
            ..Default::default()
        };
        writer.write(&step).expect("solver");
    }
    let tet_positions = vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 2.0]];
    writer
        .write(&TetFrame { mesh: "block".into(), frame: 0, time_s: 0.0, positions_m: tet_positions })
        .expect("tet frame");
    writer.write(&yarn_frame(0)).expect("yarns");
    for sample in rve_samples() {
        writer.write(&sample).expect("rve sample");
    }
    let iteration = SolverIteration {
        iteration: 4,
        energy_j: 2.5,
        residual: 1e-3,
        step_length: 1.0,
        ..Default::default()
    };
    writer.write(&iteration).expect("solver iteration");
    writer.write_message(0, &unknown_message()).expect("unknown");
    writer.finish().expect("finish").into_inner()
}

/// A trace of `frames` frames of the test mesh in small chunks, to be cut.
fn long_trace(frames: u64) -> Vec<u8> {
    let mut writer =
        TraceWriterOptions::new().chunk_size(400).seekable(Cursor::new(Vec::new())).expect("writer");
    writer.write(&mesh_topology()).expect("topology");
    for frame in 0..frames {
        let positions_m = mesh_positions(frame);
        writer
            .write(&MeshFrame { mesh: "cloth".into(), frame, time_s: 0.01 * frame as f64, positions_m })
            .expect("frame");
    }
    writer.finish().expect("finish").into_inner()
}

fn assert_close(found: f64, expected: f64) {
    let tolerance = 1e-12 * expected.abs();
    assert!((found - expected).abs() <= tolerance, "{found} != {expected}");
}

/// The `v`, `vt`, `f` and `l` lines of an OBJ file (indices back to 0-based).
#[derive(Default)]
struct Obj {
    v: Vec<[f64; 3]>,
    vt: Vec<[f64; 2]>,
    f: Vec<[u32; 3]>,
    l: Vec<Vec<u32>>,
}

fn parse_obj(path: &Path) -> Obj {
    let text = std::fs::read_to_string(path).expect("read obj");
    let mut obj = Obj::default();
    for line in text.lines() {
        let mut words = line.split_whitespace();
        let kind = words.next().expect("keyword");
        let words: Vec<&str> = words.collect();
        let number = |w: &str| w.parse::<f64>().expect("number");
        let index = |w: &str| w.split('/').next().expect("index").parse::<u32>().expect("index") - 1;
        match kind {
            "v" => obj.v.push([number(words[0]), number(words[1]), number(words[2])]),
            "vt" => obj.vt.push([number(words[0]), number(words[1])]),
            "f" => obj.f.push([index(words[0]), index(words[1]), index(words[2])]),
            "l" => obj.l.push(words.iter().map(|w| index(w)).collect()),
            other => panic!("unexpected OBJ line {other}"),
        }
    }
    obj
}

/// The names of the files in `dir`, sorted.
pub(crate) fn file_names(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .expect("read dir")
        .map(|entry| entry.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

#[test]
fn obj_frames_read_back_to_the_same_positions_and_faces() {
    let dir = tempfile::tempdir().expect("tempdir");
    let stats = export_frames(RecordReader::new(sample_trace().as_slice()), dir.path(), FrameFormat::Obj)
        .expect("export");
    let expected_files =
        ["block_000000.obj", "cloth_000000.obj", "cloth_000001.obj", "cloth_000002.obj", "tile_000000.obj"];
    assert_eq!(file_names(dir.path()), expected_files);
    assert_eq!(stats.files_written, 5);
    assert_eq!(stats.frames["/mesh/cloth"], 3);
    assert_eq!(stats.skipped["/metrics"], 3);
    assert_eq!(stats.skipped["/other/thing"], 1);
    assert_eq!(stats.metadata_records, 1);
    assert_eq!(stats.trace_metadata[0]["producer_name"], "test");
    assert_eq!(stats.trace_metadata[0]["scene"], "unit");
    assert!(stats.truncation.is_none());

    let topology = mesh_topology();
    for frame in 0..3 {
        let obj = parse_obj(&dir.path().join(format!("cloth_{frame:06}.obj")));
        assert_eq!(obj.v.len(), 4);
        for (found, expected) in obj.v.iter().zip(mesh_positions(frame)) {
            (0..3).for_each(|k| assert_close(found[k], expected[k]));
        }
        let rest_xy: Vec<[f64; 2]> = topology.rest_positions_m.iter().map(|p| [p[0], p[1]]).collect();
        assert_eq!(obj.vt, rest_xy);
        assert_eq!(obj.f, topology.triangles);
    }
    let yarns = parse_obj(&dir.path().join("tile_000000.obj"));
    assert_eq!(yarns.v, yarn_frame(0).positions_m);
    assert_eq!(yarns.l, [vec![0, 1, 2], vec![3, 4]]);
    let block = parse_obj(&dir.path().join("block_000000.obj"));
    assert_eq!(
        (block.v.len(), block.vt.len(), block.f.len()),
        (4, 0, 4),
        "a tetrahedron has 4 boundary faces"
    );
}

#[test]
fn ply_frames_have_the_exact_header_and_size() {
    let dir = tempfile::tempdir().expect("tempdir");
    export_frames(RecordReader::new(sample_trace().as_slice()), dir.path(), FrameFormat::Ply)
        .expect("export");
    let bytes = std::fs::read(dir.path().join("cloth_000002.ply")).expect("read ply");
    let header = "ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty double x\nproperty double y\n\
                  property double z\nelement face 2\nproperty list uchar uint vertex_indices\nend_header\n";
    assert_eq!(&bytes[..header.len()], header.as_bytes());
    assert_eq!(bytes.len(), header.len() + 4 * 3 * 8 + 2 * (1 + 3 * 4));
    let body = &bytes[header.len()..];
    let f64_at = |k: usize| f64::from_le_bytes(body[8 * k..8 * k + 8].try_into().expect("8 bytes"));
    let expected = mesh_positions(2);
    (0..12).for_each(|k| assert_eq!(f64_at(k), expected[k / 3][k % 3]));
    let faces = &body[96..];
    assert_eq!(faces[0], 3);
    let u32_at = |k: usize| u32::from_le_bytes(faces[k..k + 4].try_into().expect("4 bytes"));
    assert_eq!([u32_at(1), u32_at(5), u32_at(9), u32_at(14), u32_at(18), u32_at(22)], [0, 1, 2, 1, 3, 2]);

    let yarns = std::fs::read(dir.path().join("tile_000000.ply")).expect("read yarn ply");
    let header = "ply\nformat binary_little_endian 1.0\nelement vertex 5\nproperty double x\nproperty double y\n\
                  property double z\nproperty double radius\nelement edge 3\nproperty uint vertex1\n\
                  property uint vertex2\nend_header\n";
    assert_eq!(&yarns[..header.len()], header.as_bytes());
    assert_eq!(yarns.len(), header.len() + 5 * 4 * 8 + 3 * 2 * 4);
}

#[test]
fn a_frame_before_its_topology_is_an_error_naming_mesh_and_frame() {
    let mut writer = TraceWriter::new(Cursor::new(Vec::new())).expect("writer");
    writer
        .write(&MeshFrame { mesh: "cloth".into(), frame: 7, time_s: 0.0, positions_m: mesh_positions(0) })
        .expect("frame");
    writer.write(&mesh_topology()).expect("topology");
    let trace = writer.finish().expect("finish").into_inner();
    let dir = tempfile::tempdir().expect("tempdir");
    let err = export_frames(RecordReader::new(trace.as_slice()), dir.path(), FrameFormat::Obj)
        .expect_err("no topology");
    assert!(matches!(&err, ExportError::MissingTopology { frame: 7, .. }), "{err:?}");
    let message = err.to_string();
    assert!(message.contains("\"cloth\"") && message.contains("frame 7"), "{message}");
}

#[test]
fn a_frame_with_the_wrong_vertex_count_is_an_error() {
    let mut writer = TraceWriter::new(Cursor::new(Vec::new())).expect("writer");
    writer.write(&mesh_topology()).expect("topology");
    writer
        .write(&MeshFrame { mesh: "cloth".into(), frame: 2, time_s: 0.0, positions_m: vec![[0.0; 3]; 3] })
        .expect("frame");
    let trace = writer.finish().expect("finish").into_inner();
    let dir = tempfile::tempdir().expect("tempdir");
    let err = export_frames(RecordReader::new(trace.as_slice()), dir.path(), FrameFormat::Ply)
        .expect_err("bad count");
    assert!(err.to_string().contains("frame 2: 3 vertex positions, but the topology has 4"), "{err}");
    assert!(file_names(dir.path()).is_empty(), "no file, not even a temporary one");
}

#[test]
fn a_truncated_trace_exports_its_prefix_and_reports_the_truncation() {
    let full = long_trace(60);
    let cut = &full[..full.len() / 2];
    let dir = tempfile::tempdir().expect("tempdir");
    let stats = export_frames(RecordReader::new(cut), dir.path(), FrameFormat::Obj).expect("export");
    let truncation = stats.truncation.expect("truncated");
    let frames = stats.frames["/mesh/cloth"];
    assert!(frames > 0 && frames < 60, "{frames}");
    assert_eq!(truncation.messages_recovered, frames + 1, "the topology and the frames");
    let expected: Vec<String> = (0..frames).map(|frame| format!("cloth_{frame:06}.obj")).collect();
    assert_eq!(file_names(dir.path()), expected);
}

#[cfg(feature = "hdf5")]
mod hdf5_export {
    use ::hdf5::types::VarLenUnicode;

    use super::*;

    fn export_sample(dir: &Path) -> (::hdf5::File, ExportStats) {
        let path = dir.join("trace.h5");
        let stats =
            export_hdf5(RecordReader::new(sample_trace().as_slice()), &path, "sample.mcap").expect("export");
        (::hdf5::File::open(&path).expect("open"), stats)
    }

    fn read<T: ::hdf5::H5Type>(file: &::hdf5::File, path: &str) -> (Vec<usize>, Vec<T>) {
        let dataset = file.dataset(path).unwrap_or_else(|e| panic!("{path}: {e}"));
        (dataset.shape(), dataset.read_raw().expect("read"))
    }

    /// Every dataset under `group`, as absolute paths.
    fn all_datasets(group: &::hdf5::Group) -> Vec<String> {
        let mut found: Vec<String> = group.datasets().expect("datasets").iter().map(|d| d.name()).collect();
        for child in group.groups().expect("groups") {
            found.extend(all_datasets(&child));
        }
        found
    }

    fn manifest(file: &::hdf5::File) -> serde_json::Value {
        let text: VarLenUnicode = file.dataset("manifest").expect("manifest").read_scalar().expect("read");
        serde_json::from_str(text.as_str()).expect("manifest json")
    }

    #[test]
    fn the_streams_are_stacked_by_frame() {
        let dir = tempfile::tempdir().expect("tempdir");
        let (file, stats) = export_sample(dir.path());
        assert_eq!(stats.files_written, 1);
        assert_eq!(stats.skipped, BTreeMap::from([("/other/thing".to_owned(), 1)]));
        let (shape, positions) = read::<f64>(&file, "mesh/cloth/positions_m");
        assert_eq!(shape, [3, 4, 3]);
        let expected: Vec<f64> = (0..3).flat_map(|f| mesh_positions(f).into_iter().flatten()).collect();
        assert_eq!(positions, expected);
        assert_eq!(read::<u64>(&file, "mesh/cloth/frame"), (vec![3], vec![0, 1, 2]));
        assert_eq!(read::<u32>(&file, "mesh/cloth/triangles"), (vec![2, 3], vec![0, 1, 2, 1, 3, 2]));
        assert_eq!(read::<f64>(&file, "mesh/cloth/rest_positions_m").0, [4, 3]);
        assert_eq!(read::<u32>(&file, "tet/block/tets").0, [1, 4]);
        assert_eq!(read::<u32>(&file, "tet/block/triangles").0, [4, 3]);
        assert_eq!(read::<f64>(&file, "tet/block/element/gamma"), (vec![1], vec![0.5]));
        assert_eq!(read::<f64>(&file, "tet/block/positions_m").0, [1, 4, 3]);
        assert_eq!(read::<f64>(&file, "yarns/tile/positions_m").0, [1, 5, 3]);
        assert_eq!(
            read::<f64>(&file, "yarns/tile/edge_twist_rad"),
            (vec![1, 5], yarn_frame(0).edge_twist_rad)
        );
        assert_eq!(read::<f64>(&file, "yarns/tile/radii_m").0, [1, 5]);
        assert_eq!(read::<u32>(&file, "yarns/tile/yarn_ranges"), (vec![2, 2], vec![0, 3, 3, 2]));
        assert_eq!(read::<u8>(&file, "solver/converged"), (vec![3], vec![1, 1, 1]));
        assert_eq!(read::<u32>(&file, "solver/newton_iterations").1, [3, 3, 3]);
        assert_eq!(read::<f64>(&file, "solver_iteration/energy_j"), (vec![1], vec![2.5]));
        assert_eq!(read::<u32>(&file, "solver_iteration/iteration").1, [4]);
        let units: VarLenUnicode = file
            .dataset("metrics/kinetic_energy_j")
            .expect("dataset")
            .attr("units")
            .expect("units")
            .read_scalar()
            .expect("read");
        assert_eq!(units.as_str(), "J");
    }

    #[test]
    fn rve_samples_have_term_indices_and_nan_for_absent_values() {
        let dir = tempfile::tempdir().expect("tempdir");
        let (file, stats) = export_sample(dir.path());
        assert_eq!(stats.frames["/rve_sample"], 2);
        assert_eq!(read::<u32>(&file, "rve_sample/term"), (vec![2], vec![0, 1]));
        let names: Vec<VarLenUnicode> = read(&file, "rve_sample/term_names").1;
        assert_eq!(names.iter().map(VarLenUnicode::as_str).collect::<Vec<_>>(), ["sx", "sx,sa"]);
        assert_eq!(read::<u32>(&file, "rve_sample/grid_index"), (vec![2, 2], vec![3, 0, 1, 2]));
        assert_eq!(read::<f64>(&file, "rve_sample/strain").0, [2, 5]);
        assert_eq!(read::<u8>(&file, "rve_sample/converged").1, [1, 0]);
        assert_eq!(read::<u32>(&file, "rve_sample/iterations").1, [7, 50]);
        let energy = read::<f64>(&file, "rve_sample/energy_density_j_m2").1;
        assert!(energy[0] == 0.25 && energy[1].is_nan(), "{energy:?}");
        let (shape, stress) = read::<f64>(&file, "rve_sample/stress");
        assert_eq!(shape, [2, 5]);
        assert_eq!(stress[..5], [1.0, 2.0, 3.0, 4.0, 5.0]);
        assert!(stress[5..].iter().all(|x| x.is_nan()), "{stress:?}");
    }

    #[test]
    fn metrics_missing_in_a_frame_are_nan_and_late_metrics_are_back_filled() {
        let dir = tempfile::tempdir().expect("tempdir");
        let (file, stats) = export_sample(dir.path());
        assert_eq!(stats.frames["/metrics"], 3);
        let energy = read::<f64>(&file, "metrics/energy_j").1;
        assert_eq!(energy[..2], [1.0, 2.0]);
        assert!(energy[2].is_nan());
        let kinetic = read::<f64>(&file, "metrics/kinetic_energy_j").1;
        assert!(kinetic[0].is_nan(), "back-filled");
        assert_eq!(kinetic[1..], [10.0, 20.0]);
        assert_eq!(read::<f64>(&file, "metrics/time_s").1, [0.0, 0.01, 0.02]);
    }

    #[test]
    fn the_manifest_lists_every_dataset_with_its_shape_and_the_provenance() {
        let dir = tempfile::tempdir().expect("tempdir");
        let (file, _) = export_sample(dir.path());
        let manifest = manifest(&file);
        assert_eq!(manifest["format"], "yarnhom.trace.hdf5");
        assert_eq!(manifest["input"], "sample.mcap");
        assert_eq!(manifest["yarnhom_trace_version"], env!("CARGO_PKG_VERSION"));
        assert_eq!(manifest["trace_metadata"][0]["producer_name"], "test");
        assert_eq!(manifest["trace_metadata"][0]["producer_version"], "1.2.3");
        assert_eq!(manifest["trace_metadata"][0]["scene"], "unit");
        assert_eq!(manifest["skipped_messages"]["/other/thing"], 1);
        assert!(manifest["truncation"].is_null());
        let entries = manifest["datasets"].as_array().expect("datasets");
        let mut listed: Vec<String> =
            entries.iter().map(|e| e["path"].as_str().expect("path").to_owned()).collect();
        let mut present = all_datasets(&file);
        listed.sort();
        present.sort();
        assert_eq!(listed, present);
        for entry in entries {
            let path = entry["path"].as_str().expect("path");
            let dataset = file.dataset(path).expect("dataset");
            assert_eq!(entry["shape"], serde_json::json!(dataset.shape()), "{path}");
            for attr in ["units", "description"] {
                let value: VarLenUnicode = dataset.attr(attr).expect(attr).read_scalar().expect("read");
                assert_eq!(entry[attr].as_str(), Some(value.as_str()), "{path} {attr}");
            }
        }
        let positions = entries.iter().find(|e| e["path"] == "/mesh/cloth/positions_m").expect("positions");
        assert_eq!(positions["dtype"], "float64");
        assert_eq!(positions["units"], "m");
    }

    #[test]
    fn a_truncated_trace_exports_its_prefix() {
        let full = long_trace(60);
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("cut.h5");
        let stats =
            export_hdf5(RecordReader::new(&full[..full.len() / 2]), &path, "cut.mcap").expect("export");
        let truncation = stats.truncation.expect("truncated");
        let frames = stats.frames["/mesh/cloth"] as usize;
        assert_eq!(truncation.messages_recovered as usize, frames + 1);
        let file = ::hdf5::File::open(&path).expect("open");
        assert_eq!(read::<f64>(&file, "mesh/cloth/positions_m").0, [frames, 4, 3]);
        assert_eq!(manifest(&file)["truncation"]["messages_recovered"], frames + 1);
    }

    #[test]
    fn a_failed_export_leaves_nothing_behind() {
        let mut writer = TraceWriter::new(Cursor::new(Vec::new())).expect("writer");
        writer.write(&mesh_topology()).expect("topology");
        writer
            .write(&MeshFrame { mesh: "cloth".into(), frame: 0, time_s: 0.0, positions_m: mesh_positions(0) })
            .expect("frame");
        writer
            .write(&MeshFrame { mesh: "drape".into(), frame: 1, time_s: 0.0, positions_m: mesh_positions(0) })
            .expect("frame");
        let trace = writer.finish().expect("finish").into_inner();
        let dir = tempfile::tempdir().expect("tempdir");
        let err = export_hdf5(RecordReader::new(trace.as_slice()), &dir.path().join("t.h5"), "-")
            .expect_err("no topology");
        assert!(err.to_string().contains("frame 1 of mesh \"drape\""), "{err}");
        assert!(file_names(dir.path()).is_empty(), "{:?}", file_names(dir.path()));
    }

    #[test]
    fn yarn_frames_must_keep_their_shape() {
        let mut writer = TraceWriter::new(Cursor::new(Vec::new())).expect("writer");
        writer.write(&yarn_frame(0)).expect("yarns");
        let mut changed = yarn_frame(1);
        changed.yarn_ranges = vec![[0, 2], [2, 3]];
        writer.write(&changed).expect("yarns");
        let trace = writer.finish().expect("finish").into_inner();
        let dir = tempfile::tempdir().expect("tempdir");
        let err = export_hdf5(RecordReader::new(trace.as_slice()), &dir.path().join("t.h5"), "-")
            .expect_err("shape");
        assert!(err.to_string().contains("yarns \"tile\", frame 1: the yarn ranges differ"), "{err}");
    }
}
