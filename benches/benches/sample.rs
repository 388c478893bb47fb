//! Wall time of sampling sweeps (thesis App. A.3.1), lines in parallel on all cores, each
//! warm-started outward from zero strain: the published stockinette with its Table 4.1 yarn
//! model, the five 1D terms at 9 values each; and the published `stocktiniest` tile with the
//! `stock-small` row over a whole 9 x 5 plan (five 1D terms of 9, nine 2D terms of 5 x 5).
//! Compared with: thesis Table A.1, stockinette 1D terms (5 x 150 samples) in 13 s on 128
//! threads, about 2.2 thread-seconds per sample.

use criterion::{Criterion, criterion_group, criterion_main};
use yarnhom_artifacts::open::open_artifact;
use yarnhom_artifacts::{Pattern, YarnModel};
use yarnhom_rve::RveModel;
use yarnhom_rve::sample::{PlanRanges, SampleOptions, SamplePlan, sample_lines};

/// The tile of a published pattern with a Table 4.1 row.
fn tile(name: &str, row: &str) -> RveModel {
    let path = format!("{}/../../shared/data/hylc-patterns/{name}.pyp", env!("CARGO_MANIFEST_DIR"));
    let pattern = open_artifact::<Pattern>(&path).expect("published pattern").value;
    RveModel::new(&pattern, &YarnModel::table_4_1(row).expect("row")).expect("tile")
}

/// Benchmarks sampling `plan` on `model`, after one run whose convergence is printed.
fn bench_plan(c: &mut Criterion, name: &str, model: &RveModel, plan: &SamplePlan) {
    let lines = plan.lines();
    let options = SampleOptions::default();
    let results = sample_lines(model, plan, &lines, &options, &|_| {});
    let samples: Vec<_> = results.iter().flat_map(|l| &l.samples).collect();
    eprintln!(
        "{name}: {} samples, {} converged, {} Newton iterations, {} threads",
        samples.len(),
        samples.iter().filter(|s| s.converged).count(),
        samples.iter().map(|s| s.iterations).sum::<usize>(),
        rayon::current_num_threads()
    );
    let mut g = c.benchmark_group("sampling sweep");
    g.sample_size(10);
    g.bench_function(name, |b| b.iter(|| sample_lines(model, plan, &lines, &options, &|_| {})));
    g.finish();
}

fn bench_sweep(c: &mut Criterion) {
    let mut plan = SamplePlan::thesis(&PlanRanges::default(), 9, 3).expect("plan");
    plan.terms.retain(|t| t.axes.len() == 1);
    bench_plan(c, "stock 1D terms, 5 x 9 samples", &tile("stock", "stock"), &plan);
    let plan = SamplePlan::thesis(&PlanRanges::default(), 9, 5).expect("plan");
    bench_plan(c, "stocktiniest, 9 x 5 plan", &tile("stocktiniest", "stock-small"), &plan);
}

criterion_group!(benches, bench_sweep);
criterion_main!(benches);
