//! `yarnhom shell ...`: thin-shell cloth simulation with homogenized or Ch. 6 materials.

use std::path::{Path, PathBuf};

use anyhow::Context;
use clap::{Args, Subcommand};
use indicatif::{ProgressBar, ProgressStyle};
use yarnhom_artifacts::AtomicFile;
use yarnhom_shell::elastic::NewtonMatrix;
use yarnhom_shell::messages::{frame_messages, topology};
use yarnhom_shell::simulate::{FrameReport, RunTotals, run as run_scene};
use yarnhom_shell::{LinearSolver, Scene, Simulation, open_material};
use yarnhom_trace::{TraceError, TraceMetadata, TraceSink};

use crate::Outcome;
use crate::output::{finish_trace, open_trace, write_bytes};

#[derive(Debug, Subcommand)]
pub enum ShellCommand {
    /// Simulate a scene and write an MCAP trace: the mesh topology once, the vertex positions
    /// of every frame (`/mesh/frame`), energies per frame (`/metrics`) and Newton statistics per
    /// time step (`/solver`); optionally OBJ files per frame.
    Simulate(SimulateArgs),
    /// Write a built-in scene (stretch-x, stretch-y, drape) as a JSON scene file to edit.
    Scene(SceneArgs),
}

#[derive(Debug, Args)]
pub struct SimulateArgs {
    /// A built-in scene (stretch-x, stretch-y, drape), a yarnhom scene JSON or an ARCSim-HYLC
    /// scene JSON (`../shared/data/hylc-scenes/*.json`).
    pub scene: String,
    /// The material: a `.spline.yh` (`yarnhom fit`), an ARCSim-HYLC material JSON, or a JSON
    /// file `{"areal_density_kg_m2", "membrane": {k_xx, k_xy, k_yy, k_ss, k_n1, k_n2},
    /// "bending": {k_weft, k_bias, k_warp}}` for the Ch. 6 model (6.1), (6.4).
    #[arg(long)]
    pub material: PathBuf,
    /// Output trace (`.mcap`); `-` writes to stdout.
    #[arg(short, long, visible_alias = "trace")]
    pub output: String,
    /// Also write every frame as `frame_NNNN.obj` into this folder.
    #[arg(long)]
    pub obj_dir: Option<PathBuf>,
    /// Stop after this many frames (default: the scene's end time).
    #[arg(long)]
    pub frames: Option<u64>,
    /// Vertices per side of the cloth (overrides the scene).
    #[arg(long)]
    pub resolution: Option<usize>,
    /// Implicit time steps per frame (overrides the scene).
    #[arg(long)]
    pub steps_per_frame: Option<u32>,
    /// The Newton matrix (overrides the scene): the projected element Hessians (Sec. 4.2) or
    /// Gauss-Newton in the forms (faster, no 18 x 18 eigensolver; the same states).
    #[arg(long, value_enum)]
    pub newton_matrix: Option<NewtonMatrixArg>,
    /// The Newton system's solver (overrides the scene): `auto` takes Jacobi-preconditioned
    /// conjugate gradients where their bound iteration count costs less than a sparse Cholesky
    /// factorization (short time steps), else the factorization.
    #[arg(long, value_enum)]
    pub linear_solver: Option<LinearSolverArg>,
}

/// [`LinearSolver`] on the command line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum LinearSolverArg {
    /// Conjugate gradients where their bound iteration count costs less than a factorization,
    /// else Cholesky (the default).
    Auto,
    /// Sparse Cholesky for every solve.
    Cholesky,
    /// Conjugate gradients for every solve (Cholesky only where they fail).
    ConjugateGradient,
}

impl From<LinearSolverArg> for LinearSolver {
    fn from(arg: LinearSolverArg) -> Self {
        match arg {
            LinearSolverArg::Auto => LinearSolver::Auto,
            LinearSolverArg::Cholesky => LinearSolver::Cholesky,
            LinearSolverArg::ConjugateGradient => LinearSolver::ConjugateGradient,
        }
    }
}

/// [`NewtonMatrix`] on the command line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum NewtonMatrixArg {
    /// The exact element Hessians with their eigenvalues made absolute.
    Projected,
    /// Gauss-Newton in the forms, positive semidefinite by construction (the default).
    GaussNewton,
}

impl From<NewtonMatrixArg> for NewtonMatrix {
    fn from(arg: NewtonMatrixArg) -> Self {
        match arg {
            NewtonMatrixArg::Projected => NewtonMatrix::Projected,
            NewtonMatrixArg::GaussNewton => NewtonMatrix::GaussNewton,
        }
    }
}

#[derive(Debug, Args)]
pub struct SceneArgs {
    /// Built-in name.
    pub name: String,
    /// Output JSON file.
    #[arg(short, long)]
    pub output: PathBuf,
}

pub fn run(cmd: ShellCommand) -> anyhow::Result<Outcome> {
    match cmd {
        ShellCommand::Simulate(args) => simulate(args),
        ShellCommand::Scene(args) => {
            let scene = Scene::builtin(&args.name)?;
            write_bytes(&args.output, serde_json::to_string_pretty(&scene)?.as_bytes())?;
            println!("wrote {}", args.output.display());
            Ok(Outcome::Success)
        }
    }
}

fn simulate(args: SimulateArgs) -> anyhow::Result<Outcome> {
    let scene = scene_of(&args)?;
    let material = open_material(&args.material)?;
    let metadata = TraceMetadata::new("yarnhom shell simulate", env!("CARGO_PKG_VERSION"))
        .with_entry("scene", &args.scene)
        .with_entry("material", args.material.display().to_string())
        .with_entry("newton_matrix", serde_json::to_value(scene.newton_matrix)?.as_str().unwrap_or_default())
        .with_entry("linear_solver", serde_json::to_value(scene.linear_solver)?.as_str().unwrap_or_default());
    let mut trace = open_trace(&args.output, &metadata)?;
    let bar =
        progress_bar(args.frames.unwrap_or_else(|| (scene.end_time_s / scene.frame_time_s).round() as u64));
    if let Some(dir) = &args.obj_dir {
        std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    }
    let mut totals = RunTotals::default();
    let sim = run_scene(&scene, material, args.frames, |report, sim| {
        if report.frame == 0 {
            trace.write(&topology(sim, &scene.name)).map_err(|e| e.to_string())?;
        }
        write_frame(&mut trace, report, sim, &scene.name).map_err(|e| e.to_string())?;
        trace.end_frame().map_err(|e| e.to_string())?;
        if let Some(dir) = &args.obj_dir {
            write_obj(&dir.join(format!("frame_{:04}.obj", report.frame)), sim).map_err(|e| e.to_string())?;
        }
        totals.add(report);
        bar.set_position(report.frame);
        bar.set_message(format!("E {:.3e} J", report.elastic_energy_j));
        Ok(())
    })?;
    bar.finish_and_clear();
    finish_trace(Some(trace), Some(&args.output))?;
    eprintln!(
        "simulated {} s in {} steps ({} Newton iterations; linear solves: {} conjugate gradient iterations, {} \
         Cholesky factorizations), {} vertices; elastic energy {:.4e} J",
        sim.time_s,
        totals.steps,
        totals.newton_iterations,
        totals.cg_iterations,
        totals.factorizations,
        sim.positions.len(),
        sim.model.energy(&sim.positions)
    );
    Ok(Outcome::Success)
}

/// The scene with the command line's overrides.
fn scene_of(args: &SimulateArgs) -> anyhow::Result<Scene> {
    let mut scene = Scene::load(&args.scene)?;
    if let Some(n) = args.resolution {
        scene.vertices = [n, n];
    }
    scene.steps_per_frame = args.steps_per_frame.unwrap_or(scene.steps_per_frame);
    scene.newton_matrix = args.newton_matrix.map_or(scene.newton_matrix, NewtonMatrix::from);
    scene.linear_solver = args.linear_solver.map_or(scene.linear_solver, LinearSolver::from);
    Ok(scene)
}

fn progress_bar(frames: u64) -> ProgressBar {
    let bar = ProgressBar::new(frames);
    bar.set_style(
        ProgressStyle::with_template("{bar:40} frame {pos}/{len}, {elapsed} elapsed, ETA {eta} {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    bar
}

/// Writes one frame's messages to the trace.
fn write_frame(
    trace: &mut TraceSink,
    report: &FrameReport,
    sim: &Simulation,
    name: &str,
) -> Result<(), TraceError> {
    let (mesh, scalars, steps) = frame_messages(report, sim, name);
    trace.write(&mesh)?;
    trace.write(&scalars)?;
    steps.iter().try_for_each(|step| trace.write(step))
}

/// One frame as a Wavefront OBJ with material coordinates as texture coordinates.
fn write_obj(path: &Path, sim: &Simulation) -> std::io::Result<()> {
    let positions: Vec<[f64; 3]> = sim.positions.iter().map(|p| [p.x, p.y, p.z]).collect();
    let texcoords: Vec<[f64; 2]> = sim.model.mesh.material.iter().map(|m| [m.x, m.y]).collect();
    let mut out = AtomicFile::create(path)?;
    yarnhom_trace::export::write_obj(&mut out, &positions, &texcoords, &sim.model.mesh.triangles)?;
    out.commit()
}
