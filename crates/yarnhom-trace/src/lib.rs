#![doc = include_str!("../README.md")]

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
    SolverStep, TOPIC_VERSION_KEY, TetFrame, TetTopology, Topic, YarnFrame, YarnNodes, topic_schemas, topics,
};
pub use metadata::{METADATA_NAME, TraceMetadata, read_metadata};
pub use reader::{TraceMessage, TraceReader, decode};
pub use records::{ReadProgress, RecordReader, TraceRecord};
pub use sink::{STDIO, TraceSink, is_stdio, open_records, open_source};
pub use writer::{DEFAULT_CHUNK_SIZE, TraceWriter, TraceWriterOptions};

/// Re-export of [`mcap::write::NoSeek`], the adapter used by [`TraceWriter::non_seeking`].
pub use mcap::write::NoSeek;
