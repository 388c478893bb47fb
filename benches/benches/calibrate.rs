//! The simulation in the loop of the shell fit (thesis Sec. 6.3.1, (6.2)): one evaluation of
//! the objective on the real acrylic stockinette set (`shared/data/stitch-by-stitch-acrylic`),
//! i.e. its weft and warp clamped swatches simulated to equilibrium at their 6 targets each,
//! with the membrane `yarnhom calibrate shell` fits to it.
//!
//! Compared with: the thesis' shell fit has no published time; its yarn-level local solver took
//! 11 min 49 s per fabric on a share of a 256-core server (Sec. 6.6). A whole shell fit is
//! 140 to 320 of these evaluations (`yarnhom calibrate shell` prints its count and wall time).
//!
//! The bending fit's evaluation (Sec. 6.3.2): the thesis' 7 pear loops (clamp distances 0.3 to
//! 3.4 cm) along one direction, and 7 cantilevers per face, each simulated to equilibrium.
//! Compared with: no published time; the thesis reports only the fit's error (5.61% average).

use criterion::{Criterion, criterion_group, criterion_main};
use yarnhom_calib::bending_fit::BENDING_SPACING_M;
use yarnhom_calib::cantilever::CantileverTest;
use yarnhom_calib::measure::{Direction, Face};
use yarnhom_calib::pear_loop::PearLoopTest;
use yarnhom_calib::stitch_by_stitch::import_fabric;
use yarnhom_calib::swatch::SwatchTest;
use yarnhom_calib::synth::{BendingPlan, HiddenEffect, ground_truth};
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

fn bench_bending(c: &mut Criterion) {
    // The synthetic sets' base truth and bending tests.
    let truth = ground_truth(HiddenEffect::None, 0.0);
    let (membrane, bending) = (truth.membrane, truth.bending);
    let plan = BendingPlan::default();
    let distances = plan.clamp_distances_m;
    let overhangs: Vec<(Face, f64)> =
        Face::ALL.into_iter().flat_map(|f| plan.overhangs_m.iter().map(move |o| (f, *o))).collect();
    let pear = PearLoopTest::new(Direction::Weft, 0.1, 0.25, BENDING_SPACING_M);
    let cantilever = CantileverTest {
        direction: Direction::Weft,
        areal_density_kg_m2: 0.25,
        spacing_m: BENDING_SPACING_M,
    };
    let mut g = c.benchmark_group("bending fit");
    g.sample_size(10);
    g.bench_function("pear loop: 7 clamp distances, 10 cm strip, 1e-6 J", |b| {
        b.iter(|| std::hint::black_box(pear.run(&membrane, &bending, &distances).expect("equilibrium")))
    });
    g.bench_function("cantilever: 7 overhangs x 2 faces, 1e-6 J", |b| {
        b.iter(|| std::hint::black_box(cantilever.run(&membrane, &bending, &overhangs).expect("equilibrium")))
    });
    g.finish();
}

criterion_group!(benches, bench_objective, bench_bending);
criterion_main!(benches);
