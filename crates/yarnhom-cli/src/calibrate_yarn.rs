//! `yarnhom calibrate yarn`: yarn-level estimation from a measurement set (thesis Sec. 6.5).

use std::path::{Path, PathBuf};

use anyhow::Result;
use clap::Args;
use yarnhom_artifacts::open::open_artifact;
use yarnhom_artifacts::report::{Report, read_report, write_report};
use yarnhom_artifacts::{Pattern, Provenance, container};
use yarnhom_calib::data::set::{MeasurementSet, PatternSource};
use yarnhom_calib::optimize::swarm::SwarmSettings;
use yarnhom_calib::shell::fit::{ShellFit, ShellFitSettings, fit_shell};
use yarnhom_calib::yarn::fit::{best_start, fit_yarn};
use yarnhom_calib::yarn::params::YarnBasis;
use yarnhom_calib::yarn::problem::{RestShapeSettings, YarnFitEvent, YarnProblem};
use yarnhom_calib::yarn::settings::{LocalSolver, YarnFitSettings};

use yarnhom_calib::figures::yarn_fit_figure;
use yarnhom_figures::render_svg;

use crate::Outcome;
use crate::args::positive;
use crate::output::{create_dir, write_bytes};

#[derive(Debug, Args)]
pub struct YarnArgs {
    /// The measurement set directory. Its `pattern` is the input yarn geometry: a built-in
    /// generator name (for the set's `[stitch]`, else the default stitch) or a pattern file.
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
    pub local: LocalSolver,
    /// Evaluations of the local step at most (COBYLA) or Jacobians (LM, Gauss-Newton).
    #[arg(long, default_value_t = 60)]
    pub budget: u32,
    /// Seed of the swarm.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Run shard K of N independent sub-swarms (N times fewer particles, seed offset by K) and
    /// skip the local step; finish with `--start-from` on the shards' yarn-fit.json files.
    #[arg(long, value_parser = crate::args::parse_shard)]
    pub shard: Option<(u32, u32)>,
    /// Skip the swarm: start the local step from the best point of these yarn-fit.json files
    /// (e.g. the shards').
    #[arg(long, num_args = 1.., conflicts_with = "shard")]
    pub start_from: Vec<PathBuf>,
    /// Stiffness of the stiffest yarn, k_s2 (N); default: the largest `stiffness_n` of the set's
    /// `[[yarn]]` entries, or fitted when none has one.
    #[arg(long, value_parser = positive)]
    pub yarn_stiffness: Option<f64>,
    /// Rest-shape resets per evaluation (Sec. 6.5.2).
    #[arg(long, default_value_t = 8)]
    pub max_resets: u32,
}

impl YarnArgs {
    /// The fit's settings: a shard runs `1/N` of the particles with its own seed
    /// ([`SwarmSettings::shard`]) and no local step.
    fn settings(&self) -> YarnFitSettings {
        let swarm = SwarmSettings {
            particles: self.particles as usize,
            generations: self.generations as usize,
            seed: self.seed,
            ..SwarmSettings::default()
        };
        YarnFitSettings {
            swarm: self.shard.map_or(swarm, |(k, n)| swarm.shard(k, n)),
            swarm_targets: self.swarm_targets as usize,
            local_targets: self.local_targets as usize,
            local: if self.shard.is_some() { LocalSolver::None } else { self.local },
            local_budget: self.budget as usize,
            rest: RestShapeSettings { max_length_change: 0.2, max_resets: self.max_resets as usize },
            ..YarnFitSettings::default()
        }
    }
}

pub fn run(args: YarnArgs) -> Result<Outcome> {
    let set = MeasurementSet::read(&args.set)?;
    let pattern = set_pattern(&args.set, &set)?;
    create_dir(&args.output)?;
    let shell = match &args.shell_fit {
        Some(path) => read_report::<ShellFit>(path)?,
        None => {
            eprintln!("fitting the shell first ...");
            let fit = fit_shell(&set, &ShellFitSettings::default())?;
            write_report(&args.output.join("shell-fit.json"), &fit)?;
            fit
        }
    };
    let basis = YarnBasis::of_set(&set, &pattern, args.yarn_stiffness);
    let settings = args.settings();
    let problem = YarnProblem::from_shell_fit(pattern, basis, &shell, &set, &settings)?;
    let start = best_start(&args.start_from)?;
    eprintln!(
        "estimating the yarn model of {} on '{}' ({} vertices; R_est {:.3} mm; k_s2 {}) ...",
        set.fabric.name,
        problem.pattern.name,
        problem.pattern.vertex_count(),
        basis.r_est_m * 1e3,
        basis.k_s2_n.map_or("fitted".to_string(), |k| format!("{k} N")),
    );
    let fitted = fit_yarn(&problem, &set.fabric.name, &settings, start.as_deref(), &print_progress)?;
    write_report(&args.output.join("yarn-fit.json"), &fitted.fit)?;
    let from = Provenance::of("calibrate yarn", vec![MeasurementSet::input_ref(&args.set)?]);
    container::write(args.output.join("yarn.yarnmodel.yh"), &fitted.model, &from)?;
    container::write(args.output.join("rest.pattern.yh"), &fitted.rest_pattern, &from)?;
    write_bytes(&args.output.join("yarn-fit.svg"), render_svg(&yarn_fit_figure(&fitted.fit))?.as_bytes())?;
    println!("{}", fitted.fit.summary());
    eprintln!(
        "wrote yarn-fit.json, yarn.yarnmodel.yh, rest.pattern.yh and yarn-fit.svg to {}",
        args.output.display()
    );
    Ok(Outcome::Success)
}

/// Print a fit's progress.
pub(crate) fn print_progress(event: YarnFitEvent) {
    match event {
        YarnFitEvent::Generation(g, best) => eprintln!("  swarm generation {g}: best g = {best:.5}"),
        YarnFitEvent::LocalEvaluation(n, cost) => eprintln!("  local evaluation {n}: g = {cost:.5}"),
    }
}

/// The input geometry of the set in `set_dir`: its pattern file, read like any input, or its
/// built-in generator for its stitch ([`yarnhom_calib::data::set::Fabric::pattern_source`]).
pub(crate) fn set_pattern(set_dir: &Path, set: &MeasurementSet) -> Result<Pattern> {
    Ok(match set.fabric.pattern_source(set_dir)? {
        PatternSource::File(path) => open_artifact::<Pattern>(&path)?.value,
        PatternSource::Generator(generator) => generator.generate()?,
    })
}
