//! Error type of the crate.

/// Everything that can go wrong while writing or reading a trace.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum TraceError {
    /// An I/O error from the underlying file, pipe or stream (including one reported through
    /// the MCAP library).
    #[error("trace I/O error: {0}")]
    Io(#[from] std::io::Error),

    /// A trace file could not be opened for reading.
    #[error("cannot open the trace {path}: {source}")]
    Open {
        /// The file.
        path: String,
        /// What failed.
        source: std::io::Error,
    },

    /// A binary trace was to be written to a terminal.
    #[error(
        "refusing to write a binary trace to the terminal: pipe it (`| yarnhom trace info`) or give a file"
    )]
    Terminal,

    /// The MCAP container is malformed or could not be written.
    #[error("MCAP error: {0}")]
    Mcap(#[source] mcap::McapError),

    /// The trace ends before its end: the producer was killed, or the file is a partial copy.
    /// Every message before the cut was read.
    #[error("{0}")]
    Truncated(Truncation),

    /// A message could not be encoded as MessagePack.
    #[error("failed to encode message for topic {topic}: {source}")]
    Encode {
        /// Topic of the message.
        topic: &'static str,
        /// Underlying MessagePack error.
        source: rmp_serde::encode::Error,
    },

    /// A message payload could not be decoded as the topic's message type.
    #[error("failed to decode message on topic {topic}: {source}")]
    Decode {
        /// Topic of the message.
        topic: String,
        /// Underlying MessagePack error.
        source: rmp_serde::decode::Error,
    },

    /// A known topic uses a message encoding other than `msgpack`.
    #[error("topic {topic}: unsupported message encoding {encoding:?} (expected \"msgpack\")")]
    UnsupportedEncoding {
        /// Topic of the channel.
        topic: String,
        /// Message encoding found in the channel record.
        encoding: String,
    },

    /// A known topic carries a layout version this crate does not read.
    #[error(
        "topic {topic}: unsupported topic version {found:?} in channel metadata \
         (this reader supports version {supported})"
    )]
    UnsupportedTopicVersion {
        /// Topic of the channel.
        topic: String,
        /// Value of `yarnhom_topic_version` in the channel metadata, if present.
        found: Option<String>,
        /// The version this crate reads.
        supported: u32,
    },

    /// A message time cannot be represented as an MCAP timestamp.
    #[error(
        "topic {topic}: time_s = {time_s} cannot be stored as an MCAP timestamp \
         (it must be finite, >= 0 and below about 584 years)"
    )]
    InvalidTime {
        /// Topic of the message.
        topic: &'static str,
        /// The offending time in seconds.
        time_s: f64,
    },

    /// A caller-supplied metadata entry uses a key reserved by this crate.
    #[error("metadata key {key:?} is reserved by yarnhom-trace")]
    ReservedMetadataKey {
        /// The offending key.
        key: String,
    },

    /// A `yarnhom` metadata record lacks a required entry.
    #[error("the `yarnhom` metadata record lacks the required key {key:?}")]
    MissingMetadataKey {
        /// The missing key.
        key: &'static str,
    },

    /// A JSON Schema could not be serialized (should not happen for the types in this crate).
    #[error("failed to serialize the JSON Schema of topic {topic}: {source}")]
    Schema {
        /// Topic whose schema failed.
        topic: &'static str,
        /// Underlying JSON error.
        source: serde_json::Error,
    },
}

impl From<mcap::McapError> for TraceError {
    /// Lifts MCAP's I/O errors into [`TraceError::Io`]: `mcap::McapError::Io` displays only a
    /// generic sentence, which would hide e.g. "Broken pipe" or "No space left on device".
    fn from(err: mcap::McapError) -> Self {
        match err {
            mcap::McapError::Io(io) => Self::Io(io),
            other => Self::Mcap(other),
        }
    }
}

/// Where a truncated trace ended; see [`TraceError::Truncated`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Truncation {
    /// Messages read in full.
    pub messages_recovered: u64,
    /// Bytes read from the source.
    pub bytes_read: u64,
    /// Bytes after the last complete record, which could not be decoded.
    pub bytes_lost: u64,
}

impl std::fmt::Display for Truncation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "the trace is truncated: {} messages recovered from {} bytes; the last {} bytes (an \
             incomplete record or chunk) were lost",
            self.messages_recovered, self.bytes_read, self.bytes_lost
        )
    }
}
