//! `yarnhom model ...`: built-in yarn models.

use std::path::PathBuf;

use clap::{Args, Subcommand};
use yarnhom_artifacts::{YarnModel, container};

use crate::Outcome;
use crate::inputs::provenance;

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

/// Resolve `table4.1:<row>` to a built-in model.
pub fn builtin(name: &str) -> anyhow::Result<YarnModel> {
    let row = name.strip_prefix("table4.1:").unwrap_or(name);
    YarnModel::table_4_1(row).ok_or_else(|| {
        let known: Vec<String> = YarnModel::table_4_1_rows().map(|r| format!("table4.1:{r}")).collect();
        anyhow::anyhow!("unknown yarn model '{name}' (known: {})", known.join(", "))
    })
}

pub fn run(cmd: ModelCommand) -> anyhow::Result<Outcome> {
    match cmd {
        ModelCommand::List => {
            for row in YarnModel::table_4_1_rows() {
                let m = builtin(row)?;
                let params: Vec<String> = m.parameters().iter().map(|(k, v)| format!("{k}={v}")).collect();
                println!("{:<22} {}", m.name, params.join(" "));
            }
        }
        ModelCommand::Write(args) => {
            let model = builtin(&args.name)?;
            let row = model.name.trim_start_matches("table4.1:").to_string();
            let output = args.output.unwrap_or_else(|| format!("{row}.yarnmodel.yh").into());
            container::write(&output, &model, &provenance("model write", vec![]))?;
            eprintln!("wrote {}", output.display());
        }
    }
    Ok(Outcome::Success)
}
