//! The real acrylic swatches of `shared/data/stitch-by-stitch-acrylic` calibrated end to end:
//! the README's shell-fit and diagnosis tables (about 4 min on 2 cores; `-- --nocapture`
//! prints them).

#![cfg(feature = "hdf5")]

use yarnhom_calib::cause::CauseId;
use yarnhom_calib::data::set::PatternSource;
use yarnhom_calib::data::stitch_by_stitch::import_fabric;
use yarnhom_calib::diagnosis::diagnose;
use yarnhom_calib::diagnosis::settings::DiagnoseSettings;
use yarnhom_calib::optimize::swarm::SwarmSettings;
use yarnhom_calib::shell::fit::{ShellFitSettings, fit_shell};
use yarnhom_calib::shell::membrane::MembraneModel;
use yarnhom_calib::yarn::fit::fit_yarn;
use yarnhom_calib::yarn::params::YarnBasis;
use yarnhom_calib::yarn::problem::YarnProblem;
use yarnhom_calib::yarn::settings::YarnFitSettings;

const DATA: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data/stitch-by-stitch-acrylic");

#[test]
fn real_acrylic_swatches_fit_and_diagnose() {
    let (mut force, mut compression) = (Vec::new(), Vec::new());
    let (mut jammed_force, mut jammed_compression) = (Vec::new(), Vec::new());
    for pattern in ["stockinette", "garter", "rib", "seed"] {
        let files = ["x", "y"].map(|d| format!("{DATA}/acrylic-{pattern}-{d}.h5").into());
        let set = import_fabric(&files, 1).expect("imports").set;
        let fit = fit_shell(&set, &ShellFitSettings::default()).expect("fits");
        let refinement = fit.mesh_refinement_change.expect("the finer mesh has an equilibrium");
        eprintln!(
            "{pattern}: force {:.1}%, compression {:.1}%, refinement {:.1}%, {} iterations, {:.0} s",
            100.0 * fit.errors.force,
            100.0 * fit.errors.compression.expect("measured"),
            100.0 * refinement,
            fit.optimizer.iterations,
            fit.wall_time_s
        );
        assert!(refinement < 0.05, "{pattern}: the mesh resolves the swatch");
        assert_eq!(fit.unconstrained, vec!["k_ss".to_string()], "no bias tests in these files");
        force.push(fit.errors.force);
        compression.push(fit.errors.compression.expect("measured"));

        let settings = ShellFitSettings { model: MembraneModel::StvkNeoHookeanJamming, ..Default::default() };
        let jammed = fit_shell(&set, &settings).expect("fits");
        eprintln!(
            "  with jamming: force {:.1}%, compression {:.1}%, {:?}",
            100.0 * jammed.errors.force,
            100.0 * jammed.errors.compression.expect("measured"),
            jammed.material.jamming
        );
        jammed_force.push(jammed.errors.force);
        jammed_compression.push(jammed.errors.compression.expect("measured"));

        let d = diagnose(&set, &DiagnoseSettings::default()).expect("diagnoses");
        eprintln!(
            "  diagnosis: {} ({:.3} -> {:.3}), {:.0} s",
            d.cause.id.as_str(),
            d.gain.heldout_error_before,
            d.gain.heldout_error_after,
            d.wall_time_s
        );
        assert_ne!(
            d.cause.id,
            CauseId::None,
            "{pattern}: the base StVK misses these fabrics by far more than their noise"
        );
        let hysteresis = d.candidates.iter().find(|c| c.id == "friction-hysteresis").expect("listed");
        assert!(!hysteresis.testable, "the videos record loading only");
    }
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    eprintln!("mean: force {:.1}%, compression {:.1}%", 100.0 * mean(&force), 100.0 * mean(&compression));
    eprintln!(
        "mean with jamming: force {:.1}%, compression {:.1}%",
        100.0 * mean(&jammed_force),
        100.0 * mean(&jammed_compression)
    );
    // Thesis Sec. 6.3.1 over 33 fabrics: 17.59% force, 16.84% compression. With (6.1) alone
    // these four meet the force figure and miss the compression one (the discrepancy the
    // diagnosis names); with the jamming it finds (`two-phase-contact`) they meet both.
    assert!(mean(&force) <= 0.1759, "force error {}", mean(&force));
    assert!(mean(&compression) > 0.1684, "(6.1) alone meets the compression figure: {}", mean(&compression));
    assert!(mean(&jammed_force) <= 0.1759, "force error with jamming {}", mean(&jammed_force));
    assert!(
        mean(&jammed_compression) <= 0.1684,
        "compression error with jamming {}",
        mean(&jammed_compression)
    );
    for (j, plain) in jammed_compression.iter().zip(&compression) {
        assert!(*j <= plain + 0.01, "the nested fit does not lose compression: {j} vs {plain}");
    }
}

/// The authors' yarn radius and core radius per swatch (m; `sabetta/stitch-by-stitch`,
/// `code/fabric_simulations/*config.dat`), which the importer writes into each set's `[stitch]`.
const AUTHORS_RADII_M: [(&str, f64, f64); 4] = [
    ("stockinette", 0.74e-3, 0.325e-3),
    ("garter", 0.54e-3, 0.255e-3),
    ("rib", 1.18e-3, 0.41e-3),
    ("seed", 1.20e-3, 0.285e-3),
];

/// The yarn-level problem of the acrylic `pattern` set on the tile generated for its own
/// stitch, from its shell fit, as `calibrate yarn` builds it.
fn own_stitch_problem(pattern: &str, settings: &YarnFitSettings) -> YarnProblem {
    let files = ["x", "y"].map(|d| format!("{DATA}/acrylic-{pattern}-{d}.h5").into());
    let set = import_fabric(&files, 1).expect("imports").set;
    let shell = fit_shell(&set, &ShellFitSettings::default()).expect("fits");
    let dir = tempfile::tempdir().expect("tempdir");
    let tile = match set.fabric.pattern_source(dir.path()).expect("a generator") {
        PatternSource::Generator(generator) => generator.generate().expect("generates"),
        PatternSource::File(path) => panic!("a file {}", path.display()),
    };
    let basis = YarnBasis::of_set(&set, &tile, None);
    YarnProblem::from_shell_fit(tile, basis, &shell, &set, settings).expect("a problem")
}

/// The yarn-level estimation (Sec. 6.5) of the four acrylic swatches on tiles generated for
/// their own stitch, with the swarm and local budget of the validation table's reduced run
/// (16 particles, 4 generations, 20 COBYLA evaluations): Fig. 6.15's errors per swatch and
/// direction, the fitted radii beside the authors', the wall time. Prints the table of
/// docs/validation.md ("The real acrylic swatches"); about 20 min on 2 cores:
/// `cargo test -p yarnhom-calib --features hdf5 --test real_swatches -- --ignored --nocapture`.
#[test]
#[ignore = "about 20 min on 2 cores: four yarn-level fits"]
fn real_acrylic_swatches_at_yarn_level_on_their_own_stitch() {
    let settings = YarnFitSettings {
        swarm: SwarmSettings { particles: 16, generations: 4, ..SwarmSettings::default() },
        local_budget: 20,
        ..YarnFitSettings::default()
    };
    let mut comfort = Vec::new();
    for (pattern, yarn_radius_m, core_radius_m) in AUTHORS_RADII_M {
        let problem = own_stitch_problem(pattern, &settings);
        let stitch = problem.basis.stitch.expect("the importer writes the authors' stitch");
        assert_eq!((stitch.yarn_radius_m, stitch.core_radius_m), (yarn_radius_m, Some(core_radius_m)));
        let fitted = fit_yarn(&problem, pattern, &settings, None, &|_| {}).expect("fits");
        let fit = &fitted.fit;
        let line: Vec<String> = fit
            .errors
            .iter()
            .map(|e| {
                comfort.push(e.comfort_stress);
                format!(
                    "{} {:.1}% / {} / {:.1}%",
                    e.direction,
                    100.0 * e.comfort_stress,
                    e.power_stress.map_or("-".into(), |p| format!("{:.1}%", 100.0 * p)),
                    100.0 * e.compression
                )
            })
            .collect();
        eprintln!(
            "{pattern} ({} vertices): {}; R_1 {:.3} mm (yarn radius {:.3}), R_2 {:.3} mm (core {:.3}); g {:.4}; {:.0} s",
            problem.pattern.vertex_count(),
            line.join("; "),
            fit.params.r1_m * 1e3,
            yarn_radius_m * 1e3,
            fit.params.r2_m * 1e3,
            core_radius_m * 1e3,
            fit.cost,
            fit.wall_time_s
        );
        assert!(fit.cost.is_finite() && fit.errors.iter().all(|e| e.comfort_stress.is_finite()));
    }
    let within = comfort.iter().filter(|e| **e <= 0.10).count();
    eprintln!("comfort error within 10% in {within} of {} swatch directions", comfort.len());
}

/// Issue 30's continuity at round-off on a slack generated tile: the acrylic stockinette's own
/// stitch, the search fractions of `yarn_continuity.rs`, each coordinate scaled by `1 + 1e-12`.
#[test]
#[ignore = "fails: g moves by 1.1e-2, 9.7e-3, 6.7e-3 and 3.2e-9 relative at the four points: the last \
            equilibrium of the rest-shape estimation and the compression of zero orthogonal stress are \
            not unique on this slack tile (docs/validation.md)"]
fn the_objective_on_the_generated_acrylic_stockinette_is_continuous_at_round_off() {
    let problem = own_stitch_problem("stockinette", &YarnFitSettings::default());
    let targets = problem.targets(YarnFitSettings::default().swarm_targets).expect("shell targets");
    let fractions = [
        [0.5, 0.5, 0.5, 0.5, 0.5, 0.5],
        [0.2, 0.7, 0.4, 0.8, 0.3, 0.6],
        [0.8, 0.3, 0.6, 0.9, 0.7, 0.4],
        [0.5, 0.5, 0.7, 0.85, 0.5, 0.5],
    ];
    for f in fractions {
        let x: Vec<f64> =
            problem.basis.bounds().iter().zip(&f).map(|((lo, hi), t)| lo + t * (hi - lo)).collect();
        let g = problem.evaluate(&x, &targets).expect("evaluates").cost;
        for j in 0..x.len() {
            let mut moved = x.clone();
            moved[j] *= 1.0 + 1e-12;
            let h = problem.evaluate(&moved, &targets).expect("evaluates").cost;
            assert!(((h - g) / g).abs() < 1e-6, "at {x:?}, coordinate {j}: g {g} -> {h}");
        }
    }
}

/// Issue 30's comfort-range acceptance (six of eight directions within 10%) against the tiles
/// the fabrics' own stitch gives: at `samples` search points spread over the whole Sec. 6.5.3
/// box (a Halton sequence), the tile's weft and warp responses in the comfort range, each
/// allowed one common stiffness scale (every energy scaled alike scales every stress alike and
/// keeps every equilibrium, so the scale is free even beyond the box), and the smallest
/// comfort error both directions reach at once. A swatch where that error stays above 10% at
/// every point has at most one of its two directions within 10%.
#[test]
#[ignore = "about 8 min on 2 cores: 112 estimated rest shapes and their uniaxial tests"]
fn the_own_stitch_tiles_fit_weft_and_warp_within_ten_percent_at_once_nowhere() {
    let settings = YarnFitSettings::default();
    let mut best_per_swatch = Vec::new();
    for (pattern, samples) in [("stockinette", 40), ("garter", 40), ("rib", 16), ("seed", 16)] {
        let problem = own_stitch_problem(pattern, &settings);
        let targets = problem.targets(12).expect("shell targets");
        let bounds = problem.basis.bounds();
        let mut best = (f64::INFINITY, Vec::new(), [0.0; 2]);
        for k in 1..=samples {
            let x: Vec<f64> = bounds
                .iter()
                .enumerate()
                .map(|(j, (lo, hi))| lo + halton(k, PRIMES[j]) * (hi - lo))
                .collect();
            let Ok(evaluation) = problem.evaluate(&x, &targets) else { continue };
            let (error, each) = common_scale_comfort_error(&targets, &evaluation.curves);
            if error < best.0 {
                best = (error, x, each);
            }
        }
        eprintln!(
            "{pattern}: smallest comfort error of weft and warp at once {:.1}% (weft {:.1}%, warp {:.1}%) at {:?}",
            100.0 * best.0,
            100.0 * best.2[0],
            100.0 * best.2[1],
            best.1
        );
        best_per_swatch.push(best.0);
    }
    let swatches_with_both = best_per_swatch.iter().filter(|e| **e <= 0.10).count();
    assert!(
        4 + swatches_with_both < 6,
        "{swatches_with_both} swatches reach both directions within 10%: the acceptance is reachable"
    );
}

const PRIMES: [usize; 8] = [2, 3, 5, 7, 11, 13, 17, 19];

/// The `k`-th element of the van der Corput sequence in `base`.
fn halton(mut k: usize, base: usize) -> f64 {
    let (mut value, mut scale) = (0.0, 1.0);
    while k > 0 {
        scale /= base as f64;
        value += scale * (k % base) as f64;
        k /= base;
    }
    value
}

/// The smallest over one stiffness scale `a` of the larger of the two directions' comfort-range
/// errors (Fig. 6.15's: RMS over the comfort targets of `(a σ - σ*) / (1 + s) / σ*_comfort`),
/// and each direction's error at that scale.
fn common_scale_comfort_error(
    targets: &[yarnhom_calib::yarn::objective::DirectionTargets],
    curves: &[yarnhom_calib::yarn::objective::SimulatedCurve],
) -> (f64, [f64; 2]) {
    let error_at = |a: f64| -> [f64; 2] {
        let mut each = [0.0; 2];
        for (e, (t, c)) in each.iter_mut().zip(targets.iter().zip(curves)) {
            let comfort: Vec<f64> = (0..t.stretch.len())
                .filter(|&i| t.stretch[i] <= t.comfort_stretch * (1.0 + 1e-9))
                .map(|i| {
                    (a * c.stress_n_m[i] - t.stress_n_m[i]) / (1.0 + t.stretch[i]) / t.comfort_stress_n_m
                })
                .collect();
            *e = (comfort.iter().map(|r| r * r).sum::<f64>() / comfort.len().max(1) as f64).sqrt();
        }
        each
    };
    // Each error is convex in `a` (the root of a quadratic), so is the larger: a scan over
    // twelve decades of `a`, then a halving pattern search, is plenty for a percentage.
    let worst = |log_a: f64| error_at(10f64.powf(log_a)).into_iter().fold(0.0, f64::max);
    let start = (0..=1200).map(|i| -6.0 + i as f64 * 0.01).min_by(|p, q| worst(*p).total_cmp(&worst(*q)));
    let mut log_a = start.expect("a scan");
    let mut step = 0.01;
    while step > 1e-6 {
        for candidate in [log_a - step, log_a + step] {
            if worst(candidate) < worst(log_a) {
                log_a = candidate;
            }
        }
        step *= 0.5;
    }
    let each = error_at(10f64.powf(log_a));
    (each[0].max(each[1]), each)
}
