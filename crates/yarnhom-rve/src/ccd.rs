//! Additive continuous collision detection (ACCD; Li et al. 2021, "Codimensional Incremental
//! Potential Contact", Algorithm 1), which App. A.2.3 names as the better replacement of the step
//! limit: the largest fraction of a Newton step along which no two yarn centreline edges come
//! closer than a minimum separation.
//!
//! Conservative advancement: once the displacement common to both edges (the mean over their
//! four endpoints) is removed, any point of one edge moves relative to any point of the other by
//! at most `l_p = max_i |Δa_i| + max_j |Δb_j|` over the step, so their distance `d` changes at
//! most at rate `l_p`. From a distance `d` above the thickness `ξ`, the step can therefore
//! advance by `(d - ξ) / l_p` before the distance could reach `ξ`; ACCD advances by a fraction of
//! that, measures the distance again, and repeats until the remaining gap `d - ξ` falls below the
//! slack `s` times its start value or the step is done.

use nalgebra::{DVector, Vector3};
use yarnhom_geom::segment_distance;

use crate::assembly::{RveState, image_segments};
use crate::broadphase::{Aabb, EdgePair, edge_pairs, tile_image};
use crate::model::RveModel;
use crate::placement::Placement;

/// The slack `s` of [`max_collision_free_step`]: a step stops while at least this fraction of a
/// pair's initial gap `d - ξ` is left (and a pair starting within the minimum separation may
/// approach by this fraction of its distance). 0.1 as in the IPC Toolkit's additive CCD
/// (conservative rescaling 0.9).
pub const SLACK: f64 = 0.1;

/// Advances after the first are this fraction of the safe advance `(d - ξ) / l_p`
/// (Algorithm 1, line 15).
const RESCALING: f64 = 0.9;

/// At most this many advances per pair: the time reached is returned (it keeps the guarantees),
/// which bounds the work for a pair whose gap is tiny against its relative motion.
const MAX_ADVANCES: usize = 10_000;

/// The fraction `t ∈ [0, 1]` of the linear motion `x + τ Δx` of two edges `a = (x_0, x_1)` and
/// `b = (x_2, x_3)` (`start = [a0, a1, b0, b1]`, `displacement = [Δa0, Δa1, Δb0, Δb1]` over the
/// full step) up to which they stay apart, by ACCD with thickness `ξ` and slack `s = slack ∈ (0, 1)`.
///
/// With `d(τ)` the distance between the segments, `ξ = min_separation` if
/// `d(0) > min_separation` and `ξ = (1 - s) d(0)` otherwise (a pair that starts too close, as the
/// affine start's can (A.2.3), may still move, but not approach by more than `s d(0)`):
/// - `d(τ) > ξ` for every `τ ∈ [0, t]`;
/// - `t < 1` only where the gap shrinks: then `d(t) ≥ ξ + s (d(0) - ξ)`, so that the next step can
///   move again; `t ≥ min(1, (1 - s)(d(0) - ξ) / l_p)`;
/// - `t = 0` only if the centrelines touch at the start (`d(0) = 0`) or the input is not finite.
///
/// For two edges approaching head-on at constant speed, `t = (1 - s) t*` with `t*` the exact time
/// at which `d = ξ`.
pub fn edge_edge_toi(
    start: [Vector3<f64>; 4],
    displacement: [Vector3<f64>; 4],
    min_separation: f64,
    slack: f64,
) -> f64 {
    additive_toi(&start, &displacement, min_separation, slack, 1.0)
}

/// [`edge_edge_toi`] up to `t_max` instead of 1 (`t_c` of Algorithm 1): `t_max` if the edges stay
/// apart that long.
fn additive_toi(
    start: &[Vector3<f64>; 4],
    displacement: &[Vector3<f64>; 4],
    min_separation: f64,
    slack: f64,
    t_max: f64,
) -> f64 {
    let at = |t: f64, k: usize| start[k] + displacement[k] * t;
    let distance = |t: f64| segment_distance(&at(t, 0), &at(t, 1), &at(t, 2), &at(t, 3)).distance;
    let mean = displacement.iter().sum::<Vector3<f64>>() / 4.0;
    let relative = |k: usize| (displacement[k] - mean).norm();
    let l_p = relative(0).max(relative(1)) + relative(2).max(relative(3));
    if l_p == 0.0 {
        return t_max; // A common translation keeps the distance.
    }
    let d0 = distance(0.0);
    let thickness = if d0 > min_separation { min_separation } else { (1.0 - slack) * d0 };
    let gap0 = d0 - thickness;
    if !(gap0 > 0.0 && l_p.is_finite()) {
        return 0.0;
    }
    let stop = slack * gap0;
    let mut t = 0.0;
    let mut advance = (1.0 - slack) * gap0 / l_p;
    for _ in 0..MAX_ADVANCES {
        let gap = distance(t + advance) - thickness;
        if t > 0.0 && gap < stop {
            return t;
        }
        t += advance;
        if t > t_max {
            return t_max;
        }
        advance = RESCALING * gap / l_p;
    }
    t
}

/// The largest fraction `t ∈ [0, 1]` of the step `g → g + step` (`g = state.g`) that
/// [`edge_edge_toi`] allows with slack [`SLACK`] for every pair of edges of the tile and its
/// contact images ([`RveModel::images`]; each physical pair once, yarn neighbours excluded): no
/// two centrelines come closer than `min_separation` along `g + τ step`, `τ ∈ [0, t]` (pairs that
/// start closer are held to `(1 - SLACK)` times their distance). World positions are linear in
/// `g` (3.13), so the edges' straight paths are exact. Candidates come from the broad phase on the
/// union of each edge's boxes at both ends of the step, grown by half the separation.
pub fn max_collision_free_step(
    model: &RveModel,
    placement: &Placement,
    state: &RveState,
    step: &DVector<f64>,
    min_separation: f64,
) -> f64 {
    let start = image_segments(model, placement, &state.g);
    let end = image_segments(model, placement, &(&state.g + step));
    let margin = 0.5 * min_separation;
    let boxes: Vec<Vec<Aabb>> = start
        .iter()
        .zip(&end)
        .map(|(s, e)| {
            s.iter()
                .zip(e)
                .map(|((p0, q0), (p1, q1))| {
                    Aabb::around_segment(p0, q0, margin).union(&Aabb::around_segment(p1, q1, margin))
                })
                .collect()
        })
        .collect();
    let tile = tile_image(model);
    edge_pairs(model, &boxes).iter().fold(1.0, |t, &EdgePair { a, image, b }| {
        let x = |ends: &[Vec<(Vector3<f64>, Vector3<f64>)>]| {
            let ((a0, a1), (b0, b1)) = (ends[tile][a], ends[image][b]);
            [a0, a1, b0, b1]
        };
        let (x0, x1) = (x(&start), x(&end));
        additive_toi(&x0, &std::array::from_fn(|k| x1[k] - x0[k]), min_separation, SLACK, t)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use yarnhom_artifacts::{YarnModel, pyp::parse_pyp};
    use yarnhom_geom::MacroStrain;

    fn distance_at(start: &[Vector3<f64>; 4], displacement: &[Vector3<f64>; 4], t: f64) -> f64 {
        let x = |k: usize| start[k] + displacement[k] * t;
        segment_distance(&x(0), &x(1), &x(2), &x(3)).distance
    }

    /// Edge `a` along X1 at height 0, edge `b` along X2 at height `h`.
    fn crossing(h: f64) -> [Vector3<f64>; 4] {
        [
            Vector3::new(-1.0, 0.0, 0.0),
            Vector3::new(1.0, 0.0, 0.0),
            Vector3::new(0.0, -1.0, h),
            Vector3::new(0.0, 1.0, h),
        ]
    }

    #[test]
    fn crossing_edges_approaching_head_on_stop_short_of_the_separation() {
        let (h, separation, slack) = (1.0, 0.2, 0.02);
        let down = Vector3::new(0.0, 0.0, -1.0);
        // b falls by 2 over the step while a rises by 0.5: the gap closes at 2.5 per unit step.
        let up = -down * 0.5;
        let motion = [up, up, down * 2.0, down * 2.0];
        let t = edge_edge_toi(crossing(h), motion, separation, slack);
        let exact = (h - separation) / 2.5;
        assert!(t <= exact && t >= (1.0 - slack) * exact * (1.0 - 1e-12), "t = {t}, exact {exact}");
        assert!((t / exact - 1.0).abs() < 0.03);
        assert!(distance_at(&crossing(h), &motion, t) >= separation);
    }

    #[test]
    fn edges_moving_apart_or_together_take_the_whole_step() {
        let up = Vector3::new(0.0, 0.0, 1.0);
        let zero = Vector3::zeros();
        assert_eq!(edge_edge_toi(crossing(1.0), [zero, zero, up, up], 0.2, SLACK), 1.0);
        let sideways = Vector3::new(3.0, -2.0, 5.0);
        assert_eq!(edge_edge_toi(crossing(1.0), [sideways; 4], 0.2, SLACK), 1.0);
    }

    #[test]
    fn a_pair_starting_within_the_separation_may_move_but_not_approach_by_more_than_the_slack() {
        let down = Vector3::new(0.0, 0.0, -1.0);
        let motion = [Vector3::zeros(), Vector3::zeros(), down, down];
        let t = edge_edge_toi(crossing(0.1), motion, 0.2, 0.1);
        assert!(t > 0.0 && distance_at(&crossing(0.1), &motion, t) >= 0.9 * 0.1);
        assert_eq!(edge_edge_toi(crossing(0.0), motion, 0.2, 0.1), 0.0);
    }

    fn vector(range: f64) -> impl Strategy<Value = Vector3<f64>> {
        prop::array::uniform3(-range..range).prop_map(Vector3::from)
    }

    proptest! {
        #[test]
        fn the_distance_never_drops_below_the_thickness_before_the_returned_time(
            start in prop::array::uniform4(vector(1.0)),
            displacement in prop::array::uniform4(vector(3.0)),
            separation in 0.01..0.5f64,
            slack in 0.05..0.5f64,
        ) {
            let d0 = distance_at(&start, &displacement, 0.0);
            let thickness = if d0 > separation { separation } else { (1.0 - slack) * d0 };
            let t = edge_edge_toi(start, displacement, separation, slack);
            prop_assert!((0.0..=1.0).contains(&t));
            prop_assert!(t > 0.0 || d0 == 0.0);
            for k in 0..=2000 {
                let tau = t * f64::from(k) / 2000.0;
                prop_assert!(distance_at(&start, &displacement, tau) > thickness, "at {tau} of {t}");
            }
            if t < 1.0 {
                let left = distance_at(&start, &displacement, t) - thickness;
                prop_assert!(left >= slack * (d0 - thickness) * (1.0 - 1e-9));
            }
        }
    }

    #[test]
    fn a_large_step_of_a_published_tile_is_cut_before_any_pair_comes_too_close() {
        let path = format!("{}/../../../shared/data/hylc-patterns/stock.pyp", env!("CARGO_MANIFEST_DIR"));
        let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
        let pattern = parse_pyp(&text, "stock", None).expect("published pattern imports");
        let model = RveModel::new(&pattern, &YarnModel::table_4_1("stock").expect("row")).expect("tile");
        let strain: MacroStrain = "sx=0.3".parse().expect("strain");
        let placement = Placement::new(model.material.clone(), model.period_m, &strain);
        let state = RveState::affine(&model, &placement);
        let r = model.radius_m;
        let step = DVector::from_fn(model.dof_count(), |i, _| {
            if i < 3 * model.vertices { 4.0 * r * ((i * 7919 % 1000) as f64 / 500.0 - 1.0) } else { 0.0 }
        });
        let separation = r;
        let t = max_collision_free_step(&model, &placement, &state, &step, separation);
        assert!(t > 0.0 && t < 1.0, "t = {t}");
        // Every pair, by brute force, at a few times up to t.
        let at = |tau: f64| image_segments(&model, &placement, &(&state.g + &step * tau));
        let start = at(0.0);
        let tile = tile_image(&model);
        for tau in (1..=8).map(|k| t * f64::from(k) / 8.0) {
            let ends = at(tau);
            for a in 0..model.vertices {
                for (image, &o) in model.images.iter().enumerate() {
                    for b in 0..model.vertices {
                        if !(a < b || (a == b && o > [0, 0])) || !model.contact_pair(a, b, o) {
                            continue;
                        }
                        let distance = |e: &[Vec<(Vector3<f64>, Vector3<f64>)>]| {
                            let ((a0, a1), (b0, b1)) = (e[tile][a], e[image][b]);
                            segment_distance(&a0, &a1, &b0, &b1).distance
                        };
                        let d0 = distance(&start);
                        let floor = if d0 > separation { separation } else { (1.0 - SLACK) * d0 };
                        assert!(distance(&ends) > floor, "pair ({a}, {o:?}, {b}) at {tau}");
                    }
                }
            }
        }
    }
}
