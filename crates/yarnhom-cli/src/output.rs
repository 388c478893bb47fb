//! Where a command's files go: through the one atomic writer of `yarnhom-artifacts`, or to
//! standard output for `-`, and a line on stderr naming each file written.

use std::io::Write;
use std::path::Path;

use anyhow::Context;
use indicatif::{ProgressBar, ProgressStyle};
use yarnhom_artifacts::{Artifact, Provenance, container, write_atomic};
use yarnhom_trace::{TraceMetadata, TraceSink, is_stdio};

/// Writes `bytes` to `path` atomically.
pub fn write_bytes(path: &Path, bytes: &[u8]) -> anyhow::Result<()> {
    write_atomic(path, bytes).with_context(|| format!("cannot write {}", path.display()))
}

/// Writes text to a file atomically and names it on stderr, or to standard output for `-`.
pub fn write_text(output: &Path, text: &str) -> anyhow::Result<()> {
    if output.as_os_str() == "-" {
        std::io::stdout().write_all(text.as_bytes()).context("cannot write to standard output")?;
    } else {
        write_bytes(output, text.as_bytes())?;
        wrote(output);
    }
    Ok(())
}

/// Writes an artifact made by `yarnhom COMMAND` from `inputs`.
pub fn write_artifact<T: Artifact>(
    path: &Path,
    value: &T,
    command: &str,
    inputs: Vec<yarnhom_artifacts::InputRef>,
) -> anyhow::Result<()> {
    container::write(path, value, &Provenance::of(command, inputs))?;
    Ok(())
}

/// Creates a directory (and its parents) to write into.
pub fn create_dir(dir: &Path) -> anyhow::Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))
}

/// Says on stderr that `path` was written.
pub fn wrote(path: &Path) {
    eprintln!("wrote {}", path.display());
}

/// Opens a trace output (`-`: standard output).
pub fn open_trace(path: &str, metadata: &TraceMetadata) -> anyhow::Result<TraceSink> {
    TraceSink::open(path, metadata).with_context(|| format!("cannot create the trace {path}"))
}

/// Completes a trace, if one was open, and names its file on stderr.
pub fn finish_trace(trace: Option<TraceSink>, path: Option<&str>) -> anyhow::Result<()> {
    let (Some(sink), Some(path)) = (trace, path) else { return Ok(()) };
    sink.finish().with_context(|| format!("cannot complete the trace {path}"))?;
    if !is_stdio(path) {
        wrote(Path::new(path));
    }
    Ok(())
}

/// Prints a command's summary: to stdout, or to stderr when stdout carries its trace.
pub fn print_summary(text: &str, trace: Option<&str>) {
    if trace.is_some_and(is_stdio) {
        eprintln!("{text}");
    } else {
        println!("{text}");
    }
}

/// A progress bar over `total` of `unit` (`samples`, `frames`), with the elapsed time, the
/// expected time left and the caller's message.
pub fn progress_bar(total: u64, unit: &str) -> ProgressBar {
    let template = format!("{{bar:40}} {{pos}}/{{len}} {unit}, {{elapsed}} elapsed, ETA {{eta}} {{msg}}");
    let bar = ProgressBar::new(total);
    bar.set_style(ProgressStyle::with_template(&template).unwrap_or_else(|_| ProgressStyle::default_bar()));
    bar
}
