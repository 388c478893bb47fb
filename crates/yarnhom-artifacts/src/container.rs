//! The `.yh` container: one framing for every artifact kind.
//!
//! Layout (all integers little-endian):
//!
//! | offset | size | field |
//! |---|---|---|
//! | 0 | 8 | magic `89 59 48 4F 4D 0D 0A 1A` (`\x89YHOM\r\n\x1a`, PNG-style: catches text-mode mangling) |
//! | 8 | 2 | container version ([`CONTAINER_VERSION`]) |
//! | 10 | 4 | header length `h` |
//! | 14 | h | header: msgpack map ([`Header`]) |
//! | 14+h | 8 | payload length `p` (compressed bytes) |
//! | 22+h | p | payload: one zstd frame of the msgpack-encoded artifact (named fields) |
//! | 22+h+p | 4 | CRC-32 (IEEE) of every byte before it |
//!
//! Reading checks, in order: magic, container version, section lengths (truncation), the CRC,
//! the header, the kind, the schema version (older versions are migrated, newer ones refused),
//! the decompressed length, the content hash, the payload decode and finally the kind's own
//! validation. Each failure is a distinct [`Error`] variant.

use std::io::Read;
use std::path::Path;

use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

use crate::Artifact;
use crate::error::{Error, Result};

/// Magic bytes that open every `.yh` file.
pub const MAGIC: [u8; 8] = *b"\x89YHOM\r\n\x1a";
/// Version of the framing described in this module.
pub const CONTAINER_VERSION: u16 = 1;
/// zstd level used for payloads (a good ratio at negligible cost for our sizes).
const ZSTD_LEVEL: i32 = 9;
/// Refuse payloads that claim to decompress beyond this (guards against decompression bombs).
const MAX_PAYLOAD_BYTES: u64 = 64 << 30;
const FIXED_PREFIX: usize = 8 + 2 + 4;

/// The program (and version) that wrote an artifact.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize, schemars::JsonSchema)]
pub struct Producer {
    /// Program name, e.g. `yarnhom pattern import`.
    pub name: String,
    /// Program version.
    pub version: String,
}

impl Default for Producer {
    fn default() -> Self {
        Self { name: "yarnhom".into(), version: env!("CARGO_PKG_VERSION").into() }
    }
}

/// An artifact (or foreign file) that another artifact was made from.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize, schemars::JsonSchema)]
pub struct InputRef {
    /// Artifact kind, or the foreign format (e.g. `pyp`).
    pub kind: String,
    /// `sha256:<hex>` of the input's content ([`Header::content_hash`] for artifacts, the raw
    /// bytes for foreign files).
    pub content_hash: String,
    /// Where the input was read from, as given by the user (informational).
    pub path: String,
}

/// The container header: everything about an artifact except its payload.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize, schemars::JsonSchema)]
pub struct Header {
    /// Artifact kind, e.g. `pattern`.
    pub kind: String,
    /// Schema version of the payload.
    pub schema_version: u32,
    /// The program that wrote the file.
    pub producer: Producer,
    /// Creation time, RFC 3339 in UTC (from `SOURCE_DATE_EPOCH` when set, for reproducible files).
    pub created_utc: String,
    /// Content hashes of the inputs this artifact was made from.
    pub inputs: Vec<InputRef>,
    /// `sha256:<hex>` of the uncompressed msgpack payload: the artifact's identity.
    pub content_hash: String,
    /// Length of the uncompressed payload in bytes.
    pub payload_bytes: u64,
}

/// Who wrote an artifact and from what: the caller's part of the [`Header`].
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Provenance {
    /// The writing program.
    pub producer: Producer,
    /// Inputs the artifact was made from.
    pub inputs: Vec<InputRef>,
}

impl Provenance {
    /// What `yarnhom COMMAND` (this build) made from `inputs`.
    pub fn of(command: &str, inputs: Vec<InputRef>) -> Self {
        Provenance {
            producer: Producer {
                name: format!("yarnhom {command}"),
                version: env!("CARGO_PKG_VERSION").into(),
            },
            inputs,
        }
    }
}

/// `sha256:<hex>` of some bytes.
pub fn content_hash(bytes: &[u8]) -> String {
    let digest = Sha256::digest(bytes);
    let mut hex = String::with_capacity(7 + 64);
    hex.push_str("sha256:");
    for b in digest {
        hex.push_str(&format!("{b:02x}"));
    }
    hex
}

fn now_rfc3339() -> String {
    let now = std::env::var("SOURCE_DATE_EPOCH")
        .ok()
        .and_then(|s| s.trim().parse::<i64>().ok())
        .and_then(|secs| time::OffsetDateTime::from_unix_timestamp(secs).ok())
        .unwrap_or_else(time::OffsetDateTime::now_utc);
    now.format(&time::format_description::well_known::Rfc3339)
        .unwrap_or_else(|_| "1970-01-01T00:00:00Z".into())
}

/// Encode a value's payload: msgpack with named fields.
pub fn payload_of<T: Serialize>(value: &T) -> Result<Vec<u8>> {
    rmp_serde::to_vec_named(value).map_err(|e| Error::Encode { what: "payload", message: e.to_string() })
}

/// The header a fresh artifact of kind `T` with this payload gets.
pub fn header_for<T: Artifact>(payload: &[u8], provenance: &Provenance) -> Header {
    Header {
        kind: T::KIND.into(),
        schema_version: T::SCHEMA_VERSION,
        producer: provenance.producer.clone(),
        created_utc: now_rfc3339(),
        inputs: provenance.inputs.clone(),
        content_hash: content_hash(payload),
        payload_bytes: payload.len() as u64,
    }
}

/// Validate and encode an artifact into container bytes.
pub fn encode<T: Artifact>(value: &T, provenance: &Provenance) -> Result<Vec<u8>> {
    value.validate().map_err(|problem| Error::Invalid { kind: T::KIND, problem })?;
    let payload = payload_of(value)?;
    frame(&header_for::<T>(&payload, provenance), &payload)
}

/// Frame an already encoded msgpack payload under `header` (low level: the header is trusted as
/// given, so this also writes files of older or newer schema versions, e.g. test fixtures).
pub fn frame(header: &Header, payload: &[u8]) -> Result<Vec<u8>> {
    let header_bytes = rmp_serde::to_vec_named(header)
        .map_err(|e| Error::Encode { what: "header", message: e.to_string() })?;
    let compressed = zstd::bulk::compress(payload, ZSTD_LEVEL)
        .map_err(|e| Error::Encode { what: "zstd payload", message: e.to_string() })?;
    let header_len = u32::try_from(header_bytes.len())
        .map_err(|_| Error::Encode { what: "header", message: "longer than 4 GiB".into() })?;
    let mut out = Vec::with_capacity(FIXED_PREFIX + header_bytes.len() + 8 + compressed.len() + 4);
    out.extend_from_slice(&MAGIC);
    out.extend_from_slice(&CONTAINER_VERSION.to_le_bytes());
    out.extend_from_slice(&header_len.to_le_bytes());
    out.extend_from_slice(&header_bytes);
    out.extend_from_slice(&(compressed.len() as u64).to_le_bytes());
    out.extend_from_slice(&compressed);
    let crc = crc32fast::hash(&out);
    out.extend_from_slice(&crc.to_le_bytes());
    Ok(out)
}

/// A cursor over the container bytes that reports truncation by section.
struct Sections<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl<'a> Sections<'a> {
    fn take(&mut self, section: &'static str, n: u64) -> Result<&'a [u8]> {
        let available = (self.bytes.len() - self.at) as u64;
        if n > available {
            return Err(Error::Truncated { section, needed: n, available });
        }
        let n = n as usize;
        let out = &self.bytes[self.at..self.at + n];
        self.at += n;
        Ok(out)
    }

    fn array<const N: usize>(&mut self, section: &'static str) -> Result<[u8; N]> {
        let mut out = [0u8; N];
        out.copy_from_slice(self.take(section, N as u64)?);
        Ok(out)
    }
}

/// A verified container whose payload is decompressed but not yet decoded into a type.
#[derive(Debug, Clone)]
pub struct RawArtifact {
    /// The header.
    pub header: Header,
    /// The uncompressed msgpack payload.
    pub payload: Vec<u8>,
}

/// Read only the header, after checking framing and checksum (cheap: no decompression).
pub fn decode_header(bytes: &[u8]) -> Result<(Header, &[u8])> {
    let mut s = Sections { bytes, at: 0 };
    let magic =
        s.take("magic", 8).map_err(|_| Error::WrongMagic { found: bytes[..bytes.len().min(8)].to_vec() })?;
    if magic != MAGIC {
        return Err(Error::WrongMagic { found: magic.to_vec() });
    }
    let version = u16::from_le_bytes(s.array("container version")?);
    if version > CONTAINER_VERSION {
        return Err(Error::NewerContainer { found: version, supported: CONTAINER_VERSION });
    }
    let header_len = u32::from_le_bytes(s.array("header length")?);
    let header_bytes = s.take("header", u64::from(header_len))?;
    let payload_len = u64::from_le_bytes(s.array("payload length")?);
    let compressed = s.take("payload", payload_len)?;
    let crc_end = s.at;
    let stored = u32::from_le_bytes(s.array("checksum")?);
    if s.at != bytes.len() {
        return Err(Error::TrailingBytes { extra: (bytes.len() - s.at) as u64 });
    }
    let computed = crc32fast::hash(&bytes[..crc_end]);
    if stored != computed {
        return Err(Error::ChecksumMismatch { stored, computed });
    }
    let header: Header = rmp_serde::from_slice(header_bytes)
        .map_err(|e| Error::Decode { what: "header", message: e.to_string() })?;
    Ok((header, compressed))
}

/// Check framing, checksum, decompression and content hash; leave the payload undecoded.
pub fn decode_raw(bytes: &[u8]) -> Result<RawArtifact> {
    let (header, compressed) = decode_header(bytes)?;
    if header.payload_bytes > MAX_PAYLOAD_BYTES {
        return Err(Error::Decode {
            what: "payload",
            message: format!("declared size {} exceeds the limit", header.payload_bytes),
        });
    }
    let payload = decompress(compressed, header.payload_bytes)?;
    let computed = content_hash(&payload);
    if computed != header.content_hash {
        return Err(Error::ContentHashMismatch { stored: header.content_hash, computed });
    }
    Ok(RawArtifact { header, payload })
}

fn decompress(compressed: &[u8], expected: u64) -> Result<Vec<u8>> {
    let err = |message: String| Error::Decode { what: "zstd payload", message };
    let decoder = zstd::stream::read::Decoder::new(compressed).map_err(|e| err(e.to_string()))?;
    let mut out = Vec::with_capacity(expected.min(1 << 26) as usize);
    decoder.take(expected + 1).read_to_end(&mut out).map_err(|e| err(e.to_string()))?;
    if out.len() as u64 != expected {
        return Err(err(format!("decompressed to {} bytes, header says {expected}", out.len())));
    }
    Ok(out)
}

/// Decode a verified payload as kind `T`, migrating older schema versions, then validate it.
pub fn decode_payload<T: Artifact>(raw: &RawArtifact) -> Result<T> {
    let h = &raw.header;
    if h.kind != T::KIND {
        return Err(Error::WrongKind { expected: T::KIND, found: h.kind.clone() });
    }
    let value = match h.schema_version.cmp(&T::SCHEMA_VERSION) {
        std::cmp::Ordering::Greater => {
            return Err(Error::NewerSchema {
                kind: h.kind.clone(),
                found: h.schema_version,
                supported: T::SCHEMA_VERSION,
            });
        }
        std::cmp::Ordering::Equal => rmp_serde::from_slice(&raw.payload)
            .map_err(|e| Error::Decode { what: T::KIND, message: e.to_string() })?,
        std::cmp::Ordering::Less => T::migrate(h.schema_version, &raw.payload)?,
    };
    value.validate().map_err(|problem| Error::Invalid { kind: T::KIND, problem })?;
    Ok(value)
}

/// Decode container bytes as kind `T`.
pub fn decode<T: Artifact>(bytes: &[u8]) -> Result<(Header, T)> {
    let raw = decode_raw(bytes)?;
    let value = decode_payload::<T>(&raw)?;
    Ok((raw.header, value))
}

/// Read and decode a `.yh` file of kind `T`; errors name the file.
pub fn read<T: Artifact>(path: impl AsRef<Path>) -> Result<(Header, T)> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(|e| Error::from(e).at(path))?;
    decode(&bytes).map_err(|e| e.at(path))
}

/// Validate, encode and atomically write an artifact ([`crate::atomic`]), so a reader never sees
/// a half-written file. Returns the header written.
pub fn write<T: Artifact>(path: impl AsRef<Path>, value: &T, provenance: &Provenance) -> Result<Header> {
    let path = path.as_ref();
    let bytes = encode(value, provenance).map_err(|e| e.at(path))?;
    let (header, _) = decode_header(&bytes)?;
    crate::atomic::write_atomic(path, &bytes).map_err(|e| Error::from(e).at(path))?;
    Ok(header)
}
