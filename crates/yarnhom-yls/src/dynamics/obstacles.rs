//! Rigid obstacles (planes, spheres and axis-aligned boxes) and the vertex-obstacle barrier of IPC (Li et al. 2020,
//! eq. 6): `κ b(d)` with `b(d) = -(d - d̂)² ln(d / d̂)` for `0 < d < d̂`, zero beyond, and `+∞`
//! at `d ≤ 0`, where `d` is the gap between the yarn's surface and the obstacle (the vertex's
//! distance to the obstacle minus the yarn radius) and `d̂` the activation distance. The barrier
//! acts on vertices only (an edge may graze an obstacle between its vertices). Friction is
//! Coulomb's, applied to the velocities after each step ([`Obstacle::apply_friction`]).

use nalgebra::{Matrix3, Vector3};

/// A rigid, fixed obstacle with its barrier.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Obstacle {
    /// Its shape.
    pub shape: ObstacleShape,
    /// The activation distance `d̂` (m): the barrier acts on vertices whose surface is nearer.
    pub activation_distance_m: f64,
    /// The barrier's stiffness `κ` (N/m: the barrier `b` is a length squared).
    pub stiffness_n_m: f64,
    /// Coulomb friction coefficient `μ` of yarn on the obstacle (applied as the shell
    /// simulator and ARCSim do: [`Obstacle::apply_friction`]).
    pub friction: f64,
}

/// The shape of an obstacle; its inside is solid.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ObstacleShape {
    /// The half-space below a plane: points `x` with `n · (x - p) < 0` are inside.
    Plane {
        /// A point of the plane (m).
        point_m: [f64; 3],
        /// Its normal, pointing out of the obstacle (any length but zero).
        normal: [f64; 3],
    },
    /// A solid ball.
    Sphere {
        /// Centre (m).
        centre_m: [f64; 3],
        /// Radius (m).
        radius_m: f64,
    },
    /// A solid axis-aligned box.
    Box {
        /// Lowest corner (m).
        min_m: [f64; 3],
        /// Highest corner (m), above the lowest along every axis.
        max_m: [f64; 3],
    },
}

/// The signed distance of a point to the obstacle's surface (m, positive outside), its
/// gradient and Hessian.
fn signed_distance(shape: &ObstacleShape, x: &Vector3<f64>) -> (f64, Vector3<f64>, Matrix3<f64>) {
    match *shape {
        ObstacleShape::Plane { point_m, normal } => {
            let n = Vector3::from(normal).normalize();
            (n.dot(&(x - Vector3::from(point_m))), n, Matrix3::zeros())
        }
        ObstacleShape::Sphere { centre_m, radius_m } => {
            let r = x - Vector3::from(centre_m);
            let length = r.norm();
            let u = r / length;
            (length - radius_m, u, (Matrix3::identity() - u * u.transpose()) / length)
        }
        ObstacleShape::Box { min_m, max_m } => box_distance(x, &Vector3::from(min_m), &Vector3::from(max_m)),
    }
}

/// The signed distance to an axis-aligned box, its gradient and Hessian. Outside, the distance
/// to the nearest point `y` of the box, `|x - y|`: flat over a face, that of a line over an edge
/// (`(P - u uᵀ) / |x - y|`, `P` the projection on the axes along which `x` is outside the box,
/// `u` the unit direction), of a point over a corner. Inside (never reached by a vertex with a
/// finite barrier), minus the distance to the nearest face.
fn box_distance(
    x: &Vector3<f64>,
    min: &Vector3<f64>,
    max: &Vector3<f64>,
) -> (f64, Vector3<f64>, Matrix3<f64>) {
    let nearest = x.sup(min).inf(max);
    let r = x - nearest;
    let length = r.norm();
    if length > 0.0 {
        let u = r / length;
        let outside = Matrix3::from_diagonal(&r.map(|c| if c != 0.0 { 1.0 } else { 0.0 }));
        return (length, u, (outside - u * u.transpose()) / length);
    }
    let centre = 0.5 * (min + max);
    let depth = (0.5 * (max - min)) - (x - centre).abs();
    let axis = depth.imin();
    let mut n = Vector3::zeros();
    n[axis] = (x[axis] - centre[axis]).signum();
    (-depth[axis], n, Matrix3::zeros())
}

/// `(b, b', b'')` of the IPC barrier `b(d) = -(d - d̂)² ln(d / d̂)` for `0 < d < d̂`.
fn ipc_barrier(d: f64, d_hat: f64) -> (f64, f64, f64) {
    if d >= d_hat {
        return (0.0, 0.0, 0.0);
    }
    let (s, ln) = (d - d_hat, (d / d_hat).ln());
    (-s * s * ln, -2.0 * s * ln - s * s / d, -2.0 * ln - 4.0 * s / d + s * s / (d * d))
}

impl Obstacle {
    /// Gap between the surface of a yarn of radius `yarn_radius_m` centred at `x` and the
    /// obstacle (m).
    pub fn gap_m(&self, x: &Vector3<f64>, yarn_radius_m: f64) -> f64 {
        signed_distance(&self.shape, x).0 - yarn_radius_m
    }

    /// The barrier energy of a vertex at `x` (`+∞` at or inside the surface).
    pub(crate) fn energy(&self, x: &Vector3<f64>, yarn_radius_m: f64) -> f64 {
        let d = self.gap_m(x, yarn_radius_m);
        if d <= 0.0 {
            f64::INFINITY
        } else {
            self.stiffness_n_m * ipc_barrier(d, self.activation_distance_m).0
        }
    }

    /// The barrier's energy, gradient and Hessian at vertex `x`, or `None` where it is inactive
    /// (an energy of `+∞` with zero derivatives where the gap is not positive).
    pub(crate) fn energy_gradient_hessian(
        &self,
        x: &Vector3<f64>,
        yarn_radius_m: f64,
    ) -> Option<(f64, Vector3<f64>, Matrix3<f64>)> {
        let (distance, n, dn) = signed_distance(&self.shape, x);
        let d = distance - yarn_radius_m;
        if d >= self.activation_distance_m {
            return None;
        }
        if d <= 0.0 {
            return Some((f64::INFINITY, Vector3::zeros(), Matrix3::zeros()));
        }
        let (b, db, ddb) = ipc_barrier(d, self.activation_distance_m);
        let k = self.stiffness_n_m;
        Some((k * b, n * (k * db), (n * n.transpose()) * (k * ddb) + dn * (k * db)))
    }

    /// Coulomb friction over a step of `h` on a vertex of mass `m` at `x` moving at `v` (the
    /// step's end velocity), as the shell simulator and ARCSim apply it: the tangential part of
    /// `v` (to the obstacle's surface) is slowed by `μ f_n h / m`, `f_n` the barrier's normal
    /// force at `x`, and at most brought to rest (sticking); the normal part is left alone.
    pub(crate) fn apply_friction(
        &self,
        x: &Vector3<f64>,
        yarn_radius_m: f64,
        v: &mut Vector3<f64>,
        m: f64,
        h: f64,
    ) {
        if self.friction <= 0.0 {
            return;
        }
        let Some((_, gradient, _)) = self.energy_gradient_hessian(x, yarn_radius_m) else { return };
        let force = gradient.norm();
        if !(force > 0.0 && force.is_finite()) {
            return;
        }
        let n = gradient / force;
        let tangential = *v - n * n.dot(v);
        let speed = tangential.norm();
        if speed > 0.0 {
            *v -= tangential * (self.friction * force * h / (m * speed)).min(1.0);
        }
    }

    /// The largest fraction of a vertex move `delta` from `x` that keeps 10% of the gap: the
    /// gap shrinks at most by `n · δ` (plane) or `|δ|` (sphere, box: their distances change no
    /// faster than the point moves) per unit of fraction.
    pub(crate) fn step_cap(&self, x: &Vector3<f64>, delta: &Vector3<f64>, yarn_radius_m: f64) -> f64 {
        let approach = match self.shape {
            ObstacleShape::Plane { normal, .. } => -Vector3::from(normal).normalize().dot(delta),
            ObstacleShape::Sphere { .. } | ObstacleShape::Box { .. } => delta.norm(),
        };
        let gap = self.gap_m(x, yarn_radius_m);
        if approach > 0.0 { 0.9 * gap / approach } else { f64::INFINITY }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check(obstacle: &Obstacle, x: Vector3<f64>, radius: f64) {
        let (_, g, h) = obstacle.energy_gradient_hessian(&x, radius).expect("active");
        let step = 1e-7;
        for i in 0..3 {
            let (mut up, mut down) = (x, x);
            up[i] += step;
            down[i] -= step;
            let fd = (obstacle.energy(&up, radius) - obstacle.energy(&down, radius)) / (2.0 * step);
            assert!((fd - g[i]).abs() < 1e-6 * g.amax(), "gradient {i}: {fd} vs {}", g[i]);
            let (_, gu, _) = obstacle.energy_gradient_hessian(&up, radius).expect("active");
            let (_, gd, _) = obstacle.energy_gradient_hessian(&down, radius).expect("active");
            let column = (gu - gd) / (2.0 * step);
            assert!((column - h.column(i)).amax() < 1e-5 * h.amax(), "hessian column {i}");
        }
    }

    #[test]
    fn barrier_derivatives_match_finite_differences() {
        let plane = Obstacle {
            shape: ObstacleShape::Plane { point_m: [0.0, 0.0, 0.1], normal: [0.2, 0.1, 1.0] },
            activation_distance_m: 0.5,
            stiffness_n_m: 3.0,
            friction: 0.0,
        };
        let sphere =
            Obstacle { shape: ObstacleShape::Sphere { centre_m: [0.3, -0.2, 0.0], radius_m: 1.0 }, ..plane };
        check(&plane, Vector3::new(0.3, 0.2, 0.45), 0.2);
        check(&sphere, Vector3::new(0.9, 0.4, 1.0), 0.2);
        let cube = Obstacle {
            shape: ObstacleShape::Box { min_m: [-1.0, -1.0, -1.0], max_m: [1.0, 1.0, 0.0] },
            ..plane
        };
        // Over a face, an edge and a corner.
        check(&cube, Vector3::new(0.3, 0.2, 0.45), 0.2);
        check(&cube, Vector3::new(1.25, 0.2, 0.3), 0.2);
        check(&cube, Vector3::new(1.2, -1.25, 0.3), 0.2);
    }

    #[test]
    fn box_distances_over_faces_edges_corners_and_inside() {
        let (min, max) = (Vector3::new(-1.0, -1.0, -1.0), Vector3::new(1.0, 1.0, 0.0));
        let (d, n, h) = box_distance(&Vector3::new(0.2, 0.1, 0.5), &min, &max);
        assert!((d - 0.5).abs() < 1e-15 && n == Vector3::z() && h == Matrix3::zeros());
        let (d, n, _) = box_distance(&Vector3::new(2.0, 0.0, 1.0), &min, &max);
        assert!(
            (d - 2f64.sqrt()).abs() < 1e-15 && (n - Vector3::new(1.0, 0.0, 1.0) / 2f64.sqrt()).norm() < 1e-15
        );
        let (d, _, _) = box_distance(&Vector3::new(2.0, 3.0, 2.0), &min, &max);
        assert!((d - 3.0).abs() < 1e-15);
        let (d, n, _) = box_distance(&Vector3::new(0.2, 0.1, -0.1), &min, &max);
        assert!((d + 0.1).abs() < 1e-15 && n == Vector3::z());
    }

    #[test]
    fn the_barrier_is_zero_beyond_activation_and_infinite_at_contact() {
        let plane = Obstacle {
            shape: ObstacleShape::Plane { point_m: [0.0; 3], normal: [0.0, 0.0, 2.0] },
            activation_distance_m: 0.1,
            stiffness_n_m: 1.0,
            friction: 0.0,
        };
        assert!(plane.energy_gradient_hessian(&Vector3::new(0.0, 0.0, 0.31), 0.2).is_none());
        assert_eq!(plane.energy(&Vector3::new(0.0, 0.0, 0.2), 0.2), f64::INFINITY);
        let near = plane.energy(&Vector3::new(0.0, 0.0, 0.201), 0.2);
        let far = plane.energy(&Vector3::new(0.0, 0.0, 0.25), 0.2);
        assert!(near > far && far > 0.0);
        // A move of 1 toward the plane from a gap of 0.05 is cut to 90% of the gap.
        let cap = plane.step_cap(&Vector3::new(0.0, 0.0, 0.25), &Vector3::new(0.0, 0.0, -1.0), 0.2);
        assert!((cap - 0.045).abs() < 1e-15);
    }
}
