//! `yarnhom calibrate yarn`: yarn-level estimation from a measurement set (thesis Sec. 6.5).

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use clap::{Args, ValueEnum};
use yarnhom_artifacts::{InputRef, Pattern, Provenance, container};
use yarnhom_calib::figures::yarn_fit_figure;
use yarnhom_calib::measure::MeasurementSet;
use yarnhom_calib::shell_fit::{ShellFit, ShellFitSettings, fit_shell};
use yarnhom_calib::swarm::SwarmSettings;
use yarnhom_calib::yarn_fit::{
    LocalSolver, RestShapeSettings, YarnFit, YarnFitEvent, YarnFitSettings, YarnProblem, fit_yarn,
};
use yarnhom_calib::yarn_params::YarnBasis;
use yarnhom_figures::render_svg;

use crate::Outcome;

#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum LocalArg {
    /// COBYLA (derivative-free), as the thesis.
    Cobyla,
    /// Levenberg-Marquardt on the residuals of (6.11), forward-difference Jacobian.
    Lm,
    /// Gauss-Newton / Levenberg-Marquardt with the Jacobian from the parameter sensitivities of
    /// the tile's equilibrium (one evaluation per Jacobian instead of one per parameter).
    GaussNewton,
    /// No local step.
    None,
}

#[derive(Debug, Args)]
pub struct YarnArgs {
    /// The measurement set directory. Its `pattern` is the input yarn geometry: a built-in
    /// generator name (default stitch size) or a pattern file (relative to the set).
    pub set: PathBuf,
    /// Output directory (created).
    #[arg(short, long)]
    pub output: PathBuf,
    /// A `shell-fit.json` of `calibrate shell` for this set (default: fit the shell first and
    /// write OUT/shell-fit.json).
    #[arg(long)]
    pub shell_fit: Option<PathBuf>,
    /// Swarm particles (thesis: 64).
    #[arg(long, default_value_t = 64, value_parser = clap::value_parser!(u32).range(1..))]
    pub particles: u32,
    /// Swarm generations (thesis: 10).
    #[arg(long, default_value_t = 10)]
    pub generations: u32,
    /// Targets per direction during the swarm (thesis: 7).
    #[arg(long, default_value_t = 7, value_parser = clap::value_parser!(u32).range(2..=100))]
    pub swarm_targets: u32,
    /// Targets per direction during the local step and for the errors (thesis: 20).
    #[arg(long, default_value_t = 20, value_parser = clap::value_parser!(u32).range(2..=100))]
    pub local_targets: u32,
    /// The local optimizer.
    #[arg(long, value_enum, default_value = "cobyla")]
    pub local: LocalArg,
    /// Evaluations of the local step at most (COBYLA) or Jacobians (LM, Gauss-Newton).
    #[arg(long, default_value_t = 60)]
    pub budget: u32,
    /// Seed of the swarm.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Run shard K of N independent sub-swarms (N times fewer particles, seed offset by K) and
    /// skip the local step; finish with `--start-from` on the shards' yarn-fit.json files.
    #[arg(long, value_parser = parse_shard)]
    pub shard: Option<(u32, u32)>,
    /// Skip the swarm: start the local step from the best point of these yarn-fit.json files
    /// (e.g. the shards').
    #[arg(long, num_args = 1.., conflicts_with = "shard")]
    pub start_from: Vec<PathBuf>,
    /// Stiffness of the stiffest yarn, k_s2 (N); default: the largest `stiffness_n` of the set's
    /// `[[yarn]]` entries, or fitted when none has one.
    #[arg(long)]
    pub yarn_stiffness: Option<f64>,
    /// Rest-shape resets per evaluation (Sec. 6.5.2).
    #[arg(long, default_value_t = 8)]
    pub max_resets: u32,
}

fn parse_shard(text: &str) -> Result<(u32, u32), String> {
    let (k, n) = text.split_once('/').ok_or("expected K/N, e.g. 0/4")?;
    let (k, n): (u32, u32) =
        (k.parse().map_err(|_| "K is not a number")?, n.parse().map_err(|_| "N is not a number")?);
    if n == 0 || k >= n {
        return Err(format!("shard {k}/{n}: need 0 <= K < N"));
    }
    Ok((k, n))
}

/// Fibre density used when the set gives no linear density (kg/m³); statics do not use it.
const DEFAULT_DENSITY_KG_M3: f64 = 1000.0;

pub fn run(args: YarnArgs) -> Result<Outcome> {
    if let Some(k) = args.yarn_stiffness {
        anyhow::ensure!(k.is_finite() && k > 0.0, "--yarn-stiffness must be a positive force in newtons");
    }
    let set = MeasurementSet::read(&args.set)?;
    let pattern = set_pattern(&args.set, &set.fabric.pattern)?;
    std::fs::create_dir_all(&args.output)
        .with_context(|| format!("cannot create {}", args.output.display()))?;
    let shell = match &args.shell_fit {
        Some(path) => read_json::<ShellFit>(path)?,
        None => {
            eprintln!("fitting the shell first ...");
            let fit = fit_shell(&set, &ShellFitSettings::default())?;
            write_json(&args.output.join("shell-fit.json"), &fit)?;
            fit
        }
    };
    let basis = set_basis(&set, &pattern, args.yarn_stiffness);
    let k_s2 = basis.k_s2_n;
    let (particles, seed) = match args.shard {
        Some((k, n)) => ((args.particles / n).max(1) as usize, args.seed.wrapping_add(u64::from(k) * 7919)),
        None => (args.particles as usize, args.seed),
    };
    let settings = YarnFitSettings {
        swarm: SwarmSettings {
            particles,
            generations: args.generations as usize,
            seed,
            ..SwarmSettings::default()
        },
        swarm_targets: args.swarm_targets as usize,
        local_targets: args.local_targets as usize,
        local: match (args.shard, args.local) {
            (Some(_), _) | (None, LocalArg::None) => LocalSolver::None,
            (None, LocalArg::Cobyla) => LocalSolver::Cobyla,
            (None, LocalArg::Lm) => LocalSolver::LevenbergMarquardt,
            (None, LocalArg::GaussNewton) => LocalSolver::GaussNewton,
        },
        local_budget: args.budget as usize,
        rest: RestShapeSettings { max_length_change: 0.2, max_resets: args.max_resets as usize },
        ..YarnFitSettings::default()
    };
    let problem = YarnProblem::from_shell_fit(pattern, basis, &shell, &set, &settings)?;
    let start = best_start(&args.start_from)?;
    eprintln!(
        "estimating the yarn model of {} on '{}' ({} vertices; R_est {:.3} mm; k_s2 {}) ...",
        set.fabric.name,
        problem.pattern.name,
        problem.pattern.vertex_count(),
        basis.r_est_m * 1e3,
        k_s2.map_or("fitted".to_string(), |k| format!("{k} N")),
    );
    let progress = |event: YarnFitEvent| match event {
        YarnFitEvent::Generation(g, best) => eprintln!("  swarm generation {g}: best g = {best:.5}"),
        YarnFitEvent::LocalEvaluation(n, cost) => eprintln!("  local evaluation {n}: g = {cost:.5}"),
    };
    let fitted = fit_yarn(&problem, &set.fabric.name, &settings, start.as_deref(), &progress)?;
    write_json(&args.output.join("yarn-fit.json"), &fitted.fit)?;
    let from = vec![set_input(&args.set)?];
    container::write(
        args.output.join("yarn.yarnmodel.yh"),
        &fitted.model,
        &Provenance::of("calibrate yarn", from.clone()),
    )?;
    container::write(
        args.output.join("rest.pattern.yh"),
        &fitted.rest_pattern,
        &Provenance::of("calibrate yarn", from),
    )?;
    std::fs::write(args.output.join("yarn-fit.svg"), render_svg(&yarn_fit_figure(&fitted.fit))?)
        .with_context(|| format!("cannot write {}", args.output.join("yarn-fit.svg").display()))?;
    println!("{}", summary(&fitted.fit));
    eprintln!(
        "wrote yarn-fit.json, yarn.yarnmodel.yh, rest.pattern.yh and yarn-fit.svg to {}",
        args.output.display()
    );
    Ok(Outcome::Success)
}

/// The fixed quantities of a yarn-level fit of `set` on `pattern`: `k_s2` is `yarn_stiffness`,
/// else the stiffest of the set's yarns, else fitted; the density from the yarns' linear density.
pub(crate) fn set_basis(set: &MeasurementSet, pattern: &Pattern, yarn_stiffness: Option<f64>) -> YarnBasis {
    let k_s2 =
        yarn_stiffness.or_else(|| set.fabric.yarn.iter().filter_map(|y| y.stiffness_n).reduce(f64::max));
    let radius = pattern.radius_range_m().0;
    let tex = set.fabric.yarn.iter().find_map(|y| y.linear_density_tex);
    let density = tex.map_or(DEFAULT_DENSITY_KG_M3, |t| t * 1e-6 / (std::f64::consts::PI * radius * radius));
    YarnBasis::of_pattern(pattern, k_s2, density)
}

/// The set's input geometry: a pattern file (relative to the set directory, or as given) or a
/// built-in generator at its default stitch size.
pub(crate) fn set_pattern(set_dir: &Path, spec: &str) -> Result<Pattern> {
    let candidates = [set_dir.join(spec), PathBuf::from(spec)];
    if let Some(path) = candidates.iter().find(|p| p.is_file()) {
        return Ok(yarnhom_artifacts::open::open_artifact::<Pattern>(path)?.value);
    }
    let params = yarnhom_pattern::GeneratorParams::defaults_for(spec).with_context(|| {
        format!("pattern '{spec}' of {}: neither a file nor a generator", set_dir.display())
    })?;
    Ok(yarnhom_pattern::generate(spec, &params)?)
}

/// The measurement set as a provenance input: the hash of its `fabric.toml` and `stretch.csv`.
fn set_input(dir: &Path) -> Result<InputRef> {
    let mut bytes = Vec::new();
    for name in ["fabric.toml", "stretch.csv"] {
        let path = dir.join(name);
        bytes.extend(std::fs::read(&path).with_context(|| format!("cannot read {}", path.display()))?);
    }
    Ok(InputRef {
        kind: "measurement-set".into(),
        content_hash: container::content_hash(&bytes),
        path: dir.display().to_string(),
    })
}

/// The best search point among earlier fits (lowest cost), if any are given.
fn best_start(paths: &[PathBuf]) -> Result<Option<Vec<f64>>> {
    let mut best: Option<YarnFit> = None;
    for path in paths {
        let fit: YarnFit = read_json(path)?;
        if best.as_ref().is_none_or(|b| fit.cost < b.cost) {
            best = Some(fit);
        }
    }
    Ok(best.map(|b| b.coordinates))
}

fn read_json<T: serde::de::DeserializeOwned>(path: &Path) -> Result<T> {
    let text = std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
    serde_json::from_str(&text).with_context(|| format!("{}: not a valid file of its kind", path.display()))
}

fn write_json<T: serde::Serialize>(path: &Path, value: &T) -> Result<()> {
    std::fs::write(path, serde_json::to_string_pretty(value)?)
        .with_context(|| format!("cannot write {}", path.display()))
}

/// The errors table and the estimated parameters.
fn summary(fit: &YarnFit) -> String {
    let p = &fit.params;
    let mut lines = vec![
        format!(
            "yarn model of {} ({}), g = {:.5}, {:.1} s",
            fit.fabric, fit.pattern, fit.cost, fit.wall_time_s
        ),
        format!(
            "  k_s1 {:.4} N, k_s2 {:.4} N, eps_bar {:.4}, k_b {:.3e} N m², R_1 {:.4} mm, k_c1 {:.3e} N/m (R_2 {:.4} mm, k_c2 {:.3e} N/m)",
            p.k_s1_n,
            p.k_s2_n,
            p.eps_bar,
            p.k_b_nm2,
            p.r1_m * 1e3,
            p.k_c1_n_m,
            p.r2_m * 1e3,
            p.k_c2_n_m
        ),
        "  direction  comfort stress  power stress  compression".into(),
    ];
    for e in &fit.errors {
        lines.push(format!(
            "  {:<9}  {:>13.1}%  {:>12}  {:>10.1}%",
            e.direction.as_str(),
            100.0 * e.comfort_stress,
            e.power_stress.map_or("-".into(), |x| format!("{:.1}%", 100.0 * x)),
            100.0 * e.compression
        ));
    }
    if let Some(s) = &fit.swarm {
        lines.push(format!(
            "  swarm: {} evaluations ({} failed), best g = {:.5}",
            s.evaluations, s.failures, s.best_cost
        ));
    }
    if let Some(l) = &fit.local {
        lines.push(format!(
            "  local ({:?}): g {:.5} -> {:.5} in {} evaluations, {:.1} s ({})",
            l.solver, l.start_cost, l.cost, l.evaluations, l.wall_time_s, l.stop
        ));
    }
    lines.join("\n")
}
