//! Tests of the training export on small traces written in memory.

use std::io::Cursor;
use std::path::Path;

use ::hdf5::types::{FloatSize, IntSize, TypeDescriptor};

use super::*;
use crate::export::tests::file_names;
use crate::export::{ExportFormat, export_paths};
use crate::{MeshFrame, MeshTopology, Scalars, TraceMetadata, TraceWriter, TraceWriterOptions};

/// Frame spacing of the test traces, in seconds.
const DT: f64 = 0.01;
/// The constant acceleration of every free vertex, in m/s².
const ACCELERATION: [f64; 3] = [0.5, -2.0, -9.81];

/// The rest positions of the test yarn set: two yarns along x, of 3 and 4 vertices.
fn rest_positions() -> Vec<[f64; 3]> {
    let yarn = |y: f64, count: usize| (0..count).map(move |k| [0.1 + 0.01 * k as f64, y, 0.05]);
    yarn(0.0, 3).chain(yarn(0.02, 4)).collect()
}

const RANGES: [[u32; 2]; 2] = [[0, 3], [3, 4]];

/// The vertex positions at frame `k`: the rest state moved with a constant acceleration.
fn positions(k: u64) -> Vec<[f64; 3]> {
    let t = k as f64 * DT;
    rest_positions().iter().map(|p| std::array::from_fn(|i| p[i] + 0.5 * ACCELERATION[i] * t * t)).collect()
}

fn frame(yarns: &str, k: u64) -> YarnFrame {
    YarnFrame {
        yarns: yarns.into(),
        frame: k,
        time_s: k as f64 * DT,
        positions_m: positions(k),
        edge_twist_rad: Vec::new(),
        radii_m: vec![2e-4; 7],
        yarn_ranges: RANGES.to_vec(),
    }
}

/// The nodes of the test set: the first vertex of each yarn is a handle.
fn nodes(yarns: &str) -> YarnNodes {
    YarnNodes {
        yarns: yarns.into(),
        rest_positions_m: rest_positions(),
        node_type: vec![3, 0, 0, 3, 0, 0, 0],
        edges: YarnNodes::chain_edges(&RANGES),
    }
}

/// A trace of the messages `write` writes, with a metadata record and small chunks.
fn trace(write: impl FnOnce(&mut TraceWriter<Cursor<Vec<u8>>>)) -> Vec<u8> {
    let options = TraceWriterOptions::new().chunk_size(2048);
    let mut writer = options.seekable(Cursor::new(Vec::new())).expect("writer");
    writer.write_metadata(&TraceMetadata::new("test", "1.0").with_entry("scene", "fall")).expect("metadata");
    write(&mut writer);
    writer.finish().expect("finish").into_inner()
}

/// A trace of the test set with `/yarn/nodes` (if `with_nodes`), `frames` frames and metrics.
fn yarn_trace(frames: u64, with_nodes: bool) -> Vec<u8> {
    trace(|w| {
        if with_nodes {
            w.write(&nodes("swatch")).expect("nodes");
        }
        for k in 0..frames {
            w.write(&frame("swatch", k)).expect("frame");
            w.write(&Scalars { frame: k, time_s: k as f64 * DT, ..Default::default() }).expect("metrics");
        }
    })
}

fn export(traces: &[(&str, &[u8])], output: &Path) -> Result<ExportStats, ExportError> {
    let inputs = traces.iter().map(|(name, bytes)| ((*name).to_owned(), RecordReader::new(*bytes))).collect();
    export_training(inputs, &TrainingOutput::from_path(output))
}

fn read<T: ::hdf5::H5Type>(file: &File, path: &str) -> (Vec<usize>, Vec<T>) {
    let dataset = file.dataset(path).unwrap_or_else(|e| panic!("{path}: {e}"));
    (dataset.shape(), dataset.read_raw().unwrap_or_else(|e| panic!("{path}: {e}")))
}

fn dtype(file: &File, path: &str) -> TypeDescriptor {
    file.dataset(path).expect("dataset").dtype().expect("dtype").to_descriptor().expect("descriptor")
}

fn meta(dir: &Path) -> TrainingMeta {
    let text = std::fs::read_to_string(dir.join(META_FILE)).expect("meta.json");
    serde_json::from_str(&text).expect("meta json")
}

#[test]
fn the_output_path_names_the_folder_and_the_split() {
    let folder = TrainingOutput::from_path(Path::new("ds"));
    assert_eq!((folder.dir.as_path(), folder.split.as_str()), (Path::new("ds"), "train"));
    assert_eq!(folder.split_path(), Path::new("ds/train.h5"));
    let valid = TrainingOutput::from_path(Path::new("ds/valid.h5"));
    assert_eq!((valid.dir.as_path(), valid.split.as_str()), (Path::new("ds"), "valid"));
    let here = TrainingOutput::from_path(Path::new("test.h5"));
    assert_eq!((here.dir.as_path(), here.split.as_str()), (Path::new("."), "test"));
    assert_eq!(TrainingOutput::from_path(Path::new("ds.v2")).split, "train");
}

#[test]
fn a_sequence_has_the_meshgraphnets_fields_with_their_dtypes_and_values() {
    let dir = tempfile::tempdir().expect("tempdir");
    let bytes = yarn_trace(10, true);
    let stats = export(&[("fall.mcap", &bytes)], dir.path()).expect("export");
    assert_eq!(stats.files_written, 2);
    assert_eq!(stats.frames, BTreeMap::from([("train/0".to_owned(), 10)]));
    assert_eq!(stats.skipped, BTreeMap::from([("/metrics".to_owned(), 10)]));
    assert_eq!(file_names(dir.path()), ["meta.json", "train.h5"], "no temporary file is left");

    let file = File::open(dir.path().join("train.h5")).expect("open");
    let f32 = TypeDescriptor::Float(FloatSize::U4);
    let i32 = TypeDescriptor::Integer(IntSize::U4);
    for (path, expected) in [
        ("0/world_pos", &f32),
        ("0/mesh_pos", &f32),
        ("0/radius", &f32),
        ("0/node_type", &i32),
        ("0/edges", &i32),
    ] {
        assert_eq!(&dtype(&file, path), expected, "{path}");
    }
    assert_eq!(dtype(&file, "0/dt"), TypeDescriptor::Float(FloatSize::U8));

    let (shape, world_pos) = read::<f32>(&file, "0/world_pos");
    assert_eq!(shape, [10, 7, 3]);
    let expected: Vec<f32> = (0..10).flat_map(positions).flatten().map(|x| x as f32).collect();
    assert_eq!(world_pos, expected, "f64 positions rounded to f32, frame after frame");
    let rest: Vec<f32> = rest_positions().into_iter().flatten().map(|x| x as f32).collect();
    assert_eq!(read::<f32>(&file, "0/mesh_pos"), (vec![7, 3], rest));
    assert_eq!(read::<i32>(&file, "0/node_type"), (vec![7, 1], vec![3, 0, 0, 3, 0, 0, 0]));
    assert_eq!(read::<i32>(&file, "0/edges"), (vec![5, 2], vec![0, 1, 1, 2, 3, 4, 4, 5, 5, 6]));
    assert_eq!(read::<f32>(&file, "0/radius"), (vec![7, 1], vec![2e-4; 7]));
    let dt: f64 = file.dataset("0/dt").expect("dt").read_scalar().expect("read");
    assert!((dt - DT).abs() <= 1e-15, "{dt}");
    let group = file.group("0").expect("group");
    let attr = |name: &str| -> String {
        let value: ::hdf5::types::VarLenUnicode = group.attr(name).expect(name).read_scalar().expect("read");
        value.as_str().to_owned()
    };
    assert_eq!((attr("source"), attr("yarns")), ("fall.mcap".to_owned(), "swatch".to_owned()));
}

#[test]
fn meta_json_describes_the_fields_as_meshgraphnets_does_and_names_the_sources() {
    let dir = tempfile::tempdir().expect("tempdir");
    let bytes = yarn_trace(10, true);
    export(&[("fall.mcap", &bytes)], dir.path()).expect("export");
    let meta = meta(dir.path());
    assert_eq!(meta.format, FORMAT);
    assert_eq!(meta.field_names, ["edges", "mesh_pos", "node_type", "radius", "world_pos"]);
    assert_eq!(meta.trajectory_length, 10);
    let feature = |name: &str| {
        let f = &meta.features[name];
        (f.kind.as_str(), f.shape.clone(), f.dtype.as_str())
    };
    assert_eq!(feature("world_pos"), ("dynamic", vec![10, -1, 3], "float32"));
    assert_eq!(feature("mesh_pos"), ("static", vec![-1, 3], "float32"));
    assert_eq!(feature("node_type"), ("static", vec![-1, 1], "int32"));
    assert_eq!(feature("edges"), ("static", vec![-1, 2], "int32"));
    assert_eq!(feature("radius"), ("static", vec![-1, 1], "float32"));
    assert!((meta.dt - DT).abs() <= 1e-15);
    assert_eq!(meta.units["world_pos"], "m");
    assert_eq!(meta.units["dt"], "s");
    assert_eq!((meta.node_types["NORMAL"], meta.node_types["HANDLE"]), (0, 3));
    assert_eq!(meta.splits["train"], SplitInfo { file: "train.h5".into(), sequences: 1 });
    let [sequence] = meta.sequences.as_slice() else { panic!("{:?}", meta.sequences) };
    assert_eq!((sequence.split.as_str(), sequence.group.as_str()), ("train", "0"));
    assert_eq!((sequence.source.as_str(), sequence.yarns.as_str()), ("fall.mcap", "swatch"));
    assert_eq!((sequence.trajectory_length, sequence.nodes, sequence.edges), (10, 7, 5));
    assert!(sequence.from_yarn_nodes && sequence.truncation.is_none());
    assert_eq!(sequence.trace_metadata[0]["producer_name"], "test");
    assert_eq!(sequence.trace_metadata[0]["scene"], "fall");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join(META_FILE)).expect("read"))
            .expect("json");
    assert_eq!(json["features"]["world_pos"]["type"], "dynamic", "MeshGraphNets' key is `type`");
}

#[test]
fn without_yarn_nodes_the_first_frame_is_the_rest_state_and_every_node_is_normal() {
    let dir = tempfile::tempdir().expect("tempdir");
    let bytes = yarn_trace(4, false);
    export(&[("fall.mcap", &bytes)], dir.path()).expect("export");
    let file = File::open(dir.path().join("train.h5")).expect("open");
    let first: Vec<f32> = positions(0).into_iter().flatten().map(|x| x as f32).collect();
    assert_eq!(read::<f32>(&file, "0/mesh_pos").1, first);
    assert_eq!(read::<i32>(&file, "0/node_type").1, [0; 7]);
    assert_eq!(read::<i32>(&file, "0/edges").1, [0, 1, 1, 2, 3, 4, 4, 5, 5, 6], "consecutive vertices");
    assert!(!meta(dir.path()).sequences[0].from_yarn_nodes);
}

#[test]
fn each_trace_and_each_yarn_set_is_a_sequence() {
    let dir = tempfile::tempdir().expect("tempdir");
    let first = yarn_trace(5, true);
    let two_sets = trace(|w| {
        w.write(&nodes("b")).expect("nodes");
        for k in 0..6 {
            w.write(&frame("a", k)).expect("a");
            w.write(&frame("b", k)).expect("b");
        }
    });
    let stats = export(&[("one.mcap", &first), ("two.mcap", &two_sets)], dir.path()).expect("export");
    assert_eq!(stats.frames.values().sum::<u64>(), 5 + 6 + 6);
    let meta = meta(dir.path());
    let described: Vec<(&str, &str, &str, u64, bool)> = meta
        .sequences
        .iter()
        .map(|s| {
            (s.group.as_str(), s.source.as_str(), s.yarns.as_str(), s.trajectory_length, s.from_yarn_nodes)
        })
        .collect();
    assert_eq!(
        described,
        [
            ("0", "one.mcap", "swatch", 5, true),
            ("1", "two.mcap", "a", 6, false),
            ("2", "two.mcap", "b", 6, true)
        ]
    );
    assert_eq!(meta.trajectory_length, -1, "the sequences differ in length");
    assert_eq!(meta.features["world_pos"].shape, [-1, -1, 3]);
    assert_eq!(meta.splits["train"].sequences, 3);
    let file = File::open(dir.path().join("train.h5")).expect("open");
    assert_eq!(read::<f32>(&file, "2/world_pos").0, [6, 7, 3]);
    assert_eq!(read::<i32>(&file, "2/node_type").1, [3, 0, 0, 3, 0, 0, 0]);
}

#[test]
fn frames_are_appended_one_at_a_time_into_a_chunked_dataset() {
    let dir = tempfile::tempdir().expect("tempdir");
    let frames = 3000;
    let bytes = yarn_trace(frames, true);
    export(&[("long.mcap", &bytes)], dir.path()).expect("export");
    let file = File::open(dir.path().join("train.h5")).expect("open");
    let world_pos = file.dataset("0/world_pos").expect("world_pos");
    assert_eq!(world_pos.shape(), [frames as usize, 7, 3]);
    let chunk = world_pos.chunk().expect("chunked");
    assert_eq!(chunk[1..], [7, 3], "chunks of whole frames");
    assert!(chunk[0] < frames as usize, "several chunks: {chunk:?}");
    assert!(world_pos.is_resizable(), "an unlimited first dimension");
    let last: Vec<f32> = positions(frames - 1).into_iter().flatten().map(|x| x as f32).collect();
    let row: Vec<f32> =
        world_pos.read_slice_1d::<f32, _>((frames as usize - 1, 6, ..)).expect("read").to_vec();
    assert_eq!(row, last[18..]);
}

#[test]
fn a_non_uniform_time_step_is_refused_naming_the_frame() {
    let dir = tempfile::tempdir().expect("tempdir");
    let bytes = trace(|w| {
        for k in 0..8 {
            let mut f = frame("swatch", k);
            if k >= 5 {
                f.time_s += 0.5 * DT;
            }
            w.write(&f).expect("frame");
        }
    });
    let err = export(&[("jump.mcap", &bytes)], dir.path()).expect_err("non-uniform");
    let text = err.to_string();
    assert!(
        text.starts_with("jump.mcap, yarns \"swatch\", frame 5: the time step from the previous frame is"),
        "{text}"
    );
    assert!(matches!(err, ExportError::InvalidFrame { frame: 5, .. }), "{err:?}");
    assert!(file_names(dir.path()).is_empty(), "nothing is left behind: {:?}", file_names(dir.path()));
}

#[test]
fn a_time_step_within_the_tolerance_is_accepted_and_a_static_solve_is_refused() {
    let dir = tempfile::tempdir().expect("tempdir");
    let jitter = trace(|w| {
        for k in 0..6 {
            let mut f = frame("swatch", k);
            f.time_s *= 1.0 + if k % 2 == 0 { 1e-13 } else { -1e-13 };
            w.write(&f).expect("frame");
        }
    });
    export(&[("jitter.mcap", &jitter)], dir.path()).expect("rounding-level jitter passes");
    let still = trace(|w| {
        for k in 0..4 {
            w.write(&YarnFrame { time_s: 0.0, ..frame("tile", k) }).expect("frame");
        }
    });
    let err = export(&[("solve.mcap", &still)], &dir.path().join("static")).expect_err("no time step");
    assert!(err.to_string().contains("frame 1: time_s = 0 s does not increase"), "{err}");
}

#[test]
fn inputs_the_layout_cannot_hold_are_refused_clearly() {
    let dir = tempfile::tempdir().expect("tempdir");
    let refused =
        |bytes: Vec<u8>| export(&[("t.mcap", &bytes)], dir.path()).expect_err("refused").to_string();

    let mesh_only = trace(|w| {
        let topology = MeshTopology {
            triangles: vec![[0, 1, 2]],
            rest_positions_m: vec![[0.0; 3]; 3],
            name: "m".into(),
        };
        w.write(&topology).expect("topology");
        w.write(&MeshFrame { mesh: "m".into(), frame: 0, time_s: 0.0, positions_m: vec![[0.0; 3]; 3] })
            .expect("frame");
    });
    let text = refused(mesh_only);
    assert!(text.contains("t.mcap: no /yarn/frame message"), "{text}");

    let growing = trace(|w| {
        w.write(&frame("swatch", 0)).expect("frame");
        let mut more = frame("swatch", 1);
        more.positions_m.push([0.0; 3]);
        more.radii_m.push(2e-4);
        more.yarn_ranges[1][1] += 1;
        w.write(&more).expect("frame");
    });
    let text = refused(growing);
    assert!(
        text.contains("yarns \"swatch\", frame 1: 8 vertices, but the sequence's first frame has 7"),
        "{text}"
    );

    let text = refused(yarn_trace(2, true));
    assert!(text.contains("2 frames: a training sequence needs at least 3"), "{text}");

    let late_nodes = trace(|w| {
        w.write(&frame("swatch", 0)).expect("frame");
        w.write(&nodes("swatch")).expect("nodes");
    });
    let text = refused(late_nodes);
    assert!(text.contains("/yarn/nodes comes after the set's first frame (frame 0)"), "{text}");

    let mut short = nodes("swatch");
    short.rest_positions_m.pop();
    short.node_type.pop();
    short.edges.pop();
    let text = refused(trace(|w| {
        w.write(&short).expect("nodes");
        w.write(&frame("swatch", 0)).expect("frame");
    }));
    assert!(text.contains("frame 0: 7 vertices, but the set's /yarn/nodes has 6"), "{text}");

    let mut obstacle = nodes("swatch");
    obstacle.node_type[2] = 9;
    let text = refused(trace(|w| w.write(&obstacle).expect("nodes")));
    assert!(text.contains("node 2 has type 9, not a MeshGraphNets NodeType code"), "{text}");

    let mut wider = frame("swatch", 1);
    wider.radii_m[4] = 3e-4;
    let text = refused(trace(|w| {
        w.write(&frame("swatch", 0)).expect("frame");
        w.write(&wider).expect("frame");
    }));
    assert!(text.contains("frame 1: the radius of vertex 4 is 0.0003 m"), "{text}");
    assert!(file_names(dir.path()).is_empty(), "{:?}", file_names(dir.path()));
}

#[test]
fn every_sequence_must_have_the_same_time_step() {
    let dir = tempfile::tempdir().expect("tempdir");
    let a = yarn_trace(4, true);
    let b = trace(|w| {
        for k in 0..4 {
            w.write(&YarnFrame { time_s: 2.0 * DT * k as f64, ..frame("swatch", k) }).expect("frame");
        }
    });
    let err = export(&[("a.mcap", &a), ("b.mcap", &b)], dir.path()).expect_err("two time steps");
    let text = err.to_string();
    assert!(text.starts_with("b.mcap, yarns \"swatch\": frame spacing dt = 0.0"), "{text}");
    assert!(text.contains(" s differs from dt = 0.0"), "{text}");
    assert!(text.contains("of train/0 (a.mcap, yarns \"swatch\")"), "{text}");
}

#[test]
fn splits_exported_into_one_folder_share_meta_json() {
    let dir = tempfile::tempdir().expect("tempdir");
    let bytes = yarn_trace(5, true);
    export(&[("a.mcap", &bytes), ("b.mcap", &bytes)], dir.path()).expect("train");
    export(&[("c.mcap", &bytes)], &dir.path().join("valid.h5")).expect("valid");
    assert_eq!(file_names(dir.path()), ["meta.json", "train.h5", "valid.h5"]);
    let meta = meta(dir.path());
    assert_eq!(meta.splits["train"].sequences, 2);
    assert_eq!(meta.splits["valid"], SplitInfo { file: "valid.h5".into(), sequences: 1 });
    let listed: Vec<(&str, &str, &str)> =
        meta.sequences.iter().map(|s| (s.split.as_str(), s.group.as_str(), s.source.as_str())).collect();
    assert_eq!(listed, [("train", "0", "a.mcap"), ("train", "1", "b.mcap"), ("valid", "0", "c.mcap")]);
    assert_eq!(meta.trajectory_length, 5);

    // Exported again, a split is replaced; another time step is refused and changes nothing.
    export(&[("d.mcap", &bytes)], dir.path()).expect("train again");
    assert_eq!(self::meta(dir.path()).splits["train"].sequences, 1);
    let slow = trace(|w| {
        for k in 0..4 {
            w.write(&YarnFrame { time_s: 3.0 * DT * k as f64, ..frame("swatch", k) }).expect("frame");
        }
    });
    let before = std::fs::read(dir.path().join(META_FILE)).expect("read");
    let err = export(&[("slow.mcap", &slow)], &dir.path().join("test.h5")).expect_err("other dt");
    assert!(err.to_string().contains("of the other splits in the folder's meta.json"), "{err}");
    assert_eq!(std::fs::read(dir.path().join(META_FILE)).expect("read"), before);
    assert_eq!(file_names(dir.path()), ["meta.json", "train.h5", "valid.h5"]);
}

#[test]
fn a_folder_with_another_meta_json_is_refused() {
    let dir = tempfile::tempdir().expect("tempdir");
    std::fs::write(dir.path().join(META_FILE), r#"{"field_names": ["cells"], "dt": 0.02}"#).expect("write");
    let bytes = yarn_trace(4, true);
    let err = export(&[("a.mcap", &bytes)], dir.path()).expect_err("foreign meta");
    assert!(err.to_string().contains("is not the meta.json of a yarnhom training set"), "{err}");
}

#[test]
fn a_truncated_trace_gives_the_frames_before_the_cut() {
    let dir = tempfile::tempdir().expect("tempdir");
    let full = trace(|w| {
        for k in 0..200 {
            w.write(&frame("swatch", k)).expect("frame");
        }
    });
    let stats = export(&[("cut.mcap", &full[..full.len() / 2])], dir.path()).expect("export");
    let truncation = stats.truncation.expect("truncated");
    let frames = stats.frames["train/0"];
    assert!((MIN_FRAMES..200).contains(&frames), "{frames}");
    let meta = meta(dir.path());
    assert_eq!(meta.sequences[0].truncation, Some(truncation));
    assert_eq!(meta.sequences[0].trajectory_length, frames);
}

#[test]
fn only_the_training_set_takes_several_traces() {
    let dir = tempfile::tempdir().expect("tempdir");
    let inputs = ["a.mcap".to_owned(), "b.mcap".to_owned()];
    let err = export_paths(ExportFormat::Obj, &inputs, dir.path()).expect_err("two inputs");
    assert_eq!(
        err.to_string(),
        "--format obj exports one trace, 2 were given (only `training` takes several)"
    );
    let err = export_paths(ExportFormat::Training, &inputs, dir.path()).expect_err("missing files");
    assert!(err.to_string().contains("cannot open the trace a.mcap"), "{err}");
    let a = dir.path().join("a.mcap");
    std::fs::write(&a, yarn_trace(3, true)).expect("write");
    let inputs = [a.display().to_string()];
    let stats = export_paths(ExportFormat::Training, &inputs, &dir.path().join("ds")).expect("export");
    assert_eq!(stats.frames["train/0"], 3);
}
