//! `yarnhom diff A B`.

use std::path::PathBuf;

use clap::Args;
use yarnhom_artifacts::diff::{Tolerance, diff};

use crate::Outcome;
use crate::inputs;

#[derive(Debug, Args)]
pub struct DiffArgs {
    /// First artifact (any readable format).
    pub a: PathBuf,
    /// Second artifact (any readable format).
    pub b: PathBuf,
    /// Relative tolerance: values are equal if |a - b| <= atol + rtol * |b|.
    #[arg(long, default_value_t = 1e-9, allow_negative_numbers = true)]
    pub rtol: f64,
    /// Absolute tolerance, in each field's SI unit.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub atol: f64,
    /// Print the comparison as JSON.
    #[arg(long)]
    pub json: bool,
}

pub fn run(args: DiffArgs) -> anyhow::Result<Outcome> {
    anyhow::ensure!(
        args.rtol >= 0.0 && args.atol >= 0.0,
        "tolerances must be non-negative numbers (got rtol {}, atol {})",
        args.rtol,
        args.atol
    );
    let a = inputs::load(&args.a, None)?;
    let b = inputs::load(&args.b, None)?;
    let d = diff(&a.artifact, &b.artifact, Tolerance { rtol: args.rtol, atol: args.atol });
    if args.json {
        println!("{}", serde_json::to_string_pretty(&d)?);
    } else {
        println!("{}", d.report());
    }
    Ok(if d.equal() { Outcome::Success } else { Outcome::Different })
}
