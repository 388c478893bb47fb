//! Cutting swatches from the published patterns: what is kept, the rest state it carries, the
//! glue, the errors, and the artifact's round trips.

use std::collections::HashSet;

use yarnhom_artifacts::{AnyArtifact, GlueSettings, Pattern, Provenance, Swatch, YarnModel, container, pyp};
use yarnhom_yls::swatch::{CutReport, SwatchError, SwatchSize, cut_swatch, cut_swatch_keeping};

/// The published patterns; every one has a rest state.
const PATTERNS: [&str; 6] = ["stock", "rib", "honey", "basket", "satin", "stocktiniest"];

fn pattern(name: &str) -> Pattern {
    let path = format!("{}/../../../shared/data/hylc-patterns/{name}.pyp", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let p = pyp::parse_pyp(&text, name, None).expect("a valid .pyp");
    assert!(p.rest.is_some(), "{name} has a rest state");
    p
}

/// The Table 4.1 row of a pattern (`stock-small` for the 0.1 mm `stocktiniest`).
fn model(name: &str) -> YarnModel {
    let row = if name == "stocktiniest" { "stock-small" } else { name };
    YarnModel::table_4_1(row).expect("a Table 4.1 row")
}

fn cut(name: &str, size: SwatchSize) -> (Pattern, Swatch, CutReport) {
    let p = pattern(name);
    let (s, report) = cut_swatch(&p, &model(name), size, GlueSettings::default()).expect("a swatch");
    s.validate().unwrap_or_else(|e| panic!("{name}: {e}"));
    (p, s, report)
}

fn inside(x: [f64; 3], size: [f64; 2]) -> bool {
    (0.0..=size[0]).contains(&x[0]) && (0.0..=size[1]).contains(&x[1])
}

fn distance(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// Distance from a point inside the rectangle to its nearest side.
fn border_distance(x: [f64; 3], size: [f64; 2]) -> f64 {
    x[0].min(size[0] - x[0]).min(x[1]).min(size[1] - x[1])
}

/// A pattern vertex and the tile offset of the edge joining it.
type Link = (u32, [i32; 2]);

/// A side of the rectangle and the distance of a point inside to it.
type Side = (&'static str, fn([f64; 3], [f64; 2]) -> f64);

/// Per pattern vertex: the vertex its edge leads to and the edge's tile offset; and the vertex
/// whose edge leads to it, with that offset.
fn neighbours(p: &Pattern) -> (Vec<Link>, Vec<Link>) {
    let mut next = vec![(0, [0, 0]); p.vertex_count()];
    let mut prev = next.clone();
    for e in p.edges() {
        next[e.from as usize] = (e.to, e.offset);
        prev[e.to as usize] = (e.from, e.offset);
    }
    (next, prev)
}

/// The copies `(v, i, j)` of the pattern's vertices inside the rectangle, by brute force over a
/// generous range of tiles.
fn copies_inside(p: &Pattern, size: [f64; 2]) -> HashSet<(u32, [i32; 2])> {
    let reach = |k: usize| (size[k] / p.period_m[k]).ceil() as i32 + 3;
    let mut out = HashSet::new();
    for j in -3..=reach(1) {
        for i in -3..=reach(0) {
            for v in 0..p.vertex_count() as u32 {
                if inside(p.shifted(v, [i, j]), size) {
                    out.insert((v, [i, j]));
                }
            }
        }
    }
    out
}

/// Runs of consecutive copies inside the rectangle met when walking along every unrolled copy of
/// every pattern yarn from outside the rectangle to outside on the other side, as (source yarn,
/// vertices of the run). Independent of the cut's graph search: it follows the yarns.
fn runs_along_unrolled_yarns(p: &Pattern, size: [f64; 2]) -> Vec<(u32, usize)> {
    let span = [0, 1].map(|k| (size[k] / p.period_m[k]).ceil() as i32 + 4);
    let mut runs = Vec::new();
    for (y, yarn) in p.yarns.iter().enumerate() {
        let c = yarn.closure_offset();
        assert!(c[0].abs() + c[1].abs() == 1, "the walk handles yarns closing after one tile, got {c:?}");
        let (axis, other) = if c[0] != 0 { (0, 1) } else { (1, 0) };
        // Each unrolled copy passes through tile row (or column) `k` once per pass.
        for k in -3..=span[other] {
            let mut tile = [0; 2];
            tile[other] = k;
            tile[axis] = if c[axis] > 0 { -3 } else { span[axis] };
            let mut run = 0;
            let steps = (span[axis] + 4) as usize * yarn.vertices.len();
            for step in 0..steps {
                let m = step % yarn.vertices.len();
                let x = p.shifted(yarn.vertices[m], tile);
                if step == 0 {
                    assert!(!inside(x, size), "the walk starts outside");
                }
                if inside(x, size) {
                    run += 1;
                } else if run > 0 {
                    runs.push((y as u32, run));
                    run = 0;
                }
                let o = yarn.edge_offsets[m];
                tile = [tile[0] + o[0], tile[1] + o[1]];
            }
            assert_eq!(run, 0, "the walk ends outside");
        }
    }
    runs.sort_unstable();
    runs
}

/// The two end vertices of every open yarn.
fn ends(s: &Swatch) -> Vec<usize> {
    s.yarns.iter().filter(|y| !y.closed).flat_map(|y| [y.vertices().start, y.vertices().end - 1]).collect()
}

/// Per vertex, its yarn and its index along the yarn.
fn owners(s: &Swatch) -> Vec<(usize, usize)> {
    s.yarns.iter().enumerate().flat_map(|(k, y)| (0..y.vertex_count as usize).map(move |i| (k, i))).collect()
}

#[test]
fn a_cut_of_4x4_tiles_keeps_every_copy_inside_the_rectangle() {
    let (p, s, report) = cut("stock", SwatchSize::Tiles([4, 4]));
    let size = [4.0 * p.period_m[0], 4.0 * p.period_m[1]];
    assert_eq!(s.size_m, size);
    let expected = copies_inside(&p, size);
    // A rectangle of whole periods holds exactly one copy of each vertex per tile.
    assert_eq!(expected.len(), 16 * p.vertex_count());
    let kept: HashSet<(u32, [i32; 2])> =
        s.source_vertex.iter().copied().zip(s.source_tile.iter().copied()).collect();
    assert_eq!(kept.len(), s.vertex_count(), "no copy twice");
    assert!(kept.is_subset(&expected));
    assert_eq!(report.dropped_pieces, 0, "{}", report.summary());
    assert_eq!(kept, expected);
    for (k, &x) in s.positions_m.iter().enumerate() {
        assert!(inside(x, size));
        assert_eq!(x, p.shifted(s.source_vertex[k], s.source_tile[k]));
    }
}

#[test]
fn every_pattern_keeps_exactly_the_copies_inside_less_the_dropped_pieces() {
    for name in PATTERNS {
        for tiles in [[4, 4], [3, 5]] {
            let (p, s, report) = cut(name, SwatchSize::Tiles(tiles));
            let expected = copies_inside(&p, s.size_m);
            assert_eq!(expected.len(), (tiles[0] * tiles[1]) as usize * p.vertex_count(), "{name}");
            let kept: HashSet<(u32, [i32; 2])> =
                s.source_vertex.iter().copied().zip(s.source_tile.iter().copied()).collect();
            assert_eq!(kept.len(), s.vertex_count(), "{name}: no copy twice");
            assert!(kept.is_subset(&expected), "{name}");
            assert_eq!(s.vertex_count() + report.dropped_vertices, expected.len(), "{name}");
            assert_eq!(
                (report.vertices, report.edges, report.yarns),
                (s.vertex_count(), s.edge_count(), s.yarns.len())
            );
        }
    }
}

#[test]
fn yarn_pieces_match_a_walk_along_every_unrolled_yarn() {
    for name in PATTERNS {
        for size in [SwatchSize::Tiles([4, 4]), SwatchSize::Tiles([2, 3])] {
            let (p, s, report) = cut(name, size);
            let runs = runs_along_unrolled_yarns(&p, s.size_m);
            let (long, short): (Vec<_>, Vec<_>) = runs.iter().partition(|r| r.1 >= 4);
            let mut pieces: Vec<(u32, usize)> =
                s.yarns.iter().map(|y| (y.source_yarn, y.vertex_count as usize)).collect();
            pieces.sort_unstable();
            assert_eq!(pieces, long, "{name}: yarns by source yarn and length");
            assert_eq!(report.dropped_pieces, short.len(), "{name}");
            assert_eq!(report.dropped_vertices, short.iter().map(|r| r.1).sum::<usize>(), "{name}");
        }
    }
}

#[test]
fn full_courses_of_stockinette_span_the_width_uncut() {
    // Both stockinette yarns are courses closing at (1, 0). A course whose copy lies within the
    // rectangle's height is cut by the side borders only, into one yarn of 4 x 50 vertices.
    let (p, s, _) = cut("stock", SwatchSize::Tiles([4, 4]));
    let height = s.size_m[1];
    let mut uncut = 0;
    for yarn in &p.yarns {
        assert_eq!((yarn.closure_offset(), yarn.vertices.len()), ([1, 0], 50));
        // Heights along one pass of the yarn from tile row 0.
        let mut tile = [0, 0];
        let mut heights = Vec::new();
        for (&v, o) in yarn.vertices.iter().zip(&yarn.edge_offsets) {
            heights.push(p.shifted(v, tile)[1]);
            tile = [tile[0] + o[0], tile[1] + o[1]];
        }
        let lo = heights.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = heights.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        uncut += (-4..10)
            .filter(|&j| {
                let shift = f64::from(j) * p.period_m[1];
                lo + shift >= 0.0 && hi + shift <= height
            })
            .count();
    }
    let full = s.yarns.iter().filter(|y| y.vertex_count == 200).count();
    assert!(uncut > 0);
    assert_eq!(full, uncut);
    for y in s.yarns.iter().filter(|y| y.vertex_count == 200) {
        let (a, b) = (s.positions_m[y.vertices().start], s.positions_m[y.vertices().end - 1]);
        assert!(
            a[0] < p.period_m[0] && b[0] > s.size_m[0] - p.period_m[0],
            "runs from the left to the right side"
        );
    }
}

#[test]
fn kept_edges_copy_the_pattern_and_follow_its_yarns() {
    for name in PATTERNS {
        let (p, s, report) = cut(name, SwatchSize::Tiles([4, 4]));
        let rest = p.rest.as_ref().expect("rest state");
        let (next, _) = neighbours(&p);
        let mut length = 0.0;
        for (e, [a, b]) in s.edges().enumerate() {
            let (a, b) = (a as usize, b as usize);
            let v = s.source_vertex[a] as usize;
            // Oriented like the pattern yarn: b is the copy a's edge leads to.
            let (to, o) = next[v];
            let t = s.source_tile[a];
            assert_eq!((s.source_vertex[b], s.source_tile[b]), (to, [t[0] + o[0], t[1] + o[1]]), "{name}");
            assert_eq!(s.rest_length_m[e], rest.edge_length_m[v]);
            assert_eq!(s.reference_director[e], rest.edge_reference_director[v]);
            assert_eq!(s.edge_twist_rad[e], p.edge_twist_rad[v]);
            length += rest.edge_length_m[v];
        }
        assert!((report.yarn_length_m - length).abs() <= 1e-12 * length, "{name}");
        let ends: HashSet<usize> = ends(&s).into_iter().collect();
        for k in 0..s.vertex_count() {
            let v = s.source_vertex[k] as usize;
            let expected = if ends.contains(&k) {
                ([0.0; 2], 0.0, 0.0)
            } else {
                (rest.vertex_curvature[v], rest.vertex_twist_rad[v], rest.vertex_reference_twist_rad[v])
            };
            assert_eq!(
                (s.rest_curvature[k], s.rest_twist_rad[k], s.reference_twist_rad[k]),
                expected,
                "{name}"
            );
        }
        for y in &s.yarns {
            assert_eq!(y.radius_m, p.yarns[y.source_yarn as usize].radius_m);
        }
    }
}

#[test]
fn cut_yarns_are_open_and_end_within_one_edge_of_the_border() {
    for name in PATTERNS {
        let (p, s, _) = cut(name, SwatchSize::Tiles([4, 4]));
        let (next, prev) = neighbours(&p);
        for y in &s.yarns {
            assert!(!y.closed, "{name}");
            let r = y.vertices();
            let (first, last) = (r.start, r.end - 1);
            let before = prev[s.source_vertex[first] as usize];
            let after = next[s.source_vertex[last] as usize];
            // The copy before the first vertex, and after the last.
            for (k, (v, o), sign) in [(first, before, -1), (last, after, 1)] {
                let t = s.source_tile[k];
                let beyond = p.shifted(v, [t[0] + sign * o[0], t[1] + sign * o[1]]);
                let x = s.positions_m[k];
                assert!(!inside(beyond, s.size_m), "{name}: the yarn's next copy is cut away");
                assert!(border_distance(x, s.size_m) <= distance(x, beyond), "{name}: end {k}");
            }
        }
    }
}

#[test]
fn a_size_of_three_and_a_half_tiles_cuts_mid_tile() {
    let p = pattern("stock");
    let size = [3.5 * p.period_m[0], 4.0 * p.period_m[1]];
    let (s, report) =
        cut_swatch(&p, &model("stock"), SwatchSize::Metres(size), GlueSettings::default()).expect("a swatch");
    s.validate().expect("valid");
    assert_eq!(s.size_m, size);
    assert!((s.size_tiles()[0] - 3.5).abs() < 1e-12);
    let expected = copies_inside(&p, size);
    assert_eq!(s.vertex_count() + report.dropped_vertices, expected.len());
    // Between 3 and 4 copies of each vertex along X1.
    assert!(expected.len() > 12 * p.vertex_count() && expected.len() < 16 * p.vertex_count());
    let (_, whole, _) = cut("stock", SwatchSize::Tiles([4, 4]));
    assert!(s.vertex_count() < whole.vertex_count());
    // Yarns end at the new right border, which runs through the middle of tile 3.
    let right = ends(&s).into_iter().filter(|&k| size[0] - s.positions_m[k][0] < 0.5 * p.period_m[0]).count();
    assert!(right > 0);
    assert!(s.positions_m.iter().all(|x| x[0] <= size[0]));
    let runs = runs_along_unrolled_yarns(&p, size);
    assert_eq!(runs.iter().filter(|r| r.1 >= 4).count(), s.yarns.len());
}

#[test]
fn glue_joins_each_cut_end_to_its_nearest_partner_pre_stretched() {
    for name in PATTERNS {
        let (_, s, report) = cut(name, SwatchSize::Tiles([4, 4]));
        let settings = GlueSettings::default();
        assert_eq!(s.glue_settings, settings);
        let owner = owners(&s);
        let radius = |k: usize| s.yarns[owner[k].0].radius_m;
        let eligible = |a: usize, b: usize| owner[a].0 != owner[b].0 || owner[a].1.abs_diff(owner[b].1) > 3;
        let pairs: HashSet<[u32; 2]> = s.glue.iter().map(|g| g.vertices).collect();
        let mut unglued = 0;
        for a in ends(&s) {
            let nearest = (0..s.vertex_count())
                .filter(|&b| b != a && eligible(a, b))
                .map(|b| (distance(s.positions_m[a], s.positions_m[b]), b))
                .filter(|&(d, b)| d < settings.reach_radii * (radius(a) + radius(b)))
                .min_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
            match nearest {
                Some((_, b)) => {
                    let (a, b) = (a as u32, b as u32);
                    assert!(
                        pairs.contains(&[a, b]) || pairs.contains(&[b, a]),
                        "{name}: end {a} glued to {b}"
                    );
                }
                None => unglued += 1,
            }
        }
        assert_eq!(unglued, report.unglued_ends, "{name}");
        assert_eq!(pairs.len(), s.glue.len(), "{name}: no pair twice");
        let stretch = s.model.stretch_stiffness_n();
        let end_set: HashSet<usize> = ends(&s).into_iter().collect();
        for g in &s.glue {
            let [a, b] = g.vertices.map(|v| v as usize);
            assert!(end_set.contains(&a), "{name}: the first vertex is a cut end");
            let d = distance(s.positions_m[a], s.positions_m[b]);
            assert!(d < settings.reach_radii * (radius(a) + radius(b)));
            assert!((g.rest_length_m - 0.9 * d).abs() <= 1e-12 * d, "{name}: pre-stretched by 10%");
            assert!((g.stiffness_n_m - stretch / d).abs() <= 1e-12 * g.stiffness_n_m);
        }
        assert_eq!(report.glue_springs, s.glue.len());
    }
}

#[test]
fn glue_springs_hold_all_four_borders() {
    let (p, s, _) = cut("stock", SwatchSize::Tiles([4, 4]));
    let max_edge = p.edges().map(|e| {
        let d = p.edge_vector(&e);
        (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
    });
    let max_edge = max_edge.fold(0.0, f64::max);
    let glued_ends: Vec<[f64; 3]> = s.glue.iter().map(|g| s.positions_m[g.vertices[0] as usize]).collect();
    let sides: [Side; 4] = [
        ("left", |x, _| x[0]),
        ("right", |x, size| size[0] - x[0]),
        ("bottom", |x, _| x[1]),
        ("top", |x, size| size[1] - x[1]),
    ];
    for (side, distance_to) in sides {
        let n = glued_ends.iter().filter(|&&x| distance_to(x, s.size_m) <= max_edge).count();
        assert!(n > 0, "no glue spring at the {side} border");
    }
}

#[test]
fn glue_settings_choose_the_pre_stretch_and_the_stiffness() {
    let p = pattern("stock");
    let settings = GlueSettings { reach_radii: 2.0, pre_stretch: 0.25, stiffness_n_m: Some(50.0) };
    let (s, _) = cut_swatch(&p, &model("stock"), SwatchSize::Tiles([3, 3]), settings).expect("a swatch");
    s.validate().expect("valid");
    assert_eq!(s.glue_settings, settings);
    assert!(!s.glue.is_empty());
    for g in &s.glue {
        let d = distance(s.positions_m[g.vertices[0] as usize], s.positions_m[g.vertices[1] as usize]);
        assert!((g.rest_length_m - 0.75 * d).abs() <= 1e-12 * d);
        assert_eq!(g.stiffness_n_m, 50.0);
    }
    // A reach below contact (half the sum of the radii) finds no partner for any end.
    let short = GlueSettings { reach_radii: 0.5, ..GlueSettings::default() };
    let (s, report) = cut_swatch(&p, &model("stock"), SwatchSize::Tiles([3, 3]), short).expect("a swatch");
    assert!(s.glue.is_empty());
    assert_eq!(report.unglued_ends, 2 * s.yarns.len());
}

#[test]
fn yarns_are_ordered_by_source_yarn_then_tile_and_cuts_are_deterministic() {
    for name in PATTERNS {
        let (p, s, _) = cut(name, SwatchSize::Tiles([3, 3]));
        let index_in_yarn = |v: u32| {
            p.yarns.iter().find_map(|y| y.vertices.iter().position(|&w| w == v)).expect("a yarn vertex")
        };
        let keys: Vec<_> = s
            .yarns
            .iter()
            .map(|y| {
                let k = y.first_vertex as usize;
                let t = s.source_tile[k];
                (y.source_yarn, t[1], t[0], index_in_yarn(s.source_vertex[k]))
            })
            .collect();
        assert!(keys.windows(2).all(|w| w[0] < w[1]), "{name}");
        let (_, again, _) = cut(name, SwatchSize::Tiles([3, 3]));
        assert_eq!(again, s);
    }
}

#[test]
fn a_pattern_without_rest_state_is_refused() {
    let mut p = pattern("stock");
    p.rest = None;
    let e = cut_swatch(&p, &model("stock"), SwatchSize::Tiles([4, 4]), GlueSettings::default()).unwrap_err();
    assert_eq!(e, SwatchError::NoRestState("stock".into()));
    assert!(e.to_string().contains("run `yarnhom rve relax` first"), "{e}");
}

#[test]
fn bad_sizes_and_settings_are_refused() {
    let p = pattern("stock");
    let m = model("stock");
    let glue = GlueSettings::default();
    let [px, py] = p.period_m;
    let e = cut_swatch(&p, &m, SwatchSize::Metres([0.5 * px, 4.0 * py]), glue).unwrap_err();
    assert!(matches!(e, SwatchError::SmallerThanATile { .. }), "{e}");
    assert!(e.to_string().contains("smaller than one tile"), "{e}");
    let e = cut_swatch(&p, &m, SwatchSize::Metres([4.0 * px, 0.9 * py]), glue).unwrap_err();
    assert!(matches!(e, SwatchError::SmallerThanATile { .. }), "{e}");
    for size in [
        SwatchSize::Tiles([0, 4]),
        SwatchSize::Metres([-0.05, 0.05]),
        SwatchSize::Metres([f64::NAN, 0.05]),
        SwatchSize::Metres([0.05, f64::INFINITY]),
    ] {
        let e = cut_swatch(&p, &m, size, glue).unwrap_err();
        assert!(matches!(e, SwatchError::BadSize(_)), "{size:?}: {e}");
    }
    let e =
        cut_swatch(&p, &m, SwatchSize::Tiles([2, 2]), GlueSettings { pre_stretch: 1.0, ..glue }).unwrap_err();
    assert!(matches!(e, SwatchError::InvalidGlue(_)), "{e}");
    let e = cut_swatch_keeping(&p, &m, SwatchSize::Tiles([2, 2]), glue, 2).unwrap_err();
    assert_eq!(e, SwatchError::MinVertices(2));
    let e = cut_swatch_keeping(&p, &m, SwatchSize::Tiles([2, 2]), glue, 100_000).unwrap_err();
    assert!(matches!(e, SwatchError::NothingLeft { min_vertices: 100_000, .. }), "{e}");
    assert!(e.to_string().contains("no yarn piece"), "{e}");
    let mut broken = p.clone();
    broken.period_m[0] = -1.0;
    let e = cut_swatch(&broken, &m, SwatchSize::Tiles([2, 2]), glue).unwrap_err();
    assert!(matches!(e, SwatchError::InvalidPattern(_)), "{e}");
}

#[test]
fn min_vertices_decides_which_pieces_are_dropped() {
    let p = pattern("rib");
    let m = model("rib");
    let size = SwatchSize::Tiles([4, 4]);
    let (all, all_report) = cut_swatch_keeping(&p, &m, size, GlueSettings::default(), 3).expect("a swatch");
    let (some, report) = cut_swatch_keeping(&p, &m, size, GlueSettings::default(), 10).expect("a swatch");
    assert!(some.yarns.iter().all(|y| y.vertex_count >= 10));
    assert!(all.yarns.iter().any(|y| y.vertex_count < 10));
    assert_eq!(
        all.vertex_count() + all_report.dropped_vertices,
        some.vertex_count() + report.dropped_vertices
    );
    let total = |s: &Swatch, r: &CutReport| s.rest_length_m.iter().sum::<f64>() + r.dropped_length_m;
    assert!((total(&all, &all_report) - total(&some, &report)).abs() < 1e-9);
    assert!(report.dropped_length_m > 0.0);
}

#[test]
fn validate_rejects_corruptions_of_a_cut_swatch() {
    let (_, s, _) = cut("stock", SwatchSize::Tiles([2, 2]));
    type Edit = fn(&mut Swatch);
    let cases: [(Edit, &str); 7] = [
        (|s| s.yarns[1].first_vertex -= 1, "yarns[1].first_vertex"),
        (|s| s.yarns[0].vertex_count = 2, "yarns[0].vertex_count"),
        (|s| s.glue[0].vertices[1] = s.glue[0].vertices[0], "glue[0].vertices"),
        (|s| s.rest_curvature[0][1] = 0.5, "rest_curvature[0]"),
        (|s| s.rest_length_m[3] = -1.0, "rest_length_m[3]"),
        (|s| s.positions_m[5][0] = f64::NAN, "positions_m[5][0]"),
        (|s| s.edge_twist_rad.truncate(10), "edge_twist_rad"),
    ];
    for (edit, field) in cases {
        let mut bad = s.clone();
        edit(&mut bad);
        assert_eq!(bad.validate().expect_err(field).field, field);
    }
}

#[test]
fn a_swatch_round_trips_through_the_container() {
    let (_, s, _) = cut("rib", SwatchSize::Tiles([2, 2]));
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("rib.swatch.yh");
    let header = container::write(&path, &s, &Provenance::of("yls swatch", vec![])).expect("written");
    assert_eq!(header.kind, "swatch");
    let (_, back) = container::read::<Swatch>(&path).expect("read");
    assert_eq!(back, s);
    let (_, any) = AnyArtifact::read(&path).expect("read");
    assert!(any.summary().contains("of pattern 'rib'"), "{}", any.summary());
    assert_eq!(any, AnyArtifact::Swatch(s));
}

#[test]
fn a_swatch_round_trips_through_hdf5() {
    let (_, s, _) = cut("honey", SwatchSize::Tiles([2, 3]));
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("honey.swatch.h5");
    let payload = container::payload_of(&s).expect("payload");
    let header = container::header_for::<Swatch>(&payload, &Provenance::default());
    yarnhom_artifacts::hdf5::export(&path, &header, &AnyArtifact::Swatch(s.clone())).expect("exported");
    let (back_header, back) = yarnhom_artifacts::hdf5::import(&path).expect("imported");
    assert_eq!(back_header, header);
    assert_eq!(back, AnyArtifact::Swatch(s));
}

/// A swatch cut from a published rest state is nearly an equilibrium away from its border:
/// the periodic tile's rest state balances there (up to the pattern's own residual), so a step
/// without gravity moves the interior far less than the cut ends and the glue move the border;
/// and nothing crosses.
#[test]
fn a_swatch_of_a_published_rest_state_stays_put_in_its_interior() {
    use yarnhom_yls::dynamics::{Damping, Simulation};
    use yarnhom_yls::scene::scene_of_swatch;
    let (_, swatch, _) = cut("stock", SwatchSize::Tiles([5, 5]));
    let scene =
        yarnhom_yls::dynamics::Scene { damping: Some(Damping::kaldor(100.0)), ..scene_of_swatch(&swatch) };
    let mut simulation = Simulation::new(&scene).expect("a valid scene");
    let start = simulation.positions_m();
    let mut closest = f64::INFINITY;
    for _ in 0..2 {
        let report = simulation.step(1e-4).expect("steps");
        closest = closest.min(report.closest_distance_radii);
    }
    let [w, h] = swatch.size_m;
    let interior = |p: &[f64; 3]| p[0] > 0.4 * w && p[0] < 0.6 * w && p[1] > 0.4 * h && p[1] < 0.6 * h;
    let moved = |keep: &dyn Fn(&[f64; 3]) -> bool| {
        start
            .iter()
            .zip(&simulation.positions_m())
            .filter(|(p, _)| keep(p))
            .map(|(p, q)| (0..3).map(|k| (p[k] - q[k]).powi(2)).sum::<f64>().sqrt())
            .fold(0.0, f64::max)
    };
    let (inside, border) = (moved(&interior), moved(&|p| !interior(p)));
    let r = swatch.yarns[0].radius_m;
    eprintln!(
        "2 steps of 0.1 ms: interior moved {:.3} r, border {:.3} r; closest {closest:.3} r",
        inside / r,
        border / r
    );
    assert!(inside < 0.1 * border, "interior {inside} m, border {border} m");
    assert!(closest > 0.5, "closest centrelines {closest} radii");
}
