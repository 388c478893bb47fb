//! Reading any input a command accepts, recognised by its content (not its file name):
//! a `.yh` artifact, a JSON document written by `convert --to json`, an HDF5 export or a `.pyp`.

use std::path::{Path, PathBuf};

use anyhow::Context;
use yarnhom_artifacts::container::{self, content_hash};
use yarnhom_artifacts::{AnyArtifact, Fabric, Header, InputRef, JsonDocument, Pattern, Producer, Provenance};

/// The formats `yarnhom` reads and writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Format {
    /// The native container (`NAME.KIND.yh`).
    Yh,
    /// JSON: `{"header": .., "payload": ..}`.
    Json,
    /// HDF5 (array-holding kinds), readable by h5py.
    Hdf5,
    /// The published HYLC periodic pattern text format (patterns only).
    Pyp,
}

impl Format {
    /// File extension for this format, given the artifact kind.
    pub fn extension(self, kind: &str) -> String {
        match self {
            Format::Yh => format!("{kind}.yh"),
            Format::Json => format!("{kind}.json"),
            Format::Hdf5 => format!("{kind}.h5"),
            Format::Pyp => "pyp".into(),
        }
    }

    /// Recognise a format from a file's first bytes.
    pub fn sniff(bytes: &[u8]) -> Option<Format> {
        const HDF5_MAGIC: &[u8] = b"\x89HDF\r\n\x1a\n";
        if bytes.starts_with(&container::MAGIC) {
            Some(Format::Yh)
        } else if bytes.starts_with(HDF5_MAGIC) {
            Some(Format::Hdf5)
        } else if bytes.iter().find(|b| !b.is_ascii_whitespace()) == Some(&b'{') {
            Some(Format::Json)
        } else if bytes.windows(8).any(|w| w == b"*pattern") {
            Some(Format::Pyp)
        } else {
            None
        }
    }
}

/// An artifact read from some file, with its header (synthesised for foreign formats).
pub struct Loaded {
    pub path: PathBuf,
    pub format: Format,
    pub header: Header,
    pub artifact: AnyArtifact,
}

/// File stem without the `.KIND.yh` / `.pyp` / ... suffixes: `rib` for `data/rib.pattern.yh`.
pub fn base_name(path: &Path) -> String {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    name.split('.').next().filter(|s| !s.is_empty()).unwrap_or("unnamed").to_string()
}

/// Provenance of an artifact written by `command` from `inputs`.
pub fn provenance(command: &str, inputs: Vec<InputRef>) -> Provenance {
    Provenance {
        producer: Producer { name: format!("yarnhom {command}"), version: env!("CARGO_PKG_VERSION").into() },
        inputs,
    }
}

/// Read any supported input. `fabric` overrides fabric inference for `.pyp` imports.
pub fn load(path: &Path, fabric: Option<Fabric>) -> anyhow::Result<Loaded> {
    let bytes = std::fs::read(path).with_context(|| format!("cannot read {}", path.display()))?;
    let format = Format::sniff(&bytes).with_context(|| {
        format!("{}: not a yarnhom artifact, JSON document, HDF5 file or .pyp pattern", path.display())
    })?;
    let (header, artifact) = match format {
        Format::Yh => {
            let raw = container::decode_raw(&bytes).map_err(|e| e.at(path))?;
            let artifact = AnyArtifact::decode(&raw).map_err(|e| e.at(path))?;
            (raw.header, artifact)
        }
        Format::Json => {
            let doc: JsonDocument = serde_json::from_slice(&bytes)
                .with_context(|| format!("{}: not a yarnhom JSON document", path.display()))?;
            let artifact = AnyArtifact::from_json_document(&doc).map_err(|e| e.at(path))?;
            (doc.header, artifact)
        }
        Format::Hdf5 => read_hdf5(path)?,
        Format::Pyp => {
            let text = std::str::from_utf8(&bytes)
                .with_context(|| format!("{}: .pyp is not UTF-8 text", path.display()))?;
            let pattern =
                yarnhom_artifacts::pyp::parse_pyp(text, &base_name(path), fabric).map_err(|e| e.at(path))?;
            let input = InputRef {
                kind: "pyp".into(),
                content_hash: content_hash(&bytes),
                path: path.display().to_string(),
            };
            let payload = container::payload_of(&pattern)?;
            let header =
                container::header_for::<Pattern>(&payload, &provenance("pattern import", vec![input]));
            (header, AnyArtifact::Pattern(pattern))
        }
    };
    Ok(Loaded { path: path.to_path_buf(), format, header, artifact })
}

#[cfg(feature = "hdf5")]
fn read_hdf5(path: &Path) -> anyhow::Result<(Header, AnyArtifact)> {
    Ok(yarnhom_artifacts::hdf5::import(path).map_err(|e| e.at(path))?)
}

#[cfg(not(feature = "hdf5"))]
fn read_hdf5(path: &Path) -> anyhow::Result<(Header, AnyArtifact)> {
    anyhow::bail!("{}: this yarnhom was built without the `hdf5` feature", path.display())
}

/// Load a pattern (`.yh`, JSON, HDF5 or `.pyp`) and the reference to it for provenance.
pub fn load_pattern(path: &Path) -> anyhow::Result<(Pattern, InputRef)> {
    let loaded = load(path, None)?;
    let input = InputRef {
        kind: "pattern".into(),
        content_hash: loaded.header.content_hash.clone(),
        path: path.display().to_string(),
    };
    let AnyArtifact::Pattern(pattern) = loaded.artifact else {
        anyhow::bail!("{}: holds a '{}', not a pattern", path.display(), loaded.artifact.kind())
    };
    Ok((pattern, input))
}
