//! `yarnhom rerun`: a trace as a rerun recording.

use std::io::IsTerminal;
use std::path::PathBuf;

use anyhow::Context;
use clap::Args;
use yarnhom_rerun::{log_trace, rerun::RecordingStreamBuilder};
use yarnhom_trace::TraceReader;

use crate::Outcome;
use yarnhom_trace::open_source;

#[derive(Debug, Args)]
#[command(group(clap::ArgGroup::new("sink").required(true).args(["save", "stdout"])))]
pub struct RerunArgs {
    /// Input trace (`-`: standard input).
    #[arg(default_value = "-")]
    pub input: String,
    /// Save the recording to this `.rrd` file (open it with `rerun FILE.rrd`).
    #[arg(long, value_name = "FILE.rrd")]
    pub save: Option<PathBuf>,
    /// Stream the recording to standard output, for `| rerun -`.
    #[arg(long)]
    pub stdout: bool,
    /// Recording name shown in the viewer (default: the input's file name).
    #[arg(long)]
    pub name: Option<String>,
}

pub fn run(args: RerunArgs) -> anyhow::Result<Outcome> {
    let name = args.name.clone().unwrap_or_else(|| match args.input.as_str() {
        "-" => "yarnhom".into(),
        path => {
            std::path::Path::new(path).file_name().map_or("yarnhom".into(), |n| n.to_string_lossy().into())
        }
    });
    let builder = RecordingStreamBuilder::new("yarnhom").recording_name(name);
    let rec = match &args.save {
        Some(path) => builder.save(path).with_context(|| format!("cannot create {}", path.display()))?,
        None => {
            anyhow::ensure!(
                !std::io::stdout().is_terminal(),
                "refusing to write a binary recording to the terminal: pipe it into `rerun -` or use --save"
            );
            builder.stdout().context("cannot stream the recording to stdout")?
        }
    };
    let stats = log_trace(TraceReader::new(open_source(&args.input)?), &rec)
        .with_context(|| format!("logging {} to rerun", args.input))?;
    rec.flush_blocking().context("cannot flush the recording")?;
    if let Some(truncation) = stats.truncation {
        eprintln!("warning: {}: {truncation}", args.input);
    }
    eprintln!("logged {} messages ({} on topics rerun does not draw)", stats.logged, stats.skipped);
    if let Some(path) = &args.save {
        eprintln!("wrote {}", path.display());
    }
    Ok(Outcome::Success)
}
