//! The `yarnhom` MCAP metadata record.

use std::collections::BTreeMap;

use crate::TraceError;

/// Name of the MCAP metadata record written by [`TraceWriter::write_metadata`](crate::TraceWriter::write_metadata).
pub const METADATA_NAME: &str = "yarnhom";

/// Metadata key of the producer's name.
const KEY_PRODUCER_NAME: &str = "producer_name";
/// Metadata key of the producer's version.
const KEY_PRODUCER_VERSION: &str = "producer_version";
/// Metadata key of the version of this crate that wrote the trace.
const KEY_WRITER: &str = "yarnhom_trace_version";

const RESERVED_KEYS: [&str; 3] = [KEY_PRODUCER_NAME, KEY_PRODUCER_VERSION, KEY_WRITER];

/// Who produced a trace and with what inputs; stored as the MCAP metadata record `yarnhom`.
///
/// In the record, the producer's name and version are stored under `producer_name` and
/// `producer_version`, this crate's version under `yarnhom_trace_version`, and each of
/// [`entries`](Self::entries) under its own key. The three keys are reserved: entries may not
/// use them.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct TraceMetadata {
    /// Name of the program that produced the trace (e.g. `yarnhom-sim`).
    pub producer_name: String,
    /// Version of that program.
    pub producer_version: String,
    /// Free key/value pairs (scene name, material file, command line, ...).
    pub entries: BTreeMap<String, String>,
}

impl TraceMetadata {
    /// Metadata for the given producer with no entries.
    pub fn new(producer_name: impl Into<String>, producer_version: impl Into<String>) -> Self {
        Self {
            producer_name: producer_name.into(),
            producer_version: producer_version.into(),
            entries: BTreeMap::new(),
        }
    }

    /// Adds (or replaces) one free entry.
    #[must_use]
    pub fn with_entry(mut self, key: impl Into<String>, value: impl Into<String>) -> Self {
        self.entries.insert(key.into(), value.into());
        self
    }

    /// Builds the MCAP metadata record.
    pub(crate) fn to_record(&self) -> Result<mcap::records::Metadata, TraceError> {
        if let Some(key) = self.entries.keys().find(|key| RESERVED_KEYS.contains(&key.as_str())) {
            return Err(TraceError::ReservedMetadataKey { key: key.clone() });
        }
        let mut metadata = self.entries.clone();
        metadata.insert(KEY_PRODUCER_NAME.into(), self.producer_name.clone());
        metadata.insert(KEY_PRODUCER_VERSION.into(), self.producer_version.clone());
        metadata.insert(KEY_WRITER.into(), env!("CARGO_PKG_VERSION").into());
        Ok(mcap::records::Metadata { name: METADATA_NAME.into(), metadata })
    }

    /// Parses the key/values of a `yarnhom` metadata record. The writer-version key is dropped.
    pub(crate) fn from_record(mut metadata: BTreeMap<String, String>) -> Result<Self, TraceError> {
        let mut take = |key: &'static str| metadata.remove(key).ok_or(TraceError::MissingMetadataKey { key });
        let producer_name = take(KEY_PRODUCER_NAME)?;
        let producer_version = take(KEY_PRODUCER_VERSION)?;
        metadata.remove(KEY_WRITER);
        Ok(Self { producer_name, producer_version, entries: metadata })
    }
}

/// Reads every `yarnhom` metadata record of a complete trace held in memory, in file order.
///
/// Scans the top-level records without decompressing chunks (metadata records never live in
/// chunks), so it works with or without a summary section. The streaming
/// [`TraceReader`](crate::TraceReader) does not report metadata, because the MCAP message
/// reader it is built on skips metadata records.
pub fn read_metadata(mcap: &[u8]) -> Result<Vec<TraceMetadata>, TraceError> {
    let mut found = Vec::new();
    for record in mcap::read::LinearReader::new(mcap)? {
        if let mcap::records::Record::Metadata(metadata) = record?
            && metadata.name == METADATA_NAME
        {
            found.push(TraceMetadata::from_record(metadata.metadata)?);
        }
    }
    Ok(found)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn record_round_trip() {
        let meta = TraceMetadata::new("sim", "1.2.3").with_entry("scene", "drape");
        let record = meta.to_record().expect("record");
        assert_eq!(record.name, "yarnhom");
        assert_eq!(record.metadata["producer_name"], "sim");
        assert_eq!(record.metadata["yarnhom_trace_version"], env!("CARGO_PKG_VERSION"));
        assert_eq!(TraceMetadata::from_record(record.metadata).expect("parse"), meta);
    }

    #[test]
    fn reserved_keys_are_refused() {
        let meta = TraceMetadata::new("sim", "1").with_entry("producer_name", "x");
        assert!(matches!(
            meta.to_record(),
            Err(TraceError::ReservedMetadataKey { key }) if key == "producer_name"
        ));
    }

    #[test]
    fn missing_keys_are_named() {
        let err = TraceMetadata::from_record(BTreeMap::new()).expect_err("must fail");
        assert!(err.to_string().contains("producer_name"), "{err}");
    }
}
