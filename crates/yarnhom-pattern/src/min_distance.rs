//! The smallest distance between yarn centrelines in a periodic tile: the check that a pattern
//! is free of interpenetration (centrelines of touching yarns are two radii apart).

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

struct Segment {
    yarn: usize,
    index: usize,
    p0: Vector3<f64>,
    p1: Vector3<f64>,
    /// Arc length along the yarn at the start of the segment.
    arc: f64,
    /// Sum of the tile offsets of the yarn's earlier edges: where this edge sits on the
    /// unrolled yarn, relative to the tile.
    unrolled: [i32; 2],
}

/// Arc-length separation below which two pieces of the *same physical yarn* are neighbours
/// and not counted: half a turn around a yarn of radius `r` (`pi r`), the shortest length over
/// which a bent yarn can come back to touch itself.
pub fn same_yarn_exclusion(radius_m: f64) -> f64 {
    std::f64::consts::PI * radius_m
}

/// The smallest centreline distance between edges of different yarn pieces, over the tile and
/// its 8 neighbouring images. A yarn and its image shifted by a whole multiple of the yarn's
/// closure offset (counting the offsets of the edges between them) are the same physical yarn:
/// for those, pairs closer than
/// [`same_yarn_exclusion`] along the yarn are skipped. `None` for a pattern with no such pair.
pub fn min_inter_yarn_distance(pattern: &Pattern) -> Option<MinDistance> {
    let segments = segments(pattern);
    let lengths: Vec<f64> =
        pattern.yarns.iter().enumerate().map(|(y, _)| yarn_length(&segments, y)).collect();
    let mut best: Option<MinDistance> = None;
    for ox in -1..=1 {
        for oy in -1..=1 {
            let shift =
                Vector3::new(f64::from(ox) * pattern.period_m[0], f64::from(oy) * pattern.period_m[1], 0.0);
            for a in &segments {
                for b in &segments {
                    if ox == 0 && oy == 0 && (b.yarn, b.index) <= (a.yarn, a.index) {
                        continue; // each unordered pair in the tile once
                    }
                    let (b0, b1) = (b.p0 + shift, b.p1 + shift);
                    let bound = best.map_or(f64::INFINITY, |m| m.distance_m);
                    if lower_bound(a, &b0, &b1) >= bound {
                        continue;
                    }
                    if a.yarn == b.yarn {
                        let closure = pattern.yarns[a.yarn].closure_offset();
                        let offset = [ox + a.unrolled[0] - b.unrolled[0], oy + a.unrolled[1] - b.unrolled[1]];
                        if let Some(m) = multiple_of(closure, offset) {
                            let radius = pattern.yarns[a.yarn].radius_m;
                            if arc_gap(a, b, f64::from(m) * lengths[a.yarn]) < same_yarn_exclusion(radius) {
                                continue;
                            }
                        }
                    }
                    let d = segment_distance(&a.p0, &a.p1, &b0, &b1).distance;
                    if d < bound {
                        best = Some(MinDistance {
                            distance_m: d,
                            a: EdgeRef { yarn: a.yarn, index: a.index },
                            b: EdgeRef { yarn: b.yarn, index: b.index },
                            image: [ox, oy],
                        });
                    }
                }
            }
        }
    }
    best
}

fn segments(pattern: &Pattern) -> Vec<Segment> {
    let mut arc = vec![0.0; pattern.yarns.len()];
    let mut unrolled = vec![[0, 0]; pattern.yarns.len()];
    pattern
        .edges()
        .map(|e| {
            let p0 = Vector3::from(pattern.positions_m[e.from as usize]);
            let p1 = Vector3::from(pattern.shifted(e.to, e.offset));
            let (y, u) = (e.yarn, unrolled[e.yarn]);
            let s = Segment { yarn: y, index: e.index_in_yarn, p0, p1, arc: arc[y], unrolled: u };
            arc[y] += (p1 - p0).norm();
            unrolled[y] = [u[0] + e.offset[0], u[1] + e.offset[1]];
            s
        })
        .collect()
}

fn yarn_length(segments: &[Segment], yarn: usize) -> f64 {
    segments.iter().filter(|s| s.yarn == yarn).map(|s| (s.p1 - s.p0).norm()).sum()
}

/// A cheap lower bound of the distance between two segments: midpoint distance minus half
/// lengths.
fn lower_bound(a: &Segment, b0: &Vector3<f64>, b1: &Vector3<f64>) -> f64 {
    let mid = (a.p0 + a.p1 - b0 - b1).norm() / 2.0;
    mid - ((a.p1 - a.p0).norm() + (b1 - b0).norm()) / 2.0
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

/// Gap along the unrolled yarn between segment `a` and segment `b` moved by `shift` of arc.
fn arc_gap(a: &Segment, b: &Segment, shift: f64) -> f64 {
    let (a0, a1) = (a.arc, a.arc + (a.p1 - a.p0).norm());
    let (b0, b1) = (b.arc + shift, b.arc + shift + (b.p1 - b.p0).norm());
    (a0 - b1).max(b0 - a1).max(0.0)
}
