//! Every generator makes a valid, non-interpenetrating tile with the structure its name promises.

use yarnhom_artifacts::{Fabric, Pattern};
use yarnhom_pattern::{GENERATORS, GenerateError, GeneratorParams, generate, min_inter_yarn_distance};

const KNITS: [&str; 4] = ["stockinette", "garter", "rib", "seed"];
const WEAVES: [&str; 3] = ["plain", "basket", "satin"];

fn make(name: &str, edit: impl FnOnce(&mut GeneratorParams)) -> Pattern {
    let mut p = GeneratorParams::defaults_for(name).expect("known generator");
    edit(&mut p);
    generate(name, &p).unwrap_or_else(|e| panic!("{name} {p}: {e}"))
}

/// Parameter sets every generator must handle: defaults, a tight and a loose stitch, another
/// radius and resolution.
fn variants(name: &str) -> Vec<Pattern> {
    let d = GeneratorParams::defaults_for(name).expect("known");
    vec![
        make(name, |_| {}),
        make(name, |p| p.stitch_width_m *= 1.4),
        make(name, |p| p.stitch_height_m *= 1.3),
        make(name, |p| {
            p.yarn_radius_m = 1e-4;
            p.stitch_width_m = d.stitch_width_m / 10.0;
            p.stitch_height_m = d.stitch_height_m / 10.0;
        }),
        make(name, |p| p.vertices_per_stitch *= 2),
    ]
}

#[test]
fn every_generator_is_listed_with_its_fabric() {
    let names: Vec<&str> = GENERATORS.iter().map(|g| g.name).collect();
    assert_eq!(names.len(), KNITS.len() + WEAVES.len());
    for g in GENERATORS {
        let expected = if KNITS.contains(&g.name) { Fabric::Knit } else { Fabric::Woven };
        assert_eq!(g.fabric, expected, "{}", g.name);
        assert_eq!(make(g.name, |_| {}).fabric, expected);
    }
}

#[test]
fn yarns_stay_at_least_1_9_radii_apart() {
    for g in GENERATORS {
        for p in variants(g.name) {
            let r = p.yarns[0].radius_m;
            let m = min_inter_yarn_distance(&p).expect("tiles have neighbouring yarns");
            assert!(
                m.distance_m >= 1.9 * r,
                "{}: centrelines {:.3} r apart at {m:?} ({})",
                g.name,
                m.distance_m / r,
                p.origin
            );
        }
    }
}

#[test]
fn generated_patterns_infer_their_own_fabric() {
    // The importer's knit/woven inference must agree with how we built them.
    for g in GENERATORS {
        let p = make(g.name, |_| {});
        assert_eq!(p.infer_fabric(), p.fabric, "{}", g.name);
    }
}

#[test]
fn courses_run_along_x1_and_warps_along_x2() {
    for name in KNITS {
        assert!(make(name, |_| {}).yarns.iter().all(|y| y.closure_offset() == [1, 0]), "{name}");
    }
    for name in WEAVES {
        let p = make(name, |_| {});
        let along_x1 = p.yarns.iter().filter(|y| y.closure_offset() == [1, 0]).count();
        let along_x2 = p.yarns.iter().filter(|y| y.closure_offset() == [0, 1]).count();
        assert!(along_x1 > 0 && along_x2 > 0 && along_x1 + along_x2 == p.yarns.len(), "{name}");
    }
}

fn edge_lengths(p: &Pattern) -> Vec<f64> {
    p.edges().map(|e| p.edge_vector(&e).iter().map(|c| c * c).sum::<f64>().sqrt()).collect()
}

#[test]
fn edges_are_near_uniform_and_shorter_than_the_radius_scale() {
    // Every yarn is resampled at equal arc length, so edges differ only where a chord cuts a
    // bend: a chord across an arc of angle 2x is sin(x)/x of the arc, and 1.2 allows bends down
    // to a radius of half an edge (x = 1); generated yarns bend no tighter than about a radius.
    for g in GENERATORS {
        let p = make(g.name, |_| {});
        let l = edge_lengths(&p);
        let (lo, hi) = l.iter().fold((f64::INFINITY, 0.0f64), |(a, b), &x| (a.min(x), b.max(x)));
        assert!(hi / lo < 1.2, "{}: edge lengths {lo:.2e}..{hi:.2e}", g.name);
        assert!(
            hi < 2.0 * p.yarns[0].radius_m,
            "{}: edges of {hi:.2e} m are coarse against the radius",
            g.name
        );
    }
}

/// Whether the yarn's coordinate along its run direction ever goes backwards (a loop).
fn loops_back(p: &Pattern, yarn: usize) -> bool {
    p.edges().filter(|e| e.yarn == yarn).any(|e| p.edge_vector(&e)[0] < 0.0)
}

#[test]
fn knitted_courses_form_loops_and_woven_yarns_do_not() {
    for name in KNITS {
        let p = make(name, |_| {});
        assert!((0..p.yarns.len()).all(|y| loops_back(&p, y)), "{name}: a course without loops");
    }
    for name in WEAVES {
        let p = make(name, |_| {});
        for (i, y) in p.yarns.iter().enumerate() {
            let axis = if y.closure_offset() == [1, 0] { 0 } else { 1 };
            assert!(
                p.edges().filter(|e| e.yarn == i).all(|e| p.edge_vector(&e)[axis] > 0.0),
                "{name}: yarn {i} turns back"
            );
        }
    }
}

/// Mean height of the parts of a course that lie in a wale's loop head, for each wale: where
/// the upper loops' legs pass in front (knit) the head lies behind, and vice versa.
fn head_heights(p: &Pattern, course: usize, wales: usize) -> Vec<f64> {
    let w = p.period_m[0] / wales as f64;
    let y = &p.yarns[course];
    let ys: Vec<f64> = y.vertices.iter().map(|&v| p.positions_m[v as usize][1]).collect();
    let top = ys.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
    let bottom = ys.iter().cloned().fold(f64::INFINITY, f64::min);
    (0..wales)
        .map(|j| {
            let head: Vec<f64> = y
                .vertices
                .iter()
                .map(|&v| p.positions_m[v as usize])
                .filter(|x| x[1] > top - 0.15 * (top - bottom))
                .filter(|x| ((x[0] + p.period_m[0] / 2.0) / w).floor().rem_euclid(wales as f64) as usize == j)
                .map(|x| x[2])
                .collect();
            head.iter().sum::<f64>() / head.len() as f64
        })
        .collect()
}

#[test]
fn purl_stitches_mirror_knit_stitches() {
    // Stockinette: every head lies behind the legs that pass through it (negative height).
    let stock = make("stockinette", |_| {});
    assert!(head_heights(&stock, 0, 1)[0] < 0.0);
    // Rib: the heads of the knit and the purl wale lie on opposite sides.
    let rib = make("rib", |_| {});
    let heads = head_heights(&rib, 0, 2);
    assert!(heads[0] < 0.0 && heads[1] > 0.0, "rib heads {heads:?}");
    // Garter: course 0 carries knit loops above it, course 1 purl loops: opposite sides.
    let garter = make("garter", |_| {});
    let (a, b) = (head_heights(&garter, 0, 1)[0], head_heights(&garter, 1, 1)[0]);
    assert!(a * b < 0.0, "garter heads {a} {b}");
    // Seed: a checkerboard, so each course alternates and the two courses are opposite.
    let seed = make("seed", |_| {});
    let (c0, c1) = (head_heights(&seed, 0, 2), head_heights(&seed, 1, 2));
    assert!(c0[0] * c0[1] < 0.0 && c0[0] * c1[0] < 0.0, "seed heads {c0:?} {c1:?}");
}

/// Largest distance from a vertex of `points` to the periodic polyline of yarn `yarn`.
fn distance_to_yarn(p: &Pattern, yarn: usize, points: &[[f64; 3]]) -> f64 {
    use nalgebra::Vector3;
    let segments: Vec<(Vector3<f64>, Vector3<f64>)> = p
        .edges()
        .filter(|e| e.yarn == yarn)
        .flat_map(|e| {
            let a = Vector3::from(p.positions_m[e.from as usize]);
            let b = Vector3::from(p.shifted(e.to, e.offset));
            let shift = Vector3::new(p.period_m[0], 0.0, 0.0);
            [(a - shift, b - shift), (a, b), (a + shift, b + shift)]
        })
        .collect();
    points
        .iter()
        .map(|x| {
            let x = Vector3::from(*x);
            segments
                .iter()
                .map(|(a, b)| yarnhom_geom::segment_distance(&x, &x, a, b).distance)
                .fold(f64::INFINITY, f64::min)
        })
        .fold(0.0, f64::max)
}

#[test]
fn a_purl_wale_is_a_knit_wale_mirrored() {
    // 1x1 rib: moving the course by one wale and mirroring it through the mid-plane gives the
    // same course (the knit wale becomes the purl wale and vice versa).
    let rib = make("rib", |_| {});
    let w = rib.period_m[0] / 2.0;
    let mirrored: Vec<[f64; 3]> = rib.positions_m.iter().map(|x| [x[0] + w, x[1], -x[2]]).collect();
    let r = rib.yarns[0].radius_m;
    let off = distance_to_yarn(&rib, 0, &mirrored);
    assert!(off < 0.05 * r, "mirrored rib course is {:.3} r off the course", off / r);
    // Garter: the purl course is the knit course mirrored and moved up one course.
    let garter = make("garter", |_| {});
    let h = garter.period_m[1] / 2.0;
    let knit_course: Vec<[f64; 3]> = garter.yarns[0]
        .vertices
        .iter()
        .map(|&v| garter.positions_m[v as usize])
        .map(|x| [x[0], x[1] + h, -x[2]])
        .collect();
    let off = distance_to_yarn(&garter, 1, &knit_course);
    assert!(off < 0.05 * r, "mirrored garter course is {:.3} r off the purl course", off / r);
}

#[test]
fn the_smallest_allowed_stitches_still_do_not_interpenetrate() {
    for g in GENERATORS {
        let p = make(g.name, |p| [p.stitch_width_m, p.stitch_height_m] = g.min_stitch_m(p.yarn_radius_m));
        let r = p.yarns[0].radius_m;
        let m = min_inter_yarn_distance(&p).expect("pairs");
        assert!(m.distance_m >= 1.9 * r, "{}: {:.3} r", g.name, m.distance_m / r);
        // And anything smaller is refused up front.
        let mut smaller = GeneratorParams::defaults_for(g.name).expect("known");
        smaller.stitch_width_m = 0.99 * g.min_stitch_m(smaller.yarn_radius_m)[0];
        assert!(matches!(generate(g.name, &smaller), Err(GenerateError::BadParameter(_))), "{}", g.name);
    }
}

#[test]
fn too_coarse_a_tessellation_is_refused_not_returned() {
    // Garter at its smallest stitch with the fewest vertices allowed: the chords cut the loops'
    // corners and bring yarns within 1.9 r, which the generator reports instead of returning.
    let mut p = GeneratorParams::defaults_for("garter").expect("garter");
    [p.stitch_width_m, p.stitch_height_m] = GENERATORS[1].min_stitch_m(p.yarn_radius_m);
    p.vertices_per_stitch = yarnhom_pattern::knit::MIN_VERTICES_PER_STITCH;
    match generate("garter", &p) {
        Err(GenerateError::TooClose { distance_r, .. }) => assert!(distance_r < 1.9),
        other => panic!("expected TooClose, got {other:?}"),
    }
}

#[test]
fn default_knit_stitches_are_in_proportion_to_the_published_stockinette() {
    // The published tile holds two courses (its two yarns) of two loops each.
    let Some(stock) = published("stock") else { return };
    let loops_per_course = {
        let y: Vec<f64> = stock.yarns[0].vertices.iter().map(|&v| stock.positions_m[v as usize][1]).collect();
        let n = y.len();
        // A loop's head is a local maximum of X2 along the course, well above the course's middle.
        let mid = (y.iter().cloned().fold(f64::INFINITY, f64::min)
            + y.iter().cloned().fold(f64::NEG_INFINITY, f64::max))
            / 2.0;
        (0..n).filter(|&k| y[k] > mid && y[k] >= y[(k + n - 1) % n] && y[k] > y[(k + 1) % n]).count()
    };
    assert_eq!(loops_per_course, 2);
    let published = [stock.period_m[0] / 2.0, stock.period_m[1] / stock.yarns.len() as f64];
    let d = GeneratorParams::defaults_for("stockinette").expect("stockinette");
    for (ours, theirs) in [d.stitch_width_m, d.stitch_height_m].into_iter().zip(published) {
        assert!((1.0..1.2).contains(&(ours / theirs)), "default {ours} m against published {theirs} m");
    }
}

#[test]
fn bad_parameters_are_errors_not_panics() {
    let d = GeneratorParams::defaults_for("rib").expect("rib");
    let cases = [
        GeneratorParams { yarn_radius_m: -1e-3, ..d },
        GeneratorParams { stitch_width_m: f64::NAN, ..d },
        GeneratorParams { stitch_height_m: 0.0, ..d },
        GeneratorParams { stitch_width_m: 5e-3, ..d },
        GeneratorParams { vertices_per_stitch: 2, ..d },
        GeneratorParams { vertices_per_stitch: usize::MAX, ..d },
        GeneratorParams { yarn_radius_m: f64::INFINITY, ..d },
    ];
    for c in cases {
        assert!(matches!(generate("rib", &c), Err(GenerateError::BadParameter(_))), "{c}");
    }
    assert!(matches!(generate("argyle", &d), Err(GenerateError::UnknownGenerator(_))));
    let w = GeneratorParams::defaults_for("plain").expect("plain");
    assert!(generate("plain", &GeneratorParams { stitch_width_m: 1.5e-3, ..w }).is_err());
}

fn published(name: &str) -> Option<Pattern> {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data/hylc-patterns/").to_string()
        + name
        + ".pyp";
    match std::fs::read_to_string(&path) {
        Ok(text) => {
            Some(yarnhom_artifacts::pyp::parse_pyp(&text, name, None).expect("published pattern imports"))
        }
        Err(e) => {
            println!("SKIPPED: {path}: {e}");
            None
        }
    }
}

#[test]
fn published_relaxed_patterns_have_touching_yarns() {
    // Relaxed published tiles: yarns are in contact, so the closest centrelines are about two
    // radii apart (contact forces let them sink in a little); never interpenetrating deeply.
    for name in ["stock", "rib", "honey", "satin"] {
        let Some(p) = published(name) else { continue };
        let r = p.yarns[0].radius_m;
        let m = min_inter_yarn_distance(&p).expect("pairs");
        let ratio = m.distance_m / r;
        assert!((1.0..2.5).contains(&ratio), "{name}: closest centrelines {ratio:.3} radii apart");
    }
}

mod accepted_region {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(48))]
        /// Stitches from the generator's minimum up to 2.5 times it along each axis, at the
        /// default resolution or finer, are always accepted (so never closer than 1.9 r).
        #[test]
        fn stitches_between_the_minimum_and_two_and_a_half_times_it_are_accepted(
            g in 0..GENERATORS.len(),
            fw in 1.0f64..2.5,
            fh in 1.0f64..2.5,
            finer in 1usize..3,
            r in 1e-4f64..1e-2,
        ) {
            let g = &GENERATORS[g];
            let d = GeneratorParams::defaults_for(g.name).expect("known");
            let [w, h] = g.min_stitch_m(r);
            let p = GeneratorParams {
                stitch_width_m: fw * w,
                stitch_height_m: fh * h,
                yarn_radius_m: r,
                vertices_per_stitch: finer * d.vertices_per_stitch,
            };
            let pattern = generate(g.name, &p).map_err(|e| TestCaseError::fail(e.to_string()))?;
            let m = min_inter_yarn_distance(&pattern).expect("pairs");
            prop_assert!(m.distance_m >= 1.9 * r);
        }
    }
}
