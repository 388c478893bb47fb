//! `yarnhom calibrate ...`: fitting models to measured fabric (thesis Ch. 6).

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use clap::{Args, Subcommand};
use yarnhom_artifacts::report::{Report, read_report, write_report};
use yarnhom_calib::auto_model::fit_shell;
use yarnhom_calib::cause::CauseId;
use yarnhom_calib::data::set::{Direction, MeasurementSet, Phase};
use yarnhom_calib::data::targets::TargetPlan;
use yarnhom_calib::diagnosis::settings::Budget;
use yarnhom_calib::diagnosis::{confirm, diagnose};
use yarnhom_calib::experiments::pear_loop::PearLoopTest;
use yarnhom_calib::experiments::strip::hinge_bending;
use yarnhom_calib::experiments::synth::{HiddenEffect, SynthRequest, ground_truth};
use yarnhom_calib::shell::fit::{ShellFit, ShellFitSettings};
use yarnhom_calib::shell::membrane::MembraneModel;

use yarnhom_calib::figures;
use yarnhom_figures::{Figure, render_svg};

use crate::Outcome;
use crate::args::{finite, max_stretch, non_negative, positive};
use crate::calibrate_yarn::{print_progress, set_pattern};
use crate::output::{create_dir, write_bytes};

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
    #[arg(long, value_enum, default_value = "weft")]
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

#[derive(Debug, Args)]
pub struct SynthArgs {
    /// Output directory of the measurement set (created).
    #[arg(short, long)]
    pub output: PathBuf,
    /// The effect hidden in the data.
    #[arg(long, value_enum)]
    pub effect: HiddenEffect,
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
    pub model: MembraneModel,
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
        model: args.model,
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
    write_figure(&svg, &figures::shell_fit_figure(&set, &fit))?;
    let mut written = format!("{} and {}", json.display(), svg.display());
    if let Some(figure) = figures::shell_bending_figure(&fit) {
        let path = args.output.join("bending.svg");
        write_figure(&path, &figure)?;
        written += &format!(" and {}", path.display());
    }
    println!("{}", fit.summary());
    eprintln!("wrote {written}");
    Ok(Outcome::Success)
}

/// Render `figure` to an SVG file.
fn write_figure(path: &Path, figure: &Figure) -> Result<()> {
    write_bytes(path, render_svg(figure)?.as_bytes())
}

fn diagnose_command(args: DiagnoseArgs) -> Result<Outcome> {
    let set = MeasurementSet::read(&args.set)?;
    let budget = args.budget;
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
    write_bytes(&out("report.md"), d.markdown().as_bytes())?;
    write_figure(&out("fit.svg"), &figures::diagnosis_figure(&set, &d))?;
    write_figure(&out("residuals.svg"), &figures::residuals_figure(&d))?;
    let mut written = "report.json, report.md, fit.svg, residuals.svg".to_string();
    if let Some(figure) = figures::diagnosis_bending_figure(&d) {
        write_figure(&out("bending.svg"), &figure)?;
        written += ", bending.svg";
    }
    println!("{}", d.summary());
    eprintln!("wrote {}/{written}", args.output.display());
    Ok(Outcome::Success)
}

fn synth(args: SynthArgs) -> Result<Outcome> {
    let request = SynthRequest {
        name: args.output.file_name().and_then(|n| n.to_str()).unwrap_or("synthetic").to_string(),
        effect: args.effect,
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
        write_bytes(path, serde_json::to_string_pretty(&truth_json)?.as_bytes())?;
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
