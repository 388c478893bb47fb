//! Physical behaviour of the shell simulator with the published HYLC materials (Sec. 4.3.1):
//! stockinette curls, honeycomb narrows, rib is anisotropic, relaxation dissipates, a drape
//! rests on a sphere without penetrating it. Coarse meshes and large steps keep them fast.

use nalgebra::Vector3;
use yarnhom_artifacts::Spline;
use yarnhom_artifacts::open::open_artifact;
use yarnhom_fit::SplineMaterial;
use yarnhom_shell::elastic::NewtonMatrix;
use yarnhom_shell::linear_solver::CG_ERROR_SHARE;
use yarnhom_shell::scene::HandleSpec;
use yarnhom_shell::simulate::prepare;
use yarnhom_shell::{LinearSolver, LinearSolves, Scene, ShellMaterial, Simulation};

fn published(name: &str) -> ShellMaterial {
    let path = format!("{}/../../../shared/data/hylc-materials/{name}.json", env!("CARGO_MANIFEST_DIR"));
    ShellMaterial::spline(SplineMaterial::from(
        &open_artifact::<Spline>(&path).expect("published material").value,
    ))
}

/// A builtin at `n x n` vertices with `steps` steps per 1/60 s frame.
fn scene(name: &str, n: usize, steps: u32) -> Scene {
    let mut scene = Scene::builtin(name).expect("builtin");
    scene.vertices = [n, n];
    scene.steps_per_frame = steps;
    scene.tolerance_m = 1e-6;
    scene
}

fn run_steps(sim: &mut Simulation, steps: usize) {
    for _ in 0..steps {
        sim.step().expect("step");
    }
}

/// Width along y of the cloth's middle third in x.
fn middle_width(sim: &Simulation) -> f64 {
    let middle: Vec<&Vector3<f64>> = sim
        .model
        .mesh
        .material
        .iter()
        .zip(&sim.positions)
        .filter(|(m, _)| m.x.abs() < 0.02)
        .map(|(_, p)| p)
        .collect();
    let (lo, hi) =
        middle.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| (lo.min(p.y), hi.max(p.y)));
    hi - lo
}

#[test]
fn honeycomb_narrows_when_stretched_and_more_than_satin() {
    // Poisson effect (Fig. 4.8): stretched 2 x 3.5 cm along x, the honeycomb's middle narrows.
    let narrowing = |material: &str| {
        let mut s = scene("stretch-x", 13, 1);
        s.gravity = [0.0; 3];
        let mut sim = prepare(&s, published(material)).expect("scene");
        run_steps(&mut sim, 40);
        1.0 - middle_width(&sim) / 0.3
    };
    let (honey, satin) = (narrowing("honey1"), narrowing("satin1"));
    eprintln!("narrowing: honey {:.2}%, satin {:.2}%", 100.0 * honey, 100.0 * satin);
    assert!(honey > 0.05, "honeycomb narrows by {:.1}%", 100.0 * honey);
    assert!(honey > 2.0 * satin, "honeycomb {:.1}% vs satin {:.1}%", 100.0 * honey, 100.0 * satin);
}

#[test]
fn rib_resists_stretch_along_y_far_more_than_along_x() {
    // Same handle displacement along x and along y: the force needed along y is much larger,
    // i.e. under one force the rib extends far more along x.
    let force = |name: &str, axis: usize| {
        let mut s = scene(name, 13, 1);
        s.gravity = [0.0; 3];
        let mut sim = prepare(&s, published("rib1")).expect("scene");
        run_steps(&mut sim, 40);
        sim.handle_force_n(1)[axis].abs()
    };
    let (fx, fy) = (force("stretch-x", 0), force("stretch-y", 1));
    eprintln!("rib handle force: x {fx:.4} N, y {fy:.4} N");
    assert!(fy > 3.0 * fx, "rib: force along x {fx:.4} N, along y {fy:.4} N");
}

#[test]
fn hanging_stockinette_curls_at_its_free_edges_and_satin_does_not() {
    // Held along its top edge (+y), gravity along -y in the cloth's plane: the stockinette's
    // rest curvature rolls its free edges out of the plane (Sec. 4.3, Fig. 4.6).
    let curl = |material: &str| {
        let mut s = scene("stretch-x", 13, 1);
        s.gravity = [0.0, -9.81, 0.0];
        s.handles = vec![HandleSpec::Bar { side: 3, length: 1.0, width: 0.02, inset: 0.0, motion: None }];
        s.motions.clear();
        let mut sim = prepare(&s, published(material)).expect("scene");
        run_steps(&mut sim, 40);
        let edge: Vec<f64> = sim
            .model
            .mesh
            .material
            .iter()
            .zip(&sim.positions)
            .filter(|(m, _)| m.x.abs() > 0.149 || m.y < -0.149)
            .map(|(_, p)| p.z.abs())
            .collect();
        edge.iter().sum::<f64>() / edge.len() as f64
    };
    let (stock, satin) = (curl("stock1"), curl("satin1"));
    eprintln!("free-edge curl: stock {:.2} mm, satin {:.2} mm", 1e3 * stock, 1e3 * satin);
    assert!(stock > 0.01, "stockinette free edges leave the plane by {:.1} mm on average", 1e3 * stock);
    assert!(stock > 5.0 * satin, "stockinette {:.2} mm vs satin {:.2} mm", 1e3 * stock, 1e3 * satin);
}

#[test]
fn relaxation_without_driving_never_gains_energy() {
    // Free cloth, no gravity, no moving handles, released from a bumped state: implicit Euler
    // with damping dissipates, so elastic + kinetic energy never grows.
    let mut s = scene("stretch-x", 11, 1);
    s.gravity = [0.0; 3];
    s.handles.clear();
    let mut sim = prepare(&s, published("basket1")).expect("scene");
    for (p, m) in sim.positions.iter_mut().zip(&sim.model.mesh.material) {
        p.z = 0.02 * (10.0 * m.x).sin() * (10.0 * m.y).cos();
        p.x *= 1.05;
    }
    let total = |sim: &Simulation| sim.model.energy(&sim.positions) + sim.kinetic_energy();
    let mut last = total(&sim);
    let first = last;
    for step in 0..30 {
        sim.step().expect("step");
        let now = total(&sim);
        assert!(
            now <= last * (1.0 + 1e-9) + 1e-12,
            "step {step}: energy rose from {last:.6e} to {now:.6e} J"
        );
        last = now;
    }
    eprintln!("relaxation: {first:.3e} -> {last:.3e} J");
    assert!(last < 0.5 * first, "relaxation dissipates: {first:.3e} -> {last:.3e} J");
}

#[test]
fn a_patch_draped_on_a_sphere_comes_to_rest_without_penetrating_it() {
    let mut s = scene("drape", 13, 1);
    s.handles.clear();
    s.frame_time_s = 0.02;
    s.obstacles = vec![yarnhom_shell::contact::Obstacle::Sphere { center: [0.0, 0.0, -0.04], radius: 0.03 }];
    let mut sim = prepare(&s, published("satin1")).expect("scene");
    let mut peak: f64 = 0.0;
    for _ in 0..75 {
        sim.step().expect("step");
        peak = peak.max(sim.kinetic_energy());
        assert!(sim.obstacle_penetration_m() == 0.0, "a vertex entered the sphere at t = {}", sim.time_s);
    }
    let centre = sim.positions.iter().map(|p| p.z).fold(f64::INFINITY, f64::min);
    eprintln!("drape: lowest {centre:.4} m, kinetic {:.2e} J (peak {peak:.2e} J)", sim.kinetic_energy());
    assert!(centre < -0.05, "the cloth hangs over the sphere (lowest point {centre:.3} m)");
    assert!(
        sim.kinetic_energy() < 0.05 * peak,
        "at rest: kinetic {:.2e} J vs peak {peak:.2e} J",
        sim.kinetic_energy()
    );
}

#[test]
fn both_newton_matrices_reach_the_same_states() {
    // The Newton matrix changes the path to each step's minimum of `Φ`, not `Φ` (the stiffness
    // damping takes the Gauss-Newton matrix either way): the curling stockinette, stretched and
    // hanging, takes the same states with the projected Hessians and with Gauss-Newton in the
    // forms, to the Newton tolerance (1e-6 m).
    let run = |matrix: NewtonMatrix| {
        let mut s = scene("stretch-x", 11, 2);
        s.newton_matrix = matrix;
        s.tolerance_m = 1e-9;
        s.max_newton_iterations = 200;
        let mut sim = prepare(&s, published("stock1")).expect("scene");
        let mut iterations = 0;
        for _ in 0..12 {
            let stats = sim.step().expect("step");
            assert!(stats.converged, "{matrix:?}: {stats:?}");
            iterations += stats.newton_iterations;
        }
        (sim.positions, iterations)
    };
    let (projected, projected_iterations) = run(NewtonMatrix::Projected);
    let (gauss_newton, gauss_newton_iterations) = run(NewtonMatrix::GaussNewton);
    let largest = projected.iter().zip(&gauss_newton).map(|(a, b)| (a - b).amax()).fold(0.0, f64::max);
    eprintln!(
        "largest difference {largest} m, iterations {projected_iterations} and {gauss_newton_iterations}"
    );
    assert!(largest < 1e-8, "largest difference {largest} m");
    // And neither needs many more iterations than the other.
    assert!(
        gauss_newton_iterations <= 2 * projected_iterations,
        "{gauss_newton_iterations} vs {projected_iterations}"
    );
    assert!(
        projected_iterations <= 2 * gauss_newton_iterations,
        "{projected_iterations} vs {gauss_newton_iterations}"
    );
}

#[test]
fn short_steps_converge_in_one_newton_iteration_from_the_inertial_prediction() {
    // At the published scenes' Δt (80 steps per frame) Newton starts at x_n + h v_n, whose
    // first update is of the order h² a: one iteration per step meets the 0.1 mm tolerance,
    // and the states stay close to the same steps converged to 1e-9 m.
    let run = |tolerance: f64| {
        let mut s = scene("stretch-x", 11, 80);
        s.tolerance_m = tolerance;
        s.max_newton_iterations = 200;
        let mut sim = prepare(&s, published("stock1")).expect("scene");
        let initial = sim.positions.clone();
        let mut iterations = Vec::new();
        for _ in 0..60 {
            let stats = sim.step().expect("step");
            assert!(stats.converged, "{stats:?}");
            iterations.push(stats.newton_iterations);
        }
        let travelled = sim.positions.iter().zip(&initial).map(|(a, b)| (a - b).amax()).fold(0.0, f64::max);
        (sim.positions, iterations, travelled)
    };
    let (loose, iterations, _) = run(1e-4);
    assert!(iterations.iter().all(|&n| n == 1), "{iterations:?}");
    let (tight, _, travelled) = run(1e-9);
    let apart = loose.iter().zip(&tight).map(|(a, b)| (a - b).amax()).fold(0.0, f64::max);
    eprintln!("after 60 steps: {apart:.2e} m from the converged states, which moved up to {travelled:.2e} m");
    assert!(apart < 0.02 * travelled, "{apart} m apart, {travelled} m travelled");
}

#[test]
fn conjugate_gradients_take_short_steps_to_the_states_cholesky_takes() {
    // At the published Δt the inertia term dominates the Newton matrix: `auto` solves every step
    // by conjugate gradients, to an update error below `CG_ERROR_SHARE` Newton tolerances, and
    // the states follow the factored ones. An update error `δ` in step `k` is also a velocity
    // error `δ/h`, so it moves step `n` by up to `(n - k + 1) δ`: after `n` steps the states lie
    // within `n (n + 1) / 2 · δ` of each other. At 4 steps per frame `auto` factors.
    let (steps, tolerance) = (40, 1e-4);
    let run = |solver: LinearSolver, steps_per_frame: u32| {
        let mut s = scene("stretch-x", 11, steps_per_frame);
        s.tolerance_m = tolerance;
        s.linear_solver = solver;
        let mut sim = prepare(&s, published("stock1")).expect("scene");
        let mut total = LinearSolves::default();
        for _ in 0..steps {
            let stats = sim.step().expect("step");
            assert!(stats.converged, "{solver:?}: {stats:?}");
            total.cg_iterations += stats.linear_solves.cg_iterations;
            total.factorizations += stats.linear_solves.factorizations;
        }
        (sim.positions, total)
    };
    let (factored, factored_work) = run(LinearSolver::Cholesky, 80);
    assert_eq!(factored_work.cg_iterations, 0);
    let bound = (steps * (steps + 1) / 2) as f64 * CG_ERROR_SHARE * tolerance;
    for solver in [LinearSolver::Auto, LinearSolver::ConjugateGradient] {
        let (iterated, work) = run(solver, 80);
        assert_eq!(work.factorizations, 0, "{solver:?}: {work:?}");
        assert!(work.cg_iterations >= steps, "{solver:?}: {work:?}");
        let apart = iterated.iter().zip(&factored).map(|(a, b)| (a - b).amax()).fold(0.0, f64::max);
        eprintln!("{solver:?}: {work:?}, {apart:.2e} m from the factored states (bound {bound:.2e} m)");
        assert!(apart < bound, "{solver:?}: {apart} m apart");
    }
    let (_, long_steps) = run(LinearSolver::Auto, 4);
    assert!(long_steps.factorizations >= steps && long_steps.cg_iterations == 0, "{long_steps:?}");
}

/// The published `stock_drapeX.json` with `stock1` at 50 x 50 vertices to `t = 0.23 s`, at 4 and
/// 16 steps per frame: with and without its air drag (`"wind": {"density": 7.5}`) and Rayleigh
/// mass damping. Per variant the mean vertical displacement and the RMS displacement of the
/// vertices, and their RMS distance from the run as imported before the wind was (no wind,
/// `α = 1/s`).
#[test]
#[ignore = "about 3 minutes: cargo test -p yarnhom-shell --test physics -- --ignored --nocapture"]
fn the_published_drape_with_and_without_its_air_drag() {
    let path = format!("{}/../../../shared/data/hylc-scenes/stock_drapeX.json", env!("CARGO_MANIFEST_DIR"));
    let imported = Scene::load(&path).expect("published scene");
    assert_eq!((imported.wind.density_kg_m3, imported.mass_damping), (7.5, 0.0));
    let rms = |a: &[Vector3<f64>], b: &[Vector3<f64>]| {
        (a.iter().zip(b).map(|(p, q)| (p - q).norm_squared()).sum::<f64>() / a.len() as f64).sqrt()
    };
    for steps in [4, 16] {
        let mut before: Option<Vec<Vector3<f64>>> = None;
        for (density, alpha) in [(0.0, 1.0), (7.5, 0.0), (7.5, 1.0), (0.0, 0.0)] {
            let mut s = imported.clone();
            (s.steps_per_frame, s.wind.density_kg_m3, s.mass_damping) = (steps, density, alpha);
            let mut sim = prepare(&s, published("stock1")).expect("scene");
            let start = sim.positions.clone();
            run_steps(&mut sim, (0.23 / s.dt_s()).round() as usize);
            let sinking =
                start.iter().zip(&sim.positions).map(|(p, q)| p.z - q.z).sum::<f64>() / start.len() as f64;
            eprintln!(
                "{steps} steps per frame, wind {density}, alpha {alpha}: t = {:.4} s, mean drop {:.1} mm, \
                 RMS displacement {:.1} mm, RMS from no wind and alpha 1: {:.1} mm",
                sim.time_s,
                1e3 * sinking,
                1e3 * rms(&start, &sim.positions),
                1e3 * before.as_deref().map_or(0.0, |b| rms(b, &sim.positions)),
            );
            let moved = rms(&start, &sim.positions);
            assert!(moved > 0.05 && moved < 0.2, "the cloth falls and swings: {moved} m");
            before.get_or_insert(sim.positions);
        }
    }
}
