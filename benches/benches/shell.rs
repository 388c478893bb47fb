//! Seconds per implicit time step of the thin-shell simulator on the published 30 cm stretch
//! and drape scenes (built-ins `stretch-x`, `drape`) at 50 x 50 = 2500 vertices, with the
//! published ARCSim-HYLC stockinette material (`stock1.json`), one thread (`RAYON_NUM_THREADS=1`
//! gives the single-core figure) or all: at the built-ins' Δt = 4.2 ms (4 steps per 1/60 s frame)
//! with either Newton matrix (`gauss-newton`, the default, and `projected`; the default linear
//! solver factors there), and at the published scenes' own Δt = 0.209 ms (80 steps per frame,
//! `frame_steps` in `stock_stretchX.json`) with the default linear solver (conjugate gradients
//! there) and with Cholesky.
//! Compared with: thesis Table 4.2, HYLC in ARCSim 0.41-1.15 s per step at 2.1k-4.4k vertices
//! (at Δt = 0.209 ms); target 10x faster, under 0.05 s per step on one core.
//! Each sample is the mean over the same 10 steps, restarted from the same state (after 10 steps
//! at 4.2 ms, after 200 at 0.209 ms: the cloth is moving), so every sample does the same Newton
//! iterations.

use std::time::{Duration, Instant};

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::Vector3;
use yarnhom_fit::SplineMaterial;
use yarnhom_shell::elastic::NewtonMatrix;
use yarnhom_shell::simulate::prepare;
use yarnhom_shell::{LinearSolver, Scene, ShellMaterial, Simulation};

/// Steps in the measured window.
const WINDOW: u32 = 10;

/// Positions, velocities and time of a simulation.
type State = (Vec<Vector3<f64>>, Vec<Vector3<f64>>, f64);

fn stock() -> ShellMaterial {
    let path = format!("{}/../../shared/data/hylc-materials/stock1.json", env!("CARGO_MANIFEST_DIR"));
    ShellMaterial::spline(SplineMaterial::from(
        &yarnhom_artifacts::open::open_artifact::<yarnhom_artifacts::Spline>(&path)
            .map(|o| o.value)
            .expect("published material"),
    ))
}

/// The mean wall time of the window's steps from the state `(positions, velocities, time)`,
/// and its Newton iterations.
fn run_window(sim: &mut Simulation, state: &State) -> (Duration, u32) {
    (sim.positions, sim.velocities, sim.time_s) = state.clone();
    let started = Instant::now();
    let iterations = (0..WINDOW).map(|_| sim.step().expect("step").newton_iterations).sum();
    (started.elapsed() / WINDOW, iterations)
}

fn bench_steps(c: &mut Criterion) {
    let mut g = c.benchmark_group("shell time step");
    g.sample_size(10);
    // (matrix, linear solver, their names, steps per frame, steps before the window)
    let cases = [
        (NewtonMatrix::GaussNewton, LinearSolver::Auto, "gauss-newton, auto", 4, 10),
        (NewtonMatrix::Projected, LinearSolver::Auto, "projected, auto", 4, 10),
        (NewtonMatrix::GaussNewton, LinearSolver::Auto, "gauss-newton, auto", 80, 200),
        (NewtonMatrix::GaussNewton, LinearSolver::Cholesky, "gauss-newton, cholesky", 80, 200),
    ];
    for (name, (matrix, solver, solver_name, steps_per_frame, settle)) in
        ["stretch-x", "drape"].into_iter().flat_map(|n| cases.map(|c| (n, c)))
    {
        let mut scene = Scene::builtin(name).expect("builtin");
        scene.newton_matrix = matrix;
        scene.linear_solver = solver;
        scene.steps_per_frame = steps_per_frame;
        let mut sim = prepare(&scene, stock()).expect("scene");
        for _ in 0..settle {
            sim.step().expect("step");
        }
        let state = (sim.positions.clone(), sim.velocities.clone(), sim.time_s);
        let (_, iterations) = run_window(&mut sim, &state);
        eprintln!(
            "{name}, {solver_name}: {} vertices, {} triangles, dt {} s, {:.1} Newton iterations per step (steps {}-{}), {} threads",
            sim.positions.len(),
            sim.model.mesh.triangles.len(),
            scene.dt_s(),
            f64::from(iterations) / f64::from(WINDOW),
            settle + 1,
            settle + WINDOW as usize,
            rayon::current_num_threads()
        );
        let dt_ms = 1e3 * scene.dt_s();
        g.bench_function(format!("{name}, 2500 vertices, stock1, {solver_name}, dt {dt_ms:.3} ms"), |b| {
            b.iter_custom(|samples| (0..samples).map(|_| run_window(&mut sim, &state).0).sum())
        });
    }
    g.finish();
}

criterion_group!(benches, bench_steps);
criterion_main!(benches);
