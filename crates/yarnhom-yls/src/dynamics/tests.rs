//! Finite-difference checks of the whole incremental potential.

use nalgebra::{DMatrix, DVector};

use super::contact::Candidate;
use super::potential::{StepContext, Want};
use super::step::candidates_at;
use super::system::System;
use super::*;

/// A reproducible pseudo-random number in `[-1, 1]` (xorshift).
fn random(state: &mut u64) -> f64 {
    *state ^= *state << 13;
    *state ^= *state >> 7;
    *state ^= *state << 17;
    2.0 * (*state >> 11) as f64 / (1u64 << 53) as f64 - 1.0
}

const RADIUS: f64 = 0.1;

fn material() -> RodMaterial {
    RodMaterial {
        stretch: StretchLaw::Linear { k_n: 50.0 },
        bend_stiffness_nm2: [0.02, 0.03],
        twist_stiffness_nm2: 0.015,
    }
}

/// Two gently bent yarns crossing 1.5 radii apart just above a plane, glued at one pair of ends,
/// with every term of the potential active: rods, contact, glue, obstacle barrier, gravity,
/// damping and a handle.
fn scene(rng: &mut u64) -> Scene {
    let mut jitter = |scale: f64| random(rng) * scale;
    let a: Vec<[f64; 3]> =
        (0..7).map(|i| [0.1 * i as f64 - 0.3, jitter(0.02), 0.12 + jitter(0.01)]).collect();
    let b: Vec<[f64; 3]> =
        (0..6).map(|i| [jitter(0.02), 0.1 * i as f64 - 0.25, 0.27 + jitter(0.01)]).collect();
    let yarn = |p: Vec<[f64; 3]>| YarnInput::at_rest(p, false, RADIUS, material(), 0.3, [0.0, 0.0, 1.0]);
    let mut scene = Scene::new(vec![yarn(a), yarn(b)]);
    scene.glue = vec![GlueSpring { vertices: [6, 7], rest_length_m: 0.05, stiffness_n_m: 4.0 }];
    scene.contact = ContactModel::Kaldor { stiffness_n_m: 20.0 };
    scene.gravity_m_s2 = [0.0, 0.0, -9.81];
    scene.obstacles = vec![Obstacle {
        shape: ObstacleShape::Plane { point_m: [0.0, 0.0, 0.0], normal: [0.0, 0.1, 1.0] },
        activation_distance_m: 0.05,
        stiffness_n_m: 3.0,
        friction: 0.0,
    }];
    scene.handles = vec![Handle::fixed(vec![0, 1])];
    scene.damping = Some(Damping { window_vertices: 4, rate_per_s: 7.0 });
    scene
}

/// The dense Hessian of lower-triangle triplets.
fn dense(n: usize, triplets: &[(usize, usize, f64)]) -> DMatrix<f64> {
    let mut h = DMatrix::zeros(n, n);
    for &(i, j, v) in triplets {
        h[(i, j)] += v;
        if i != j {
            h[(j, i)] += v;
        }
    }
    h
}

#[test]
fn incremental_potential_derivatives_match_finite_differences() {
    let mut rng = 17u64;
    let scene = scene(&mut rng);
    let system = System::new(&scene).expect("valid scene");
    let q_n = system.initial_q(&scene);
    let n = system.dof_count();
    let velocity = DVector::from_fn(3 * system.vertex_count(), |_, _| 0.3 * random(&mut rng));
    let context = StepContext::new(&system, &q_n, &velocity, 0.01);
    // An iterate away from the start (positions by up to 0.1 radius, twists by 0.2 rad).
    let q = DVector::from_fn(n, |i, _| {
        q_n[i] + random(&mut rng) * if i < 3 * system.vertex_count() { 0.01 } else { 0.2 }
    });
    let candidates: Vec<Candidate> = candidates_at(&system, &q);
    let at = |q: &DVector<f64>| context.evaluate(q, &candidates, Want::Derivatives);
    let start = at(&q);
    let parts = start.parts;
    assert!(
        [parts.contact, parts.glue, parts.obstacle, parts.damping, parts.elastic, parts.inertia]
            .iter()
            .all(|&p| p > 0.0),
        "every term is active: {parts:?}"
    );
    let hessian = dense(n, &start.triplets);
    let (mut g_error, mut h_error): (f64, f64) = (0.0, 0.0);
    for i in 0..n {
        let step = if i < 3 * system.vertex_count() { 1e-7 } else { 1e-6 };
        let (mut up, mut down) = (q.clone(), q.clone());
        up[i] += step;
        down[i] -= step;
        let energy = |q: &DVector<f64>| context.evaluate(q, &candidates, Want::Energy).parts.total();
        let g_fd = (energy(&up) - energy(&down)) / (2.0 * step);
        g_error = g_error.max((g_fd - start.gradient[i]).abs());
        let column = (at(&up).gradient - at(&down).gradient) / (2.0 * step);
        h_error = h_error.max((column - hessian.column(i)).amax());
    }
    let (g_scale, h_scale) = (start.gradient.amax(), hessian.amax());
    println!("relative errors: gradient {:e}, Hessian {:e}", g_error / g_scale, h_error / h_scale);
    assert!(g_error < 1e-6 * g_scale, "gradient off by {g_error} of {g_scale}");
    assert!(h_error < 1e-5 * h_scale, "Hessian off by {h_error} of {h_scale}");
    // The energy alone is the energy of the derivatives' evaluation, to the bit.
    assert_eq!(context.evaluate(&q, &candidates, Want::Energy).parts, parts);
}

#[test]
fn the_damping_term_has_its_own_finite_difference_check() {
    // Damping alone (no other term is non-quadratic there): its Hessian is exact, so the
    // gradient of a displaced state equals the Hessian times the displacement.
    let mut rng = 5u64;
    let mut scene = scene(&mut rng);
    scene.obstacles.clear();
    scene.contact = ContactModel::Off;
    let system = System::new(&scene).expect("valid scene");
    let q_n = system.initial_q(&scene);
    let zero = DVector::zeros(3 * system.vertex_count());
    let with = StepContext::new(&system, &q_n, &zero, 0.01);
    let without = StepContext { damping: None, ..StepContext::new(&system, &q_n, &zero, 0.01) };
    let q = DVector::from_fn(q_n.len(), |i, _| q_n[i] + 0.01 * random(&mut rng));
    let difference = |q: &DVector<f64>| {
        let (a, b) = (with.evaluate(q, &[], Want::Derivatives), without.evaluate(q, &[], Want::Derivatives));
        (a.parts.damping, a.gradient - b.gradient, dense(q.len(), &a.triplets) - dense(q.len(), &b.triplets))
    };
    let (energy, gradient, hessian) = difference(&q);
    let delta = &q - &q_n;
    assert!((energy - 0.5 * delta.dot(&(&hessian * &delta))).abs() < 1e-12 * energy);
    assert!((gradient - &hessian * &delta).amax() < 1e-10 * hessian.amax());
}
