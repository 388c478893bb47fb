//! Mirror images and symmetrization of periodic tiles, on generated and published tiles.

use yarnhom_artifacts::{Pattern, pyp::parse_pyp};
use yarnhom_pattern::{GeneratorParams, MirrorAxis, find_mirror, generate, mirrored};

fn published(name: &str) -> Pattern {
    let path = format!("{}/../../../shared/data/hylc-patterns/{name}.pyp", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    parse_pyp(&text, name, None).expect("published pattern")
}

fn generated(name: &str) -> Pattern {
    generate(name, &GeneratorParams::defaults_for(name).expect("known")).expect("generates")
}

#[test]
fn generated_knits_are_their_own_mirror_images_about_the_wale_axis() {
    for name in ["stockinette", "rib", "garter", "seed"] {
        let p = generated(name);
        let m = find_mirror(&p, MirrorAxis::X1).expect("a mirror");
        let r = p.yarns[0].radius_m;
        assert!(m.max_distance_m() < 1e-9 * r, "{name}: {} m", m.max_distance_m());
        assert!(m.reversed.iter().all(|&b| b), "{name}: course yarns run backwards in the mirror");
    }
}

#[test]
fn a_plain_weave_maps_warps_forwards_and_wefts_backwards() {
    // The generated weave is symmetric about its warps' centre planes, but its weft vertices are
    // not placed symmetrically about them: vertex to vertex, the image is 0.026 radii off.
    let p = generated("plain");
    let m = find_mirror(&p, MirrorAxis::X1).expect("a mirror");
    assert!(m.max_distance_m() < 0.05 * p.yarns[0].radius_m, "{} m", m.max_distance_m());
    for (yarn, reversed) in p.yarns.iter().zip(&m.reversed) {
        let along_x1 = yarn.closure_offset()[0] != 0;
        assert_eq!(*reversed, along_x1, "{:?}", yarn.closure_offset());
    }
}

#[test]
fn the_published_stockinette_is_not_its_own_mirror_image() {
    let p = published("stock");
    let m = find_mirror(&p, MirrorAxis::X1).expect("a mirror");
    let r = p.yarns[0].radius_m;
    println!("published stock: {:.3} radii RMS, {:.3} max", m.rms_distance_m() / r, m.max_distance_m() / r);
    assert!(m.rms_distance_m() > 0.1 * r, "the published tile is asymmetric: {} m", m.rms_distance_m());
    // The image is as far from the tile as the tile from the image.
    let image = mirrored(&p, &m).expect("image");
    let back = find_mirror(&image, MirrorAxis::X1).expect("a mirror of the image");
    assert!((back.rms_distance_m() / m.rms_distance_m() - 1.0).abs() < 1e-9);
}

#[test]
fn every_published_tile_has_a_mirror_image_near_it() {
    // The published tiles all have mirror symmetries up to their relaxation's asymmetry; report
    // how far each is (the numbers in the README).
    for name in ["stock", "rib", "honey", "basket", "satin"] {
        let p = published(name);
        let r = p.yarns[0].radius_m;
        for axis in [MirrorAxis::X1, MirrorAxis::X2] {
            match find_mirror(&p, axis) {
                Ok(m) => println!(
                    "{name} {axis}: {:.3} radii RMS, {:.3} max",
                    m.rms_distance_m() / r,
                    m.max_distance_m() / r
                ),
                Err(e) => println!("{name} {axis}: {e}"),
            }
        }
    }
}
