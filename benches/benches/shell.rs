//! Seconds per implicit time step of the thin-shell simulator on the published 30 cm stretch
//! and drape scenes (built-ins `stretch-x`, `drape`) at 50 x 50 = 2500 vertices, with the
//! published ARCSim-HYLC stockinette material (`stock1.json`), one thread (`RAYON_NUM_THREADS=1`
//! gives the single-core figure) or all, with either Newton matrix (`projected`, the default,
//! and `gauss-newton`).
//! Compared with: thesis Table 4.2, HYLC in ARCSim 0.41-1.15 s per step at 2.1k-4.4k vertices;
//! target 10x faster, under 0.05 s per step on one core.
//! Each sample is the mean over the same 10 steps (steps 11-20: the cloth is moving), restarted
//! from the state after step 10, so every sample does the same Newton iterations.

use std::time::{Duration, Instant};

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::Vector3;
use yarnhom_artifacts::arcsim::read_spline;
use yarnhom_fit::SplineMaterial;
use yarnhom_shell::elastic::NewtonMatrix;
use yarnhom_shell::simulate::prepare;
use yarnhom_shell::{Scene, ShellMaterial, Simulation};

/// Steps before the measured window, and in it.
const SETTLE: usize = 10;
const WINDOW: u32 = 10;

/// Positions, velocities and time of a simulation.
type State = (Vec<Vector3<f64>>, Vec<Vector3<f64>>, f64);

fn stock() -> ShellMaterial {
    let path = format!("{}/../../shared/data/hylc-materials/stock1.json", env!("CARGO_MANIFEST_DIR"));
    ShellMaterial::spline(SplineMaterial::from(
        &read_spline(std::path::Path::new(&path)).expect("published material"),
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
    let matrices = [(NewtonMatrix::Projected, "projected"), (NewtonMatrix::GaussNewton, "gauss-newton")];
    for (name, (matrix, matrix_name)) in
        ["stretch-x", "drape"].into_iter().flat_map(|n| matrices.map(|m| (n, m)))
    {
        let mut scene = Scene::builtin(name).expect("builtin");
        scene.newton_matrix = matrix;
        let mut sim = prepare(&scene, stock()).expect("scene");
        for _ in 0..SETTLE {
            sim.step().expect("step");
        }
        let state = (sim.positions.clone(), sim.velocities.clone(), sim.time_s);
        let (_, iterations) = run_window(&mut sim, &state);
        eprintln!(
            "{name}, {matrix_name}: {} vertices, {} triangles, dt {} s, {:.1} Newton iterations per step (steps {}-{}), {} threads",
            sim.positions.len(),
            sim.model.mesh.triangles.len(),
            scene.dt_s(),
            f64::from(iterations) / f64::from(WINDOW),
            SETTLE + 1,
            SETTLE + WINDOW as usize,
            rayon::current_num_threads()
        );
        g.bench_function(format!("{name}, 2500 vertices, stock1, {matrix_name}"), |b| {
            b.iter_custom(|samples| (0..samples).map(|_| run_window(&mut sim, &state).0).sum())
        });
    }
    g.finish();
}

criterion_group!(benches, bench_steps);
criterion_main!(benches);
