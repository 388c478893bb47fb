//! Yarn dynamics against closed-form and reference results: the elastica of a cantilever under
//! its own weight, backward Euler's first-order dissipation, penetration-free contact, damping
//! that spares rigid motion, determinism across thread counts, and input errors.

use yarnhom_yls::dynamics::{
    ContactModel, Damping, Handle, InputError, Keyframe, Obstacle, ObstacleShape, RodMaterial, Scene,
    Simulation, StepError, StepReport, StretchLaw, YarnInput,
};

fn material(bend_nm2: f64, twist_nm2: f64, stretch_n: f64) -> RodMaterial {
    RodMaterial {
        stretch: StretchLaw::Linear { k_n: stretch_n },
        bend_stiffness_nm2: [bend_nm2; 2],
        twist_stiffness_nm2: twist_nm2,
    }
}

/// A straight yarn of `n` vertices from `start` with edges `spacing` (a vector), at rest.
fn straight(
    n: usize,
    start: [f64; 3],
    spacing: [f64; 3],
    radius_m: f64,
    material: RodMaterial,
    density: f64,
) -> YarnInput {
    let positions = (0..n).map(|i| std::array::from_fn(|k| start[k] + i as f64 * spacing[k])).collect();
    YarnInput::at_rest(positions, false, radius_m, material, density, [0.0, 0.0, 1.0])
}

// ---------------------------------------------------------------------------------------------
// Cantilever under its own weight.

/// The elastica of a cantilever of length `L` clamped horizontally at `s = 0` under a uniform
/// weight `q` per length, by shooting: with `θ(s)` the downward slope angle and `m(s)` the
/// bending moment, moment balance of the part beyond `s` gives
/// `m(s) = ∫_s^L q (x(σ) - x(s)) dσ`, so `m'(s) = -q (L - s) cos θ(s)`, and the constitutive law
/// `θ'(s) = m(s) / EI`; `θ(0) = 0`, `m(L) = 0`. The root moment `m(0)` lies in `(0, qL²/2]` and
/// `m(L)` grows with it, so bisection on it converges; RK4 over 4000 steps. Returns the tip
/// drop `w = ∫_0^L sin θ ds`.
fn elastica_tip_drop(q: f64, length: f64, ei: f64) -> f64 {
    let shoot = |m0: f64| {
        let steps = 4000;
        let h = length / steps as f64;
        // State (θ, m, w); derivative at s.
        let f = |s: f64, y: [f64; 3]| [y[1] / ei, -q * (length - s) * y[0].cos(), y[0].sin()];
        let mut y = [0.0, m0, 0.0];
        for i in 0..steps {
            let s = i as f64 * h;
            let k1 = f(s, y);
            let k2 = f(s + h / 2.0, std::array::from_fn(|k| y[k] + h / 2.0 * k1[k]));
            let k3 = f(s + h / 2.0, std::array::from_fn(|k| y[k] + h / 2.0 * k2[k]));
            let k4 = f(s + h, std::array::from_fn(|k| y[k] + h * k3[k]));
            y = std::array::from_fn(|k| y[k] + h / 6.0 * (k1[k] + 2.0 * k2[k] + 2.0 * k3[k] + k4[k]));
        }
        y
    };
    let (mut lo, mut hi) = (0.0, q * length * length / 2.0);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if shoot(mid)[1] < 0.0 { lo = mid } else { hi = mid }
    }
    shoot(0.5 * (lo + hi))[2]
}

/// Tip drop of the simulated cantilever (length 1, `EI = 1`) under gravity with load parameter
/// `q L³ / EI = load`, run with damping until it rests. The clamp is the first edge (its two
/// vertices a handle), centred on the origin: the bending element at the second vertex spans
/// half an edge on either side, so the beam starts at the clamp edge's midpoint, and `segments`
/// free edges of length `L / (segments + 1/2)` follow. Also returns the clamp's vertical
/// force over the yarn's weight.
fn cantilever_at_rest(segments: usize, load: f64) -> (f64, usize, f64) {
    let gravity = 9.81;
    let h = 1.0 / (segments as f64 + 0.5);
    // Nearly inextensible (axial strain below 1e-5).
    let yarn = straight(
        segments + 2,
        [-0.5 * h, 0.0, 0.0],
        [h, 0.0, 0.0],
        0.01,
        material(1.0, 1.0, 1e6),
        load / gravity,
    );
    let mut scene = Scene::new(vec![yarn]);
    scene.gravity_m_s2 = [0.0, 0.0, -gravity];
    scene.handles = vec![Handle::fixed(vec![0, 1])];
    scene.damping = Some(Damping::kaldor(10.0));
    let mut simulation = Simulation::new(&scene).expect("valid scene");
    let tip = segments + 1;
    let mut steps = 0;
    for _ in 0..400 {
        let before = simulation.positions_m()[tip][2];
        simulation.step(0.1).expect("the step converges");
        steps += 1;
        if (simulation.positions_m()[tip][2] - before).abs() < 1e-10 {
            break;
        }
    }
    let weight: f64 = simulation.vertex_masses_kg().iter().sum::<f64>() * gravity;
    let clamp = simulation.handle_forces_n()[0];
    (-simulation.positions_m()[tip][2], steps, clamp[2] / weight)
}

#[test]
fn a_cantilever_under_its_own_weight_comes_to_rest_at_the_elastica() {
    let segments = 40;
    // Large deflection: q L³ / EI = 3.
    let reference = elastica_tip_drop(3.0, 1.0, 1.0);
    assert!(reference > 0.2, "the load gives a large deflection ({reference})");
    let (drop, steps, clamp) = cantilever_at_rest(segments, 3.0);
    // At rest the clamp carries the whole weight.
    assert!((clamp - 1.0).abs() < 1e-5, "the clamp holds {clamp} of the weight");
    let error = drop / reference - 1.0;
    println!(
        "q L³/EI = 3: tip drop {drop:.5} L, elastica {reference:.5} L, error {error:+.2e}, {steps} steps"
    );
    assert!(error.abs() < 0.01, "tip drop {drop}, elastica {reference}");
    // Small load: the linear theory's q L⁴ / (8 EI), which the elastica approaches.
    let load = 0.01;
    let linear = load / 8.0;
    let reference = elastica_tip_drop(load, 1.0, 1.0);
    assert!((reference / linear - 1.0).abs() < 1e-4, "elastica {reference} vs linear {linear}");
    let (drop, steps, _) = cantilever_at_rest(segments, load);
    let error = drop / linear - 1.0;
    println!(
        "q L³/EI = 0.01: tip drop {drop:.4e} L, q L⁴/(8 EI) = {linear:.4e} L, error {error:+.2e}, {steps} steps"
    );
    assert!(error.abs() < 0.01, "tip drop {drop}, linear theory {linear}");
}

// ---------------------------------------------------------------------------------------------
// Backward Euler's dissipation.

/// A free yarn (length 1, 21 vertices, `EI = 1`, density 1, straight at rest) released at
/// rest from a bent shape; no damping, contact or gravity. The bent curvature
/// `κ(s) = 4 sin²(π s / L)` vanishes with its slope at both ends, as a free end's moment and
/// shear do, so the shape lies mostly in the first bending mode rather than spreading over all
/// of them (as a circular arc's would). Returns the total energy after every step of `h` up to
/// time `duration`.
fn released_bent_yarn(h: f64, duration: f64) -> Vec<f64> {
    let n = 21;
    let spacing = 1.0 / (n - 1) as f64;
    let turning =
        |s: f64| 4.0 * (s / 2.0 - (2.0 * std::f64::consts::PI * s).sin() / (4.0 * std::f64::consts::PI));
    let mut bent = vec![[0.0; 3]];
    for i in 0..n - 1 {
        let angle = turning((i as f64 + 0.5) * spacing);
        let last = bent[i];
        bent.push([last[0] + spacing * angle.cos(), last[1] + spacing * angle.sin(), 0.0]);
    }
    let mut yarn = straight(n, [0.0; 3], [spacing, 0.0, 0.0], 0.01, material(1.0, 1.0, 1e4), 1.0);
    let bent = YarnInput::at_rest(bent, false, 0.01, yarn.material, 1.0, [0.0, 0.0, 1.0]);
    // The bent positions and their frames with the straight rest shape.
    yarn.positions_m = bent.positions_m;
    yarn.reference_director = bent.reference_director;
    yarn.reference_twist_rad = bent.reference_twist_rad;
    let mut simulation = Simulation::new(&Scene::new(vec![yarn])).expect("valid scene");
    let mut energies = vec![simulation.energies().total_j()];
    let steps = (duration / h).round() as usize;
    for _ in 0..steps {
        energies.push(simulation.step(h).expect("the step converges").energies.total_j());
    }
    energies
}

/// Backward Euler dissipates, at first order in `h`: a mode of frequency `ω` loses energy at
/// the rate `≈ ω² h` per unit time while `ω h ≪ 1`, so the energy lost over a fixed time
/// halves with `h` where the loss is small. The bent yarn's energy sits mostly in the first
/// bending mode (`ω h ≈ 0.02` at `h = 10⁻³`, a loss near 10% over the run); higher modes, for
/// which the loss saturates, pull the ratio below 2, so it must lie in `[1.5, 2.5]`. The total energy never increases
/// beyond round-off (`10⁻¹²` of the initial energy) along the way.
#[test]
fn backward_euler_dissipates_at_first_order_in_the_time_step() {
    let duration = 0.2;
    let coarse = released_bent_yarn(1e-3, duration);
    let fine = released_bent_yarn(5e-4, duration);
    let initial = coarse[0];
    for energies in [&coarse, &fine] {
        let largest_rise = energies.windows(2).map(|w| w[1] - w[0]).fold(f64::NEG_INFINITY, f64::max);
        assert!(largest_rise <= 1e-12 * initial, "the energy rose by {largest_rise} of {initial}");
    }
    let (lost_coarse, lost_fine) = (initial - coarse[coarse.len() - 1], initial - fine[fine.len() - 1]);
    let ratio = lost_coarse / lost_fine;
    println!(
        "energy {initial:.5} J; lost over {duration} s: {:.3}% at h = 1e-3, {:.3}% at h = 5e-4; ratio {ratio:.3}",
        100.0 * lost_coarse / initial,
        100.0 * lost_fine / initial
    );
    assert!((1.5..=2.5).contains(&ratio), "loss ratio {ratio}");
}

// ---------------------------------------------------------------------------------------------
// Contact.

const R: f64 = 0.01;

fn yarn_material() -> RodMaterial {
    material(1e-4, 1e-4, 100.0)
}

/// Yarn A along x on a plane (centre 1.3 radii above it), yarn B along y crossing above it,
/// their centrelines `gap` radii apart; gravity pulls both down.
fn crossing_scene(gap: f64) -> Scene {
    let z_a = 1.3 * R;
    let a = straight(11, [-0.1, 0.0, z_a], [0.02, 0.0, 0.0], R, yarn_material(), 0.01);
    let b = straight(11, [0.0, -0.1, z_a + gap * R], [0.0, 0.02, 0.0], R, yarn_material(), 0.01);
    let mut scene = Scene::new(vec![a, b]);
    scene.contact = ContactModel::Kaldor { stiffness_n_m: 10.0 };
    scene.gravity_m_s2 = [0.0, 0.0, -9.81];
    scene.obstacles = vec![Obstacle {
        shape: ObstacleShape::Plane { point_m: [0.0; 3], normal: [0.0, 0.0, 1.0] },
        activation_distance_m: 0.5 * R,
        stiffness_n_m: 1.0,
        friction: 0.0,
    }];
    scene.damping = Some(Damping::kaldor(5.0));
    scene
}

#[test]
fn a_yarn_falling_onto_a_crossing_yarn_on_a_plane_never_touches_it() {
    let mut simulation = Simulation::new(&crossing_scene(3.5)).expect("valid scene");
    let reports: Vec<StepReport> =
        (0..100).map(|_| simulation.step(2e-3).expect("the step converges")).collect();
    let closest = reports.iter().map(|r| r.closest_distance_radii).fold(f64::INFINITY, f64::min);
    let final_distance = reports[reports.len() - 1].closest_distance_radii;
    let iterations: usize = reports.iter().map(|r| r.newton_iterations).sum();
    println!(
        "closest centreline distance over 100 steps: {closest:.3} radii, at the end {final_distance:.3} radii; \
         {iterations} Newton iterations"
    );
    assert!(closest > 0.0, "the yarns touched");
    // B lies on A: the contact acts (below 2 radii) and holds it (above 1 radius).
    assert!(final_distance < 2.0 && final_distance > 1.0, "{final_distance}");
    // The stored energy, shared among the vertices, sums to the state's.
    let e = simulation.energies();
    let shared: f64 = simulation.vertex_energies_j().iter().sum();
    let stored = e.elastic_j + e.glue_j + e.contact_j;
    assert!(e.contact_j > 0.0 && (shared - stored).abs() <= 1e-12 * stored, "{shared} vs {stored}");
    // Both yarns rest above the plane.
    let lowest = simulation.positions_m().iter().map(|p| p[2]).fold(f64::INFINITY, f64::min);
    assert!(lowest > R, "a vertex at {lowest} m sank into the plane");
}

#[test]
fn a_step_that_would_pass_one_yarn_through_another_is_capped() {
    // A held at both ends; B, 2.5 radii above A (out of reach of the contact), moves down at a
    // speed that carries it 4 radii in one step: the inertial prediction x̃ = x + h v, where the
    // first Newton step goes with no contact in reach, lies 1.5 radii below A.
    let a = straight(11, [-0.1, 0.0, 0.0], [0.02, 0.0, 0.0], R, yarn_material(), 0.01);
    let b = straight(5, [0.0, -0.04, 2.5 * R], [0.0, 0.02, 0.0], R, yarn_material(), 0.01);
    let mut scene = Scene::new(vec![a, b]);
    scene.contact = ContactModel::Kaldor { stiffness_n_m: 100.0 };
    scene.handles = vec![Handle::fixed(vec![0, 1, 9, 10])];
    let mut simulation = Simulation::new(&scene).expect("valid scene");
    let h = 0.01;
    let speed = 4.0 * R / h;
    let velocities: Vec<[f64; 3]> =
        (0..16).map(|v| if v >= 11 { [0.0, 0.0, -speed] } else { [0.0; 3] }).collect();
    simulation.set_velocities_m_s(&velocities).expect("one velocity per vertex");
    let predicted_b = simulation.positions_m()[13][2] - speed * h;
    assert!(predicted_b < -R, "the prediction passes through A ({predicted_b})");
    let reports: Vec<StepReport> = (0..20).map(|_| simulation.step(h).expect("the step converges")).collect();
    let closest = reports.iter().map(|r| r.closest_distance_radii).fold(f64::INFINITY, f64::min);
    println!(
        "first step: {} contact caps, {} reach caps, {} line-search cuts, {} Newton iterations; \
         closest distance over 20 steps {closest:.3} radii",
        reports[0].step_caps,
        reports[0].reach_caps,
        reports[0].line_search_cuts,
        reports[0].newton_iterations
    );
    assert!(reports[0].step_caps >= 1, "the contact cap shortened the first step");
    assert!(closest > 0.0, "the yarns touched");
    // B ends above A: it was stopped, not carried through.
    let b_middle = simulation.positions_m()[13][2];
    assert!(b_middle > simulation.positions_m()[5][2], "B ended at {b_middle}, below A");
}

// ---------------------------------------------------------------------------------------------
// Damping.

/// A free yarn (no gravity, contact or obstacles) moving with `velocity(x)`, `steps` steps of
/// `h`, with or without damping: the total energy at the end.
fn moving_yarn(
    damping: Option<Damping>,
    velocity: impl Fn([f64; 3]) -> [f64; 3],
    steps: usize,
) -> (f64, f64) {
    let yarn = straight(15, [-0.07, 0.0, 0.0], [0.01, 0.0, 0.0], 0.001, material(1e-5, 1e-5, 100.0), 0.01);
    let mut scene = Scene::new(vec![yarn]);
    scene.damping = damping;
    let mut simulation = Simulation::new(&scene).expect("valid scene");
    let velocities: Vec<[f64; 3]> = simulation.positions_m().into_iter().map(velocity).collect();
    simulation.set_velocities_m_s(&velocities).expect("one velocity per vertex");
    let initial = simulation.energies().total_j();
    for _ in 0..steps {
        simulation.step(1e-3).expect("the step converges");
    }
    (initial, simulation.energies().total_j())
}

/// The damping of non-rigid motion removes no energy from a rigid motion: a translation keeps
/// its energy exactly, and a rotation pays only at second order in its angle per step `θ`
/// (the finite rotation of a step is rigid only to first order, and backward Euler's radial
/// pull-back of the stretched prediction is `O(θ²)`), at most `c h θ²` of its energy per step
/// by that estimate. A bending wave of similar energy loses far more with damping than
/// without.
#[test]
fn damping_spares_rigid_motion_and_damps_the_rest() {
    let rate = 50.0;
    let damping = Some(Damping::kaldor(rate));
    let steps = 50;
    let (initial, end) = moving_yarn(damping, |_| [0.3, -0.2, 0.1], steps);
    println!("translation: energy {initial:.6e} J -> {end:.6e} J");
    assert!((end / initial - 1.0).abs() < 1e-12);
    // About z at 20 rad/s: θ = 0.02 rad per step, 1 rad over the run.
    let omega = 20.0;
    let spin = |x: [f64; 3]| [-omega * x[1], omega * x[0], 0.0];
    let (initial, damped) = moving_yarn(damping, spin, steps);
    let (_, undamped) = moving_yarn(None, spin, steps);
    let rotation_cost = (undamped - damped) / initial;
    let bound = rate * 1e-3 * (omega * 1e-3).powi(2) * steps as f64;
    println!(
        "rotation: energy {initial:.6e} J -> {damped:.6e} J damped, {undamped:.6e} J undamped: \
         damping costs {rotation_cost:.2e} of it (second-order bound {bound:.0e})"
    );
    assert!(rotation_cost.abs() < bound);
    // Wavenumber 60/m (a wavelength of 10 edges): `ω h ≈ 0.1`, so backward Euler alone damps
    // it little.
    let wave = |x: [f64; 3]| [0.0, 0.5 * (60.0 * x[0]).sin(), 0.0];
    let (initial, damped) = moving_yarn(damping, wave, steps);
    let (_, undamped) = moving_yarn(None, wave, steps);
    let wave_cost = (undamped - damped) / initial;
    println!(
        "wave: energy {initial:.6e} J -> {damped:.6e} J damped, {undamped:.6e} J undamped: damping costs {wave_cost:.2e}"
    );
    assert!(wave_cost > 100.0 * rotation_cost.abs());
}

// ---------------------------------------------------------------------------------------------
// Determinism.

/// Positions, twists and velocities after `steps` steps of the crossing scene, as bits.
fn crossing_run_bits(steps: usize) -> Vec<u64> {
    // B starts within the contact's reach of A, A within the plane's barrier.
    let mut simulation = Simulation::new(&crossing_scene(1.9)).expect("valid scene");
    for _ in 0..steps {
        simulation.step(2e-3).expect("the step converges");
    }
    let positions = simulation.positions_m().into_iter().flatten();
    let velocities = simulation.velocities_m_s().into_iter().flatten();
    positions.chain(simulation.edge_twists_rad()).chain(velocities).map(f64::to_bits).collect()
}

#[test]
fn results_are_bit_identical_for_any_thread_count() {
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("a thread pool")
            .install(|| crossing_run_bits(8))
    };
    let (one, three) = (run(1), run(3));
    assert_eq!(one, three);
}

// ---------------------------------------------------------------------------------------------
// Handles.

#[test]
fn handles_follow_their_keyframes_and_may_not_outrun_the_contact_caps() {
    // Yarn 0 held whole, translated 1 radius along y over 0.1 s and then held; yarn 1 free,
    // parallel to it 3 radii away.
    let a = straight(6, [0.0; 3], [0.02, 0.0, 0.0], R, yarn_material(), 0.01);
    let b = straight(6, [0.0, 3.0 * R, 0.0], [0.02, 0.0, 0.0], R, yarn_material(), 0.01);
    let mut scene = Scene::new(vec![a, b]);
    scene.contact = ContactModel::Kaldor { stiffness_n_m: 10.0 };
    let key = |time_s: f64, y: f64| Keyframe { time_s, translation_m: [0.0, y, 0.0] };
    scene.handles = vec![Handle { vertices: (0..6).collect(), keyframes: vec![key(0.0, 0.0), key(0.1, R)] }];
    let start = Simulation::new(&scene).expect("valid scene").positions_m();
    let mut simulation = Simulation::new(&scene).expect("valid scene");
    for step in 1..=15 {
        simulation.step(0.01).expect("the step converges");
        let expected = R * (0.01 * step as f64 / 0.1).min(1.0);
        let positions = simulation.positions_m();
        for (v, (now, then)) in positions.iter().zip(&start).take(6).enumerate() {
            let moved = now[1] - then[1];
            assert!((moved - expected).abs() < 1e-15, "vertex {v} at step {step}: {moved} vs {expected}");
        }
    }
    // The same handle jumping 3 radii in one step would cross yarn 1's reach: refused, and the
    // state is kept.
    scene.handles[0].keyframes = vec![key(0.0, 0.0), key(0.01, 3.0 * R)];
    let mut simulation = Simulation::new(&scene).expect("valid scene");
    let error = simulation.step(0.01).expect_err("too far for one step");
    println!("{error}");
    assert!(matches!(error, StepError::HandleMoveTooFar { .. }), "{error}");
    assert_eq!(simulation.positions_m(), start);
}

// ---------------------------------------------------------------------------------------------
// Input errors.

#[test]
fn bad_input_gives_clear_errors() {
    let base = || {
        let mut scene = Scene::new(vec![straight(5, [0.0; 3], [0.1, 0.0, 0.0], 0.01, yarn_material(), 0.01)]);
        scene.handles = vec![Handle::fixed(vec![0, 1])];
        scene
    };
    let keyframes = |keyframes: Vec<Keyframe>| {
        let mut scene = base();
        scene.handles[0].keyframes = keyframes;
        Simulation::new(&scene).err()
    };
    let key = |time_s: f64, x: f64| Keyframe { time_s, translation_m: [x, 0.0, 0.0] };
    assert!(matches!(
        keyframes(vec![key(0.0, 0.0), key(1.0, f64::NAN)]),
        Some(InputError::Keyframes { handle: 0, .. })
    ));
    assert!(matches!(
        keyframes(vec![key(0.0, 0.0), key(f64::INFINITY, 1.0)]),
        Some(InputError::Keyframes { .. })
    ));
    assert!(matches!(keyframes(vec![key(1.0, 0.0), key(1.0, 1.0)]), Some(InputError::Keyframes { .. })));
    assert!(matches!(keyframes(vec![]), Some(InputError::Keyframes { .. })));
    let error = keyframes(vec![key(2.0, 0.0), key(1.0, 1.0)]).expect("an error");
    println!("{error}");

    let mut scene = base();
    scene.handles.push(Handle::fixed(vec![3, 5]));
    let error = Simulation::new(&scene).err();
    assert_eq!(error, Some(InputError::VertexOutOfRange { what: "handle 1".into(), vertex: 5, vertices: 5 }));
    println!("{}", error.expect("an error"));
    let mut scene = base();
    scene.handles.push(Handle::fixed(vec![1]));
    assert_eq!(Simulation::new(&scene).err(), Some(InputError::VertexInTwoHandles { vertex: 1 }));

    let mut simulation = Simulation::new(&base()).expect("valid scene");
    let before = simulation.positions_m();
    for h in [0.0, -1e-3, f64::NAN, f64::INFINITY] {
        let error = simulation.step(h).expect_err("a bad time step");
        assert!(matches!(error, StepError::InvalidTimeStep { .. }), "{error}");
    }
    assert_eq!(simulation.positions_m(), before, "the state is unchanged");
    assert_eq!(simulation.time_s(), 0.0);
}

/// A straight horizontal yarn falling across the air reaches the terminal speed of the wind
/// law, `ρ s v² = λ g` (`s` the cloth area per yarn length, `λ` the linear density), and air
/// moving along the yarn drags it along at the drag coefficient's rate.
#[test]
fn a_falling_yarn_reaches_the_terminal_speed_of_the_wind_law() {
    use yarnhom_yls::dynamics::YarnWind;
    let (density, area_per_length, lambda) = (7.5, 2e-3, 3.77e-4);
    let yarn = straight(20, [0.0; 3], [0.005, 0.0, 0.0], 1e-3, material(1e-9, 1e-9, 10.0), lambda);
    let wind = YarnWind {
        density_kg_m3: density,
        velocity_m_s: [0.0; 3],
        drag_kg_m2_s: 0.0,
        area_per_length_m: area_per_length,
    };
    let scene = Scene { gravity_m_s2: [0.0, 0.0, -9.81], wind: Some(wind), ..Scene::new(vec![yarn.clone()]) };
    let mut simulation = Simulation::new(&scene).expect("a valid scene");
    for _ in 0..600 {
        simulation.step(1e-3).expect("steps");
    }
    let terminal = (lambda * 9.81 / (density * area_per_length)).sqrt();
    for v in simulation.velocities_m_s() {
        assert!((v[2] + terminal).abs() < 1e-3 * terminal, "{} m/s against -{terminal} m/s", v[2]);
        assert!(v[0].abs() < 1e-9 && v[1].abs() < 1e-9);
    }

    // Air along the yarn at 1 m/s drags it with `d s (u - v)` per length: `v = u (1 - e^(-d s t / λ))`.
    let drag = 0.05;
    let along = YarnWind {
        density_kg_m3: density,
        velocity_m_s: [1.0, 0.0, 0.0],
        drag_kg_m2_s: drag,
        area_per_length_m: area_per_length,
    };
    let scene = Scene { wind: Some(along), ..Scene::new(vec![yarn]) };
    let mut simulation = Simulation::new(&scene).expect("a valid scene");
    let (h, steps) = (1e-4, 500);
    for _ in 0..steps {
        simulation.step(h).expect("steps");
    }
    let rate = drag * area_per_length / lambda;
    // The force is taken at each step's start (explicit, as ARCSim's): `v_{k+1} = v_k +
    // h r (u - v_k)`, so `v_k = u (1 - (1 - h r)^k)` exactly.
    let expected = 1.0 - (1.0 - h * rate).powi(steps);
    let v = simulation.velocities_m_s()[10][0];
    assert!((v - expected).abs() < 1e-6, "{v} m/s against {expected} m/s");
}

// ---------------------------------------------------------------------------------------------
// Obstacle friction.

/// A straight yarn resting on the plane z = 0 under gravity, then launched along x at `v0`
/// with friction `mu` (no damping): how far it slides in `duration`, and its speed at the end.
fn slide_on_a_plane(mu: f64, v0: f64, duration: f64) -> (f64, f64) {
    let yarn = straight(11, [0.0, 0.0, 1.2 * R], [0.02, 0.0, 0.0], R, yarn_material(), 0.01);
    let mut scene = Scene::new(vec![yarn]);
    scene.gravity_m_s2 = [0.0, 0.0, -9.81];
    scene.obstacles = vec![Obstacle {
        shape: ObstacleShape::Plane { point_m: [0.0; 3], normal: [0.0, 0.0, 1.0] },
        activation_distance_m: 0.5 * R,
        stiffness_n_m: 10.0,
        friction: mu,
    }];
    let mut simulation = Simulation::new(&scene).expect("valid scene");
    // Come to rest on the plane: long steps, whose numerical dissipation stops the bouncing
    // on the barrier (friction has nothing to act on yet).
    for _ in 0..60 {
        simulation.step(0.02).expect("the step converges");
    }
    let h = 2e-4;
    let rest = simulation.velocities_m_s().iter().map(|v| v[2].abs()).fold(0.0, f64::max);
    assert!(rest < 1e-6, "the yarn rests on the plane ({rest} m/s)");
    let start = simulation.positions_m()[5][0];
    let launched = vec![[v0, 0.0, 0.0]; 11];
    simulation.set_velocities_m_s(&launched).expect("valid velocities");
    let steps = (duration / h).round() as usize;
    for _ in 0..steps {
        simulation.step(h).expect("the step converges");
    }
    let speed = simulation.velocities_m_s().iter().map(|v| v[0].abs()).fold(0.0, f64::max);
    (simulation.positions_m()[5][0] - start, speed)
}

#[test]
fn friction_on_an_obstacle_stops_a_sliding_yarn_at_coulombs_distance() {
    let (mu, v0, g) = (0.3, 0.1, 9.81);
    // Coulomb: deceleration μ g, stopping distance v0² / (2 μ g) = 1.70 mm after 34 ms.
    let expected = v0 * v0 / (2.0 * mu * g);
    let (slid, speed) = slide_on_a_plane(mu, v0, 0.05);
    println!("slid {slid:.4e} m, Coulomb {expected:.4e} m, final speed {speed:.1e} m/s");
    assert!((slid / expected - 1.0).abs() < 0.02, "slid {slid} m, expected {expected} m");
    assert_eq!(speed, 0.0, "static friction holds the yarn");
    // Without friction it keeps its speed.
    let (slid, speed) = slide_on_a_plane(0.0, v0, 0.01);
    assert!((slid / (v0 * 0.01) - 1.0).abs() < 1e-6 && (speed / v0 - 1.0).abs() < 1e-6, "{slid} {speed}");
}
