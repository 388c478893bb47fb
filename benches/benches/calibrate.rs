//! The simulation in the loop of the shell fit (thesis Sec. 6.3.1, (6.2)): one evaluation of
//! the objective on the real acrylic stockinette set (`shared/data/stitch-by-stitch-acrylic`),
//! i.e. its weft and warp clamped swatches simulated to equilibrium at their 6 targets each,
//! with the membrane `yarnhom calibrate shell` fits to it.
//!
//! Compared with: the thesis' shell fit has no published time; its yarn-level local solver took
//! 11 min 49 s per fabric on a share of a 256-core server (Sec. 6.6). A whole shell fit is
//! 140 to 320 of these evaluations (`yarnhom calibrate shell` prints its count and wall time).

use criterion::{Criterion, criterion_group, criterion_main};
use yarnhom_calib::measure::Direction;
use yarnhom_calib::stitch_by_stitch::import_fabric;
use yarnhom_calib::swatch::SwatchTest;
use yarnhom_calib::targets::{TargetPlan, targets};
use yarnhom_shell::StvkNeoHookean;

fn bench_objective(c: &mut Criterion) {
    let data = format!("{}/../../shared/data/stitch-by-stitch-acrylic", env!("CARGO_MANIFEST_DIR"));
    let files = ["x", "y"].map(|d| format!("{data}/acrylic-stockinette-{d}.h5").into());
    let set = import_fabric(&files, 1).expect("the published files import").set;
    let targets = targets(&set, &TargetPlan::default()).expect("targets");
    // The membrane `yarnhom calibrate shell` fits to this set.
    let material = StvkNeoHookean {
        k_xx: 31.8,
        k_xy: -118.2,
        k_yy: 454.0,
        k_ss: 161.2,
        k_n1: 0.84,
        k_n2: 232.2,
        stiffening: None,
    };
    let tests: Vec<(SwatchTest, Vec<f64>)> = [Direction::Weft, Direction::Warp]
        .into_iter()
        .map(|d| {
            let stretches = targets.iter().filter(|t| t.direction == d).map(|t| t.stretch).collect();
            (SwatchTest::new(d, set.fabric.swatch.specimen(d), 0.004), stretches)
        })
        .collect();
    let mut g = c.benchmark_group("shell fit");
    g.sample_size(20);
    g.bench_function("objective (6.2): stockinette weft + warp clamped swatches, 6 targets each", |b| {
        b.iter(|| {
            for (test, stretches) in &tests {
                std::hint::black_box(test.run(&material, stretches).expect("equilibrium"));
            }
        })
    });
    g.finish();
}

criterion_group!(benches, bench_objective);
criterion_main!(benches);
