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

/// Where a pattern's yarn centrelines come closest, in radii of the first yarn of the pair, as a line
/// for `yarnhom inspect`: about 2 for touching yarns, well below for interpenetrating ones.
pub fn closest_yarns(p: &Pattern) -> String {
    match min_inter_yarn_distance(p) {
        Some(m) => format!(
            "closest centrelines: {:.3} radii apart (yarn {} edge {}, yarn {} edge {} in tile {:?})",
            m.distance_m / p.yarns[m.a.yarn].radius_m,
            m.a.yarn,
            m.a.index,
            m.b.yarn,
            m.b.index,
            m.image
        ),
        None => "closest centrelines: no two yarn pieces to compare".into(),
    }
}

/// The smallest centreline distance between edges of different yarn pieces (see
/// [`YarnNeighbours`]) over all periodic images: first the tile and its 8 neighbouring images;
/// then, if the tile is small against the distance found (a segment at a farther image could
/// still come closer), every image that can, up to [`MAX_IMAGE_REACH`] periods away. A course
/// whose loops are taller than the tile, for instance, meets the course two tiles up. `None`
/// for a pattern with no such pair.
pub fn min_inter_yarn_distance(pattern: &Pattern) -> Option<MinDistance> {
    let neighbours = YarnNeighbours::new(pattern);
    let segments = segments_of(pattern);
    let nearest = closest_within_images(pattern, &neighbours, &segments, [1, 1])?;
    let reach = images_within(pattern, &segments, nearest.distance_m);
    if reach[0] > 1 || reach[1] > 1 {
        closest_within_images(pattern, &neighbours, &segments, reach)
    } else {
        Some(nearest)
    }
}

/// Per edge (indexed by source vertex): the centreline distance to the nearest edge that is not
/// its neighbour along a yarn, over the tile and its images within reach. The largest of these is
/// the smallest radius at which every edge touches another (`R_est` of thesis Sec. 6.5.3).
pub fn edge_clearances(pattern: &Pattern) -> Vec<f64> {
    let neighbours = YarnNeighbours::new(pattern);
    let segments = segments_of(pattern);
    // Every edge has another within a period of it (its own images at the latest).
    let reach = images_within(pattern, &segments, pattern.period_m[0].max(pattern.period_m[1]));
    let mut clearance = vec![f64::INFINITY; pattern.vertex_count()];
    for ox in -reach[0]..=reach[0] {
        for oy in -reach[1]..=reach[1] {
            let shift =
                Vector3::new(f64::from(ox) * pattern.period_m[0], f64::from(oy) * pattern.period_m[1], 0.0);
            for a in &segments {
                for b in &segments {
                    let (b0, b1) = (b.p0 + shift, b.p1 + shift);
                    let bound = clearance[a.from as usize];
                    if lower_bound(&a.p0, &a.p1, &b0, &b1) >= bound
                        || (ox == 0 && oy == 0 && a.from == b.from)
                        || neighbours.are_neighbours(a.from, b.from, [ox, oy])
                    {
                        continue;
                    }
                    let d = segment_distance(&a.p0, &a.p1, &b0, &b1).distance;
                    clearance[a.from as usize] = bound.min(d);
                }
            }
        }
    }
    clearance
}

/// The tile's edges as segments.
fn segments_of(pattern: &Pattern) -> Vec<Segment> {
    pattern
        .edges()
        .map(|e| Segment {
            edge: EdgeRef { yarn: e.yarn, index: e.index_in_yarn },
            from: e.from,
            p0: Vector3::from(pattern.positions_m[e.from as usize]),
            p1: Vector3::from(pattern.shifted(e.to, e.offset)),
        })
        .collect()
}

/// An edge with its end points (the end shifted by the edge's tile offset).
struct Segment {
    edge: EdgeRef,
    from: u32,
    p0: Vector3<f64>,
    p1: Vector3<f64>,
}

/// The closest non-neighbouring pair between the tile and its images `-reach..=reach`.
fn closest_within_images(
    pattern: &Pattern,
    neighbours: &YarnNeighbours,
    segments: &[Segment],
    reach: [i32; 2],
) -> Option<MinDistance> {
    let mut best: Option<MinDistance> = None;
    for ox in -reach[0]..=reach[0] {
        for oy in -reach[1]..=reach[1] {
            let shift =
                Vector3::new(f64::from(ox) * pattern.period_m[0], f64::from(oy) * pattern.period_m[1], 0.0);
            for (i, a) in segments.iter().enumerate() {
                for (j, b) in segments.iter().enumerate() {
                    if ox == 0 && oy == 0 && j <= i {
                        continue; // each unordered pair in the tile once
                    }
                    let (b0, b1) = (b.p0 + shift, b.p1 + shift);
                    let bound = best.map_or(f64::INFINITY, |m| m.distance_m);
                    if lower_bound(&a.p0, &a.p1, &b0, &b1) >= bound
                        || neighbours.are_neighbours(a.from, b.from, [ox, oy])
                    {
                        continue;
                    }
                    let d = segment_distance(&a.p0, &a.p1, &b0, &b1).distance;
                    if d < bound {
                        best = Some(MinDistance { distance_m: d, a: a.edge, b: b.edge, image: [ox, oy] });
                    }
                }
            }
        }
    }
    best
}

/// Farthest image searched along an axis. Tiles whose vertices lie within a few periods of the
/// tile (every generated or published one) never need it; it bounds the work for patterns with
/// vertices spread over many periods, whose farther images are then not searched.
pub const MAX_IMAGE_REACH: i32 = 8;

/// How many images along each axis can hold a segment closer than `distance` to the tile's: the
/// segments span a box of extent `e` along an axis, so an image `k` periods away is at least
/// `k * period - e` from them. Between 1 and [`MAX_IMAGE_REACH`].
fn images_within(pattern: &Pattern, segments: &[Segment], distance: f64) -> [i32; 2] {
    std::array::from_fn(|axis| {
        let ends = segments.iter().flat_map(|s| [s.p0[axis], s.p1[axis]]);
        let (lo, hi) = ends.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| (lo.min(x), hi.max(x)));
        let images = ((hi - lo + distance) / pattern.period_m[axis]).floor();
        // A non-finite extent (invalid positions) stays with the neighbouring images.
        if images.is_finite() { (images.min(f64::from(MAX_IMAGE_REACH)) as i32).max(1) } else { 1 }
    })
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

#[cfg(test)]
mod tests {
    use super::*;
    use yarnhom_artifacts::{Fabric, Yarn};

    /// Two straight yarns along X1 in a unit tile, at X2 = `y[0]` and `y[1]`; radius 0.2, so a
    /// yarn's own pieces (1/3 apart) are within `pi r` of each other along it.
    fn two_straight_yarns(y: [f64; 2]) -> Pattern {
        let xs = [0.0, 1.0 / 3.0, 2.0 / 3.0];
        let positions_m = y.iter().flat_map(|&y| xs.map(|x| [x, y, 0.0])).collect();
        let yarn = |first: u32| Yarn {
            radius_m: 0.2,
            vertices: (first..first + 3).collect(),
            edge_offsets: vec![[0, 0], [0, 0], [1, 0]],
        };
        Pattern {
            name: "lines".into(),
            fabric: Fabric::Woven,
            period_m: [1.0, 1.0],
            positions_m,
            edge_twist_rad: vec![0.0; 6],
            yarns: vec![yarn(0), yarn(3)],
            rest: None,
            origin: "test".into(),
        }
    }

    #[test]
    fn a_yarn_stored_periods_away_is_measured_against_its_nearest_image() {
        // Yarn 1 lies 0.45 above yarn 0 once moved back two periods; the neighbouring images
        // alone would report yarn 0 against its own image one period up (1.0 apart).
        let p = two_straight_yarns([0.0, 2.45]);
        p.validate().expect("valid");
        let m = min_inter_yarn_distance(&p).expect("pairs");
        assert!((m.distance_m - 0.45).abs() < 1e-12, "{m:?}");
        assert_eq!(m.image[1].abs(), 2, "{m:?}");
    }

    #[test]
    fn a_straight_yarn_is_not_its_own_neighbour_along_itself() {
        // Same yarn, images shifted along its closure: one physical yarn, no pair counts; the
        // closest pieces are the yarns 0.3 apart.
        let m = min_inter_yarn_distance(&two_straight_yarns([0.0, 0.3])).expect("pairs");
        assert!((m.distance_m - 0.3).abs() < 1e-12, "{m:?}");
        assert_ne!(m.a.yarn, m.b.yarn);
    }
}
