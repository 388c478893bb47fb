//! `yarnhom measure ...`: measurement sets of real fabric swatches (calibration inputs).

use std::path::PathBuf;

use clap::{Args, Subcommand};
use yarnhom_calib::data::set::MeasurementSet;

use crate::Outcome;

#[derive(Debug, Subcommand)]
pub enum MeasureCommand {
    /// Convert stitch-by-stitch HDF5 files (`shared/data/stitch-by-stitch-acrylic/*.h5`) of one
    /// fabric into a measurement set: every video as a repeat, load and unload phases separated, saturated
    /// gauge readings dropped and counted (see `schemas/measurement-set.md`).
    ImportStitchByStitch(ImportArgs),
    /// Read and validate a measurement set; print points per direction and phase with their
    /// stretch and force ranges.
    Check(CheckArgs),
}

#[derive(Debug, Args)]
pub struct ImportArgs {
    /// The `.h5` files of one fabric (each name gives the pattern and the direction: `-x` weft,
    /// `-y` warp); several files are merged into one set, one swatch per direction.
    #[arg(required = true)]
    pub inputs: Vec<PathBuf>,
    /// Output directory (created; fabric.toml and stretch.csv are replaced).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Keep every N-th point of each video and phase (1: all).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..))]
    pub every: u32,
}

#[derive(Debug, Args)]
pub struct CheckArgs {
    /// The measurement set directory.
    pub dir: PathBuf,
}

pub fn run(cmd: MeasureCommand) -> anyhow::Result<Outcome> {
    match cmd {
        MeasureCommand::ImportStitchByStitch(args) => import_stitch_by_stitch(args),
        MeasureCommand::Check(args) => check(args),
    }
}

#[cfg(feature = "hdf5")]
fn import_stitch_by_stitch(args: ImportArgs) -> anyhow::Result<Outcome> {
    let every = usize::try_from(args.every)?;
    let imported = yarnhom_calib::data::stitch_by_stitch::import_fabric(&args.inputs, every)?;
    imported.set.write(&args.output)?;
    eprintln!("{}", imported.report());
    eprintln!("wrote {} ({} stretch points)", args.output.display(), imported.set.stretch.len());
    Ok(Outcome::Success)
}

#[cfg(not(feature = "hdf5"))]
fn import_stitch_by_stitch(_: ImportArgs) -> anyhow::Result<Outcome> {
    anyhow::bail!("this yarnhom was built without the `hdf5` feature")
}

fn check(args: CheckArgs) -> anyhow::Result<Outcome> {
    let set = MeasurementSet::read(&args.dir)?;
    println!("{}", set.summary());
    Ok(Outcome::Success)
}
