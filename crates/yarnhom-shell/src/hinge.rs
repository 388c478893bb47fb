//! Edge-hinge bending energy, thesis eq. (6.4), with an optional rest curvature `κ̄`:
//! `E = k_θ (κ - κ̄)² A_e`, `κ = 3θ/H`, with exact gradient and Hessian (`κ̄ = 0` is (6.4)).
//!
//! A hinge is `[e0, e1, a, b]`: the interior edge `e0 → e1`, the far vertex `a` of the triangle
//! `(e0, e1, a)` (counter-clockwise in material space) and the far vertex `b` of the triangle
//! `(e1, e0, b)`. `θ` is the signed dihedral angle of [`crate::dihedral`]: positive when the
//! surface folds towards its normal `(x_{e1} - x_{e0}) × (x_a - x_{e0})` (the side that is up
//! for a counter-clockwise material frame laid flat). With `κ̄ = 0` (the material rest state is
//! flat) the sign drops out of the energy; a rest curvature `κ̄ > 0` curls the surface
//! towards its normal, so the rest angle is `θ̄ = κ̄ H / 3`.
//!
//! * `H` = mean of the rest altitudes of `a` and `b` over the edge;
//! * `A_e = (A_a + A_b)/3`, a third of the two incident rest triangle areas. With this choice
//!   the edges share out every triangle's area (three edges per triangle), so `Σ_e A_e` tiles
//!   the surface, and `κ A_e = θ |e|` (as `A_e = |e| H/3`): `Σ_e κ_e A_e = Σ_e θ_e |e|` is the
//!   usual integrated curvature `∫ (κ1 + κ2) dA`. Written with `h̄ = H/3` this is the discrete
//!   shells energy `k θ² |e|/h̄` (Grinspun et al. 2003).
//!
//! So `κ` estimates `κ1 + κ2` (twice the mean curvature) in the `A_e`-weighted mean, not
//! edge by edge: on a cylinder of radius `R` meshed with edges along the axis only the axial
//! edges fold, each with `θ = H/R`, so they carry `κ = 3/R` and the other edges 0, while the
//! `A_e`-weighted mean is `1/R` (see the cylinder tests). Hence `Σ_e k_θ κ_e² A_e` depends on
//! the mesh: on that cylinder mesh it is `3 k_θ/R²` per unit area, not `k_θ/R²`.

use crate::dihedral::{Vec3, signed_dihedral_angle, signed_dihedral_angle_with_derivatives};
use nalgebra::{SMatrix, SVector, Vector2};
use std::f64::consts::{FRAC_PI_2, FRAC_PI_4};

/// Rest data of one hinge.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HingeRest {
    /// `k_θ`.
    pub stiffness: f64,
    /// `H`, the mean rest altitude of `a` and `b` over the edge.
    pub mean_altitude: f64,
    /// `A_e = (A_a + A_b)/3`.
    pub area: f64,
    /// The rest angle `θ̄ = κ̄ H / 3` of the rest curvature `κ̄`.
    pub rest_angle: f64,
}

impl HingeRest {
    /// From material coordinates `[e0, e1, a, b]`, the stiffness `k_θ` and the rest curvature
    /// `κ̄` (1/m). Panics unless `(e0, e1, a)` and `(e1, e0, b)` are both counter-clockwise and
    /// non-degenerate.
    pub fn new(material: &[Vector2<f64>; 4], stiffness: f64, rest_curvature: f64) -> Self {
        let [e0, e1, a, b] = material;
        let edge = e1 - e0;
        let double_area_a = edge.perp(&(a - e0));
        let double_area_b = (e0 - e1).perp(&(b - e1));
        assert!(
            double_area_a > 0.0 && double_area_b > 0.0,
            "hinge triangles (e0, e1, a), (e1, e0, b) must be counter-clockwise"
        );
        let edge_len = edge.norm();
        let mean_altitude = 0.5 * (double_area_a + double_area_b) / edge_len;
        Self {
            stiffness,
            mean_altitude,
            area: (double_area_a + double_area_b) / 6.0,
            rest_angle: rest_curvature * mean_altitude / 3.0,
        }
    }

    /// `κ = 3θ/H`.
    fn curvature_of(&self, angle: f64) -> f64 {
        3.0 * angle / self.mean_altitude
    }

    /// `W` with `E = W θ²`: `W = 9 k_θ A_e / H²`.
    fn angle_weight(&self) -> f64 {
        9.0 * self.stiffness * self.area / (self.mean_altitude * self.mean_altitude)
    }
}

/// Energy of one hinge with its gradient and Hessian over `[e0, e1, a, b]` (12 DOFs).
#[derive(Clone, Debug)]
pub struct HingeEnergy {
    /// Energy (J).
    pub energy: f64,
    /// Gradient over the 12 hinge DOFs.
    pub gradient: SVector<f64, 12>,
    /// Hessian.
    pub hessian: SMatrix<f64, 12, 12>,
    /// Its Gauss-Newton part `2W ∇θ ⊗ ∇θ` (positive semidefinite; without `2W (θ - θ̄) ∇²θ`).
    pub gauss_newton: SMatrix<f64, 12, 12>,
}

/// Curvature `κ = 3θ/H` of the hinge at positions `[e0, e1, a, b]`.
pub fn hinge_curvature(rest: &HingeRest, hinge: &[Vec3; 4]) -> f64 {
    rest.curvature_of(signed_dihedral_angle(hinge))
}

/// `E = k_θ (κ - κ̄)² A_e`, eq. (6.4) with a rest curvature.
pub fn hinge_energy(rest: &HingeRest, hinge: &[Vec3; 4]) -> f64 {
    let excess = signed_dihedral_angle(hinge) - rest.rest_angle;
    rest.angle_weight() * excess * excess
}

/// `E = W (θ - θ̄)²`, `∇E = 2W(θ - θ̄) ∇θ`, `∇²E = 2W (∇θ ⊗ ∇θ + (θ - θ̄) ∇²θ)`.
pub fn hinge_energy_with_derivatives(rest: &HingeRest, hinge: &[Vec3; 4]) -> HingeEnergy {
    let dihedral = signed_dihedral_angle_with_derivatives(hinge);
    let (excess, weight) = (dihedral.angle - rest.rest_angle, rest.angle_weight());
    let gauss_newton = dihedral.gradient * dihedral.gradient.transpose() * (2.0 * weight);
    HingeEnergy {
        energy: weight * excess * excess,
        gradient: dihedral.gradient * (2.0 * weight * excess),
        hessian: gauss_newton + dihedral.hessian * (2.0 * weight * excess),
        gauss_newton,
    }
}

/// A hinge's bending stiffness (or rest curvature) from its rest edge direction (material
/// space), interpolated between the weft, bias and warp values.
///
/// Convention: material X is the weft and Y the warp direction; `k_weft` resists curvature
/// along X (`II11`, bending the weft yarns), `k_warp` curvature along Y (`II22`), `k_bias`
/// curvature along a diagonal. A hinge folds the cloth about its edge, so its curvature runs
/// across the edge: an edge along **Y** gets `k_weft`, an edge along **X** gets `k_warp`, a
/// diagonal edge `k_bias`. In between, the stiffness is linear in the angle `φ ∈ [0, π/2]`
/// between the edge normal and X (`|atan2|` of the normal folded into `[0, π/2]`):
/// weft at 0, bias at π/4, warp at π/2. Independent of the edge's sign and of mirroring.
pub fn anisotropic_stiffness(rest_edge_dir: &Vector2<f64>, k_weft: f64, k_bias: f64, k_warp: f64) -> f64 {
    let edge_angle = rest_edge_dir.y.atan2(rest_edge_dir.x).abs();
    let folded_edge_angle = edge_angle.min(std::f64::consts::PI - edge_angle);
    let bend_angle = FRAC_PI_2 - folded_edge_angle;
    let t = bend_angle / FRAC_PI_4;
    if t <= 1.0 { k_weft + (k_bias - k_weft) * t } else { k_bias + (k_warp - k_bias) * (t - 1.0) }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::{
        GridMesh, XorShift, assert_all_close, assert_close, fd_gradient, fd_jacobian, random_hinge,
    };

    fn hinge_from(q: &SVector<f64, 12>) -> [Vec3; 4] {
        [0, 1, 2, 3].map(|v| q.fixed_rows::<3>(3 * v).into_owned())
    }

    /// A random rest hinge: an edge with `a` left of it and `b` right of it.
    fn random_rest(rng: &mut XorShift) -> HingeRest {
        let e0 = Vector2::new(rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0));
        let along = Vector2::new(rng.uniform(0.5, 1.5), rng.uniform(-0.5, 0.5));
        let left = Vector2::new(-along.y, along.x);
        let a = e0 + rng.uniform(-0.2, 1.2) * along + rng.uniform(0.3, 1.2) * left;
        let b = e0 + rng.uniform(-0.2, 1.2) * along - rng.uniform(0.3, 1.2) * left;
        HingeRest::new(&[e0, e0 + along, a, b], rng.uniform(0.5, 2.0), rng.uniform(-2.0, 2.0))
    }

    #[test]
    fn derivatives_match_finite_differences() {
        for seed in 1..=6 {
            let mut rng = XorShift::new(seed);
            for _ in 0..10 {
                let rest = random_rest(&mut rng);
                let hinge = random_hinge(&mut rng, 2.6);
                let q = SVector::<f64, 12>::from_iterator(hinge.iter().flat_map(|v| v.iter().copied()));
                let d = hinge_energy_with_derivatives(&rest, &hinge);
                assert_close(d.energy, hinge_energy(&rest, &hinge), 1e-12 * d.energy.max(1.0));
                let fd = fd_gradient(|q| hinge_energy(&rest, &hinge_from(q)), &q);
                assert_all_close(&d.gradient, &fd, 1e-6);
                let fd_hessian =
                    fd_jacobian(|q| hinge_energy_with_derivatives(&rest, &hinge_from(q)).gradient, &q);
                assert_all_close(&d.hessian, &fd_hessian, 1e-6);
                assert_eq!(d.hessian, d.hessian.transpose());
            }
        }
    }

    #[test]
    fn energy_is_stiffness_times_curvature_squared_times_area() {
        let mut rng = XorShift::new(7);
        let rest = random_rest(&mut rng);
        let hinge = random_hinge(&mut rng, 2.0);
        let kappa = hinge_curvature(&rest, &hinge);
        let rest_kappa = 3.0 * rest.rest_angle / rest.mean_altitude;
        assert!(rest_kappa != 0.0);
        let excess = kappa - rest_kappa;
        assert_close(hinge_energy(&rest, &hinge), rest.stiffness * excess * excess * rest.area, 1e-12);
    }

    #[test]
    fn a_rest_curvature_towards_the_normal_is_the_energy_minimum_of_a_cylinder() {
        // The grid wrapped onto the cylinder curls towards +z, the normal of the flat grid.
        let radius = 0.4;
        let energy = |rest_curvature: f64| -> f64 {
            cylinder_hinges(radius)
                .iter()
                .map(|(rest, x, m)| {
                    let curled = HingeRest::new(m, rest.stiffness, rest_curvature);
                    hinge_energy(&curled, x)
                })
                .sum()
        };
        // Axial hinges carry κ = 3/R: their rest curvature 3/R makes them free of energy.
        let axial_only = |rest_curvature: f64| -> f64 {
            cylinder_hinges(radius)
                .iter()
                .filter(|(_, _, m)| (m[1].x - m[0].x).abs() < 1e-12)
                .map(|(rest, x, m)| hinge_energy(&HingeRest::new(m, rest.stiffness, rest_curvature), x))
                .sum()
        };
        assert!(axial_only(3.0 / radius) < 1e-20);
        assert!(energy(1.0 / radius) < energy(0.0) && energy(0.0) < energy(-1.0 / radius));
    }

    #[test]
    fn rest_data_of_unit_square_split() {
        let square = [(0.0, 0.0), (1.0, 1.0), (0.0, 1.0), (1.0, 0.0)].map(|(x, y)| Vector2::new(x, y));
        let rest = HingeRest::new(&square, 2.0, 0.0);
        assert_close(rest.mean_altitude, 0.5f64.sqrt(), 1e-15);
        assert_close(rest.area, 1.0 / 3.0, 1e-15);
    }

    /// Interior hinges `[e0, e1, a, b]` of a regular grid wrapped onto a cylinder of radius
    /// `radius` whose axis is along Y, with each hinge's rest data.
    fn cylinder_hinges(radius: f64) -> Vec<(HingeRest, [Vec3; 4], [Vector2<f64>; 4])> {
        let grid = GridMesh::new(0.5, 0.5, 0.01);
        let far = grid.far_vertices();
        let wrap = |p: Vector2<f64>| {
            let turn = p.x / radius;
            Vec3::new(radius * turn.sin(), p.y, radius * (1.0 - turn.cos()))
        };
        let mut hinges = Vec::new();
        for t in &grid.triangles {
            for i in 0..3 {
                let (e0, e1) = (t[(i + 1) % 3], t[(i + 2) % 3]);
                let Some(&b) = far.get(&(e0, e1)).filter(|_| e0 < e1) else {
                    continue;
                };
                let material = [e0, e1, t[i], b].map(|v| grid.material[v]);
                hinges.push((HingeRest::new(&material, 1.0, 0.0), material.map(wrap), material));
            }
        }
        hinges
    }

    #[test]
    fn cylinder_axis_aligned_hinges_carry_three_over_radius() {
        let radius = 0.4;
        for (rest, hinge, material) in cylinder_hinges(radius) {
            let kappa = hinge_curvature(&rest, &hinge);
            let along_axis = (material[1].x - material[0].x).abs() < 1e-12;
            let expected = if along_axis { 3.0 / radius } else { 0.0 };
            assert_close(kappa, expected, 1e-9 / radius);
        }
    }

    #[test]
    fn cylinder_area_weighted_curvature_is_inverse_radius() {
        let radius = 0.4;
        let hinges = cylinder_hinges(radius);
        let weighted: f64 = hinges.iter().map(|(rest, x, _)| hinge_curvature(rest, x) * rest.area).sum();
        let area: f64 = hinges.iter().map(|(rest, _, _)| rest.area).sum();
        assert_close(weighted / area, 1.0 / radius, 0.01 / radius);
    }

    #[test]
    fn stiffness_follows_the_bending_direction() {
        let (weft, bias, warp) = (1.0, 2.0, 5.0);
        let k = |x: f64, y: f64| anisotropic_stiffness(&Vector2::new(x, y), weft, bias, warp);
        assert_close(k(0.0, 1.0), weft, 1e-15);
        assert_close(k(0.0, -3.0), weft, 1e-15);
        assert_close(k(1.0, 0.0), warp, 1e-15);
        assert_close(k(-2.0, 0.0), warp, 1e-15);
        for (x, y) in [(1.0, 1.0), (-1.0, 1.0), (1.0, -1.0), (-1.0, -1.0)] {
            assert_close(k(x, y), bias, 1e-14);
        }
        let (s, c) = (std::f64::consts::PI / 8.0).sin_cos();
        assert_close(k(s, c), 0.5 * (weft + bias), 1e-14); // edge 22.5° off Y
        assert_close(k(c, -s), 0.5 * (bias + warp), 1e-14); // edge 22.5° off X
    }
}
