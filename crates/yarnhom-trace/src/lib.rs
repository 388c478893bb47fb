//! MCAP simulation traces for yarnhom, the yarn-level cloth toolchain.
//!
//! A trace is an [MCAP](https://mcap.dev) file (or stream) whose messages are
//! [MessagePack](https://msgpack.org) maps with named fields (`message_encoding = "msgpack"`).
//! Every channel carries the [JSON Schema](https://json-schema.org) of its message type, generated
//! by [`schemars`] from the Rust structs in this crate (`schema encoding = "jsonschema"`), so a
//! trace can be decoded without this crate. Chunks are compressed with zstd.
//!
//! # Topics
//!
//! | topic | message type | schema name | units | when written |
//! |---|---|---|---|---|
//! | `/mesh/topology` | [`MeshTopology`] | `yarnhom.MeshTopology.v1` | rest positions in metres; triangle indices are 0-based vertex indices | once per mesh, before any frame of that mesh |
//! | `/mesh/frame` | [`MeshFrame`] | `yarnhom.MeshFrame.v1` | time in seconds, positions in metres (world coordinates) | once per output frame |
//! | `/yarn/frame` | [`YarnFrame`] | `yarnhom.YarnFrame.v1` | positions and radii in metres, twists in radians | once per yarn-level state (output frame, Newton iteration, or sample) |
//! | `/tet/topology` | [`TetTopology`] | `yarnhom.TetTopology.v1` | rest positions in metres; per-element values in their SI units | once per tet mesh, before its frames |
//! | `/tet/frame` | [`TetFrame`] | `yarnhom.TetFrame.v1` | time in seconds, positions in metres | once per output frame |
//! | `/metrics` | [`Scalars`] | `yarnhom.Scalars.v1` | time in seconds; each value in the SI unit its name implies (energies in J, forces in N, lengths in m) | once per output frame (or whenever the producer has new scalars) |
//! | `/solver` | [`SolverStep`] | `yarnhom.SolverStep.v1` | time and wall time in seconds; residual in the solver's own norm | once per solver step (time step) |
//! | `/solver/iteration` | [`SolverIteration`] | `yarnhom.SolverIteration.v1` | energy in J; residual in the solver's own norm | once per Newton iteration of a traced static solve |
//! | `/rve/sample` | [`RveSample`] | `yarnhom.RveSample.v1` | energy density J/m², stress J/m² per unit strain (J/m per unit curvature) | once per solved sample of a sweep |
//!
//! Every message except the topologies has a `frame` field (its index on the producer's clock:
//! output frame, Newton iteration, sample number) and a `time_s` field (simulated time; 0 for
//! static solves). The filters ([`filter`]) decimate and select on these two fields for any
//! msgpack topic, so other producers' topics with the same fields are filtered alike.
//!
//! Besides messages, a trace carries one MCAP *Metadata* record named `yarnhom`
//! ([`METADATA_NAME`]) with the producer's name and version and free key/value pairs given by the
//! caller (scene name, material file, ...). See [`TraceMetadata`].
//!
//! # Versioning
//!
//! Each topic has its own layout version ([`Topic::VERSION`], currently 1 for all topics). It is
//! stored twice: as a `.vN` suffix of the schema name and in the channel metadata under
//! [`TOPIC_VERSION_KEY`] (`yarnhom_topic_version`). The reader refuses a known topic whose
//! version it does not support instead of guessing. A change that old readers could misread
//! (renaming or re-typing a field, changing units) needs a new version; adding a topic does not.
//!
//! # Timestamps
//!
//! MCAP `log_time` and `publish_time` are the message's simulated time `time_s` in nanoseconds
//! (rounded). `/mesh/topology` has no time and is logged at time 0, so it sorts before frames in
//! log-time order. The MCAP `sequence` field is the message's `frame` number modulo 2³²
//! (MCAP sequences are 32-bit); for `/mesh/topology` it counts topologies written (0, 1, ...).
//! The authoritative frame number is the `frame` field in the message itself.
//!
//! # Exporting
//!
//! [`export`] turns a trace into per-frame OBJ or PLY files (meshes, tet-mesh boundaries, yarn
//! polylines) or, with the `hdf5` feature, into one HDF5 file of fixed-shape arrays for
//! machine-learning training.
//!
//! # Comparing
//!
//! [`diff_traces`] compares two traces topic by topic and frame by frame, streaming both,
//! without knowing the message types (see [`diff`]); `yarnhom diff A.mcap B.mcap` prints it.
//!
//! # Writing and reading
//!
//! ```no_run
//! use yarnhom_trace::{MeshFrame, MeshTopology, TraceMetadata, TraceReader, TraceWriter};
//!
//! # fn main() -> Result<(), yarnhom_trace::TraceError> {
//! let mut trace = TraceWriter::create("out.mcap")?;
//! trace.write_metadata(
//!     &TraceMetadata::new("yarnhom-sim", "0.1.0").with_entry("scene", "drape.toml"),
//! )?;
//! trace.write(&MeshTopology {
//!     triangles: vec![[0, 1, 2]],
//!     rest_positions_m: vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
//!     name: "cloth".into(),
//! })?;
//! trace.write(&MeshFrame {
//!     mesh: "cloth".into(),
//!     frame: 0,
//!     time_s: 0.0,
//!     positions_m: vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
//! })?;
//! trace.finish()?; // out.mcap appears only now (atomic rename)
//!
//! for message in TraceReader::new(std::fs::File::open("out.mcap")?) {
//!     println!("{:?}", message?);
//! }
//! # Ok(())
//! # }
//! ```

pub mod diff;
mod error;
pub mod export;
pub mod filter;
mod messages;
mod metadata;
mod reader;
mod records;
mod sink;
mod writer;

pub use diff::{TopicDiff, TraceDiff, diff_traces};
pub use error::{TraceError, Truncation};
pub use messages::{
    MESSAGE_ENCODING, MeshFrame, MeshTopology, RveSample, SCHEMA_ENCODING, Scalars, SolverIteration,
    SolverStep, TOPIC_VERSION_KEY, TetFrame, TetTopology, Topic, YarnFrame, topic_schemas, topics,
};
pub use metadata::{METADATA_NAME, TraceMetadata, read_metadata};
pub use reader::{TraceMessage, TraceReader, decode};
pub use records::{ReadProgress, RecordReader, TraceRecord};
pub use sink::{STDIO, TraceSink, is_stdio, open_records, open_source};
pub use writer::{DEFAULT_CHUNK_SIZE, TraceWriter, TraceWriterOptions};

/// Re-export of [`mcap::write::NoSeek`], the adapter used by [`TraceWriter::non_seeking`].
pub use mcap::write::NoSeek;
