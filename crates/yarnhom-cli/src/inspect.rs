//! `yarnhom inspect FILE`.

use std::path::PathBuf;

use clap::Args;
use yarnhom_artifacts::open::{Contents, Input, open};
use yarnhom_artifacts::{AnyArtifact, Header, JsonDocument};
use yarnhom_calib::report::CalibrationReport;

use crate::Outcome;

#[derive(Debug, Args)]
pub struct InspectArgs {
    /// The file: a `.yh` artifact, a JSON document, an HDF5 export, a `.pyp` pattern, an
    /// ARCSim-HYLC or Ch. 6 material, or a calibration report (recognised by content).
    pub input: PathBuf,
    /// Print the header and payload as one JSON document instead of the summary.
    #[arg(long)]
    pub json: bool,
}

pub fn run(args: InspectArgs) -> anyhow::Result<Outcome> {
    let Input { path, format, contents } = open(&args.input)?;
    if let (true, Contents::Artifact { header, artifact }) = (args.json, &contents) {
        let doc = JsonDocument { header: header.clone(), payload: artifact.to_json()? };
        println!("{}", serde_json::to_string_pretty(&doc)?);
        return Ok(Outcome::Success);
    }
    println!("file: {} ({format:?})", path.display());
    match contents {
        Contents::Artifact { header, artifact } => print_artifact(&header, &artifact)?,
        Contents::Membrane(m) => println!("{}", m.summary()),
        Contents::Report(report) => {
            println!("report: {} v{}", report.format, report.version);
            println!("{}", CalibrationReport::decode(report.document)?.summary());
        }
        Contents::Trace => println!("an MCAP trace: `yarnhom trace info {}` summarizes it", path.display()),
    }
    Ok(Outcome::Success)
}

fn print_artifact(h: &Header, artifact: &AnyArtifact) -> anyhow::Result<()> {
    let current = yarnhom_artifacts::schema_version(&h.kind)?;
    let migrated = if h.schema_version < current {
        format!(" (read through migration to v{current})")
    } else {
        String::new()
    };
    println!("kind: {} v{}{migrated}", h.kind, h.schema_version);
    println!("producer: {} {}", h.producer.name, h.producer.version);
    println!("created: {}", h.created_utc);
    println!("content: {} ({} bytes)", h.content_hash, h.payload_bytes);
    for input in &h.inputs {
        println!("input: {} {} ({})", input.kind, input.content_hash, input.path);
    }
    println!("{}", artifact.summary());
    if let AnyArtifact::Pattern(p) = artifact {
        println!("  {}", yarnhom_pattern::closest_yarns(p));
    }
    Ok(())
}
