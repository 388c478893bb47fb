//! `yarnhom`: the command-line tool of the yarnhom yarn-level cloth toolchain.
//!
//! This crate only parses arguments, reports progress and errors, and wires the library
//! crates together; it holds no numerics. Exit status: 0 success (and "equal" for `diff`),
//! 1 "different" for `diff`, 2 any error (bad input, unreadable file, usage).

mod args;
mod calibrate;
mod calibrate_yarn;
mod convert;
mod diff;
mod fit;
mod grid;
mod inspect;
mod measure;
mod model;
mod output;
mod pattern;
#[cfg(feature = "rerun")]
mod rerun_cmd;
mod rve;
mod sample;
mod schema;
mod shell;
mod trace;
mod trace_export;
mod yls;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

/// yarnhom: yarn-level cloth, from periodic yarn patterns to homogenized materials.
///
/// Every stage reads and writes versioned, schema-defined artifacts (`NAME.KIND.yh`: a
/// checksummed, zstd-compressed msgpack container). `yarnhom inspect` tells what a file is,
/// `yarnhom convert` turns it into JSON, HDF5 or `.pyp`, `yarnhom diff` compares two of them (or
/// two MCAP traces).
#[derive(Debug, Parser)]
#[command(name = "yarnhom", version, propagate_version = true, max_term_width = 100)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Periodic yarn patterns: list and run the built-in generators, import and export `.pyp`.
    #[command(subcommand)]
    Pattern(pattern::PatternCommand),
    /// Yarn models: the built-in Table 4.1 parameter sets, written as `yarnmodel` artifacts.
    #[command(subcommand)]
    Model(model::ModelCommand),
    /// The periodic yarn tile (thesis Ch. 3): equilibrium, homogenized energy and stress.
    #[command(subcommand)]
    Rve(rve::RveCommand),
    /// Sampled energy grids (thesis App. A.3.1): merge the shards of a sampling run.
    #[command(subcommand)]
    Grid(grid::GridCommand),
    /// Homogenized cloth materials (thesis Sec. 4.1, App. A.3): fit a sampled grid into a
    /// spline material; import and export ARCSim-HYLC material JSON; plot and compare fits.
    Fit(fit::FitArgs),
    /// Thin-shell cloth simulation (thesis Sec. 4.2, Ch. 6) of scenes with spline or Ch. 6
    /// materials, recorded as MCAP traces.
    #[command(subcommand)]
    Shell(shell::ShellCommand),
    /// Yarn-level simulation of whole swatches (thesis Sec. 4.3.1): cut a swatch from a
    /// pattern, simulate the shell simulator's scenes on it yarn by yarn.
    #[command(subcommand)]
    Yls(yls::YlsCommand),
    /// MCAP traces as stream filters: info, select, decimate, merge, export (OBJ, PLY, HDF5).
    /// Each reads a file or stdin (`-`) and writes a file or stdout (`-`).
    #[command(subcommand)]
    Trace(trace::TraceCommand),
    /// Turn a trace into a rerun recording: `--save FILE.rrd`, or `--stdout` for `| rerun -`.
    #[cfg(feature = "rerun")]
    Rerun(rerun_cmd::RerunArgs),
    /// Describe an artifact: kind, schema version, provenance and a human summary.
    Inspect(inspect::InspectArgs),
    /// Convert an artifact between `.yh`, JSON, HDF5 and `.pyp`.
    Convert(convert::ConvertArgs),
    /// Print the JSON Schema of an artifact kind, or write every schema to a folder.
    Schema(schema::SchemaArgs),
    /// Compare two artifacts of the same kind (spline materials by their energies and stresses
    /// on a dense strain plan) or two MCAP traces (per topic and frame); exit 0 if equal within
    /// tolerance, 1 if different, 2 on error (unreadable file, kinds that cannot be compared).
    Diff(diff::DiffArgs),
    /// Measurement sets of real swatches (calibration inputs): import the published
    /// stitch-by-stitch data, validate and summarize a set.
    #[command(subcommand)]
    Measure(measure::MeasureCommand),
    /// Fit models to a measurement set (thesis Ch. 6): `calibrate shell` fits the (6.1)
    /// membrane by simulating the clamped swatch tests, `calibrate diagnose` names what the
    /// base model gets wrong, `calibrate synth` writes sets with hidden effects.
    #[command(subcommand)]
    Calibrate(calibrate::CalibrateCommand),
}

/// What a command reports back to `main`.
enum Outcome {
    Success,
    Different,
}

fn run(cli: Cli) -> anyhow::Result<Outcome> {
    match cli.command {
        Command::Pattern(cmd) => pattern::run(cmd),
        Command::Model(cmd) => model::run(cmd),
        Command::Rve(cmd) => rve::run(cmd),
        Command::Grid(cmd) => grid::run(cmd),
        Command::Fit(args) => fit::run(args),
        Command::Shell(cmd) => shell::run(cmd),
        Command::Yls(cmd) => yls::run(cmd),
        Command::Trace(cmd) => trace::run(cmd),
        #[cfg(feature = "rerun")]
        Command::Rerun(args) => rerun_cmd::run(args),
        Command::Inspect(args) => inspect::run(args),
        Command::Convert(args) => convert::run(args),
        Command::Schema(args) => schema::run(args),
        Command::Diff(args) => diff::run(args),
        Command::Measure(cmd) => measure::run(cmd),
        Command::Calibrate(cmd) => calibrate::run(cmd),
    }
}

fn main() -> ExitCode {
    quiet_on_closed_stdout();
    let cli = Cli::parse();
    match run(cli) {
        Ok(Outcome::Success) => ExitCode::SUCCESS,
        Ok(Outcome::Different) => ExitCode::from(1),
        // The reader at the other end of a pipe stopped reading (`| head`): end quietly, as
        // command-line tools do.
        Err(e) if is_broken_pipe(&e) => ExitCode::SUCCESS,
        Err(e) => {
            let chain: Vec<String> = e.chain().map(ToString::to_string).collect();
            eprintln!("error: {}", chain.join(": "));
            ExitCode::from(2)
        }
    }
}

/// Whether an error comes from writing into a pipe whose reader has gone.
fn is_broken_pipe(error: &anyhow::Error) -> bool {
    error.chain().any(|cause| {
        cause.downcast_ref::<std::io::Error>().is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe)
    })
}

/// Ends the process quietly when `println!` finds standard output closed by its reader
/// (`yarnhom inspect x | head -1`): `println!` panics there, and the default hook would print a
/// panic message for what is the reader's normal way of saying "enough". Every other panic goes
/// to the default hook.
fn quiet_on_closed_stdout() {
    let default_hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let message = info
            .payload()
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| info.payload().downcast_ref::<&str>().copied())
            .unwrap_or("");
        if message.starts_with("failed printing to stdout") && message.contains("Broken pipe") {
            std::process::exit(0);
        }
        default_hook(info);
    }));
}

#[cfg(test)]
mod tests {
    /// `docs/cli.md`, the full command reference, is generated from the clap definitions;
    /// `YARNHOM_WRITE_CLI_DOCS=1 cargo test -p yarnhom-cli --bin yarnhom` rewrites it.
    #[test]
    fn the_command_reference_is_current() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../docs/cli.md");
        let generated = clap_markdown::help_markdown::<super::Cli>();
        if std::env::var_os("YARNHOM_WRITE_CLI_DOCS").is_some() {
            std::fs::write(path, &generated).expect("writes docs/cli.md");
        }
        let committed = std::fs::read_to_string(path).unwrap_or_default();
        assert!(
            committed == generated,
            "docs/cli.md is stale: regenerate it with `YARNHOM_WRITE_CLI_DOCS=1 cargo test -p yarnhom-cli --bin yarnhom`"
        );
    }
}
