//! Seconds per backward Euler step of the yarn-level simulator (`yls simulate`) on the built-in
//! `stretch-x` scene with swatches of the published stockinette (`stock.pyp`, Table 4.1 yarn):
//! 4 x 4 tiles (1600 vertices) and 8 x 8 (6400 vertices), at the default 16 steps per 1/60 s
//! frame (Δt = 1.04 ms), the first 4 steps from rest, each sample from a fresh simulation.
//! Compared with: thesis Table 4.2, direct yarn-level simulation of the 30 cm stockinette
//! (76,156 vertices) at 0.18 s per step, Δt = 1e-5 s, 615 s per 1/30 s frame; our target is
//! the same swatch at 60 s per 1/30 s frame on 2 cores (`yls swatch --size 0.3x0.3` gives
//! 75,371 vertices).

use criterion::{BatchSize, Criterion, criterion_group, criterion_main};
use yarnhom_artifacts::{GlueSettings, YarnModel, pyp};
use yarnhom_yls::dynamics::Simulation;
use yarnhom_yls::run::{RunSettings, place};
use yarnhom_yls::swatch::{SwatchSize, cut_swatch};

/// Steps per sample.
const STEPS: usize = 4;

fn bench_steps(c: &mut Criterion) {
    let path = format!("{}/../../shared/data/hylc-patterns/stock.pyp", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(path).expect("the published stockinette");
    let pattern = pyp::parse_pyp(&text, "stock", None).expect("a valid .pyp");
    let model = YarnModel::table_4_1("stock").expect("a Table 4.1 row");
    let scene = yarnhom_shell::Scene::builtin("stretch-x").expect("a built-in");
    let settings = RunSettings::default();
    let time_step_s = scene.frame_time_s / f64::from(settings.steps_per_frame);
    let mut g = c.benchmark_group("yarn-level time step");
    g.sample_size(10);
    for tiles in [4, 8] {
        let swatch = cut_swatch(&pattern, &model, SwatchSize::Tiles([tiles, tiles]), GlueSettings::default())
            .expect("cuts")
            .0;
        let placed = place(&swatch, &scene, &settings).expect("places");
        let name = format!(
            "stretch-x, stock {tiles}x{tiles} tiles, {} vertices, {STEPS} steps",
            swatch.positions_m.len()
        );
        g.bench_function(name, |b| {
            b.iter_batched(
                || Simulation::new(&placed).expect("a valid scene"),
                |mut simulation| {
                    for _ in 0..STEPS {
                        simulation.step(time_step_s).expect("steps");
                    }
                    simulation
                },
                BatchSize::LargeInput,
            )
        });
    }
    g.finish();
}

criterion_group!(benches, bench_steps);
criterion_main!(benches);
