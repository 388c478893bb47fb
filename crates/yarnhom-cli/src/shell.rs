//! `yarnhom shell ...`: thin-shell cloth simulation with homogenized or Ch. 6 materials.

use std::path::PathBuf;

use clap::{Args, Subcommand};
use yarnhom_shell::elastic::NewtonMatrix;
use yarnhom_shell::messages::record_frame;
use yarnhom_shell::simulate::{RunTotals, run as run_scene, write_obj};
use yarnhom_shell::{LinearSolver, Scene, open_material};
use yarnhom_trace::TraceMetadata;

use crate::Outcome;
use crate::output::{create_dir, finish_trace, open_trace, progress_bar, write_bytes};

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
    pub newton_matrix: Option<NewtonMatrix>,
    /// The Newton system's solver (overrides the scene): `auto` takes Jacobi-preconditioned
    /// conjugate gradients where their bound iteration count costs less than a sparse Cholesky
    /// factorization (short time steps), else the factorization.
    #[arg(long, value_enum)]
    pub linear_solver: Option<LinearSolver>,
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
    let frames = args.frames.unwrap_or_else(|| (scene.end_time_s / scene.frame_time_s).round() as u64);
    let bar = progress_bar(frames, "frames");
    if let Some(dir) = &args.obj_dir {
        create_dir(dir)?;
    }
    let mut totals = RunTotals::default();
    let sim = run_scene(&scene, material, args.frames, |report, sim| {
        record_frame(&mut trace, report, sim, &scene.name).map_err(|e| e.to_string())?;
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
    eprintln!("{}", totals.summary(&sim));
    Ok(Outcome::Success)
}

/// The scene with the command line's overrides.
fn scene_of(args: &SimulateArgs) -> anyhow::Result<Scene> {
    let mut scene = Scene::load(&args.scene)?;
    if let Some(n) = args.resolution {
        scene.vertices = [n, n];
    }
    scene.steps_per_frame = args.steps_per_frame.unwrap_or(scene.steps_per_frame);
    scene.newton_matrix = args.newton_matrix.unwrap_or(scene.newton_matrix);
    scene.linear_solver = args.linear_solver.unwrap_or(scene.linear_solver);
    Ok(scene)
}
