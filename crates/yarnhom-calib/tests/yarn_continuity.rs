//! The yarn-level objective (6.11) is continuous at round-off: moving one coordinate of a
//! search point by 1e-12 relative moves `g` by far less than 1e-6 relative, so fits do not
//! depend on the build, the thread count or the order of floating-point sums.
//!
//! The problem is the one `calibrate yarn` builds for the real acrylic stockinette on the
//! published `stock.pyp` (the bench `calibrate -- "yarn fit"`), at that bench's search points.

use yarnhom_artifacts::pyp::parse_pyp;
use yarnhom_calib::data::set::Direction;
use yarnhom_calib::yarn::objective::DirectionTargets;
use yarnhom_calib::yarn::params::YarnBasis;
use yarnhom_calib::yarn::problem::{TargetSource, YarnProblem};
use yarnhom_calib::yarn::settings::YarnFitSettings;
use yarnhom_shell::StvkNeoHookean;

/// The membrane `calibrate shell` fits to the acrylic stockinette set (the bench's).
const STOCKINETTE_MEMBRANE: StvkNeoHookean = StvkNeoHookean {
    k_xx: 31.8,
    k_xy: -118.2,
    k_yy: 454.0,
    k_ss: 161.2,
    k_n1: 0.84,
    k_n2: 232.2,
    stiffening: None,
    jamming: None,
};

/// The yarn-level problem of the stockinette membrane on `stock.pyp`: weft and warp to the
/// set's largest stretches (0.6 and 0.4) on its 5 cm specimens.
fn stock_problem() -> YarnProblem {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data/hylc-patterns/stock.pyp");
    let text = std::fs::read_to_string(path).expect("published stock.pyp");
    let pattern = parse_pyp(&text, "stock", None).expect("published pattern");
    let basis = YarnBasis::of_pattern(&pattern, None, 1000.0);
    let settings = YarnFitSettings::default();
    YarnProblem {
        pattern,
        basis,
        source: TargetSource::Shell(STOCKINETTE_MEMBRANE),
        directions: vec![(Direction::Weft, 0.6, 0.05), (Direction::Warp, 0.4, 0.05)],
        rest: settings.rest,
        comfort_force_n: settings.comfort_force_n,
    }
}

/// Search points as fractions of each coordinate's range (the bench's): the midpoint and
/// three points spread over the box.
const SEARCH_FRACTIONS: [[f64; 6]; 4] = [
    [0.5, 0.5, 0.5, 0.5, 0.5, 0.5],
    [0.2, 0.7, 0.4, 0.8, 0.3, 0.6],
    [0.8, 0.3, 0.6, 0.3, 0.7, 0.4],
    [0.5, 0.5, 0.5, 0.5, 0.5, 0.85],
];

/// The largest relative change of `g` over every coordinate of `x` scaled by `1 + eps`.
fn largest_relative_change(problem: &YarnProblem, targets: &[DirectionTargets], x: &[f64], eps: f64) -> f64 {
    let g = problem.evaluate(x, targets).expect("evaluates").cost;
    (0..x.len())
        .map(|j| {
            let mut moved = x.to_vec();
            moved[j] *= 1.0 + eps;
            let h = problem.evaluate(&moved, targets).expect("evaluates").cost;
            eprintln!("x = {x:.4?}, coordinate {j} x (1 + {eps:e}): g {g:.12e} -> {h:.12e}");
            ((h - g) / g).abs()
        })
        .fold(0.0, f64::max)
}

fn points(problem: &YarnProblem) -> Vec<Vec<f64>> {
    SEARCH_FRACTIONS
        .iter()
        .map(|f| problem.basis.bounds().iter().zip(f).map(|((lo, hi), t)| lo + t * (hi - lo)).collect())
        .collect()
}

#[test]
fn the_objective_is_continuous_at_round_off_at_the_box_midpoint() {
    let problem = stock_problem();
    let targets = problem.targets(YarnFitSettings::default().swarm_targets).expect("shell targets");
    let change = largest_relative_change(&problem, &targets, &points(&problem)[0], 1e-12);
    assert!(change < 1e-6, "g moves by {change:e} relative");
}

/// Every search point, at 1e-12 and 1e-13 (about 3 min on 2 cores; the largest change
/// measured is 4.1e-8 relative).
#[test]
#[ignore = "about 3 min: the four search points of the bench"]
fn the_objective_is_continuous_at_round_off_at_every_search_point() {
    let problem = stock_problem();
    let targets = problem.targets(YarnFitSettings::default().swarm_targets).expect("shell targets");
    for x in points(&problem) {
        for eps in [1e-12, 1e-13] {
            let change = largest_relative_change(&problem, &targets, &x, eps);
            assert!(change < 1e-6, "at {x:?}, eps {eps:e}: g moves by {change:e} relative");
        }
    }
}

/// The objective is the same to the bit on one thread and on several: the rest-shape
/// estimation is serial and the targets are solved in parallel into their own slots.
#[test]
fn the_objective_is_the_same_for_any_thread_count() {
    let problem = stock_problem();
    let targets = problem.targets(YarnFitSettings::default().swarm_targets).expect("shell targets");
    let x = &points(&problem)[1];
    let on = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("a pool");
        pool.install(|| problem.evaluate(x, &targets).expect("evaluates").cost)
    };
    assert_eq!(on(1).to_bits(), on(3).to_bits());
}
