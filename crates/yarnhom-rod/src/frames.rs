//! Reference frames of discrete elastic rods (Bergou et al. 2010): parallel transport,
//! time-parallel reference directors and the reference twist.

use num_dual::DualNum;

use crate::vec3::V3;

/// Parallel transport of `v` from unit tangent `a` to unit tangent `b`: the rotation about
/// `a x b` that takes `a` to `b`, `v + w x v + w x (w x v) / (1 + a.b)` with `w = a x b`.
/// Smooth (and exact) for `a.b > -1`.
pub fn parallel_transport<T: DualNum<Primitive = f64> + Copy>(a: V3<T>, b: V3<T>, v: V3<T>) -> V3<T> {
    let w = a.cross(b);
    let c = a.dot(b);
    let wv = w.cross(v);
    v + wv + w.cross(wv).scale((c + 1.0).recip())
}

/// Signed angle from `u` to `v` about the unit `axis` (both orthogonal to it), in `(-pi, pi]`.
pub fn signed_angle<T: DualNum<Primitive = f64> + Copy>(u: V3<T>, v: V3<T>, axis: V3<T>) -> T {
    u.cross(v).dot(axis).atan2(u.dot(v))
}

/// The reference frame of one edge, as last updated: its unit tangent and first director.
/// Between updates the director follows the edge by parallel transport from that tangent
/// (time-parallel transport), which is how its derivatives enter the energy.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EdgeFrame {
    /// Unit tangent at the last update.
    pub tangent: [f64; 3],
    /// First reference director at the last update (unit, orthogonal to `tangent`).
    pub director: [f64; 3],
}

impl EdgeFrame {
    /// A frame for an edge with vector `edge` whose first director is as close as possible to
    /// `hint` (projected onto the normal plane; any normal if `hint` is parallel to the edge).
    pub fn new(edge: [f64; 3], hint: [f64; 3]) -> Self {
        let t = V3::<f64>(edge).normalized();
        let project = |h: V3<f64>| h - t.scale(t.dot(h));
        let mut d = project(V3(hint));
        if d.norm() < 1e-8 {
            let axis = if t.0[0].abs() < 0.9 { [1.0, 0.0, 0.0] } else { [0.0, 1.0, 0.0] };
            d = project(V3(axis));
        }
        EdgeFrame { tangent: t.re(), director: d.normalized().re() }
    }

    /// The reference director for the edge's current tangent `t` (unit), by parallel transport.
    pub fn director_at<T: DualNum<Primitive = f64> + Copy>(&self, t: V3<T>) -> V3<T> {
        parallel_transport(V3::constant(self.tangent), t, V3::constant(self.director))
    }

    /// The frame moved to the edge's new vector (time-parallel update).
    pub fn updated(&self, edge: [f64; 3]) -> Self {
        let t = V3::<f64>(edge).normalized();
        let d = self.director_at(t);
        // Re-orthonormalize against round-off drift.
        let d = (d - t.scale(t.dot(d))).normalized();
        EdgeFrame { tangent: t.re(), director: d.re() }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn transport_takes_a_to_b_and_preserves_angles() {
        let a = V3::<f64>([1.0, 0.0, 0.0]);
        let b = V3::<f64>([0.6, 0.8, 0.0]);
        let moved = parallel_transport(a, b, a);
        assert!((moved - b).norm() < 1e-15);
        let v = V3([0.0, 0.0, 1.0]);
        assert!((parallel_transport(a, b, v) - v).norm() < 1e-15, "the rotation axis is fixed");
        let u = V3([0.0, 1.0, 0.0]);
        let pu = parallel_transport(a, b, u);
        assert!((pu.dot(b)).abs() < 1e-15 && (pu.norm() - 1.0).abs() < 1e-15);
    }

    #[test]
    fn signed_angle_has_the_right_sign() {
        let z = V3::<f64>([0.0, 0.0, 1.0]);
        let angle = signed_angle(V3([1.0, 0.0, 0.0]), V3([0.0, 1.0, 0.0]), z);
        assert!((angle - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
    }

    #[test]
    fn frames_are_orthonormal_and_follow_the_edge() {
        let f = EdgeFrame::new([1.0, 1.0, 0.0], [0.0, 0.0, 1.0]);
        assert!((V3(f.director).dot(V3(f.tangent))).abs() < 1e-15);
        let g = f.updated([1.0, 1.0, 0.5]);
        let (t, d) = (V3(g.tangent), V3(g.director));
        assert!(t.dot(d).abs() < 1e-15 && (d.norm() - 1.0).abs() < 1e-15);
    }
}
