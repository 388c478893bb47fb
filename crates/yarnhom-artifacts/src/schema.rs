//! JSON Schemas generated from the artifact types (`schemas/<kind>.v<N>.schema.json`).

use crate::Artifact;

/// The JSON Schema of kind `T`, with an `$id` naming kind and version.
pub fn of<T: Artifact>() -> serde_json::Value {
    let mut schema = serde_json::to_value(schemars::schema_for!(T)).unwrap_or_default();
    if let Some(map) = schema.as_object_mut() {
        map.insert("$id".into(), format!("yarnhom:{}.v{}", T::KIND, T::SCHEMA_VERSION).into());
        map.insert(
            "description".into(),
            format!(
                "Payload of a yarnhom '{}' artifact, schema version {} (msgpack with named fields in `.yh` files).",
                T::KIND,
                T::SCHEMA_VERSION
            )
            .into(),
        );
    }
    schema
}

/// The file name of a kind's committed schema.
pub fn file_name(kind: &str, version: u32) -> String {
    format!("{kind}.v{version}.schema.json")
}
