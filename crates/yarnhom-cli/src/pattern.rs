//! `yarnhom pattern ...`: generators and `.pyp` interop.

use std::path::PathBuf;

use anyhow::Context;
use clap::{Args, Subcommand};
use yarnhom_artifacts::{AnyArtifact, Fabric, Pattern, container};
use yarnhom_pattern::{GENERATORS, GeneratorParams, MirrorAxis, find_mirror, mirrored, root_mean_square};

use crate::Outcome;
use crate::inputs::{self, base_name, provenance};

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
    pub axis: AxisArg,
    /// Write the mirror image here.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
}

/// Mirror axes on the command line.
#[derive(Debug, Clone, Copy, clap::ValueEnum)]
pub enum AxisArg {
    /// `X1 -> -X1` (a knit's wale axis).
    X1,
    /// `X2 -> -X2`.
    X2,
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
    pub fabric: Option<FabricArg>,
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

/// Fabric kinds on the command line.
#[derive(Debug, Clone, Copy, clap::ValueEnum)]
pub enum FabricArg {
    /// Knitted.
    Knit,
    /// Woven.
    Woven,
}

impl From<FabricArg> for Fabric {
    fn from(f: FabricArg) -> Self {
        match f {
            FabricArg::Knit => Fabric::Knit,
            FabricArg::Woven => Fabric::Woven,
        }
    }
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
    if let Some(v) = args.stitch_width_m {
        params.stitch_width_m = v;
    }
    if let Some(v) = args.stitch_height_m {
        params.stitch_height_m = v;
    }
    if let Some(v) = args.radius_m {
        params.yarn_radius_m = v;
    }
    if let Some(v) = args.vertices_per_stitch {
        params.vertices_per_stitch = v;
    }
    let pattern = yarnhom_pattern::generate(&args.name, &params)?;
    eprintln!("{}", pattern.origin);
    let output = args.output.unwrap_or_else(|| format!("{}.pattern.yh", args.name).into());
    write_pattern(&output, &pattern, provenance("pattern generate", vec![]))
}

fn import(args: ImportArgs) -> anyhow::Result<()> {
    let loaded = inputs::load(&args.input, args.fabric.map(Fabric::from))?;
    anyhow::ensure!(loaded.format == inputs::Format::Pyp, "{}: not a .pyp file", args.input.display());
    let AnyArtifact::Pattern(mut pattern) = loaded.artifact else {
        anyhow::bail!("{}: not a pattern", args.input.display())
    };
    if let Some(name) = args.name {
        pattern.name = name;
    }
    let output = args.output.unwrap_or_else(|| format!("{}.pattern.yh", pattern.name).into());
    write_pattern(&output, &pattern, provenance("pattern import", loaded.header.inputs))
}

fn export(args: ExportArgs) -> anyhow::Result<()> {
    let loaded = inputs::load(&args.input, None)?;
    let AnyArtifact::Pattern(pattern) = &loaded.artifact else {
        anyhow::bail!(
            "{}: holds a '{}', only patterns export to .pyp",
            args.input.display(),
            loaded.artifact.kind()
        )
    };
    let text = yarnhom_artifacts::pyp::write_pyp(pattern)?;
    let output = args.output.unwrap_or_else(|| format!("{}.pyp", base_name(&args.input)).into());
    write_text(&output, &text)
}

fn mirror(args: MirrorArgs) -> anyhow::Result<()> {
    let (pattern, input) = inputs::load_pattern(&args.input)?;
    let axis = match args.axis {
        AxisArg::X1 => MirrorAxis::X1,
        AxisArg::X2 => MirrorAxis::X2,
    };
    let mirror = find_mirror(&pattern, axis)?;
    let (r_lo, _) = pattern.radius_range_m();
    println!(
        "mirror {axis} of {} ({} yarn(s), {} vertices)",
        pattern.name,
        pattern.yarns.len(),
        pattern.vertex_count()
    );
    for (y, (partner, reversed)) in mirror.partner.iter().zip(&mirror.reversed).enumerate() {
        let way = if *reversed { "backwards" } else { "forwards" };
        println!("  yarn {y} <- yarn {partner}, {way}");
    }
    let t = mirror.shift_m;
    println!("  translation ({:.4}, {:.4}, {:.4}) mm", t[0] * 1e3, t[1] * 1e3, t[2] * 1e3);
    println!(
        "  vertices from their images: {:.4} mm RMS ({:.3} radii), {:.4} mm at most ({:.3} radii)",
        mirror.rms_distance_m() * 1e3,
        mirror.rms_distance_m() / r_lo,
        mirror.max_distance_m() * 1e3,
        mirror.max_distance_m() / r_lo
    );
    let curves = mirror.centreline_distances_m(&pattern);
    let rms = root_mean_square(curves.iter().copied());
    let max = curves.iter().copied().fold(0.0, f64::max);
    println!(
        "  centrelines from their images (shapes only, vertex spacing aside): {:.4} mm RMS ({:.3} radii), {:.4} mm at most ({:.3} radii)",
        rms * 1e3,
        rms / r_lo,
        max * 1e3,
        max / r_lo
    );
    if let Some(output) = args.output {
        let image = mirrored(&pattern, &mirror)?;
        write_pattern(&output, &image, provenance("pattern mirror", vec![input]))?;
    }
    Ok(())
}

fn write_pattern(
    output: &PathBuf,
    pattern: &Pattern,
    provenance: yarnhom_artifacts::Provenance,
) -> anyhow::Result<()> {
    container::write(output, pattern, &provenance)?;
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

/// Write text to a file atomically, or to standard output for `-`.
pub fn write_text(output: &PathBuf, text: &str) -> anyhow::Result<()> {
    if output.as_os_str() == "-" {
        use std::io::Write;
        std::io::stdout().write_all(text.as_bytes()).context("cannot write to standard output")?;
    } else {
        container::write_atomic(output, text.as_bytes()).map_err(|e| e.at(output))?;
        eprintln!("wrote {}", output.display());
    }
    Ok(())
}
