//! Mirror symmetry of a periodic tile: how far a tile is from its mirror image, and that image.
//!
//! A fabric that is symmetric under `X1 -> -X1` (or `X2 -> -X2`) answers a shear `sa` and its
//! opposite `-sa` alike (the reflection maps one onto the other and keeps `sx`, `sy`, `kx`, `ky`).
//! The published stockinette tile is close to but not exactly such a fabric (as curves, 0.10 yarn
//! radii RMS from its `X2 -> -X2` image, [`Mirror::centreline_distances_m`]), and its shear
//! response is nearly but not exactly symmetric either; the thesis symmetrizes the sampled
//! energies (Sec. 4.3.1).
//! The mirror image of a tile, rest state included, is the tile's response to the mirrored
//! strain: a test of the rod frames' conventions and of the solver's equivariance.
//!
//! The mirror `M x = R x + t` (`R` negates one in-plane coordinate) maps every yarn onto a yarn
//! with the same vertex count: a yarn whose direction of travel `R` reverses (a course yarn under
//! `X1 -> -X1`) is traversed backwards, `k -> m - k`, the others forwards, `k -> m + k`. The
//! rod data transform as follows (Bergou et al. 2010's frames, as in `yarnhom_rod::frames`): an
//! edge's reference director `d -> R d`; with the yarn traversed backwards its tangent goes to
//! `-R t` and the material frame `(m1, m2) -> (R m1, R m2)`, so twist angles and curvatures
//! `(κ1, κ2)` are kept; forwards, the tangent goes to `R t`, `(m1, m2) -> (R m1, -R m2)`, so twist
//! angles and `κ2` change sign. A reflection reverses every rotation about the tangent: rest and
//! reference twists change sign either way.

use nalgebra::Vector3;
use yarnhom_artifacts::{Pattern, RestState};
use yarnhom_geom::stats::root_mean_square;

/// The in-plane coordinate a mirror negates.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum MirrorAxis {
    /// `X1 -> -X1`: the mirror plane is parallel to X2 (a knit's wale axis).
    X1,
    /// `X2 -> -X2`: the mirror plane is parallel to X1 (a knit's course axis).
    X2,
}

impl MirrorAxis {
    fn index(self) -> usize {
        match self {
            MirrorAxis::X1 => 0,
            MirrorAxis::X2 => 1,
        }
    }

    fn reflect(self, x: Vector3<f64>) -> Vector3<f64> {
        let mut y = x;
        y[self.index()] = -y[self.index()];
        y
    }
}

impl std::fmt::Display for MirrorAxis {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            MirrorAxis::X1 => "X1 -> -X1",
            MirrorAxis::X2 => "X2 -> -X2",
        })
    }
}

/// Why a tile has no mirror image of the kind asked for.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MirrorError {
    /// No assignment of yarns to mirrored yarns of the same vertex count and direction.
    #[error("no mirror {0}: the yarns cannot be matched to mirrored yarns of the same vertex count")]
    NoMatch(MirrorAxis),
    /// A pattern without rest state whose edges are twisted: the twist angles have no reference
    /// frames to be mirrored in.
    #[error("the pattern has edge twists but no rest state (no reference frames to mirror them in)")]
    TwistWithoutFrames,
}

/// How a tile maps onto its mirror image, and how far it is from it.
#[derive(Debug, Clone, PartialEq)]
pub struct Mirror {
    /// The coordinate the mirror negates.
    pub axis: MirrorAxis,
    /// `source[v]`: the vertex whose mirror image lands nearest vertex `v`.
    pub source: Vec<u32>,
    /// Per yarn: the yarn whose mirror image it lies on.
    pub partner: Vec<usize>,
    /// Per yarn: whether the mirror traverses it backwards.
    pub reversed: Vec<bool>,
    /// The translation `t` of the mirror `x -> R x + t` (m), within half a period of 0.
    pub shift_m: [f64; 3],
    /// `residual_m[v]`: vertex `v`'s position minus the mirror image of its source (m).
    pub residual_m: Vec<[f64; 3]>,
}

impl Mirror {
    /// Root mean square distance of the vertices from their mirror images (m).
    pub fn rms_distance_m(&self) -> f64 {
        root_mean_square(self.residual_m.iter().map(|r| Vector3::from(*r).norm()))
    }

    /// The mirror as `yarnhom pattern mirror` prints it: which yarn maps onto which, the
    /// translation, and the RMS and largest distances of the vertices and of the centrelines
    /// from their images, in mm and in radii of the thinnest yarn.
    pub fn report(&self, pattern: &Pattern) -> String {
        let (r_lo, _) = pattern.radius_range_m();
        let mut lines = vec![format!(
            "mirror {} of {} ({} yarn(s), {} vertices)",
            self.axis,
            pattern.name,
            pattern.yarns.len(),
            pattern.vertex_count()
        )];
        for (y, (partner, reversed)) in self.partner.iter().zip(&self.reversed).enumerate() {
            let way = if *reversed { "backwards" } else { "forwards" };
            lines.push(format!("  yarn {y} <- yarn {partner}, {way}"));
        }
        let t = self.shift_m;
        lines.push(format!("  translation ({:.4}, {:.4}, {:.4}) mm", t[0] * 1e3, t[1] * 1e3, t[2] * 1e3));
        let distances = |rms: f64, max: f64| {
            format!(
                "{:.4} mm RMS ({:.3} radii), {:.4} mm at most ({:.3} radii)",
                rms * 1e3,
                rms / r_lo,
                max * 1e3,
                max / r_lo
            )
        };
        lines.push(format!(
            "  vertices from their images: {}",
            distances(self.rms_distance_m(), self.max_distance_m())
        ));
        let curves = self.centreline_distances_m(pattern);
        let (rms, max) =
            (root_mean_square(curves.iter().copied()), curves.iter().copied().fold(0.0, f64::max));
        lines.push(format!(
            "  centrelines from their images (shapes only, vertex spacing aside): {}",
            distances(rms, max)
        ));
        lines.join("\n")
    }

    /// Largest distance of a vertex from its mirror image (m).
    pub fn max_distance_m(&self) -> f64 {
        self.residual_m.iter().map(|r| Vector3::from(*r).norm()).fold(0.0, f64::max)
    }

    /// Distance of every vertex of `pattern` (the tile this mirror was found on) from the mirror
    /// image of its partner yarn's centreline: the nearest point of the image polyline around its
    /// source, with the mirror's translation refined for these distances (a translation-only
    /// point-to-curve alignment) (m). Unlike [`Mirror::residual_m`] this compares shapes only:
    /// two tiles whose yarns follow the same curves with vertices spaced differently along them
    /// are 0 apart.
    pub fn centreline_distances_m(&self, pattern: &Pattern) -> Vec<f64> {
        let mut place = vec![(0, 0); pattern.vertex_count()];
        for (y, yarn) in pattern.yarns.iter().enumerate() {
            for (k, &v) in yarn.vertices.iter().enumerate() {
                place[v as usize] = (y, k as i64);
            }
        }
        let yarns: Vec<Unwrapped> = (0..pattern.yarns.len()).map(|y| Unwrapped::of(pattern, y)).collect();
        // Each vertex minus its nearest point on the image centreline moved by `offset`.
        let residuals = |offset: Vector3<f64>| -> Vec<Vector3<f64>> {
            (0..pattern.vertex_count())
                .map(|v| {
                    let x = Vector3::from(pattern.positions_m[v]);
                    let image_of_source = x - Vector3::from(self.residual_m[v]) + offset;
                    let (partner, k) = place[self.source[v] as usize];
                    let w = &yarns[partner];
                    let image = |j: i64| image_of_source + self.axis.reflect(w.at(j) - w.at(k));
                    (k - IMAGE_NEIGHBOURHOOD..k + IMAGE_NEIGHBOURHOOD)
                        .map(|j| x - nearest_on_segment(x, image(j), image(j + 1)))
                        .min_by(|a, b| a.norm_squared().total_cmp(&b.norm_squared()))
                        .expect("a non-empty neighbourhood")
                })
                .collect()
        };
        let mut offset = Vector3::zeros();
        for _ in 0..ALIGNMENT_ITERATIONS {
            let step = mean(residuals(offset).into_iter());
            offset += step;
            if step.norm() < ALIGNMENT_TOLERANCE * pattern.radius_range_m().0 {
                break;
            }
        }
        residuals(offset).iter().map(Vector3::norm).collect()
    }
}

/// Edges on either side of a vertex's source searched for the nearest point of the image
/// centreline in [`Mirror::centreline_distances_m`].
const IMAGE_NEIGHBOURHOOD: i64 = 3;

/// Iteration limit and step tolerance (in yarn radii) of the translation refinement in
/// [`Mirror::centreline_distances_m`].
const ALIGNMENT_ITERATIONS: usize = 200;
const ALIGNMENT_TOLERANCE: f64 = 1e-9;

/// The point of the segment `a b` nearest `x`.
fn nearest_on_segment(x: Vector3<f64>, a: Vector3<f64>, b: Vector3<f64>) -> Vector3<f64> {
    let ab = b - a;
    let t = ((x - a).dot(&ab) / ab.norm_squared().max(f64::MIN_POSITIVE)).clamp(0.0, 1.0);
    a + ab * t
}

/// One yarn's centreline unwrapped across tile boundaries, extended periodically.
struct Unwrapped {
    points: Vec<Vector3<f64>>,
    /// Where the yarn re-enters itself: `closure_offset * period`.
    closure: Vector3<f64>,
    closure_offset: [i32; 2],
}

impl Unwrapped {
    fn of(pattern: &Pattern, yarn: usize) -> Self {
        let y = &pattern.yarns[yarn];
        let mut points = Vec::with_capacity(y.vertices.len());
        let mut at = Vector3::from(pattern.positions_m[y.vertices[0] as usize]);
        for e in pattern.edges().filter(|e| e.yarn == yarn) {
            points.push(at);
            at += Vector3::from(pattern.edge_vector(&e));
        }
        let c = y.closure_offset();
        let closure =
            Vector3::new(f64::from(c[0]) * pattern.period_m[0], f64::from(c[1]) * pattern.period_m[1], 0.0);
        Unwrapped { points, closure, closure_offset: c }
    }

    /// Point `j` of the periodically extended yarn (`j` may be negative or beyond `n`).
    fn at(&self, j: i64) -> Vector3<f64> {
        let n = self.points.len() as i64;
        self.points[j.rem_euclid(n) as usize] + self.closure * j.div_euclid(n) as f64
    }
}

/// Yarn `b` as the mirror image of yarn `a`: which way it runs and from where.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Match {
    partner: usize,
    reversed: bool,
    start: i64,
}

impl Match {
    /// Index along the partner yarn of the mirror source of point `k` of this yarn.
    fn source_index(self, k: i64) -> i64 {
        if self.reversed { self.start - k } else { self.start + k }
    }
}

/// Differences `u_k - R w_source(k)` of yarn `a` against its partner.
fn differences<'a>(
    axis: MirrorAxis,
    a: &'a Unwrapped,
    b: &'a Unwrapped,
    m: Match,
) -> impl Iterator<Item = Vector3<f64>> + 'a {
    (0..a.points.len() as i64).map(move |k| a.at(k) - axis.reflect(b.at(m.source_index(k))))
}

fn mean(v: impl Iterator<Item = Vector3<f64>>) -> Vector3<f64> {
    let (sum, count) = v.fold((Vector3::zeros(), 0usize), |(s, c), x| (s + x, c + 1));
    sum / count.max(1) as f64
}

/// The whole-period translation closest to `x` (in-plane).
fn nearest_lattice(x: Vector3<f64>, period: [f64; 2]) -> Vector3<f64> {
    Vector3::new((x[0] / period[0]).round() * period[0], (x[1] / period[1]).round() * period[1], 0.0)
}

/// Sum of squared residuals of yarn `a` against its partner under the common shift `t`, with
/// the yarn's own whole-period offset.
fn squared_residual(
    axis: MirrorAxis,
    a: &Unwrapped,
    b: &Unwrapped,
    m: Match,
    t: Vector3<f64>,
    period: [f64; 2],
) -> f64 {
    let lattice = nearest_lattice(mean(differences(axis, a, b, m)) - t, period);
    differences(axis, a, b, m).map(|d| (d - t - lattice).norm_squared()).sum()
}

/// Every way yarn `b` can be the mirror image of yarn `a`.
fn candidate_matches(axis: MirrorAxis, a: &Unwrapped, b: &Unwrapped, partner: usize) -> Vec<Match> {
    if a.points.len() != b.points.len() {
        return vec![];
    }
    let mut reflected = b.closure_offset;
    reflected[axis.index()] = -reflected[axis.index()];
    let reversed = match (reflected == a.closure_offset, reflected.map(|c| -c) == a.closure_offset) {
        (true, _) => false,
        (false, true) => true,
        (false, false) => return vec![],
    };
    (0..a.points.len() as i64).map(|start| Match { partner, reversed, start }).collect()
}

/// The best partner of every yarn under the shift `t`, if the partners form a permutation, and
/// the total squared residual.
fn matches_under_shift(
    axis: MirrorAxis,
    yarns: &[Unwrapped],
    t: Vector3<f64>,
    period: [f64; 2],
) -> Option<(Vec<Match>, f64)> {
    let mut total = 0.0;
    let mut out = Vec::with_capacity(yarns.len());
    for a in yarns {
        let (best, residual) = (0..yarns.len())
            .flat_map(|b| candidate_matches(axis, a, &yarns[b], b))
            .map(|m| (m, squared_residual(axis, a, &yarns[m.partner], m, t, period)))
            .min_by(|x, y| x.1.total_cmp(&y.1))?;
        total += residual;
        out.push(best);
    }
    let mut used = vec![false; yarns.len()];
    for m in &out {
        if std::mem::replace(&mut used[m.partner], true) {
            return None;
        }
    }
    Some((out, total))
}

/// The mirror image about `axis` closest to the tile: every candidate for the first yarn fixes
/// the translation, every other yarn takes its best partner under it, and the assignment with the
/// smallest squared distance wins. `O(Y³ n³)` for `Y` yarns of `n` vertices, instant for the
/// published tiles.
pub fn find_mirror(pattern: &Pattern, axis: MirrorAxis) -> Result<Mirror, MirrorError> {
    let yarns: Vec<Unwrapped> = (0..pattern.yarns.len()).map(|y| Unwrapped::of(pattern, y)).collect();
    let period = pattern.period_m;
    let first = yarns.first().ok_or(MirrorError::NoMatch(axis))?;
    let (matches, _) = (0..yarns.len())
        .flat_map(|b| candidate_matches(axis, first, &yarns[b], b))
        .filter_map(|m| {
            matches_under_shift(axis, &yarns, mean(differences(axis, first, &yarns[m.partner], m)), period)
        })
        .min_by(|x, y| x.1.total_cmp(&y.1))
        .ok_or(MirrorError::NoMatch(axis))?;
    // The common shift: the mean difference over every vertex, each yarn's brought to the
    // first's period.
    let reference = mean(differences(axis, first, &yarns[matches[0].partner], matches[0]));
    let per_yarn: Vec<Vector3<f64>> = yarns
        .iter()
        .zip(&matches)
        .map(|(a, &m)| {
            let d = mean(differences(axis, a, &yarns[m.partner], m));
            (d - nearest_lattice(d - reference, period)) * a.points.len() as f64
        })
        .collect();
    let shift = per_yarn.iter().sum::<Vector3<f64>>() / pattern.vertex_count() as f64;
    let shift = shift - nearest_lattice(shift, period);
    let mut source = vec![0u32; pattern.vertex_count()];
    let mut residual = vec![[0.0; 3]; pattern.vertex_count()];
    for (y, (a, &m)) in yarns.iter().zip(&matches).enumerate() {
        let partner = &pattern.yarns[m.partner].vertices;
        let lattice = nearest_lattice(mean(differences(axis, a, &yarns[m.partner], m)) - shift, period);
        for (k, d) in differences(axis, a, &yarns[m.partner], m).enumerate() {
            let v = pattern.yarns[y].vertices[k] as usize;
            source[v] = partner[m.source_index(k as i64).rem_euclid(partner.len() as i64) as usize];
            residual[v] = (d - shift - lattice).into();
        }
    }
    Ok(Mirror {
        axis,
        source,
        partner: matches.iter().map(|m| m.partner).collect(),
        reversed: matches.iter().map(|m| m.reversed).collect(),
        shift_m: shift.into(),
        residual_m: residual,
    })
}

/// The mirror image of the tile under `mirror` (found by [`find_mirror`] on this tile), as a
/// pattern with the tile's vertices and yarns: vertex `v` at the image of its source, each edge
/// carrying the rest length, frame and twist of the edge it is the image of (edge offsets
/// changed by the whole periods between the images of neighbouring vertices).
pub fn mirrored(pattern: &Pattern, mirror: &Mirror) -> Result<Pattern, MirrorError> {
    let mut out = pattern.clone();
    // Vertex `v` at the exact image of its source; `whole[v]`: the whole periods between that
    // image and the point `v - residual` that continues the tile's yarn, taken out of the
    // edge offsets so that every edge of the image is the image of an edge.
    let period = pattern.period_m;
    let whole: Vec<[i32; 2]> = (0..pattern.vertex_count())
        .map(|v| {
            let image = mirror.axis.reflect(Vector3::from(pattern.positions_m[mirror.source[v] as usize]))
                + Vector3::from(mirror.shift_m);
            let along_yarn = Vector3::from(pattern.positions_m[v]) - Vector3::from(mirror.residual_m[v]);
            let lattice = nearest_lattice(image - along_yarn, period);
            out.positions_m[v] = image.into();
            [(lattice[0] / period[0]).round() as i32, (lattice[1] / period[1]).round() as i32]
        })
        .collect();
    for (y, yarn) in out.yarns.iter_mut().enumerate() {
        let n = yarn.vertices.len();
        for k in 0..n {
            let (from, to) = (yarn.vertices[k] as usize, yarn.vertices[(k + 1) % n] as usize);
            let o = &mut yarn.edge_offsets[k];
            *o = [o[0] + whole[from][0] - whole[to][0], o[1] + whole[from][1] - whole[to][1]];
        }
        debug_assert_eq!(yarn.closure_offset(), pattern.yarns[y].closure_offset());
    }
    let mut reversed_at = vec![false; pattern.vertex_count()];
    for (yarn, reversed) in pattern.yarns.iter().zip(&mirror.reversed) {
        yarn.vertices.iter().for_each(|&v| reversed_at[v as usize] = *reversed);
    }
    // The edge leaving `v` is the image of the edge leaving `source[v]` (forwards) or of the one
    // arriving at `source[v]`, i.e. leaving `source[next(v)]` (backwards).
    let mut edge_source = vec![0u32; pattern.vertex_count()];
    for e in pattern.edges() {
        let backwards = mirror.reversed[e.yarn];
        edge_source[e.from as usize] = mirror.source[if backwards { e.to } else { e.from } as usize];
    }
    // Twist angles and κ2 keep their sign on yarns the mirror reverses, and change it on others.
    let sign = |v: u32| if reversed_at[v as usize] { 1.0 } else { -1.0 };
    let edge_twists: Vec<f64> = (0..pattern.vertex_count() as u32)
        .map(|v| sign(v) * pattern.edge_twist_rad[edge_source[v as usize] as usize])
        .collect();
    match &pattern.rest {
        None if pattern.edge_twist_rad.iter().any(|t| *t != 0.0) => {
            return Err(MirrorError::TwistWithoutFrames);
        }
        None => {}
        Some(rest) => {
            let by_edge = |v: u32| edge_source[v as usize] as usize;
            let by_vertex = |v: u32| mirror.source[v as usize] as usize;
            let reflect = |d: [f64; 3]| mirror.axis.reflect(Vector3::from(d)).into();
            let n = pattern.vertex_count() as u32;
            out.edge_twist_rad = edge_twists;
            out.rest = Some(RestState {
                edge_length_m: (0..n).map(|v| rest.edge_length_m[by_edge(v)]).collect(),
                vertex_curvature: (0..n)
                    .map(|v| {
                        let [k1, k2] = rest.vertex_curvature[by_vertex(v)];
                        [k1, sign(v) * k2]
                    })
                    .collect(),
                vertex_twist_rad: (0..n).map(|v| -rest.vertex_twist_rad[by_vertex(v)]).collect(),
                edge_reference_director: (0..n)
                    .map(|v| reflect(rest.edge_reference_director[by_edge(v)]))
                    .collect(),
                vertex_reference_twist_rad: (0..n)
                    .map(|v| -rest.vertex_reference_twist_rad[by_vertex(v)])
                    .collect(),
            });
        }
    }
    out.origin = format!("{}; mirrored {}", pattern.origin, mirror.axis);
    Ok(out)
}
