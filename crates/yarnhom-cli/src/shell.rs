//! `yarnhom shell ...`: thin-shell cloth simulation with homogenized or Ch. 6 materials.

use std::collections::BTreeMap;
use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::Context;
use clap::{Args, Subcommand};
use indicatif::{ProgressBar, ProgressStyle};
use serde::Deserialize;
use yarnhom_fit::SplineMaterial;
use yarnhom_shell::elastic::NewtonMatrix;
use yarnhom_shell::simulate::{FrameReport, run as run_scene};
use yarnhom_shell::{HingeBending, LinearSolver, Scene, ShellMaterial, Simulation, StvkNeoHookean};
use yarnhom_trace::{MeshFrame, MeshTopology, Scalars, SolverStep, TraceMetadata};

use crate::Outcome;
use crate::trace_out::TraceSink;

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
            std::fs::write(&args.output, serde_json::to_string_pretty(&scene)?)
                .with_context(|| format!("cannot write {}", args.output.display()))?;
            println!("wrote {}", args.output.display());
            Ok(Outcome::Success)
        }
    }
}

/// The Ch. 6 model as a JSON file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct StvkFile {
    areal_density_kg_m2: f64,
    membrane: StvkNeoHookean,
    bending: HingeBending,
}

/// A material from a spline artifact, an ARCSim-HYLC JSON or a Ch. 6 JSON file.
pub fn load_material(path: &Path) -> anyhow::Result<ShellMaterial> {
    let text = std::fs::read(path).with_context(|| format!("cannot read {}", path.display()))?;
    if text.windows(10).any(|w| w == b"\"membrane\"") {
        let file: StvkFile = serde_json::from_slice(&text)
            .with_context(|| format!("{}: not a Ch. 6 material", path.display()))?;
        return Ok(ShellMaterial::stvk(file.areal_density_kg_m2, file.membrane, file.bending));
    }
    let spline = crate::fit::load_spline(path)?;
    Ok(ShellMaterial::spline(SplineMaterial::from(&spline)))
}

fn simulate(args: SimulateArgs) -> anyhow::Result<Outcome> {
    let mut scene = Scene::load(&args.scene)?;
    if let Some(n) = args.resolution {
        scene.vertices = [n, n];
    }
    scene.steps_per_frame = args.steps_per_frame.unwrap_or(scene.steps_per_frame);
    scene.newton_matrix = args.newton_matrix.map_or(scene.newton_matrix, NewtonMatrix::from);
    scene.linear_solver = args.linear_solver.map_or(scene.linear_solver, LinearSolver::from);
    let material = load_material(&args.material)?;
    let metadata = TraceMetadata::new("yarnhom shell simulate", env!("CARGO_PKG_VERSION"))
        .with_entry("scene", &args.scene)
        .with_entry("material", args.material.display().to_string())
        .with_entry("newton_matrix", serde_json::to_value(scene.newton_matrix)?.as_str().unwrap_or_default())
        .with_entry("linear_solver", serde_json::to_value(scene.linear_solver)?.as_str().unwrap_or_default());
    let mut trace = TraceSink::open(&args.output, &metadata)?;
    let total = args.frames.unwrap_or_else(|| (scene.end_time_s / scene.frame_time_s).round() as u64);
    let bar = ProgressBar::new(total);
    bar.set_style(
        ProgressStyle::with_template("{bar:40} frame {pos}/{len}, {elapsed} elapsed, ETA {eta} {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    if let Some(dir) = &args.obj_dir {
        std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    }
    let mut newton_total = 0u64;
    let mut steps_total = 0u64;
    let (mut cg_total, mut factorizations_total) = (0u64, 0u64);
    let sim = run_scene(&scene, material, args.frames, |report, sim| {
        if report.frame == 0 {
            trace.write(&topology(sim, &scene.name)).map_err(|e| e.to_string())?;
        }
        write_frame(&mut trace, report, sim, &scene.name).map_err(|e| e.to_string())?;
        trace.end_frame().map_err(|e| e.to_string())?;
        if let Some(dir) = &args.obj_dir {
            write_obj(&dir.join(format!("frame_{:04}.obj", report.frame)), sim).map_err(|e| e.to_string())?;
        }
        newton_total += report.steps.iter().map(|s| u64::from(s.newton_iterations)).sum::<u64>();
        steps_total += report.steps.len() as u64;
        cg_total += report.steps.iter().map(|s| u64::from(s.linear_solves.cg_iterations)).sum::<u64>();
        factorizations_total +=
            report.steps.iter().map(|s| u64::from(s.linear_solves.factorizations)).sum::<u64>();
        bar.set_position(report.frame);
        bar.set_message(format!("E {:.3e} J", report.elastic_energy_j));
        Ok(())
    })?;
    bar.finish_and_clear();
    trace.finish()?;
    eprintln!(
        "simulated {} s in {} steps ({} Newton iterations; linear solves: {} conjugate gradient iterations, {} \
         Cholesky factorizations), {} vertices; elastic energy {:.4e} J",
        sim.time_s,
        steps_total,
        newton_total,
        cg_total,
        factorizations_total,
        sim.positions.len(),
        sim.model.energy(&sim.positions)
    );
    Ok(Outcome::Success)
}

fn topology(sim: &Simulation, name: &str) -> MeshTopology {
    MeshTopology {
        triangles: sim.model.mesh.triangles.clone(),
        rest_positions_m: sim.model.mesh.material.iter().map(|m| [m.x, m.y, 0.0]).collect(),
        name: name.into(),
    }
}

fn write_frame(
    trace: &mut TraceSink,
    report: &FrameReport,
    sim: &Simulation,
    name: &str,
) -> Result<(), yarnhom_trace::TraceError> {
    let positions_m = sim.positions.iter().map(|p| [p.x, p.y, p.z]).collect();
    trace.write(&MeshFrame { mesh: name.into(), frame: report.frame, time_s: report.time_s, positions_m })?;
    let values = BTreeMap::from([
        ("elastic_energy_j".to_string(), report.elastic_energy_j),
        ("kinetic_energy_j".to_string(), report.kinetic_energy_j),
        ("gravity_energy_j".to_string(), report.gravity_energy_j),
        ("penetration_m".to_string(), report.penetration_m),
        (
            "cg_iterations".to_string(),
            report.steps.iter().map(|s| f64::from(s.linear_solves.cg_iterations)).sum(),
        ),
        (
            "cholesky_factorizations".to_string(),
            report.steps.iter().map(|s| f64::from(s.linear_solves.factorizations)).sum(),
        ),
    ]);
    trace.write(&Scalars { frame: report.frame, time_s: report.time_s, values })?;
    for s in &report.steps {
        trace.write(&SolverStep {
            frame: report.frame,
            time_s: report.time_s,
            newton_iterations: s.newton_iterations,
            residual: s.residual_n,
            line_search_steps: s.line_search_steps,
            converged: s.converged,
            wall_time_s: s.wall_time_s,
        })?;
    }
    Ok(())
}

/// One frame as a Wavefront OBJ with material coordinates as texture coordinates.
fn write_obj(path: &Path, sim: &Simulation) -> std::io::Result<()> {
    let positions: Vec<[f64; 3]> = sim.positions.iter().map(|p| [p.x, p.y, p.z]).collect();
    let texcoords: Vec<[f64; 2]> = sim.model.mesh.material.iter().map(|m| [m.x, m.y]).collect();
    let mut out = std::io::BufWriter::new(std::fs::File::create(path)?);
    yarnhom_trace::export::write_obj(&mut out, &positions, &texcoords, &sim.model.mesh.triangles)?;
    out.flush()
}
