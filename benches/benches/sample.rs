//! Wall time of a sampling sweep (thesis App. A.3.1) of the published stockinette with its
//! Table 4.1 yarn model: the five 1D terms at 9 values each, lines in parallel on all cores,
//! each warm-started outward from zero strain.
//! Compared with: thesis Table A.1, stockinette 1D terms (5 x 150 samples) in 13 s on 128
//! threads, about 2.2 thread-seconds per sample.

use criterion::{Criterion, criterion_group, criterion_main};
use yarnhom_artifacts::{YarnModel, pyp::parse_pyp};
use yarnhom_rve::RveModel;
use yarnhom_rve::sample::{PlanRanges, SampleOptions, SamplePlan, sample_lines};

fn bench_sweep(c: &mut Criterion) {
    let path = format!("{}/../../shared/data/hylc-patterns/stock.pyp", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let pattern = parse_pyp(&text, "stock", None).expect("published pattern");
    let model = RveModel::new(&pattern, &YarnModel::table_4_1("stock").expect("row")).expect("tile");
    let mut plan = SamplePlan::thesis(&PlanRanges::default(), 9, 3).expect("plan");
    plan.terms.retain(|t| t.axes.len() == 1);
    let lines = plan.lines();
    let options = SampleOptions::default();
    let results = sample_lines(&model, &plan, &lines, &options, &|_| {});
    let samples: Vec<_> = results.iter().flat_map(|l| &l.samples).collect();
    eprintln!(
        "stock 1D sweep: {} samples, {} converged, {} Newton iterations, {} threads",
        samples.len(),
        samples.iter().filter(|s| s.converged).count(),
        samples.iter().map(|s| s.iterations).sum::<usize>(),
        rayon::current_num_threads()
    );
    let mut g = c.benchmark_group("sampling sweep");
    g.sample_size(10);
    g.bench_function("stock 1D terms, 5 x 9 samples", |b| {
        b.iter(|| sample_lines(&model, &plan, &lines, &options, &|_| {}))
    });
    g.finish();
}

criterion_group!(benches, bench_sweep);
criterion_main!(benches);
