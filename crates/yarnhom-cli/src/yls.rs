//! `yarnhom yls ...`: yarn-level simulation of whole swatches.

use std::path::PathBuf;

use clap::{Args, Subcommand};
use yarnhom_artifacts::open::{open_artifact, open_pattern_and_model};
use yarnhom_artifacts::{GlueSettings, Swatch};
use yarnhom_trace::TraceMetadata;
use yarnhom_yls::dynamics::Simulation;
use yarnhom_yls::record::record_frame;
use yarnhom_yls::run::{RunSettings, place, run as run_frames};
use yarnhom_yls::swatch::{SwatchSize, cut_swatch};

use crate::Outcome;
use crate::args::{non_negative, positive};
use crate::output::{finish_trace, open_trace, progress_bar, write_artifact, wrote};

#[derive(Debug, Subcommand)]
pub enum YlsCommand {
    /// Cut a swatch from a pattern with a rest state (a published `.pyp` or `rve relax`'s
    /// output): the tile repeated over a rectangle, the yarns cut at its border and each cut
    /// end glued to its nearest crossing by a spring pre-stretched through the thickness
    /// (thesis Sec. 4.3.1). Prints what was kept and dropped.
    Swatch(SwatchArgs),
    /// Simulate a scene with a swatch in place of the cloth: a built-in (stretch-x, stretch-y,
    /// drape), a yarnhom scene JSON or an ARCSim-HYLC scene. Writes the yarns per frame
    /// (`/yarn/frame`), energies and the closest centreline distance (`/metrics`) and Newton
    /// statistics per step (`/solver`). Obstacle friction and the shell's Rayleigh damping are
    /// not used; the yarns get Kaldor's damping of non-rigid motion.
    Simulate(SimulateArgs),
}

#[derive(Debug, Args)]
pub struct SwatchArgs {
    /// The pattern (`.pattern.yh` or `.pyp`), with a rest state.
    pub pattern: PathBuf,
    /// The yarn model: `table4.1:ROW` or a `.yarnmodel.yh`.
    #[arg(long)]
    pub model: String,
    /// Width x height of the rectangle in metres, e.g. `0.3x0.3`.
    #[arg(long, value_parser = pair::<f64>, conflicts_with = "tiles", required_unless_present = "tiles")]
    pub size: Option<[f64; 2]>,
    /// Whole tiles along x and y instead, e.g. `8x8`.
    #[arg(long, value_parser = pair::<u32>)]
    pub tiles: Option<[u32; 2]>,
    /// Glue partners within this many summed yarn radii of a cut end.
    #[arg(long, default_value = "1.5", value_parser = positive)]
    pub glue_reach: f64,
    /// Glue springs' rest length is (1 - this) times their length in the swatch.
    #[arg(long, default_value = "0.1", value_parser = non_negative)]
    pub glue_pre_stretch: f64,
    /// Output file.
    #[arg(short, long)]
    pub output: PathBuf,
}

#[derive(Debug, Args)]
pub struct SimulateArgs {
    /// The scene: built-in name, yarnhom scene JSON or ARCSim-HYLC scene JSON.
    pub scene: String,
    /// The swatch (`yls swatch`).
    #[arg(long)]
    pub swatch: PathBuf,
    /// Output trace (`.mcap`); `-` writes to stdout.
    #[arg(short, long, visible_alias = "trace")]
    pub output: String,
    /// Stop after this many frames (default: the scene's end time).
    #[arg(long)]
    pub frames: Option<u64>,
    /// Backward Euler steps per frame.
    #[arg(long, default_value_t = RunSettings::default().steps_per_frame)]
    pub steps_per_frame: u32,
    /// Rate of Kaldor's damping of non-rigid motion (1/s).
    #[arg(long, default_value_t = RunSettings::default().damping_rate_per_s, value_parser = non_negative)]
    pub damping: f64,
}

/// `AxB` as two numbers.
fn pair<T: std::str::FromStr>(text: &str) -> Result<[T; 2], String> {
    let parse = |v: &str| v.trim().parse::<T>().map_err(|_| format!("'{v}' is not a number"));
    let (a, b) = text.split_once('x').ok_or_else(|| format!("expected AxB, got '{text}'"))?;
    Ok([parse(a)?, parse(b)?])
}

pub fn run(cmd: YlsCommand) -> anyhow::Result<Outcome> {
    match cmd {
        YlsCommand::Swatch(args) => swatch(args),
        YlsCommand::Simulate(args) => simulate(args),
    }
}

fn swatch(args: SwatchArgs) -> anyhow::Result<Outcome> {
    let (pattern, model, inputs) = open_pattern_and_model(&args.pattern, &args.model)?;
    let size = match (args.size, args.tiles) {
        (Some(size), _) => SwatchSize::Metres(size),
        (None, Some(tiles)) => SwatchSize::Tiles(tiles),
        (None, None) => anyhow::bail!("give --size or --tiles"),
    };
    let glue = GlueSettings { reach_radii: args.glue_reach, pre_stretch: args.glue_pre_stretch, stiffness_n_m: None };
    let (swatch, report) = cut_swatch(&pattern, &model, size, glue)?;
    write_artifact(&args.output, &swatch, "yls swatch", inputs)?;
    eprintln!("{}", report.summary());
    wrote(&args.output);
    Ok(Outcome::Success)
}

fn simulate(args: SimulateArgs) -> anyhow::Result<Outcome> {
    let scene = yarnhom_shell::Scene::load(&args.scene)?;
    let swatch = open_artifact::<Swatch>(&args.swatch)?.value;
    let settings =
        RunSettings { steps_per_frame: args.steps_per_frame, damping_rate_per_s: args.damping, ..RunSettings::default() };
    let mut simulation = Simulation::new(&place(&swatch, &scene, &settings)?)?;
    let metadata = TraceMetadata::new("yarnhom yls simulate", env!("CARGO_PKG_VERSION"))
        .with_entry("scene", &args.scene)
        .with_entry("swatch", args.swatch.display().to_string())
        .with_entry("steps_per_frame", args.steps_per_frame.to_string())
        .with_entry("damping_rate_per_s", args.damping.to_string());
    let mut trace = open_trace(&args.output, &metadata)?;
    let frames = args.frames.unwrap_or_else(|| (scene.end_time_s / scene.frame_time_s).round() as u64);
    let bar = progress_bar(frames, "frames");
    run_frames(&mut simulation, frames, scene.frame_time_s, settings.steps_per_frame, |report, sim| {
        record_frame(&mut trace, report, sim, &swatch.name).map_err(|e| e.to_string())?;
        bar.set_position(report.frame);
        bar.set_message(format!("closest {:.2} r", report.closest_distance_radii));
        Ok(())
    })?;
    bar.finish_and_clear();
    finish_trace(Some(trace), Some(&args.output))?;
    eprintln!("simulated {} s of {} yarns, {} vertices", simulation.time_s(), swatch.yarns.len(), swatch.positions_m.len());
    Ok(Outcome::Success)
}
