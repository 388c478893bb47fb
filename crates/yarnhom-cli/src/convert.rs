//! `yarnhom convert FILE --to FORMAT`.

use std::path::{Path, PathBuf};

use clap::Args;
use yarnhom_artifacts::{AnyArtifact, JsonDocument, Provenance, container};

use crate::Outcome;
use crate::inputs::{self, Format, Loaded, base_name};
use crate::pattern::write_text;

#[derive(Debug, Args)]
pub struct ConvertArgs {
    /// The input: a `.yh` artifact, a JSON document, an HDF5 export or a `.pyp` pattern
    /// (recognised by content).
    pub input: PathBuf,
    /// Output format. The conversion is lossless: converting back gives the same artifact.
    #[arg(long, value_enum)]
    pub to: Format,
    /// Output file (default: the input's base name with the format's extension; `-` writes
    /// JSON or `.pyp` to standard output).
    #[arg(short, long)]
    pub output: Option<PathBuf>,
}

pub fn run(args: ConvertArgs) -> anyhow::Result<Outcome> {
    let loaded = inputs::load(&args.input, None)?;
    let kind = loaded.artifact.kind();
    let output = args
        .output
        .unwrap_or_else(|| format!("{}.{}", base_name(&args.input), args.to.extension(kind)).into());
    anyhow::ensure!(
        output != args.input,
        "output {} would overwrite the input; choose another name with -o",
        output.display()
    );
    match args.to {
        Format::Yh => write_yh(&output, &loaded)?,
        Format::Json => {
            let doc = JsonDocument { header: loaded.header.clone(), payload: loaded.artifact.to_json()? };
            write_text(&output, &(serde_json::to_string_pretty(&doc)? + "\n"))?;
        }
        Format::Pyp => {
            let AnyArtifact::Pattern(p) = &loaded.artifact else {
                anyhow::bail!("only patterns convert to .pyp; {} holds a '{kind}'", args.input.display())
            };
            write_text(&output, &yarnhom_artifacts::pyp::write_pyp(p)?)?;
        }
        Format::Hdf5 => write_hdf5(&output, &loaded)?,
    }
    Ok(Outcome::Success)
}

/// Re-encode keeping the original producer and inputs: a conversion changes no content.
fn write_yh(output: &Path, loaded: &Loaded) -> anyhow::Result<()> {
    let provenance =
        Provenance { producer: loaded.header.producer.clone(), inputs: loaded.header.inputs.clone() };
    let bytes = loaded.artifact.encode(&provenance)?;
    container::write_atomic(output, &bytes).map_err(|e| e.at(output))?;
    eprintln!("wrote {}", output.display());
    Ok(())
}

#[cfg(feature = "hdf5")]
fn write_hdf5(output: &Path, loaded: &Loaded) -> anyhow::Result<()> {
    anyhow::ensure!(output.as_os_str() != "-", "HDF5 cannot be written to standard output");
    yarnhom_artifacts::hdf5::export(output, &loaded.header, &loaded.artifact).map_err(|e| e.at(output))?;
    eprintln!("wrote {}", output.display());
    Ok(())
}

#[cfg(not(feature = "hdf5"))]
fn write_hdf5(_: &Path, _: &Loaded) -> anyhow::Result<()> {
    anyhow::bail!("this yarnhom was built without the `hdf5` feature")
}
