//! Discrete elastic rods against closed-form and published results (REFERENCES.md, "Rods").

use nalgebra::{DMatrix, DVector};
use yarnhom_rod::{Rod, RodMaterial, StretchLaw};

fn material(bend: f64, twist: f64, stretch: f64) -> RodMaterial {
    RodMaterial {
        stretch: StretchLaw::Linear { k_n: stretch },
        bend_stiffness_nm2: [bend; 2],
        twist_stiffness_nm2: twist,
    }
}

fn zero_twists(rod: &Rod, positions: &[[f64; 3]]) -> DVector<f64> {
    let edges = rod.dof_count() - 3 * positions.len();
    rod.dofs_of(positions, &vec![0.0; edges])
}

#[test]
fn a_rod_at_its_rest_shape_has_no_energy_and_no_force() {
    // Straight, and a helix with its own twist ("rest curvature equal to current curvature: energy
    // and gradient zero to round-off").
    let straight: Vec<[f64; 3]> = (0..12).map(|i| [0.1 * i as f64, 0.0, 0.0]).collect();
    let helix: Vec<[f64; 3]> = (0..40)
        .map(|i| {
            let s = 0.25 * i as f64;
            [s.cos(), s.sin(), 0.15 * s]
        })
        .collect();
    for positions in [straight, helix] {
        let rod = Rod::at_rest(&positions, false, material(2.0, 1.0, 100.0), [0.0, 0.0, 1.0]);
        let (e, g, _) = rod.assemble(&zero_twists(&rod, &positions));
        assert!(e.abs() < 1e-24, "energy {e}");
        assert!(g.amax() < 1e-12, "force {}", g.amax());
    }
}

fn ring(n: usize, radius: f64) -> Vec<[f64; 3]> {
    (0..n)
        .map(|i| {
            let a = std::f64::consts::TAU * i as f64 / n as f64;
            [radius * a.cos(), radius * a.sin(), 0.0]
        })
        .collect()
}

#[test]
fn a_closed_polygon_ring_bends_with_the_discrete_energy_ratio() {
    // REFERENCES.md: bending energy over the continuum value 2 pi^2 alpha / L is
    // (n tan(pi/n) / pi)^2: 1.11257 (n=8), 1.02628 (16), 1.00646 (32), 1.00161 (64).
    for (n, published) in [(8, 1.11257), (16, 1.02628), (32, 1.00646), (64, 1.00161)] {
        let positions = ring(n, 0.3);
        let rod = Rod::at_rest(&positions, true, material(1.7, 1.0, 50.0), [0.0, 0.0, 1.0])
            .with_straight_rest_shape();
        let (energy, _, _) = rod.assemble(&zero_twists(&rod, &positions));
        let length = n as f64 * 2.0 * 0.3 * (std::f64::consts::PI / n as f64).sin();
        let ratio = energy / (2.0 * std::f64::consts::PI.powi(2) * 1.7 / length);
        assert!((ratio - published).abs() < 1e-5, "n = {n}: ratio {ratio}, published {published}");
    }
}

/// Static equilibrium of a cantilever of length 1 and bending stiffness 1 along +x under a tip
/// load `load` (= P L^2 / EI) in -y, by Newton's method with load steps. Returns (w/L, u/L).
///
/// The clamp is the first edge (both its vertices and its twist fixed), centred on the origin:
/// the bending element at its end vertex integrates curvature over half an edge on either side,
/// so the beam it discretizes starts at the edge midpoint. `segments` free edges follow, of
/// length `h = L / (segments + 1/2)`.
fn cantilever(segments: usize, load: f64) -> (f64, f64) {
    let h = 1.0 / (segments as f64 + 0.5);
    let positions: Vec<[f64; 3]> = (0..segments + 2).map(|i| [(i as f64 - 0.5) * h, 0.0, 0.0]).collect();
    // Nearly inextensible: axial strain P/EA = 1e-6.
    let mut rod = Rod::at_rest(&positions, false, material(1.0, 1.0, 1e6), [0.0, 0.0, 1.0]);
    let mut q = zero_twists(&rod, &positions);
    let n = positions.len();
    let fixed: Vec<usize> = (0..6).chain([3 * n]).collect();
    let tip_y = 3 * (n - 1) + 1;
    for step in 1..=10 {
        let p = load * step as f64 / 10.0;
        for _ in 0..50 {
            let (_, mut g, triplets) = rod.assemble(&q);
            g[tip_y] += p;
            let mut hess = DMatrix::<f64>::zeros(q.len(), q.len());
            for (i, j, v) in triplets {
                hess[(i, j)] += v;
            }
            for &i in &fixed {
                g[i] = 0.0;
                hess.row_mut(i).fill(0.0);
                hess.column_mut(i).fill(0.0);
                hess[(i, i)] = 1.0;
            }
            if g.amax() < 1e-11 {
                break;
            }
            let dx = hess.lu().solve(&(-&g)).expect("the clamped rod's Hessian is regular");
            q += dx;
            rod.update_references(&q);
        }
    }
    let tip = [q[3 * (n - 1)], q[3 * (n - 1) + 1]];
    (-tip[1], 1.0 - tip[0])
}

#[test]
fn large_deflection_cantilever_matches_the_elastica() {
    // REFERENCES.md: tip load P L^2 / EI = 1 gives w/L = 0.30172, u/L = 0.05643; = 2 gives
    // 0.49346, 0.16064. The issue asks for 1% at 64 segments; we hold 0.2%.
    for (load, w_ref, u_ref) in [(1.0, 0.30172, 0.05643), (2.0, 0.49346, 0.16064)] {
        let (w, u) = cantilever(64, load);
        println!("k = {load}: w/L = {w:.5} (elastica {w_ref}), u/L = {u:.5} (elastica {u_ref})");
        assert!((w / w_ref - 1.0).abs() < 2e-3, "k = {load}: w/L = {w}, elastica {w_ref}");
        assert!((u / u_ref - 1.0).abs() < 2e-3, "k = {load}: u/L = {u}, elastica {u_ref}");
    }
}
