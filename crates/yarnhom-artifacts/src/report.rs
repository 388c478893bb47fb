//! Versioned JSON reports: the small documents a stage writes for people to read and scripts to
//! consume (`jq`, Python), and that later stages read back as inputs.
//!
//! A report is a JSON object whose top level holds a `format` tag (e.g. `"yarnhom.diagnosis"`)
//! and a layout `version`. Unlike the `.yh` container (whose checksums and compression matter
//! for array-heavy kinds), a report stays plain pretty-printed JSON, under the same version
//! policy (`schemas/README.md`): a reader decodes the current version, migrates every older one
//! ([`Report::migrate`]), and refuses a newer one with an error naming both versions; a writer
//! writes the current version, atomically.

use std::cmp::Ordering;
use std::path::Path;

use serde::Serialize;
use serde::de::DeserializeOwned;

use crate::atomic::write_atomic;
use crate::{Error, Result};

/// A kind of versioned JSON report: a serde type with a `format` tag and a layout `version`
/// among its top-level fields.
pub trait Report: Serialize + DeserializeOwned + schemars::JsonSchema {
    /// The `format` field, e.g. `"yarnhom.diagnosis"`.
    const FORMAT: &'static str;
    /// The current layout version, the `version` field of every report written.
    const VERSION: u32;

    /// Decode a document of an older `version` into the current type (its `version` field set
    /// to [`Report::VERSION`]). Kinds without history refuse.
    fn migrate(version: u32, _document: serde_json::Value) -> Result<Self> {
        Err(Error::NoMigration { kind: Self::FORMAT.into(), found: version, supported: Self::VERSION })
    }

    /// A human summary (what `yarnhom inspect` prints).
    fn summary(&self) -> String;
}

/// The `format` (`yarnhom.<name>`) and `version` of a report document, if it has both.
pub fn report_format(document: &serde_json::Value) -> Option<(&str, u32)> {
    let format = document.get("format")?.as_str().filter(|f| f.starts_with("yarnhom."))?;
    let version = u32::try_from(document.get("version")?.as_u64()?).ok()?;
    Some((format, version))
}

/// Decode a report document of kind `T`: the current version directly, an older one through
/// [`Report::migrate`]; a document of another format, or of a newer version, is refused.
pub fn decode_report<T: Report>(document: serde_json::Value) -> Result<T> {
    let (format, version) = report_format(&document).ok_or_else(|| Error::Decode {
        what: T::FORMAT,
        message: "no `format` and `version` fields: not a yarnhom report".into(),
    })?;
    if format != T::FORMAT {
        return Err(Error::WrongKind { expected: T::FORMAT, found: format.into() });
    }
    match version.cmp(&T::VERSION) {
        Ordering::Greater => {
            Err(Error::NewerSchema { kind: format.into(), found: version, supported: T::VERSION })
        }
        Ordering::Equal => serde_json::from_value(document)
            .map_err(|e| Error::Decode { what: T::FORMAT, message: e.to_string() }),
        Ordering::Less => T::migrate(version, document),
    }
}

/// Read a report file of kind `T` (see [`decode_report`]); errors name the file.
pub fn read_report<T: Report>(path: &Path) -> Result<T> {
    let bytes = std::fs::read(path).map_err(|e| Error::from(e).at(path))?;
    let document = serde_json::from_slice(&bytes)
        .map_err(|e| Error::Decode { what: "JSON", message: e.to_string() }.at(path))?;
    decode_report(document).map_err(|e| e.at(path))
}

/// Write `report` to `path` atomically (see [`write_atomic`]), as pretty-printed JSON
/// (`serde_json::to_string_pretty`, no trailing newline). A report whose own `format` and
/// `version` fields are not `T`'s current ones is refused: writers write the current version.
pub fn write_report<T: Report>(path: &Path, report: &T) -> Result<()> {
    let encode = |message: String| Error::Encode { what: T::FORMAT, message }.at(path);
    let document = serde_json::to_value(report).map_err(|e| encode(e.to_string()))?;
    if report_format(&document) != Some((T::FORMAT, T::VERSION)) {
        return Err(encode(format!("not a {} report of version {}", T::FORMAT, T::VERSION)));
    }
    let text = serde_json::to_string_pretty(report).map_err(|e| encode(e.to_string()))?;
    write_atomic(path, text.as_bytes()).map_err(|e| Error::from(e).at(path))
}

#[cfg(test)]
mod tests {
    use serde::Deserialize;

    use super::*;

    /// A report whose version 1 called `size` `length`.
    #[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
    struct Sample {
        format: String,
        version: u32,
        size: f64,
    }

    impl Report for Sample {
        const FORMAT: &'static str = "yarnhom.sample";
        const VERSION: u32 = 2;
        fn migrate(version: u32, document: serde_json::Value) -> Result<Self> {
            let length = document["length"].as_f64();
            match (version, length) {
                (1, Some(size)) => Ok(Sample { format: Self::FORMAT.into(), version: Self::VERSION, size }),
                (1, None) => Err(Error::Decode { what: "sample v1", message: "no `length`".into() }),
                _ => Err(Error::NoMigration { kind: Self::FORMAT.into(), found: version, supported: 2 }),
            }
        }
        fn summary(&self) -> String {
            format!("size {}", self.size)
        }
    }

    fn sample() -> Sample {
        Sample { format: Sample::FORMAT.into(), version: 2, size: 0.1 + 0.2 }
    }

    #[test]
    fn a_report_round_trips_as_pretty_json_and_old_versions_migrate() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("sample.json");
        write_report(&path, &sample()).expect("writes");
        let text = std::fs::read_to_string(&path).expect("reads");
        assert_eq!(text, serde_json::to_string_pretty(&sample()).expect("json"));
        assert_eq!(read_report::<Sample>(&path).expect("reads"), sample());
        let v1 = serde_json::json!({ "format": "yarnhom.sample", "version": 1, "length": 0.1 + 0.2 });
        assert_eq!(report_format(&v1), Some(("yarnhom.sample", 1)));
        assert_eq!(decode_report::<Sample>(v1).expect("migrates"), sample());
    }

    #[test]
    fn other_formats_newer_versions_and_stale_writes_are_refused() {
        let decode = |document: serde_json::Value| decode_report::<Sample>(document).expect_err("refused");
        let newer = decode(serde_json::json!({ "format": "yarnhom.sample", "version": 3, "size": 1.0 }));
        assert!(matches!(newer, Error::NewerSchema { found: 3, supported: 2, .. }), "{newer}");
        assert!(newer.to_string().contains("upgrade yarnhom"), "{newer}");
        let other = decode(serde_json::json!({ "format": "yarnhom.other", "version": 2 }));
        assert!(matches!(other, Error::WrongKind { expected: "yarnhom.sample", .. }), "{other}");
        assert!(matches!(decode(serde_json::json!({ "size": 1.0 })), Error::Decode { .. }));
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("stale.json");
        let stale = Sample { version: 1, ..sample() };
        let error = write_report(&path, &stale).expect_err("a stale version is not written");
        assert!(matches!(error.root(), Error::Encode { .. }) && !path.exists(), "{error}");
        let missing = read_report::<Sample>(&dir.path().join("missing.json")).expect_err("no file");
        assert!(missing.to_string().contains("missing.json"), "{missing}");
    }
}
