//! The one way to open an input: every file a yarnhom command takes is recognised by its
//! content, never by its name, and decoded into a typed value, or refused with one error that
//! names the file and the problem.
//!
//! | content | [`Format`] | [`Contents`] |
//! |---|---|---|
//! | `.yh` container of any kind (older schema versions migrated) | `Yh` | `Artifact` |
//! | JSON document of `yarnhom convert --to json` (`{"header", "payload"}`) | `Json` | `Artifact` |
//! | HDF5 export of `yarnhom convert --to hdf5` (feature `hdf5`) | `Hdf5` | `Artifact` |
//! | published HYLC `.pyp` pattern | `Pyp` | `Artifact` (a pattern) |
//! | ARCSim-HYLC material JSON (`"strain scale"`, `//` comments allowed) | `Arcsim` | `Artifact` (a spline) |
//! | Ch. 6 material JSON (`{"areal_density_kg_m2", "membrane", "bending"}`) | `Membrane` | `Membrane` |
//! | calibration report (`{"format": "yarnhom.<name>", "version": N, ...}`) | `Report` | `Report` |
//! | MCAP trace | `Mcap` | `Trace` (streamed by `yarnhom-trace`, not decoded here) |
//!
//! Foreign formats get a header made up on the spot (producer `yarnhom pattern import` or
//! `yarnhom fit import-arcsim`, the file's content hash as input), so provenance can name them.

use std::path::{Path, PathBuf};

use crate::container::{self, content_hash};
use crate::error::{Error, Result};
use crate::membrane::MembraneMaterial;
use crate::report::report_format;
use crate::{
    AnyArtifact, Artifact, Fabric, Header, InputRef, JsonDocument, Pattern, Provenance, Spline, YarnModel,
};

/// The first bytes of an HDF5 file.
const HDF5_MAGIC: &[u8] = b"\x89HDF\r\n\x1a\n";
/// The first bytes of an MCAP file.
pub const MCAP_MAGIC: &[u8] = b"\x89MCAP0\r\n";
/// The prefix of a yarnmodel spec naming a row of the thesis' Table 4.1.
pub const TABLE_4_1: &str = "table4.1:";

/// How a file was recognised.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// The native container (`NAME.KIND.yh`).
    Yh,
    /// A JSON document of an artifact (`{"header": .., "payload": ..}`).
    Json,
    /// An HDF5 export of an artifact.
    Hdf5,
    /// The published HYLC periodic pattern text format.
    Pyp,
    /// An ARCSim-HYLC spline material JSON.
    Arcsim,
    /// A Ch. 6 material JSON.
    Membrane,
    /// A versioned calibration report (JSON).
    Report,
    /// An MCAP trace.
    Mcap,
}

/// A versioned JSON report (`shell-fit.json`, `yarn-fit.json`, `report.json`), undecoded: the
/// crate that owns its type decodes it (`yarnhom-calib`).
#[derive(Debug, Clone, PartialEq)]
pub struct ReportDocument {
    /// The `format` field, e.g. `yarnhom.diagnosis`.
    pub format: String,
    /// The `version` field.
    pub version: u32,
    /// The whole document.
    pub document: serde_json::Value,
}

/// What a file holds.
// One value per opened file, moved out at once: the artifact variant's size costs nothing.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone, PartialEq)]
pub enum Contents {
    /// An artifact, with its header (made up for foreign formats).
    Artifact {
        /// The container header.
        header: Header,
        /// The decoded, validated artifact.
        artifact: AnyArtifact,
    },
    /// A Ch. 6 cloth material.
    Membrane(MembraneMaterial),
    /// A calibration report.
    Report(ReportDocument),
    /// An MCAP trace, to be streamed.
    Trace,
}

/// An opened input.
#[derive(Debug, Clone, PartialEq)]
pub struct Input {
    /// The file.
    pub path: PathBuf,
    /// How it was recognised.
    pub format: Format,
    /// What it holds.
    pub contents: Contents,
}

impl Contents {
    /// What the contents are, for messages: the artifact kind, `membrane material`, the
    /// report's format or `trace`.
    pub fn describe(&self) -> String {
        match self {
            Contents::Artifact { artifact, .. } => format!("'{}'", artifact.kind()),
            Contents::Membrane(_) => "Ch. 6 membrane material".into(),
            Contents::Report(r) => format!("'{}' report", r.format),
            Contents::Trace => "MCAP trace".into(),
        }
    }
}

impl Input {
    /// The artifact this input holds, with its header; any other content is an error naming
    /// the file.
    pub fn into_artifact(self) -> Result<(Header, AnyArtifact)> {
        match self.contents {
            Contents::Artifact { header, artifact } => Ok((header, artifact)),
            other => Err(Error::NotAnArtifact { found: other.describe() }.at(&self.path)),
        }
    }
}

/// A typed artifact opened from a file, and the reference to it that provenance records.
#[derive(Debug, Clone, PartialEq)]
pub struct Opened<T> {
    /// The artifact.
    pub value: T,
    /// Its header.
    pub header: Header,
    /// The input reference (kind, content hash, path) for the provenance of what is made from it.
    pub input: InputRef,
}

/// Opens any input.
pub fn open(path: impl AsRef<Path>) -> Result<Input> {
    open_pattern_as(path, None)
}

/// Opens any input; a `.pyp` pattern is read as `fabric` when given (else its fabric is
/// inferred).
pub fn open_pattern_as(path: impl AsRef<Path>, fabric: Option<Fabric>) -> Result<Input> {
    let path = path.as_ref();
    let Some(bytes) = read_unless_trace(path).map_err(|e| Error::from(e).at(path))? else {
        return Ok(Input { path: path.to_path_buf(), format: Format::Mcap, contents: Contents::Trace });
    };
    let (format, contents) = decode(path, &bytes, fabric).map_err(|e| e.at(path))?;
    Ok(Input { path: path.to_path_buf(), format, contents })
}

/// The bytes of a file, or `None` for an MCAP trace, which is streamed, never read whole.
fn read_unless_trace(path: &Path) -> std::io::Result<Option<Vec<u8>>> {
    use std::io::Read;
    let mut file = std::fs::File::open(path)?;
    let mut bytes = Vec::new();
    file.by_ref().take(MCAP_MAGIC.len() as u64).read_to_end(&mut bytes)?;
    if bytes == MCAP_MAGIC {
        return Ok(None);
    }
    file.read_to_end(&mut bytes)?;
    Ok(Some(bytes))
}

/// Opens an artifact of kind `T` (a spline also from an ARCSim-HYLC JSON, a pattern also from a
/// `.pyp`); another kind or content is an error naming the file.
pub fn open_artifact<T: Artifact + TryFrom<AnyArtifact, Error = AnyArtifact>>(
    path: impl AsRef<Path>,
) -> Result<Opened<T>> {
    let path = path.as_ref();
    let (header, artifact) = open(path)?.into_artifact()?;
    let value = T::try_from(artifact)
        .map_err(|other| Error::WrongKind { expected: T::KIND, found: other.kind().to_string() }.at(path))?;
    let input = InputRef {
        kind: T::KIND.into(),
        content_hash: header.content_hash.clone(),
        path: path.display().to_string(),
    };
    Ok(Opened { value, header, input })
}

/// A yarn model from a spec: `table4.1:ROW` (a row of the thesis' Table 4.1) or a `yarnmodel`
/// file; the input reference is `None` for a built-in row.
pub fn open_yarn_model(spec: &str) -> Result<(YarnModel, Option<InputRef>)> {
    match spec.strip_prefix(TABLE_4_1) {
        Some(_) => Ok((builtin_yarn_model(spec)?, None)),
        None => open_artifact::<YarnModel>(spec).map(|o| (o.value, Some(o.input))),
    }
}

/// The pattern at `path` and the yarn model of `model_spec` (see [`open_yarn_model`]) a tile
/// is built from, and the inputs they name in provenance (the pattern first).
pub fn open_pattern_and_model(path: &Path, model_spec: &str) -> Result<(Pattern, YarnModel, Vec<InputRef>)> {
    let pattern = open_artifact::<Pattern>(path)?;
    let (model, model_input) = open_yarn_model(model_spec)?;
    Ok((pattern.value, model, std::iter::once(pattern.input).chain(model_input).collect()))
}

/// A built-in yarn model: `table4.1:ROW` (or just `ROW`), a row of the thesis' Table 4.1.
pub fn builtin_yarn_model(spec: &str) -> Result<YarnModel> {
    let row = spec.strip_prefix(TABLE_4_1).unwrap_or(spec);
    YarnModel::table_4_1(row).ok_or_else(|| {
        let known: Vec<String> = YarnModel::table_4_1_rows().map(|r| format!("{TABLE_4_1}{r}")).collect();
        Error::UnknownYarnModel { name: spec.into(), known: known.join(", ") }
    })
}

/// A file's name without its `.KIND.yh`, `.pyp`, ... suffixes: `rib` for `data/rib.pattern.yh`.
pub fn base_name(path: &Path) -> String {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    name.split('.').next().filter(|s| !s.is_empty()).unwrap_or("unnamed").to_string()
}

/// Recognises and decodes the bytes of `path`.
fn decode(path: &Path, bytes: &[u8], fabric: Option<Fabric>) -> Result<(Format, Contents)> {
    if bytes.starts_with(&container::MAGIC) {
        let raw = container::decode_raw(bytes)?;
        let artifact = AnyArtifact::decode(&raw)?;
        Ok((Format::Yh, Contents::Artifact { header: raw.header, artifact }))
    } else if bytes.starts_with(HDF5_MAGIC) {
        let (header, artifact) = read_hdf5(path)?;
        Ok((Format::Hdf5, Contents::Artifact { header, artifact }))
    } else if bytes.iter().find(|b| !b.is_ascii_whitespace()).is_some_and(|&b| b == b'{' || b == b'/') {
        decode_json(path, bytes)
    } else if bytes.windows(8).any(|w| w == b"*pattern") {
        decode_pyp(path, bytes, fabric)
    } else {
        Err(Error::UnknownFormat)
    }
}

/// A JSON input: an artifact document, an ARCSim-HYLC material, a Ch. 6 material or a report.
fn decode_json(path: &Path, bytes: &[u8]) -> Result<(Format, Contents)> {
    let text = std::str::from_utf8(bytes).map_err(|e| json_error(e.to_string()))?;
    let value: serde_json::Value = match serde_json::from_str(text) {
        Ok(value) => value,
        // ARCSim's JSON allows comments; nothing else yarnhom reads does.
        Err(_) => return decode_arcsim(path, bytes, text),
    };
    let has = |key: &str| value.get(key).is_some();
    if has("strain scale") {
        decode_arcsim(path, bytes, text)
    } else if has("header") && has("payload") {
        let doc: JsonDocument = serde_json::from_value(value).map_err(|e| json_error(e.to_string()))?;
        let artifact = AnyArtifact::from_json_document(&doc)?;
        Ok((Format::Json, Contents::Artifact { header: doc.header, artifact }))
    } else if has("membrane") {
        let material: MembraneMaterial =
            serde_json::from_value(value).map_err(|e| json_error(format!("not a Ch. 6 material: {e}")))?;
        Ok((Format::Membrane, Contents::Membrane(material)))
    } else if let Some((format, version)) = report_format(&value) {
        let report = ReportDocument { format: format.to_string(), version, document: value };
        Ok((Format::Report, Contents::Report(report)))
    } else {
        Err(json_error(
            "none of: an artifact document ({\"header\", \"payload\"}), an ARCSim-HYLC material (\"strain scale\"), \
             a Ch. 6 material (\"membrane\"), a yarnhom report (\"format\": \"yarnhom.…\")"
                .into(),
        ))
    }
}

fn json_error(message: String) -> Error {
    Error::Format { format: "JSON", line: 0, message }
}

/// An ARCSim-HYLC material as a spline named after the file, with a made-up header.
fn decode_arcsim(path: &Path, bytes: &[u8], text: &str) -> Result<(Format, Contents)> {
    let spline: Spline = crate::arcsim::parse_spline(path, text)?;
    let header = foreign_header(&spline, "fit import-arcsim", "arcsim-material", path, bytes)?;
    Ok((Format::Arcsim, Contents::Artifact { header, artifact: AnyArtifact::Spline(spline) }))
}

/// A `.pyp` pattern named after the file, with a made-up header.
fn decode_pyp(path: &Path, bytes: &[u8], fabric: Option<Fabric>) -> Result<(Format, Contents)> {
    let text = std::str::from_utf8(bytes).map_err(|e| Error::Format {
        format: ".pyp",
        line: 0,
        message: format!("not UTF-8 text: {e}"),
    })?;
    let pattern = crate::pyp::parse_pyp(text, &base_name(path), fabric)?;
    let header = foreign_header(&pattern, "pattern import", "pyp", path, bytes)?;
    Ok((Format::Pyp, Contents::Artifact { header, artifact: AnyArtifact::Pattern(pattern) }))
}

/// The header of an artifact read from a foreign file: made by `yarnhom COMMAND`, from that
/// file (its kind `input_kind` and content hash).
fn foreign_header<T: Artifact>(
    value: &T,
    command: &str,
    input_kind: &str,
    path: &Path,
    bytes: &[u8],
) -> Result<Header> {
    let input = InputRef {
        kind: input_kind.into(),
        content_hash: content_hash(bytes),
        path: path.display().to_string(),
    };
    let payload = container::payload_of(value)?;
    Ok(container::header_for::<T>(&payload, &Provenance::of(command, vec![input])))
}

#[cfg(feature = "hdf5")]
fn read_hdf5(path: &Path) -> Result<(Header, AnyArtifact)> {
    crate::hdf5::import(path)
}

#[cfg(not(feature = "hdf5"))]
fn read_hdf5(_: &Path) -> Result<(Header, AnyArtifact)> {
    Err(Error::Unrepresentable {
        format: "hdf5",
        message: "this yarnhom was built without the `hdf5` feature".into(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Pattern;

    fn write(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
        let path = dir.join(name);
        std::fs::write(&path, bytes).expect("write");
        path
    }

    #[test]
    fn json_inputs_are_told_apart_by_content_whatever_their_name() {
        let dir = tempfile::tempdir().expect("dir");
        let membrane = br#"{"areal_density_kg_m2": 0.2,
            "membrane": {"k_xx": 60, "k_xy": 5, "k_yy": 25, "k_ss": 8, "k_n1": 0, "k_n2": 0},
            "bending": {"k_weft": 1e-6, "k_bias": 1e-6, "k_warp": 1e-6}}"#;
        let input = open(write(dir.path(), "material.spline.yh", membrane)).expect("opens");
        assert_eq!(input.format, Format::Membrane);
        let Contents::Membrane(m) = input.contents else { panic!("a membrane") };
        assert_eq!(m.membrane.k_yy, 25.0);

        let report = br#"{"format": "yarnhom.shell-fit", "version": 1, "fabric": "x"}"#;
        let input = open(write(dir.path(), "a.json", report)).expect("opens");
        let Contents::Report(r) = input.contents else { panic!("a report") };
        assert_eq!((r.format.as_str(), r.version), ("yarnhom.shell-fit", 1));

        let err = open(write(dir.path(), "b.json", br#"{"what": 1}"#)).expect_err("unknown JSON");
        assert!(err.to_string().starts_with(&dir.path().join("b.json").display().to_string()), "{err}");
        let err = open(write(dir.path(), "c.bin", b"\x00\x01garbage")).expect_err("unknown bytes");
        assert!(err.to_string().contains("c.bin"), "{err}");
    }

    #[test]
    fn a_published_material_opens_as_a_spline_and_a_published_pattern_as_a_pattern() {
        let data = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data");
        let spline = open_artifact::<Spline>(format!("{data}/hylc-materials/stock1.json")).expect("spline");
        assert_eq!(spline.value.name, "stock1");
        assert_eq!(spline.header.producer.name, "yarnhom fit import-arcsim");
        let pattern = open_artifact::<Pattern>(format!("{data}/hylc-patterns/rib.pyp")).expect("pattern");
        assert_eq!(pattern.value.name, "rib");
        assert_eq!(pattern.input.kind, "pattern");
        let err = open_artifact::<Pattern>(format!("{data}/hylc-materials/stock1.json")).expect_err("kind");
        assert!(err.to_string().contains("expected a 'pattern'"), "{err}");
    }

    #[test]
    fn yarn_models_come_from_table_4_1_or_a_file() {
        let (model, input) = open_yarn_model("table4.1:rib").expect("built-in");
        assert_eq!((model, input), (YarnModel::table_4_1("rib").expect("row"), None));
        let err = open_yarn_model("table4.1:nonsense").expect_err("no such row");
        assert!(err.to_string().contains("nonsense"), "{err}");
        assert!(open_yarn_model("/no/such/file.yarnmodel.yh").is_err());
    }
}
