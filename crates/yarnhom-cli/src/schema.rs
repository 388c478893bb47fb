//! `yarnhom schema KIND`.

use std::path::PathBuf;

use clap::Args;
use yarnhom_artifacts::{KINDS, json_schema, schema, schema_version};

use crate::Outcome;
use crate::output::{create_dir, write_text};

#[derive(Debug, Args)]
pub struct SchemaArgs {
    /// Artifact kind (pattern, yarnmodel). Omit with --write-all.
    #[arg(required_unless_present = "write_all")]
    pub kind: Option<String>,
    /// Write the current schema of every kind as DIR/KIND.vN.schema.json, of the calibration
    /// reports as DIR/shell-fit.vN.schema.json, DIR/diagnosis.vN.schema.json and
    /// DIR/yarn-fit.vN.schema.json, and of every trace topic as
    /// DIR/trace/SCHEMA_NAME.schema.json (how the committed `schemas/` folder is made).
    #[arg(long, value_name = "DIR", conflicts_with = "kind")]
    pub write_all: Option<PathBuf>,
}

pub fn run(args: SchemaArgs) -> anyhow::Result<Outcome> {
    if let Some(dir) = args.write_all {
        for kind in KINDS {
            let path = dir.join(schema::file_name(kind, schema_version(kind)?));
            let text = serde_json::to_string_pretty(&json_schema(kind)?)? + "\n";
            write_text(&path, &text)?;
        }
        let reports = [
            (
                "shell-fit",
                yarnhom_calib::shell::fit::SHELL_FIT_VERSION,
                yarnhom_calib::shell::fit::shell_fit_schema(),
            ),
            (
                "diagnosis",
                yarnhom_calib::diagnosis::report::DIAGNOSIS_VERSION,
                yarnhom_calib::diagnosis::report::diagnosis_schema(),
            ),
            (
                "yarn-fit",
                yarnhom_calib::yarn::fit::YARN_FIT_VERSION,
                yarnhom_calib::yarn::fit::yarn_fit_schema(),
            ),
        ];
        for (name, version, schema) in reports {
            let path = dir.join(format!("{name}.v{version}.schema.json"));
            let text = serde_json::to_string_pretty(&schema)? + "\n";
            write_text(&path, &text)?;
        }
        let trace_dir = dir.join("trace");
        create_dir(&trace_dir)?;
        for (_, name, schema) in yarnhom_trace::topic_schemas() {
            let path = trace_dir.join(format!("{name}.schema.json"));
            let text = serde_json::to_string_pretty(&schema)? + "\n";
            write_text(&path, &text)?;
        }
    } else if let Some(kind) = args.kind {
        println!("{}", serde_json::to_string_pretty(&json_schema(&kind)?)?);
    }
    Ok(Outcome::Success)
}
