//! Newton convergence of the shell integrator on a built-in scene with a published material:
//! per step the iterations, line-search halvings, final residual and wall time.
//! `cargo run --release -p yarnhom-shell --example newton_probe -- SCENE MATERIAL N STEPS [TOLERANCE_M]
//! [projected|gauss-newton] [STEPS_PER_FRAME] [auto|cholesky]` (the published scenes take 80 steps per 1/60 s
//! frame, Δt = 0.209 ms; the built-ins 4; the last argument is the linear solver). With `PROBE_DUMP=FILE` it writes the final positions, one vertex `x y z` per
//! line, to compare runs (the README's accuracy figures for one Newton iteration per step).

use yarnhom_artifacts::Spline;
use yarnhom_artifacts::open::open_artifact;
use yarnhom_fit::SplineMaterial;
use yarnhom_shell::Scene;
use yarnhom_shell::ShellMaterial;
use yarnhom_shell::simulate::prepare;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let scene_name = args.get(1).map_or("stretch-x", String::as_str);
    let material = args.get(2).map_or("stock1", String::as_str);
    let n: usize = args.get(3).and_then(|a| a.parse().ok()).unwrap_or(25);
    let steps: usize = args.get(4).and_then(|a| a.parse().ok()).unwrap_or(20);
    let path = format!("{}/../../../shared/data/hylc-materials/{material}.json", env!("CARGO_MANIFEST_DIR"));
    let spline = open_artifact::<Spline>(&path).expect("published material").value;
    let mut scene = Scene::builtin(scene_name).expect("built-in scene");
    scene.vertices = [n, n];
    if let Some(tolerance) = args.get(5).and_then(|a| a.parse().ok()) {
        scene.tolerance_m = tolerance;
    }
    if let Some(matrix) = args.get(6) {
        scene.newton_matrix = serde_json::from_value(serde_json::Value::String(matrix.clone()))
            .expect("projected or gauss-newton");
    }
    if let Some(steps) = args.get(7).and_then(|a| a.parse().ok()) {
        scene.steps_per_frame = steps;
    }
    if let Some(solver) = args.get(8) {
        scene.linear_solver =
            serde_json::from_value(serde_json::Value::String(solver.clone())).expect("auto or cholesky");
    }
    let mut sim = prepare(&scene, ShellMaterial::spline(SplineMaterial::from(&spline))).expect("scene");
    for _ in 0..steps {
        let s = sim.step().expect("step");
        println!(
            "t {:.4} s: {:2} Newton iterations, {:2} halvings, {:3} CG iterations, {} factorizations, residual \
             {:.2e} N, converged {}, {:.3} s",
            sim.time_s,
            s.newton_iterations,
            s.line_search_steps,
            s.linear_solves.cg_iterations,
            s.linear_solves.factorizations,
            s.residual_n,
            s.converged,
            s.wall_time_s
        );
    }
    if let Ok(path) = std::env::var("PROBE_DUMP") {
        let text: String = sim.positions.iter().map(|p| format!("{} {} {}\n", p.x, p.y, p.z)).collect();
        std::fs::write(path, text).expect("dump");
    }
}
