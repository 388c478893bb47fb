//! `yarnhom inspect FILE`.

use std::path::PathBuf;

use clap::Args;

use crate::Outcome;
use crate::inputs;

#[derive(Debug, Args)]
pub struct InspectArgs {
    /// The file: a `.yh` artifact, a JSON document, an HDF5 export or a `.pyp` pattern.
    pub input: PathBuf,
    /// Print the header and payload as one JSON document instead of the summary.
    #[arg(long)]
    pub json: bool,
}

pub fn run(args: InspectArgs) -> anyhow::Result<Outcome> {
    let loaded = inputs::load(&args.input, None)?;
    if args.json {
        let doc =
            yarnhom_artifacts::JsonDocument { header: loaded.header, payload: loaded.artifact.to_json()? };
        println!("{}", serde_json::to_string_pretty(&doc)?);
        return Ok(Outcome::Success);
    }
    let h = &loaded.header;
    let current = yarnhom_artifacts::schema_version(&h.kind)?;
    let migrated = if h.schema_version < current {
        format!(" (read through migration to v{current})")
    } else {
        String::new()
    };
    println!("file: {} ({:?})", loaded.path.display(), loaded.format);
    println!("kind: {} v{}{migrated}", h.kind, h.schema_version);
    println!("producer: {} {}", h.producer.name, h.producer.version);
    println!("created: {}", h.created_utc);
    println!("content: {} ({} bytes)", h.content_hash, h.payload_bytes);
    for input in &h.inputs {
        println!("input: {} {} ({})", input.kind, input.content_hash, input.path);
    }
    println!("{}", loaded.artifact.summary());
    if let yarnhom_artifacts::AnyArtifact::Pattern(p) = &loaded.artifact {
        println!("  {}", closest_yarns(p));
    }
    Ok(Outcome::Success)
}

/// Where the yarn centrelines come closest (in radii): about 2 for touching yarns, well below
/// for interpenetrating ones.
fn closest_yarns(p: &yarnhom_artifacts::Pattern) -> String {
    match yarnhom_pattern::min_inter_yarn_distance(p) {
        Some(m) => format!(
            "closest centrelines: {:.3} radii apart (yarn {} edge {}, yarn {} edge {} in tile {:?})",
            m.distance_m / p.yarns[m.a.yarn].radius_m,
            m.a.yarn,
            m.a.index,
            m.b.yarn,
            m.b.index,
            m.image
        ),
        None => "closest centrelines: no two yarn pieces to compare".into(),
    }
}
