use yarnhom_shell::{HingeBending, Scene, ShellMaterial, StvkNeoHookean};

#[test]
#[ignore = "timing probe"]
fn stretch_probe() {
    let mut scene = Scene::builtin("stretch-x").expect("scene");
    scene.vertices = [std::env::var("N").map(|n| n.parse().unwrap()).unwrap_or(20); 2];
    let material = ShellMaterial::stvk(
        0.3,
        StvkNeoHookean { k_xx: 5.0, k_xy: 1.0, k_yy: 3.0, k_ss: 1.0, k_n1: 0.5, k_n2: 0.1 },
        HingeBending { k_weft: 1e-6, k_bias: 1e-6, k_warp: 1e-6 },
    );
    yarnhom_shell::simulate::run(&scene, material, Some(10), |r, _| {
        let it: u32 = r.steps.iter().map(|s| s.newton_iterations).sum();
        let wall: f64 = r.steps.iter().map(|s| s.wall_time_s).sum();
        eprintln!("frame {} t {:.3} E {:.3e} K {:.3e} newton {it} wall {wall:.3}", r.frame, r.time_s, r.elastic_energy_j, r.kinetic_energy_j);
        Ok(())
    })
    .expect("runs");
}
