//! Yarn-level traces as a training set for learned simulators, in the layout of MeshGraphNets
//! (Pfaff et al. 2021) as its h5py-based PyTorch ports read it (feature `hdf5`):
//! `yarnhom trace export --format training TRACE... -o DIR`, or [`export_training`].
//!
//! # Layout
//!
//! A folder holding `meta.json` and one HDF5 file per split, `<split>.h5`. The split is `train`
//! when the output is given as a folder `DIR`, and `SPLIT` when it is given as `DIR/SPLIT.h5`
//! (`-o ds/valid.h5`, `-o ds/test.h5`): exporting the splits one after the other into the same
//! folder builds one data set, whose `meta.json` lists them all. Each input trace gives one
//! sequence per yarn set (a set is the `yarns` name of its `/yarn/frame` messages), stored as
//! the group `/<index>` of the split's file: `/0`, `/1`, ... in the order of the inputs, and
//! within an input in the order of the sets' first frames. `T` frames, `N` nodes (the yarn
//! vertices, yarn after yarn as in the frames), `E` edges:
//!
//! | dataset | type, shape | units | meaning |
//! |---|---|---|---|
//! | `/<i>/world_pos` | f32 `[T, N, 3]` | m | node positions of each frame (`dynamic`) |
//! | `/<i>/mesh_pos` | f32 `[N, 3]` | m | rest positions: the `rest_positions_m` of the set's `/yarn/nodes`, else the first frame's positions |
//! | `/<i>/node_type` | i32 `[N, 1]` | 1 | MeshGraphNets `NodeType` code: 0 `NORMAL` (free), 3 `HANDLE` (prescribed motion); all 0 without `/yarn/nodes` |
//! | `/<i>/edges` | i32 `[E, 2]` | 1 | the yarn segments as 0-based node pairs: the `edges` of `/yarn/nodes`, else the consecutive vertices of each yarn range |
//! | `/<i>/radius` | f32 `[N, 1]` | m | yarn radius at each node (the same in every frame) |
//! | `/<i>/dt` | f64, scalar | s | frame spacing: (last time - first time) / (T - 1) |
//!
//! Every dataset has the string attributes `units` and `description`; each group has `source`
//! (the input trace as given) and `yarns` (the set's name); the root has `format`
//! (`yarnhom.trace.training`), `split` and `yarnhom_trace_version`. `world_pos` is chunked
//! (whole frames, about 64 KiB per chunk) with an unlimited first dimension and grows by one
//! frame per message; the other datasets are written once. Numbers are little-endian.
//!
//! `meta.json` ([`TrainingMeta`]) keeps MeshGraphNets' keys and adds provenance:
//!
//! ```json
//! {
//!   "format": "yarnhom.trace.training", "format_version": 1, "yarnhom_trace_version": "0.1.0",
//!   "simulator": "yarnhom",
//!   "field_names": ["edges", "mesh_pos", "node_type", "radius", "world_pos"],
//!   "trajectory_length": 10,
//!   "features": {
//!     "edges": {"type": "static", "shape": [-1, 2], "dtype": "int32"},
//!     "mesh_pos": {"type": "static", "shape": [-1, 3], "dtype": "float32"},
//!     "node_type": {"type": "static", "shape": [-1, 1], "dtype": "int32"},
//!     "radius": {"type": "static", "shape": [-1, 1], "dtype": "float32"},
//!     "world_pos": {"type": "dynamic", "shape": [10, -1, 3], "dtype": "float32"}
//!   },
//!   "dt": 0.01,
//!   "units": {"dt": "s", "edges": "1", "mesh_pos": "m", "node_type": "1", "radius": "m", "world_pos": "m"},
//!   "node_types": {"HANDLE": 3, "NORMAL": 0, "SIZE": 9},
//!   "splits": {"train": {"file": "train.h5", "sequences": 2}},
//!   "sequences": [
//!     {"split": "train", "group": "0", "source": "a.mcap", "yarns": "stockinette",
//!      "trajectory_length": 10, "nodes": 12, "edges": 10, "dt": 0.01, "first_frame": 0,
//!      "first_time_s": 0.0, "from_yarn_nodes": true, "truncation": null,
//!      "trace_metadata": [{"producer_name": "yarnhom yls simulate", "...": "..."}]},
//!     ...
//!   ]
//! }
//! ```
//!
//! A shape's -1 is a size that varies between sequences, as in MeshGraphNets; the frame count
//! is `trajectory_length` when every sequence of every split has the same one, else -1 too
//! (each sequence's is in `sequences`). The learned quantity of MeshGraphNets' cloth model is
//! the acceleration target `world_pos[t+1] - 2 world_pos[t] + world_pos[t-1]` (in metres per
//! frame²; divided by `dt²` in m/s²): `tools/training_example.py` computes it from a data set
//! with h5py and numpy alone.
//!
//! # Why this layout
//!
//! DeepMind's MeshGraphNets stores a data set as `meta.json` plus one TFRecord file per split.
//! The PyTorch ports that most people train with convert those records into one HDF5 file per
//! split, `<split>.h5`, with one group per trajectory named by its index, and their loaders open
//! `<split>.h5` with h5py, list the trajectories with `keys()` and read `file[key][field]`
//! (e.g. `meshGraphNets_pytorch`'s `parse_tfrecord.py` and `dataset/fpc.py`). This layout is
//! that one, so those loaders read it without a conversion step, and `meta.json` keeps the
//! keys (`field_names`, `trajectory_length`, `features` with `type`, `shape`, `dtype`) that
//! code written against DeepMind's loader looks up. One file per split, not per sequence,
//! keeps a split to one open file; one group per sequence lets sequences differ in node count
//! (a small tile and a large swatch in one set). The differences: static fields are stored once
//! per sequence (`[N, 3]`), neither with the leading 1 of the TFRecords' `[1, -1, 3]` nor tiled
//! over the frames as the converters do (`np.broadcast_to` does that without a copy), and the
//! graph is given as `edges` (yarns are polylines, not triangles: there is no `cells`).
//!
//! Positions are f32, as in MeshGraphNets and as the loaders expect; an acceleration target
//! computed from them carries a rounding error of a few f32 ulps of the positions (about
//! 1e-8 m for coordinates of 0.1 m), which may matter for small time steps. No NPZ variant is
//! written: NPZ is a zip archive of `.npy` files (a new dependency), and it cannot grow frame by
//! frame as a chunked HDF5 dataset does.
//!
//! # Rules
//!
//! - Several yarn sets in one trace (e.g. traces of separate runs joined by `trace merge`) are
//!   exported as separate sequences: the learned simulator sees no interaction between them.
//! - A trace without any `/yarn/frame` message is an error, as is a sequence of fewer than 3
//!   frames (one acceleration target needs the previous, current and next positions).
//! - Every frame of a set must have the first frame's vertex count, yarn ranges and radii, and
//!   finite positions; times must increase with a uniform spacing: each spacing must equal the
//!   first within [`DT_TOLERANCE`] (relative), else the error names the frame (resample, or
//!   take a uniform subset with `yarnhom trace select`/`decimate`). Every sequence of the data
//!   set (those already in the folder's `meta.json` included) must have the same `dt` within
//!   the same tolerance.
//! - `/yarn/nodes` must come before its set's first frame, match its vertex count, index only
//!   its vertices, and use codes below `SIZE` (9); a second one for the same set must equal the
//!   first. Messages on other topics are skipped and counted.
//! - Memory is bounded independently of the trace's length: one message at a time, plus for
//!   each yarn set of the trace being read its first frame's yarn ranges and radii (and its
//!   `/yarn/nodes` until its first frame).
//! - A truncated trace is exported up to the cut; `sequences[i].truncation` says what was lost.
//! - The split's file and then `meta.json` are each written to a temporary file and renamed into
//!   place: a failed export leaves the folder as it was. A split exported again is replaced;
//!   the other splits' entries in `meta.json` are kept.

use std::collections::BTreeMap;
use std::io::Read;
use std::path::{Path, PathBuf};

use ::hdf5::{File, Group};
use yarnhom_artifacts::hdf5::layer::{Spec, create_group, write_str_attr};
use yarnhom_artifacts::{AtomicFile, write_atomic};

use super::geometry::{check_indices, check_yarn_frame};
use super::hdf5::{Catalog, Column, h5_error};
use super::{ExportError, ExportStats, for_each_message};
use crate::records::RecordReader;
use crate::{TraceMessage, YarnFrame, YarnNodes, open_records};

mod meta;
#[cfg(test)]
mod tests;

pub use meta::{Feature, SequenceInfo, SplitInfo, TrainingMeta};

/// The `format` of `meta.json` and of the split files' root attribute.
pub const FORMAT: &str = "yarnhom.trace.training";
/// The `format_version` of `meta.json`: the version of the layout.
pub const FORMAT_VERSION: u32 = 1;
/// The name of the data set's description in its folder.
pub const META_FILE: &str = "meta.json";
/// The split written when the output is given as a folder.
pub const DEFAULT_SPLIT: &str = "train";
/// How far (relative) a frame spacing may stray from the first spacing of its sequence, and a
/// sequence's `dt` from the data set's.
pub const DT_TOLERANCE: f64 = 1e-9;
/// The fewest frames of a sequence: one acceleration target needs three positions.
pub const MIN_FRAMES: u64 = 3;

/// Where a training export goes: the data set's folder and the split.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TrainingOutput {
    /// The folder of `meta.json` and the split files, created if needed.
    pub dir: PathBuf,
    /// The split's name (`train`, `valid`, `test`, ...): its file is `<split>.h5`.
    pub split: String,
}

impl TrainingOutput {
    /// The output named by a path: `DIR/SPLIT.h5` is the split `SPLIT` of the data set in `DIR`;
    /// anything else is a folder, whose split is [`DEFAULT_SPLIT`].
    pub fn from_path(output: &Path) -> Self {
        let split = output.extension().filter(|e| *e == "h5").and(output.file_stem());
        match split {
            Some(split) if !split.is_empty() => {
                let dir = output.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
                Self { dir: dir.to_path_buf(), split: split.to_string_lossy().into_owned() }
            }
            _ => Self { dir: output.to_path_buf(), split: DEFAULT_SPLIT.to_owned() },
        }
    }

    /// The split's HDF5 file.
    pub fn split_path(&self) -> PathBuf {
        self.dir.join(split_file_name(&self.split))
    }

    /// The data set's `meta.json`.
    pub fn meta_path(&self) -> PathBuf {
        self.dir.join(META_FILE)
    }
}

/// The file name of a split.
fn split_file_name(split: &str) -> String {
    format!("{split}.h5")
}

/// Exports the traces at `inputs` (paths; `-` is standard input) as the training set at
/// `output` (a folder, or `DIR/SPLIT.h5`: see [`TrainingOutput::from_path`]). Every input is
/// opened before anything is written.
pub fn export_training_paths(inputs: &[String], output: &Path) -> Result<ExportStats, ExportError> {
    let opened = inputs
        .iter()
        .map(|path| Ok((path.clone(), open_records(path)?)))
        .collect::<Result<Vec<_>, ExportError>>()?;
    export_training(opened, &TrainingOutput::from_path(output))
}

/// Exports traces, each named for `meta.json` and read one after the other, as one split of a
/// training set (see the [module docs](self) for the layout and the rules). The stats count
/// frames per sequence (`<split>/<group>`), the messages skipped over all inputs, and the first
/// truncation met (each sequence's is in `meta.json`).
pub fn export_training<R: Read>(
    inputs: Vec<(String, RecordReader<R>)>,
    output: &TrainingOutput,
) -> Result<ExportStats, ExportError> {
    if inputs.is_empty() {
        let problem = "no input trace: a training set needs at least one".to_owned();
        return Err(ExportError::InvalidInput { input: output.dir.display().to_string(), problem });
    }
    std::fs::create_dir_all(&output.dir)
        .map_err(|error| ExportError::Write { path: output.dir.clone(), error })?;
    let mut writer = SplitWriter::create(output)?;
    let mut stats = ExportStats::default();
    for (name, records) in inputs {
        let mut input_stats = ExportStats::default();
        writer.input = name;
        for_each_message(records, &mut input_stats, |message, stats| writer.write(message, stats))?;
        writer.end_input(&mut input_stats)?;
        add_stats(&mut stats, input_stats);
    }
    writer.finish(output, &mut stats)?;
    Ok(stats)
}

/// Adds the stats of one input to the export's.
fn add_stats(total: &mut ExportStats, input: ExportStats) {
    total.frames.extend(input.frames);
    for (topic, count) in input.skipped {
        *total.skipped.entry(topic).or_default() += count;
    }
    total.metadata_records += input.metadata_records;
    total.trace_metadata.extend(input.trace_metadata);
    total.truncation = total.truncation.or(input.truncation);
}

/// Writes the sequences of one split into its HDF5 file, one message at a time.
struct SplitWriter {
    // Fields are dropped in order: the datasets are closed before the file, and the file before
    // an abandoned temporary file is deleted.
    /// The sequences of the input being read, in order of their first frame.
    open: Vec<Sequence>,
    /// `/yarn/nodes` of the input being read, by set, until the set's first frame.
    nodes: BTreeMap<String, YarnNodes>,
    catalog: Catalog,
    file: File,
    temp: AtomicFile,
    /// The name of the input being read.
    input: String,
    /// The sequences of earlier inputs.
    done: Vec<SequenceInfo>,
    /// The split's name.
    split: String,
    /// The sequences of the folder's other splits, and their `dt`.
    others: Vec<SequenceInfo>,
    other_dt: Option<f64>,
}

impl SplitWriter {
    /// Starts a split: reads the folder's `meta.json`, if any, and creates an empty HDF5 file
    /// next to the split's.
    fn create(output: &TrainingOutput) -> Result<Self, ExportError> {
        let existing = TrainingMeta::read_existing(&output.meta_path())?;
        let other_dt = existing.as_ref().filter(|m| m.sequences.iter().any(|s| s.split != output.split));
        let other_dt = other_dt.map(|m| m.dt);
        let others = existing.map(|m| m.sequences).unwrap_or_default();
        let others = others.into_iter().filter(|s| s.split != output.split).collect();
        let path = output.split_path();
        let temp =
            AtomicFile::create(&path).map_err(|error| ExportError::Write { path: path.clone(), error })?;
        let file = File::with_options()
            .with_fcpl(|fcpl| fcpl.obj_track_times(false))
            .create(temp.temp_path())
            .map_err(|e| {
                h5_error(
                    format!("cannot create {} (to become {})", temp.temp_path().display(), path.display()),
                    e,
                )
            })?;
        Ok(Self {
            open: Vec::new(),
            nodes: BTreeMap::new(),
            catalog: Catalog::default(),
            file,
            temp,
            input: String::new(),
            done: Vec::new(),
            split: output.split.clone(),
            others,
            other_dt,
        })
    }

    /// Exports one message of the current input.
    fn write(&mut self, message: TraceMessage, stats: &mut ExportStats) -> Result<(), ExportError> {
        match message {
            TraceMessage::Yarns(frame) => self.write_frame(&frame, stats),
            TraceMessage::YarnNodes(nodes) => self.add_nodes(nodes),
            other => {
                stats.skip(&other);
                Ok(())
            }
        }
    }

    /// Keeps a set's `/yarn/nodes` for its first frame.
    fn add_nodes(&mut self, nodes: YarnNodes) -> Result<(), ExportError> {
        let stream = self.stream(&nodes.yarns);
        if let Some(sequence) = self.open.iter().find(|s| s.yarns == nodes.yarns) {
            let problem = format!(
                "/yarn/nodes comes after the set's first frame (frame {}): write it before the frames",
                sequence.first_frame
            );
            return Err(ExportError::InvalidInput { input: stream, problem });
        }
        check_nodes(&nodes)
            .map_err(|problem| ExportError::InvalidInput { input: stream.clone(), problem })?;
        match self.nodes.get(&nodes.yarns) {
            Some(known) if *known != nodes => {
                let problem = "a second /yarn/nodes of this set differs from the first".to_owned();
                Err(ExportError::InvalidInput { input: stream, problem })
            }
            Some(_) => Ok(()),
            None => {
                self.nodes.insert(nodes.yarns.clone(), nodes);
                Ok(())
            }
        }
    }

    /// Appends a frame to its set's sequence, which its first frame creates.
    fn write_frame(&mut self, frame: &YarnFrame, stats: &mut ExportStats) -> Result<(), ExportError> {
        let stream = self.stream(&frame.yarns);
        let position = match self.open.iter().position(|s| s.yarns == frame.yarns) {
            Some(position) => position,
            None => {
                let index = self.done.len() + self.open.len();
                let group = create_group(&self.file, &index.to_string())?;
                write_str_attr(&group, "source", &self.input)?;
                write_str_attr(&group, "yarns", &frame.yarns)?;
                let nodes = self.nodes.remove(&frame.yarns);
                let sequence = Sequence::create(&mut self.catalog, group, index, &stream, frame, nodes)?;
                self.open.push(sequence);
                self.open.len() - 1
            }
        };
        let sequence = &mut self.open[position];
        sequence.push(&stream, frame)?;
        stats.count_frame(&format!("{}/{}", self.split, sequence.index));
        Ok(())
    }

    /// Closes the sequences of the input just read; refuses an input without any.
    fn end_input(&mut self, stats: &mut ExportStats) -> Result<(), ExportError> {
        if self.open.is_empty() {
            let problem = "no /yarn/frame message: the training export needs yarn-level frames".to_owned();
            return Err(ExportError::InvalidInput { input: self.input.clone(), problem });
        }
        for nodes in std::mem::take(&mut self.nodes).into_values() {
            stats.skip(&TraceMessage::YarnNodes(nodes));
        }
        for sequence in std::mem::take(&mut self.open) {
            let stream = self.stream(&sequence.yarns);
            let info = sequence.finish(&mut self.catalog, &stream, &self.split, &self.input, stats)?;
            self.check_dt(&stream, &info)?;
            self.done.push(info);
        }
        Ok(())
    }

    /// Checks that a sequence's `dt` is the data set's: the first sequence's, or that of the
    /// other splits in the folder.
    fn check_dt(&self, stream: &str, info: &SequenceInfo) -> Result<(), ExportError> {
        let reference = match (self.other_dt, self.done.first()) {
            (Some(dt), _) => Some((dt, "the other splits in the folder's meta.json".to_owned())),
            (None, Some(first)) => Some((
                first.dt,
                format!("{}/{} ({}, yarns {:?})", first.split, first.group, first.source, first.yarns),
            )),
            (None, None) => None,
        };
        match reference {
            Some((dt, of)) if !meta::same_dt(dt, info.dt) => {
                let problem = format!(
                    "frame spacing dt = {} s differs from dt = {dt} s of {of} by more than {DT_TOLERANCE} (relative): \
                     a training set has one time step",
                    info.dt
                );
                Err(ExportError::InvalidInput { input: stream.to_owned(), problem })
            }
            _ => Ok(()),
        }
    }

    /// Writes the root attributes, closes the split's file and moves it into place, then writes
    /// `meta.json` with the other splits' sequences and this one's.
    fn finish(self, output: &TrainingOutput, stats: &mut ExportStats) -> Result<(), ExportError> {
        let Self { open, catalog, file, mut temp, done, split, others, other_dt, .. } = self;
        drop(open);
        drop(catalog);
        write_str_attr(&file, "format", FORMAT)?;
        write_str_attr(&file, "split", &split)?;
        write_str_attr(&file, "yarnhom_trace_version", env!("CARGO_PKG_VERSION"))?;
        file.close().map_err(|e| h5_error(format!("cannot close {}", temp.temp_path().display()), e))?;
        let dt = other_dt.or(done.first().map(|s| s.dt)).unwrap_or(f64::NAN);
        let mut sequences = others;
        sequences.extend(done);
        sequences.sort_by(|a, b| a.split.cmp(&b.split));
        let meta = TrainingMeta::new(dt, sequences);
        let meta_path = output.meta_path();
        let json = serde_json::to_string_pretty(&meta)
            .map_err(|e| ExportError::Write { path: meta_path.clone(), error: std::io::Error::other(e) })?;
        let destination = temp.destination().to_path_buf();
        temp.commit().map_err(|error| ExportError::Write { path: destination, error })?;
        write_atomic(&meta_path, json + "\n")
            .map_err(|error| ExportError::Write { path: meta_path, error })?;
        stats.files_written += 2;
        Ok(())
    }

    /// A set of the current input, for messages: `a.mcap, yarns "name"`.
    fn stream(&self, yarns: &str) -> String {
        format!("{}, yarns {yarns:?}", self.input)
    }
}

/// Checks a `/yarn/nodes` on its own: one type per rest position, known codes, edges between
/// its vertices.
fn check_nodes(nodes: &YarnNodes) -> Result<(), String> {
    let n = nodes.rest_positions_m.len();
    if nodes.node_type.len() != n {
        return Err(format!("/yarn/nodes has {} node types for {n} rest positions", nodes.node_type.len()));
    }
    if let Some((k, code)) = nodes.node_type.iter().enumerate().find(|(_, code)| **code >= YarnNodes::CODES) {
        return Err(format!(
            "/yarn/nodes: node {k} has type {code}, not a MeshGraphNets NodeType code (0 to {})",
            YarnNodes::CODES - 1
        ));
    }
    check_indices(&nodes.edges, n, "/yarn/nodes: edge")
}

/// One sequence being written: its open datasets and what later frames must repeat.
struct Sequence {
    group: Group,
    index: usize,
    yarns: String,
    world_pos: Column,
    /// The first frame's yarn ranges and radii, which every frame must repeat.
    yarn_ranges: Vec<[u32; 2]>,
    radii_m: Vec<f64>,
    from_yarn_nodes: bool,
    edges: usize,
    frames: u64,
    first_frame: u64,
    first_time_s: f64,
    last_time_s: f64,
    /// The spacing of the first two frames, in seconds.
    step_s: Option<f64>,
    /// The frame being appended, in f32.
    buffer: Vec<[f32; 3]>,
}

impl Sequence {
    /// Writes the static datasets of a set into `group`, from its `/yarn/nodes` if the trace has
    /// one, and starts `world_pos`.
    fn create(
        catalog: &mut Catalog,
        group: Group,
        index: usize,
        stream: &str,
        first: &YarnFrame,
        nodes: Option<YarnNodes>,
    ) -> Result<Self, ExportError> {
        let invalid = |problem: String| ExportError::frame(stream, first.frame, problem);
        check_yarn_frame(first).map_err(invalid)?;
        let n = first.positions_m.len();
        if n == 0 || i32::try_from(n).is_err() {
            return Err(invalid(format!("{n} vertices: a training sequence needs 1 to 2^31 - 1 nodes")));
        }
        if let Some(nodes) = &nodes
            && nodes.rest_positions_m.len() != n
        {
            let count = nodes.rest_positions_m.len();
            return Err(invalid(format!("{n} vertices, but the set's /yarn/nodes has {count}")));
        }
        let from_yarn_nodes = nodes.is_some();
        let (rest, types, edges) = match nodes {
            Some(nodes) => {
                let types = nodes.node_type.iter().map(|&code| i32::from(code)).collect();
                (nodes.rest_positions_m, types, nodes.edges)
            }
            None => (first.positions_m.clone(), vec![0; n], YarnNodes::chain_edges(&first.yarn_ranges)),
        };
        let mesh_pos: Vec<[f32; 3]> = rest.iter().map(|p| p.map(|x| x as f32)).collect();
        catalog.fixed(&group, "mesh_pos", &[n, 3], mesh_pos.as_flattened(), &MESH_POS)?;
        catalog.fixed(&group, "node_type", &[n, 1], &types, &NODE_TYPE)?;
        // Indices are below `n`, which fits in i32 (checked above).
        let edge_rows: Vec<[i32; 2]> = edges.iter().map(|e| e.map(|v| v as i32)).collect();
        catalog.fixed(&group, "edges", &[edges.len(), 2], edge_rows.as_flattened(), &EDGES)?;
        let radius: Vec<f32> = first.radii_m.iter().map(|&r| r as f32).collect();
        catalog.fixed(&group, "radius", &[n, 1], &radius, &RADIUS)?;
        Ok(Self {
            world_pos: catalog.growing::<f32>(&group, "world_pos", &[n, 3], &WORLD_POS)?,
            group,
            index,
            yarns: first.yarns.clone(),
            yarn_ranges: first.yarn_ranges.clone(),
            radii_m: first.radii_m.clone(),
            from_yarn_nodes,
            edges: edges.len(),
            frames: 0,
            first_frame: first.frame,
            first_time_s: first.time_s,
            last_time_s: first.time_s,
            step_s: None,
            buffer: Vec::with_capacity(n),
        })
    }

    /// Appends a frame, after checking it against the first.
    fn push(&mut self, stream: &str, frame: &YarnFrame) -> Result<(), ExportError> {
        let invalid = |problem: String| ExportError::frame(stream, frame.frame, problem);
        if self.frames > 0 {
            self.check_shape(frame).map_err(invalid)?;
            self.check_time(frame.time_s).map_err(invalid)?;
        }
        if let Some((k, p)) =
            frame.positions_m.iter().enumerate().find(|(_, p)| !p.iter().all(|x| x.is_finite()))
        {
            return Err(invalid(format!("vertex {k} has a non-finite position {p:?}")));
        }
        self.buffer.clear();
        self.buffer.extend(frame.positions_m.iter().map(|p| p.map(|x| x as f32)));
        self.world_pos.push_rows(&self.buffer)?;
        self.frames += 1;
        self.last_time_s = frame.time_s;
        Ok(())
    }

    /// A later frame must have the first frame's vertices, yarn ranges and radii.
    fn check_shape(&self, frame: &YarnFrame) -> Result<(), String> {
        check_yarn_frame(frame)?;
        let n = self.radii_m.len();
        if frame.positions_m.len() != n {
            return Err(format!(
                "{} vertices, but the sequence's first frame has {n}: a training sequence has a fixed set of nodes",
                frame.positions_m.len()
            ));
        }
        if frame.yarn_ranges != self.yarn_ranges {
            return Err(
                "the yarn ranges differ from the first frame's: a training sequence has fixed edges".into()
            );
        }
        match frame.radii_m.iter().zip(&self.radii_m).position(|(a, b)| a != b) {
            Some(k) => Err(format!(
                "the radius of vertex {k} is {} m, {} m in the first frame: the training layout has one radius per node",
                frame.radii_m[k], self.radii_m[k]
            )),
            None => Ok(()),
        }
    }

    /// A later frame's time must follow the last by the sequence's time step.
    fn check_time(&mut self, time_s: f64) -> Result<(), String> {
        let step = time_s - self.last_time_s;
        match self.step_s {
            None if step > 0.0 && step.is_finite() => {
                self.step_s = Some(step);
                Ok(())
            }
            None => Err(format!(
                "time_s = {time_s} s does not increase from the first frame's {} s: a training sequence needs a time step",
                self.last_time_s
            )),
            Some(first) if meta::same_dt(first, step) => Ok(()),
            Some(first) => Err(format!(
                "the time step from the previous frame is {step} s, the first step {first} s: frames must be \
                 uniformly spaced (within {DT_TOLERANCE} relative) for a training sequence; resample the trace or \
                 select a uniform part (`yarnhom trace select --time`, `trace decimate`)"
            )),
        }
    }

    /// Writes `dt` and describes the sequence; refuses one too short to train on.
    fn finish(
        self,
        catalog: &mut Catalog,
        stream: &str,
        split: &str,
        source: &str,
        stats: &ExportStats,
    ) -> Result<SequenceInfo, ExportError> {
        if self.frames < MIN_FRAMES {
            let problem = format!(
                "{} frames: a training sequence needs at least {MIN_FRAMES} (previous, current and next positions)",
                self.frames
            );
            return Err(ExportError::InvalidInput { input: stream.to_owned(), problem });
        }
        let dt = (self.last_time_s - self.first_time_s) / (self.frames - 1) as f64;
        catalog.fixed(&self.group, "dt", &[], &[dt], &DT)?;
        Ok(SequenceInfo {
            split: split.to_owned(),
            group: self.index.to_string(),
            source: source.to_owned(),
            yarns: self.yarns,
            trajectory_length: self.frames,
            nodes: self.radii_m.len(),
            edges: self.edges,
            dt,
            first_frame: self.first_frame,
            first_time_s: self.first_time_s,
            from_yarn_nodes: self.from_yarn_nodes,
            truncation: stats.truncation,
            trace_metadata: stats.trace_metadata.clone(),
        })
    }
}

const WORLD_POS: Spec = Spec { units: "m", description: "node positions of each frame (dynamic)" };
const MESH_POS: Spec = Spec {
    units: "m",
    description: "rest position of each node: /yarn/nodes rest_positions_m, else the first frame's positions",
};
const NODE_TYPE: Spec = Spec {
    units: "1",
    description: "MeshGraphNets NodeType code of each node: 0 NORMAL (free), 3 HANDLE (prescribed motion)",
};
const EDGES: Spec = Spec { units: "1", description: "yarn segments as pairs of 0-based node indices" };
const RADIUS: Spec = Spec { units: "m", description: "yarn radius at each node" };
const DT: Spec = Spec { units: "s", description: "frame spacing of the sequence" };
