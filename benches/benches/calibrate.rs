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
//!
//! One evaluation of the yarn-level objective (Sec. 6.5.3, (6.11)) on the published `stock.pyp`
//! (100 vertices) against the same set's shell targets: the rest-shape estimation (Sec. 6.5.2)
//! and the tile's solves at the swarm's 7 targets per direction (weft and warp), at fixed search
//! points. A default `yarnhom calibrate yarn` run is about 704 such evaluations (swarm) and 61 at
//! 20 targets (COBYLA). Compared with: the thesis' yarn-level solver took 11 min 49 s per fabric
//! on a share of a 256-core server (Sec. 6.6).

use criterion::{Criterion, criterion_group, criterion_main};
use yarnhom_artifacts::pyp::parse_pyp;
use yarnhom_calib::data::set::{Direction, Face, MeasurementSet};
use yarnhom_calib::data::stitch_by_stitch::import_fabric;
use yarnhom_calib::data::targets::{Target, TargetPlan, targets};
use yarnhom_calib::experiments::bending_tests::BENDING_SPACING_M;
use yarnhom_calib::experiments::cantilever::CantileverTest;
use yarnhom_calib::experiments::pear_loop::PearLoopTest;
use yarnhom_calib::experiments::swatch::SwatchTest;
use yarnhom_calib::experiments::synth::{BendingPlan, HiddenEffect, ground_truth};
use yarnhom_calib::yarn::params::YarnBasis;
use yarnhom_calib::yarn::problem::{TargetSource, YarnProblem};
use yarnhom_calib::yarn::settings::YarnFitSettings;
use yarnhom_shell::StvkNeoHookean;

/// The real acrylic stockinette set and its shell targets.
fn stockinette_set() -> (MeasurementSet, Vec<Target>) {
    let data = format!("{}/../../shared/data/stitch-by-stitch-acrylic", env!("CARGO_MANIFEST_DIR"));
    let files = ["x", "y"].map(|d| format!("{data}/acrylic-stockinette-{d}.h5").into());
    let set = import_fabric(&files, 1).expect("the published files import").set;
    let targets = targets(&set, &TargetPlan::default()).expect("targets").targets;
    (set, targets)
}

/// The membrane `yarnhom calibrate shell` fits to the stockinette set.
fn stockinette_membrane() -> StvkNeoHookean {
    StvkNeoHookean {
        k_xx: 31.8,
        k_xy: -118.2,
        k_yy: 454.0,
        k_ss: 161.2,
        k_n1: 0.84,
        k_n2: 232.2,
        stiffening: None,
        jamming: None,
    }
}

fn bench_objective(c: &mut Criterion) {
    let (set, targets) = stockinette_set();
    let material = stockinette_membrane();
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

/// The yarn-level problem of the stockinette set on the published `stock.pyp`, as `yarnhom
/// calibrate yarn` builds it (the set names no yarn stiffness, so `k_s2` is fitted too).
fn stock_yarn_problem() -> YarnProblem {
    let (set, targets) = stockinette_set();
    let path = format!("{}/../../shared/data/hylc-patterns/stock.pyp", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(&path).expect("published stock.pyp");
    let pattern = parse_pyp(&text, "stock", None).expect("published pattern");
    let basis = YarnBasis::of_pattern(&pattern, None, 1000.0);
    let directions = [Direction::Weft, Direction::Warp]
        .into_iter()
        .map(|d| {
            let largest = targets.iter().filter(|t| t.direction == d).map(|t| t.stretch).fold(0.0, f64::max);
            (d, largest, set.fabric.swatch.specimen(d).width_m)
        })
        .collect();
    let settings = YarnFitSettings::default();
    YarnProblem {
        pattern,
        basis,
        source: TargetSource::Shell(stockinette_membrane()),
        directions,
        rest: settings.rest,
        comfort_force_n: settings.comfort_force_n,
    }
}

/// Fixed search points, as fractions of each coordinate's range: the midpoint and three
/// points spread over the box.
const SEARCH_FRACTIONS: [[f64; 6]; 4] = [
    [0.5, 0.5, 0.5, 0.5, 0.5, 0.5],
    [0.2, 0.7, 0.4, 0.8, 0.3, 0.6],
    [0.8, 0.3, 0.6, 0.3, 0.7, 0.4],
    [0.5, 0.5, 0.5, 0.5, 0.5, 0.85],
];

fn bench_yarn_objective(c: &mut Criterion) {
    let problem = stock_yarn_problem();
    let settings = YarnFitSettings::default();
    let targets = problem.targets(settings.swarm_targets).expect("shell targets");
    let points: Vec<Vec<f64>> = SEARCH_FRACTIONS
        .iter()
        .map(|f| problem.basis.bounds().iter().zip(f).map(|((lo, hi), t)| lo + t * (hi - lo)).collect())
        .collect();
    // The objective at each point, to compare runs of this bench across changes of the solver.
    for x in &points {
        let cost = problem.evaluate(x, &targets).map(|e| e.cost);
        eprintln!("yarn objective at {x:.4?}: g = {cost:.10?}");
    }
    let mut g = c.benchmark_group("yarn fit");
    g.sample_size(10);
    g.bench_function("objective (6.11): stock.pyp, rest shape + 7 targets x weft, warp, 4 points", |b| {
        b.iter(|| {
            for x in &points {
                std::hint::black_box(problem.evaluate(x, &targets).map(|e| e.cost).ok());
            }
        })
    });
    g.finish();
}

criterion_group!(benches, bench_objective, bench_bending, bench_yarn_objective);
criterion_main!(benches);
