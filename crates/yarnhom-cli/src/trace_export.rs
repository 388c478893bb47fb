//! `yarnhom trace export`: a trace as per-frame OBJ or PLY files for viewers, as one HDF5 file
//! of fixed-shape arrays, or yarn-level traces as a MeshGraphNets-style training set (feature
//! `hdf5`). The layouts are documented in `yarnhom_trace::export`; the work is done there.

use std::path::PathBuf;

use anyhow::Context;
use clap::Args;
use yarnhom_trace::export::{self, ExportFormat};

use crate::Outcome;

#[derive(Debug, Args)]
pub struct ExportArgs {
    /// Input trace (`-`: standard input); several for `training`, each giving one sequence per
    /// yarn set.
    #[arg(default_value = "-")]
    pub input: Vec<String>,
    /// Output format.
    #[arg(long, value_enum)]
    pub format: ExportFormat,
    /// Output: a folder for `obj`, `ply` and `training` (created if needed), a file for `hdf5`.
    #[arg(short, long)]
    pub output: PathBuf,
}

pub fn run(args: ExportArgs) -> anyhow::Result<Outcome> {
    let input = args.input.join(" ");
    let stats = export::export_paths(args.format, &args.input, &args.output)
        .with_context(|| format!("trace export {input} to {}", args.output.display()))?;
    if let Some(truncation) = &stats.truncation {
        eprintln!("warning: {input}: {truncation}");
    }
    eprintln!("trace export {input} -> {}: {stats}", args.output.display());
    Ok(Outcome::Success)
}
