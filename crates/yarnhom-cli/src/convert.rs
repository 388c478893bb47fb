//! `yarnhom convert FILE --to FORMAT`.

use std::path::{Path, PathBuf};

use clap::Args;
use yarnhom_artifacts::open::{base_name, open};
use yarnhom_artifacts::{AnyArtifact, Header, JsonDocument, Provenance};

use crate::Outcome;
use crate::output::{write_text, wrote};

/// The formats `convert` writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum OutputFormat {
    /// The native container (`NAME.KIND.yh`).
    Yh,
    /// JSON: `{"header": .., "payload": ..}`.
    Json,
    /// HDF5 (array-holding kinds), readable by h5py.
    Hdf5,
    /// The published HYLC periodic pattern text format (patterns only).
    Pyp,
}

impl OutputFormat {
    /// File extension for this format, given the artifact kind.
    fn extension(self, kind: &str) -> String {
        match self {
            OutputFormat::Yh => format!("{kind}.yh"),
            OutputFormat::Json => format!("{kind}.json"),
            OutputFormat::Hdf5 => format!("{kind}.h5"),
            OutputFormat::Pyp => "pyp".into(),
        }
    }
}

#[derive(Debug, Args)]
pub struct ConvertArgs {
    /// The input: a `.yh` artifact, a JSON document, an HDF5 export, a `.pyp` pattern or an
    /// ARCSim-HYLC material (recognised by content).
    pub input: PathBuf,
    /// Output format. The conversion is lossless: converting back gives the same artifact.
    #[arg(long, value_enum)]
    pub to: OutputFormat,
    /// Output file (default: the input's base name with the format's extension; `-` writes
    /// JSON or `.pyp` to standard output).
    #[arg(short, long)]
    pub output: Option<PathBuf>,
}

pub fn run(args: ConvertArgs) -> anyhow::Result<Outcome> {
    let (header, artifact) = open(&args.input)?.into_artifact()?;
    let kind = artifact.kind();
    let output = args
        .output
        .unwrap_or_else(|| format!("{}.{}", base_name(&args.input), args.to.extension(kind)).into());
    anyhow::ensure!(
        output != args.input,
        "output {} would overwrite the input; choose another name with -o",
        output.display()
    );
    match args.to {
        OutputFormat::Yh => write_yh(&output, &header, &artifact)?,
        OutputFormat::Json => {
            let doc = JsonDocument { header, payload: artifact.to_json()? };
            write_text(&output, &(serde_json::to_string_pretty(&doc)? + "\n"))?;
        }
        OutputFormat::Pyp => {
            let AnyArtifact::Pattern(p) = &artifact else {
                anyhow::bail!("only patterns convert to .pyp; {} holds a '{kind}'", args.input.display())
            };
            write_text(&output, &yarnhom_artifacts::pyp::write_pyp(p)?)?;
        }
        OutputFormat::Hdf5 => write_hdf5(&output, &header, &artifact)?,
    }
    Ok(Outcome::Success)
}

/// Re-encode keeping the original producer and inputs: a conversion changes no content.
fn write_yh(output: &Path, header: &Header, artifact: &AnyArtifact) -> anyhow::Result<()> {
    let provenance = Provenance { producer: header.producer.clone(), inputs: header.inputs.clone() };
    crate::output::write_bytes(output, &artifact.encode(&provenance)?)?;
    wrote(output);
    Ok(())
}

#[cfg(feature = "hdf5")]
fn write_hdf5(output: &Path, header: &Header, artifact: &AnyArtifact) -> anyhow::Result<()> {
    anyhow::ensure!(output.as_os_str() != "-", "HDF5 cannot be written to standard output");
    yarnhom_artifacts::hdf5::export(output, header, artifact).map_err(|e| e.at(output))?;
    wrote(output);
    Ok(())
}

#[cfg(not(feature = "hdf5"))]
fn write_hdf5(_: &Path, _: &Header, _: &AnyArtifact) -> anyhow::Result<()> {
    anyhow::bail!("this yarnhom was built without the `hdf5` feature")
}
