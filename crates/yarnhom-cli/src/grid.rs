//! `yarnhom grid ...`: sampled energy grids (thesis App. A.3.1).

use std::path::PathBuf;

use clap::{Args, Subcommand};
use yarnhom_artifacts::grid::Grid;
use yarnhom_artifacts::open::open_artifact;

use crate::Outcome;
use crate::output::{write_artifact, wrote};

#[derive(Debug, Subcommand)]
pub enum GridCommand {
    /// Join the shards of a sampling run (`yarnhom rve sample --shard K/N`) into one grid,
    /// bit-identical to an unsharded run. Shards must come from the same pattern, model and plan
    /// and must not overlap; a missing shard leaves the result partial, which the summary says.
    Merge(MergeArgs),
}

#[derive(Debug, Args)]
pub struct MergeArgs {
    /// The shard files (`grid` artifacts).
    #[arg(required = true)]
    pub shards: Vec<PathBuf>,
    /// Output file.
    #[arg(short, long)]
    pub output: PathBuf,
}

pub fn run(cmd: GridCommand) -> anyhow::Result<Outcome> {
    match cmd {
        GridCommand::Merge(args) => merge(args),
    }
}

fn merge(args: MergeArgs) -> anyhow::Result<Outcome> {
    let (mut parts, mut sources) = (Vec::new(), Vec::new());
    for path in &args.shards {
        let shard = open_artifact::<Grid>(path)?;
        parts.push(shard.value);
        sources.push(shard.input);
    }
    let merged = Grid::merge(parts)?;
    write_artifact(&args.output, &merged, "grid merge", sources)?;
    if !merged.is_complete() {
        eprintln!(
            "warning: the merged grid holds {} of the plan's {} samples (shards missing?)",
            merged.samples.len(),
            merged.expected_samples()
        );
    }
    println!("{}", merged.summary());
    wrote(&args.output);
    Ok(Outcome::Success)
}
