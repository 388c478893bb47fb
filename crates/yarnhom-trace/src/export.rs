//! Exporting traces: per-frame OBJ or PLY files for viewers, and (feature `hdf5`) one HDF5 file
//! of fixed-shape arrays for machine-learning training, or yarn-level traces as a training set
//! for learned simulators in the MeshGraphNets layout (module `training`). [`export_paths`] is
//! `yarnhom trace export`: any of them from traces named by path.
//!
//! All read the trace one record at a time ([`RecordReader`]) and keep one message in memory,
//! plus the topologies of the meshes (and, for HDF5, the first frame's yarn ranges of each yarn
//! set and the names of the metrics and RVE terms). A truncated trace is not an error: whatever
//! was read before the cut is exported and the [`Truncation`] is returned in [`ExportStats`].
//! A message that cannot be decoded, or a topic version this crate does not read, is an error.
//! Messages on topics the format does not hold (unknown topics; `/yarn/nodes` but for the
//! training set; for OBJ and PLY every topic but the geometry) are skipped and counted by topic.
//!
//! # OBJ and PLY ([`export_frames`])
//!
//! Into a folder (created if needed), one file per frame, named `<name>_<frame:06>.obj` or
//! `.ply` after the mesh or yarn set (characters other than ASCII letters, digits, `-`, `_`,
//! `.` become `_`, as does a leading `.`):
//!
//! - `/mesh/frame`: the frame's vertex positions and the triangles of the mesh's topology; OBJ
//!   files also get texture coordinates `vt` from the rest positions (x, y), as
//!   `yarnhom shell simulate --obj-dir` writes them.
//! - `/tet/frame`: the frame's vertex positions (all of them, also interior ones) and the
//!   boundary triangles of the tet mesh (faces of one tetrahedron only), oriented outwards.
//! - `/yarn/frame`: the yarn centrelines as open polylines (OBJ `l` lines, one per yarn; PLY
//!   `edge` elements between consecutive vertices and a `radius` vertex property).
//!
//! PLY files are `binary_little_endian 1.0` with `double` coordinates (see [`write_ply`] and
//! [`write_ply_polylines`] for the exact headers); OBJ numbers are printed with the shortest
//! representation that reads back to the same `f64`. A frame whose topology has not appeared
//! yet is [`ExportError::MissingTopology`]; a later topology of the same name replaces the
//! earlier one; a later frame of the same name and number overwrites the file. Each file is
//! written through a temporary file and renamed into place.
//!
//! # HDF5 (`export_hdf5`, feature `hdf5`)
//!
//! One group per stream; every frame of a stream has the same shape, so a stream's per-frame
//! arrays stack into datasets whose first dimension is the frame (`F`, the number of messages of
//! that stream, in trace order). Per-frame datasets are chunked (whole rows, up to 1024 of them
//! and about 64 KiB per chunk, at least one row), uncompressed, with an unlimited first
//! dimension; they are appended to one frame at a time. `V` vertices, `T` triangles, `E` tetrahedra, `Y` yarns, `N` RVE samples, `K` RVE terms.
//! Numbers are little-endian; `f64` values are stored bit for bit.
//!
//! | dataset | type, shape | units | meaning |
//! |---|---|---|---|
//! | `/manifest` | string, scalar | | JSON: every dataset with its path, shape, dtype, units and description, plus provenance (see below) |
//! | `/mesh/<name>/positions_m` | f64 `[F, V, 3]` | m | vertex positions of each frame |
//! | `/mesh/<name>/frame` | u64 `[F]` | 1 | frame number of each frame |
//! | `/mesh/<name>/time_s` | f64 `[F]` | s | simulated time of each frame |
//! | `/mesh/<name>/triangles` | u32 `[T, 3]` | 1 | triangles, 0-based rows of the positions, counter-clockwise seen from the front |
//! | `/mesh/<name>/rest_positions_m` | f64 `[V, 3]` | m | rest (material) positions |
//! | `/tet/<name>/positions_m`, `frame`, `time_s`, `rest_positions_m` | as for meshes | | |
//! | `/tet/<name>/tets` | u32 `[E, 4]` | 1 | tetrahedra, 0-based vertex indices |
//! | `/tet/<name>/triangles` | u32 `[T, 3]` | 1 | boundary triangles (faces of one tetrahedron only), oriented outwards |
//! | `/tet/<name>/element/<value>` | f64 `[E]` | from the name's suffix | per-tetrahedron value |
//! | `/yarns/<name>/positions_m` | f64 `[F, V, 3]` | m | centreline vertices, yarn after yarn |
//! | `/yarns/<name>/edge_twist_rad` | f64 `[F, V]` | rad | twist of the edge leaving each vertex; NaN rows for frames without twists |
//! | `/yarns/<name>/radii_m` | f64 `[F, V]` | m | yarn radius at each vertex |
//! | `/yarns/<name>/yarn_ranges` | u32 `[Y, 2]` | 1 | `[first vertex, vertex count]` of each yarn (the same in every frame) |
//! | `/yarns/<name>/frame`, `time_s` | u64, f64 `[F]` | 1, s | frame number and simulated time |
//! | `/metrics/frame`, `/metrics/time_s` | u64, f64 `[F]` | 1, s | frame number and simulated time of each `/metrics` message |
//! | `/metrics/<value>` | f64 `[F]` | from the name's suffix | the value in each message; NaN where a message lacks it |
//! | `/solver/frame`, `time_s` | u64, f64 `[F]` | 1, s | one row per `/solver` message |
//! | `/solver/newton_iterations`, `line_search_steps` | u32 `[F]` | 1 | |
//! | `/solver/residual` | f64 `[F]` | 1 | final residual in the solver's own norm |
//! | `/solver/converged` | u8 `[F]` | 1 | 1 if converged, else 0 |
//! | `/solver/wall_time_s` | f64 `[F]` | s | wall-clock time of the step |
//! | `/solver_iteration/frame`, `time_s` | u64, f64 `[F]` | 1, s | one row per `/solver/iteration` message |
//! | `/solver_iteration/iteration` | u32 `[F]` | 1 | iteration within the solve |
//! | `/solver_iteration/energy_j` | f64 `[F]` | J | energy at the start of the iteration |
//! | `/solver_iteration/residual`, `step_length` | f64 `[F]` | 1 | |
//! | `/rve_sample/frame`, `time_s` | u64, f64 `[N]` | 1, s | one row per `/rve/sample` message |
//! | `/rve_sample/term` | u32 `[N]` | 1 | index of the sample's plan term into `/rve_sample/term_names` |
//! | `/rve_sample/term_names` | string `[K]` | | plan term names (`sx`, `sx,sa`, ...) in order of first appearance |
//! | `/rve_sample/grid_index` | u32 `[N, 2]` | 1 | index in the term's axes (second 0 for 1D terms) |
//! | `/rve_sample/strain` | f64 `[N, 5]` | 1, 1, 1, 1/m, 1/m | imposed strain sx, sa, sy, kx, ky |
//! | `/rve_sample/converged` | u8 `[N]` | 1 | 1 if the equilibrium was found, else 0 |
//! | `/rve_sample/energy_density_j_m2` | f64 `[N]` | J/m² | energy density; NaN where absent |
//! | `/rve_sample/stress` | f64 `[N, 5]` | J/m², J/m | stress; NaN rows where absent |
//! | `/rve_sample/iterations` | u32 `[N]` | 1 | Newton iterations |
//!
//! Every dataset has the string attributes `units` and `description`; every stream group under
//! `/mesh`, `/tet` and `/yarns` has the attribute `name`, the stream's name in the trace (in a
//! link name, `/` becomes `_`). Units of metrics and element values come from the name's suffix
//! (`_j` J, `_n` N, `_m` m, `_s` s, `_rad` rad, `_j_m2` J/m^2, ...; otherwise `SI`). The root
//! group has the string attributes `yarnhom_trace_version` and `input`.
//!
//! The manifest is a JSON object: `format` (`yarnhom.trace.hdf5`), `format_version` (1),
//! `yarnhom_trace_version` (of the exporter), `input` (the path given), `trace_metadata` (the
//! key/values of each `yarnhom` metadata record of the trace: producer name and version, the
//! writing `yarnhom_trace_version`, the producer's entries), `truncation` (null, or what a
//! truncated trace lost), `skipped_messages` (by topic), and `datasets`: a list of
//! `{"path", "shape", "dtype", "units", "description"}` in creation order (dtype `float64`,
//! `uint64`, `uint32`, `uint8` or `string`), the manifest itself included.
//!
//! Fixed shapes are the point: a mesh frame whose vertex count differs from its topology's, a
//! yarn frame whose vertex count or yarn ranges differ from the first frame of its set, and a
//! second, different topology of the same mesh are errors. The file is written to a temporary
//! file next to the destination and renamed into place when complete: a failed export leaves
//! nothing behind.
//!
//! # Training sets (module `training`, feature `hdf5`)
//!
//! Yarn-level traces (`/yarn/frame`, and `/yarn/nodes` where the producer writes it) as a data
//! set for learned simulators in the layout of the h5py-based MeshGraphNets loaders: `meta.json`
//! and one HDF5 file per split, a group per sequence with `world_pos [T, N, 3]`, `mesh_pos`,
//! `node_type`, `edges`, `radius` and `dt`. The module's docs give the layout, why it was chosen
//! and what is refused.

use std::collections::BTreeMap;
use std::io::{self, Read};
use std::path::{Path, PathBuf};

use serde::Serialize;

use crate::error::Truncation;
use crate::records::{RecordReader, TraceRecord};
use crate::{METADATA_NAME, TraceError, TraceMessage, decode, open_records, topics};

mod frames;
mod geometry;
#[cfg(feature = "hdf5")]
mod hdf5;
mod obj;
mod ply;
#[cfg(test)]
mod tests;
#[cfg(feature = "hdf5")]
pub mod training;

pub use geometry::{boundary_triangles, check_tet_topology};
pub use obj::{write_obj, write_obj_polylines};
pub use ply::{write_ply, write_ply_polylines};

/// What [`export_paths`] writes (`yarnhom trace export --format`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum ExportFormat {
    /// Wavefront OBJ, one file per frame (`<mesh>_<frame>.obj`) in the folder `-o`.
    Obj,
    /// Binary PLY, one file per frame (`<mesh>_<frame>.ply`) in the folder `-o`.
    Ply,
    /// One HDF5 file `-o` with a dataset per stream and field, stacked by frame, and a JSON
    /// manifest of every dataset.
    Hdf5,
    /// A MeshGraphNets-style training set of yarn-level sequences, one per yarn set of each
    /// input: `meta.json` and `train.h5` in the folder `-o` (`-o DIR/SPLIT.h5` for another
    /// split, e.g. `valid`).
    Training,
}

impl ExportFormat {
    /// The format's name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Self::Obj => "obj",
            Self::Ply => "ply",
            Self::Hdf5 => "hdf5",
            Self::Training => "training",
        }
    }
}

/// The file format of [`export_frames`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FrameFormat {
    /// Wavefront OBJ (text).
    Obj,
    /// Stanford PLY, binary little-endian.
    Ply,
}

impl FrameFormat {
    /// The file extension, without the dot.
    pub fn extension(self) -> &'static str {
        match self {
            Self::Obj => "obj",
            Self::Ply => "ply",
        }
    }
}

/// What an export read and wrote.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct ExportStats {
    /// Files written: one per frame for OBJ and PLY, one for HDF5.
    pub files_written: u64,
    /// Frames (rows) exported per stream, by stream: `/mesh/<name>`, `/tet/<name>`,
    /// `/yarns/<name>` (names as in the trace), `/metrics`, `/solver`, `/solver_iteration`,
    /// `/rve_sample`.
    pub frames: BTreeMap<String, u64>,
    /// Messages not exported, by topic.
    pub skipped: BTreeMap<String, u64>,
    /// Metadata records read.
    pub metadata_records: u64,
    /// The key/values of each `yarnhom` metadata record read ([`crate::METADATA_NAME`]): the
    /// producer's name and version, the `yarnhom_trace_version` that wrote the trace, the
    /// producer's entries.
    pub trace_metadata: Vec<BTreeMap<String, String>>,
    /// Set if the trace ended early; everything before the cut was exported.
    pub truncation: Option<Truncation>,
}

impl ExportStats {
    /// Counts one exported frame of `stream`.
    fn count_frame(&mut self, stream: &str) {
        *self.frames.entry(stream.to_owned()).or_default() += 1;
    }

    /// Counts one exported frame of `stream` written as a file of its own.
    fn count_file(&mut self, stream: &str) {
        self.count_frame(stream);
        self.files_written += 1;
    }

    /// Counts one skipped message.
    fn skip(&mut self, message: &TraceMessage) {
        *self.skipped.entry(topic_of(message).to_owned()).or_default() += 1;
    }

    /// Messages skipped, over all topics.
    pub fn skipped_messages(&self) -> u64 {
        self.skipped.values().sum()
    }
}

impl std::fmt::Display for ExportStats {
    /// One line: files, frames per stream, skipped messages.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let frames: Vec<String> = self.frames.iter().map(|(stream, n)| format!("{stream} {n}")).collect();
        let frames = if frames.is_empty() { "none".to_owned() } else { frames.join(", ") };
        let files = if self.files_written == 1 { "file" } else { "files" };
        write!(
            f,
            "{} {files} written; frames: {frames}; {} messages skipped",
            self.files_written,
            self.skipped_messages()
        )?;
        if !self.skipped.is_empty() {
            let topics: Vec<&str> = self.skipped.keys().map(String::as_str).collect();
            write!(f, " ({})", topics.join(", "))?;
        }
        Ok(())
    }
}

/// Everything that can stop an export.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ExportError {
    /// The trace could not be read or a message not decoded (a truncated trace is not an error:
    /// see [`ExportStats::truncation`]).
    #[error(transparent)]
    Trace(#[from] TraceError),

    /// An output file or folder could not be written.
    #[error("cannot write {}: {error}", path.display())]
    Write {
        /// The file or folder.
        path: PathBuf,
        /// What went wrong.
        error: io::Error,
    },

    /// A frame came before the topology of its mesh.
    #[error("frame {frame} of {mesh} comes before the topology of that mesh")]
    MissingTopology {
        /// The mesh, as `mesh "name"` or `tet mesh "name"`.
        mesh: String,
        /// The frame number.
        frame: u64,
    },

    /// A topology that cannot be exported (indices out of range; for HDF5, a second topology
    /// of the same mesh that differs from the first).
    #[error("{stream}: {problem}")]
    InvalidTopology {
        /// The mesh, as `mesh "name"` or `tet mesh "name"`.
        stream: String,
        /// What is wrong.
        problem: String,
    },

    /// A frame that cannot be exported (a vertex count other than its topology's, yarn ranges
    /// out of range; for HDF5, a shape other than the stream's first frame's).
    #[error("{stream}, frame {frame}: {problem}")]
    InvalidFrame {
        /// The stream, as `mesh "name"`, `tet mesh "name"`, `yarns "name"` or `metrics`.
        stream: String,
        /// The frame number.
        frame: u64,
        /// What is wrong.
        problem: String,
    },

    /// An input, or a training set's output folder, that the export cannot use (for the
    /// training set: a trace without yarn frames, a sequence too short or with another time
    /// step than the others, a misplaced `/yarn/nodes`, a `meta.json` of something else).
    #[error("{input}: {problem}")]
    InvalidInput {
        /// The input (a trace, a yarn set as `a.mcap, yarns "name"`, or a file of the output).
        input: String,
        /// What is wrong.
        problem: String,
    },

    /// A format that exports one trace was given several.
    #[error("--format {format} exports one trace, {count} were given (only `training` takes several)")]
    InputCount {
        /// The format's name.
        format: &'static str,
        /// The traces given.
        count: usize,
    },

    /// A format that needs the `hdf5` feature, in a build without it.
    #[error(
        "--format {format} needs the `hdf5` feature: rebuild yarnhom with `--features hdf5` (needs libhdf5)"
    )]
    NeedsHdf5 {
        /// The format's name.
        format: &'static str,
    },

    /// Writing an HDF5 dataset, group or attribute failed (the shared HDF5 layer of
    /// `yarnhom-artifacts`).
    #[cfg(feature = "hdf5")]
    #[error(transparent)]
    Hdf5Layer(#[from] yarnhom_artifacts::Error),

    /// The HDF5 library failed.
    #[cfg(feature = "hdf5")]
    #[error("HDF5: {context}: {error}")]
    Hdf5 {
        /// What was being done, naming the dataset.
        context: String,
        /// The library's error.
        error: ::hdf5::Error,
    },
}

impl ExportError {
    fn topology(stream: &str, problem: String) -> Self {
        Self::InvalidTopology { stream: stream.to_owned(), problem }
    }

    fn frame(stream: &str, frame: u64, problem: String) -> Self {
        Self::InvalidFrame { stream: stream.to_owned(), frame, problem }
    }
}

/// Exports the traces at `inputs` (paths; `-` is standard input) in `format` to `output` (a
/// folder for OBJ, PLY and the training set, a file for HDF5): what `yarnhom trace export`
/// does. Only [`ExportFormat::Training`] takes several traces; HDF5 and the training set need
/// the `hdf5` feature.
pub fn export_paths(
    format: ExportFormat,
    inputs: &[String],
    output: &Path,
) -> Result<ExportStats, ExportError> {
    let single = || match inputs {
        [input] => Ok(input.as_str()),
        _ => Err(ExportError::InputCount { format: format.name(), count: inputs.len() }),
    };
    match format {
        ExportFormat::Obj => export_frames(open_records(single()?)?, output, FrameFormat::Obj),
        ExportFormat::Ply => export_frames(open_records(single()?)?, output, FrameFormat::Ply),
        #[cfg(feature = "hdf5")]
        ExportFormat::Hdf5 => export_hdf5(open_records(single()?)?, output, single()?),
        #[cfg(feature = "hdf5")]
        ExportFormat::Training => training::export_training_paths(inputs, output),
        #[cfg(not(feature = "hdf5"))]
        ExportFormat::Hdf5 | ExportFormat::Training => Err(ExportError::NeedsHdf5 { format: format.name() }),
    }
}

/// Writes every mesh, tet-mesh and yarn frame of a trace as one OBJ or PLY file into `dir`,
/// created if needed (see the [module docs](self) for names and contents).
pub fn export_frames<R: Read>(
    input: RecordReader<R>,
    dir: &Path,
    format: FrameFormat,
) -> Result<ExportStats, ExportError> {
    let mut writer = frames::FrameWriter::create(dir, format)?;
    let mut stats = ExportStats::default();
    for_each_message(input, &mut stats, |message, stats| writer.write(message, stats))?;
    Ok(stats)
}

/// Writes a trace as one HDF5 file at `path`, atomically (see the [module docs](self) for the
/// layout). `input` names the trace in the manifest (its path, or `-`).
#[cfg(feature = "hdf5")]
pub fn export_hdf5<R: Read>(
    input: RecordReader<R>,
    path: &Path,
    input_name: &str,
) -> Result<ExportStats, ExportError> {
    let mut writer = hdf5::Hdf5Writer::create(path)?;
    let mut stats = ExportStats::default();
    for_each_message(input, &mut stats, |message, stats| writer.write(message, stats))?;
    writer.finish(input_name, &mut stats)?;
    Ok(stats)
}

/// Decodes every message of `input` and hands it to `export`, in file order. Metadata records
/// are counted, and the `yarnhom` ones kept, in `stats`; a truncation ends the input and is
/// kept in `stats` too.
fn for_each_message<R: Read>(
    input: RecordReader<R>,
    stats: &mut ExportStats,
    mut export: impl FnMut(TraceMessage, &mut ExportStats) -> Result<(), ExportError>,
) -> Result<(), ExportError> {
    for record in input {
        match record {
            Ok(TraceRecord::Metadata(metadata)) => {
                stats.metadata_records += 1;
                if metadata.name == METADATA_NAME {
                    stats.trace_metadata.push(metadata.metadata);
                }
            }
            Ok(TraceRecord::Message(message)) => export(decode(&message)?, stats)?,
            Err(TraceError::Truncated(truncation)) => stats.truncation = Some(truncation),
            Err(err) => return Err(err.into()),
        }
    }
    Ok(())
}

/// The topic a decoded message came from.
fn topic_of(message: &TraceMessage) -> &str {
    match message {
        TraceMessage::Topology(_) => topics::MESH_TOPOLOGY,
        TraceMessage::Frame(_) => topics::MESH_FRAME,
        TraceMessage::Yarns(_) => topics::YARN_FRAME,
        TraceMessage::YarnNodes(_) => topics::YARN_NODES,
        TraceMessage::TetTopology(_) => topics::TET_TOPOLOGY,
        TraceMessage::TetFrame(_) => topics::TET_FRAME,
        TraceMessage::Scalars(_) => topics::METRICS,
        TraceMessage::Solver(_) => topics::SOLVER,
        TraceMessage::SolverIteration(_) => topics::SOLVER_ITERATION,
        TraceMessage::RveSample(_) => topics::RVE_SAMPLE,
        TraceMessage::Unknown { topic } => topic,
    }
}
