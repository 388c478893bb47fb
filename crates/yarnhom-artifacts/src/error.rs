//! Errors of reading, writing and validating artifacts.
//!
//! Every way a file can be bad has its own variant, so callers (and the CLI's one-line
//! report) can name the problem precisely. Nothing in this crate panics on bad bytes.

use std::path::PathBuf;

/// Everything that can go wrong with an artifact.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// An operating-system error while reading or writing.
    #[error("i/o error: {0}")]
    Io(#[from] std::io::Error),
    /// The file does not start with the yarnhom magic bytes.
    #[error("not a yarnhom artifact (wrong magic bytes {found:02x?})")]
    WrongMagic {
        /// The first bytes of the file.
        found: Vec<u8>,
    },
    /// The container framing is newer than this build understands.
    #[error("container version {found} is newer than the supported version {supported}; upgrade yarnhom")]
    NewerContainer {
        /// Version in the file.
        found: u16,
        /// Newest version this build reads.
        supported: u16,
    },
    /// The file ends before a section it announces.
    #[error("truncated file: {section} needs {needed} bytes but only {available} remain")]
    Truncated {
        /// The section being read.
        section: &'static str,
        /// Bytes the section needs.
        needed: u64,
        /// Bytes left in the file.
        available: u64,
    },
    /// Bytes follow the checksum.
    #[error("{extra} unexpected bytes after the end of the artifact")]
    TrailingBytes {
        /// How many extra bytes.
        extra: u64,
    },
    /// The stored CRC-32 does not match the bytes: the file was corrupted.
    #[error("checksum mismatch: stored {stored:08x}, computed {computed:08x} (file corrupted)")]
    ChecksumMismatch {
        /// CRC-32 stored in the file.
        stored: u32,
        /// CRC-32 of the bytes read.
        computed: u32,
    },
    /// The decoded payload does not hash to the content hash in the header.
    #[error("content hash mismatch: header says {stored}, payload hashes to {computed}")]
    ContentHashMismatch {
        /// Hash stored in the header.
        stored: String,
        /// Hash of the payload.
        computed: String,
    },
    /// The header names a kind this build does not know.
    #[error("unknown artifact kind '{0}' (known kinds: {known})", known = crate::KINDS.join(", "))]
    UnknownKind(String),
    /// The file is none of the formats yarnhom reads.
    #[error(
        "not a yarnhom artifact (.yh, JSON document, HDF5 export), .pyp pattern, ARCSim-HYLC or Ch. 6 material, \
         yarnhom report or MCAP trace"
    )]
    UnknownFormat,
    /// The file holds something other than an artifact (a material file, a report, a trace).
    #[error("holds a {found}, not an artifact")]
    NotAnArtifact {
        /// What it holds.
        found: String,
    },
    /// A yarn model spec names no built-in model.
    #[error("unknown yarn model '{name}' (known: {known})")]
    UnknownYarnModel {
        /// The spec given.
        name: String,
        /// The built-in models, comma-separated.
        known: String,
    },
    /// The file holds a different kind than the caller asked for.
    #[error("expected a '{expected}' artifact but the file holds '{found}'")]
    WrongKind {
        /// Kind the caller wants.
        expected: &'static str,
        /// Kind in the file.
        found: String,
    },
    /// The file was written by a newer yarnhom with a newer schema.
    #[error(
        "'{kind}' schema version {found} is newer than the supported version {supported}; upgrade yarnhom"
    )]
    NewerSchema {
        /// Artifact kind.
        kind: String,
        /// Version in the file.
        found: u32,
        /// Newest version this build reads.
        supported: u32,
    },
    /// An old schema version for which no migration exists.
    #[error("'{kind}' schema version {found} has no migration to version {supported}")]
    NoMigration {
        /// Artifact kind.
        kind: String,
        /// Version in the file.
        found: u32,
        /// Version this build reads.
        supported: u32,
    },
    /// The bytes could not be decoded (bad zstd frame, malformed msgpack or JSON).
    #[error("cannot decode {what}: {message}")]
    Decode {
        /// What was being decoded.
        what: &'static str,
        /// The decoder's message.
        message: String,
    },
    /// The value could not be encoded.
    #[error("cannot encode {what}: {message}")]
    Encode {
        /// What was being encoded.
        what: &'static str,
        /// The encoder's message.
        message: String,
    },
    /// The decoded value breaks an invariant of its kind.
    #[error("invalid {kind}: {problem}")]
    Invalid {
        /// Artifact kind.
        kind: &'static str,
        /// What is wrong (shown inline, so not exposed as `source()`).
        problem: ValidationError,
    },
    /// A problem in a foreign format (`.pyp`, ARCSim JSON, ...), with its line.
    #[error("{format} line {line}: {message}")]
    Format {
        /// The foreign format.
        format: &'static str,
        /// 1-based line number (0 when the whole file is at fault).
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// A value cannot be represented in the target format.
    #[error("cannot export to {format}: {message}")]
    Unrepresentable {
        /// The target format.
        format: &'static str,
        /// Why.
        message: String,
    },
    /// HDF5 library error.
    #[error("hdf5: {0}")]
    Hdf5(String),
    /// Any of the above, with the file it concerns.
    #[error("{}: {error}", path.display())]
    At {
        /// The file.
        path: PathBuf,
        /// The problem (shown inline, so not exposed as `source()`).
        error: Box<Error>,
    },
}

impl Error {
    /// Attach the file this error concerns (once: an error already located keeps its path).
    pub fn at(self, path: impl Into<PathBuf>) -> Self {
        match self {
            Error::At { .. } => self,
            other => Error::At { path: path.into(), error: Box::new(other) },
        }
    }

    /// The error without its file location.
    pub fn root(&self) -> &Error {
        match self {
            Error::At { error, .. } => error.root(),
            other => other,
        }
    }
}

/// A broken invariant, with the path of the offending field (e.g. `yarns[2].radius_m`).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{field}: {problem}")]
pub struct ValidationError {
    /// Path of the field within the artifact.
    pub field: String,
    /// What is wrong with it.
    pub problem: String,
}

impl ValidationError {
    /// A validation error at `field`.
    pub fn new(field: impl Into<String>, problem: impl Into<String>) -> Self {
        Self { field: field.into(), problem: problem.into() }
    }
}

/// Result alias of this crate.
pub type Result<T, E = Error> = std::result::Result<T, E>;
