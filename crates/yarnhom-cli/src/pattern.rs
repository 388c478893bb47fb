//! `yarnhom pattern ...`: generators and `.pyp` interop.

use std::path::{Path, PathBuf};

use clap::{Args, Subcommand};
use yarnhom_artifacts::open::{Format, base_name, open_artifact, open_pattern_as};
use yarnhom_artifacts::{AnyArtifact, Fabric, InputRef, Pattern};
use yarnhom_pattern::{GENERATORS, GeneratorParams, MirrorAxis, find_mirror, mirrored};

use crate::Outcome;
use crate::output::{write_artifact, write_text};

#[derive(Debug, Subcommand)]
pub enum PatternCommand {
    /// List the built-in pattern generators.
    List,
    /// Generate a pattern from a built-in generator (see `pattern list`).
    ///
    /// The result is a plausible, non-self-intersecting starting state for relaxation
    /// (`yarnhom rve relax`), without rest state. Unset sizes take the generator's defaults,
    /// which are printed.
    Generate(GenerateArgs),
    /// Import a `.pyp` periodic yarn pattern (the format of the published HYLC patterns),
    /// including its rest state when the file has one.
    Import(ImportArgs),
    /// Export a pattern to `.pyp` (numbers written so that they read back exactly).
    Export(ExportArgs),
    /// How far a pattern is from its mirror image (`X1 -> -X1` or `X2 -> -X2`, with the best
    /// translation and yarn matching), and that image, rest state included.
    ///
    /// A tile that is its own mirror image answers the shears `sa` and `-sa` alike; one that is
    /// not answers them differently. Two distances are reported: of the vertices from the images
    /// of their matched vertices, and of the vertices from the image centrelines (shapes only;
    /// the published stockinette under `X2 -> -X2`: 0.87 and 0.10 radii RMS, its vertices sit at
    /// other places along the same curves). The image answers the mirrored strain exactly as the
    /// tile answers the strain.
    Mirror(MirrorArgs),
}

#[derive(Debug, Args)]
pub struct MirrorArgs {
    /// A pattern (`.yh`, JSON, HDF5 or `.pyp`).
    pub input: PathBuf,
    /// The coordinate the mirror negates.
    #[arg(long, value_enum, default_value = "x1")]
    pub axis: MirrorAxis,
    /// Write the mirror image here.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
}

#[derive(Debug, Args)]
pub struct GenerateArgs {
    /// Generator name: stockinette, garter, rib, seed, plain, basket, satin.
    pub name: String,
    /// Stitch width (m): wale spacing for knits, warp yarn spacing for weaves.
    #[arg(long, allow_negative_numbers = true)]
    pub stitch_width_m: Option<f64>,
    /// Stitch height (m): course spacing for knits, weft yarn spacing for weaves.
    #[arg(long, allow_negative_numbers = true)]
    pub stitch_height_m: Option<f64>,
    /// Yarn radius (m).
    #[arg(long, allow_negative_numbers = true)]
    pub radius_m: Option<f64>,
    /// Centreline vertices per stitch (resolution).
    #[arg(long)]
    pub vertices_per_stitch: Option<usize>,
    /// Output file (default: NAME.pattern.yh).
    #[arg(short, long)]
    pub output: Option<PathBuf>,
}

#[derive(Debug, Args)]
pub struct ImportArgs {
    /// The `.pyp` file.
    pub input: PathBuf,
    /// Knit or woven; inferred from the geometry when not given (knitted yarns loop back).
    #[arg(long, value_enum)]
    pub fabric: Option<Fabric>,
    /// Pattern name (default: the file name without extension).
    #[arg(long)]
    pub name: Option<String>,
    /// Output file (default: NAME.pattern.yh).
    #[arg(short, long)]
    pub output: Option<PathBuf>,
}

#[derive(Debug, Args)]
pub struct ExportArgs {
    /// A pattern (`.yh`, JSON or HDF5).
    pub input: PathBuf,
    /// Output `.pyp` file (default: NAME.pyp; `-` for standard output).
    #[arg(short, long)]
    pub output: Option<PathBuf>,
}

pub fn run(cmd: PatternCommand) -> anyhow::Result<Outcome> {
    match cmd {
        PatternCommand::List => list(),
        PatternCommand::Generate(args) => generate(args),
        PatternCommand::Import(args) => import(args),
        PatternCommand::Export(args) => export(args),
        PatternCommand::Mirror(args) => mirror(args),
    }
    .map(|()| Outcome::Success)
}

fn list() -> anyhow::Result<()> {
    for g in GENERATORS {
        println!("{:<12} {:<6} {}", g.name, g.fabric.to_string(), g.description);
    }
    Ok(())
}

fn generate(args: GenerateArgs) -> anyhow::Result<()> {
    let mut params = GeneratorParams::defaults_for(&args.name)?;
    params.stitch_width_m = args.stitch_width_m.unwrap_or(params.stitch_width_m);
    params.stitch_height_m = args.stitch_height_m.unwrap_or(params.stitch_height_m);
    params.yarn_radius_m = args.radius_m.unwrap_or(params.yarn_radius_m);
    params.vertices_per_stitch = args.vertices_per_stitch.unwrap_or(params.vertices_per_stitch);
    let pattern = yarnhom_pattern::generate(&args.name, &params)?;
    eprintln!("{}", pattern.origin);
    let output = args.output.unwrap_or_else(|| format!("{}.pattern.yh", args.name).into());
    write_pattern(&output, &pattern, "pattern generate", vec![])
}

fn import(args: ImportArgs) -> anyhow::Result<()> {
    let input = open_pattern_as(&args.input, args.fabric)?;
    anyhow::ensure!(input.format == Format::Pyp, "{}: not a .pyp file", args.input.display());
    let (header, artifact) = input.into_artifact()?;
    let AnyArtifact::Pattern(mut pattern) = artifact else {
        anyhow::bail!("{}: not a pattern", args.input.display())
    };
    if let Some(name) = args.name {
        pattern.name = name;
    }
    let output = args.output.unwrap_or_else(|| format!("{}.pattern.yh", pattern.name).into());
    write_pattern(&output, &pattern, "pattern import", header.inputs)
}

fn export(args: ExportArgs) -> anyhow::Result<()> {
    let pattern = open_artifact::<Pattern>(&args.input)?.value;
    let text = yarnhom_artifacts::pyp::write_pyp(&pattern)?;
    let output = args.output.unwrap_or_else(|| format!("{}.pyp", base_name(&args.input)).into());
    write_text(&output, &text)
}

fn mirror(args: MirrorArgs) -> anyhow::Result<()> {
    let opened = open_artifact::<Pattern>(&args.input)?;
    let pattern = &opened.value;
    let mirror = find_mirror(pattern, args.axis)?;
    println!("{}", mirror.report(pattern));
    if let Some(output) = args.output {
        let image = mirrored(pattern, &mirror)?;
        write_pattern(&output, &image, "pattern mirror", vec![opened.input])?;
    }
    Ok(())
}

fn write_pattern(
    output: &Path,
    pattern: &Pattern,
    command: &str,
    inputs: Vec<InputRef>,
) -> anyhow::Result<()> {
    write_artifact(output, pattern, command, inputs)?;
    eprintln!(
        "wrote {} ({} yarn(s), {} vertices, {:.3} x {:.3} mm)",
        output.display(),
        pattern.yarns.len(),
        pattern.vertex_count(),
        pattern.period_m[0] * 1e3,
        pattern.period_m[1] * 1e3
    );
    Ok(())
}
