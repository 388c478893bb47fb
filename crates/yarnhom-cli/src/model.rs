//! `yarnhom model ...`: built-in yarn models.

use std::path::PathBuf;

use clap::{Args, Subcommand};
use yarnhom_artifacts::YarnModel;
use yarnhom_artifacts::open::builtin_yarn_model;

use crate::Outcome;
use crate::output::{write_artifact, wrote};

#[derive(Debug, Subcommand)]
pub enum ModelCommand {
    /// List the built-in yarn models (the rows of the thesis' Table 4.1).
    List,
    /// Write a built-in yarn model as a `yarnmodel` artifact.
    Write(WriteArgs),
}

#[derive(Debug, Args)]
pub struct WriteArgs {
    /// Model name, e.g. `table4.1:stock` (see `model list`).
    pub name: String,
    /// Output file (default: ROW.yarnmodel.yh).
    #[arg(short, long)]
    pub output: Option<PathBuf>,
}

pub fn run(cmd: ModelCommand) -> anyhow::Result<Outcome> {
    match cmd {
        ModelCommand::List => {
            for row in YarnModel::table_4_1_rows() {
                let m = builtin_yarn_model(row)?;
                let params: Vec<String> = m.parameters().iter().map(|(k, v)| format!("{k}={v}")).collect();
                println!("{:<22} {}", m.name, params.join(" "));
            }
        }
        ModelCommand::Write(args) => {
            let model = builtin_yarn_model(&args.name)?;
            let row = model.name.trim_start_matches("table4.1:").to_string();
            let output = args.output.unwrap_or_else(|| format!("{row}.yarnmodel.yh").into());
            write_artifact(&output, &model, "model write", vec![])?;
            wrote(&output);
        }
    }
    Ok(Outcome::Success)
}
