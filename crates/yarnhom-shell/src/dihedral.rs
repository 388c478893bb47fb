//! Signed dihedral angle of a hinge and the altitude of a triangle over an edge, with exact
//! closed-form gradients and Hessians in the style of Tamstorf & Grinspun 2013, "Discrete
//! bending forces and their Jacobians".
//!
//! A hinge is `[p0, p1, a, b]`: the edge `p0 → p1`, the triangle `(p0, p1, a)` and the triangle
//! `(p1, p0, b)`, both counter-clockwise about their normals `n_a`, `n_b` (a consistently
//! oriented mesh). The signed angle is
//! `θ = atan2((n_b × n_a) · ê, n_a · n_b)`, `ê = (p1 - p0)/|p1 - p0|`,
//! which is positive when `b` lies on the `+n_a` side of the plane of `(p0, p1, a)`, i.e. when
//! the surface bends towards the normal. In `(-π, π]`, smooth away from `±π`.
//!
//! The derivation treats each triangle as a *wing* `(q0, q1, apex)` seen from its edge,
//! in its local frame `(ê, u, n)`: `ê` the unit edge direction, `n` the unit normal,
//! `u = n × ê` the in-plane edge normal towards the apex. With `l` the edge length, `h` the
//! apex altitude, `ξ` the apex's foot parameter along `q0 → q1` and, over `[q0, q1, apex]`,
//! `α = (ξ - 1, -ξ, 1)`, `σ = (-1, 1, 0)`:
//!
//! * `∇h = α ⊗ u`, and each wing adds `α ⊗ n/h` to `∇θ`;
//! * `∂n/∂x_v = -(α_v u/h + σ_v ê/l) nᵀ`, `∂ξ/∂x_v = α_v ê/l + σ_v h u/l²`;
//! * hence closed-form Hessian blocks (`Wing::angle_hessian_block`,
//!   `Wing::altitude_hessian_block`), each a few scaled outer products of the frame vectors.
//!
//! All triangles must be non-degenerate; θ jumps at `±π` (a fully folded hinge).

use nalgebra::{Matrix3, SMatrix, SVector, Vector3};

/// A point or vector in world space (m).
pub type Vec3 = Vector3<f64>;

/// `σ` over `[q0, q1, apex]`.
const SIGMA: [f64; 3] = [-1.0, 1.0, 0.0];

/// Wing-local index of each hinge slot `[p0, p1, a, b]` in the wings `(p0, p1, a)` and
/// `(p1, p0, b)`.
const WING_A_INDEX: [Option<usize>; 4] = [Some(0), Some(1), Some(2), None];
const WING_B_INDEX: [Option<usize>; 4] = [Some(1), Some(0), None, Some(2)];

/// Signed dihedral angle θ with its gradient and Hessian over `[p0, p1, a, b]` (12 DOFs).
#[derive(Clone, Debug)]
pub struct DihedralDerivatives {
    /// The signed dihedral angle (rad).
    pub angle: f64,
    /// Its gradient over the 12 hinge DOFs.
    pub gradient: SVector<f64, 12>,
    /// Its Hessian.
    pub hessian: SMatrix<f64, 12, 12>,
}

/// Signed dihedral angle θ of the hinge `[p0, p1, a, b]` (see the module docs for the sign).
pub fn signed_dihedral_angle(hinge: &[Vec3; 4]) -> f64 {
    let [p0, p1, a, b] = hinge;
    let edge = p1 - p0;
    let normal_a = edge.cross(&(a - p0));
    let normal_b = (p0 - p1).cross(&(b - p1));
    angle_between_normals(&normal_a, &normal_b, &edge)
}

/// θ from (not necessarily unit) normals and the edge `p0 → p1`; atan2 is scale invariant.
pub(crate) fn angle_between_normals(normal_a: &Vec3, normal_b: &Vec3, edge: &Vec3) -> f64 {
    let sine = normal_b.cross(normal_a).dot(edge);
    let cosine = normal_a.dot(normal_b) * edge.norm();
    sine.atan2(cosine)
}

/// θ, ∇θ and ∇²θ of the hinge `[p0, p1, a, b]`.
pub fn signed_dihedral_angle_with_derivatives(hinge: &[Vec3; 4]) -> DihedralDerivatives {
    let hinge = Hinge::new(hinge);
    let mut gradient = SVector::<f64, 12>::zeros();
    let mut hessian = SMatrix::<f64, 12, 12>::zeros();
    for (s, slot_gradient) in hinge.angle_gradient().iter().enumerate() {
        gradient.fixed_rows_mut::<3>(3 * s).copy_from(slot_gradient);
        for t in s..4 {
            add_symmetric_block(&mut hessian, s, t, &hinge.angle_hessian_block(s, t));
        }
    }
    DihedralDerivatives { angle: hinge.angle(), gradient, hessian }
}

/// Adds the 3×3 `block` at vertex slots `(s, t)` of a Hessian and, for `s ≠ t`, its transpose
/// at `(t, s)`. Plain column-major indexing: nalgebra's strided views are much slower here.
pub(crate) fn add_symmetric_block<const N: usize>(
    hessian: &mut SMatrix<f64, N, N>,
    s: usize,
    t: usize,
    block: &Matrix3<f64>,
) {
    let data = hessian.as_mut_slice();
    for c in 0..3 {
        for r in 0..3 {
            data[(3 * t + c) * N + 3 * s + r] += block[(r, c)];
            if s != t {
                data[(3 * s + r) * N + 3 * t + c] += block[(r, c)];
            }
        }
    }
}

/// The two wings `(p0, p1, a)` and `(p1, p0, b)` of a hinge `[p0, p1, a, b]`.
pub(crate) struct Hinge {
    pub wing_a: Wing,
    pub wing_b: Wing,
}

impl Hinge {
    pub fn new(hinge: &[Vec3; 4]) -> Self {
        let [p0, p1, a, b] = hinge;
        Self { wing_a: Wing::new(p0, p1, a), wing_b: Wing::new(p1, p0, b) }
    }

    pub fn angle(&self) -> f64 {
        angle_between_normals(&self.wing_a.normal, &self.wing_b.normal, &self.wing_a.edge_dir)
    }

    /// `∇θ` per hinge slot `[p0, p1, a, b]`.
    pub fn angle_gradient(&self) -> [Vec3; 4] {
        [0, 1, 2, 3].map(|s| {
            let part = |wing: &Wing, index: Option<usize>| {
                index.map_or_else(Vec3::zeros, |v| wing.angle_gradient(v))
            };
            part(&self.wing_a, WING_A_INDEX[s]) + part(&self.wing_b, WING_B_INDEX[s])
        })
    }

    /// Block `(s, t)` of `∇²θ` over hinge slots; symmetric: block `(t, s)` is its transpose.
    pub fn angle_hessian_block(&self, s: usize, t: usize) -> Matrix3<f64> {
        let part = |wing: &Wing, index: &[Option<usize>; 4]| match (index[s], index[t]) {
            (Some(u), Some(v)) => wing.angle_hessian_block(u, v),
            _ => Matrix3::zeros(),
        };
        part(&self.wing_a, &WING_A_INDEX) + part(&self.wing_b, &WING_B_INDEX)
    }
}

/// A triangle `(q0, q1, apex)`, counter-clockwise about its normal, seen from its edge
/// `q0 → q1`. Wing-local vertex indices are `[q0, q1, apex]`.
pub(crate) struct Wing {
    pub normal: Vec3,
    /// Distance of the apex from the edge line, `h = 2 area / |q1 - q0|`.
    pub altitude: f64,
    edge_dir: Vec3,
    edge_len: f64,
    /// `u = n × ê`, the unit in-plane edge normal pointing towards the apex.
    inward: Vec3,
    /// `α = (ξ - 1, -ξ, 1)`, ξ the foot parameter of the apex along `q0 → q1`.
    alpha: [f64; 3],
    /// `u nᵀ + n uᵀ`.
    inward_normal_sym: Matrix3<f64>,
    /// `ê nᵀ`.
    edge_normal: Matrix3<f64>,
    /// `ê uᵀ`.
    edge_inward: Matrix3<f64>,
    /// `n nᵀ`.
    normal_normal: Matrix3<f64>,
    /// `u uᵀ`.
    inward_inward: Matrix3<f64>,
}

impl Wing {
    pub fn new(q0: &Vec3, q1: &Vec3, apex: &Vec3) -> Self {
        let edge = q1 - q0;
        let to_apex = apex - q0;
        let edge_len_sq = edge.norm_squared();
        let edge_len = edge_len_sq.sqrt();
        let scaled_normal = edge.cross(&to_apex);
        let double_area = scaled_normal.norm();
        let normal = scaled_normal / double_area;
        let edge_dir = edge / edge_len;
        let inward = normal.cross(&edge_dir);
        let foot = to_apex.dot(&edge) / edge_len_sq;
        let inward_normal = inward * normal.transpose();
        Self {
            normal,
            altitude: double_area / edge_len,
            edge_dir,
            edge_len,
            inward,
            alpha: [foot - 1.0, -foot, 1.0],
            inward_normal_sym: inward_normal + inward_normal.transpose(),
            edge_normal: edge_dir * normal.transpose(),
            edge_inward: edge_dir * inward.transpose(),
            normal_normal: normal * normal.transpose(),
            inward_inward: inward * inward.transpose(),
        }
    }

    /// `∂h/∂x_v = α_v u`.
    pub fn altitude_gradient(&self, v: usize) -> Vec3 {
        self.inward * self.alpha[v]
    }

    /// Block `(u, v)` of `∇²h`:
    /// `(α_u α_v/h) n nᵀ - (α_u σ_v ê uᵀ + σ_u α_v u êᵀ)/l - σ_u σ_v (h/l²) u uᵀ`.
    pub fn altitude_hessian_block(&self, u: usize, v: usize) -> Matrix3<f64> {
        let (a, s, h, l) = (self.alpha, SIGMA, self.altitude, self.edge_len);
        self.normal_normal * (a[u] * a[v] / h)
            - (self.edge_inward * (a[u] * s[v]) + self.edge_inward.transpose() * (s[u] * a[v])) / l
            + self.inward_inward * (-s[u] * s[v] * h / (l * l))
    }

    /// This wing's part of `∂θ/∂x_v`: `α_v n/h`.
    fn angle_gradient(&self, v: usize) -> Vec3 {
        self.normal * (self.alpha[v] / self.altitude)
    }

    /// Block `(u, v)` of this wing's part of `∇²θ`, the Jacobian of `α_u n/h`:
    /// `-(α_u α_v/h² + σ_u σ_v/(2l²)) (u nᵀ + n uᵀ) - (α_u σ_v ê nᵀ + σ_u α_v n êᵀ)/(l h)`.
    /// The exact Jacobian has `-σ_u σ_v n uᵀ/l²` where this has its symmetric part; the
    /// dropped `-σ_u σ_v [ê]×/(2l²)` cancels between the two wings of a hinge, whose edge
    /// directions `ê` are opposite.
    fn angle_hessian_block(&self, u: usize, v: usize) -> Matrix3<f64> {
        let (a, s, h, l) = (self.alpha, SIGMA, self.altitude, self.edge_len);
        let tilt = a[u] * a[v] / (h * h) + s[u] * s[v] / (2.0 * l * l);
        let twist = self.edge_normal * (a[u] * s[v]) + self.edge_normal.transpose() * (s[u] * a[v]);
        -(self.inward_normal_sym * tilt + twist / (l * h))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::{
        XorShift, apex_across, assert_all_close, assert_close, fd_gradient, fd_jacobian, random_hinge,
        random_triangle,
    };

    fn hinge_from(q: &SVector<f64, 12>) -> [Vec3; 4] {
        [0, 1, 2, 3].map(|v| q.fixed_rows::<3>(3 * v).into_owned())
    }

    fn dofs_of<const N: usize>(vertices: &[Vec3]) -> SVector<f64, N> {
        SVector::from_iterator(vertices.iter().flat_map(|v| v.iter().copied()))
    }

    #[test]
    fn sign_is_positive_when_bending_towards_normal() {
        let hinge = |lift: f64| {
            [
                Vec3::zeros(),
                Vec3::new(0.0, 1.0, 0.0),
                Vec3::new(-1.0, 0.5, 0.0), // (p0, p1, a) has normal +z
                Vec3::new(1.0, 0.5, lift),
            ]
        };
        assert!(signed_dihedral_angle(&hinge(0.3)) > 0.0);
        assert!(signed_dihedral_angle(&hinge(-0.3)) < 0.0);
        assert_close(signed_dihedral_angle(&hinge(1.0)), std::f64::consts::FRAC_PI_4, 1e-14);
    }

    #[test]
    fn angle_is_the_constructed_fold() {
        let mut rng = XorShift::new(5);
        for k in 0..50 {
            let [p0, p1, a] = random_triangle(&mut rng);
            let fold = -3.0 + 6.0 * k as f64 / 49.0;
            let b = apex_across(&mut rng, &p0, &p1, &a, fold);
            let hinge = [p0, p1, a, b];
            assert_close(signed_dihedral_angle(&hinge), fold, 1e-12);
            assert_close(signed_dihedral_angle_with_derivatives(&hinge).angle, fold, 1e-12);
        }
    }

    #[test]
    fn gradient_and_hessian_match_finite_differences() {
        for seed in 1..=8 {
            let mut rng = XorShift::new(seed);
            for _ in 0..10 {
                let hinge = random_hinge(&mut rng, 2.6);
                let q = dofs_of::<12>(&hinge);
                let d = signed_dihedral_angle_with_derivatives(&hinge);
                let fd = fd_gradient(|q| signed_dihedral_angle(&hinge_from(q)), &q);
                assert_all_close(&d.gradient, &fd, 1e-6);
                let fd_hessian =
                    fd_jacobian(|q| signed_dihedral_angle_with_derivatives(&hinge_from(q)).gradient, &q);
                assert_all_close(&d.hessian, &fd_hessian, 1e-6);
                assert_eq!(d.hessian, d.hessian.transpose());
            }
        }
    }

    #[test]
    fn altitude_derivatives_match_finite_differences() {
        let wing_of = |q: &SVector<f64, 9>| {
            let v = [0, 1, 2].map(|i| q.fixed_rows::<3>(3 * i).into_owned());
            Wing::new(&v[0], &v[1], &v[2])
        };
        let gradient_of =
            |wing: &Wing| SVector::<f64, 9>::from_fn(|k, _| wing.altitude_gradient(k / 3)[k % 3]);
        let mut rng = XorShift::new(11);
        for _ in 0..20 {
            let q = dofs_of::<9>(&random_triangle(&mut rng));
            let wing = wing_of(&q);
            let fd = fd_gradient(|q| wing_of(q).altitude, &q);
            assert_all_close(&gradient_of(&wing), &fd, 1e-6);
            let fd_hessian = fd_jacobian(|q| gradient_of(&wing_of(q)), &q);
            let hessian = SMatrix::<f64, 9, 9>::from_fn(|r, c| {
                wing.altitude_hessian_block(r / 3, c / 3)[(r % 3, c % 3)]
            });
            assert_all_close(&hessian, &fd_hessian, 1e-6);
        }
    }
}
