//! `yarnhom rve ...`: the periodic yarn tile (thesis Ch. 3).

use std::path::PathBuf;
use std::time::Instant;

use anyhow::Context;
use clap::{Args, Subcommand};
use yarnhom_artifacts::{AnyArtifact, RveSolve, StrainSample, YarnModel, container};
use yarnhom_geom::MacroStrain;
use yarnhom_rve::homogenize::{solve_at_observed, stress_at_equilibrium, stress_by_finite_differences};
use yarnhom_rve::relax::RelaxEvent;
use yarnhom_rve::{Iterate, RelaxMethod, RelaxOptions, RveModel, SolveOptions, StepControl, StopReason};
use yarnhom_trace::{SolverIteration, TraceMetadata};

use crate::Outcome;
use crate::inputs::{self, base_name, provenance};
use crate::trace_out::{TraceSink, is_stdout, yarn_frame};

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

/// A built-in `table4.1:<row>` model or a `yarnmodel` file.
fn load_model(spec: &str) -> anyhow::Result<(YarnModel, Option<yarnhom_artifacts::InputRef>)> {
    if let Some(row) = spec.strip_prefix("table4.1:") {
        return Ok((crate::model::builtin(row)?, None));
    }
    let loaded = inputs::load(std::path::Path::new(spec), None)?;
    let input = yarnhom_artifacts::InputRef {
        kind: "yarnmodel".into(),
        content_hash: loaded.header.content_hash.clone(),
        path: spec.into(),
    };
    match loaded.artifact {
        AnyArtifact::YarnModel(m) => Ok((m, Some(input))),
        other => anyhow::bail!("{spec}: holds a '{}', not a yarnmodel", other.kind()),
    }
}

/// The pattern and yarn model a tile command works on, and the inputs they name in provenance.
pub(crate) fn load_pattern_and_model(
    path: &std::path::Path,
    model_spec: &str,
) -> anyhow::Result<(yarnhom_artifacts::Pattern, YarnModel, Vec<yarnhom_artifacts::InputRef>)> {
    let (pattern, input) = inputs::load_pattern(path)?;
    let (model, model_input) = load_model(model_spec)?;
    Ok((pattern, model, std::iter::once(input).chain(model_input).collect()))
}

pub(crate) fn stop_reason(reason: StopReason) -> &'static str {
    match reason {
        StopReason::Converged => "converged",
        StopReason::IterationLimit => "iteration_limit",
        StopReason::LineSearchFailed => "line_search_failed",
        StopReason::FactorizationFailed => "factorization_failed",
    }
}

fn solve(args: SolveArgs) -> anyhow::Result<Outcome> {
    let strain: MacroStrain = args.strain.parse()?;
    let (pattern, model, inputs_list) = load_pattern_and_model(&args.pattern, &args.model)?;
    let pattern = &pattern;
    let tile = RveModel::new(pattern, &model).with_context(|| format!("{}", args.pattern.display()))?;
    let step_control = match args.ccd {
        Some(d) if !(d > 0.0 && d < 2.0) => {
            anyhow::bail!("--ccd {d}: the separation must lie strictly between 0 and 2 yarn radii")
        }
        Some(min_separation_radii) => StepControl::AdditiveCcd { min_separation_radii },
        None => StepControl::StepLimit,
    };
    let options =
        SolveOptions { max_iterations: args.max_iterations, step_control, ..SolveOptions::default() };
    eprintln!(
        "solving '{}' ({} vertices) with '{}' at {}",
        pattern.name,
        pattern.vertex_count(),
        model.name,
        args.strain
    );
    let placement = yarnhom_rve::homogenize::placement(&tile, &strain);
    let mut trace = match &args.trace {
        Some(path) => {
            let metadata = TraceMetadata::new("yarnhom rve solve", env!("CARGO_PKG_VERSION"))
                .with_entry("pattern", args.pattern.display().to_string())
                .with_entry("model", &args.model)
                .with_entry("strain", &args.strain);
            Some(TraceSink::open(path, &metadata)?)
        }
        None => None,
    };
    let mut trace_error = None;
    let mut record = |iterate: &Iterate<'_>| {
        if let Some(sink) = trace.as_mut().filter(|_| trace_error.is_none()) {
            let frame = iterate.iteration as u64;
            let written = sink
                .write(&SolverIteration {
                    frame,
                    time_s: 0.0,
                    iteration: iterate.iteration as u32,
                    energy_j: iterate.energy_j,
                    residual: iterate.gradient_ratio,
                    step_length: iterate.step_length,
                })
                .and_then(|()| sink.write(&yarn_frame(pattern, &tile, &placement, iterate.state, frame)))
                .and_then(|()| sink.end_frame());
            trace_error = written.err();
        }
    };
    let started = Instant::now();
    let (report, state) = solve_at_observed(&tile, &strain, None, &options, &mut record);
    let seconds = started.elapsed().as_secs_f64();
    if let Some(err) = trace_error {
        return Err(anyhow::Error::new(err).context("cannot write the trace"));
    }
    if let Some(sink) = trace {
        sink.finish()?;
    }
    let stress = (report.converged && !args.no_stress).then(|| stress_at_equilibrium(&tile, &strain, &state));
    let stress_fd = (report.converged && args.fd_stress)
        .then(|| stress_by_finite_differences(&tile, &strain, &state))
        .flatten();
    let result = RveSolve {
        pattern: pattern.name.clone(),
        model: model.name.clone(),
        strain: StrainSample {
            sx: strain.s.sx,
            sa: strain.s.sa,
            sy: strain.s.sy,
            kx: strain.kx,
            ky: strain.ky,
        },
        converged: report.converged,
        stop_reason: stop_reason(report.reason).into(),
        energy_density_j_m2: report.converged.then_some(report.energy_density_j_m2),
        stress,
        stress_fd,
        iterations: report.iterations as u32,
        gradient_ratio: report.gradient_ratio,
        seconds,
        positions_m: yarnhom_rve::assembly::world_positions(&tile, &placement, &state),
        edge_twist_rad: (0..tile.vertices as u32).map(|v| state.g[tile.twist_dof(v)]).collect(),
    };
    let output = args.output.unwrap_or_else(|| format!("{}.rvesolve.yh", base_name(&args.pattern)).into());
    container::write(&output, &result, &provenance("rve solve", inputs_list))?;
    if args.trace.as_deref().is_some_and(is_stdout) {
        eprintln!("{}", result.summary());
    } else {
        println!("{}", result.summary());
    }
    eprintln!("wrote {}", output.display());
    if report.converged {
        Ok(Outcome::Success)
    } else {
        eprintln!("error: the solve did not converge ({})", stop_reason(report.reason));
        Ok(Outcome::Different)
    }
}

fn residual(args: ResidualArgs) -> anyhow::Result<Outcome> {
    let (pattern, model, _) = load_pattern_and_model(&args.pattern, &args.model)?;
    let r = yarnhom_rve::residual::equilibrium_residual(&pattern, &model)?;
    println!(
        "forces at the stored state of '{}' under '{}' (projected on the constraints):",
        pattern.name, model.name
    );
    println!("  stretching          {:.4e} N", r.stretch);
    println!("  bending, twisting   {:.4e} N", r.bend_twist);
    println!("  contact             {:.4e} N", r.contact);
    println!("  total               {:.4e} N ({:.3} of the stretching force)", r.total, r.relative_at(1.0));
    match r.best_contact_scale() {
        Some(c) => println!(
            "  best contact scale  {c:.3} (the contact that balances this state best), leaving {:.3} of the stretching force",
            r.relative_at(c)
        ),
        None => println!("  no contact force: no yarns within reach of each other"),
    }
    Ok(Outcome::Success)
}

fn relax(args: RelaxArgs) -> anyhow::Result<Outcome> {
    let (pattern, model, inputs_list) = load_pattern_and_model(&args.pattern, &args.model)?;
    let pattern = &pattern;
    let method = match args.estimation {
        Some(bound) if !(bound > 0.0 && bound < 1.0) => {
            anyhow::bail!("--estimation {bound}: the rest-length bound must lie strictly between 0 and 1")
        }
        Some(max_length_change) => RelaxMethod::Estimation { max_length_change },
        None => RelaxMethod::Reference,
    };
    if args.keep_rest_shape && pattern.rest.is_none() {
        anyhow::bail!(
            "{}: --keep-rest-shape needs a pattern with a rest state, and '{}' has none",
            args.pattern.display(),
            pattern.name
        );
    }
    let options = RelaxOptions {
        method,
        keep_rest_shape: args.keep_rest_shape,
        max_resets: args.max_resets,
        ..RelaxOptions::default()
    };
    eprintln!("relaxing '{}' ({} vertices) with '{}'", pattern.name, pattern.vertex_count(), model.name);
    let started = Instant::now();
    let mut show = |event: RelaxEvent| match event {
        RelaxEvent::Reset(k, energy) => {
            eprintln!(
                "  reset {:>3}: relaxed tile energy {energy:.3e} J ({:.1} s)",
                k + 1,
                started.elapsed().as_secs_f64()
            )
        }
        RelaxEvent::PeriodStep(s, sigma) => eprintln!(
            "  periods: sx {:+.5} sy {:+.5}, stress {:+.3e} {:+.3e} J/m² ({:.1} s)",
            s[0],
            s[1],
            sigma[0],
            sigma[1],
            started.elapsed().as_secs_f64()
        ),
    };
    let (relaxed, report) = yarnhom_rve::relax(pattern, &model, &options, &mut show)
        .with_context(|| format!("{}", args.pattern.display()))?;
    if !args.keep_rest_shape && report.stress_free_energy_j >= options.stress_free_energy_j {
        eprintln!(
            "warning: no stress-free state within {} resets (tile energy {:.3e} J, target {:.0e} J); continuing",
            report.resets, report.stress_free_energy_j, options.stress_free_energy_j
        );
    }
    let output =
        args.output.unwrap_or_else(|| format!("{}.relaxed.pattern.yh", base_name(&args.pattern)).into());
    container::write(&output, &relaxed, &provenance("rve relax", inputs_list))?;
    let [sx, sa, sy] = report.residual_stress_j_m2;
    println!(
        "relaxed '{}': {} resets, periods {:.4} x {:.4} mm (period strain {:+.4}, {:+.4}), {} Newton iterations, {:.1} s\n  in-plane stress at zero strain: dsx {sx:.3e}, dsa {sa:.3e}, dsy {sy:.3e} J/m²",
        relaxed.name,
        report.resets,
        relaxed.period_m[0] * 1e3,
        relaxed.period_m[1] * 1e3,
        report.period_strain[0],
        report.period_strain[1],
        report.iterations,
        started.elapsed().as_secs_f64()
    );
    eprintln!("wrote {}", output.display());
    Ok(Outcome::Success)
}
