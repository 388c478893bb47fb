//! `yarnhom trace export`: a trace as per-frame OBJ or PLY files for viewers, or as one HDF5
//! file of fixed-shape arrays for machine-learning training (feature `hdf5`). The layouts are
//! documented in `yarnhom_trace::export`.

use std::path::PathBuf;

use anyhow::Context;
use clap::{Args, ValueEnum};
use yarnhom_trace::export::{self, ExportStats, FrameFormat};

use crate::Outcome;
use yarnhom_trace::open_records;

/// What `trace export` writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ExportFormat {
    /// Wavefront OBJ, one file per frame (`<mesh>_<frame>.obj`) in the folder `-o`.
    Obj,
    /// Binary PLY, one file per frame (`<mesh>_<frame>.ply`) in the folder `-o`.
    Ply,
    /// One HDF5 file `-o` with a dataset per stream and field, stacked by frame, and a JSON
    /// manifest of every dataset.
    Hdf5,
}

#[derive(Debug, Args)]
pub struct ExportArgs {
    /// Input trace (`-`: standard input).
    #[arg(default_value = "-")]
    pub input: String,
    /// Output format.
    #[arg(long, value_enum)]
    pub format: ExportFormat,
    /// Output: a folder for `obj` and `ply` (created if needed), a file for `hdf5`.
    #[arg(short, long)]
    pub output: PathBuf,
}

pub fn run(args: ExportArgs) -> anyhow::Result<Outcome> {
    let stats = match args.format {
        ExportFormat::Obj => export_frames(&args, FrameFormat::Obj)?,
        ExportFormat::Ply => export_frames(&args, FrameFormat::Ply)?,
        ExportFormat::Hdf5 => export_hdf5(&args)?,
    };
    if let Some(truncation) = &stats.truncation {
        eprintln!("warning: {}: {truncation}", args.input);
    }
    eprintln!("trace export {} -> {}: {stats}", args.input, args.output.display());
    Ok(Outcome::Success)
}

fn export_frames(args: &ExportArgs, format: FrameFormat) -> anyhow::Result<ExportStats> {
    export::export_frames(open_records(&args.input)?, &args.output, format)
        .with_context(|| format!("trace export {} to {}", args.input, args.output.display()))
}

#[cfg(feature = "hdf5")]
fn export_hdf5(args: &ExportArgs) -> anyhow::Result<ExportStats> {
    export::export_hdf5(open_records(&args.input)?, &args.output, &args.input)
        .with_context(|| format!("trace export {} to {}", args.input, args.output.display()))
}

#[cfg(not(feature = "hdf5"))]
fn export_hdf5(_args: &ExportArgs) -> anyhow::Result<ExportStats> {
    anyhow::bail!(
        "--format hdf5 needs the `hdf5` feature: rebuild yarnhom with `--features hdf5` (needs libhdf5)"
    )
}
