//! `yarnhom rve ...`: the periodic yarn tile (thesis Ch. 3).

use std::path::PathBuf;
use std::time::Instant;

use anyhow::Context;
use clap::{Args, Subcommand};
use yarnhom_artifacts::open::{base_name, open_pattern_and_model};
use yarnhom_geom::MacroStrain;
use yarnhom_rve::homogenize::{Outputs, solve_to_artifact};
use yarnhom_rve::messages::record_iterate;
use yarnhom_rve::relax::RelaxEvent;
use yarnhom_rve::{Iterate, RelaxMethod, RelaxOptions, RveModel, SolveOptions, StepControl};
use yarnhom_trace::TraceMetadata;

use crate::Outcome;
use crate::output::{finish_trace, open_trace, print_summary, write_artifact, wrote};

#[derive(Debug, Subcommand)]
pub enum RveCommand {
    /// Solve the tile's elastostatic equilibrium under a macro strain and report the homogenized
    /// energy density (3.22) and stress (3.23c; `--fd-stress` adds the finite-difference check).
    ///
    /// The pattern needs a rest state (the published `.pyp` patterns have one). Exit status 0
    /// when the solve converged, 1 when it did not (the artifact is written anyway and says so,
    /// with no energy), 2 on bad input.
    Solve(SolveArgs),
    /// Compute a pattern's rest state: Algorithm 2 of the thesis (stress-free state, pre-tension,
    /// in-plane energy minimum), or the rest-shape estimation of Sec. 6.5.2 (`--estimation`).
    ///
    /// The result is a pattern whose tile carries no in-plane stress at zero strain (Algorithm 2)
    /// or whose rest lengths stay within the given bound of the input (Sec. 6.5.2). Works on
    /// generated patterns (no rest state yet) and on imported ones. Exit status 0 on success,
    /// 2 when a stage fails (the message names the stage).
    Relax(RelaxArgs),
    /// Sample the homogenized energy (and stress) over the plan of App. A.3.1 into a `grid`
    /// artifact: five 1D terms of N1D samples and nine 2D terms of N2D x N2D (all pairs of
    /// sx, sa, sy, kx, ky but kx-ky), each term over its own ranges (Alg. 6; default the
    /// published stockinette's: 1D sx, sy -0.52..0.78, sa ±0.75, kx ±200, ky ±230 1/m; in the
    /// planes sx, sy -0.1..0.67 (-0.37..0.8 in sx,sy), sa ±0.6, kx ±144..160, ky ±166..184),
    /// non-uniformly spaced, each sweep line warm-started outward from zero strain, lines in
    /// parallel on all cores (RAYON_NUM_THREADS to limit).
    ///
    /// Resumable: every finished line is appended to OUTPUT.checkpoint, and a rerun with the
    /// same arguments continues from it. `--shard K/N` computes one of N disjoint sets of lines
    /// (for a Slurm job array or a Kubernetes Indexed Job: tools/slurm-sample.sh,
    /// tools/k8s-sample.yaml); `yarnhom grid merge` joins the shards bit-identically.
    Sample(crate::sample::SampleArgs),
    /// Measure how far the pattern's stored state is from an equilibrium of the yarn model: the
    /// forces of stretching, of bending and twisting, and of contact at the pattern's own
    /// geometry (its periods, zero strain), projected on the solver's constraints, and the
    /// contact scale that would balance them best.
    ///
    /// A published rest state is an equilibrium of the code that made it; a large residual
    /// means the two models differ, and the contact scale says by how much their contact does.
    /// (The published HYLC patterns, pooled, gave the factor between Table 4.1's `k_contact`
    /// and this model's Kaldor integral.) Exit status 0, 2 on bad input.
    Residual(ResidualArgs),
}

#[derive(Debug, Args)]
pub struct ResidualArgs {
    /// The pattern, with a rest state (`.yh`, JSON, HDF5 or `.pyp`).
    pub pattern: PathBuf,
    /// Yarn model: a built-in `table4.1:<row>` (see `yarnhom model list`) or a `yarnmodel` file.
    #[arg(long)]
    pub model: String,
}

#[derive(Debug, Args)]
pub struct RelaxArgs {
    /// The pattern (`.yh`, JSON, HDF5 or `.pyp`).
    pub pattern: PathBuf,
    /// Yarn model: a built-in `table4.1:<row>` (see `yarnhom model list`) or a `yarnmodel` file.
    #[arg(long)]
    pub model: String,
    /// Sec. 6.5.2 instead of Algorithm 2: rest-shape resets with rest lengths bounded to the
    /// given relative change of their input values (the thesis uses 0.2), no pre-tension and
    /// no period change.
    #[arg(long, value_name = "MAX_LENGTH_CHANGE")]
    pub estimation: Option<f64>,
    /// Keep the input's rest shape and only move the periods to the in-plane energy minimum
    /// (Algorithm 2's last stage), e.g. for published patterns relaxed by another code.
    #[arg(long, conflicts_with = "estimation")]
    pub keep_rest_shape: bool,
    /// Largest number of rest-shape resets.
    #[arg(long, default_value_t = 40)]
    pub max_resets: usize,
    /// Output file (default: PATTERN.relaxed.pattern.yh, PATTERN the input's base name).
    #[arg(short, long)]
    pub output: Option<PathBuf>,
}

#[derive(Debug, Args)]
pub struct SolveArgs {
    /// The pattern (`.yh`, JSON, HDF5 or `.pyp`).
    pub pattern: PathBuf,
    /// Yarn model: a built-in `table4.1:<row>` (see `yarnhom model list`) or a `yarnmodel` file.
    #[arg(long)]
    pub model: String,
    /// Macro strain `sx=..,sa=..,sy=..,kx=..,ky=..` (omitted ones are 0): stretches along X1, X2
    /// (`> -1`), shear `sa` (the cosine of the deformed axes' angle, `|sa| < 1`), curvatures (1/m).
    #[arg(long, allow_hyphen_values = true)]
    pub strain: String,
    /// Skip the homogenized stress.
    #[arg(long, conflicts_with = "fd_stress")]
    pub no_stress: bool,
    /// Also compute the stress by central differences of ten warm-started solves, the check of
    /// the equilibrium stress (3.23c).
    #[arg(long)]
    pub fd_stress: bool,
    /// Newton iteration limit.
    #[arg(long, default_value_t = 2000)]
    pub max_iterations: usize,
    /// Keep steps collision-safe by additive continuous collision detection (Li et al. 2021)
    /// with this smallest centreline distance in yarn radii, instead of the step limit of A.2.3.
    #[arg(long, value_name = "MIN_SEPARATION_RADII")]
    pub ccd: Option<f64>,
    /// Record every Newton iteration into an MCAP trace (`-`: stdout): the tile's yarns
    /// (`/yarn/frame`, frame = iteration) with energy, residual and step length
    /// (`/solver/iteration`).
    #[arg(long, value_name = "TRACE")]
    pub trace: Option<String>,
    /// Output file (default: PATTERN.rvesolve.yh, PATTERN the input's base name).
    #[arg(short, long)]
    pub output: Option<PathBuf>,
}

pub fn run(cmd: RveCommand) -> anyhow::Result<Outcome> {
    match cmd {
        RveCommand::Solve(args) => solve(args),
        RveCommand::Relax(args) => relax(args),
        RveCommand::Sample(args) => crate::sample::run(args),
        RveCommand::Residual(args) => residual(args),
    }
}

/// `--ccd D` as a step control, or the step limit of A.2.3.
fn step_control(ccd: Option<f64>) -> anyhow::Result<StepControl> {
    match ccd {
        Some(d) if !(d > 0.0 && d < 2.0) => {
            anyhow::bail!("--ccd {d}: the separation must lie strictly between 0 and 2 yarn radii")
        }
        Some(min_separation_radii) => Ok(StepControl::AdditiveCcd { min_separation_radii }),
        None => Ok(StepControl::StepLimit),
    }
}

fn solve(args: SolveArgs) -> anyhow::Result<Outcome> {
    let strain: MacroStrain = args.strain.parse()?;
    let (pattern, model, inputs) = open_pattern_and_model(&args.pattern, &args.model)?;
    let tile = RveModel::new(&pattern, &model).with_context(|| format!("{}", args.pattern.display()))?;
    let options = SolveOptions {
        max_iterations: args.max_iterations,
        step_control: step_control(args.ccd)?,
        ..SolveOptions::default()
    };
    eprintln!(
        "solving '{}' ({} vertices) with '{}' at {}",
        pattern.name,
        pattern.vertex_count(),
        model.name,
        args.strain
    );
    let metadata = TraceMetadata::new("yarnhom rve solve", env!("CARGO_PKG_VERSION"))
        .with_entry("pattern", args.pattern.display().to_string())
        .with_entry("model", &args.model)
        .with_entry("strain", &args.strain);
    let mut trace = args.trace.as_deref().map(|path| open_trace(path, &metadata)).transpose()?;
    let placement = yarnhom_rve::homogenize::placement(&tile, &strain);
    let mut trace_error = None;
    let mut record = |iterate: &Iterate<'_>| {
        if let Some(sink) = trace.as_mut().filter(|_| trace_error.is_none()) {
            trace_error = record_iterate(sink, &pattern, &tile, &placement, iterate).err();
        }
    };
    let outputs = Outputs { stress: !args.no_stress, fd_stress: args.fd_stress };
    let result =
        solve_to_artifact(&tile, [&pattern.name, &model.name], &strain, &options, outputs, &mut record);
    if let Some(err) = trace_error {
        return Err(anyhow::Error::new(err).context("cannot write the trace"));
    }
    finish_trace(trace, args.trace.as_deref())?;
    let output = args.output.unwrap_or_else(|| format!("{}.rvesolve.yh", base_name(&args.pattern)).into());
    write_artifact(&output, &result, "rve solve", inputs)?;
    print_summary(&result.summary(), args.trace.as_deref());
    wrote(&output);
    if result.converged {
        Ok(Outcome::Success)
    } else {
        eprintln!("error: the solve did not converge ({})", result.stop_reason);
        Ok(Outcome::Different)
    }
}

fn residual(args: ResidualArgs) -> anyhow::Result<Outcome> {
    let (pattern, model, _) = open_pattern_and_model(&args.pattern, &args.model)?;
    let r = yarnhom_rve::residual::equilibrium_residual(&pattern, &model)?;
    println!(
        "forces at the stored state of '{}' under '{}' (projected on the constraints):",
        pattern.name, model.name
    );
    println!("{}", r.report());
    Ok(Outcome::Success)
}

fn relax(args: RelaxArgs) -> anyhow::Result<Outcome> {
    let (pattern, model, inputs) = open_pattern_and_model(&args.pattern, &args.model)?;
    if args.keep_rest_shape && pattern.rest.is_none() {
        anyhow::bail!(
            "{}: --keep-rest-shape needs a pattern with a rest state, and '{}' has none",
            args.pattern.display(),
            pattern.name
        );
    }
    let options = RelaxOptions {
        method: relax_method(args.estimation)?,
        keep_rest_shape: args.keep_rest_shape,
        max_resets: args.max_resets,
        ..RelaxOptions::default()
    };
    eprintln!("relaxing '{}' ({} vertices) with '{}'", pattern.name, pattern.vertex_count(), model.name);
    let started = Instant::now();
    let mut show = |event: RelaxEvent| eprintln!("  {event} ({:.1} s)", started.elapsed().as_secs_f64());
    let (relaxed, report) = yarnhom_rve::relax(&pattern, &model, &options, &mut show)
        .with_context(|| format!("{}", args.pattern.display()))?;
    if !args.keep_rest_shape && report.stress_free_energy_j >= options.stress_free_energy_j {
        eprintln!(
            "warning: no stress-free state within {} resets (tile energy {:.3e} J, target {:.0e} J); continuing",
            report.resets, report.stress_free_energy_j, options.stress_free_energy_j
        );
    }
    let output =
        args.output.unwrap_or_else(|| format!("{}.relaxed.pattern.yh", base_name(&args.pattern)).into());
    write_artifact(&output, &relaxed, "rve relax", inputs)?;
    println!("{}", report.summary(&relaxed, started.elapsed().as_secs_f64()));
    wrote(&output);
    Ok(Outcome::Success)
}

/// Algorithm 2, or the Sec. 6.5.2 estimation with `--estimation BOUND`.
fn relax_method(estimation: Option<f64>) -> anyhow::Result<RelaxMethod> {
    match estimation {
        Some(bound) if !(bound > 0.0 && bound < 1.0) => {
            anyhow::bail!("--estimation {bound}: the rest-length bound must lie strictly between 0 and 1")
        }
        Some(max_length_change) => Ok(RelaxMethod::Estimation { max_length_change }),
        None => Ok(RelaxMethod::Reference),
    }
}
