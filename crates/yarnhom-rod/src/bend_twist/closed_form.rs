//! Closed-form gradient and Hessian of the bend-twist energy (Bergou et al. 2008, 2010; (3.25),
//! (6.6)), exact at any configuration: the time-parallel transport of the reference directors
//! from their last update (Bergou et al. 2010) is differentiated, not approximated by its
//! derivative at the update as in those papers' Hessians.
//!
//! With unit tangents `t_k`, reference directors `d_k`, `u_k = t_k × d_k` and
//! `h = 1 / (1 + t0·t1)`, the projections of `κb = 2 h t0 × t1` on the directors are dot
//! products of one vector of each edge, and the element depends on the edges only
//! through the seven bilinears
//! `β = (χ, A, B, C, D, E, G) = (t0·t1, u0·t1, d0·t1, t0·u1, t0·d1, d0·d1, d0·u1)`:
//! - `κ1 = h (c0 B + s0 A - c1 D - s1 C)`, `κ2 = h (c0 A - s0 B - c1 C + s1 D)` with
//!   `(c_k, s_k) = (cos θ_k, sin θ_k)`;
//! - the reference twist is `atan2(h B C - G, E - h B D)`, the angle from the transport
//!   `P d0 = d0 - h B (t0 + t1)` of `d0` to `d1` about `t1`.
//!
//! The energy is `W(β(e0, e1), θ0, θ1)`, so its Hessian is `Jᵀ ∇²W J + Σ_j ∂W/∂β_j ∇²β_j`
//! (`J` the Jacobian of `(β, θ)`); the last sum needs the second derivatives of each edge
//! vector only contracted with one covector, which have closed forms.

use std::ops::{Add, Sub};

use nalgebra::{Matrix3, SMatrix, SVector, Vector3};

use super::{BendTwist, BendTwistDofs, BendTwistReference};
use crate::frames::EdgeFrame;

type Vec3 = Vector3<f64>;
type Mat3 = Matrix3<f64>;

/// Outer variables: the bilinears `χ, A, B, C, D, E, G`, then the twist angles `θ0, θ1`.
const CHI: usize = 0;
const A: usize = 1;
const B: usize = 2;
const C: usize = 3;
const D: usize = 4;
const E: usize = 5;
const G: usize = 6;
const THETA0: usize = 7;
const THETA1: usize = 8;
const OUTER: usize = 9;

/// The vectors of an edge: unit tangent and first and second reference directors.
const TANGENT: usize = 0;
const FIRST_DIRECTOR: usize = 1;
const SECOND_DIRECTOR: usize = 2;

/// Each bilinear `β_j = p·q` as (vector of edge 0, vector of edge 1), in the order of [`CHI`]..[`G`].
const BILINEARS: [(usize, usize); 7] = [
    (TANGENT, TANGENT),
    (SECOND_DIRECTOR, TANGENT),
    (FIRST_DIRECTOR, TANGENT),
    (TANGENT, SECOND_DIRECTOR),
    (TANGENT, FIRST_DIRECTOR),
    (FIRST_DIRECTOR, FIRST_DIRECTOR),
    (FIRST_DIRECTOR, SECOND_DIRECTOR),
];

/// Energy, gradient and Hessian in the DOFs `(x0, x1, x2, θ0, θ1)`.
pub(super) fn energy_gradient_hessian(
    element: &BendTwist,
    reference: &BendTwistReference,
    q: &BendTwistDofs,
) -> (f64, SVector<f64, 11>, SMatrix<f64, 11, 11>) {
    let x = |i: usize| Vec3::new(q[3 * i], q[3 * i + 1], q[3 * i + 2]);
    let edges = [
        EdgeVectors::new(&reference.frames[0], x(1) - x(0)),
        EdgeVectors::new(&reference.frames[1], x(2) - x(1)),
    ];
    let (beta, beta_jacobian) = bilinears(&edges);
    let w = element.outer_energy(reference.reference_twist_rad, &beta, [q[9], q[10]]);
    let mu = std::array::from_fn(|j| w.gradient[j]);
    let gradient = reduced_gradient(&beta_jacobian, &w.gradient);
    let hessian = reduced_hessian(&beta_jacobian, &w.hessian, &weighted_bilinear_hessian(&edges, &mu));
    (w.value, to_dofs(&gradient), to_dofs(&to_dofs(&hessian).transpose()))
}

/// The unit tangent `t = e / |e|` of an edge vector `e`, with its Jacobian `(I - t tᵀ) / |e|`.
struct Tangent {
    t: Vec3,
    inverse_length: f64,
    jacobian: Mat3,
}

impl Tangent {
    fn new(e: Vec3) -> Self {
        let inverse_length = e.norm().recip();
        let t = e * inverse_length;
        Tangent { t, inverse_length, jacobian: (Mat3::identity() - t * t.transpose()) * inverse_length }
    }

    /// `Σ_i w_i ∂²t_i/∂e² = -(w tᵀ + t wᵀ + (w·t) (I - 3 t tᵀ)) / |e|²`.
    fn hessian_along(&self, w: &Vec3) -> Mat3 {
        let t = self.t;
        let symmetric = w * t.transpose() + t * w.transpose();
        let normal = (Mat3::identity() - t * t.transpose() * 3.0) * w.dot(&t);
        -(symmetric + normal) * self.inverse_length.powi(2)
    }
}

/// A vector `v ⟂ a` parallel transported from the unit tangent `a` to `t`:
/// `T(t) = v - φ (a + t)` with `φ = v·t / (1 + a·t)`, which on unit `t` is the rotation of
/// [`crate::frames::parallel_transport`]; with its Jacobian in `t`.
struct Transported {
    value: Vec3,
    a: Vec3,
    a_plus_t: Vec3,
    inverse_one_plus_at: f64,
    /// `∇φ = (v - φ a) / (1 + a·t)`.
    grad_phi: Vec3,
    jacobian: Mat3,
}

impl Transported {
    fn new(a: Vec3, v: Vec3, t: Vec3) -> Self {
        let inverse_one_plus_at = (1.0 + a.dot(&t)).recip();
        let phi = v.dot(&t) * inverse_one_plus_at;
        let grad_phi = (v - a * phi) * inverse_one_plus_at;
        let a_plus_t = a + t;
        let jacobian = -(a_plus_t * grad_phi.transpose()) - Mat3::identity() * phi;
        Transported { value: v - a_plus_t * phi, a, a_plus_t, inverse_one_plus_at, grad_phi, jacobian }
    }

    /// `Σ_i w_i ∂²T_i/∂t² = -(w·(a + t)) ∇²φ - (w ∇φᵀ + ∇φ wᵀ)`, with
    /// `∇²φ = -(a ∇φᵀ + ∇φ aᵀ) / (1 + a·t)`.
    fn hessian_along(&self, w: &Vec3) -> Mat3 {
        let g = self.grad_phi;
        let along = w.dot(&self.a_plus_t) * self.inverse_one_plus_at;
        (self.a * g.transpose() + g * self.a.transpose()) * along - (w * g.transpose() + g * w.transpose())
    }
}

/// An edge's tangent and reference directors `(t, d, u)` (indexed by [`TANGENT`],
/// [`FIRST_DIRECTOR`], [`SECOND_DIRECTOR`]) with their Jacobians in the edge vector.
/// `u = t × d` is the transport of `a × d̄`, as rotations commute with the cross product.
struct EdgeVectors {
    tangent: Tangent,
    directors: [Transported; 2],
    values: [Vec3; 3],
    jacobians: [Mat3; 3],
}

impl EdgeVectors {
    fn new(frame: &EdgeFrame, e: Vec3) -> Self {
        let tangent = Tangent::new(e);
        let (a, d) = (Vec3::from(frame.tangent), Vec3::from(frame.director));
        let directors = [Transported::new(a, d, tangent.t), Transported::new(a, a.cross(&d), tangent.t)];
        let values = [tangent.t, directors[0].value, directors[1].value];
        let jt = tangent.jacobian;
        let jacobians = [jt, directors[0].jacobian * jt, directors[1].jacobian * jt];
        EdgeVectors { tangent, directors, values, jacobians }
    }

    /// `Σ_k w_k·∂²v_k/∂e²` for covectors `w_k` on the vectors `v_k = (t, d, u)`, by the chain
    /// rule through `t`.
    fn hessian_along(&self, w: &[Vec3; 3]) -> Mat3 {
        let [d, u] = &self.directors;
        let jt = self.tangent.jacobian;
        let w_t = w[TANGENT]
            + d.jacobian.transpose() * w[FIRST_DIRECTOR]
            + u.jacobian.transpose() * w[SECOND_DIRECTOR];
        self.tangent.hessian_along(&w_t)
            + jt.transpose()
                * (d.hessian_along(&w[FIRST_DIRECTOR]) + u.hessian_along(&w[SECOND_DIRECTOR]))
                * jt
    }
}

/// The bilinears `β` and their Jacobian in `(e0, e1)`.
fn bilinears(edges: &[EdgeVectors; 2]) -> ([f64; 7], SMatrix<f64, 7, 6>) {
    let mut jacobian = SMatrix::<f64, 7, 6>::zeros();
    let values = std::array::from_fn(|j| {
        let (p, q) = BILINEARS[j];
        let (vp, vq) = (edges[0].values[p], edges[1].values[q]);
        jacobian.fixed_view_mut::<1, 3>(j, 0).tr_copy_from(&(edges[0].jacobians[p].tr_mul(&vq)));
        jacobian.fixed_view_mut::<1, 3>(j, 3).tr_copy_from(&(edges[1].jacobians[q].tr_mul(&vp)));
        vp.dot(&vq)
    });
    (values, jacobian)
}

/// `Σ_j μ_j ∇²β_j` in `(e0, e1)`.
fn weighted_bilinear_hessian(edges: &[EdgeVectors; 2], mu: &[f64; 7]) -> SMatrix<f64, 6, 6> {
    let mut covectors = [[Vec3::zeros(); 3]; 2];
    let mut mixed = Mat3::zeros();
    for (&(p, q), &m) in BILINEARS.iter().zip(mu) {
        covectors[0][p] += edges[1].values[q] * m;
        covectors[1][q] += edges[0].values[p] * m;
        mixed += edges[0].jacobians[p].tr_mul(&edges[1].jacobians[q]) * m;
    }
    let mut hessian = SMatrix::<f64, 6, 6>::zeros();
    hessian.fixed_view_mut::<3, 3>(0, 0).copy_from(&edges[0].hessian_along(&covectors[0]));
    hessian.fixed_view_mut::<3, 3>(3, 3).copy_from(&edges[1].hessian_along(&covectors[1]));
    hessian.fixed_view_mut::<3, 3>(0, 3).copy_from(&mixed);
    hessian.fixed_view_mut::<3, 3>(3, 0).copy_from(&mixed.transpose());
    hessian
}

/// The gradient in the reduced variables `(e0, e1, θ0, θ1)` from the one in the outer
/// variables `(β, θ0, θ1)`, whose Jacobian is `diag(Jβ, I)`.
fn reduced_gradient(beta_jacobian: &SMatrix<f64, 7, 6>, outer: &SVector<f64, OUTER>) -> SVector<f64, 8> {
    let mut gradient = SVector::<f64, 8>::zeros();
    gradient.fixed_rows_mut::<6>(0).copy_from(&beta_jacobian.tr_mul(&outer.fixed_rows::<7>(0)));
    gradient.fixed_rows_mut::<2>(6).copy_from(&outer.fixed_rows::<2>(THETA0));
    gradient
}

/// The Hessian in the reduced variables, `diag(Jβ, I)ᵀ ∇²W diag(Jβ, I)` from the outer
/// Hessian `∇²W`, plus `Σ_j ∂W/∂β_j ∇²β_j` (`bilinear`) in the edge block.
fn reduced_hessian(
    beta_jacobian: &SMatrix<f64, 7, 6>,
    outer: &SMatrix<f64, OUTER, OUTER>,
    bilinear: &SMatrix<f64, 6, 6>,
) -> SMatrix<f64, 8, 8> {
    let edges = beta_jacobian.tr_mul(&outer.fixed_view::<7, 7>(0, 0)) * beta_jacobian + bilinear;
    let mixed = beta_jacobian.tr_mul(&outer.fixed_view::<7, 2>(0, THETA0));
    let mut hessian = SMatrix::<f64, 8, 8>::zeros();
    hessian.fixed_view_mut::<6, 6>(0, 0).copy_from(&edges);
    hessian.fixed_view_mut::<6, 2>(0, 6).copy_from(&mixed);
    hessian.fixed_view_mut::<2, 6>(6, 0).copy_from(&mixed.transpose());
    hessian.fixed_view_mut::<2, 2>(6, 6).copy_from(&outer.fixed_view::<2, 2>(THETA0, THETA0));
    hessian
}

/// `Lᵀ a` for the map `L` from the DOFs `(x0, x1, x2, θ0, θ1)` to the reduced variables
/// `(e0, e1, θ0, θ1)`, `e0 = x1 - x0`, `e1 = x2 - x1`: pulls derivatives back to the DOFs.
fn to_dofs<const C: usize>(a: &SMatrix<f64, 8, C>) -> SMatrix<f64, 11, C> {
    let (e0, e1) = (a.fixed_rows::<3>(0), a.fixed_rows::<3>(3));
    let mut pulled = SMatrix::<f64, 11, C>::zeros();
    pulled.fixed_rows_mut::<3>(0).copy_from(&(-e0));
    pulled.fixed_rows_mut::<3>(3).copy_from(&(e0 - e1));
    pulled.fixed_rows_mut::<3>(6).copy_from(&e1);
    pulled.fixed_rows_mut::<2>(9).copy_from(&a.fixed_rows::<2>(6));
    pulled
}

/// A function of the outer variables with its gradient and Hessian.
#[derive(Debug, Clone, Copy)]
struct Jet {
    value: f64,
    gradient: SVector<f64, OUTER>,
    hessian: SMatrix<f64, OUTER, OUTER>,
}

impl Jet {
    fn constant(value: f64) -> Self {
        Jet { value, gradient: SVector::zeros(), hessian: SMatrix::zeros() }
    }

    fn variable(index: usize, value: f64) -> Self {
        let mut jet = Jet::constant(value);
        jet.gradient[index] = 1.0;
        jet
    }

    fn set_mixed(&mut self, i: usize, j: usize, value: f64) {
        self.hessian[(i, j)] = value;
        self.hessian[(j, i)] = value;
    }

    /// `s X + c Y` for `(s, c) = (sin φ, cos φ)` of an angle `φ = θ + const` (the variable
    /// `indices[2]`), `X` and `Y` the variables `indices[0]`, `indices[1]`.
    fn rotated(indices: [usize; 3], xy: [f64; 2], (s, c): (f64, f64)) -> Self {
        let [ix, iy, itheta] = indices;
        let [x, y] = xy;
        let mut jet = Jet::constant(s * x + c * y);
        jet.gradient[ix] = s;
        jet.gradient[iy] = c;
        jet.gradient[itheta] = c * x - s * y;
        jet.set_mixed(ix, itheta, c);
        jet.set_mixed(iy, itheta, -s);
        jet.hessian[(itheta, itheta)] = -jet.value;
        jet
    }

    /// The product `X Y` of two variables.
    fn product(indices: [usize; 2], xy: [f64; 2]) -> Self {
        let mut jet = Jet::constant(xy[0] * xy[1]);
        jet.gradient[indices[0]] = xy[1];
        jet.gradient[indices[1]] = xy[0];
        jet.set_mixed(indices[0], indices[1], 1.0);
        jet
    }

    /// `self / (1 + χ)`, for `self` independent of `χ`.
    fn over_one_plus_chi(self, chi: f64) -> Self {
        let h = (1.0 + chi).recip();
        let mut jet = Jet { value: self.value * h, gradient: self.gradient * h, hessian: self.hessian * h };
        let cross = self.gradient * (-h * h);
        jet.hessian.set_column(CHI, &cross);
        jet.hessian.set_row(CHI, &cross.transpose());
        jet.hessian[(CHI, CHI)] = 2.0 * h * h * h * self.value;
        jet.gradient[CHI] = -h * h * self.value;
        jet
    }

    /// `atan2(y, x)`.
    fn atan2(y: Self, x: Self) -> Self {
        let r2 = x.value * x.value + y.value * y.value;
        let (dx, dy) = (-y.value / r2, x.value / r2);
        let dxx = 2.0 * x.value * y.value / (r2 * r2);
        let dxy = (y.value * y.value - x.value * x.value) / (r2 * r2);
        let (gx, gy) = (x.gradient, y.gradient);
        let hessian = x.hessian * dx
            + y.hessian * dy
            + (gx * gx.transpose() - gy * gy.transpose()) * dxx
            + (gx * gy.transpose() + gy * gx.transpose()) * dxy;
        Jet { value: y.value.atan2(x.value), gradient: gx * dx + gy * dy, hessian }
    }

    /// `weight (self - rest)²`.
    fn squared_deviation(self, rest: f64, weight: f64) -> Self {
        let r = self.value - rest;
        let g = self.gradient;
        Jet {
            value: weight * r * r,
            gradient: g * (2.0 * weight * r),
            hessian: (g * g.transpose() + self.hessian * r) * (2.0 * weight),
        }
    }
}

impl Add for Jet {
    type Output = Jet;
    fn add(self, o: Jet) -> Jet {
        Jet {
            value: self.value + o.value,
            gradient: self.gradient + o.gradient,
            hessian: self.hessian + o.hessian,
        }
    }
}

impl Sub for Jet {
    type Output = Jet;
    fn sub(self, o: Jet) -> Jet {
        Jet {
            value: self.value - o.value,
            gradient: self.gradient - o.gradient,
            hessian: self.hessian - o.hessian,
        }
    }
}

impl BendTwist {
    /// The energy as a function of the outer variables `(β, θ0, θ1)`; `reference_twist` picks
    /// the branch of the reference twist.
    fn outer_energy(&self, reference_twist: f64, beta: &[f64; 7], theta: [f64; 2]) -> Jet {
        let [k1, k2] = curvature(beta, theta);
        let raw = reference_twist_jet(beta);
        let turns = ((reference_twist - raw.value) / std::f64::consts::TAU).round();
        let mut twist = raw + Jet::variable(THETA1, theta[1]) - Jet::variable(THETA0, theta[0]);
        twist.value += turns * std::f64::consts::TAU;
        let [a1, a2] = self.bend_stiffness_nm2;
        let scale = self.rest_length_sum_m.recip();
        k1.squared_deviation(self.rest_curvature[0], a1 * scale)
            + k2.squared_deviation(self.rest_curvature[1], a2 * scale)
            + twist.squared_deviation(self.rest_twist_rad, self.twist_stiffness_nm2 * scale)
    }
}

/// Material curvature `κ1 = h (c0 B + s0 A - c1 D - s1 C)`, `κ2 = h (c0 A - s0 B - c1 C + s1 D)`.
fn curvature(beta: &[f64; 7], theta: [f64; 2]) -> [Jet; 2] {
    let (s0, c0) = theta[0].sin_cos();
    let (s1, c1) = theta[1].sin_cos();
    let edge0 = |sc| Jet::rotated([A, B, THETA0], [beta[A], beta[B]], sc);
    let edge1 = |sc| Jet::rotated([C, D, THETA1], [beta[C], beta[D]], sc);
    [edge0((s0, c0)) - edge1((s1, c1)), edge0((c0, -s0)) - edge1((c1, -s1))]
        .map(|k| k.over_one_plus_chi(beta[CHI]))
}

/// Reference twist `atan2(h B C - G, E - h B D)` (in `(-π, π]`).
fn reference_twist_jet(beta: &[f64; 7]) -> Jet {
    let transported =
        |other: usize| Jet::product([B, other], [beta[B], beta[other]]).over_one_plus_chi(beta[CHI]);
    let x = Jet::variable(E, beta[E]) - transported(D);
    let y = transported(C) - Jet::variable(G, beta[G]);
    Jet::atan2(y, x)
}
