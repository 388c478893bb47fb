//! Yarn-yarn contact candidates: which pairs of edges may interact, found by a uniform spatial
//! hash, with their centreline (segment-segment) distances.
//!
//! - Exclusion: two edges of one yarn never interact if they share a vertex or are one edge
//!   apart (index difference 1 or 2, around a closed yarn cyclically); nor do two edges one of
//!   whose ends is glued to one of the other's ([`yarnhom_artifacts::GlueSpring`]): across a glue spring the
//!   spring plays the middle edge. Every other pair within the law's reach interacts, edges of
//!   one yarn included.
//! - Broad phase: each edge's box, grown by half the broad-phase radius, goes into the cells of
//!   a uniform grid hashed by cell coordinates (cell side the largest grown box); pairs sharing
//!   a cell whose exact centreline distance is below the broad-phase radius are the candidates.
//! - The list of a step ([`CandidateList`], a Verlet list): found with the radius
//!   `reach + margin`, so that while no vertex has moved further than `margin / 2` from where
//!   it was found, every pair outside the list stays out of reach ([`super::caps`] keeps each
//!   Newton step within that slack). At every Newton iterate the listed pairs' distances are
//!   recomputed; the list is found anew once a vertex has used half the slack (`margin / 4`).

use std::collections::HashMap;

use nalgebra::Vector3;
use rayon::prelude::*;

/// An edge of the scene.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Edge {
    /// First and second vertex (global indices).
    pub ends: [usize; 2],
    /// Rest length (m).
    pub rest_length_m: f64,
    /// The yarn it belongs to.
    pub yarn: usize,
    /// Its index along the yarn.
    pub index: usize,
}

/// A pair of edges (`a < b`, global edge indices) within the broad-phase radius, with the
/// distance of their centrelines when it was found.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Candidate {
    /// First edge.
    pub a: usize,
    /// Second edge.
    pub b: usize,
    /// Centreline distance (m).
    pub distance_m: f64,
}

/// The candidate pairs of a step, kept across its Newton iterates (the module's rule).
#[derive(Debug, Clone, Default)]
pub(crate) struct CandidateList {
    /// Vertex positions where the broad phase last ran.
    found_at: Vec<f64>,
    /// The pairs, with their distances at the latest positions.
    pub pairs: Vec<Candidate>,
    /// How much further any vertex may move before a pair outside the list could come within
    /// reach: `margin / 2` less the largest move since the list was found (m; ∞ without contact).
    pub slack_m: f64,
}

impl CandidateList {
    /// The list at positions `x` (vertex `v` at `x[3v..3v+3]`), or an empty one without
    /// contact (`broad_phase` `None`); `broad_phase` is `(reach + margin, margin)` (m).
    pub(crate) fn new(topology: &ContactTopology, x: &[f64], broad_phase: Option<(f64, f64)>) -> Self {
        match broad_phase {
            Some((radius_m, margin_m)) => CandidateList {
                found_at: x.to_vec(),
                pairs: topology.candidates(x, radius_m),
                slack_m: 0.5 * margin_m,
            },
            None => CandidateList { found_at: vec![], pairs: vec![], slack_m: f64::INFINITY },
        }
    }

    /// Bring the list to positions `x`: the pairs' distances there, or the list found anew
    /// there once the slack left is under half the initial `margin / 2`.
    pub(crate) fn update(&mut self, topology: &ContactTopology, x: &[f64], broad_phase: Option<(f64, f64)>) {
        let Some((_, margin_m)) = broad_phase else { return };
        let moved = self
            .found_at
            .chunks_exact(3)
            .zip(x.chunks_exact(3))
            .map(|(a, b)| Vector3::new(b[0] - a[0], b[1] - a[1], b[2] - a[2]).norm())
            .fold(0.0, f64::max);
        if moved > 0.25 * margin_m {
            *self = CandidateList::new(topology, x, broad_phase);
            return;
        }
        self.slack_m = 0.5 * margin_m - moved;
        self.pairs.par_iter_mut().for_each(|c| c.distance_m = topology.distance_m(x, c.a, c.b));
    }

    /// The pairs closer than `reach_m` (with a relative allowance of `10⁻⁹` for the round-off
    /// of the distances): at the list's positions, the only pairs with any contact energy.
    pub(crate) fn within(&self, reach_m: f64) -> Vec<Candidate> {
        self.pairs.iter().filter(|c| c.distance_m < reach_m * (1.0 + 1e-9)).copied().collect()
    }

    /// The smallest centreline distance of the pairs (m; ∞ for none).
    pub(crate) fn closest_m(&self) -> f64 {
        self.pairs.iter().map(|c| c.distance_m).fold(f64::INFINITY, f64::min)
    }
}

/// The edges of a scene and the pairs excluded from contact.
#[derive(Debug, Clone)]
pub(crate) struct ContactTopology {
    /// All edges, yarn after yarn.
    pub edges: Vec<Edge>,
    /// Per yarn: number of edges and whether it is closed.
    yarns: Vec<(usize, bool)>,
    /// Glued vertex pairs, smaller index first, sorted.
    glued: Vec<(usize, usize)>,
}

impl ContactTopology {
    /// The topology of yarns `(first vertex, vertices, closed, rest lengths)` joined by the glue
    /// springs `glued` (vertex pairs).
    pub(crate) fn new(yarns: &[(usize, usize, bool, &[f64])], glued: &[(usize, usize)]) -> Self {
        let mut edges = Vec::new();
        for (yarn, &(first, n, _, rest)) in yarns.iter().enumerate() {
            for (index, &rest_length_m) in rest.iter().enumerate() {
                edges.push(Edge {
                    ends: [first + index, first + (index + 1) % n],
                    rest_length_m,
                    yarn,
                    index,
                });
            }
        }
        let mut glued: Vec<(usize, usize)> = glued.iter().map(|&(a, b)| (a.min(b), a.max(b))).collect();
        glued.sort_unstable();
        glued.dedup();
        ContactTopology {
            edges,
            yarns: yarns.iter().map(|&(_, _, c, rest)| (rest.len(), c)).collect(),
            glued,
        }
    }

    /// Whether edges `e` and `f` are kept out of contact (the rule of the module).
    pub(crate) fn excluded(&self, e: usize, f: usize) -> bool {
        let (a, b) = (&self.edges[e], &self.edges[f]);
        if a.yarn == b.yarn {
            let (m, closed) = self.yarns[a.yarn];
            let gap = a.index.abs_diff(b.index);
            let gap = if closed { gap.min(m - gap) } else { gap };
            if gap <= 2 {
                return true;
            }
        }
        a.ends
            .iter()
            .any(|&u| b.ends.iter().any(|&v| self.glued.binary_search(&(u.min(v), u.max(v))).is_ok()))
    }

    /// The candidate pairs at positions `x` (vertex `v` at `x[3v..3v+3]`) within `radius_m`,
    /// sorted by `(a, b)`.
    pub(crate) fn candidates(&self, x: &[f64], radius_m: f64) -> Vec<Candidate> {
        let point = |v: usize| Vector3::new(x[3 * v], x[3 * v + 1], x[3 * v + 2]);
        let grow = Vector3::repeat(0.5 * radius_m);
        let boxes: Vec<(Vector3<f64>, Vector3<f64>)> = self
            .edges
            .iter()
            .map(|e| {
                let (p, q) = (point(e.ends[0]), point(e.ends[1]));
                (p.inf(&q) - grow, p.sup(&q) + grow)
            })
            .collect();
        let cell = boxes.iter().map(|(lo, hi)| (hi - lo).max()).fold(radius_m, f64::max);
        let mut grid: HashMap<[i64; 3], Vec<usize>> = HashMap::new();
        for (e, (lo, hi)) in boxes.iter().enumerate() {
            let (l, h) = (lo.map(|c| (c / cell).floor() as i64), hi.map(|c| (c / cell).floor() as i64));
            for i in l.x..=h.x {
                for j in l.y..=h.y {
                    for k in l.z..=h.z {
                        grid.entry([i, j, k]).or_default().push(e);
                    }
                }
            }
        }
        let mut pairs: Vec<(usize, usize)> = grid
            .values()
            .flat_map(|bucket| {
                bucket
                    .iter()
                    .enumerate()
                    .flat_map(move |(i, &e)| bucket[..i].iter().map(move |&f| (e.min(f), e.max(f))))
            })
            .collect();
        pairs.sort_unstable();
        pairs.dedup();
        let overlap = |e: usize, f: usize| {
            let ((lo_a, hi_a), (lo_b, hi_b)) = (boxes[e], boxes[f]);
            (0..3).all(|k| lo_a[k] <= hi_b[k] && lo_b[k] <= hi_a[k])
        };
        pairs
            .par_iter()
            .filter(|&&(e, f)| overlap(e, f) && !self.excluded(e, f))
            .filter_map(|&(a, b)| {
                let distance_m = self.distance_m(x, a, b);
                (distance_m < radius_m).then_some(Candidate { a, b, distance_m })
            })
            .collect()
    }

    /// Centreline distance of edges `e` and `f` at positions `x`.
    pub(crate) fn distance_m(&self, x: &[f64], e: usize, f: usize) -> f64 {
        let point = |v: usize| Vector3::new(x[3 * v], x[3 * v + 1], x[3 * v + 2]);
        let (a, b) = (&self.edges[e], &self.edges[f]);
        segment_distance(&point(a.ends[0]), &point(a.ends[1]), &point(b.ends[0]), &point(b.ends[1]))
    }
}

/// Distance from `p` to the segment `a b`.
fn point_segment_distance(p: &Vector3<f64>, a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    let d = b - a;
    let length2 = d.norm_squared();
    let s = if length2 > 0.0 { ((p - a).dot(&d) / length2).clamp(0.0, 1.0) } else { 0.0 };
    (a + d * s - p).norm()
}

/// Distance between the segments `p0 p1` and `q0 q1`: the clamped closest points of the two
/// lines (Ericson 2005, Sec. 5.1.9), and the four endpoint-segment distances, which settle the
/// (nearly) parallel cases exactly. Every value computed is the distance of two points on the
/// segments, so round-off can only overestimate by the error of the interior solution.
pub(crate) fn segment_distance(
    p0: &Vector3<f64>,
    p1: &Vector3<f64>,
    q0: &Vector3<f64>,
    q1: &Vector3<f64>,
) -> f64 {
    let endpoints = point_segment_distance(p0, q0, q1)
        .min(point_segment_distance(p1, q0, q1))
        .min(point_segment_distance(q0, p0, p1))
        .min(point_segment_distance(q1, p0, p1));
    let (d1, d2, r) = (p1 - p0, q1 - q0, p0 - q0);
    let (a, b, c, e, f) = (d1.norm_squared(), d1.dot(&d2), d1.dot(&r), d2.norm_squared(), d2.dot(&r));
    let denominator = a * e - b * b;
    if a == 0.0 || e == 0.0 || denominator <= 1e-12 * a * e {
        return endpoints;
    }
    let s = (b * f - c * e) / denominator;
    let t = (b * s + f) / e;
    if (0.0..=1.0).contains(&s) && (0.0..=1.0).contains(&t) {
        endpoints.min((p0 + d1 * s - q0 - d2 * t).norm())
    } else {
        endpoints
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn segment_distances_of_crossing_parallel_and_skew_segments() {
        let v = |x: f64, y: f64, z: f64| Vector3::new(x, y, z);
        // Crossing at a height of 0.3.
        let d =
            segment_distance(&v(-1.0, 0.0, 0.0), &v(1.0, 0.0, 0.0), &v(0.2, -1.0, 0.3), &v(0.2, 1.0, 0.3));
        assert!((d - 0.3).abs() < 1e-15);
        // Parallel, overlapping: 0.5 apart.
        let d = segment_distance(&v(0.0, 0.0, 0.0), &v(1.0, 0.0, 0.0), &v(0.5, 0.5, 0.0), &v(2.0, 0.5, 0.0));
        assert!((d - 0.5).abs() < 1e-15);
        // Closest points at an end: lines cross outside the segments.
        let d = segment_distance(&v(0.0, 0.0, 0.0), &v(1.0, 0.0, 0.0), &v(2.0, -1.0, 0.0), &v(2.0, 1.0, 0.0));
        assert!((d - 1.0).abs() < 1e-15);
        // Against a brute-force sampling of both segments.
        let (p0, p1, q0, q1) = (v(0.1, 0.3, -0.2), v(0.9, -0.4, 0.5), v(-0.3, 0.2, 0.6), v(0.8, 0.1, -0.1));
        let mut brute = f64::INFINITY;
        for i in 0..=400 {
            for j in 0..=400 {
                let (s, t) = (i as f64 / 400.0, j as f64 / 400.0);
                brute = brute.min((p0 + (p1 - p0) * s - q0 - (q1 - q0) * t).norm());
            }
        }
        let d = segment_distance(&p0, &p1, &q0, &q1);
        assert!(d <= brute && brute - d < 1e-4, "{d} vs {brute}");
    }

    #[test]
    fn neighbours_along_a_yarn_and_across_glue_are_excluded() {
        let rest = [1.0; 6];
        // Yarn 0: open, vertices 0..7 (edges 0..6); yarn 1: closed, vertices 7..13 (edges 6..12).
        let topology = ContactTopology::new(&[(0, 7, false, &rest), (7, 6, true, &rest)], &[(6, 7)]);
        assert!(topology.excluded(0, 1) && topology.excluded(0, 2) && !topology.excluded(0, 3));
        // Closed: edges 6 and 11 share vertex 7; 6 and 10 are one apart; 6 and 9 interact.
        assert!(topology.excluded(6, 11) && topology.excluded(6, 10) && !topology.excluded(6, 9));
        // Glue 6-7: edge 5 (5-6) and edges 6 (7-8) and 11 (12-7) are excluded, edge 4 is not.
        assert!(topology.excluded(5, 6) && topology.excluded(5, 11) && !topology.excluded(4, 6));
    }

    #[test]
    fn the_spatial_hash_finds_exactly_the_pairs_within_the_radius() {
        // A zig-zag yarn folded over itself: compare with all pairs.
        let n = 40;
        let x: Vec<f64> = (0..n)
            .flat_map(|i| {
                let s = i as f64 * 0.25;
                [s.sin() * 2.0, (1.3 * s).cos(), 0.1 * s]
            })
            .collect();
        let rest = vec![0.3; n - 1];
        let topology = ContactTopology::new(&[(0, n, false, &rest)], &[]);
        for radius in [0.2, 0.6, 1.5] {
            let found: Vec<(usize, usize)> =
                topology.candidates(&x, radius).iter().map(|c| (c.a, c.b)).collect();
            let mut all = vec![];
            for a in 0..n - 1 {
                for b in a + 1..n - 1 {
                    if !topology.excluded(a, b) && topology.distance_m(&x, a, b) < radius {
                        all.push((a, b));
                    }
                }
            }
            assert_eq!(found, all, "radius {radius}");
        }
    }

    #[test]
    fn the_list_of_a_step_holds_every_pair_within_reach_until_it_is_found_anew() {
        let n = 40;
        let zigzag = |phase: f64| -> Vec<f64> {
            (0..n)
                .flat_map(|i| {
                    let s = i as f64 * 0.25;
                    [(s + phase).sin() * 2.0, (1.3 * s).cos(), 0.1 * s]
                })
                .collect()
        };
        let rest = vec![0.3; n - 1];
        let topology = ContactTopology::new(&[(0, n, false, &rest)], &[]);
        let (reach, margin) = (0.4, 0.4);
        let broad_phase = Some((reach + margin, margin));
        let x0 = zigzag(0.0);
        let mut list = CandidateList::new(&topology, &x0, broad_phase);
        assert_eq!(list.slack_m, 0.5 * margin);
        // Moves under margin / 4 keep the list and spend its slack; the distances follow.
        for phase in [0.01, 0.02, 0.03, 0.04, 0.05, 0.3] {
            let x = zigzag(phase);
            let moved = x0
                .chunks(3)
                .zip(x.chunks(3))
                .map(|(a, b)| Vector3::from_column_slice(a).metric_distance(&Vector3::from_column_slice(b)))
                .fold(0.0, f64::max);
            list.update(&topology, &x, broad_phase);
            if moved <= 0.25 * margin {
                assert_eq!(list.slack_m, 0.5 * margin - moved, "phase {phase}");
            } else {
                assert_eq!(list.slack_m, 0.5 * margin, "found anew at phase {phase}");
            }
            for c in &list.pairs {
                assert_eq!(c.distance_m, topology.distance_m(&x, c.a, c.b));
            }
            // Every pair within reach is listed, and `within` keeps exactly those.
            let near: Vec<_> = topology.candidates(&x, reach).iter().map(|c| (c.a, c.b)).collect();
            let listed: Vec<_> =
                list.within(reach).iter().filter(|c| c.distance_m < reach).map(|c| (c.a, c.b)).collect();
            assert_eq!(listed, near, "phase {phase}");
        }
        assert!(list.closest_m() > 0.0 && list.closest_m() < reach);
    }
}
