//! The sampling plan and sweep engine of App. A.3.1.

use std::collections::HashSet;
use std::sync::atomic::{AtomicUsize, Ordering};

use yarnhom_artifacts::{YarnModel, pyp::parse_pyp};
use yarnhom_fit::sampled_ranges;
use yarnhom_rve::RveModel;
use yarnhom_rve::sample::{
    AxisKind, LineResult, PlanRanges, SampleError, SampleOptions, SamplePlan, SampleRanges, SweepLine,
    axis_values, plane_axes, sample_lines, shard_lines,
};

fn stocktiniest() -> RveModel {
    let name = "stocktiniest";
    let path = format!("{}/../../../shared/data/hylc-patterns/{name}.pyp", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let pattern = parse_pyp(&text, name, None).expect("published pattern imports");
    RveModel::new(&pattern, &YarnModel::table_4_1("stock-small").expect("row")).expect("tile")
}

fn spacings(values: &[f64]) -> Vec<f64> {
    values.windows(2).map(|w| w[1] - w[0]).collect()
}

#[test]
fn ranges_must_contain_zero_and_stay_valid_strains() {
    let d = SampleRanges::default();
    assert_eq!(SampleRanges::new(d.lower, d.upper), Ok(d));
    let scale: Vec<f64> = d.lower.iter().zip(d.upper).map(|(l, u)| l.abs().max(u)).collect();
    assert_eq!(scale, [0.78, 0.75, 0.78, 200.0, 230.0], "the published stockinette's 1D ranges");
    let broken = |k: usize, lower: f64, upper: f64| {
        let (mut l, mut u) = (d.lower, d.upper);
        (l[k], u[k]) = (lower, upper);
        matches!(SampleRanges::new(l, u), Err(SampleError::Range { .. }))
    };
    assert!(broken(0, 0.1, 0.5), "0 must lie inside");
    assert!(broken(3, -1.0, 0.0), "0 must lie strictly inside");
    assert!(broken(0, -1.0, 0.5), "sx > -1");
    assert!(broken(2, -1.5, 0.5), "sy > -1");
    assert!(broken(1, -0.5, 1.0), "|sa| < 1");
    assert!(broken(4, -1.0, f64::INFINITY), "finite");
    assert!(broken(4, f64::NAN, 1.0), "finite");
}

/// The default ranges are those `stock1.json` was sampled over, as its control points give them
/// back (`yarnhom_fit::ranges`).
#[test]
fn the_default_ranges_are_those_of_the_published_stockinette_fit() {
    let path = format!("{}/../../../shared/data/hylc-materials/stock1.json", env!("CARGO_MANIFEST_DIR"));
    let published = sampled_ranges(
        &yarnhom_artifacts::open::open_artifact::<yarnhom_artifacts::Spline>(&path)
            .map(|o| o.value)
            .expect("stock1.json"),
    )
    .expect("ranges");
    let close = |a: [f64; 2], b: [f64; 2]| a.iter().zip(b).all(|(x, y)| (x - y).abs() <= 1e-9 * y.abs());
    let ranges = PlanRanges::default();
    for (axis, &range) in published.single.iter().enumerate() {
        let ours = [ranges.single.lower[axis], ranges.single.upper[axis]];
        assert!(close(ours, range), "1D {axis}: {ours:?} vs {range:?}");
    }
    assert_eq!(published.planes.len(), ranges.planes.len());
    for (plane, (axes, range)) in ranges.planes.iter().zip(&published.planes) {
        assert_eq!(plane.axes, axes.map(usize::from));
        assert!(
            close(plane.ranges[0], range[0]) && close(plane.ranges[1], range[1]),
            "{plane:?} vs {range:?}"
        );
    }
}

#[test]
fn plan_ranges_need_every_plane_once_and_valid() {
    let d = PlanRanges::default();
    assert_eq!(PlanRanges::new(d.single, d.planes.clone()), Ok(d.clone()));
    assert_eq!(d.planes.iter().map(|p| p.axes).collect::<Vec<_>>(), plane_axes());
    let mut missing = d.planes.clone();
    missing.pop();
    assert!(matches!(PlanRanges::new(d.single, missing), Err(SampleError::Planes(_))));
    let mut swapped = d.planes.clone();
    swapped.swap(0, 1);
    assert!(matches!(PlanRanges::new(d.single, swapped), Err(SampleError::Planes(_))));
    let mut outside = d.clone();
    outside.plane_mut([1, 4]).expect("sa,ky").ranges[0] = [-0.6, 1.0];
    assert!(matches!(
        PlanRanges::new(outside.single, outside.planes),
        Err(SampleError::Range { name: "sa", .. })
    ));
    let mut d = d;
    assert!(d.plane_mut([3, 4]).is_none(), "kx and ky are never sampled together");
}

#[test]
fn axis_values_are_ascending_with_exact_ends_and_zero() {
    for kind in [AxisKind::Symmetric, AxisKind::Compression] {
        for (lower, upper) in [(-0.3, 0.8), (-0.75, 0.75), (-200.0, 200.0), (-0.9, 0.05), (-0.01, 3.0)] {
            for n in [3, 4, 5, 9, 50, 150] {
                let v = axis_values(lower, upper, n, kind);
                assert_eq!(v.len(), n);
                assert_eq!((v[0], v[n - 1]), (lower, upper), "{kind:?} [{lower}, {upper}] n={n}");
                assert!(v.windows(2).all(|w| w[0] < w[1]), "{kind:?} [{lower}, {upper}] n={n}: {v:?}");
                assert_eq!(v.iter().filter(|x| **x == 0.0).count(), 1, "{v:?}");
                assert!(v.iter().all(|x| x.to_bits() != (-0.0f64).to_bits()), "no negative zero");
            }
        }
    }
}

#[test]
fn symmetric_axes_are_densest_around_zero_and_mirror_symmetric() {
    for n in [5, 51, 150] {
        let v = axis_values(-200.0, 200.0, n, AxisKind::Symmetric);
        let d = spacings(&v);
        let zero = v.iter().position(|x| *x == 0.0).expect("0");
        assert!(d[zero] < d[n - 2] && d[zero - 1] < d[0], "{v:?}");
        if n % 2 == 1 {
            assert_eq!(zero, n / 2);
            assert!(v.iter().zip(v.iter().rev()).all(|(a, b)| (a + b).abs() <= 1e-12 * 200.0), "{v:?}");
        }
        // Spacing grows monotonically away from 0 on both sides.
        assert!(d[zero..].windows(2).all(|w| w[0] < w[1]));
        assert!(d[..zero].windows(2).all(|w| w[0] > w[1]));
    }
    let thesis = spacings(&axis_values(-0.75, 0.75, 150, AxisKind::Symmetric));
    assert!(thesis[0] > 3.0 * thesis[74], "ends sampled over 3x more sparsely than the origin");
}

#[test]
fn stretch_axes_are_densest_towards_compression() {
    for n in [5, 9, 50, 150] {
        let v = axis_values(-0.3, 0.8, n, AxisKind::Compression);
        let d = spacings(&v);
        assert!(d[0] < d[n - 2], "{v:?}");
        let zero = v.iter().position(|x| *x == 0.0).expect("0");
        assert!(d[..zero].windows(2).all(|w| w[0] < w[1]) && d[zero..].windows(2).all(|w| w[0] < w[1]));
        // More samples in compression than a uniform spacing would give.
        let uniform = (n - 1) as f64 * 0.3 / 1.1;
        assert!(zero as f64 >= uniform.round(), "n={n}: {zero} samples in compression, uniform {uniform}");
    }
    let thesis = spacings(&axis_values(-0.3, 0.8, 150, AxisKind::Compression));
    assert!(thesis[148] > 10.0 * thesis[0]);
    assert!(thesis.windows(2).all(|w| w[0] < w[1] * (1.0 + 1e-2)), "spacing grows (up to the seam at 0)");
}

#[test]
fn the_thesis_plan_has_five_1d_and_nine_2d_terms_without_kx_ky() {
    let ranges = PlanRanges::default();
    let plan = SamplePlan::thesis(&ranges, 150, 50).expect("plan");
    assert_eq!(plan.sample_count(), 750 + 22500, "App. A.3.1");
    let axes: Vec<Vec<usize>> = plan.terms.iter().map(|t| t.axes.clone()).collect();
    assert_eq!(&axes[..5], &[vec![0], vec![1], vec![2], vec![3], vec![4]]);
    assert_eq!(axes.len(), 14);
    assert!(!axes.contains(&vec![3, 4]), "bending along one direction at a time (Sec. 4.1.1)");
    assert!(axes[5..].iter().all(|a| a.len() == 2 && a[0] < a[1]));
    assert_eq!(axes[5..].iter().collect::<HashSet<_>>().len(), 9);
    for term in &plan.terms[..5] {
        let (axis, r) = (term.axes[0], ranges.single);
        assert_eq!(term.values[0], axis_values(r.lower[axis], r.upper[axis], 150, AxisKind::of(axis)));
    }
    for (term, plane) in plan.terms[5..].iter().zip(&ranges.planes) {
        assert_eq!(term.axes, plane.axes, "the 2D terms in the order of their ranges");
        for (slot, &axis) in term.axes.iter().enumerate() {
            let [lower, upper] = plane.ranges[slot];
            assert_eq!(term.values[slot], axis_values(lower, upper, 50, AxisKind::of(axis)));
        }
    }
    assert_eq!(SamplePlan::thesis(&ranges, 2, 50), Err(SampleError::TooFewValues(2)));
}

#[test]
fn lines_walk_outward_from_the_origin_and_cover_every_sample_once() {
    let plan = SamplePlan::thesis(&PlanRanges::default(), 9, 6).expect("plan");
    let lines = plan.lines();
    assert_eq!(lines, plan.lines(), "deterministic");
    assert_eq!(lines.len(), 5 * 2 + 9 * 6 * 2);
    let mut seen = HashSet::new();
    for (k, line) in lines.iter().enumerate() {
        assert_eq!(line.index, k);
        let term = &plan.terms[line.term];
        let first = term.strain(line.points[0])[term.axes[0]];
        let origin_next = term.values[0].iter().position(|x| *x == 0.0).expect("0");
        assert!(line.points[0][0].abs_diff(origin_next) <= 1, "starts next to the origin: {first}");
        for w in line.points.windows(2) {
            assert_eq!(w[0][1], w[1][1], "along the first axis");
            assert_eq!(w[0][0].abs_diff(w[1][0]), 1, "neighbours");
            let outward = |p: [usize; 2]| term.strain(p)[term.axes[0]].abs();
            assert!(outward(w[1]) > outward(w[0]), "outward");
        }
        for p in &line.points {
            assert!(seen.insert((line.term, *p)), "sample {p:?} of term {} twice", line.term);
        }
    }
    assert_eq!(seen.len(), plan.sample_count());
}

#[test]
fn shards_deal_every_line_exactly_once() {
    let lines = SamplePlan::thesis(&PlanRanges::default(), 9, 5).expect("plan").lines();
    for count in [1, 2, 3, 7, 200] {
        let mut union: Vec<SweepLine> = (0..count).flat_map(|i| shard_lines(&lines, i, count)).collect();
        union.sort_by_key(|l| l.index);
        assert_eq!(union, lines, "{count} shards");
    }
}

/// A plan of a few small terms: sx and kx alone, and the (sx, sa) grid.
fn tiny_plan() -> SamplePlan {
    let mut plan = SamplePlan::thesis(&PlanRanges::default(), 5, 3).expect("plan");
    plan.terms = [0, 3, 5].into_iter().map(|t| plan.terms[t].clone()).collect();
    assert_eq!(plan.terms[2].axes, [0, 1]);
    plan
}

fn without_seconds(mut results: Vec<LineResult>) -> Vec<LineResult> {
    for sample in results.iter_mut().flat_map(|r| r.samples.iter_mut()) {
        sample.seconds = 0.0;
    }
    results
}

fn run_on(threads: usize, model: &RveModel, plan: &SamplePlan, lines: &[SweepLine]) -> Vec<LineResult> {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("pool");
    let options = SampleOptions { geometry: true, ..SampleOptions::default() };
    let done = AtomicUsize::new(0);
    let results = pool.install(|| {
        sample_lines(model, plan, lines, &options, &|_| {
            done.fetch_add(1, Ordering::Relaxed);
        })
    });
    assert_eq!(done.into_inner(), lines.len(), "one callback per line");
    without_seconds(results)
}

#[test]
fn sweeps_are_identical_for_any_thread_count_and_sharding() {
    let model = stocktiniest();
    let plan = tiny_plan();
    let lines = plan.lines();
    let serial = run_on(1, &model, &plan, &lines);
    assert_eq!(serial.iter().map(|r| r.line).collect::<Vec<_>>(), (0..lines.len()).collect::<Vec<_>>());
    for (result, line) in serial.iter().zip(&lines) {
        assert_eq!(result.samples.len(), line.points.len());
        for (k, (sample, point)) in result.samples.iter().zip(&line.points).enumerate() {
            assert_eq!(sample.term, line.term);
            assert_eq!(sample.index, point.map(|i| i as u32));
            assert_eq!(sample.strain, plan.terms[line.term].strain(*point));
            let warm = k > 0 && result.samples[k - 1].converged;
            assert_eq!(sample.warm_started, warm, "cold at the start and after a failure");
            assert_eq!(sample.energy_density_j_m2.is_some(), sample.converged);
            assert_eq!(sample.stress.is_some(), sample.converged);
            assert_eq!(sample.positions_m.as_ref().map(Vec::len), Some(model.vertices));
            assert_eq!(sample.edge_twist_rad.as_ref().map(Vec::len), Some(model.vertices));
        }
    }
    let converged = serial.iter().flat_map(|r| &r.samples).filter(|s| s.converged).count();
    assert!(converged * 10 >= 9 * plan.sample_count(), "{converged} of {} converged", plan.sample_count());
    let rest = serial.iter().flat_map(|r| &r.samples).find(|s| s.strain == [0.0; 5]).expect("origin");
    assert!(rest.energy_density_j_m2.is_some() && !rest.warm_started);

    assert_eq!(run_on(2, &model, &plan, &lines), serial, "2 threads");
    let mut sharded: Vec<LineResult> =
        (0..2).flat_map(|i| run_on(2, &model, &plan, &shard_lines(&lines, i, 2))).collect();
    sharded.sort_by_key(|r| r.line);
    assert_eq!(sharded, serial, "2 shards");
}
