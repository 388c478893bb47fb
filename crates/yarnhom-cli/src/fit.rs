//! `yarnhom fit ...`: homogenized cloth materials from sampled grids (thesis Sec. 4.1, App.
//! A.3), and the ARCSim-HYLC material JSON in both directions.

use std::path::{Path, PathBuf};

use anyhow::Context;
use clap::{Args, Subcommand};
use yarnhom_artifacts::arcsim::{ArcsimMaterial, read_spline};
use yarnhom_artifacts::grid::AXIS_NAMES;
use yarnhom_artifacts::{AnyArtifact, AxisLimit, FitSettings, Grid, InputRef, Spline, container};
use yarnhom_fit::fit::restrict_grid;
use yarnhom_fit::ranges::STOCKINETTE_SPAN_2D_BENDING;
use yarnhom_fit::{
    SplineMaterial, TermShape, fit_errors, fit_grid_with_regularized_terms, regularized_term_shapes,
    term_shapes,
};

use crate::Outcome;
use crate::inputs::{self, provenance};

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

/// The index of a strain parameter by its name (`sx`, `sa`, `sy`, `kx`, `ky`).
pub(crate) fn parse_axis(name: &str) -> Result<usize, String> {
    AXIS_NAMES
        .iter()
        .position(|&a| a == name.trim())
        .ok_or_else(|| format!("unknown axis '{name}' (axes: {})", AXIS_NAMES.join(", ")))
}

/// `MIN:MAX` as two numbers.
pub(crate) fn parse_interval(text: &str) -> Result<[f64; 2], String> {
    let (min, max) = text.split_once(':').ok_or_else(|| format!("expected MIN:MAX, got '{text}'"))?;
    let number = |v: &str| v.trim().parse::<f64>().map_err(|e| format!("'{v}': {e}"));
    Ok([number(min)?, number(max)?])
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

/// A grid artifact from a file, with its input reference.
fn load_grid(path: &Path) -> anyhow::Result<(Grid, InputRef)> {
    let loaded = inputs::load(path, None)?;
    let input = InputRef {
        kind: "grid".into(),
        content_hash: loaded.header.content_hash.clone(),
        path: path.display().to_string(),
    };
    match loaded.artifact {
        AnyArtifact::Grid(grid) => Ok((grid, input)),
        other => anyhow::bail!("{}: holds a '{}', not a grid", path.display(), other.kind()),
    }
}

/// A spline from a `.spline.yh` (or its JSON/HDF5 forms) or an ARCSim-HYLC JSON.
pub fn load_spline(path: &Path) -> anyhow::Result<Spline> {
    let bytes = std::fs::read(path).with_context(|| format!("cannot read {}", path.display()))?;
    if inputs::Format::sniff(&bytes).is_none() || bytes.windows(13).any(|w| w == b"\"strain scale") {
        return Ok(read_spline(path)?);
    }
    match inputs::load(path, None)?.artifact {
        AnyArtifact::Spline(spline) => Ok(spline),
        other => anyhow::bail!("{}: holds a '{}', not a spline", path.display(), other.kind()),
    }
}

fn fit(args: GridFitArgs) -> anyhow::Result<Outcome> {
    let (Some(grid_path), Some(output)) = (&args.grid, &args.output) else {
        anyhow::bail!("usage: yarnhom fit GRID -o OUTPUT.spline.yh");
    };
    let (grid, input) = load_grid(grid_path)?;
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
    container::write(output, &spline, &provenance("fit", vec![input]))?;
    println!("{}", spline.summary());
    let fitted = restrict_grid(&grid, &args.limits);
    if !args.limits.is_empty() {
        println!(
            "limits: {} of the grid's {} samples used (the rest lie beyond the limits)",
            fitted.samples.len(),
            grid.samples.len()
        );
    }
    print_errors(&fitted, &spline, !args.no_shear_symmetry);
    print_shapes(&fitted, &spline, &fit.regularized_2d);
    println!("wrote {}", output.display());
    Ok(Outcome::Success)
}

/// The fit's relative RMS error on each term of its grid (the acceptance figure).
fn print_errors(grid: &Grid, spline: &Spline, symmetrized_shear: bool) {
    let material = SplineMaterial::from(spline);
    println!(
        "relative RMS error of the fit on its grid: of Ψ; of Ψ - f0; of Ψ as modelled (2D terms without compression, A.3.6{}):",
        if symmetrized_shear { "; symmetrized in sa, Sec. 4.1" } else { "" }
    );
    for e in fit_errors(grid, &material, spline.rest_energy_density_j_m2, symmetrized_shear) {
        let modelled = e
            .relative_rms_modelled
            .map_or("-".to_string(), |r| format!("{:6.2}% ({} samples)", 100.0 * r, e.samples_modelled));
        println!(
            "  {:8} {:5} samples  {:6.2}%  {:6.2}%  {modelled}",
            e.term,
            e.samples,
            100.0 * e.relative_rms,
            100.0 * e.relative_rms_deformation
        );
    }
}

/// Whether each quasiconvexified term, and the material's energy on each term's plane, has a
/// single minimum along its lines (A.36).
fn print_shapes(grid: &Grid, spline: &Spline, regularized_2d: &[yarnhom_artifacts::BicubicTerm]) {
    println!(
        "single minimum along every line through each term's control points, halfway between them and \
         along the edges, over 1.5x the sampled range (A.36); of each quasiconvexified term (the 1D \
         terms, the 2D terms' regularized fits f*, Sec. 4.1.2) / of the material's energy on the term's \
         axis or plane (f0 + f_u + f_v + f_uv, their sum, which the thesis allows more minima):"
    );
    let terms = regularized_term_shapes(grid, spline, regularized_2d, 1e-6);
    for (term, material) in terms.iter().zip(term_shapes(grid, spline, 1e-6)) {
        println!("  {:8} {} / {}", term.term, shape_verdict(term), shape_verdict(&material));
    }
}

/// `yes (N lines)` or `NO on K of N lines, e.g. ...`.
fn shape_verdict(shape: &TermShape) -> String {
    match shape.violations.first() {
        None => format!("yes ({} lines)", shape.lines),
        Some(first) => format!("NO on {} of {} lines, e.g. {first}", shape.violations.len(), shape.lines),
    }
}

fn import(args: ImportArgs) -> anyhow::Result<Outcome> {
    let spline = read_spline(&args.input)?;
    container::write(&args.output, &spline, &provenance("fit import-arcsim", Vec::new()))?;
    println!("{}", spline.summary());
    println!("wrote {}", args.output.display());
    Ok(Outcome::Success)
}

fn export(args: ExportArgs) -> anyhow::Result<Outcome> {
    let spline = load_spline(&args.input)?;
    let json = ArcsimMaterial::from_spline(&spline).to_json()?;
    std::fs::write(&args.output, json).with_context(|| format!("cannot write {}", args.output.display()))?;
    println!("wrote {}", args.output.display());
    Ok(Outcome::Success)
}

fn plot(args: PlotArgs) -> anyhow::Result<Outcome> {
    let (grid, _) = load_grid(&args.grid)?;
    let spline = load_spline(&args.spline)?;
    std::fs::create_dir_all(&args.output)
        .with_context(|| format!("cannot create {}", args.output.display()))?;
    for (file, figure) in yarnhom_fit::figures::fit_figures(&grid, &spline) {
        let path = args.output.join(file);
        std::fs::write(&path, yarnhom_figures::render_svg(&figure)?)
            .with_context(|| format!("cannot write {}", path.display()))?;
        println!("wrote {}", path.display());
    }
    Ok(Outcome::Success)
}

/// The strain range `[lo, hi]` a spline's 1D term has knots over (its fitted range).
fn knot_range(spline: &Spline, axis: usize) -> Option<[f64; 2]> {
    let term = spline.terms_1d.iter().find(|t| t.axis as usize == axis)?;
    let scale = spline.strain_scale[axis];
    Some([term.knots[0] * scale, term.knots[term.knots.len() - 1] * scale])
}

/// Two splines' 1D terms over the strains both were fitted on (the overlap of their knot
/// ranges), each relative to its value at zero strain.
fn compare(args: CompareArgs) -> anyhow::Result<Outcome> {
    let (a, b) = (load_spline(&args.first)?, load_spline(&args.second)?);
    let (ma, mb) = (SplineMaterial::from(&a), SplineMaterial::from(&b));
    println!(
        "1D terms of '{}' and '{}' (energy relative to rest, J/m²) over the strains both were fitted on:",
        a.name, b.name
    );
    println!("  term  range                 RMS first  RMS second  RMS difference  shape correlation");
    for axis in 0..5 {
        let (Some(ra), Some(rb)) = (knot_range(&a, axis), knot_range(&b, axis)) else { continue };
        let (lo, hi) = (ra[0].max(rb[0]), ra[1].min(rb[1]));
        let xs: Vec<f64> = (0..=100).map(|k| lo + (hi - lo) * f64::from(k) / 100.0).collect();
        let curve = |m: &SplineMaterial| -> Option<Vec<f64>> {
            let zero = m.term_1d(axis, 0.0)?;
            xs.iter().map(|&x| m.term_1d(axis, x).map(|v| v - zero)).collect()
        };
        let (Some(ca), Some(cb)) = (curve(&ma), curve(&mb)) else { continue };
        let rms = |v: &[f64]| (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt();
        let diff: Vec<f64> = ca.iter().zip(&cb).map(|(x, y)| x - y).collect();
        println!(
            "  {:4}  [{:8.3}, {:8.3}]  {:10.4e} {:11.4e} {:15.4e} {:18.3}",
            yarnhom_artifacts::grid::AXIS_NAMES[axis],
            lo,
            hi,
            rms(&ca),
            rms(&cb),
            rms(&diff),
            correlation(&ca, &cb)
        );
    }
    Ok(Outcome::Success)
}

/// Pearson correlation of two curves: 1 for the same shape up to scale.
fn correlation(a: &[f64], b: &[f64]) -> f64 {
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    let (ma, mb) = (mean(a), mean(b));
    let cov: f64 = a.iter().zip(b).map(|(x, y)| (x - ma) * (y - mb)).sum();
    let va: f64 = a.iter().map(|x| (x - ma).powi(2)).sum();
    let vb: f64 = b.iter().map(|y| (y - mb).powi(2)).sum();
    cov / (va * vb).sqrt()
}
