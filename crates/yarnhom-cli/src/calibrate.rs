//! `yarnhom calibrate ...`: fitting models to measured fabric (thesis Ch. 6).

use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::{Args, Subcommand, ValueEnum};
use yarnhom_calib::diagnose::{CauseId, DiagnoseSettings, Diagnosis, diagnose};
use yarnhom_calib::figures;
use yarnhom_calib::lm::LmSettings;
use yarnhom_calib::measure::{Direction, MeasurementSet, Phase};
use yarnhom_calib::pear_loop::PearLoopTest;
use yarnhom_calib::shell_fit::{MembraneModel, ShellBending, ShellFit, ShellFitSettings, fit_shell};
use yarnhom_calib::synth::{BendingPlan, HiddenEffect, SynthPlan, ground_truth, synthesize};

/// Areal density of synthetic sets with bending tests (kg/m²): a mid-weight knit.
const SYNTH_AREAL_DENSITY_KG_M2: f64 = 0.25;
use yarnhom_calib::targets::TargetPlan;
use yarnhom_calib::yarn_confirm::{SearchSize, YarnLevel, confirm_diagnosis, skipped};
use yarnhom_calib::yarn_fit::{YarnFitEvent, YarnFitSettings};

use yarnhom_figures::render_svg;
use yarnhom_shell::HingeBending;

use crate::Outcome;
use crate::calibrate_yarn::{set_basis, set_pattern};

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
    #[arg(long, default_value_t = 0.10)]
    pub length: f64,
    /// Areal density (kg/m²).
    #[arg(long)]
    pub density: f64,
    /// Hinge stiffnesses `k_weft,k_bias,k_warp` (J), or one value for all.
    #[arg(long, value_delimiter = ',', num_args = 1..=3, required = true)]
    pub bending: Vec<f64>,
    /// Rest curvatures `weft,bias,warp` (1/m), or one value for all; positive curls towards
    /// the face that is up when the strip lies flat, the way the loop's bulb bends.
    #[arg(long, value_delimiter = ',', num_args = 1..=3, default_value = "0")]
    pub rest_curvature: Vec<f64>,
    /// The membrane: a `shell-fit.json` of `calibrate shell` (default: a knit-like anisotropic
    /// StVK, 60 / 25 J/m²).
    #[arg(long)]
    pub membrane: Option<PathBuf>,
    /// Clamp distances (m).
    #[arg(long, value_delimiter = ',', required = true)]
    pub distances: Vec<f64>,
    /// Mesh edge length (m).
    #[arg(long, default_value_t = 0.005)]
    pub spacing: f64,
}

fn parse_direction(name: &str) -> Result<Direction, String> {
    Direction::parse(name).ok_or_else(|| format!("unknown direction '{name}' (weft, bias, warp)"))
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

impl Budget {
    /// The yarn-level confirmation's fit settings (none for `quick`).
    fn confirmation(self) -> Option<YarnFitSettings> {
        match self {
            Budget::Quick => None,
            Budget::Normal => Some(SearchSize::Reduced.settings()),
            Budget::Thorough => Some(SearchSize::Full.settings()),
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
    #[arg(long, default_value_t = 5.0)]
    pub force_cap: f64,
    /// Time against confidence: mesh size and optimizer iterations per model, and the size of
    /// the yarn-level confirmation (none with `quick`).
    #[arg(long, value_enum, default_value = "normal")]
    pub budget: Budget,
    /// Known yarn stretch stiffness k_s2 (N) for the yarn-level confirmation; default: the
    /// stiffest of the set's yarns, else fitted.
    #[arg(long)]
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

#[derive(Debug, Args)]
pub struct SynthArgs {
    /// Output directory of the measurement set (created).
    #[arg(short, long)]
    pub output: PathBuf,
    /// The effect hidden in the data.
    #[arg(long, value_enum)]
    pub effect: EffectArg,
    /// Strength of the effect (1: clearly visible at 2% noise).
    #[arg(long, default_value_t = 1.0)]
    pub strength: f64,
    /// Noise: standard deviation of force and compression as a fraction of their mean values.
    #[arg(long, default_value_t = 0.02)]
    pub noise: f64,
    /// Seed of the noise.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Largest stretch of every direction.
    #[arg(long, default_value_t = 0.4)]
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
    #[arg(long, default_value_t = 5.0)]
    pub force_cap: f64,
    /// Mesh edge length of the simulated swatch (m).
    #[arg(long, default_value_t = 0.004)]
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
    anyhow::ensure!(
        args.force_cap.is_finite() && args.force_cap > 0.0,
        "--force-cap must be a positive number of newtons"
    );
    anyhow::ensure!(
        args.spacing.is_finite() && args.spacing > 0.0,
        "--spacing must be a positive length in metres"
    );
    let set = MeasurementSet::read(&args.set)?;
    let settings = ShellFitSettings {
        plan: TargetPlan {
            per_direction: args.targets as usize,
            force_cap_n: args.force_cap,
            phase: Phase::Load,
        },
        model: match args.model {
            ModelArg::Stvk => MembraneModel::Stvk,
            ModelArg::StvkNeoHookean => MembraneModel::StvkNeoHookean,
            ModelArg::StvkNeoHookeanJamming => MembraneModel::StvkNeoHookeanJamming,
        },
        spacing_m: args.spacing,
        ..ShellFitSettings::default()
    };
    eprintln!(
        "fitting {} to {} ({} readings) ...",
        model_name(settings.model),
        set.fabric.name,
        set.stretch.len()
    );
    let fit = fit_shell(&set, &settings)?;
    std::fs::create_dir_all(&args.output)
        .with_context(|| format!("cannot create {}", args.output.display()))?;
    let json = args.output.join("shell-fit.json");
    std::fs::write(&json, serde_json::to_string_pretty(&fit)?)
        .with_context(|| format!("cannot write {}", json.display()))?;
    let svg = args.output.join("shell-fit.svg");
    std::fs::write(&svg, render_svg(&figures::shell_fit_figure(&set, &fit))?)
        .with_context(|| format!("cannot write {}", svg.display()))?;
    let mut written = format!("{} and {}", json.display(), svg.display());
    if let Some(figure) = figures::shell_bending_figure(&fit) {
        let path = args.output.join("bending.svg");
        std::fs::write(&path, render_svg(&figure)?)
            .with_context(|| format!("cannot write {}", path.display()))?;
        written += &format!(" and {}", path.display());
    }
    println!("{}", summary(&fit));
    eprintln!("wrote {written}");
    Ok(Outcome::Success)
}

fn diagnose_command(args: DiagnoseArgs) -> Result<Outcome> {
    anyhow::ensure!(
        args.force_cap.is_finite() && args.force_cap > 0.0,
        "--force-cap must be a positive number of newtons"
    );
    if let Some(k) = args.yarn_stiffness {
        anyhow::ensure!(k.is_finite() && k > 0.0, "--yarn-stiffness must be a positive force in newtons");
    }
    let set = MeasurementSet::read(&args.set)?;
    let (spacing_m, max_iterations) = match args.budget {
        Budget::Quick => (0.008, 10),
        Budget::Normal => (0.005, 30),
        Budget::Thorough => (0.0035, 80),
    };
    let settings = DiagnoseSettings {
        targets_per_direction: args.targets as usize,
        force_cap_n: args.force_cap,
        spacing_m,
        lm: LmSettings { max_iterations, ..LmSettings::default() },
    };
    eprintln!(
        "diagnosing {} ({} readings): base and {} candidates ...",
        set.fabric.name,
        set.stretch.len(),
        CauseId::CANDIDATES.len()
    );
    let mut d = diagnose(&set, &settings)?;
    d.yarn_level = Some(match args.budget.confirmation() {
        None => YarnLevel::NotRun {
            reason:
                "--budget quick screens at the shell level only (normal or thorough confirm on the yarn tile)"
                    .into(),
        },
        Some(fit) => {
            skipped(d.cause.id).unwrap_or_else(|| match set_pattern(&args.set, &set.fabric.pattern) {
                Err(e) => YarnLevel::NotRun { reason: format!("the set's pattern: {e:#}") },
                Ok(pattern) => {
                    let basis = set_basis(&set, &pattern, args.yarn_stiffness);
                    eprintln!(
                        "confirming {} on the yarn tile '{}' ({} vertices) ...",
                        d.cause.id.as_str(),
                        pattern.name,
                        pattern.vertex_count()
                    );
                    let progress = |event: YarnFitEvent| match event {
                        YarnFitEvent::Generation(g, best) => {
                            eprintln!("  swarm generation {g}: best g = {best:.5}")
                        }
                        YarnFitEvent::LocalEvaluation(n, cost) => {
                            eprintln!("  local evaluation {n}: g = {cost:.5}")
                        }
                    };
                    confirm_diagnosis(&set, &d, pattern, basis, &fit, &progress)
                }
            })
        }
    });
    std::fs::create_dir_all(&args.output)
        .with_context(|| format!("cannot create {}", args.output.display()))?;
    let write = |name: &str, text: String| -> Result<()> {
        let path = args.output.join(name);
        std::fs::write(&path, text).with_context(|| format!("cannot write {}", path.display()))
    };
    write("report.json", serde_json::to_string_pretty(&d)?)?;
    write("report.md", report_markdown(&d))?;
    write("fit.svg", render_svg(&figures::diagnosis_figure(&set, &d))?)?;
    write("residuals.svg", render_svg(&figures::residuals_figure(&d))?)?;
    let mut written = "report.json, report.md, fit.svg, residuals.svg".to_string();
    if let Some(figure) = figures::diagnosis_bending_figure(&d) {
        write("bending.svg", render_svg(&figure)?)?;
        written += ", bending.svg";
    }
    println!("cause: {} ({})", d.cause.id.as_str(), d.cause.explanation);
    for line in &d.cause.evidence {
        println!("  {line}");
    }
    println!(
        "held-out error {:.4} -> {:.4}; {:.1} s",
        d.gain.heldout_error_before, d.gain.heldout_error_after, d.wall_time_s
    );
    match &d.yarn_level {
        Some(YarnLevel::Confirmation(c)) => println!("yarn level: {} ({:.1} s)", c.verdict, c.wall_time_s),
        Some(YarnLevel::NotRun { reason }) => println!("yarn level: not run: {reason}"),
        None => {}
    }
    eprintln!("wrote {}/{written}", args.output.display());
    Ok(Outcome::Success)
}

/// `report.md`: the verdict, the evidence, the candidate table, the parameters, the figures.
fn report_markdown(d: &Diagnosis) -> String {
    let number = |x: f64| format!("{x:.4}");
    let maybe = |x: Option<f64>| x.map_or("-".into(), number);
    let mut md = format!(
        "# Diagnosis of {}

**Cause: `{}`** — {}.

## Evidence

",
        d.fabric,
        d.cause.id.as_str(),
        d.cause.explanation
    );
    for line in &d.cause.evidence {
        md += &format!(
            "- {line}
"
        );
    }
    md += &format!(
        "
Held-out error (RMS normalized residual on targets not fitted): {} before, {} after. Noise level {}.

",
        number(d.gain.heldout_error_before),
        number(d.gain.heldout_error_after),
        number(d.noise)
    );
    md += "## Candidates

| model | testable | parameters | fitted error | held-out error | criterion (AIC) | note |
|---|---|---|---|---|---|---|
";
    for m in std::iter::once(&d.base).chain(d.bending.as_ref().map(|t| &t.base)).chain(&d.candidates) {
        md += &format!(
            "| {} | {} | {} | {} | {} | {} | {} |
",
            m.id,
            if m.testable { "yes" } else { "no" },
            m.parameter_count,
            maybe(m.error),
            maybe(m.heldout_error),
            maybe(m.criterion),
            m.note.as_deref().unwrap_or("")
        );
    }
    let bending_base = d.bending.as_ref().map(|t| &t.base);
    for (title, model) in [
        ("Base parameters", Some(&d.base)),
        ("Bending base parameters", bending_base),
        ("Extended parameters", d.extended.as_ref()),
    ] {
        let Some(model) = model else { continue };
        md += &format!(
            "
## {title} ({})

",
            model.id
        );
        for (name, value) in &model.params {
            md += &format!(
                "- `{name}` = {value:.6}
"
            );
        }
    }
    md += &yarn_level_markdown(d.yarn_level.as_ref());
    md += "
## Figures

![measured, base and extended](fit.svg)

![residuals](residuals.svg)

";
    md += &format!(
        "{} loading targets ({} fitted), {} unloading targets; {:.1} s.
",
        d.load_targets.len(),
        d.load_fitted.iter().filter(|f| **f).count(),
        d.unload_targets.len(),
        d.wall_time_s
    );
    md
}

/// The yarn-level confirmation's section of `report.md`.
fn yarn_level_markdown(level: Option<&YarnLevel>) -> String {
    let c = match level {
        None => return String::new(),
        Some(YarnLevel::NotRun { reason }) => {
            return format!("\n## Yarn-level confirmation\n\nNot run: {reason}.\n");
        }
        Some(YarnLevel::Confirmation(c)) => c,
    };
    let mut md = format!(
        "\n## Yarn-level confirmation\n\n**{}** — {}\n\nTile `{}`; targets: the extended shell's uniform tests, {} per \
         direction fitted and as many held out between them; a swarm per model ({} evaluations in all, the \
         extension's seeded with the base's optimum), then {} local steps from their best (and the base's second \
         from the extension's optimum); {:.1} s.\n\n| yarn model | parameters | fitted error | held-out error | criterion (AIC) | local evaluations |\n|---|---|---|---|---|---|\n",
        if c.confirmed { "Confirmed" } else { "Not confirmed" },
        c.verdict,
        c.pattern,
        c.settings.local_targets,
        c.swarm_evaluations,
        serde_json::to_value(c.settings.local)
            .ok()
            .and_then(|v| v.as_str().map(String::from))
            .unwrap_or_default(),
        c.wall_time_s
    );
    for (name, m) in [("base (linear stretch, single-phase contact)", &c.base), ("extended", &c.extended)] {
        md += &format!(
            "| {name} | {} | {:.4} | {:.4} | {:.1} | {} |\n",
            m.coordinates.len(),
            m.error,
            m.heldout_error,
            m.criterion,
            m.evaluations
        );
    }
    for (name, m) in [("Base yarn parameters", &c.base), ("Extended yarn parameters", &c.extended)] {
        md += &format!("\n### {name}\n\n");
        let p = serde_json::to_value(m.params).unwrap_or_default();
        for (key, value) in p.as_object().into_iter().flatten() {
            md += &format!("- `{key}` = {value}\n");
        }
    }
    md
}

fn synth(args: SynthArgs) -> Result<Outcome> {
    anyhow::ensure!(args.strength.is_finite() && args.strength >= 0.0, "--strength must be a number >= 0");
    anyhow::ensure!(args.noise.is_finite() && args.noise >= 0.0, "--noise must be a number >= 0");
    anyhow::ensure!(
        args.max_stretch.is_finite() && args.max_stretch > 0.0 && args.max_stretch <= 2.0,
        "--max-stretch must be in (0, 2]"
    );
    let effect = match args.effect {
        EffectArg::None => HiddenEffect::None,
        EffectArg::AreaPreservation => HiddenEffect::AreaPreservation,
        EffectArg::BiphasicStretch => HiddenEffect::BiphasicStretch,
        EffectArg::TwoPhaseContact => HiddenEffect::TwoPhaseContact,
        EffectArg::FrictionHysteresis => HiddenEffect::FrictionHysteresis,
        EffectArg::RestCurvature => HiddenEffect::RestCurvature,
        EffectArg::AnisotropicBending => HiddenEffect::AnisotropicBending,
        EffectArg::Softening => HiddenEffect::Softening,
    };
    let truth = ground_truth(effect, args.strength);
    let name = args.output.file_name().and_then(|n| n.to_str()).unwrap_or("synthetic").to_string();
    let bending_tests = args.bending_tests
        || matches!(effect, HiddenEffect::RestCurvature | HiddenEffect::AnisotropicBending);
    let mut clean_plan = SynthPlan {
        readings: 120,
        unload: true,
        bending: bending_tests.then(|| BendingPlan { noise: args.noise, ..BendingPlan::default() }),
        ..SynthPlan::new(&name, args.max_stretch)
    };
    if bending_tests {
        clean_plan.fabric.swatch.areal_density_kg_m2 = Some(SYNTH_AREAL_DENSITY_KG_M2);
    }
    let clean = synthesize(&truth, &clean_plan)?;
    let mean = |f: &dyn Fn(&yarnhom_calib::StretchPoint) -> f64| {
        clean.stretch.iter().map(|p| f(p).abs()).sum::<f64>() / clean.stretch.len() as f64
    };
    let plan = SynthPlan {
        force_noise_n: args.noise * mean(&|p| p.force_n),
        compression_noise: args.noise * mean(&|p| p.compression.unwrap_or(0.0)),
        seed: args.seed,
        ..clean_plan
    };
    let set = synthesize(&truth, &plan)?;
    set.write(&args.output)?;
    if let Some(path) = &args.truth {
        let truth_json = serde_json::json!({ "truth": truth, "effect": format!("{:?}", args.effect) });
        std::fs::write(path, serde_json::to_string_pretty(&truth_json)?)
            .with_context(|| format!("cannot write {}", path.display()))?;
    }
    eprintln!(
        "wrote {} ({} stretch, {} pear-loop and {} cantilever readings)",
        args.output.display(),
        set.stretch.len(),
        set.bending.len(),
        set.cantilever.len()
    );
    Ok(Outcome::Success)
}

fn pear_loop(args: PearLoopArgs) -> Result<Outcome> {
    let positive = |x: f64| x.is_finite() && x > 0.0;
    anyhow::ensure!(
        positive(args.length) && positive(args.spacing),
        "--length and --spacing must be positive lengths in metres"
    );
    anyhow::ensure!(positive(args.density), "--density must be a positive areal density in kg/m²");
    anyhow::ensure!(args.bending.iter().all(|k| positive(*k)), "--bending stiffnesses must be positive (J)");
    let per_direction = |values: &[f64], option: &str| match *values {
        [v] => Ok([v; 3]),
        [weft, bias, warp] => Ok([weft, bias, warp]),
        _ => Err(anyhow::anyhow!("{option} takes one value or three (weft,bias,warp)")),
    };
    let [k_weft, k_bias, k_warp] = per_direction(&args.bending, "--bending")?;
    let [rest_curvature_weft, rest_curvature_bias, rest_curvature_warp] =
        per_direction(&args.rest_curvature, "--rest-curvature")?;
    anyhow::ensure!(
        args.rest_curvature.iter().all(|k| k.is_finite()),
        "--rest-curvature must be finite (1/m)"
    );
    let bending = HingeBending {
        k_weft,
        k_bias,
        k_warp,
        rest_curvature_weft,
        rest_curvature_bias,
        rest_curvature_warp,
    };
    let membrane = match &args.membrane {
        Some(path) => {
            let text =
                std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
            let fit: ShellFit = serde_json::from_str(&text)
                .with_context(|| format!("{}: not a shell-fit.json", path.display()))?;
            fit.material
        }
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

fn model_name(model: MembraneModel) -> &'static str {
    match model {
        MembraneModel::Stvk => "anisotropic StVK",
        MembraneModel::StvkNeoHookean => "anisotropic StVK + Neo-Hookean (6.1)",
        MembraneModel::StvkNeoHookeanJamming => "anisotropic StVK + Neo-Hookean (6.1) + jamming",
    }
}

fn percent(x: Option<f64>) -> String {
    x.map_or("-".into(), |x| format!("{:.1}%", 100.0 * x))
}

/// The human summary: material, errors per direction, optimizer and mesh check.
fn summary(fit: &ShellFit) -> String {
    let m = &fit.material;
    let mut lines = vec![
        format!("fabric {}: {}", fit.fabric, model_name(fit.settings.model)),
        format!(
            "  k_xx {:.4} k_xy {:.4} k_yy {:.4} k_ss {:.4} k_n1 {:.4} k_n2 {:.4} (J/m²)",
            m.k_xx, m.k_xy, m.k_yy, m.k_ss, m.k_n1, m.k_n2
        ),
    ];
    if let Some(j) = m.jamming {
        lines.push(format!(
            "  jamming past compressive Green strain {:.4}: k_weft {:.4} k_warp {:.4} (J/m²)",
            j.onset, j.k_weft, j.k_warp
        ));
    }
    if !fit.unconstrained.is_empty() {
        lines.push(format!("  not constrained by the data (held): {}", fit.unconstrained.join(", ")));
    }
    lines.push(
        "  direction  force error  compression error  (the screening material, fitted to the uniform test)"
            .into(),
    );
    for ((d, f, c), (_, sf, sc)) in fit.errors.by_direction.iter().zip(&fit.screening_errors.by_direction) {
        lines.push(format!(
            "  {:<9}  {:>11}  {:>17}  ({} / {})",
            d.as_str(),
            percent(Some(*f)),
            percent(*c),
            percent(Some(*sf)),
            percent(*sc)
        ));
    }
    lines.push(format!(
        "  mean       {:>11}  {:>17}  (thesis Sec. 6.3.1 average over 33 fabrics: 17.6% / 16.8%)",
        percent(Some(fit.errors.force)),
        percent(fit.errors.compression)
    ));
    let refinement = fit.mesh_refinement_change.map_or("no equilibrium on the finer mesh".into(), |c| {
        format!("a mesh twice as fine changes a reading by {:.1}%", 100.0 * c)
    });
    lines.push(format!(
        "  {} Levenberg-Marquardt iterations, {} swatch simulations, {:.1} s; {} vertices per swatch; {refinement}",
        fit.optimizer.iterations, fit.optimizer.evaluations, fit.wall_time_s, fit.vertices,
    ));
    lines.extend(bending_summary(fit.bending.as_ref()));
    lines.join("\n")
}

/// The bending lines of the summary: stiffnesses and errors per direction, or why there are
/// none.
fn bending_summary(bending: Option<&ShellBending>) -> Vec<String> {
    let Some(bending) = bending else { return vec!["bending: no bending tests in the set".into()] };
    let Some(fit) = &bending.fit else {
        return vec![format!("bending: not fitted: {}", bending.note.as_deref().unwrap_or("unknown reason"))];
    };
    let b = &fit.bending;
    let mut lines = vec![
        format!(
            "bending (6.4): k_weft {:.3e} k_bias {:.3e} k_warp {:.3e} J ({} simulations of the {} tests)",
            b.k_weft,
            b.k_bias,
            b.k_warp,
            fit.evaluations,
            bending.tests.len()
        ),
        "  direction  pear-loop error  cantilever error".into(),
    ];
    for e in &fit.by_direction {
        lines.push(format!(
            "  {:<9}  {:>15}  {:>16}",
            e.direction.as_str(),
            percent(e.pear_loop),
            percent(e.cantilever)
        ));
    }
    lines.push(format!(
        "  all        {:>15}  (thesis Sec. 6.3.2 pear-loop average: 5.61%)",
        percent(Some(fit.error))
    ));
    lines
}
