//! The committed JSON Schemas in `schemas/` must match the Rust types.

use yarnhom_artifacts::{KINDS, json_schema, schema, schema_version};

const DIR: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../schemas");
const REGENERATE: &str = "regenerate with `cargo run -p yarnhom-cli -- schema --write-all schemas`, \
and if a committed version changed, bump the kind's schema version and add a migration (schemas/README.md)";

fn committed(file: &str) -> serde_json::Value {
    let path = format!("{DIR}/{file}");
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}; {REGENERATE}"));
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{path}: {e}"))
}

#[test]
fn committed_schemas_match_the_types() {
    for kind in KINDS {
        let file = schema::file_name(kind, schema_version(kind).expect("known kind"));
        let expected = json_schema(kind).expect("schema");
        assert!(committed(&file) == expected, "schemas/{file} is stale; {REGENERATE}");
    }
}

#[test]
fn old_schema_versions_stay_committed() {
    let v0 =
        serde_json::to_value(schemars::schema_for!(yarnhom_artifacts::yarnmodel::YarnModelV0)).expect("json");
    let file = committed("yarnmodel.v0.schema.json");
    assert_eq!(file["properties"], v0["properties"], "the v0 layout must never change");
}
