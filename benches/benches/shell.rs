//! Seconds per implicit time step of the thin-shell simulator on the published 30 cm stretch
//! and drape scenes (built-ins `stretch-x`, `drape`) at 50 x 50 = 2500 vertices, with the
//! published ARCSim-HYLC stockinette material (`stock1.json`), one thread (`RAYON_NUM_THREADS=1`
//! gives the single-core figure) or all.
//! Compared with: thesis Table 4.2, HYLC in ARCSim 0.41-1.15 s per step at 2.1k-4.4k vertices;
//! target 10x faster, under 0.05 s per step on one core.
//! Each sample is one step of a simulation already advanced 10 steps (the cloth is moving).

use criterion::{Criterion, criterion_group, criterion_main};
use yarnhom_artifacts::arcsim::read_spline;
use yarnhom_fit::SplineMaterial;
use yarnhom_shell::simulate::prepare;
use yarnhom_shell::{Scene, ShellMaterial};

fn stock() -> ShellMaterial {
    let path = format!("{}/../../shared/data/hylc-materials/stock1.json", env!("CARGO_MANIFEST_DIR"));
    ShellMaterial::spline(SplineMaterial::from(
        &read_spline(std::path::Path::new(&path)).expect("published material"),
    ))
}

fn bench_steps(c: &mut Criterion) {
    let mut g = c.benchmark_group("shell time step");
    g.sample_size(10);
    for name in ["stretch-x", "drape"] {
        let scene = Scene::builtin(name).expect("builtin");
        let mut sim = prepare(&scene, stock()).expect("scene");
        let mut iterations = 0;
        for _ in 0..10 {
            iterations += sim.step().expect("step").newton_iterations;
        }
        eprintln!(
            "{name}: {} vertices, {} triangles, dt {} s, {:.1} Newton iterations per step, {} threads",
            sim.positions.len(),
            sim.model.mesh.triangles.len(),
            scene.dt_s(),
            f64::from(iterations) / 10.0,
            rayon::current_num_threads()
        );
        g.bench_function(format!("{name}, 2500 vertices, stock1"), |b| b.iter(|| sim.step().expect("step")));
    }
    g.finish();
}

criterion_group!(benches, bench_steps);
criterion_main!(benches);
