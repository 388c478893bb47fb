//! Broad phase for edge-edge proximity in the periodic tile: which pairs of edges — one in the
//! tile, one in a tile image within contact range ([`RveModel::images`]) — may come close. Each
//! edge is bounded by an axis-aligned box grown by a margin (half the contact reach for yarn-yarn
//! contact, Sec. 3.3; the swept box of a step for collision detection, A.2.3), and the tile's
//! boxes are put in a uniform grid (a spatial hash), which every image edge's box near the tile
//! queries, so the cost grows with the number of nearby pairs rather than `E² · images`.

use nalgebra::Vector3;

use crate::model::RveModel;

/// An axis-aligned box.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Aabb {
    /// Lower corner.
    pub lo: Vector3<f64>,
    /// Upper corner.
    pub hi: Vector3<f64>,
}

impl Aabb {
    /// The box of the segment `p q`, grown by `margin` on every side.
    pub fn around_segment(p: &Vector3<f64>, q: &Vector3<f64>, margin: f64) -> Self {
        let m = Vector3::repeat(margin);
        Aabb { lo: p.inf(q) - m, hi: p.sup(q) + m }
    }

    /// The smallest box holding both.
    pub fn union(&self, other: &Aabb) -> Self {
        Aabb { lo: self.lo.inf(&other.lo), hi: self.hi.sup(&other.hi) }
    }

    /// Whether the (closed) boxes intersect.
    pub fn overlaps(&self, other: &Aabb) -> bool {
        (0..3).all(|k| self.lo[k] <= other.hi[k] && other.lo[k] <= self.hi[k])
    }

    fn largest_side(&self) -> f64 {
        (self.hi - self.lo).max()
    }
}

/// A pair of edges (indexed by source vertex): `a` in the tile, `b` in the tile image
/// `model.images[image]`. Pairs order by `(a, image, b)`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct EdgePair {
    /// Edge in the tile.
    pub a: usize,
    /// Index of `b`'s image in [`RveModel::images`].
    pub image: usize,
    /// Edge in the image.
    pub b: usize,
}

/// Index of the tile itself (offset `[0, 0]`) in [`RveModel::images`].
pub fn tile_image(model: &RveModel) -> usize {
    model.images.iter().position(|&o| o == [0, 0]).expect("the tile itself is an image")
}

/// The edge pairs whose boxes overlap, `boxes[i][e]` bounding edge `e` in the image
/// `model.images[i]`; each physical pair once (`(a, b, o)` and `(b, a, -o)` are the same pair:
/// kept with `a < b`, or `a = b` and `o > 0`), yarn neighbours excluded
/// ([`yarnhom_pattern::YarnNeighbours`]); sorted, so that sums over them are reproducible.
pub fn edge_pairs(model: &RveModel, boxes: &[Vec<Aabb>]) -> Vec<EdgePair> {
    let tile = &boxes[tile_image(model)];
    let grid = Grid::new(tile);
    let tile_bounds = bounds(tile);
    let mut pairs = Vec::new();
    let mut hits = Vec::new();
    for (image, (&o, image_boxes)) in model.images.iter().zip(boxes).enumerate() {
        for (b, query) in image_boxes.iter().enumerate().filter(|(_, q)| q.overlaps(&tile_bounds)) {
            grid.overlapping(query, &mut hits);
            pairs.extend(
                hits.iter()
                    .filter(|&&a| (a < b || (a == b && o > [0, 0])) && model.contact_pair(a, b, o))
                    .map(|&a| EdgePair { a, image, b }),
            );
        }
    }
    pairs.sort_unstable();
    pairs
}

/// The box around some boxes (an empty, inverted box for none).
fn bounds(boxes: &[Aabb]) -> Aabb {
    let empty = Aabb { lo: Vector3::repeat(f64::INFINITY), hi: Vector3::repeat(f64::NEG_INFINITY) };
    boxes.iter().fold(empty, |u, b| u.union(b))
}

/// Boxes spanning more cells than this along an axis are not put in the grid but tested
/// directly, which bounds the cells per box (a degenerate step can produce huge swept boxes).
const WIDE_CELLS: f64 = 4.0;

/// Buckets per axis at most: cells beyond wrap around (a spatial hash), so that boxes strewn far
/// apart cost no memory; cells sharing a bucket only add candidates, which the exact test drops.
const MAX_BUCKETS: i64 = 32;

/// A range of cells, `lo..=hi` along each axis.
type Cells = ([i64; 3], [i64; 3]);

/// A uniform grid over boxes, hashed into a table of buckets (cell coordinates modulo the table
/// size, which spans the boxes' cells up to [`MAX_BUCKETS`] per axis) stored as one list: bucket
/// `k` holds `items[starts[k]..starts[k + 1]]`, each box in the buckets of every cell it touches.
/// The cell size is the boxes' mean largest side, so a typical box touches at most 2 cells per
/// axis and sits in a bucket with the few boxes near it.
struct Grid<'a> {
    boxes: &'a [Aabb],
    cell: f64,
    /// The cells touched by the boxes in the grid (empty, `lo > hi`, for none).
    span: Cells,
    /// The first cell of each box in the grid.
    first: Vec<[i64; 3]>,
    buckets: [i64; 3],
    starts: Vec<usize>,
    items: Vec<usize>,
    wide: Vec<usize>,
}

impl<'a> Grid<'a> {
    fn new(boxes: &'a [Aabb]) -> Self {
        let cell = boxes.iter().map(Aabb::largest_side).sum::<f64>() / boxes.len() as f64;
        let mut grid = Grid {
            boxes,
            cell,
            span: ([i64::MAX; 3], [i64::MIN; 3]),
            first: Vec::new(),
            buckets: [1; 3],
            starts: Vec::new(),
            items: Vec::new(),
            wide: Vec::new(),
        };
        let ranges: Vec<Option<Cells>> = boxes.iter().map(|b| grid.cells(b)).collect();
        grid.first = ranges.iter().map(|r| r.map_or([0; 3], |(lo, _)| lo)).collect();
        for &(lo, hi) in ranges.iter().flatten() {
            grid.span = (
                std::array::from_fn(|k| grid.span.0[k].min(lo[k])),
                std::array::from_fn(|k| grid.span.1[k].max(hi[k])),
            );
        }
        grid.buckets = std::array::from_fn(|k| {
            grid.span.1[k].saturating_sub(grid.span.0[k]).saturating_add(1).clamp(1, MAX_BUCKETS)
        });
        let size = (grid.buckets[0] * grid.buckets[1] * grid.buckets[2]) as usize;
        grid.starts = vec![0; size + 1];
        for &(lo, hi) in ranges.iter().flatten() {
            for c in cells_between(lo, hi) {
                let k = grid.bucket(c);
                grid.starts[k + 1] += 1;
            }
        }
        for k in 0..size {
            grid.starts[k + 1] += grid.starts[k];
        }
        let mut next = grid.starts.clone();
        grid.items = vec![0; grid.starts[size]];
        for (i, range) in ranges.iter().enumerate() {
            match *range {
                Some((lo, hi)) => {
                    for c in cells_between(lo, hi) {
                        let k = grid.bucket(c);
                        grid.items[next[k]] = i;
                        next[k] += 1;
                    }
                }
                None => grid.wide.push(i),
            }
        }
        grid
    }

    /// The range of cells a box touches; `None` for a box too wide for the grid (or not finite).
    fn cells(&self, b: &Aabb) -> Option<Cells> {
        let lo = b.lo.map(|x| (x / self.cell).floor());
        let hi = b.hi.map(|x| (x / self.cell).floor());
        // Written so that NaN (an empty grid, a degenerate cell or box) counts as wide.
        let narrow = (0..3).all(|k| lo[k].is_finite() && hi[k].is_finite() && hi[k] - lo[k] < WIDE_CELLS);
        narrow.then(|| (lo.map(|x| x as i64).into(), hi.map(|x| x as i64).into()))
    }

    /// The bucket of a cell.
    fn bucket(&self, c: [i64; 3]) -> usize {
        let [nx, ny, nz] = self.buckets;
        ((c[0].rem_euclid(nx) * ny + c[1].rem_euclid(ny)) * nz + c[2].rem_euclid(nz)) as usize
    }

    /// The boxes overlapping `query` into `hits`, each once (in no particular order).
    fn overlapping(&self, query: &Aabb, hits: &mut Vec<usize>) {
        hits.clear();
        let Some((lo, hi)) = self.cells(query) else {
            hits.extend((0..self.boxes.len()).filter(|&i| self.boxes[i].overlaps(query)));
            return;
        };
        let clamped = (
            std::array::from_fn(|k| lo[k].max(self.span.0[k])),
            std::array::from_fn(|k| hi[k].min(self.span.1[k])),
        );
        for c in cells_between(clamped.0, clamped.1) {
            let k = self.bucket(c);
            for &i in &self.items[self.starts[k]..self.starts[k + 1]] {
                // A box touching several cells of the query counts in one: the cell of the lower
                // corner of their intersection, which both touch.
                let corner: [i64; 3] = std::array::from_fn(|k| self.first[i][k].max(lo[k]));
                if corner == c && self.boxes[i].overlaps(query) {
                    hits.push(i);
                }
            }
        }
        hits.extend(self.wide.iter().filter(|&&i| self.boxes[i].overlaps(query)));
    }
}

/// Every cell of the inclusive range `lo..=hi`.
fn cells_between(lo: [i64; 3], hi: [i64; 3]) -> impl Iterator<Item = [i64; 3]> {
    (lo[0]..=hi[0])
        .flat_map(move |i| (lo[1]..=hi[1]).flat_map(move |j| (lo[2]..=hi[2]).map(move |k| [i, j, k])))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::assembly::{RveState, image_segments};
    use crate::placement::Placement;
    use yarnhom_artifacts::{YarnModel, pyp::parse_pyp};
    use yarnhom_geom::{MacroStrain, segment_distance};
    use yarnhom_pattern::min_distance::lower_bound;

    fn published(name: &str) -> RveModel {
        let path = format!("{}/../../../shared/data/hylc-patterns/{name}.pyp", env!("CARGO_MANIFEST_DIR"));
        let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
        let pattern = parse_pyp(&text, name, None).expect("published pattern imports");
        RveModel::new(&pattern, &YarnModel::table_4_1(name).expect("row")).expect("tile")
    }

    /// Every pair `(a, image, b)` passing `keep`, each physical pair once, neighbours excluded.
    fn brute_force(model: &RveModel, keep: impl Fn(usize, usize, usize) -> bool) -> Vec<EdgePair> {
        let mut pairs = Vec::new();
        for a in 0..model.vertices {
            for (image, &o) in model.images.iter().enumerate() {
                for b in 0..model.vertices {
                    if (a < b || (a == b && o > [0, 0])) && model.contact_pair(a, b, o) && keep(a, image, b) {
                        pairs.push(EdgePair { a, image, b });
                    }
                }
            }
        }
        pairs
    }

    #[test]
    fn the_grid_finds_the_pairs_of_the_brute_force_search_on_published_tiles() {
        for name in ["stock", "rib"] {
            let model = published(name);
            let reach = model.contact.reach_m();
            for strain in ["sx=0", "sx=0.3", "sy=-0.2,sa=0.3", "kx=40", "sx=0.1,ky=-60"] {
                let strain: MacroStrain = strain.parse().expect("strain");
                let placement = Placement::new(model.material.clone(), model.period_m, &strain);
                let mut state = RveState::affine(&model, &placement);
                // Away from the affine start, by up to a yarn radius.
                let r = model.radius_m;
                for v in 0..3 * model.vertices {
                    state.g[v] += r * ((v * 7919 % 1000) as f64 / 500.0 - 1.0);
                }
                let ends = image_segments(&model, &placement, &state.g);
                let boxes: Vec<Vec<Aabb>> = ends
                    .iter()
                    .map(|e| e.iter().map(|(p, q)| Aabb::around_segment(p, q, reach / 2.0)).collect())
                    .collect();
                let grid = edge_pairs(&model, &boxes);
                let tile = &ends[tile_image(&model)];
                let box_overlap =
                    |a: usize, i: usize, b: usize| boxes[tile_image(&model)][a].overlaps(&boxes[i][b]);
                assert_eq!(grid, brute_force(&model, box_overlap), "{name} at {strain:?}");
                // Every pair within reach is found, and the contact pairs (the lower-bound cull
                // of the assembly) are those of the brute-force search less some beyond reach.
                let distance = |a: usize, i: usize, b: usize| {
                    let ((a0, a1), (b0, b1)) = (tile[a], ends[i][b]);
                    segment_distance(&a0, &a1, &b0, &b1).distance
                };
                let within = brute_force(&model, |a, i, b| distance(a, i, b) < reach);
                assert!(!within.is_empty());
                assert!(within.iter().all(|p| grid.binary_search(p).is_ok()), "{name} at {strain:?}");
                let culled = |a: usize, i: usize, b: usize| {
                    let ((a0, a1), (b0, b1)) = (tile[a], ends[i][b]);
                    lower_bound(&a0, &a1, &b0, &b1) < reach
                };
                let contact = brute_force(&model, culled);
                let found: Vec<EdgePair> =
                    grid.iter().copied().filter(|p| culled(p.a, p.image, p.b)).collect();
                assert!(found.iter().all(|p| contact.binary_search(p).is_ok()));
                assert!(
                    contact
                        .iter()
                        .filter(|p| found.binary_search(p).is_err())
                        .all(|p| distance(p.a, p.image, p.b) >= reach)
                );
            }
        }
    }

    /// The boxes of `grid` overlapping `query`, sorted.
    fn found(grid: &Grid, query: &Aabb) -> Vec<usize> {
        let mut hits = Vec::new();
        grid.overlapping(query, &mut hits);
        hits.sort_unstable();
        hits
    }

    #[test]
    fn wide_and_degenerate_boxes_are_tested_directly() {
        let unit = |x: f64| Aabb { lo: Vector3::new(x, 0.0, 0.0), hi: Vector3::new(x + 1.0, 1.0, 1.0) };
        let wide = Aabb { lo: Vector3::new(-100.0, 0.5, 0.5), hi: Vector3::new(100.0, 0.6, 0.6) };
        let mut boxes: Vec<Aabb> = (0..20).map(|i| unit(3.0 * f64::from(i))).collect();
        boxes.push(wide);
        let grid = Grid::new(&boxes);
        assert_eq!(grid.wide, [20]);
        assert_eq!(found(&grid, &unit(2.5)), [1, 20]);
        assert_eq!(found(&grid, &wide), (0..=20).collect::<Vec<_>>());
        assert!(found(&grid, &unit(f64::NAN)).is_empty());
        // A box that is not finite is kept apart and meets nothing.
        boxes.push(unit(f64::NAN));
        let with_nan = Grid::new(&boxes);
        assert_eq!(with_nan.wide, [20, 21]);
        assert_eq!(found(&with_nan, &unit(0.5)), [0, 20]);
        // Zero-size boxes give a zero cell: all are tested directly.
        let points = [Aabb::around_segment(&Vector3::zeros(), &Vector3::zeros(), 0.0); 2];
        let degenerate = Grid::new(&points);
        assert!(degenerate.items.is_empty());
        assert_eq!(found(&degenerate, &unit(0.0)), [0, 1]);
    }

    #[test]
    fn boxes_far_apart_share_buckets_without_false_hits() {
        let unit = |x: f64| Aabb { lo: Vector3::new(x, 0.0, 0.0), hi: Vector3::new(x + 1.0, 1.0, 1.0) };
        // 1e6 cells apart: a multiple of the 32 buckets, so both fall in the same ones.
        let boxes = [unit(0.0), unit(1e6)];
        let grid = Grid::new(&boxes);
        assert_eq!(grid.buckets[0], 32);
        assert_eq!(grid.items.len(), 2 * 2 * 2 * 2);
        assert_eq!(found(&grid, &unit(0.5)), [0]);
        assert_eq!(found(&grid, &unit(1e6 - 0.5)), [1]);
    }
}
