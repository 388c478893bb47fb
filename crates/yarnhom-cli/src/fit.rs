//! `yarnhom fit ...`: homogenized cloth materials from sampled grids (thesis Sec. 4.1, App.
//! A.3), and the ARCSim-HYLC material JSON in both directions.

use std::path::PathBuf;

use anyhow::Context;
use clap::{Args, Subcommand};
use yarnhom_artifacts::arcsim::ArcsimMaterial;
use yarnhom_artifacts::open::{Format, Opened, open, open_artifact};
use yarnhom_artifacts::{AnyArtifact, AxisLimit, FitSettings, Grid, Spline};
use yarnhom_fit::fit::restrict_grid;
use yarnhom_fit::ranges::STOCKINETTE_SPAN_2D_BENDING;
use yarnhom_fit::report::fit_report;
use yarnhom_fit::{comparison_report, fit_grid_with_regularized_terms};

use crate::Outcome;
use crate::args::{parse_axis, parse_interval};
use crate::output::{create_dir, write_artifact, write_bytes, wrote};

/// `yarnhom fit GRID -o X.spline.yh`, or one of the subcommands.
#[derive(Debug, Args)]
#[command(args_conflicts_with_subcommands = true, subcommand_negates_reqs = true)]
pub struct FitArgs {
    #[command(subcommand)]
    pub command: Option<FitCommand>,
    #[command(flatten)]
    pub grid: GridFitArgs,
}

#[derive(Debug, Subcommand)]
pub enum FitCommand {
    /// Read a published ARCSim-HYLC material JSON (e.g. `../shared/data/hylc-materials/stock1.json`)
    /// into a `spline` artifact.
    ImportArcsim(ImportArgs),
    /// Write a `spline` artifact as ARCSim-HYLC material JSON, for ARCSim-HYLC to simulate.
    ExportArcsim(ExportArgs),
    /// Figures of a fit against its grid: per 1D term data, fit and control points (Fig. 4.4);
    /// per 2D term data, sum of 1D fits, residual, fit and error heat maps (Fig. 4.5). SVG.
    Plot(PlotArgs),
    /// Compare two spline materials' 1D terms over the strains both were fitted on (e.g. our fit
    /// of a pattern against the published fit of it): RMS of each, of their difference, and the
    /// correlation of their shapes.
    Compare(CompareArgs),
}

/// Fitting a grid.
#[derive(Debug, Args)]
pub struct GridFitArgs {
    /// The sampled grid (`yarnhom rve sample`).
    #[arg(required = true)]
    pub grid: Option<PathBuf>,
    /// Output spline file.
    #[arg(short, long, required = true)]
    pub output: Option<PathBuf>,
    /// Areal mass density of the cloth (kg/m²); default 0.3.
    #[arg(long, default_value_t = 0.3)]
    pub areal_density: f64,
    /// The stockinette settings of Sec. 4.3 and App. A.3: 2D bending knots within 30% of the
    /// range, quasiconvexity slope 0.01.
    #[arg(long)]
    pub stockinette: bool,
    /// Quasiconvexity slope `p_min` of the marching (A.36); default 0.001.
    #[arg(long)]
    pub min_slope: Option<f64>,
    /// Control points on each side of 0 for 1D terms (default 5).
    #[arg(long)]
    pub knots_1d: Option<u32>,
    /// Control points on each side of 0 for each axis of 2D terms (default 4).
    #[arg(long)]
    pub knots_2d: Option<u32>,
    /// Smallest MLS support radius in normalized strain (A.35; default 0.12).
    #[arg(long)]
    pub mls_radius: Option<f64>,
    /// Do not symmetrize the data in `sa`.
    #[arg(long)]
    pub no_shear_symmetry: bool,
    /// Fit only the samples with an axis within limits, e.g. `--limit kx=-160:160` (repeatable):
    /// the thesis chooses its sampling limits below self-intersection and jamming (App. A.3.1);
    /// this applies such limits to a grid sampled wider. The limits must contain 0.
    #[arg(long = "limit", value_name = "AXIS=MIN:MAX", value_parser = parse_limit)]
    pub limits: Vec<AxisLimit>,
}

/// `AXIS=MIN:MAX` with `MIN <= 0 <= MAX`.
fn parse_limit(text: &str) -> Result<AxisLimit, String> {
    let (name, range) = text.split_once('=').ok_or("expected AXIS=MIN:MAX, e.g. kx=-160:160")?;
    let axis = parse_axis(name)?;
    let [min, max] = parse_interval(range)?;
    if !(min <= 0.0 && max >= 0.0) {
        return Err(format!("the limits must contain 0 (the rest state), got {min}:{max}"));
    }
    Ok(AxisLimit { axis: axis as u8, min, max })
}

#[derive(Debug, Args)]
pub struct ImportArgs {
    /// ARCSim-HYLC material JSON.
    pub input: PathBuf,
    /// Output spline file.
    #[arg(short, long)]
    pub output: PathBuf,
}

#[derive(Debug, Args)]
pub struct ExportArgs {
    /// A spline artifact.
    pub input: PathBuf,
    /// Output JSON file.
    #[arg(short, long)]
    pub output: PathBuf,
}

#[derive(Debug, Args)]
pub struct PlotArgs {
    /// The grid the spline was fitted to.
    pub grid: PathBuf,
    /// The spline (`.spline.yh`, or an ARCSim-HYLC JSON).
    pub spline: PathBuf,
    /// Output folder for the figures.
    #[arg(short, long)]
    pub output: PathBuf,
}

#[derive(Debug, Args)]
pub struct CompareArgs {
    /// First spline (`.spline.yh` or ARCSim-HYLC JSON).
    pub first: PathBuf,
    /// Second spline.
    pub second: PathBuf,
}

pub fn run(args: FitArgs) -> anyhow::Result<Outcome> {
    match args.command {
        Some(FitCommand::ImportArcsim(a)) => import(a),
        Some(FitCommand::ExportArcsim(a)) => export(a),
        Some(FitCommand::Plot(a)) => plot(a),
        Some(FitCommand::Compare(a)) => compare(a),
        None => fit(args.grid),
    }
}

fn settings(args: &GridFitArgs) -> FitSettings {
    let mut s = FitSettings::default();
    if args.stockinette {
        s.span_2d_bending = STOCKINETTE_SPAN_2D_BENDING;
        s.min_slope = 0.01;
    }
    s.min_slope = args.min_slope.unwrap_or(s.min_slope);
    s.knots_per_side_1d = args.knots_1d.unwrap_or(s.knots_per_side_1d);
    s.knots_per_side_2d = args.knots_2d.unwrap_or(s.knots_per_side_2d);
    s.mls_radius = args.mls_radius.unwrap_or(s.mls_radius);
    s.symmetrize_shear = !args.no_shear_symmetry;
    s.limits = args.limits.clone();
    s
}

fn fit(args: GridFitArgs) -> anyhow::Result<Outcome> {
    let (Some(grid_path), Some(output)) = (&args.grid, &args.output) else {
        anyhow::bail!("usage: yarnhom fit GRID -o OUTPUT.spline.yh");
    };
    let Opened { value: grid, input, .. } = open_artifact::<Grid>(grid_path)?;
    if !grid.is_complete() {
        eprintln!(
            "warning: the grid holds {} of its plan's {} samples",
            grid.samples.len(),
            grid.expected_samples()
        );
    }
    let fit = fit_grid_with_regularized_terms(&grid, &settings(&args), args.areal_density)
        .with_context(|| format!("cannot fit {}", grid_path.display()))?;
    let spline = fit.spline;
    write_artifact(output, &spline, "fit", vec![input])?;
    println!("{}", spline.summary());
    let fitted = restrict_grid(&grid, &args.limits);
    if !args.limits.is_empty() {
        println!(
            "limits: {} of the grid's {} samples used (the rest lie beyond the limits)",
            fitted.samples.len(),
            grid.samples.len()
        );
    }
    println!("{}", fit_report(&fitted, &spline, &fit.regularized_2d, !args.no_shear_symmetry));
    wrote(output);
    Ok(Outcome::Success)
}

fn import(args: ImportArgs) -> anyhow::Result<Outcome> {
    let input = open(&args.input)?;
    anyhow::ensure!(input.format == Format::Arcsim, "{}: not an ARCSim-HYLC material", args.input.display());
    let (_, artifact) = input.into_artifact()?;
    let AnyArtifact::Spline(spline) = artifact else {
        unreachable!("an ARCSim-HYLC material opens as a spline")
    };
    write_artifact(&args.output, &spline, "fit import-arcsim", Vec::new())?;
    println!("{}", spline.summary());
    wrote(&args.output);
    Ok(Outcome::Success)
}

fn export(args: ExportArgs) -> anyhow::Result<Outcome> {
    let spline = open_artifact::<Spline>(&args.input)?.value;
    let json = ArcsimMaterial::from_spline(&spline).to_json()?;
    write_bytes(&args.output, json.as_bytes())?;
    wrote(&args.output);
    Ok(Outcome::Success)
}

fn plot(args: PlotArgs) -> anyhow::Result<Outcome> {
    let grid = open_artifact::<Grid>(&args.grid)?.value;
    let spline = open_artifact::<Spline>(&args.spline)?.value;
    create_dir(&args.output)?;
    for (file, figure) in yarnhom_fit::figures::fit_figures(&grid, &spline) {
        let path = args.output.join(file);
        write_bytes(&path, yarnhom_figures::render_svg(&figure)?.as_bytes())?;
        wrote(&path);
    }
    Ok(Outcome::Success)
}

/// Two splines' 1D terms over the strains both were fitted on.
fn compare(args: CompareArgs) -> anyhow::Result<Outcome> {
    let a = open_artifact::<Spline>(&args.first)?.value;
    let b = open_artifact::<Spline>(&args.second)?.value;
    println!("{}", comparison_report(&a, &b));
    Ok(Outcome::Success)
}
