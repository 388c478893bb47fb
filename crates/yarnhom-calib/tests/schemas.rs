//! The committed calibration report schemas (`schemas/shell-fit.vN.schema.json`,
//! `schemas/diagnosis.vN.schema.json`, `schemas/yarn-fit.vN.schema.json`) are current.

use yarnhom_calib::diagnosis::report::{DIAGNOSIS_VERSION, diagnosis_schema};
use yarnhom_calib::shell::fit::{SHELL_FIT_VERSION, shell_fit_schema};
use yarnhom_calib::yarn::fit::{YARN_FIT_VERSION, yarn_fit_schema};

#[test]
fn committed_report_schemas_are_current() {
    for (name, version, schema) in [
        ("shell-fit", SHELL_FIT_VERSION, shell_fit_schema()),
        ("diagnosis", DIAGNOSIS_VERSION, diagnosis_schema()),
        ("yarn-fit", YARN_FIT_VERSION, yarn_fit_schema()),
    ] {
        let path = format!("{}/../../schemas/{name}.v{version}.schema.json", env!("CARGO_MANIFEST_DIR"));
        let committed = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
        let expected = serde_json::to_string_pretty(&schema).expect("json") + "\n";
        assert!(
            committed == expected,
            "{path} is stale; regenerate with `cargo run -p yarnhom-cli -- schema --write-all schemas`"
        );
    }
}
