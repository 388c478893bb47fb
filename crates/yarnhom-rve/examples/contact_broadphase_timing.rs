//! Timing of the contact search of the tile assembly: the uniform-grid broad phase
//! ([`yarnhom_rve::broadphase`]) against the brute-force search it replaced (every tile edge
//! against every edge of every contact image near the tile, with the cheap distance bound), on
//! the published stockinette and rib tiles at sx = 0.3, and the whole assembly for scale. Both
//! searches end in the same lower-bound cull; the counts printed are the pairs left for the
//! contact energy (the grid's boxes also drop pairs beyond reach that pass the bound).
//! Run: `cargo run --release -p yarnhom-rve --example contact_broadphase_timing`.

use std::time::Instant;

use nalgebra::Vector3;
use yarnhom_artifacts::{YarnModel, pyp::parse_pyp};
use yarnhom_geom::MacroStrain;
use yarnhom_pattern::min_distance::lower_bound;
use yarnhom_rve::assembly::{RveState, Want, assemble, image_segments};
use yarnhom_rve::broadphase::{Aabb, edge_pairs, tile_image};
use yarnhom_rve::{Placement, RveModel};

const DATA: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data");
const REPEATS: u32 = 200;

/// Mean seconds per call of `f` and its last result.
fn time<T>(mut f: impl FnMut() -> T) -> (f64, T) {
    let start = Instant::now();
    let mut last = f();
    for _ in 1..REPEATS {
        last = f();
    }
    (start.elapsed().as_secs_f64() / f64::from(REPEATS), last)
}

fn main() {
    println!(
        "| tile | edges x images | positions (ms) | grid search (ms) | brute force (ms) | pairs | assembly (ms) |"
    );
    println!("|---|---|---|---|---|---|---|");
    for name in ["stock", "rib"] {
        let text = std::fs::read_to_string(format!("{DATA}/hylc-patterns/{name}.pyp")).expect("pattern");
        let pattern = parse_pyp(&text, name, None).expect("imports");
        let model = RveModel::new(&pattern, &YarnModel::table_4_1(name).expect("row")).expect("tile");
        let strain: MacroStrain = "sx=0.3".parse().expect("strain");
        let placement = Placement::new(model.material.clone(), model.period_m, &strain);
        let state = RveState::affine(&model, &placement);
        let reach = model.contact.reach_m();
        let (positions, ends) = time(|| image_segments(&model, &placement, &state.g));
        let tile = &ends[tile_image(&model)];
        let culled = |a: usize, image: usize, b: usize| {
            let ((a0, a1), (b0, b1)) = (tile[a], ends[image][b]);
            lower_bound(&a0, &a1, &b0, &b1) < reach
        };
        let (grid, grid_pairs) = time(|| {
            let boxes: Vec<Vec<Aabb>> = ends
                .iter()
                .map(|e| e.iter().map(|(p, q)| Aabb::around_segment(p, q, 0.5 * reach)).collect())
                .collect();
            edge_pairs(&model, &boxes).iter().filter(|p| culled(p.a, p.image, p.b)).count()
        });
        let (brute, brute_pairs) = time(|| {
            // Images whose segments' box is beyond reach of the tile's hold no contact.
            let bounds: Vec<Aabb> = ends
                .iter()
                .map(|e| {
                    e.iter()
                        .map(|(p, q)| Aabb::around_segment(p, q, 0.0))
                        .reduce(|u, b| u.union(&b))
                        .expect("edges")
                })
                .collect();
            let tile_bounds = bounds[tile_image(&model)];
            let near: Vec<bool> = bounds
                .iter()
                .map(|b| {
                    (b.lo - tile_bounds.hi).sup(&(tile_bounds.lo - b.hi)).sup(&Vector3::zeros()).norm()
                        < reach
                })
                .collect();
            let mut count = 0;
            for a in 0..model.vertices {
                for (image, &o) in model.images.iter().enumerate().filter(|(i, _)| near[*i]) {
                    for b in 0..model.vertices {
                        if (a < b || (a == b && o > [0, 0]))
                            && culled(a, image, b)
                            && model.contact_pair(a, b, o)
                        {
                            count += 1;
                        }
                    }
                }
            }
            count
        });
        let (assembly, _) = time(|| assemble(&model, &placement, &state, &state.g, Want::Derivatives));
        println!(
            "| {name} | {} x {} | {:.3} | {:.3} | {:.3} | {grid_pairs} (brute force {brute_pairs}) | {:.3} |",
            model.vertices,
            model.images.len(),
            1e3 * positions,
            1e3 * grid,
            1e3 * brute,
            1e3 * assembly
        );
    }
}
