//! Segments: closest points in 3D and crossings in the plane.

use nalgebra::{Vector2, Vector3};

/// The closest points of two segments `p0 + s (p1 - p0)` and `q0 + t (q1 - q0)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SegmentDistance {
    /// Distance between the closest points.
    pub distance: f64,
    /// Parameter of the closest point on the first segment, in `[0, 1]`.
    pub s: f64,
    /// Parameter of the closest point on the second segment, in `[0, 1]`.
    pub t: f64,
}

/// Closest points of two 3D segments (Ericson, *Real-Time Collision Detection*, 5.1.9), robust
/// for parallel and zero-length segments.
pub fn segment_distance(
    p0: &Vector3<f64>,
    p1: &Vector3<f64>,
    q0: &Vector3<f64>,
    q1: &Vector3<f64>,
) -> SegmentDistance {
    let d1 = p1 - p0;
    let d2 = q1 - q0;
    let r = p0 - q0;
    let a = d1.norm_squared();
    let e = d2.norm_squared();
    let f = d2.dot(&r);
    let tiny = f64::EPSILON * f64::EPSILON;
    let (s, t) = if a <= tiny && e <= tiny {
        (0.0, 0.0)
    } else if a <= tiny {
        (0.0, (f / e).clamp(0.0, 1.0))
    } else {
        let c = d1.dot(&r);
        if e <= tiny {
            ((-c / a).clamp(0.0, 1.0), 0.0)
        } else {
            let b = d1.dot(&d2);
            let denom = a * e - b * b;
            // Parallel segments (denom ~ 0): any s works; take s = 0 and let t follow.
            let mut s =
                if denom > f64::EPSILON * a * e { ((b * f - c * e) / denom).clamp(0.0, 1.0) } else { 0.0 };
            let mut t = (b * s + f) / e;
            if t < 0.0 {
                t = 0.0;
                s = (-c / a).clamp(0.0, 1.0);
            } else if t > 1.0 {
                t = 1.0;
                s = ((b - c) / a).clamp(0.0, 1.0);
            }
            (s, t)
        }
    };
    let distance = ((p0 + d1 * s) - (q0 + d2 * t)).norm();
    SegmentDistance { distance, s, t }
}

/// Where two 2D segments properly cross: the parameters `(s, t)` in `[0, 1)` of the crossing
/// point on each, or `None` if they do not cross (parallel segments never count as crossing).
pub fn segment_crossing_2d(
    p0: &Vector2<f64>,
    p1: &Vector2<f64>,
    q0: &Vector2<f64>,
    q1: &Vector2<f64>,
) -> Option<(f64, f64)> {
    let d1 = p1 - p0;
    let d2 = q1 - q0;
    let denom = d1.perp(&d2);
    if denom.abs() <= f64::EPSILON * d1.norm() * d2.norm() {
        return None;
    }
    let r = q0 - p0;
    let s = r.perp(&d2) / denom;
    let t = r.perp(&d1) / denom;
    ((0.0..1.0).contains(&s) && (0.0..1.0).contains(&t)).then_some((s, t))
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn v(x: f64, y: f64, z: f64) -> Vector3<f64> {
        Vector3::new(x, y, z)
    }

    fn sampled_minimum(p0: &Vector3<f64>, p1: &Vector3<f64>, q0: &Vector3<f64>, q1: &Vector3<f64>) -> f64 {
        let n = 200;
        let mut best = f64::INFINITY;
        for i in 0..=n {
            let a = p0 + (p1 - p0) * (i as f64 / n as f64);
            for j in 0..=n {
                let b = q0 + (q1 - q0) * (j as f64 / n as f64);
                best = best.min((a - b).norm());
            }
        }
        best
    }

    #[test]
    fn crossing_perpendicular_segments_are_their_offset_apart() {
        let d =
            segment_distance(&v(-1.0, 0.0, 0.0), &v(1.0, 0.0, 0.0), &v(0.0, -1.0, 2.0), &v(0.0, 1.0, 2.0));
        assert!((d.distance - 2.0).abs() < 1e-15);
        assert!((d.s - 0.5).abs() < 1e-15 && (d.t - 0.5).abs() < 1e-15);
    }

    #[test]
    fn parallel_and_collinear_segments() {
        let d = segment_distance(&v(0.0, 0.0, 0.0), &v(1.0, 0.0, 0.0), &v(0.5, 1.0, 0.0), &v(2.0, 1.0, 0.0));
        assert!((d.distance - 1.0).abs() < 1e-15);
        let d = segment_distance(&v(0.0, 0.0, 0.0), &v(1.0, 0.0, 0.0), &v(3.0, 0.0, 0.0), &v(2.0, 0.0, 0.0));
        assert!((d.distance - 1.0).abs() < 1e-15);
    }

    #[test]
    fn degenerate_segments_are_points() {
        let p = v(1.0, 2.0, 3.0);
        let d = segment_distance(&p, &p, &v(0.0, 0.0, 0.0), &v(2.0, 0.0, 0.0));
        assert!((d.distance - 13f64.sqrt()).abs() < 1e-14);
        let d = segment_distance(&p, &p, &v(1.0, 2.0, 4.0), &v(1.0, 2.0, 4.0));
        assert!((d.distance - 1.0).abs() < 1e-15);
    }

    #[test]
    fn planar_crossings() {
        let c = segment_crossing_2d(
            &Vector2::new(0.0, 0.0),
            &Vector2::new(2.0, 0.0),
            &Vector2::new(0.5, -1.0),
            &Vector2::new(0.5, 3.0),
        );
        let (s, t) = c.expect("they cross");
        assert!((s - 0.25).abs() < 1e-15 && (t - 0.25).abs() < 1e-15);
        assert!(
            segment_crossing_2d(
                &Vector2::new(0.0, 0.0),
                &Vector2::new(1.0, 0.0),
                &Vector2::new(0.0, 1.0),
                &Vector2::new(1.0, 1.0)
            )
            .is_none()
        );
        assert!(
            segment_crossing_2d(
                &Vector2::new(0.0, 0.0),
                &Vector2::new(1.0, 0.0),
                &Vector2::new(2.0, -1.0),
                &Vector2::new(2.0, 1.0)
            )
            .is_none()
        );
    }

    proptest! {
        #[test]
        fn distance_is_the_true_minimum(c in prop::collection::vec(-2.0f64..2.0, 12)) {
            let (p0, p1, q0, q1) = (v(c[0], c[1], c[2]), v(c[3], c[4], c[5]), v(c[6], c[7], c[8]), v(c[9], c[10], c[11]));
            let d = segment_distance(&p0, &p1, &q0, &q1);
            let sampled = sampled_minimum(&p0, &p1, &q0, &q1);
            // Never below the true minimum (the sampled one is an upper bound of it) by more than
            // round-off, and within the sampling resolution of it.
            prop_assert!(d.distance <= sampled + 1e-12);
            let step = ((p1 - p0).norm() + (q1 - q0).norm()) / 200.0;
            prop_assert!(d.distance >= sampled - step - 1e-12);
            let a = p0 + (p1 - p0) * d.s;
            let b = q0 + (q1 - q0) * d.t;
            prop_assert!(((a - b).norm() - d.distance).abs() < 1e-12);
        }
    }
}
