//! `meta.json` of a training set: what it holds, and how a new split joins an existing one.

use std::collections::BTreeMap;
use std::path::Path;

use serde::{Deserialize, Serialize};

use super::{DT_TOLERANCE, FORMAT, FORMAT_VERSION, split_file_name};
use crate::YarnNodes;
use crate::error::Truncation;
use crate::export::ExportError;

/// The contents of `meta.json` (see the [module docs](super) for the meaning of each field).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrainingMeta {
    /// `yarnhom.trace.training`.
    pub format: String,
    /// The version of the layout: 1.
    pub format_version: u32,
    /// The version of `yarnhom-trace` that last wrote the file.
    pub yarnhom_trace_version: String,
    /// `yarnhom` (MeshGraphNets names its simulator here, e.g. `arcsim`).
    pub simulator: String,
    /// The per-sequence arrays, in the order of MeshGraphNets' `field_names`.
    pub field_names: Vec<String>,
    /// Frames per sequence when every sequence of every split has the same number, else -1.
    pub trajectory_length: i64,
    /// Type (`static` or `dynamic`), shape (-1 for a size that varies between sequences) and
    /// dtype of each field, by name.
    pub features: BTreeMap<String, Feature>,
    /// The frame spacing of every sequence, in seconds.
    pub dt: f64,
    /// The unit of each field and of `dt` (`1` for codes and indices).
    pub units: BTreeMap<String, String>,
    /// The node-type codes used (MeshGraphNets' `NodeType`), and `SIZE`, the number of codes.
    pub node_types: BTreeMap<String, u8>,
    /// Each split by name: its file and how many sequences it holds.
    pub splits: BTreeMap<String, SplitInfo>,
    /// Every sequence of every split, split after split, in group order.
    pub sequences: Vec<SequenceInfo>,
}

/// One field of [`TrainingMeta::features`], as MeshGraphNets' `meta.json` describes it.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Feature {
    /// `static` (one array per sequence) or `dynamic` (one per frame, frames first).
    #[serde(rename = "type")]
    pub kind: String,
    /// The dataset's shape; -1 where it varies between sequences.
    pub shape: Vec<i64>,
    /// The numpy name of the element type (`float32`, `int32`).
    pub dtype: String,
}

/// One split of [`TrainingMeta::splits`].
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct SplitInfo {
    /// The HDF5 file of the split, relative to the folder: `<split>.h5`.
    pub file: String,
    /// Sequences in it (groups `/0`, `/1`, ...).
    pub sequences: usize,
}

/// One sequence of [`TrainingMeta::sequences`]: where it lives and where it came from.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SequenceInfo {
    /// The split holding it.
    pub split: String,
    /// Its group in the split's file (`0`, `1`, ...).
    pub group: String,
    /// The trace it was exported from, as given (`-` for standard input).
    pub source: String,
    /// The yarn set's name in the trace.
    pub yarns: String,
    /// Frames (`T`).
    pub trajectory_length: u64,
    /// Nodes (`N`), the yarn vertices.
    pub nodes: usize,
    /// Edges (`E`), the yarn segments.
    pub edges: usize,
    /// Frame spacing, in seconds: (last time - first time) / (T - 1).
    pub dt: f64,
    /// `frame` of the first exported frame, on the producer's clock.
    pub first_frame: u64,
    /// Simulated time of the first exported frame, in seconds.
    pub first_time_s: f64,
    /// Whether rest positions, node types and edges came from the trace's `/yarn/nodes`
    /// (`false`: the first frame's positions, every node `NORMAL`, consecutive vertices).
    pub from_yarn_nodes: bool,
    /// Set if the trace ended early: the sequence holds the frames before the cut.
    pub truncation: Option<Truncation>,
    /// The trace's `yarnhom` metadata records (producer, its version and inputs).
    pub trace_metadata: Vec<BTreeMap<String, String>>,
}

/// The fields, in [`TrainingMeta::field_names`] order: name, type, shape after the first
/// dimension for dynamic fields, dtype, units.
const FIELDS: [(&str, &str, &[i64], &str, &str); 5] = [
    ("edges", "static", &[-1, 2], "int32", "1"),
    ("mesh_pos", "static", &[-1, 3], "float32", "m"),
    ("node_type", "static", &[-1, 1], "int32", "1"),
    ("radius", "static", &[-1, 1], "float32", "m"),
    ("world_pos", "dynamic", &[-1, 3], "float32", "m"),
];

impl TrainingMeta {
    /// The meta of a training set holding `sequences` (of any splits) at frame spacing `dt`.
    pub(super) fn new(dt: f64, sequences: Vec<SequenceInfo>) -> Self {
        let lengths: Vec<u64> = sequences.iter().map(|s| s.trajectory_length).collect();
        let trajectory_length = match lengths.first() {
            Some(&t) if lengths.iter().all(|&other| other == t) => i64::try_from(t).unwrap_or(-1),
            _ => -1,
        };
        let features = FIELDS
            .iter()
            .map(|&(name, kind, shape, dtype, _)| {
                let shape = match kind {
                    "dynamic" => std::iter::once(trajectory_length).chain(shape.iter().copied()).collect(),
                    _ => shape.to_vec(),
                };
                (name.to_owned(), Feature { kind: kind.to_owned(), shape, dtype: dtype.to_owned() })
            })
            .collect();
        let mut units: BTreeMap<String, String> =
            FIELDS.iter().map(|&(name, .., units)| (name.to_owned(), units.to_owned())).collect();
        units.insert("dt".into(), "s".into());
        let node_types = BTreeMap::from([
            ("NORMAL".to_owned(), YarnNodes::NORMAL),
            ("HANDLE".to_owned(), YarnNodes::HANDLE),
            ("SIZE".to_owned(), YarnNodes::CODES),
        ]);
        let mut splits: BTreeMap<String, SplitInfo> = BTreeMap::new();
        for sequence in &sequences {
            let file = split_file_name(&sequence.split);
            splits.entry(sequence.split.clone()).or_insert(SplitInfo { file, sequences: 0 }).sequences += 1;
        }
        Self {
            format: FORMAT.to_owned(),
            format_version: FORMAT_VERSION,
            yarnhom_trace_version: env!("CARGO_PKG_VERSION").to_owned(),
            simulator: "yarnhom".to_owned(),
            field_names: FIELDS.iter().map(|&(name, ..)| name.to_owned()).collect(),
            trajectory_length,
            features,
            dt,
            units,
            node_types,
            splits,
            sequences,
        }
    }

    /// Reads the `meta.json` at `path`, if there is one, to add a split to: it must be a
    /// training set's meta of a layout version this crate writes.
    pub fn read_existing(path: &Path) -> Result<Option<Self>, ExportError> {
        let text = match std::fs::read_to_string(path) {
            Ok(text) => text,
            Err(error) if error.kind() == std::io::ErrorKind::NotFound => return Ok(None),
            Err(error) => return Err(invalid(path, format!("cannot be read: {error}"))),
        };
        let value: serde_json::Value = serde_json::from_str(&text).map_err(|e| {
            invalid(path, format!("is not JSON ({e}): give the training set a folder of its own"))
        })?;
        let format = value.get("format").and_then(serde_json::Value::as_str);
        if format != Some(FORMAT) {
            let problem = format!(
                "is not the meta.json of a yarnhom training set (format {format:?}, expected {FORMAT:?}): \
                 give the training set a folder of its own"
            );
            return Err(invalid(path, problem));
        }
        let version = value.get("format_version").and_then(serde_json::Value::as_u64);
        if version != Some(u64::from(FORMAT_VERSION)) {
            let problem = format!(
                "has format_version {version:?}; this yarnhom writes version {FORMAT_VERSION} and cannot add a split to it"
            );
            return Err(invalid(path, problem));
        }
        serde_json::from_value(value).map(Some).map_err(|e| invalid(path, format!("cannot be read: {e}")))
    }
}

/// Whether two frame spacings are the same within [`DT_TOLERANCE`] (relative).
pub(super) fn same_dt(a: f64, b: f64) -> bool {
    (a - b).abs() <= DT_TOLERANCE * a.abs().max(b.abs())
}

fn invalid(path: &Path, problem: String) -> ExportError {
    ExportError::InvalidInput { input: path.display().to_string(), problem }
}
