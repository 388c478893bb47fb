//! The yarn-level fit of a set with its own `[stitch]`: the tile is generated for the stitch,
//! the basis records it and holds `R_2` at the core's fraction of `R_1`; without `[stitch]`
//! everything is as before.

use std::time::Instant;

use yarnhom_artifacts::Pattern;
use yarnhom_calib::data::set::{
    Direction, Fabric, MeasurementSet, PatternSource, Phase, Stitch, StretchPoint, Swatch,
};
use yarnhom_calib::yarn::objective::COMFORT_FORCE_N;
use yarnhom_calib::yarn::params::YarnBasis;
use yarnhom_calib::yarn::problem::{RestShapeSettings, TargetSource, YarnProblem};

/// The authors' acrylic stockinette stitch (`sabetta/stitch-by-stitch`,
/// `code/fabric_simulations/stockinetteconfig.dat`).
const STOCKINETTE: Stitch = Stitch {
    length_m: 11.28e-3,
    yarn_radius_m: 0.74e-3,
    core_radius_m: Some(0.325e-3),
    courses_per_m: None,
    wales_per_m: None,
};

fn set(stitch: Option<Stitch>) -> MeasurementSet {
    let point = |stretch: f64, force_n: f64| StretchPoint {
        direction: Direction::Weft,
        stretch,
        force_n,
        compression: None,
        phase: Phase::Load,
        repeat: None,
    };
    MeasurementSet {
        fabric: Fabric {
            name: "acrylic stockinette".into(),
            pattern: "stockinette".into(),
            swatch: Swatch::default(),
            stitch,
            yarn: vec![],
        },
        stretch: vec![point(0.1, 1.0), point(0.2, 3.0)],
        bending: vec![],
        cantilever: vec![],
    }
}

/// The set's tile, as `calibrate yarn` builds it.
fn tile(set: &MeasurementSet) -> Pattern {
    let dir = tempfile::tempdir().expect("tempdir");
    match set.fabric.pattern_source(dir.path()).expect("a generator") {
        PatternSource::Generator(generator) => generator.generate().expect("generates"),
        PatternSource::File(path) => panic!("a file {}", path.display()),
    }
}

#[test]
fn the_basis_of_a_set_with_a_stitch_records_it_and_holds_r2_at_the_core() {
    let own = set(Some(STOCKINETTE));
    let pattern = tile(&own);
    let basis = YarnBasis::of_set(&own, &pattern, None);
    assert_eq!(basis.stitch, Some(STOCKINETTE));
    assert_eq!(basis.radius_m, 0.74e-3);
    let per_stitch = basis.tile_length_per_stitch_m.expect("a generated knit");
    assert!((per_stitch / 11.28e-3 - 1.0).abs() < 0.01, "{per_stitch}");
    let x: Vec<f64> = basis.bounds().iter().map(|(lo, hi)| 0.5 * (lo + hi)).collect();
    let p = basis.params(&x);
    assert!((p.r2_m / p.r1_m - 0.325 / 0.74).abs() < 1e-12, "{p:?}");

    // Without [stitch]: the default tile and the thesis' R_2, as before.
    let default = set(None);
    let pattern = tile(&default);
    let params = yarnhom_pattern::GeneratorParams::defaults_for("stockinette").expect("known");
    assert_eq!(pattern, yarnhom_pattern::generate("stockinette", &params).expect("generates"));
    let basis = YarnBasis::of_set(&default, &pattern, None);
    assert_eq!(basis.stitch, None);
    assert_eq!(basis.params(&x).r2_m, 0.25 * basis.r_est_m);
}

/// A problem on `set`'s tile whose targets are the tile's own response at `truth` (fractions of
/// the search box), along the courses and the wales up to 30% stretch.
fn problem(set: &MeasurementSet, truth: f64) -> YarnProblem {
    let pattern = tile(set);
    let basis = YarnBasis::of_set(set, &pattern, None);
    let x: Vec<f64> = basis.bounds().iter().map(|(lo, hi)| lo + truth * (hi - lo)).collect();
    YarnProblem {
        source: TargetSource::Yarn(basis.params(&x)),
        basis,
        pattern,
        directions: vec![(Direction::Weft, 0.3, 0.06), (Direction::Warp, 0.3, 0.06)],
        rest: RestShapeSettings { max_length_change: 0.2, max_resets: 8 },
        comfort_force_n: COMFORT_FORCE_N,
    }
}

/// One evaluation of the objective (rest shape, then 7 targets per direction) on the
/// stockinette's own stitch and on the default stitch. Minutes in a debug build; run with
/// `cargo test -p yarnhom-calib --test yarn_stitch -- --ignored --nocapture`.
#[test]
#[ignore = "timing: one yarn-objective evaluation per tile"]
fn one_objective_evaluation_on_the_own_and_the_default_stitch() {
    for (name, set) in [("own stitch", set(Some(STOCKINETTE))), ("default stitch", set(None))] {
        let problem = problem(&set, 0.5);
        let started = Instant::now();
        let targets = problem.targets(7);
        let truth_s = started.elapsed().as_secs_f64();
        let targets = match targets {
            Ok(t) => t,
            Err(e) => {
                eprintln!("{name}: the truth does not simulate ({e}) after {truth_s:.1} s");
                continue;
            }
        };
        let x: Vec<f64> = problem.basis.bounds().iter().map(|(lo, hi)| lo + 0.4 * (hi - lo)).collect();
        let started = Instant::now();
        let evaluation = problem.evaluate(&x, &targets);
        let s = started.elapsed().as_secs_f64();
        eprintln!(
            "{name}: {} vertices, R_est {:.4} mm, radius {:.3} mm; targets {truth_s:.1} s; one evaluation {s:.1} s: {}",
            problem.pattern.vertex_count(),
            problem.basis.r_est_m * 1e3,
            problem.basis.radius_m * 1e3,
            evaluation.map_or_else(|e| format!("failed: {e}"), |e| format!("g = {:.5}", e.cost)),
        );
    }
}
