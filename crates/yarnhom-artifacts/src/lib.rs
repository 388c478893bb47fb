#![doc = include_str!("../README.md")]

pub mod arcsim;
pub mod atomic;
pub mod check;
pub mod container;
pub mod diff;
pub mod error;
pub mod grid;
#[cfg(feature = "hdf5")]
pub mod hdf5;
pub mod membrane;
pub mod open;
pub mod pattern;
pub mod pyp;
pub mod report;
pub mod rvesolve;
pub mod schema;
pub mod spline;
pub mod swatch;
pub mod yarnmodel;

use serde::{Deserialize, Serialize, de::DeserializeOwned};

pub use atomic::{AtomicFile, write_atomic};
pub use container::{Header, InputRef, Producer, Provenance, RawArtifact};
pub use error::{Error, Result, ValidationError};
pub use grid::{Grid, GridSample, GridShard, GridTerm, MergeError};
pub use pattern::{Fabric, Pattern, RestState, Yarn};
pub use rvesolve::{RveSolve, StrainSample};
pub use spline::{AxisLimit, BicubicTerm, CubicTerm, FitSettings, Spline, SplineOrigin};
pub use swatch::{GlueSettings, GlueSpring, Swatch, SwatchYarn};
pub use yarnmodel::{YarnMechanics, YarnModel};

/// A kind of artifact: a serde type with a name, a schema version, invariants and migrations.
pub trait Artifact: Serialize + DeserializeOwned + schemars::JsonSchema {
    /// The kind's name in headers and file names (`<name>.<KIND>.yh`).
    const KIND: &'static str;
    /// The current schema version of the payload.
    const SCHEMA_VERSION: u32;
    /// Check the kind's invariants.
    fn validate(&self) -> std::result::Result<(), ValidationError>;
    /// A human summary for `yarnhom inspect`.
    fn summary(&self) -> String;
    /// Decode a msgpack payload of an older schema version. Kinds without history refuse.
    fn migrate(version: u32, _payload: &[u8]) -> Result<Self> {
        Err(Error::NoMigration { kind: Self::KIND.into(), found: version, supported: Self::SCHEMA_VERSION })
    }
}

impl Artifact for Pattern {
    const KIND: &'static str = "pattern";
    const SCHEMA_VERSION: u32 = 1;
    fn validate(&self) -> std::result::Result<(), ValidationError> {
        Pattern::validate(self)
    }
    fn summary(&self) -> String {
        Pattern::summary(self)
    }
}

impl Artifact for YarnModel {
    const KIND: &'static str = "yarnmodel";
    const SCHEMA_VERSION: u32 = 1;
    fn validate(&self) -> std::result::Result<(), ValidationError> {
        YarnModel::validate(self)
    }
    fn summary(&self) -> String {
        YarnModel::summary(self)
    }
    fn migrate(version: u32, payload: &[u8]) -> Result<Self> {
        YarnModel::migrate(version, payload)
    }
}

/// An artifact as a JSON document: its header and its payload (`yarnhom convert --to json`).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct JsonDocument {
    /// The container header.
    pub header: Header,
    /// The payload, in the schema version named by the header.
    pub payload: serde_json::Value,
}

macro_rules! artifact_kinds {
    ($($variant:ident => $ty:ty),+ $(,)?) => {
        /// A decoded artifact of any kind.
        // One value per file, moved out at once: the size of the largest kind costs nothing.
        #[allow(clippy::large_enum_variant)]
        #[derive(Debug, Clone, PartialEq)]
        pub enum AnyArtifact {
            $(
                #[doc = concat!("A `", stringify!($ty), "`.")]
                $variant($ty),
            )+
        }

        $(
            impl TryFrom<AnyArtifact> for $ty {
                type Error = AnyArtifact;
                /// The artifact if it is of this kind, else the artifact back.
                fn try_from(artifact: AnyArtifact) -> std::result::Result<Self, AnyArtifact> {
                    match artifact {
                        AnyArtifact::$variant(value) => Ok(value),
                        other => Err(other),
                    }
                }
            }
        )+

        /// Every artifact kind this build knows.
        pub const KINDS: &[&str] = &[$(<$ty as Artifact>::KIND),+];

        impl AnyArtifact {
            /// Decode a verified container of any known kind (migrating older versions).
            pub fn decode(raw: &RawArtifact) -> Result<Self> {
                match raw.header.kind.as_str() {
                    $(k if k == <$ty as Artifact>::KIND => Ok(Self::$variant(container::decode_payload(raw)?)),)+
                    other => Err(Error::UnknownKind(other.to_string())),
                }
            }

            /// The kind's name.
            pub fn kind(&self) -> &'static str {
                match self { $(Self::$variant(_) => <$ty as Artifact>::KIND,)+ }
            }

            /// A human summary.
            pub fn summary(&self) -> String {
                match self { $(Self::$variant(a) => a.summary(),)+ }
            }

            /// Validate and encode into container bytes.
            pub fn encode(&self, provenance: &Provenance) -> Result<Vec<u8>> {
                match self { $(Self::$variant(a) => container::encode(a, provenance),)+ }
            }

            /// The payload as JSON (current schema version).
            pub fn to_json(&self) -> Result<serde_json::Value> {
                let value = match self { $(Self::$variant(a) => serde_json::to_value(a),)+ };
                value.map_err(|e| Error::Encode { what: "json", message: e.to_string() })
            }
        }

        /// The JSON Schema of a kind's current version.
        pub fn json_schema(kind: &str) -> Result<serde_json::Value> {
            match kind {
                $(k if k == <$ty as Artifact>::KIND => Ok(schema::of::<$ty>()),)+
                other => Err(Error::UnknownKind(other.to_string())),
            }
        }

        /// The current schema version of a kind.
        pub fn schema_version(kind: &str) -> Result<u32> {
            match kind {
                $(k if k == <$ty as Artifact>::KIND => Ok(<$ty as Artifact>::SCHEMA_VERSION),)+
                other => Err(Error::UnknownKind(other.to_string())),
            }
        }
    };
}

impl Artifact for RveSolve {
    const KIND: &'static str = "rvesolve";
    const SCHEMA_VERSION: u32 = 2;
    fn validate(&self) -> std::result::Result<(), ValidationError> {
        RveSolve::validate(self)
    }
    fn summary(&self) -> String {
        RveSolve::summary(self)
    }
    /// Version 1 had no equilibrium stress (3.23c): it decodes with `stress` absent.
    fn migrate(version: u32, payload: &[u8]) -> Result<Self> {
        match version {
            1 => rmp_serde::from_slice(payload)
                .map_err(|e| Error::Decode { what: "rvesolve v1", message: e.to_string() }),
            _ => Err(Error::NoMigration { kind: Self::KIND.into(), found: version, supported: 2 }),
        }
    }
}

impl Artifact for Grid {
    const KIND: &'static str = "grid";
    const SCHEMA_VERSION: u32 = 1;
    fn validate(&self) -> std::result::Result<(), ValidationError> {
        Grid::validate(self)
    }
    fn summary(&self) -> String {
        Grid::summary(self)
    }
}

impl Artifact for Swatch {
    const KIND: &'static str = "swatch";
    const SCHEMA_VERSION: u32 = 1;
    fn validate(&self) -> std::result::Result<(), ValidationError> {
        Swatch::validate(self)
    }
    fn summary(&self) -> String {
        Swatch::summary(self)
    }
}

artifact_kinds! {
    Pattern => Pattern,
    YarnModel => YarnModel,
    RveSolve => RveSolve,
    Grid => Grid,
    Spline => Spline,
    Swatch => Swatch,
}

impl AnyArtifact {
    /// Read a `.yh` file of any kind; errors name the file.
    pub fn read(path: impl AsRef<std::path::Path>) -> Result<(Header, Self)> {
        let path = path.as_ref();
        let bytes = std::fs::read(path).map_err(|e| Error::from(e).at(path))?;
        let raw = container::decode_raw(&bytes).map_err(|e| e.at(path))?;
        let value = Self::decode(&raw).map_err(|e| e.at(path))?;
        Ok((raw.header, value))
    }

    /// Decode a [`JsonDocument`], migrating an older schema version like a `.yh` file would.
    pub fn from_json_document(doc: &JsonDocument) -> Result<Self> {
        let payload = rmp_serde::to_vec_named(&doc.payload)
            .map_err(|e| Error::Encode { what: "payload", message: e.to_string() })?;
        let header = Header { content_hash: container::content_hash(&payload), ..doc.header.clone() };
        Self::decode(&RawArtifact { header, payload })
    }
}
