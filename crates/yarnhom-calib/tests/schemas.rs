//! The committed shell-fit schema (`schemas/shell-fit.vN.schema.json`) is current.

use yarnhom_calib::shell_fit::{SHELL_FIT_VERSION, shell_fit_schema};

#[test]
fn committed_shell_fit_schema_is_current() {
    let path =
        format!("{}/../../schemas/shell-fit.v{SHELL_FIT_VERSION}.schema.json", env!("CARGO_MANIFEST_DIR"));
    let committed = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let expected = serde_json::to_string_pretty(&shell_fit_schema()).expect("json") + "\n";
    assert!(
        committed == expected,
        "{path} is stale; regenerate with `cargo run -p yarnhom-cli -- schema --write-all schemas`"
    );
}
