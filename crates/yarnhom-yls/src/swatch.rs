//! Cutting a yarn-level swatch from a periodic pattern (thesis Sec. 4.3.1).
//!
//! A reference swatch is a periodic pattern with a rest state tiled over a rectangle; the yarns
//! are cut at the border. [`cut_swatch`] builds the [`Swatch`] artifact.
//!
//! # Cutting
//!
//! The unrolled yarns of the tiled pattern form a graph. Its nodes are the pairs (pattern vertex
//! `v`, tile `T = (i, j)`), at `positions_m[v] + (i P1, j P2, 0)`; its edges follow each yarn's
//! `edge_offsets`: edge `k` of a yarn runs from `(v_k, T)` to `(v_{k+1}, T + offset_k)`. The cut
//! keeps the nodes inside the closed rectangle `[0, W] x [0, H]` of the pattern's tile
//! coordinates (tile `(0, 0)` at the origin); the tiles to enumerate follow from the rectangle
//! and the pattern's bounding box. Every node has at most one kept successor and one kept
//! predecessor, so each connected component of the kept nodes is a path: one swatch yarn, open,
//! oriented like its pattern yarn. (A component could only be a cycle if a yarn closed on itself
//! within the tiling; a valid pattern's yarns never do, as their offsets never sum to zero, so a
//! cut makes no closed yarns.) Components with fewer than `min_vertices` vertices
//! ([`DEFAULT_MIN_VERTICES`] = 4 unless given, at least 3 as a rod needs) are dropped; the
//! [`CutReport`] says how many and how much yarn length.
//!
//! The yarns are ordered by source yarn, then by the tile `(j, i)` of their first node, then by
//! the position of that node along the pattern yarn. Each copy carries the pattern's rest state:
//! per edge its rest length, reference director and twist (of the pattern edge it copies), per
//! interior vertex its rest curvature, rest twist and reference twist; the two end vertices of
//! an open yarn get zeros, as no bending element spans them.
//!
//! # Glue
//!
//! The thesis keeps the cut border from unravelling by "effectively glu\[ing\] the yarns together
//! with springs that are pre-stretched in the thickness direction"; that one sentence is all it
//! says. Our reading, with [`GlueSettings`]: every end vertex `a` of an open yarn gets one
//! spring to the nearest vertex `b` (smallest centreline distance `d`, ties to the lower index)
//! that lies on another yarn, or on the same yarn more than [`SAME_YARN_GAP`] edges away along
//! it, and is within reach, `d < reach_radii (r_a + r_b)` (default 1.5: a crossing in contact is
//! about `r_a + r_b` apart). The spring's rest length is `(1 - pre_stretch) d` (default 0.1), so
//! in the rest configuration it pulls the two yarns together through the thickness; its
//! stiffness is `stiffness_n_m`, by default the yarn's stretch stiffness
//! ([`YarnModel::stretch_stiffness_n`], `E π r²` for an elastic rod) divided by `d`, i.e. the
//! stiffness of a piece of yarn as long as the spring. A pair already glued from its other end
//! is not glued twice; an end with no vertex within reach stays free (counted in the report).

use std::collections::{HashMap, HashSet};

use yarnhom_artifacts::{
    GlueSettings, GlueSpring, Pattern, RestState, Swatch, SwatchYarn, ValidationError, YarnModel,
};

/// Pieces of yarn with fewer vertices than this are dropped by [`cut_swatch`].
pub const DEFAULT_MIN_VERTICES: usize = 4;

/// A glue partner on the cut end's own yarn must be more than this many edges away along it.
pub const SAME_YARN_GAP: usize = 3;

/// Rectangles that would make a cut look at more vertex copies than this are refused
/// ([`SwatchError::TooLarge`]): about 3 x 10^5 tiles of the largest published pattern (`rib`).
pub const MAX_COPIES: f64 = 1e8;

/// The rectangle to cut.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SwatchSize {
    /// Width and height (m): the rectangle `[0, W] x [0, H]`, cut wherever it ends (mid-tile if
    /// need be).
    Metres([f64; 2]),
    /// Whole tiles `[nx, ny]`: the rectangle `[0, nx P1] x [0, ny P2]`.
    Tiles([u32; 2]),
}

impl SwatchSize {
    /// Width and height of the rectangle (m) for tiles of `period_m`.
    pub fn metres(&self, period_m: [f64; 2]) -> [f64; 2] {
        match *self {
            SwatchSize::Metres(size) => size,
            SwatchSize::Tiles([nx, ny]) => [f64::from(nx) * period_m[0], f64::from(ny) * period_m[1]],
        }
    }
}

/// What a cut kept and dropped.
#[derive(Debug, Clone, PartialEq)]
pub struct CutReport {
    /// Yarns of the swatch.
    pub yarns: usize,
    /// Vertices of the swatch.
    pub vertices: usize,
    /// Edges of the swatch.
    pub edges: usize,
    /// Total rest length of the swatch's yarns (m).
    pub yarn_length_m: f64,
    /// Pieces of yarn dropped for having fewer than `min_vertices` vertices.
    pub dropped_pieces: usize,
    /// Vertices of the dropped pieces.
    pub dropped_vertices: usize,
    /// Total rest length of the dropped pieces (m).
    pub dropped_length_m: f64,
    /// Glue springs made.
    pub glue_springs: usize,
    /// Cut ends with no glue partner within reach (and not glued from their partner's side).
    pub unglued_ends: usize,
}

impl CutReport {
    /// A one-line human summary.
    pub fn summary(&self) -> String {
        format!(
            "{} yarns, {} vertices, {} edges, {:.1} mm of yarn; dropped {} pieces ({} vertices, {:.1} mm); {} glue springs, {} ends unglued",
            self.yarns,
            self.vertices,
            self.edges,
            self.yarn_length_m * 1e3,
            self.dropped_pieces,
            self.dropped_vertices,
            self.dropped_length_m * 1e3,
            self.glue_springs,
            self.unglued_ends,
        )
    }
}

/// Why a swatch cannot be cut.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SwatchError {
    /// The pattern has no rest state to copy.
    #[error("pattern '{0}' has no rest state; run `yarnhom rve relax` first")]
    NoRestState(String),
    /// The pattern breaks an invariant.
    #[error("invalid pattern: {0}")]
    InvalidPattern(ValidationError),
    /// The yarn model breaks an invariant.
    #[error("invalid yarn model: {0}")]
    InvalidModel(ValidationError),
    /// The glue settings are out of range.
    #[error("invalid glue settings: {0}")]
    InvalidGlue(ValidationError),
    /// A size that is not a finite positive number (or zero tiles).
    #[error("the swatch size must be finite and > 0 in both directions, got {0:?} m")]
    BadSize([f64; 2]),
    /// The rectangle is narrower or lower than one tile.
    #[error(
        "the rectangle {:.3} mm x {:.3} mm is smaller than one tile of the pattern ({:.3} mm x {:.3} mm)",
        size_m[0] * 1e3, size_m[1] * 1e3, period_m[0] * 1e3, period_m[1] * 1e3
    )]
    SmallerThanATile {
        /// The rectangle (m).
        size_m: [f64; 2],
        /// The pattern's tile (m).
        period_m: [f64; 2],
    },
    /// The rectangle holds too many tiles to enumerate.
    #[error(
        "the rectangle {:.3} m x {:.3} m holds about {copies:.2e} vertex copies, more than the {MAX_COPIES:.0e} a cut may enumerate (sizes are in metres)",
        size_m[0], size_m[1]
    )]
    TooLarge {
        /// The rectangle (m).
        size_m: [f64; 2],
        /// Vertex copies the cut would enumerate.
        copies: f64,
    },
    /// Fewer than 3 vertices per yarn asked for.
    #[error("min_vertices must be at least 3 (a rod with bending needs 3 vertices), got {0}")]
    MinVertices(usize),
    /// Every piece was too short.
    #[error(
        "no yarn piece of at least {min_vertices} vertices is left after cutting ({dropped} shorter pieces dropped)"
    )]
    NothingLeft {
        /// The minimum asked for.
        min_vertices: usize,
        /// Pieces dropped.
        dropped: usize,
    },
}

/// Cut a swatch of `size` from `pattern` (which needs a rest state), to be simulated with
/// `model`, gluing the cut ends by `glue`; pieces of fewer than [`DEFAULT_MIN_VERTICES`]
/// vertices are dropped. See the [module docs](self) for the rules.
pub fn cut_swatch(
    pattern: &Pattern,
    model: &YarnModel,
    size: SwatchSize,
    glue: GlueSettings,
) -> Result<(Swatch, CutReport), SwatchError> {
    cut_swatch_keeping(pattern, model, size, glue, DEFAULT_MIN_VERTICES)
}

/// [`cut_swatch`], dropping pieces of fewer than `min_vertices` vertices (at least 3).
pub fn cut_swatch_keeping(
    pattern: &Pattern,
    model: &YarnModel,
    size: SwatchSize,
    glue: GlueSettings,
    min_vertices: usize,
) -> Result<(Swatch, CutReport), SwatchError> {
    let rest = checked_inputs(pattern, model, &glue, min_vertices)?;
    let size_m = checked_size(size, pattern)?;
    let lattice = Lattice::new(pattern, size_m);
    let (kept, dropped): (Vec<Piece>, Vec<Piece>) =
        lattice.pieces().into_iter().partition(|p| p.nodes.len() >= min_vertices);
    if kept.is_empty() {
        return Err(SwatchError::NothingLeft { min_vertices, dropped: dropped.len() });
    }
    let mut swatch = assemble(pattern, rest, model, size_m, &kept, glue);
    let (springs, unglued_ends) = glue_springs(&swatch, &glue, model.stretch_stiffness_n());
    swatch.glue = springs;
    let report = CutReport {
        yarns: swatch.yarns.len(),
        vertices: swatch.vertex_count(),
        edges: swatch.edge_count(),
        yarn_length_m: swatch.rest_length_m.iter().fold(0.0, |a, l| a + l),
        dropped_pieces: dropped.len(),
        dropped_vertices: dropped.iter().map(|p| p.nodes.len()).sum(),
        dropped_length_m: dropped.iter().map(|p| piece_length(rest, &p.nodes)).fold(0.0, |a, l| a + l),
        glue_springs: swatch.glue.len(),
        unglued_ends,
    };
    Ok((swatch, report))
}

/// The pattern's rest state, once the pattern, model, glue settings and `min_vertices` are
/// checked.
fn checked_inputs<'a>(
    pattern: &'a Pattern,
    model: &YarnModel,
    glue: &GlueSettings,
    min_vertices: usize,
) -> Result<&'a RestState, SwatchError> {
    pattern.validate().map_err(SwatchError::InvalidPattern)?;
    model.validate().map_err(SwatchError::InvalidModel)?;
    glue.validate("glue").map_err(SwatchError::InvalidGlue)?;
    if min_vertices < 3 {
        return Err(SwatchError::MinVertices(min_vertices));
    }
    pattern.rest.as_ref().ok_or_else(|| SwatchError::NoRestState(pattern.name.clone()))
}

/// The rectangle (m), checked positive, finite, at least one tile of `pattern` in each
/// direction and at most [`MAX_COPIES`] vertex copies.
fn checked_size(size: SwatchSize, pattern: &Pattern) -> Result<[f64; 2], SwatchError> {
    let period_m = pattern.period_m;
    let size_m = size.metres(period_m);
    if !size_m.iter().all(|s| s.is_finite() && *s > 0.0) {
        return Err(SwatchError::BadSize(size_m));
    }
    if size_m[0] < period_m[0] || size_m[1] < period_m[1] {
        return Err(SwatchError::SmallerThanATile { size_m, period_m });
    }
    // The tiles enumerated: those of the rectangle and a margin of the pattern's extent.
    let tiles = |k: usize| size_m[k] / period_m[k] + 4.0;
    let copies = tiles(0) * tiles(1) * pattern.vertex_count() as f64;
    if copies > MAX_COPIES {
        return Err(SwatchError::TooLarge { size_m, copies });
    }
    Ok(size_m)
}

/// A copy of a pattern vertex in a tile.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Node {
    vertex: u32,
    tile: [i32; 2],
}

/// One connected component of the kept nodes: its pattern yarn and its nodes along the yarn.
struct Piece {
    yarn: u32,
    nodes: Vec<Node>,
}

/// The unrolled yarns of a pattern tiled over a rectangle.
struct Lattice<'a> {
    pattern: &'a Pattern,
    size_m: [f64; 2],
    /// Per pattern vertex, the vertex its edge leads to and that edge's tile offset.
    next: Vec<(u32, [i32; 2])>,
    /// Per pattern vertex, the vertex whose edge leads to it and that edge's tile offset.
    prev: Vec<(u32, [i32; 2])>,
    /// Per pattern vertex, its yarn and its position along it.
    place: Vec<(u32, u32)>,
    /// The tiles `[lo, hi]` (inclusive) along X1 and X2 whose copies may lie in the rectangle.
    tiles: [[i32; 2]; 2],
}

impl<'a> Lattice<'a> {
    fn new(pattern: &'a Pattern, size_m: [f64; 2]) -> Self {
        let n = pattern.vertex_count();
        let mut next = vec![(0, [0, 0]); n];
        let mut prev = vec![(0, [0, 0]); n];
        let mut place = vec![(0, 0); n];
        for e in pattern.edges() {
            next[e.from as usize] = (e.to, e.offset);
            prev[e.to as usize] = (e.from, e.offset);
            place[e.from as usize] = (e.yarn as u32, e.index_in_yarn as u32);
        }
        let tiles = [0, 1].map(|axis| tile_range(pattern, size_m, axis));
        Lattice { pattern, size_m, next, prev, place, tiles }
    }

    fn position(&self, node: Node) -> [f64; 3] {
        self.pattern.shifted(node.vertex, node.tile)
    }

    /// Whether the node lies in the closed rectangle.
    fn inside(&self, node: Node) -> bool {
        let x = self.position(node);
        (0.0..=self.size_m[0]).contains(&x[0]) && (0.0..=self.size_m[1]).contains(&x[1])
    }

    fn successor(&self, node: Node) -> Node {
        let (vertex, o) = self.next[node.vertex as usize];
        Node { vertex, tile: [node.tile[0] + o[0], node.tile[1] + o[1]] }
    }

    fn predecessor(&self, node: Node) -> Node {
        let (vertex, o) = self.prev[node.vertex as usize];
        Node { vertex, tile: [node.tile[0] - o[0], node.tile[1] - o[1]] }
    }

    /// Every copy of every pattern vertex in the enumerated tiles.
    fn nodes(&self) -> impl Iterator<Item = Node> + '_ {
        let [[i0, i1], [j0, j1]] = self.tiles;
        (j0..=j1).flat_map(move |j| {
            (i0..=i1).flat_map(move |i| {
                (0..self.pattern.vertex_count() as u32).map(move |vertex| Node { vertex, tile: [i, j] })
            })
        })
    }

    /// The connected components of the kept nodes, each traced from its first node (one whose
    /// predecessor is cut away) along the yarn, in the swatch's yarn order.
    fn pieces(&self) -> Vec<Piece> {
        let mut starts: Vec<Node> =
            self.nodes().filter(|&n| self.inside(n) && !self.inside(self.predecessor(n))).collect();
        starts.sort_by_key(|n| {
            let (yarn, index) = self.place[n.vertex as usize];
            (yarn, n.tile[1], n.tile[0], index)
        });
        starts.into_iter().map(|start| self.trace(start)).collect()
    }

    /// The kept nodes from `start` along the yarn until the next one is cut away.
    fn trace(&self, start: Node) -> Piece {
        let mut nodes = vec![start];
        let mut next = self.successor(start);
        while self.inside(next) {
            nodes.push(next);
            next = self.successor(next);
        }
        Piece { yarn: self.place[start.vertex as usize].0, nodes }
    }
}

/// The tiles `[lo, hi]` along `axis` whose copies of some vertex can lie in `[0, size]`:
/// `0 <= x + t P <= size` for some vertex coordinate `x` of the pattern's bounding box, widened
/// by one tile against rounding.
fn tile_range(pattern: &Pattern, size_m: [f64; 2], axis: usize) -> [i32; 2] {
    let (lo, hi) = pattern
        .positions_m
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| (lo.min(x[axis]), hi.max(x[axis])));
    let period = pattern.period_m[axis];
    [(-hi / period).ceil() as i32 - 1, ((size_m[axis] - lo) / period).floor() as i32 + 1]
}

/// Rest length of a piece's edges: the pattern's rest length of each copied edge (m).
fn piece_length(rest: &RestState, piece: &[Node]) -> f64 {
    let edges = piece.len().saturating_sub(1);
    piece[..edges].iter().map(|n| rest.edge_length_m[n.vertex as usize]).sum()
}

/// The swatch of the kept pieces (open yarns with the pattern's rest state), without glue yet.
fn assemble(
    pattern: &Pattern,
    rest: &RestState,
    model: &YarnModel,
    size_m: [f64; 2],
    pieces: &[Piece],
    glue_settings: GlueSettings,
) -> Swatch {
    let mut s = Swatch {
        name: format!("{}-{:.2}x{:.2}mm", pattern.name, size_m[0] * 1e3, size_m[1] * 1e3),
        pattern: pattern.clone(),
        model: model.clone(),
        size_m,
        positions_m: Vec::new(),
        edge_twist_rad: Vec::new(),
        source_vertex: Vec::new(),
        source_tile: Vec::new(),
        yarns: Vec::with_capacity(pieces.len()),
        rest_length_m: Vec::new(),
        reference_director: Vec::new(),
        rest_curvature: Vec::new(),
        rest_twist_rad: Vec::new(),
        reference_twist_rad: Vec::new(),
        glue: Vec::new(),
        glue_settings,
    };
    for piece in pieces {
        push_yarn(&mut s, pattern, rest, piece);
    }
    s
}

/// Append one piece as an open yarn: its vertices with their rest state (zeros at the ends),
/// then its edges.
fn push_yarn(s: &mut Swatch, pattern: &Pattern, rest: &RestState, piece: &Piece) {
    s.yarns.push(SwatchYarn {
        radius_m: pattern.yarns[piece.yarn as usize].radius_m,
        first_vertex: s.positions_m.len() as u32,
        vertex_count: piece.nodes.len() as u32,
        closed: false,
        source_yarn: piece.yarn,
    });
    let last = piece.nodes.len() - 1;
    for (k, node) in piece.nodes.iter().enumerate() {
        let v = node.vertex as usize;
        let end = k == 0 || k == last;
        s.positions_m.push(pattern.shifted(node.vertex, node.tile));
        s.source_vertex.push(node.vertex);
        s.source_tile.push(node.tile);
        s.rest_curvature.push(if end { [0.0; 2] } else { rest.vertex_curvature[v] });
        s.rest_twist_rad.push(if end { 0.0 } else { rest.vertex_twist_rad[v] });
        s.reference_twist_rad.push(if end { 0.0 } else { rest.vertex_reference_twist_rad[v] });
    }
    for node in &piece.nodes[..last] {
        let v = node.vertex as usize;
        s.edge_twist_rad.push(pattern.edge_twist_rad[v]);
        s.rest_length_m.push(rest.edge_length_m[v]);
        s.reference_director.push(rest.edge_reference_director[v]);
    }
}

/// The glue springs of the module docs' rule, and the number of ends left unglued.
fn glue_springs(s: &Swatch, settings: &GlueSettings, stretch_stiffness_n: f64) -> (Vec<GlueSpring>, usize) {
    let owner = vertex_owners(s);
    let r_max = s.yarns.iter().map(|y| y.radius_m).fold(0.0, f64::max);
    let grid = CellGrid::new(&s.positions_m, settings.reach_radii * 2.0 * r_max);
    let ends = s.yarns.iter().filter(|y| !y.closed).flat_map(|y| {
        let r = y.vertices();
        [r.start, r.end - 1]
    });
    let mut glued: HashSet<[usize; 2]> = HashSet::new();
    let mut springs = Vec::new();
    let mut unglued = 0;
    for a in ends {
        let Some((b, d)) = nearest_partner(s, &owner, &grid, settings.reach_radii, a) else {
            unglued += 1;
            continue;
        };
        if glued.insert([a.min(b), a.max(b)]) {
            springs.push(GlueSpring {
                vertices: [a as u32, b as u32],
                rest_length_m: (1.0 - settings.pre_stretch) * d,
                stiffness_n_m: settings.stiffness_n_m.unwrap_or(stretch_stiffness_n / d),
            });
        }
    }
    (springs, unglued)
}

/// Per vertex, its yarn and its index along the yarn.
fn vertex_owners(s: &Swatch) -> Vec<(usize, usize)> {
    s.yarns.iter().enumerate().flat_map(|(k, y)| (0..y.vertex_count as usize).map(move |i| (k, i))).collect()
}

/// The nearest vertex `b` to vertex `a` that may be glued to it (another yarn, or more than
/// [`SAME_YARN_GAP`] edges away on its own) within `reach_radii (r_a + r_b)`, with its distance.
fn nearest_partner(
    s: &Swatch,
    owner: &[(usize, usize)],
    grid: &CellGrid,
    reach_radii: f64,
    a: usize,
) -> Option<(usize, f64)> {
    let (yarn_a, index_a) = owner[a];
    let r_a = s.yarns[yarn_a].radius_m;
    let x = s.positions_m[a];
    grid.near(x)
        .filter(|&b| {
            let (yarn_b, index_b) = owner[b];
            yarn_b != yarn_a || index_b.abs_diff(index_a) > SAME_YARN_GAP
        })
        .map(|b| (b, distance(x, s.positions_m[b])))
        .filter(|&(b, d)| d > 0.0 && d < reach_radii * (r_a + s.yarns[owner[b].0].radius_m))
        .min_by(|p, q| p.1.total_cmp(&q.1).then(p.0.cmp(&q.0)))
}

fn distance(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// Vertices bucketed by square cells of the (X1, X2) plane, so that every vertex within `cell`
/// of a point lies in the 3 x 3 cells around it.
struct CellGrid {
    cell: f64,
    buckets: HashMap<[i64; 2], Vec<usize>>,
}

impl CellGrid {
    fn new(positions: &[[f64; 3]], cell: f64) -> Self {
        let mut grid = CellGrid { cell, buckets: HashMap::new() };
        for (i, &x) in positions.iter().enumerate() {
            grid.buckets.entry(grid.key(x)).or_default().push(i);
        }
        grid
    }

    fn key(&self, x: [f64; 3]) -> [i64; 2] {
        [(x[0] / self.cell).floor() as i64, (x[1] / self.cell).floor() as i64]
    }

    /// The vertices in the 3 x 3 cells around `x`.
    fn near(&self, x: [f64; 3]) -> impl Iterator<Item = usize> + '_ {
        let [ci, cj] = self.key(x);
        (-1..=1)
            .flat_map(move |di| (-1..=1).map(move |dj| [ci + di, cj + dj]))
            .filter_map(|k| self.buckets.get(&k))
            .flatten()
            .copied()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tiles_give_whole_periods_and_metres_pass_through() {
        let p = [0.015, 0.008];
        assert_eq!(SwatchSize::Tiles([4, 3]).metres(p), [0.06, 0.024]);
        assert_eq!(SwatchSize::Metres([0.05, 0.02]).metres(p), [0.05, 0.02]);
    }

    /// A valid one-yarn tile of `period_m`.
    fn tile(period_m: [f64; 2]) -> Pattern {
        Pattern {
            name: "line".into(),
            fabric: yarnhom_artifacts::Fabric::Woven,
            period_m,
            positions_m: vec![[0.0, 0.0, 0.0], [0.3 * period_m[0], 0.0, 1e-4], [0.6 * period_m[0], 0.0, 0.0]],
            edge_twist_rad: vec![0.0; 3],
            yarns: vec![yarnhom_artifacts::Yarn {
                radius_m: 1e-4,
                vertices: vec![0, 1, 2],
                edge_offsets: vec![[0, 0], [0, 0], [1, 0]],
            }],
            rest: None,
            origin: "test".into(),
        }
    }

    #[test]
    fn sizes_are_checked() {
        let p = tile([0.015, 0.008]);
        let check = |size| checked_size(size, &p);
        assert!(matches!(check(SwatchSize::Tiles([0, 3])), Err(SwatchError::BadSize(_))));
        assert!(matches!(check(SwatchSize::Metres([f64::NAN, 0.1])), Err(SwatchError::BadSize(_))));
        assert!(matches!(check(SwatchSize::Metres([-0.1, 0.1])), Err(SwatchError::BadSize(_))));
        assert!(matches!(
            check(SwatchSize::Metres([0.1, 0.0079])),
            Err(SwatchError::SmallerThanATile { .. })
        ));
        assert_eq!(check(SwatchSize::Tiles([1, 1])), Ok(p.period_m));
        // 100 m x 100 m: tens of millions of tiles.
        let e = check(SwatchSize::Metres([100.0, 100.0])).unwrap_err();
        assert!(matches!(e, SwatchError::TooLarge { .. }), "{e}");
        assert!(e.to_string().contains("sizes are in metres"), "{e}");
    }

    #[test]
    fn the_cell_grid_finds_every_vertex_within_a_cell() {
        let positions: Vec<[f64; 3]> =
            (0..200).map(|i| [(i as f64 * 0.37).sin() * 0.01, (i as f64 * 0.11).cos() * 0.01, 0.0]).collect();
        let grid = CellGrid::new(&positions, 0.002);
        for &x in &positions {
            let mut near: Vec<usize> = grid.near(x).collect();
            near.sort_unstable();
            let within: Vec<usize> =
                (0..positions.len()).filter(|&j| distance(x, positions[j]) < 0.002).collect();
            assert!(within.iter().all(|j| near.binary_search(j).is_ok()));
        }
    }
}
