//! MCAP simulation traces for yarnhom, the yarn-level cloth toolchain.
//!
//! A trace is an [MCAP](https://mcap.dev) file (or stream) whose messages are
//! [MessagePack](https://msgpack.org) maps with named fields (`message_encoding = "msgpack"`).
//! Every channel carries the [JSON Schema](https://json-schema.org) of its message type, generated
//! by [`schemars`] from the Rust structs in this crate (`schema encoding = "jsonschema"`), so a
//! trace can be decoded without this crate. Chunks are compressed with zstd.
//!
//! # Topics (format slice 1)
//!
//! | topic | message type | schema name | units | when written |
//! |---|---|---|---|---|
//! | `/mesh/topology` | [`MeshTopology`] | `yarnhom.MeshTopology.v1` | rest positions in metres; triangle indices are 0-based vertex indices | once per mesh, before any frame of that mesh |
//! | `/mesh/frame` | [`MeshFrame`] | `yarnhom.MeshFrame.v1` | time in seconds, positions in metres (world coordinates) | once per output frame |
//! | `/metrics` | [`Scalars`] | `yarnhom.Scalars.v1` | time in seconds; each value in the SI unit its name implies (energies in J, forces in N, lengths in m) | once per output frame (or whenever the producer has new scalars) |
//! | `/solver` | [`SolverStep`] | `yarnhom.SolverStep.v1` | time and wall time in seconds; residual in the solver's own norm | once per solver step (time step) |
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
//! trace.write_topology(&MeshTopology {
//!     triangles: vec![[0, 1, 2]],
//!     rest_positions_m: vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
//!     name: "cloth".into(),
//! })?;
//! trace.write_frame(&MeshFrame {
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

mod error;
mod messages;
mod metadata;
mod reader;
mod writer;

pub use error::TraceError;
pub use messages::{
    MESSAGE_ENCODING, MeshFrame, MeshTopology, SCHEMA_ENCODING, Scalars, SolverStep, TOPIC_VERSION_KEY,
    Topic, topics,
};
pub use metadata::{METADATA_NAME, TraceMetadata, read_metadata};
pub use reader::{TraceMessage, TraceReader};
pub use writer::{AtomicFile, DEFAULT_CHUNK_SIZE, TraceWriter, TraceWriterOptions};

/// Re-export of [`mcap::write::NoSeek`], the adapter used by [`TraceWriter::non_seeking`].
pub use mcap::write::NoSeek;
