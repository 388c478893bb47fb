//! Knit tiles of a given yarn length per stitch: every knit generator reaches the target within
//! 1% at the given radius, and targets it cannot reach are errors that say why.

use yarnhom_artifacts::Pattern;
use yarnhom_pattern::{
    GENERATORS, GenerateError, GeneratorParams, StitchSpec, StitchTile, centreline_length_m, generate,
    generate_stitch, length_per_stitch_m, min_inter_yarn_distance,
};

const KNITS: [&str; 4] = ["stockinette", "garter", "rib", "seed"];

/// The authors' yarn-level stitches of the four acrylic swatches (`sabetta/stitch-by-stitch`,
/// `code/fabric_simulations/*config.dat`): pattern, stitch length, yarn radius, core radius (mm).
const ACRYLIC: [(&str, f64, f64, f64); 4] = [
    ("stockinette", 11.28, 0.74, 0.325),
    ("garter", 10.55, 0.54, 0.255),
    ("rib", 16.10, 1.18, 0.41),
    ("seed", 15.67, 1.20, 0.285),
];

fn spec(length_mm: f64, radius_mm: f64, core_mm: Option<f64>) -> StitchSpec {
    StitchSpec {
        length_m: length_mm * 1e-3,
        yarn_radius_m: radius_mm * 1e-3,
        core_radius_m: core_mm.map(|c| c * 1e-3),
        courses_per_m: None,
        wales_per_m: None,
    }
}

/// Total length of the tile's edges over the stitches, counted independently of the library:
/// the yarns' vertices in order, closed across the tile by their closure offsets.
fn measured_length_per_stitch(p: &Pattern, stitches: usize) -> f64 {
    let mut total = 0.0;
    for yarn in &p.yarns {
        let closure = yarn.closure_offset();
        let n = yarn.vertices.len();
        for k in 0..n {
            let a = p.positions_m[yarn.vertices[k] as usize];
            let mut b = p.positions_m[yarn.vertices[(k + 1) % n] as usize];
            if k + 1 == n {
                b[0] += f64::from(closure[0]) * p.period_m[0];
                b[1] += f64::from(closure[1]) * p.period_m[1];
            }
            total += ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2) + (b[2] - a[2]).powi(2)).sqrt();
        }
    }
    total / stitches as f64
}

/// Stitches of a tile, counted from its geometry: loop heads (local maxima of X2 along a course
/// in its upper part), over all courses.
fn loop_heads(p: &Pattern) -> usize {
    p.yarns
        .iter()
        .map(|y| {
            let x2: Vec<f64> = y.vertices.iter().map(|&v| p.positions_m[v as usize][1]).collect();
            let (lo, hi) =
                x2.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| (a.min(v), b.max(v)));
            let mid = 0.5 * (lo + hi);
            let n = x2.len();
            (0..n).filter(|&k| x2[k] > mid && x2[k] >= x2[(k + n - 1) % n] && x2[k] > x2[(k + 1) % n]).count()
        })
        .sum()
}

fn check(name: &str, s: &StitchSpec) -> StitchTile {
    let tile = generate_stitch(name, s).unwrap_or_else(|e| panic!("{name}: {e}"));
    let p = &tile.pattern;
    let stitches = loop_heads(p);
    let g = GENERATORS.iter().find(|g| g.name == name).expect("known");
    assert_eq!(stitches, g.stitches_per_tile(), "{name}: loop heads");
    let length = measured_length_per_stitch(p, stitches);
    assert!((length / s.length_m - 1.0).abs() < 0.01, "{name}: {length} m per stitch, target {}", s.length_m);
    assert!(
        (tile.length_per_stitch_m / length - 1.0).abs() < 1e-9,
        "{name}: reported {}",
        tile.length_per_stitch_m
    );
    assert_eq!(length_per_stitch_m(p), Some(tile.length_per_stitch_m), "{name}: from the origin");
    assert!(p.yarns.iter().all(|y| y.radius_m == s.yarn_radius_m), "{name}: radius");
    p.validate().expect("a valid pattern");
    // The loops keep 1.9 loop radii apart; the loop radius is between the core and the yarn.
    let rho = tile.params.yarn_radius_m;
    assert!(rho <= s.yarn_radius_m && rho >= s.core_radius_m.unwrap_or(s.yarn_radius_m) * (1.0 - 1e-12));
    let closest = min_inter_yarn_distance(p).expect("pairs").distance_m;
    assert!(closest >= 1.9 * rho * (1.0 - 1e-9), "{name}: {:.3} loop radii", closest / rho);
    tile
}

#[test]
fn the_authors_acrylic_stitches_are_met_within_one_percent_at_their_radius() {
    for (name, length, radius, core) in ACRYLIC {
        let tile = check(name, &spec(length, radius, Some(core)));
        // Half the yarn an incompressible yarn of that radius needs: the yarns are squashed,
        // never below their cores.
        assert!(tile.compression() < 1.0, "{name}: {}", tile.compression());
        println!(
            "{name}: target {length} mm, tile {:.4} mm per stitch ({:+.1e}); stitch {:.3} x {:.3} mm, loop radius {:.4} mm",
            tile.length_per_stitch_m * 1e3,
            tile.length_per_stitch_m * 1e3 / length - 1.0,
            tile.params.stitch_width_m * 1e3,
            tile.params.stitch_height_m * 1e3,
            tile.params.yarn_radius_m * 1e3
        );
    }
}

#[test]
fn every_knit_generator_meets_each_acrylic_stitch_it_can_hold() {
    // Another pattern's stitch: met within 1%, or refused as too short with the shortest
    // length the generator needs at that core, which is then longer than the target.
    let mut met = 0;
    for name in KNITS {
        for (own, length, radius, core) in ACRYLIC {
            let s = spec(length, radius, Some(core));
            match generate_stitch(name, &s) {
                Ok(_) => {
                    check(name, &s);
                    met += 1;
                }
                Err(e) => {
                    assert_ne!(name, own, "{e}");
                    let text = e.to_string();
                    assert!(text.contains("too short even with the yarn compressed to its core"), "{text}");
                }
            }
        }
    }
    println!("{met} of 16 pattern x stitch pairs met");
    assert!(met >= 10, "only {met} of 16 pattern x stitch pairs met");
}

#[test]
fn loose_stitches_keep_the_yarn_radius_and_the_default_aspect() {
    // 1 mm yarn, lengths from the default stitch's up to twice it: no compression.
    for name in KNITS {
        let d = GeneratorParams::defaults_for(name).expect("known");
        let default_length = default_length(name);
        for factor in [1.0, 1.3, 2.0] {
            let tile = check(name, &spec(factor * default_length * 1e3, 1.0, None));
            assert_eq!(tile.compression(), 1.0, "{name}");
            let aspect = tile.params.stitch_width_m / tile.params.stitch_height_m;
            assert!((aspect / (d.stitch_width_m / d.stitch_height_m) - 1.0).abs() < 1e-9, "{name}: {aspect}");
            // Longer yarn, larger stitch.
            assert!(tile.params.stitch_width_m >= d.stitch_width_m * (1.0 - 1e-6), "{name} x{factor}");
        }
    }
}

/// Length per stitch of a generator's default tile (m).
fn default_length(name: &str) -> f64 {
    let d = GeneratorParams::defaults_for(name).expect("known");
    let stitches = GENERATORS.iter().find(|g| g.name == name).expect("known").stitches_per_tile();
    centreline_length_m(&generate(name, &d).expect("generates")) / stitches as f64
}

#[test]
fn fixed_counts_are_kept() {
    // 1 mm yarn, 1.3 times the default length: the default course height fixed, the wale
    // adapts (stockinette); the default wale width fixed, the course adapts (rib).
    let stock = GeneratorParams::defaults_for("stockinette").expect("known");
    let base = spec(1.3 * default_length("stockinette") * 1e3, 1.0, None);
    let courses =
        check("stockinette", &StitchSpec { courses_per_m: Some(1.0 / stock.stitch_height_m), ..base });
    assert!((courses.params.stitch_height_m / stock.stitch_height_m - 1.0).abs() < 1e-12);
    assert!(courses.params.stitch_width_m > stock.stitch_width_m);
    let rib = GeneratorParams::defaults_for("rib").expect("known");
    let base = spec(1.3 * default_length("rib") * 1e3, 1.0, None);
    let wales = check("rib", &StitchSpec { wales_per_m: Some(1.0 / rib.stitch_width_m), ..base });
    assert!((wales.params.stitch_width_m / rib.stitch_width_m - 1.0).abs() < 1e-12);
    assert!(wales.params.stitch_height_m > rib.stitch_height_m);
    // Both counts fix the stitch; only the compression is free, so only a narrow range of
    // lengths is reachable. At the stitch found above for courses only, both counts give back
    // its length, uncompressed.
    let base = spec(1.3 * default_length("stockinette") * 1e3, 1.0, None);
    let both = StitchSpec {
        courses_per_m: Some(1.0 / courses.params.stitch_height_m),
        wales_per_m: Some(1.0 / courses.params.stitch_width_m),
        core_radius_m: Some(0.5e-3),
        ..base
    };
    let tile = check("stockinette", &both);
    assert!((tile.compression() - 1.0).abs() < 1e-3, "{}", tile.compression());
    // A little less yarn: the yarns are squashed to fit.
    let shorter = check("stockinette", &StitchSpec { length_m: 0.99 * both.length_m, ..both });
    assert!(shorter.compression() < 0.999, "{}", shorter.compression());
    let too_long = StitchSpec { length_m: 1.5 * both.length_m, ..both };
    let error = generate_stitch("stockinette", &too_long).expect_err("too long for the fixed stitch");
    assert!(error.to_string().contains("too long for a stitch of"), "{error}");
}

#[test]
fn unreachable_stitches_are_errors_that_say_why() {
    let stitch_error = |name: &str, s: StitchSpec| match generate_stitch(name, &s) {
        Err(e @ GenerateError::Stitch { .. }) => e.to_string(),
        other => panic!("{name} {s}: expected a stitch error, got {other:?}"),
    };
    // The authors' stockinette without its core: an incompressible 0.74 mm yarn needs twice the
    // length.
    let e = stitch_error("stockinette", spec(11.28, 0.74, None));
    assert!(e.contains("too short at this yarn radius") && e.contains("no core radius"), "{e}");
    // Shorter than even the core allows.
    let e = stitch_error("garter", spec(5.0, 0.54, Some(0.255)));
    assert!(e.contains("too short even with the yarn compressed to its core"), "{e}");
    // Bad numbers.
    for bad in [
        spec(-1.0, 0.74, None),
        spec(f64::NAN, 0.74, None),
        spec(11.0, 0.0, None),
        spec(11.0, 0.74, Some(0.8)),
        StitchSpec { courses_per_m: Some(f64::INFINITY), ..spec(40.0, 1.0, None) },
    ] {
        stitch_error("rib", bad);
    }
    // Counts too dense for the yarn.
    let dense = StitchSpec { wales_per_m: Some(1000.0), ..spec(40.0, 1.0, None) };
    assert!(stitch_error("seed", dense).contains("wale width of 1.0000 mm is too small"));
    // Weaves have no stitch.
    assert!(stitch_error("plain", spec(40.0, 1.0, None)).contains("woven"));
    assert!(matches!(
        generate_stitch("argyle", &spec(40.0, 1.0, None)),
        Err(GenerateError::UnknownGenerator(_))
    ));
}

#[test]
fn patterns_of_other_origin_have_no_known_stitch_count() {
    let d = GeneratorParams::defaults_for("seed").expect("seed");
    let mut p = generate("seed", &d).expect("generates");
    assert!(length_per_stitch_m(&p).is_some());
    p.origin = "imported from seed.pyp".into();
    assert_eq!(length_per_stitch_m(&p), None);
    let plain =
        generate("plain", &GeneratorParams::defaults_for("plain").expect("plain")).expect("generates");
    assert_eq!(length_per_stitch_m(&plain), None);
}
