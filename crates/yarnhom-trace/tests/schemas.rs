//! The committed topic schemas (`schemas/trace/`) are the ones the writer stores in traces.

const REGENERATE: &str = "regenerate with `cargo run -p yarnhom-cli -- schema --write-all schemas`";

#[test]
fn committed_topic_schemas_are_current() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../schemas/trace");
    for (topic, name, schema) in yarnhom_trace::topic_schemas() {
        let path = format!("{dir}/{name}.schema.json");
        let committed =
            std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}; {REGENERATE}"));
        let expected = serde_json::to_string_pretty(&schema).expect("json") + "\n";
        assert!(committed == expected, "{path} ({topic}) is stale; {REGENERATE}");
    }
    let files = std::fs::read_dir(dir).expect("schemas/trace").count();
    assert_eq!(files, yarnhom_trace::topic_schemas().len(), "a schema file without a topic in {dir}");
}
