//! Bending and twisting at one interior vertex of a discrete elastic rod (Bergou et al. 2008,
//! 2010), the element of (3.25) and, with isotropic stiffness, (6.6).
//!
//! DOFs `q = (x0, x1, x2, θ0, θ1)`: the vertex `x1`, its neighbours, and the twist angles of the
//! material frames of edges `e0 = x1 - x0`, `e1 = x2 - x1` relative to their reference frames.
//! - curvature binormal `κb = 2 t0 × t1 / (1 + t0·t1)`;
//! - material curvature `κ = (½ (m2⁰ + m2¹)·κb, -½ (m1⁰ + m1¹)·κb)`;
//! - twist `m = θ1 - θ0 + m_ref`, with the reference twist `m_ref` the angle from the parallel
//!   transport of edge 0's reference director to edge 1's;
//! - energy `[α1 (κ1 - κ̄1)² + α2 (κ2 - κ̄2)² + β (m - m̄)²] / l̄` with `l̄ = L̄0 + L̄1`, which
//!   converges to `½ ∫ (EI κ² + GJ τ²) ds` and equals (6.6) for `α1 = α2 = k_b`.
//!
//! Reference directors are time-parallel: between updates they follow their edges by parallel
//! transport from the tangent of the last update ([`EdgeFrame`]). The energy is written once,
//! generic over dual numbers; its gradient and Hessian are exact derivatives of that function,
//! in closed form ([`BendTwist::energy_gradient_hessian`], derived in `closed_form`) and, as the
//! reference the tests check it against, with second-order forward-mode dual numbers
//! (`num-dual`, [`BendTwist::energy_gradient_hessian_autodiff`]).

use nalgebra::{SMatrix, SVector};
use num_dual::{Dual2SVec64, DualNum};

use crate::frames::{EdgeFrame, parallel_transport, signed_angle};
use crate::vec3::V3;

mod closed_form;

/// Stiffness and rest shape of one bending-twisting element.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BendTwist {
    /// Bending stiffnesses `(α1, α2)` about the material directors (N m²): `γ E I` in Ch. 3-5
    /// ((3.25), `I = π r⁴ / 4`), `k_b` in Ch. 6.
    pub bend_stiffness_nm2: [f64; 2],
    /// Twisting stiffness `β` (N m²): `γ G J` in Ch. 3-5 (`J = π r⁴ / 2`); 0 in Ch. 6.
    pub twist_stiffness_nm2: f64,
    /// Rest material curvature `κ̄`.
    pub rest_curvature: [f64; 2],
    /// Rest twist `m̄` (rad).
    pub rest_twist_rad: f64,
    /// `l̄ = L̄0 + L̄1`, the sum of the rest lengths of the two edges (m).
    pub rest_length_sum_m: f64,
}

/// The reference of one element: the two edges' frames at their last update and the reference
/// twist then.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BendTwistReference {
    /// Frames of edges 0 and 1.
    pub frames: [EdgeFrame; 2],
    /// Reference twist at the last update (rad), which picks the branch of the angle.
    pub reference_twist_rad: f64,
}

/// DOFs of one element: `(x0, x1, x2, θ0, θ1)`.
pub type BendTwistDofs = SVector<f64, 11>;

/// Material curvature `(κ1, κ2)` and twist `m` of the element, for any dual number type.
pub fn curvature_and_twist<T: DualNum<Primitive = f64> + Copy>(
    reference: &BendTwistReference,
    q: &[T; 11],
) -> ([T; 2], T) {
    let x = |i: usize| V3([q[3 * i], q[3 * i + 1], q[3 * i + 2]]);
    let (e0, e1) = (x(1) - x(0), x(2) - x(1));
    let (t0, t1) = (e0.normalized(), e1.normalized());
    let d0 = reference.frames[0].director_at(t0);
    let d1 = reference.frames[1].director_at(t1);
    let (m1_0, m2_0) = material_frame(t0, d0, q[9]);
    let (m1_1, m2_1) = material_frame(t1, d1, q[10]);
    let kb = t0.cross(t1).scale((t0.dot(t1) + 1.0).recip() * 2.0);
    let half = T::from(0.5);
    let kappa = [(m2_0 + m2_1).dot(kb) * half, -((m1_0 + m1_1).dot(kb) * half)];
    let raw = signed_angle(parallel_transport(t0, t1, d0), d1, t1);
    let turns = ((reference.reference_twist_rad - raw.re()) / std::f64::consts::TAU).round();
    let reference_twist = raw + turns * std::f64::consts::TAU;
    (kappa, q[10] - q[9] + reference_twist)
}

/// Material directors `(m1, m2)` of an edge with tangent `t`, reference director `d` and twist
/// angle `theta`.
fn material_frame<T: DualNum<Primitive = f64> + Copy>(t: V3<T>, d: V3<T>, theta: T) -> (V3<T>, V3<T>) {
    let d2 = t.cross(d);
    let (s, c) = theta.sin_cos();
    (d.scale(c) + d2.scale(s), d2.scale(c) - d.scale(s))
}

impl BendTwist {
    fn energy_of<T: DualNum<Primitive = f64> + Copy>(
        &self,
        reference: &BendTwistReference,
        q: &[T; 11],
    ) -> T {
        let (kappa, twist) = curvature_and_twist(reference, q);
        let [a1, a2] = self.bend_stiffness_nm2;
        let d1 = kappa[0] - self.rest_curvature[0];
        let d2 = kappa[1] - self.rest_curvature[1];
        let dm = twist - self.rest_twist_rad;
        (d1 * d1 * a1 + d2 * d2 * a2 + dm * dm * self.twist_stiffness_nm2) / self.rest_length_sum_m
    }

    /// The element's energy (J).
    pub fn energy(&self, reference: &BendTwistReference, q: &BendTwistDofs) -> f64 {
        self.energy_of(reference, &std::array::from_fn(|i| q[i]))
    }

    /// Energy, gradient and Hessian in the DOFs `(x0, x1, x2, θ0, θ1)`, exact (to round-off) at
    /// any configuration, in closed form. The reference frames must be orthonormal, as
    /// [`EdgeFrame`] keeps them.
    pub fn energy_gradient_hessian(
        &self,
        reference: &BendTwistReference,
        q: &BendTwistDofs,
    ) -> (f64, SVector<f64, 11>, SMatrix<f64, 11, 11>) {
        closed_form::energy_gradient_hessian(self, reference, q)
    }

    /// [`Self::energy_gradient_hessian`] by second-order forward-mode dual numbers over all 11
    /// DOFs: the reference implementation, far slower (about 60 times on one
    /// x86-64 core).
    pub fn energy_gradient_hessian_autodiff(
        &self,
        reference: &BendTwistReference,
        q: &BendTwistDofs,
    ) -> (f64, SVector<f64, 11>, SMatrix<f64, 11, 11>) {
        num_dual::hessian(
            |v: SVector<Dual2SVec64<11>, 11>| self.energy_of(reference, &std::array::from_fn(|i| v[i])),
            q,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::{check_derivatives, random_vector};

    fn element() -> BendTwist {
        BendTwist {
            bend_stiffness_nm2: [2.0, 3.0],
            twist_stiffness_nm2: 1.5,
            rest_curvature: [0.2, -0.1],
            rest_twist_rad: 0.05,
            rest_length_sum_m: 2.0,
        }
    }

    /// A reference built at configuration `q`, with directors from a fixed hint.
    fn reference_at(q: &BendTwistDofs, twist: f64) -> BendTwistReference {
        let e =
            |i: usize| [q[3 * i + 3] - q[3 * i], q[3 * i + 4] - q[3 * i + 1], q[3 * i + 5] - q[3 * i + 2]];
        BendTwistReference {
            frames: [EdgeFrame::new(e(0), [0.3, 0.1, 1.0]), EdgeFrame::new(e(1), [0.3, 0.1, 1.0])],
            reference_twist_rad: twist,
        }
    }

    fn random_element_dofs(rng: &mut u64) -> BendTwistDofs {
        // A gently bent polyline plus noise: edges of length ~1, angle well below 180 degrees.
        let base = BendTwistDofs::from_column_slice(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.8, 0.6, 0.1, 0.0, 0.0]);
        base + random_vector::<11>(rng, 0.3)
    }

    #[test]
    fn derivatives_match_finite_differences_at_and_away_from_the_reference() {
        let mut rng = 11u64;
        let el = element();
        for _ in 0..40 {
            let q0 = random_element_dofs(&mut rng);
            let reference = reference_at(&q0, 0.0);
            let (_, twist) = curvature_and_twist(&reference, &std::array::from_fn(|i| q0[i]));
            let reference = BendTwistReference { reference_twist_rad: twist, ..reference };
            // At the reference configuration and at a nearby perturbed one.
            for q in [q0, q0 + random_vector::<11>(&mut rng, 0.05)] {
                check_derivatives(&|q: &BendTwistDofs| el.energy_gradient_hessian(&reference, q), &q);
            }
        }
    }

    /// DOFs with edge lengths near 1 meeting at turning angle `angle`, rigidly moved at random,
    /// with twists in `[-1.5, 1.5]`.
    fn bent_element_dofs(rng: &mut u64, angle: f64) -> BendTwistDofs {
        let r = random_vector::<8>(rng, 1.0);
        let rotation = nalgebra::Rotation3::new(nalgebra::Vector3::new(3.0 * r[0], 3.0 * r[1], 3.0 * r[2]));
        let shift = nalgebra::Vector3::new(r[3], r[4], r[5]);
        let (l0, l1) = (1.0 + 0.3 * r[6], 1.0 + 0.3 * r[7]);
        let points = [
            nalgebra::Vector3::new(-l0, 0.0, 0.0),
            nalgebra::Vector3::zeros(),
            nalgebra::Vector3::new(l1 * angle.cos(), l1 * angle.sin(), 0.0),
        ];
        let mut q = random_vector::<11>(rng, 1.5);
        for (i, p) in points.iter().enumerate() {
            q.fixed_rows_mut::<3>(3 * i).copy_from(&(rotation * p + shift));
        }
        q
    }

    /// Largest entry-wise difference of energy, gradient and Hessian, relative to the largest
    /// entry of each.
    fn relative_difference(
        a: &(f64, SVector<f64, 11>, SMatrix<f64, 11, 11>),
        b: &(f64, SVector<f64, 11>, SMatrix<f64, 11, 11>),
    ) -> f64 {
        let energy = (a.0 - b.0).abs() / a.0.abs().max(1e-300);
        let gradient = (a.1 - b.1).amax() / a.1.amax().max(1e-300);
        let hessian = (a.2 - b.2).amax() / a.2.amax().max(1e-300);
        energy.max(gradient).max(hessian)
    }

    #[test]
    fn closed_form_derivatives_equal_dual_numbers_at_and_away_from_the_reference() {
        let mut rng = 23u64;
        let mut worst: f64 = 0.0;
        let angles = [0.0, 1e-9, 1e-4, 0.3, 1.0, 2.0, 2.6, 150f64.to_radians()];
        for (n, &angle) in angles.iter().cycle().take(400).enumerate() {
            let q0 = bent_element_dofs(&mut rng, angle);
            let hint = random_vector::<3>(&mut rng, 1.0);
            let e = |i: usize| std::array::from_fn(|k| q0[3 * i + 3 + k] - q0[3 * i + k]);
            let frames = [EdgeFrame::new(e(0), hint.into()), EdgeFrame::new(e(1), hint.into())];
            let reference = BendTwistReference { frames, reference_twist_rad: 0.0 };
            let (_, twist) = curvature_and_twist(&reference, &std::array::from_fn(|i| q0[i]));
            let reference = BendTwistReference { reference_twist_rad: twist, ..reference };
            let r = random_vector::<4>(&mut rng, 0.5);
            let el = BendTwist {
                rest_curvature: [r[0], r[1]],
                rest_twist_rad: r[2],
                twist_stiffness_nm2: if n % 5 == 0 { 0.0 } else { 1.5 + r[3] },
                ..element()
            };
            // At the reference, and moved away from it by up to 0.3 per coordinate.
            for q in [q0, q0 + random_vector::<11>(&mut rng, 0.3)] {
                let fast = el.energy_gradient_hessian(&reference, &q);
                let autodiff = el.energy_gradient_hessian_autodiff(&reference, &q);
                let difference = relative_difference(&fast, &autodiff);
                assert!(difference < 1e-10, "angle {angle}: relative difference {difference}");
                worst = worst.max(difference);
            }
        }
        println!("largest relative difference, closed form vs dual numbers: {worst:e}");
    }

    #[test]
    fn energy_is_invariant_under_rigid_motions() {
        let mut rng = 5u64;
        let el = element();
        let q = random_element_dofs(&mut rng);
        let reference = reference_at(&q, 0.0);
        let e = el.energy(&reference, &q);
        // Rotate positions and reference frames together, then translate.
        let r = nalgebra::Rotation3::new(nalgebra::Vector3::new(0.3, -0.7, 1.1));
        let rot = |v: [f64; 3]| (r * nalgebra::Vector3::from(v)).into();
        let mut q2 = q;
        for i in 0..3 {
            let p = r * nalgebra::Vector3::new(q[3 * i], q[3 * i + 1], q[3 * i + 2])
                + nalgebra::Vector3::new(5.0, -2.0, 1.0);
            q2.fixed_rows_mut::<3>(3 * i).copy_from(&p);
        }
        let frames =
            reference.frames.map(|f| EdgeFrame { tangent: rot(f.tangent), director: rot(f.director) });
        let e2 = el.energy(&BendTwistReference { frames, ..reference }, &q2);
        assert!((e - e2).abs() < 1e-12 * e.abs().max(1.0), "{e} vs {e2}");
    }
}
