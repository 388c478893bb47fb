//! Wall time of one periodic tile solve (thesis Ch. 3) on the published patterns with their
//! Table 4.1 yarn models, cold (affine start), warm-started from the solution at a nearby
//! strain (1% less stretch or curvature), and started by the secant predictor through the
//! solutions at 1% and 2% less (`secant_start`, as the sampler does along its sweep lines).
//! Compared with: thesis Table A.1, about 5.7 thread-seconds per sample for stockinette and 25
//! for rib; yarnhom's target is under 0.2 s per cold stock solve on one core. Stock at sx=0.3 is
//! also solved with additive CCD steps in place of the step limit.

use criterion::{Criterion, criterion_group, criterion_main};
use yarnhom_artifacts::{YarnModel, pyp::parse_pyp};
use yarnhom_geom::MacroStrain;
use yarnhom_rve::homogenize::{secant_start, solve_at};
use yarnhom_rve::{RveModel, SolveOptions, StepControl};

fn tile(name: &str) -> RveModel {
    let path = format!("{}/../../shared/data/hylc-patterns/{name}.pyp", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let pattern = parse_pyp(&text, name, None).expect("published pattern");
    RveModel::new(&pattern, &YarnModel::table_4_1(name).expect("Table 4.1 row")).expect("tile")
}

fn bench_solves(c: &mut Criterion) {
    let mut g = c.benchmark_group("rve solve");
    g.sample_size(10);
    for name in ["stock", "rib"] {
        let model = tile(name);
        for (label, [before, last, strain]) in
            [("sx=0.3", ["sx=0.294", "sx=0.297", "sx=0.3"]), ("kx=40", ["kx=39.2", "kx=39.6", "kx=40"])]
        {
            let [before, last, strain]: [MacroStrain; 3] =
                [before, last, strain].map(|s| s.parse().expect("strain"));
            let (cold, _) = solve_at(&model, &strain, None, &SolveOptions::default());
            let (_, first) = solve_at(&model, &before, None, &SolveOptions::default());
            let (_, nearby) = solve_at(&model, &last, Some(&first), &SolveOptions::warm_started());
            let (warm, _) = solve_at(&model, &strain, Some(&nearby), &SolveOptions::warm_started());
            let predict = || secant_start(&model, &strain, (&last, &nearby), (&before, &first));
            let (predicted, _) = solve_at(&model, &strain, Some(&predict()), &SolveOptions::warm_started());
            eprintln!(
                "{name} {label}: {} vertices, {} iterations cold, {} warm, {} predicted; converged {} {} {}",
                model.vertices,
                cold.iterations,
                warm.iterations,
                predicted.iterations,
                cold.converged,
                warm.converged,
                predicted.converged
            );
            g.bench_function(format!("{name} {label} cold"), |b| {
                b.iter(|| solve_at(&model, &strain, None, &SolveOptions::default()))
            });
            g.bench_function(format!("{name} {label} warm"), |b| {
                b.iter(|| solve_at(&model, &strain, Some(&nearby), &SolveOptions::warm_started()))
            });
            g.bench_function(format!("{name} {label} predicted"), |b| {
                b.iter(|| solve_at(&model, &strain, Some(&predict()), &SolveOptions::warm_started()))
            });
        }
    }
    let model = tile("stock");
    let strain: MacroStrain = "sx=0.3".parse().expect("strain");
    let ccd = SolveOptions {
        step_control: StepControl::AdditiveCcd { min_separation_radii: 0.5 },
        ..SolveOptions::default()
    };
    eprintln!("stock sx=0.3 ccd: {} iterations", solve_at(&model, &strain, None, &ccd).0.iterations);
    g.bench_function("stock sx=0.3 cold ccd", |b| b.iter(|| solve_at(&model, &strain, None, &ccd)));
    g.finish();
}

criterion_group!(benches, bench_solves);
criterion_main!(benches);
