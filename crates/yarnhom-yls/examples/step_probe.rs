//! Per-step Newton statistics of a yarn-level run, for finding where steps get hard:
//! `cargo run --release -p yarnhom-yls --example step_probe -- [TILES] [STEPS] [SCENE]`
//! runs `STEPS` backward Euler steps (default 8) of a built-in `SCENE` (default `stretch-x`) on
//! a `TILES x TILES` swatch (default 4) of the published stockinette with the Table 4.1 yarn,
//! at the default run settings, and prints per step the Newton iterations, line-search cuts,
//! step caps (contact, reach, obstacle), shifted Hessians, the closest centrelines (radii) and
//! the wall time.

use yarnhom_artifacts::{GlueSettings, YarnModel, pyp};
use yarnhom_yls::dynamics::Simulation;
use yarnhom_yls::run::{RunSettings, place};
use yarnhom_yls::swatch::{SwatchSize, cut_swatch};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let tiles: u32 = args.next().map_or(Ok(4), |s| s.parse())?;
    let steps: usize = args.next().map_or(Ok(8), |s| s.parse())?;
    let scene_name = args.next().unwrap_or_else(|| "stretch-x".into());
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data/hylc-patterns/stock.pyp");
    let pattern = pyp::parse_pyp(&std::fs::read_to_string(path)?, "stock", None)?;
    let model = YarnModel::table_4_1("stock").ok_or("no Table 4.1 row")?;
    let scene = yarnhom_shell::Scene::builtin(&scene_name)?;
    let settings = RunSettings::default();
    let time_step_s = scene.frame_time_s / f64::from(settings.steps_per_frame);
    let swatch = cut_swatch(&pattern, &model, SwatchSize::Tiles([tiles, tiles]), GlueSettings::default())?.0;
    let mut simulation = Simulation::new(&place(&swatch, &scene, &settings)?)?;
    println!(
        "{scene_name}, stock {tiles}x{tiles} tiles, {} vertices, Δt = {time_step_s:.3e} s",
        swatch.positions_m.len()
    );
    let started = std::time::Instant::now();
    for step in 0..steps {
        let r = simulation.step(time_step_s)?;
        println!(
            "step {step:4}: {:3} Newton, {:3} cuts, caps {}/{}/{}, {} shifted, closest {:.3} radii, {:.3} s",
            r.newton_iterations,
            r.line_search_cuts,
            r.step_caps,
            r.reach_caps,
            r.obstacle_caps,
            r.hessian_shifts,
            r.closest_distance_radii,
            r.wall_time_s
        );
    }
    println!(
        "{steps} steps in {:.2} s, {} symbolic analyses",
        started.elapsed().as_secs_f64(),
        simulation.symbolic_analyses()
    );
    Ok(())
}
