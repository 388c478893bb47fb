//! `yarnhom calibrate ...`: fitting models to measured fabric (thesis Ch. 6).

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use clap::{Args, Subcommand, ValueEnum};
use plotters::prelude::*;
use yarnhom_artifacts::container::write_atomic;
use yarnhom_artifacts::report::{Report, read_report, write_report};
use yarnhom_calib::cause::CauseId;
use yarnhom_calib::data::set::{Direction, Face, MeasurementSet, Phase};
use yarnhom_calib::data::targets::{Target, TargetPlan};
use yarnhom_calib::diagnosis::report::{BendingTrack, Diagnosis};
use yarnhom_calib::diagnosis::{confirm, diagnose, settings};
use yarnhom_calib::experiments::bending_tests::BendingTest;
use yarnhom_calib::experiments::pear_loop::PearLoopTest;
use yarnhom_calib::experiments::strip::hinge_bending;
use yarnhom_calib::experiments::swatch::SimulatedReading;
use yarnhom_calib::experiments::synth::{HiddenEffect, SynthRequest, ground_truth};
use yarnhom_calib::shell::fit::{ShellBending, ShellFit, ShellFitSettings, fit_shell};
use yarnhom_calib::shell::membrane::MembraneModel;

use crate::Outcome;
use crate::calibrate_yarn::{create_dir, print_progress, set_pattern};
use crate::fit_plot::{FONT, format_value, plot_error, render};

#[derive(Debug, Subcommand)]
pub enum CalibrateCommand {
    /// Fit the Ch. 6 membrane (anisotropic StVK + Neo-Hookean, (6.1)) to a measurement set's
    /// stretch tests by simulating the clamped swatch to equilibrium at each target (6.2);
    /// write OUT/shell-fit.json (material, errors, uniform targets (6.3)) and
    /// OUT/shell-fit.svg (Fig. 6.6: force and compression vs stretch per direction).
    Shell(ShellArgs),
    /// Diagnose what the base model (plain anisotropic StVK on the simulated clamped swatches)
    /// gets wrong: fit it on half the targets, fit every testable extension of the cause
    /// catalog, judge them on the held-out half and by an information criterion; write
    /// OUT/report.json, OUT/report.md, OUT/fit.svg and OUT/residuals.svg.
    Diagnose(DiagnoseArgs),
    /// Write a synthetic measurement set: clamped stretch tests simulated on a known membrane
    /// with an effect hidden in it, plus noise (for testing `calibrate diagnose`).
    Synth(SynthArgs),
    /// Simulate the pear-loop bending test (Sec. 6.2.3, 6.3.2): a strip of a given weight,
    /// membrane and hinge bending (6.4) clamped into a loop at each clamp distance; print the
    /// loop's height, width and aspect ratio (to choose distances where the test is sensitive).
    PearLoop(PearLoopArgs),
    /// Estimate the Ch. 6 yarn model (Sec. 6.5) whose periodic tile reproduces the fitted
    /// shell's uniform targets: particle swarm, then COBYLA or Levenberg-Marquardt, the yarns'
    /// rest shape re-estimated at every evaluation; write OUT/yarn-fit.json, the estimated
    /// OUT/yarn.yarnmodel.yh and OUT/rest.pattern.yh, and OUT/yarn-fit.svg (Fig. 6.13 style).
    Yarn(crate::calibrate_yarn::YarnArgs),
}

#[derive(Debug, Args)]
pub struct PearLoopArgs {
    /// Direction of the strip's long axis.
    #[arg(long, default_value = "weft", value_parser = parse_direction)]
    pub direction: Direction,
    /// Free length between the clamps (m).
    #[arg(long, default_value_t = 0.10, value_parser = positive)]
    pub length: f64,
    /// Areal density (kg/m²).
    #[arg(long, value_parser = positive)]
    pub density: f64,
    /// Hinge stiffnesses `k_weft,k_bias,k_warp` (J), or one value for all.
    #[arg(long, value_delimiter = ',', num_args = 1..=3, required = true, value_parser = positive)]
    pub bending: Vec<f64>,
    /// Rest curvatures `weft,bias,warp` (1/m), or one value for all; positive curls towards
    /// the face that is up when the strip lies flat, the way the loop's bulb bends.
    #[arg(long, value_delimiter = ',', num_args = 1..=3, default_value = "0", value_parser = finite)]
    pub rest_curvature: Vec<f64>,
    /// The membrane: a `shell-fit.json` of `calibrate shell` (default: a knit-like anisotropic
    /// StVK, 60 / 25 J/m²).
    #[arg(long)]
    pub membrane: Option<PathBuf>,
    /// Clamp distances (m).
    #[arg(long, value_delimiter = ',', required = true)]
    pub distances: Vec<f64>,
    /// Mesh edge length (m).
    #[arg(long, default_value_t = 0.005, value_parser = positive)]
    pub spacing: f64,
}

fn parse_direction(name: &str) -> Result<Direction, String> {
    Direction::parse(name).ok_or_else(|| format!("unknown direction '{name}' (weft, bias, warp)"))
}

/// A number of the range `ok` accepts, else `message`.
fn number(text: &str, ok: impl Fn(f64) -> bool, message: &str) -> Result<f64, String> {
    text.parse::<f64>().ok().filter(|x| ok(*x)).ok_or_else(|| message.to_string())
}

/// A finite number > 0 (a `value_parser`).
pub(crate) fn positive(text: &str) -> Result<f64, String> {
    number(text, |x| x.is_finite() && x > 0.0, "must be a positive finite number")
}

fn non_negative(text: &str) -> Result<f64, String> {
    number(text, |x| x.is_finite() && x >= 0.0, "must be a number >= 0")
}

fn finite(text: &str) -> Result<f64, String> {
    number(text, f64::is_finite, "must be a finite number")
}

fn max_stretch(text: &str) -> Result<f64, String> {
    number(text, |x| x.is_finite() && x > 0.0 && x <= 2.0, "must be in (0, 2]")
}

#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum Budget {
    /// Coarse swatches (8 mm), 10 optimizer iterations per model; no yarn-level confirmation.
    Quick,
    /// 5 mm swatches, 30 iterations per model; the cause confirmed on the tile by a reduced
    /// yarn-level fit (swarm 16 x 3 on 5 targets per direction, Gauss-Newton 8 Jacobians on 8).
    Normal,
    /// 3.5 mm swatches, 80 iterations per model; the confirmation by the full yarn-level fit
    /// (swarm 64 x 10 on 7 targets, Gauss-Newton 20 Jacobians on 20).
    Thorough,
}

impl From<Budget> for settings::Budget {
    fn from(budget: Budget) -> Self {
        match budget {
            Budget::Quick => settings::Budget::Quick,
            Budget::Normal => settings::Budget::Normal,
            Budget::Thorough => settings::Budget::Thorough,
        }
    }
}

#[derive(Debug, Args)]
pub struct DiagnoseArgs {
    /// The measurement set directory.
    pub set: PathBuf,
    /// Output directory (created).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Targets per direction (even ones fitted, odd ones held out).
    #[arg(long, default_value_t = 10, value_parser = clap::value_parser!(u32).range(4..=60))]
    pub targets: u32,
    /// The stretch range ends where the measured force reaches this (N).
    #[arg(long, default_value_t = 5.0, value_parser = positive)]
    pub force_cap: f64,
    /// Time against confidence: mesh size and optimizer iterations per model, and the size of
    /// the yarn-level confirmation (none with `quick`).
    #[arg(long, value_enum, default_value = "normal")]
    pub budget: Budget,
    /// Known yarn stretch stiffness k_s2 (N) for the yarn-level confirmation; default: the
    /// stiffest of the set's yarns, else fitted.
    #[arg(long, value_parser = positive)]
    pub yarn_stiffness: Option<f64>,
}

#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum EffectArg {
    None,
    AreaPreservation,
    BiphasicStretch,
    TwoPhaseContact,
    FrictionHysteresis,
    RestCurvature,
    AnisotropicBending,
    /// Off the catalog (softening past an onset): the diagnosis should say `unexplained`.
    Softening,
}

impl From<EffectArg> for HiddenEffect {
    fn from(effect: EffectArg) -> Self {
        match effect {
            EffectArg::None => HiddenEffect::None,
            EffectArg::AreaPreservation => HiddenEffect::AreaPreservation,
            EffectArg::BiphasicStretch => HiddenEffect::BiphasicStretch,
            EffectArg::TwoPhaseContact => HiddenEffect::TwoPhaseContact,
            EffectArg::FrictionHysteresis => HiddenEffect::FrictionHysteresis,
            EffectArg::RestCurvature => HiddenEffect::RestCurvature,
            EffectArg::AnisotropicBending => HiddenEffect::AnisotropicBending,
            EffectArg::Softening => HiddenEffect::Softening,
        }
    }
}

#[derive(Debug, Args)]
pub struct SynthArgs {
    /// Output directory of the measurement set (created).
    #[arg(short, long)]
    pub output: PathBuf,
    /// The effect hidden in the data.
    #[arg(long, value_enum)]
    pub effect: EffectArg,
    /// Strength of the effect (1: clearly visible at 2% noise).
    #[arg(long, default_value_t = 1.0, value_parser = non_negative)]
    pub strength: f64,
    /// Noise: standard deviation of force and compression as a fraction of their mean values.
    #[arg(long, default_value_t = 0.02, value_parser = non_negative)]
    pub noise: f64,
    /// Seed of the noise.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Largest stretch of every direction, in (0, 2].
    #[arg(long, default_value_t = 0.4, value_parser = max_stretch)]
    pub max_stretch: f64,
    /// Also write the bending tests: pear loops (7 clamp distances, 0.3 to 3.4 cm) and
    /// cantilevers on both faces (7 overhangs, 0.8 to 3.2 cm) per direction, with the same
    /// relative noise; the swatch's areal density is set to 0.25 kg/m². Implied by the bending
    /// effects.
    #[arg(long)]
    pub bending_tests: bool,
    /// Also write the ground truth (membrane, friction, bending) as JSON here.
    #[arg(long)]
    pub truth: Option<PathBuf>,
}

#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum ModelArg {
    /// Plain anisotropic StVK.
    Stvk,
    /// StVK with the Neo-Hookean area terms (6.1).
    StvkNeoHookean,
    /// (6.1) with jamming past an onset compression (the `two-phase-contact` extension).
    StvkNeoHookeanJamming,
}

impl From<ModelArg> for MembraneModel {
    fn from(model: ModelArg) -> Self {
        match model {
            ModelArg::Stvk => MembraneModel::Stvk,
            ModelArg::StvkNeoHookean => MembraneModel::StvkNeoHookean,
            ModelArg::StvkNeoHookeanJamming => MembraneModel::StvkNeoHookeanJamming,
        }
    }
}

#[derive(Debug, Args)]
pub struct ShellArgs {
    /// The measurement set directory.
    pub set: PathBuf,
    /// Output directory (created).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Targets per direction, evenly spaced in stretch (thesis: 6).
    #[arg(long, default_value_t = 6, value_parser = clap::value_parser!(u32).range(2..=50))]
    pub targets: u32,
    /// The stretch range ends where the measured force reaches this (N; thesis: 5).
    #[arg(long, default_value_t = 5.0, value_parser = positive)]
    pub force_cap: f64,
    /// Mesh edge length of the simulated swatch (m).
    #[arg(long, default_value_t = 0.004, value_parser = positive)]
    pub spacing: f64,
    /// The membrane model.
    #[arg(long, value_enum, default_value = "stvk-neo-hookean")]
    pub model: ModelArg,
}

pub fn run(cmd: CalibrateCommand) -> Result<Outcome> {
    match cmd {
        CalibrateCommand::Shell(args) => shell(args),
        CalibrateCommand::Diagnose(args) => diagnose_command(args),
        CalibrateCommand::Synth(args) => synth(args),
        CalibrateCommand::PearLoop(args) => pear_loop(args),
        CalibrateCommand::Yarn(args) => crate::calibrate_yarn::run(args),
    }
}

fn shell(args: ShellArgs) -> Result<Outcome> {
    let set = MeasurementSet::read(&args.set)?;
    let settings = ShellFitSettings {
        plan: TargetPlan {
            per_direction: args.targets as usize,
            force_cap_n: args.force_cap,
            phase: Phase::Load,
        },
        model: args.model.into(),
        spacing_m: args.spacing,
        ..ShellFitSettings::default()
    };
    eprintln!(
        "fitting {} to {} ({} readings) ...",
        settings.model.name(),
        set.fabric.name,
        set.stretch.len()
    );
    let fit = fit_shell(&set, &settings)?;
    create_dir(&args.output)?;
    let json = args.output.join("shell-fit.json");
    write_report(&json, &fit)?;
    let svg = args.output.join("shell-fit.svg");
    write_figure(&svg, plot_shell_fit(&set, &fit)?)?;
    let mut written = format!("{} and {}", json.display(), svg.display());
    if let Some(ShellBending { fit: Some(bending), tests, measured, .. }) = &fit.bending {
        let path = args.output.join("bending.svg");
        let fitted = vec![true; tests.len()];
        let predictions = [("fitted".to_string(), bending.simulated.clone())];
        let figure = BendingFigure { tests, measured, fitted: &fitted, predictions: &predictions };
        write_figure(&path, plot_bending(&fit.fabric, figure)?)?;
        written += &format!(" and {}", path.display());
    }
    println!("{}", fit.summary());
    eprintln!("wrote {written}");
    Ok(Outcome::Success)
}

fn write_figure(path: &Path, svg: String) -> Result<()> {
    std::fs::write(path, svg).with_context(|| format!("cannot write {}", path.display()))
}

fn diagnose_command(args: DiagnoseArgs) -> Result<Outcome> {
    let set = MeasurementSet::read(&args.set)?;
    let budget = settings::Budget::from(args.budget);
    let settings = budget.settings(args.targets as usize, args.force_cap);
    let (name, readings) = (&set.fabric.name, set.stretch.len());
    eprintln!(
        "diagnosing {name} ({readings} readings): base and {} candidates ...",
        CauseId::CANDIDATES.len()
    );
    let mut d = diagnose(&set, &settings)?;
    let cause = d.cause.id.as_str();
    let pattern = || {
        let pattern = set_pattern(&args.set, &set)?;
        let vertices = pattern.vertex_count();
        eprintln!("confirming {cause} on the yarn tile '{}' ({vertices} vertices) ...", pattern.name);
        anyhow::Ok(pattern)
    };
    let level = confirm::yarn_level(&set, &d, budget, args.yarn_stiffness, pattern, &print_progress);
    d.yarn_level = Some(level);
    create_dir(&args.output)?;
    let out = |name: &str| args.output.join(name);
    write_report(&out("report.json"), &d)?;
    write_atomic(&out("report.md"), d.markdown().as_bytes()).map_err(|e| e.at(out("report.md")))?;
    write_figure(&out("fit.svg"), plot_diagnosis(&set, &d)?)?;
    write_figure(&out("residuals.svg"), plot_residuals(&d)?)?;
    let mut written = "report.json, report.md, fit.svg, residuals.svg".to_string();
    if let Some(track) = &d.bending {
        write_figure(&out("bending.svg"), plot_bending(&d.fabric, track.into())?)?;
        written += ", bending.svg";
    }
    println!("{}", d.summary());
    eprintln!("wrote {}/{written}", args.output.display());
    Ok(Outcome::Success)
}

fn synth(args: SynthArgs) -> Result<Outcome> {
    let request = SynthRequest {
        name: args.output.file_name().and_then(|n| n.to_str()).unwrap_or("synthetic").to_string(),
        effect: args.effect.into(),
        strength: args.strength,
        noise: args.noise,
        seed: args.seed,
        max_stretch: args.max_stretch,
        bending_tests: args.bending_tests,
    };
    let (truth, set) = request.synthesize()?;
    set.write(&args.output)?;
    if let Some(path) = &args.truth {
        let truth_json = serde_json::json!({ "truth": truth, "effect": format!("{:?}", args.effect) });
        write_atomic(path, serde_json::to_string_pretty(&truth_json)?.as_bytes()).map_err(|e| e.at(path))?;
    }
    let (stretch, pear, cantilever) = (set.stretch.len(), set.bending.len(), set.cantilever.len());
    eprintln!(
        "wrote {} ({stretch} stretch, {pear} pear-loop and {cantilever} cantilever readings)",
        args.output.display()
    );
    Ok(Outcome::Success)
}

fn pear_loop(args: PearLoopArgs) -> Result<Outcome> {
    let bending = hinge_bending(&args.bending, &args.rest_curvature)
        .context("--bending and --rest-curvature take one value or three (weft,bias,warp)")?;
    let membrane = match &args.membrane {
        Some(path) => read_report::<ShellFit>(path)?.material,
        None => ground_truth(HiddenEffect::None, 0.0).membrane,
    };
    let test = PearLoopTest::new(args.direction, args.length, args.density, args.spacing);
    let readings = test.run(&membrane, &bending, &args.distances)?;
    println!("clamp_distance_m,height_m,width_m,aspect_ratio");
    for r in readings {
        println!("{},{},{},{}", r.clamp_distance_m, r.height_m, r.width_m, r.aspect_ratio);
    }
    Ok(Outcome::Success)
}

pub(crate) const MEASURED: RGBColor = RGBColor(0xB0, 0xB8, 0xC8);
pub(crate) const TARGET: RGBColor = RGBColor(0x1F, 0x5F, 0xD0);
pub(crate) const FITTED: RGBColor = RGBColor(0xC0, 0x30, 0x30);
pub(crate) const UNIFORM: RGBColor = RGBColor(0x1A, 0x9A, 0x3A);
const UNLOAD: RGBColor = RGBColor(0xE0, 0x90, 0x20);

/// How a series is drawn.
#[derive(Clone, Copy)]
pub(crate) enum Mark {
    /// Small filled dots (raw readings).
    Speck(RGBColor),
    /// Filled circles.
    Dot(RGBColor),
    /// Hollow circles.
    Ring(RGBColor),
    /// Crosses.
    Cross(RGBColor),
    /// A polyline.
    Line(RGBColor),
}

pub(crate) struct Series {
    pub label: String,
    pub mark: Mark,
    pub points: Vec<(f64, f64)>,
}

/// One chart of a figure: y against x (stretch unless said otherwise).
pub(crate) struct Panel {
    pub title: String,
    pub x_label: &'static str,
    pub y_label: String,
    pub series: Vec<Series>,
}

/// Draw `panels` in a grid of `columns` (row-major) as an SVG string.
pub(crate) fn plot_panels(panels: &[Panel], columns: usize) -> Result<String> {
    let rows = panels.len().div_ceil(columns.max(1));
    let size = (420 * columns as u32, 380 * rows as u32);
    render(size, |root| {
        for (area, panel) in root.split_evenly((rows, columns)).iter().zip(panels) {
            draw_panel(area, panel)?;
        }
        Ok(())
    })
}

fn draw_panel(area: &DrawingArea<SVGBackend<'_>, plotters::coord::Shift>, panel: &Panel) -> Result<()> {
    let points = || panel.series.iter().flat_map(|s| s.points.iter());
    let x_max = points().map(|p| p.0).fold(0.0_f64, f64::max).max(1e-6) * 1.05;
    let (lo, hi) = points().map(|p| p.1).fold((0.0_f64, 0.0_f64), |(a, b), y| (a.min(y), b.max(y)));
    let pad = 0.05 * (hi - lo).max(1e-9);
    let mut chart = ChartBuilder::on(area)
        .caption(&panel.title, (FONT, 16))
        .margin(10)
        .x_label_area_size(40)
        .y_label_area_size(55)
        .build_cartesian_2d(0.0..x_max, (lo - pad)..(hi + pad))
        .map_err(plot_error)?;
    chart
        .configure_mesh()
        .x_desc(panel.x_label)
        .y_desc(panel.y_label.as_str())
        .label_style((FONT, 12))
        .x_label_formatter(&|x| format_value(*x))
        .y_label_formatter(&|y| format_value(*y))
        .light_line_style(WHITE.mix(0.0))
        .draw()
        .map_err(plot_error)?;
    for s in &panel.series {
        let points = s.points.iter().copied();
        let drawn = match s.mark {
            Mark::Speck(c) => chart.draw_series(points.map(|p| Circle::new(p, 1, c.filled()))),
            Mark::Dot(c) => chart.draw_series(points.map(|p| Circle::new(p, 4, c.filled()))),
            Mark::Ring(c) => chart.draw_series(points.map(|p| Circle::new(p, 4, c.stroke_width(2)))),
            Mark::Cross(c) => chart.draw_series(points.map(|p| Cross::new(p, 5, c.stroke_width(2)))),
            Mark::Line(c) => chart.draw_series(LineSeries::new(points, c.stroke_width(2))),
        }
        .map_err(plot_error)?;
        let mark = s.mark;
        drawn.label(s.label.as_str()).legend(
            move |(x, y)| -> DynElement<'static, SVGBackend<'_>, (i32, i32)> {
                match mark {
                    Mark::Line(c) => {
                        PathElement::new(vec![(x - 8, y), (x + 8, y)], c.stroke_width(2)).into_dyn()
                    }
                    Mark::Cross(c) => Cross::new((x, y), 5, c.stroke_width(2)).into_dyn(),
                    Mark::Ring(c) => Circle::new((x, y), 4, c.stroke_width(2)).into_dyn(),
                    Mark::Speck(c) | Mark::Dot(c) => Circle::new((x, y), 3, c.filled()).into_dyn(),
                }
            },
        );
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperLeft)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK.mix(0.5))
        .label_font((FONT, 12))
        .draw()
        .map_err(plot_error)
}

/// The quantity of a figure row: force or compression.
#[derive(Clone, Copy)]
enum Quantity {
    Force,
    Compression,
}

impl Quantity {
    fn label(self) -> &'static str {
        match self {
            Quantity::Force => "force (N)",
            Quantity::Compression => "compression",
        }
    }

    fn of(self, force_n: f64, compression: Option<f64>) -> Option<f64> {
        match self {
            Quantity::Force => Some(force_n),
            Quantity::Compression => compression,
        }
    }

    fn of_reading(self, r: &SimulatedReading) -> f64 {
        match self {
            Quantity::Force => r.force_n,
            Quantity::Compression => r.compression,
        }
    }
}

/// Raw loading readings of `direction` up to `s_max`, thinned to about 1500 points.
fn raw_readings(
    set: &MeasurementSet,
    direction: Direction,
    phase: Phase,
    s_max: f64,
    q: Quantity,
) -> Vec<(f64, f64)> {
    let readings: Vec<_> = set
        .stretch
        .iter()
        .filter(|p| p.direction == direction && p.phase == phase && p.stretch <= s_max)
        .collect();
    let thin = (readings.len() / 1500).max(1);
    readings
        .iter()
        .step_by(thin)
        .filter_map(|p| q.of(p.force_n, p.compression).map(|v| (p.stretch, v)))
        .collect()
}

fn target_points<'a>(targets: impl Iterator<Item = &'a Target>, q: Quantity) -> Vec<(f64, f64)> {
    targets.filter_map(|t| q.of(t.force_n, t.compression).map(|v| (t.stretch, v))).collect()
}

/// Fig. 6.6: per direction a column, force vs stretch on top and compression vs stretch below;
/// raw loading readings (grey), targets (blue), the clamped-swatch fit (red), the uniform test
/// of the fitted material (green, (6.3)).
fn plot_shell_fit(set: &MeasurementSet, fit: &ShellFit) -> Result<String> {
    let directions: Vec<Direction> = fit.errors.by_direction.iter().map(|e| e.0).collect();
    let mut panels = Vec::new();
    for q in [Quantity::Force, Quantity::Compression] {
        for &direction in &directions {
            let specimen = set.fabric.swatch.specimen(direction);
            let mine: Vec<(usize, &Target)> =
                fit.targets.iter().enumerate().filter(|(_, t)| t.direction == direction).collect();
            let s_max = mine.iter().map(|(_, t)| t.stretch).fold(0.0, f64::max) * 1.05;
            let uniform = std::iter::once((0.0, 0.0)).chain(
                fit.uniform_targets.iter().filter(|u| u.direction == direction).map(|u| {
                    let p = u.point;
                    (p.stretch, q.of(p.stress_n_m * specimen.width_m, Some(p.compression)).unwrap_or(0.0))
                }),
            );
            panels.push(Panel {
                x_label: "stretch",
                title: format!("{} {direction}: {}", fit.fabric, q.label()),
                y_label: q.label().into(),
                series: vec![
                    Series {
                        label: "readings (load)".into(),
                        mark: Mark::Speck(MEASURED),
                        points: raw_readings(set, direction, Phase::Load, s_max, q),
                    },
                    Series {
                        label: "uniform test (6.3)".into(),
                        mark: Mark::Line(UNIFORM),
                        points: uniform.collect(),
                    },
                    Series {
                        label: "targets".into(),
                        mark: Mark::Dot(TARGET),
                        points: target_points(mine.iter().map(|(_, t)| *t), q),
                    },
                    Series {
                        label: "clamped swatch, fitted".into(),
                        mark: Mark::Cross(FITTED),
                        points: mine
                            .iter()
                            .map(|(i, t)| (t.stretch, q.of_reading(&fit.simulated[*i])))
                            .collect(),
                    },
                ],
            });
        }
    }
    plot_panels(&panels, directions.len())
}

/// The predictions of `id` at `direction`'s targets (load or unload).
fn predicted(d: &Diagnosis, id: &str, direction: Direction, unload: bool, q: Quantity) -> Vec<(f64, f64)> {
    let Some(p) = d.predictions.iter().find(|p| p.id == id) else { return Vec::new() };
    let (targets, readings) =
        if unload { (&d.unload_targets, &p.unload) } else { (&d.load_targets, &p.load) };
    targets
        .iter()
        .zip(readings)
        .filter(|(t, _)| t.direction == direction)
        .map(|(t, r)| (t.stretch, q.of_reading(r)))
        .collect()
}

/// Measured against base and extended: per direction force and compression, fitted targets
/// filled, held-out ones hollow, unloading in orange.
fn plot_diagnosis(set: &MeasurementSet, d: &Diagnosis) -> Result<String> {
    let directions: Vec<Direction> =
        Direction::ALL.into_iter().filter(|x| d.load_targets.iter().any(|t| t.direction == *x)).collect();
    let extended = d.extended.as_ref().map(|e| e.id.clone());
    let mut panels = Vec::new();
    for q in [Quantity::Force, Quantity::Compression] {
        for &direction in &directions {
            let s_max = d
                .load_targets
                .iter()
                .filter(|t| t.direction == direction)
                .map(|t| t.stretch)
                .fold(0.0, f64::max)
                * 1.05;
            let split = |fitted: bool| {
                target_points(
                    d.load_targets
                        .iter()
                        .zip(&d.load_fitted)
                        .filter(|(t, f)| t.direction == direction && **f == fitted)
                        .map(|(t, _)| t),
                    q,
                )
            };
            let mut series = vec![
                Series {
                    label: "readings (load)".into(),
                    mark: Mark::Speck(MEASURED),
                    points: raw_readings(set, direction, Phase::Load, s_max, q),
                },
                Series { label: "fitted targets".into(), mark: Mark::Dot(TARGET), points: split(true) },
                Series { label: "held-out targets".into(), mark: Mark::Ring(TARGET), points: split(false) },
                Series {
                    label: "base".into(),
                    mark: Mark::Line(BLACK),
                    points: predicted(d, "base", direction, false, q),
                },
            ];
            if let Some(id) = &extended {
                series.push(Series {
                    label: id.clone(),
                    mark: Mark::Line(FITTED),
                    points: predicted(d, id, direction, false, q),
                });
            }
            if d.unload_targets.iter().any(|t| t.direction == direction) {
                series.push(Series {
                    label: "unloading targets".into(),
                    mark: Mark::Ring(UNLOAD),
                    points: target_points(d.unload_targets.iter().filter(|t| t.direction == direction), q),
                });
                let id = extended.as_deref().unwrap_or("base");
                series.push(Series {
                    label: format!("{id}, unloading"),
                    mark: Mark::Cross(UNLOAD),
                    points: predicted(d, id, direction, true, q),
                });
            }
            panels.push(Panel {
                x_label: "stretch",
                title: format!("{} {direction}: {}", d.fabric, q.label()),
                y_label: q.label().into(),
                series,
            });
        }
    }
    plot_panels(&panels, directions.len())
}

/// The readings of bending tests and the models' simulations of them.
struct BendingFigure<'a> {
    tests: &'a [BendingTest],
    measured: &'a [f64],
    fitted: &'a [bool],
    predictions: &'a [(String, Vec<f64>)],
}

impl<'a> From<&'a BendingTrack> for BendingFigure<'a> {
    fn from(t: &'a BendingTrack) -> Self {
        Self { tests: &t.tests, measured: &t.measured, fitted: &t.fitted, predictions: &t.predictions }
    }
}

/// Bending tests: per direction, pear-loop aspect ratio against clamp distance and cantilever
/// tip drop against overhang (both faces), measured (fitted filled, held out hollow) against
/// the models (first black, second red).
fn plot_bending(fabric: &str, track: BendingFigure<'_>) -> Result<String> {
    let directions: Vec<Direction> =
        Direction::ALL.into_iter().filter(|d| track.tests.iter().any(|t| t.direction() == *d)).collect();
    let kinds: [(&str, &'static str, &str); 3] = [
        ("pear loop", "clamp distance (m)", "aspect ratio"),
        ("cantilever, face up", "overhang (m)", "tip drop (m)"),
        ("cantilever, face down", "overhang (m)", "tip drop (m)"),
    ];
    let kind_of = |t: &BendingTest| match t {
        BendingTest::PearLoop { .. } => 0,
        BendingTest::Cantilever { face: Face::Up, .. } => 1,
        BendingTest::Cantilever { face: Face::Down, .. } => 2,
    };
    let x_of = |t: &BendingTest| match t {
        BendingTest::PearLoop { clamp_distance_m, .. } => *clamp_distance_m,
        BendingTest::Cantilever { overhang_m, .. } => *overhang_m,
    };
    let mut panels = Vec::new();
    for (k, (kind, x_label, y_label)) in kinds.iter().enumerate() {
        if !track.tests.iter().any(|t| kind_of(t) == k) {
            continue;
        }
        for &direction in &directions {
            let mine: Vec<usize> = (0..track.tests.len())
                .filter(|&i| kind_of(&track.tests[i]) == k && track.tests[i].direction() == direction)
                .collect();
            let mut sorted = mine.clone();
            sorted.sort_by(|a, b| x_of(&track.tests[*a]).total_cmp(&x_of(&track.tests[*b])));
            let measured = |fitted: bool| {
                mine.iter()
                    .filter(|&&i| track.fitted[i] == fitted)
                    .map(|&i| (x_of(&track.tests[i]), track.measured[i]))
                    .collect()
            };
            let mut series = vec![
                Series { label: "measured, fitted".into(), mark: Mark::Dot(TARGET), points: measured(true) },
                Series {
                    label: "measured, held out".into(),
                    mark: Mark::Ring(TARGET),
                    points: measured(false),
                },
            ];
            for ((id, simulated), colour) in track.predictions.iter().zip([BLACK, FITTED]) {
                series.push(Series {
                    label: id.clone(),
                    mark: Mark::Line(colour),
                    points: sorted.iter().map(|&i| (x_of(&track.tests[i]), simulated[i])).collect(),
                });
            }
            panels.push(Panel {
                title: format!("{fabric} {direction}: {kind}"),
                x_label,
                y_label: (*y_label).into(),
                series,
            });
        }
    }
    plot_panels(&panels, directions.len())
}

/// Residuals (model minus measured, over the measured value's scale) against stretch per
/// direction and quantity, for the base and the extension, loading targets.
fn plot_residuals(d: &Diagnosis) -> Result<String> {
    let directions: Vec<Direction> =
        Direction::ALL.into_iter().filter(|x| d.load_targets.iter().any(|t| t.direction == *x)).collect();
    let mut panels = Vec::new();
    for q in [Quantity::Force, Quantity::Compression] {
        for &direction in &directions {
            let mine: Vec<&Target> = d.load_targets.iter().filter(|t| t.direction == direction).collect();
            let scale = mine.iter().filter_map(|t| q.of(t.force_n, t.compression)).map(f64::abs).sum::<f64>()
                / mine.len().max(1) as f64;
            let scale = scale.max(if matches!(q, Quantity::Compression) { 0.01 } else { 1e-12 });
            let residual = |id: &str| -> Vec<(f64, f64)> {
                predicted(d, id, direction, false, q)
                    .into_iter()
                    .zip(&mine)
                    .filter_map(|((s, v), t)| q.of(t.force_n, t.compression).map(|m| (s, (v - m) / scale)))
                    .collect()
            };
            let mut series =
                vec![Series { label: "base".into(), mark: Mark::Dot(BLACK), points: residual("base") }];
            if let Some(e) = &d.extended {
                series.push(Series {
                    label: e.id.clone(),
                    mark: Mark::Cross(FITTED),
                    points: residual(&e.id),
                });
            }
            panels.push(Panel {
                x_label: "stretch",
                title: format!("{} {direction}: {} residual", d.fabric, q.label()),
                y_label: "(model - measured) / mean".into(),
                series,
            });
        }
    }
    plot_panels(&panels, directions.len())
}
