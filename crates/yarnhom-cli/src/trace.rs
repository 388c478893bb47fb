//! `yarnhom trace ...`: stream filters over MCAP traces. Each reads a file or standard input
//! (`-`, the default) and writes a file or standard output (`-`, the default), one chunk at a
//! time, so they chain with pipes:
//! `yarnhom shell simulate drape -o - | yarnhom trace decimate --every 4 | yarnhom trace info`.

use std::io::Write;
use std::ops::Range;

use anyhow::Context;
use clap::{Args, Subcommand};
use yarnhom_trace::filter::{self, FilterStats, Selection, parse_range};
use yarnhom_trace::{TraceMetadata, open_records};

use crate::Outcome;
use crate::output::{finish_trace, open_trace};

#[derive(Debug, Subcommand)]
pub enum TraceCommand {
    /// Summarize a trace: topics with message counts, sizes, frame and time ranges; metadata.
    Info(InfoArgs),
    /// Keep the messages of some topics, frames or times. Topologies (messages without a frame)
    /// are kept whenever their topic is.
    Select(SelectArgs),
    /// Keep every N-th frame (frames 0, N, 2N, ...) of every topic, and the topologies.
    Decimate(DecimateArgs),
    /// Interleave several traces by time into one.
    Merge(MergeArgs),
    /// Export a trace: per-frame OBJ or PLY files (meshes, tet-mesh boundaries, yarn
    /// polylines) into a folder, one HDF5 file of fixed-shape arrays for training, or yarn-level
    /// traces as a MeshGraphNets-style training set.
    Export(crate::trace_export::ExportArgs),
}

#[derive(Debug, Args)]
pub struct InfoArgs {
    /// Input trace (`-`: standard input).
    #[arg(default_value = "-")]
    pub input: String,
    /// Print the summary as JSON.
    #[arg(long)]
    pub json: bool,
}

#[derive(Debug, Args)]
pub struct SelectArgs {
    /// Input trace (`-`: standard input).
    #[arg(default_value = "-")]
    pub input: String,
    /// Output trace (`-`: standard output).
    #[arg(short, long, default_value = "-")]
    pub output: String,
    /// Topics to keep: a name (`/mesh/frame`) or a prefix ending in `*` (`/mesh/*`); repeat for
    /// several. Default: every topic.
    #[arg(long = "topic", value_name = "TOPIC")]
    pub topics: Vec<String>,
    /// Frames to keep, `A:B` (A included, B excluded; either may be left out).
    #[arg(long, value_name = "A:B", value_parser = frame_range)]
    pub frames: Option<Range<u64>>,
    /// Simulated times to keep in seconds, `A:B` (A included, B excluded; either may be left out).
    #[arg(long, value_name = "A:B", value_parser = time_range)]
    pub time: Option<Range<f64>>,
}

#[derive(Debug, Args)]
pub struct DecimateArgs {
    /// Input trace (`-`: standard input).
    #[arg(default_value = "-")]
    pub input: String,
    /// Output trace (`-`: standard output).
    #[arg(short, long, default_value = "-")]
    pub output: String,
    /// Keep frames that are multiples of N.
    #[arg(long, value_name = "N")]
    pub every: u64,
}

#[derive(Debug, Args)]
pub struct MergeArgs {
    /// Input traces (at most one `-` for standard input).
    #[arg(required = true, num_args = 2..)]
    pub inputs: Vec<String>,
    /// Output trace (`-`: standard output).
    #[arg(short, long, default_value = "-")]
    pub output: String,
}

pub fn run(cmd: TraceCommand) -> anyhow::Result<Outcome> {
    match cmd {
        TraceCommand::Info(args) => info(args),
        TraceCommand::Select(args) => {
            let selection =
                Selection { topics: args.topics, frames: args.frames, time_s: args.time, every: None };
            let command = "trace select";
            run_filter(&args.input, &args.output, command, &selection)
        }
        TraceCommand::Decimate(args) => {
            anyhow::ensure!(args.every > 0, "--every must be at least 1");
            let selection = Selection { every: Some(args.every), ..Selection::default() };
            run_filter(
                &args.input,
                &args.output,
                &format!("trace decimate --every {}", args.every),
                &selection,
            )
        }
        TraceCommand::Merge(args) => merge(args),
        TraceCommand::Export(args) => crate::trace_export::run(args),
    }
}

fn info(args: InfoArgs) -> anyhow::Result<Outcome> {
    let summary =
        filter::info(open_records(&args.input)?).with_context(|| format!("reading {}", args.input))?;
    if args.json {
        writeln!(std::io::stdout().lock(), "{}", serde_json::to_string_pretty(&summary)?)?;
    } else {
        write!(std::io::stdout().lock(), "{summary}")?;
    }
    Ok(Outcome::Success)
}

/// The metadata record a filter adds to its output: what was done to which input.
fn filter_metadata(command: &str, inputs: &[String]) -> TraceMetadata {
    TraceMetadata::new(format!("yarnhom {command}"), env!("CARGO_PKG_VERSION"))
        .with_entry("inputs", inputs.join(" "))
}

fn run_filter(input: &str, output: &str, command: &str, selection: &Selection) -> anyhow::Result<Outcome> {
    let reader = open_records(input)?;
    let mut sink = open_trace(output, &filter_metadata(command, &[input.to_owned()]))?;
    let stats = sink.filter(reader, selection).with_context(|| format!("{command} {input}"))?;
    finish_trace(Some(sink), Some(output))?;
    report(command, &stats, &[input.to_owned()]);
    Ok(Outcome::Success)
}

fn merge(args: MergeArgs) -> anyhow::Result<Outcome> {
    anyhow::ensure!(
        args.inputs.iter().filter(|i| *i == "-").count() <= 1,
        "standard input (`-`) can be given once only"
    );
    let readers = args.inputs.iter().map(|i| open_records(i)).collect::<Result<Vec<_>, _>>()?;
    let mut sink = open_trace(&args.output, &filter_metadata("trace merge", &args.inputs))?;
    let stats = sink.merge(readers).context("trace merge")?;
    finish_trace(Some(sink), Some(&args.output))?;
    report("trace merge", &stats, &args.inputs);
    Ok(Outcome::Success)
}

/// Tells on stderr what a filter did, with a warning per truncated input.
fn report(command: &str, stats: &FilterStats, inputs: &[String]) {
    for (input, truncation) in &stats.truncated_inputs {
        eprintln!("warning: {}: {truncation}", inputs.get(*input).map_or("?", String::as_str));
    }
    eprintln!(
        "{command}: kept {} of {} messages ({} metadata records copied)",
        stats.messages_written, stats.messages_read, stats.metadata_records
    );
}

/// `--frames A:B`.
fn frame_range(text: &str) -> Result<Range<u64>, String> {
    parse_range(text, 0, u64::MAX)
}

/// `--time A:B` (seconds).
fn time_range(text: &str) -> Result<Range<f64>, String> {
    parse_range(text, 0.0, f64::INFINITY)
}
