//! `yarnhom yls ...`: yarn-level simulation of whole swatches.

use std::path::{Path, PathBuf};

use clap::{Args, Subcommand};
use yarnhom_artifacts::open::{open_artifact, open_pattern_and_model};
use yarnhom_artifacts::{GlueSettings, Swatch};
use yarnhom_trace::{TraceMetadata, is_stdio};
use yarnhom_yls::dynamics::Simulation;
use yarnhom_yls::record::{record_resumable, record_run};
use yarnhom_yls::run::{Frames, RunSettings, place};
use yarnhom_yls::swatch::{SwatchSize, cut_swatch};
use yarnhom_yls::variations::{Variation, shard_sequences};

use crate::Outcome;
use crate::args::{non_negative, positive};
use crate::output::{create_dir, finish_trace, open_trace, progress_bar, write_artifact, wrote};

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
    /// statistics per step (`/solver`). The shell's Rayleigh damping is not used; the yarns get
    /// Kaldor's damping of non-rigid motion.
    Simulate(SimulateArgs),
    /// Record training sequences: `--variations` randomized variants of each scene (handle
    /// motions scaled by 0.5-1.5, sphere obstacles shifted by up to 10% of the swatch, the
    /// swatch lifted by up to a tenth of its size; variant 0 as written), one trace per
    /// sequence, `DIR/seq_NNNNNN.mcap`, with its draws in the trace's metadata. Sequences
    /// already in DIR are kept (a rerun resumes); `--shard K/N` records every N-th sequence
    /// from K (a Slurm array or Kubernetes Indexed Job) exactly as the whole recording would.
    Record(RecordArgs),
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
    #[command(flatten)]
    pub run: RunArgs,
    /// Output trace (`.mcap`); `-` writes to stdout.
    #[arg(short, long, visible_alias = "trace")]
    pub output: String,
}

#[derive(Debug, Args)]
pub struct RunArgs {
    /// The swatch (`yls swatch`).
    #[arg(long)]
    pub swatch: PathBuf,
    /// Stop after this many frames (default: the scene's end time).
    #[arg(long)]
    pub frames: Option<u64>,
    /// Backward Euler steps per frame.
    #[arg(long, default_value_t = RunSettings::default().steps_per_frame)]
    pub steps_per_frame: u32,
    /// Save the state every this many frames (`T.checkpoint`, the frames so far as
    /// `T.partNNNN`): a rerun of a killed run with the same arguments continues from there, to
    /// the bit; 0: never (as for `-o -`).
    #[arg(long, default_value_t = 50)]
    pub checkpoint_every: u64,
    /// Rate of Kaldor's damping of non-rigid motion (1/s).
    #[arg(long, default_value_t = RunSettings::default().damping_rate_per_s, value_parser = non_negative)]
    pub damping: f64,
}

#[derive(Debug, Args)]
pub struct RecordArgs {
    /// Scenes (built-in names or scene files).
    #[arg(required = true)]
    pub scenes: Vec<String>,
    #[command(flatten)]
    pub run: RunArgs,
    /// Variants per scene.
    #[arg(long, default_value_t = 1)]
    pub variations: u64,
    /// Seed of the variants' draws.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Record only shard K of N (`K/N`).
    #[arg(long, value_parser = crate::args::parse_shard)]
    pub shard: Option<(u32, u32)>,
    /// Output folder.
    #[arg(short, long)]
    pub output: PathBuf,
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
        YlsCommand::Record(args) => record(args),
    }
}

fn swatch(args: SwatchArgs) -> anyhow::Result<Outcome> {
    let (pattern, model, inputs) = open_pattern_and_model(&args.pattern, &args.model)?;
    let size = match (args.size, args.tiles) {
        (Some(size), _) => SwatchSize::Metres(size),
        (None, Some(tiles)) => SwatchSize::Tiles(tiles),
        (None, None) => anyhow::bail!("give --size or --tiles"),
    };
    let glue = GlueSettings {
        reach_radii: args.glue_reach,
        pre_stretch: args.glue_pre_stretch,
        stiffness_n_m: None,
    };
    let (swatch, report) = cut_swatch(&pattern, &model, size, glue)?;
    write_artifact(&args.output, &swatch, "yls swatch", inputs)?;
    eprintln!("{}", report.summary());
    wrote(&args.output);
    Ok(Outcome::Success)
}

fn simulate(args: SimulateArgs) -> anyhow::Result<Outcome> {
    let scene = yarnhom_shell::Scene::load(&args.scene)?;
    let swatch = open_artifact::<Swatch>(&args.run.swatch)?.value;
    let placed = place(&swatch, &scene, &settings(&args.run))?;
    let metadata = metadata(&args.run, &args.scene, serde_json::Value::Null);
    run_to_trace(&args.run, &swatch, &scene, placed, &args.output, &metadata)?;
    Ok(Outcome::Success)
}

fn record(args: RecordArgs) -> anyhow::Result<Outcome> {
    let scenes = args.scenes.iter().map(|s| yarnhom_shell::Scene::load(s)).collect::<Result<Vec<_>, _>>()?;
    let swatch = open_artifact::<Swatch>(&args.run.swatch)?.value;
    create_dir(&args.output)?;
    let (index, count) = args.shard.map_or((0, 1), |(k, n)| (u64::from(k), u64::from(n)));
    for sequence in shard_sequences(scenes.len() as u64 * args.variations, index, count) {
        let path = args.output.join(format!("seq_{sequence:06}.mcap"));
        if path.exists() {
            eprintln!("{} exists: kept", path.display());
            continue;
        }
        let variation = Variation::draw(sequence, args.variations, args.seed, swatch.size_m);
        let scene = variation.apply_to_scene(&scenes[variation.scene]);
        let placed = variation.lift(place(&swatch, &scene, &settings(&args.run))?);
        let metadata = metadata(&args.run, &args.scenes[variation.scene], serde_json::to_value(variation)?);
        eprintln!("sequence {sequence}: {} variant {}", scene.name, variation.variation);
        run_to_trace(&args.run, &swatch, &scene, placed, path.to_str().unwrap_or_default(), &metadata)?;
    }
    Ok(Outcome::Success)
}

fn settings(args: &RunArgs) -> RunSettings {
    RunSettings {
        steps_per_frame: args.steps_per_frame,
        damping_rate_per_s: args.damping,
        ..RunSettings::default()
    }
}

fn metadata(args: &RunArgs, scene: &str, variation: serde_json::Value) -> TraceMetadata {
    TraceMetadata::new("yarnhom yls", env!("CARGO_PKG_VERSION"))
        .with_entry("scene", scene)
        .with_entry("swatch", args.swatch.display().to_string())
        .with_entry("steps_per_frame", args.steps_per_frame.to_string())
        .with_entry("damping_rate_per_s", args.damping.to_string())
        .with_entry("variation", variation.to_string())
}

/// Simulates `placed` (the swatch in `scene`) into the trace at `output`, with a progress bar.
fn run_to_trace(
    args: &RunArgs,
    swatch: &Swatch,
    scene: &yarnhom_shell::Scene,
    placed: yarnhom_yls::dynamics::Scene,
    output: &str,
    metadata: &TraceMetadata,
) -> anyhow::Result<()> {
    let mut simulation = Simulation::new(&placed)?;
    let frames = args.frames.unwrap_or_else(|| (scene.end_time_s / scene.frame_time_s).round() as u64);
    let bar = progress_bar(frames, "frames");
    let progress = |r: &yarnhom_yls::run::FrameReport| {
        bar.set_position(r.frame);
        bar.set_message(format!("closest {:.2} r", r.closest_distance_radii));
    };
    let plan =
        Frames { count: frames, frame_time_s: scene.frame_time_s, steps_per_frame: args.steps_per_frame };
    if args.checkpoint_every == 0 || is_stdio(output) {
        let mut trace = open_trace(output, metadata)?;
        record_run(&mut trace, &mut simulation, &swatch.name, &plan, progress)?;
        finish_trace(Some(trace), Some(output))?;
    } else {
        let (path, every) = (Path::new(output), args.checkpoint_every);
        let resumed =
            record_resumable(path, metadata, &mut simulation, &swatch.name, &plan, every, progress)?;
        if resumed > 0 {
            eprintln!("resumed {output} at frame {resumed}");
        }
    }
    bar.finish_and_clear();
    eprintln!("simulated {} s of {} yarn vertices", simulation.time_s(), swatch.positions_m.len());
    Ok(())
}
