//! The smallest distance between yarn centrelines in a periodic tile: the check that a pattern
//! is free of interpenetration (centrelines of touching yarns are two radii apart), and the rule
//! for which edge pairs are neighbours along one physical yarn (shared with contact).

use nalgebra::Vector3;
use yarnhom_artifacts::Pattern;
use yarnhom_geom::segment_distance;

/// An edge of a pattern, by yarn and position along it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct EdgeRef {
    /// Yarn index.
    pub yarn: usize,
    /// Edge index along the yarn.
    pub index: usize,
}

/// Where two yarn pieces come closest.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MinDistance {
    /// Centreline distance (m).
    pub distance_m: f64,
    /// Edge in the tile.
    pub a: EdgeRef,
    /// Edge in the periodic image `image`.
    pub b: EdgeRef,
    /// Tile offset of `b`'s image.
    pub image: [i32; 2],
}

/// Arc-length separation below which two pieces of the *same physical yarn* are neighbours
/// and not counted: half a turn around a yarn of radius `r` (`pi r`), the shortest length over
/// which a bent yarn can come back to touch itself.
pub fn same_yarn_exclusion(radius_m: f64) -> f64 {
    std::f64::consts::PI * radius_m
}

/// Where each edge (indexed by its source vertex) lies along its physical yarn: the rule that
/// decides which edge pairs are near neighbours along one yarn. A yarn and its image shifted by
/// a whole multiple of the yarn's closure offset (counting the offsets of the edges between
/// them) are the same physical yarn; pairs of its pieces closer than [`same_yarn_exclusion`]
/// along it are neighbours.
#[derive(Debug, Clone)]
pub struct YarnNeighbours {
    /// Per source vertex: yarn, arc length at the edge start, edge length, unrolled tile offset.
    edges: Vec<(usize, f64, f64, [i32; 2])>,
    /// Per yarn: length, closure offset, exclusion length.
    yarns: Vec<(f64, [i32; 2], f64)>,
}

impl YarnNeighbours {
    /// The neighbour rule of a pattern, with arc lengths measured on its current geometry.
    pub fn new(pattern: &Pattern) -> Self {
        let mut edges = vec![(0, 0.0, 0.0, [0, 0]); pattern.vertex_count()];
        let mut yarns = Vec::with_capacity(pattern.yarns.len());
        for (y, yarn) in pattern.yarns.iter().enumerate() {
            let (mut arc, mut unrolled) = (0.0, [0, 0]);
            for e in pattern.edges().filter(|e| e.yarn == y) {
                let d = pattern.edge_vector(&e);
                let length = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
                edges[e.from as usize] = (y, arc, length, unrolled);
                arc += length;
                unrolled = [unrolled[0] + e.offset[0], unrolled[1] + e.offset[1]];
            }
            yarns.push((arc, yarn.closure_offset(), same_yarn_exclusion(yarn.radius_m)));
        }
        YarnNeighbours { edges, yarns }
    }

    /// Whether the edge leaving vertex `a` (in the tile) and the edge leaving vertex `b` in the
    /// tile image `image` are near neighbours along one physical yarn.
    pub fn are_neighbours(&self, a: u32, b: u32, image: [i32; 2]) -> bool {
        let (ya, arc_a, len_a, un_a) = self.edges[a as usize];
        let (yb, arc_b, len_b, un_b) = self.edges[b as usize];
        if ya != yb {
            return false;
        }
        let (length, closure, exclusion) = self.yarns[ya];
        let offset = [image[0] + un_a[0] - un_b[0], image[1] + un_a[1] - un_b[1]];
        let Some(m) = multiple_of(closure, offset) else { return false };
        let b0 = arc_b + f64::from(m) * length;
        let gap = (arc_a - (b0 + len_b)).max(b0 - (arc_a + len_a)).max(0.0);
        gap < exclusion
    }
}

/// The smallest centreline distance between edges of different yarn pieces (see
/// [`YarnNeighbours`]), over the tile and its 8 neighbouring images. `None` for a pattern with no
/// such pair.
pub fn min_inter_yarn_distance(pattern: &Pattern) -> Option<MinDistance> {
    let neighbours = YarnNeighbours::new(pattern);
    let segments: Vec<(EdgeRef, u32, Vector3<f64>, Vector3<f64>)> = pattern
        .edges()
        .map(|e| {
            let p0 = Vector3::from(pattern.positions_m[e.from as usize]);
            let p1 = Vector3::from(pattern.shifted(e.to, e.offset));
            (EdgeRef { yarn: e.yarn, index: e.index_in_yarn }, e.from, p0, p1)
        })
        .collect();
    let mut best: Option<MinDistance> = None;
    for ox in -1..=1 {
        for oy in -1..=1 {
            let shift =
                Vector3::new(f64::from(ox) * pattern.period_m[0], f64::from(oy) * pattern.period_m[1], 0.0);
            for (i, (ra, va, a0, a1)) in segments.iter().enumerate() {
                for (j, (rb, vb, b0, b1)) in segments.iter().enumerate() {
                    if ox == 0 && oy == 0 && j <= i {
                        continue; // each unordered pair in the tile once
                    }
                    let (b0, b1) = (b0 + shift, b1 + shift);
                    let bound = best.map_or(f64::INFINITY, |m| m.distance_m);
                    if lower_bound(a0, a1, &b0, &b1) >= bound || neighbours.are_neighbours(*va, *vb, [ox, oy])
                    {
                        continue;
                    }
                    let d = segment_distance(a0, a1, &b0, &b1).distance;
                    if d < bound {
                        best = Some(MinDistance { distance_m: d, a: *ra, b: *rb, image: [ox, oy] });
                    }
                }
            }
        }
    }
    best
}

/// A cheap lower bound of the distance between two segments: midpoint distance minus half
/// lengths.
pub fn lower_bound(a0: &Vector3<f64>, a1: &Vector3<f64>, b0: &Vector3<f64>, b1: &Vector3<f64>) -> f64 {
    let mid = (a0 + a1 - b0 - b1).norm() / 2.0;
    mid - ((a1 - a0).norm() + (b1 - b0).norm()) / 2.0
}

/// `m` with `offset = m * closure`, if there is one.
fn multiple_of(closure: [i32; 2], offset: [i32; 2]) -> Option<i32> {
    let m = match closure {
        [0, 0] => return None,
        [0, c] => offset[1] / c,
        [c, _] => offset[0] / c,
    };
    (m * closure[0] == offset[0] && m * closure[1] == offset[1]).then_some(m)
}
