//! `yarnhom calibrate ...`: fitting models to measured fabric (thesis Ch. 6).

use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::{Args, Subcommand, ValueEnum};
use plotters::prelude::*;
use yarnhom_calib::measure::{Direction, MeasurementSet, Phase};
use yarnhom_calib::shell_fit::{MembraneModel, ShellFit, ShellFitSettings, fit_shell};
use yarnhom_calib::targets::TargetPlan;

use crate::Outcome;
use crate::fit_plot::{FONT, format_value, plot_error, render};

#[derive(Debug, Subcommand)]
pub enum CalibrateCommand {
    /// Fit the Ch. 6 membrane (anisotropic StVK + Neo-Hookean, (6.1)) to a measurement set's
    /// stretch tests by simulating the clamped swatch to equilibrium at each target (6.2);
    /// write OUT/shell-fit.json (material, errors, uniform targets (6.3)) and
    /// OUT/shell-fit.svg (Fig. 6.6: force and compression vs stretch per direction).
    Shell(ShellArgs),
}

#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum ModelArg {
    /// Plain anisotropic StVK.
    Stvk,
    /// StVK with the Neo-Hookean area terms (6.1).
    StvkNeoHookean,
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
    std::fs::write(&svg, plot_shell_fit(&set, &fit)?)
        .with_context(|| format!("cannot write {}", svg.display()))?;
    println!("{}", summary(&fit));
    eprintln!("wrote {} and {}", json.display(), svg.display());
    Ok(Outcome::Success)
}

fn model_name(model: MembraneModel) -> &'static str {
    match model {
        MembraneModel::Stvk => "anisotropic StVK",
        MembraneModel::StvkNeoHookean => "anisotropic StVK + Neo-Hookean (6.1)",
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
    lines.push(format!(
        "  {} Levenberg-Marquardt iterations, {} swatch simulations, {:.1} s; {} vertices per swatch; \
         a mesh twice as fine changes a reading by {:.1}%",
        fit.optimizer.iterations,
        fit.optimizer.evaluations,
        fit.wall_time_s,
        fit.vertices,
        100.0 * fit.mesh_refinement_change
    ));
    lines.join("\n")
}

const MEASURED: RGBColor = RGBColor(0xB0, 0xB8, 0xC8);
const TARGET: RGBColor = RGBColor(0x1F, 0x5F, 0xD0);
const FITTED: RGBColor = RGBColor(0xC0, 0x30, 0x30);
const UNIFORM: RGBColor = RGBColor(0x1A, 0x9A, 0x3A);

/// Fig. 6.6: per direction a column, force vs stretch on top and compression vs stretch below;
/// raw loading readings (grey), targets (blue), the clamped-swatch fit (red), the uniform test
/// of the fitted material (green, (6.3)).
fn plot_shell_fit(set: &MeasurementSet, fit: &ShellFit) -> Result<String> {
    let directions: Vec<Direction> = fit.errors.by_direction.iter().map(|e| e.0).collect();
    let size = (420 * directions.len() as u32, 760);
    render(size, |root| {
        let columns = root.split_evenly((2, directions.len()));
        for (k, &direction) in directions.iter().enumerate() {
            let specimen = set.fabric.swatch.specimen(direction);
            let targets: Vec<_> =
                fit.targets.iter().enumerate().filter(|(_, t)| t.direction == direction).collect();
            let s_max = targets.iter().map(|(_, t)| t.stretch).fold(0.0, f64::max) * 1.05;
            let readings: Vec<_> = set
                .stretch
                .iter()
                .filter(|p| p.direction == direction && p.phase == Phase::Load && p.stretch <= s_max)
                .collect();
            let thin = (readings.len() / 1500).max(1);
            let uniform: Vec<_> =
                fit.uniform_targets.iter().filter(|u| u.direction == direction).map(|u| u.point).collect();
            for (row, is_force) in [(0, true), (1, false)] {
                let area = &columns[row * directions.len() + k];
                let value =
                    |force: f64, compression: Option<f64>| if is_force { Some(force) } else { compression };
                let raw: Vec<(f64, f64)> = readings
                    .iter()
                    .step_by(thin)
                    .filter_map(|p| value(p.force_n, p.compression).map(|v| (p.stretch, v)))
                    .collect();
                let measured: Vec<(f64, f64)> = targets
                    .iter()
                    .filter_map(|(_, t)| value(t.force_n, t.compression).map(|v| (t.stretch, v)))
                    .collect();
                let simulated: Vec<(f64, f64)> = targets
                    .iter()
                    .map(|(i, t)| {
                        let r = fit.simulated[*i];
                        (t.stretch, if is_force { r.force_n } else { r.compression })
                    })
                    .collect();
                let line: Vec<(f64, f64)> = std::iter::once((0.0, 0.0))
                    .chain(uniform.iter().map(|u| {
                        (u.stretch, if is_force { u.stress_n_m * specimen.width_m } else { u.compression })
                    }))
                    .collect();
                let ys = raw.iter().chain(&measured).chain(&simulated).chain(&line).map(|p| p.1);
                let (lo, hi) = ys.fold((0.0_f64, 0.0_f64), |(a, b), y| (a.min(y), b.max(y)));
                let pad = 0.05 * (hi - lo).max(1e-9);
                let quantity = if is_force { "force (N)" } else { "compression" };
                let mut chart = ChartBuilder::on(area)
                    .caption(format!("{} {direction}: {quantity}", fit.fabric), (FONT, 16))
                    .margin(10)
                    .x_label_area_size(40)
                    .y_label_area_size(55)
                    .build_cartesian_2d(0.0..s_max.max(1e-6), (lo - pad)..(hi + pad))
                    .map_err(plot_error)?;
                chart
                    .configure_mesh()
                    .x_desc("stretch")
                    .y_desc(quantity)
                    .label_style((FONT, 12))
                    .x_label_formatter(&|x| format_value(*x))
                    .y_label_formatter(&|y| format_value(*y))
                    .light_line_style(WHITE.mix(0.0))
                    .draw()
                    .map_err(plot_error)?;
                chart
                    .draw_series(raw.iter().map(|&p| Circle::new(p, 1, MEASURED.filled())))
                    .map_err(plot_error)?
                    .label("readings (load)")
                    .legend(|p| Circle::new(p, 2, MEASURED.filled()));
                chart
                    .draw_series(LineSeries::new(line.iter().copied(), UNIFORM.stroke_width(2)))
                    .map_err(plot_error)?
                    .label("uniform test (6.3)")
                    .legend(|(x, y)| PathElement::new(vec![(x - 8, y), (x + 8, y)], UNIFORM.stroke_width(2)));
                chart
                    .draw_series(measured.iter().map(|&p| Circle::new(p, 4, TARGET.filled())))
                    .map_err(plot_error)?
                    .label("targets")
                    .legend(|p| Circle::new(p, 4, TARGET.filled()));
                chart
                    .draw_series(simulated.iter().map(|&p| Cross::new(p, 5, FITTED.stroke_width(2))))
                    .map_err(plot_error)?
                    .label("clamped swatch, fitted")
                    .legend(|p| Cross::new(p, 5, FITTED.stroke_width(2)));
                chart
                    .configure_series_labels()
                    .position(SeriesLabelPosition::UpperLeft)
                    .background_style(WHITE.mix(0.85))
                    .border_style(BLACK.mix(0.5))
                    .label_font((FONT, 12))
                    .draw()
                    .map_err(plot_error)?;
            }
        }
        Ok(())
    })
}
