//! Woven tiles: weft yarns run along X1, warp yarns along X2, and at every crossing one passes
//! over the other as the weave's interlacing chart says. Yarns are straight in plan view; their
//! height follows `curve::undulate` through the crossings, so crossing centrelines are
//! `2 * LEVEL_R = 3 r` apart and level where they meet.

use yarnhom_artifacts::{Fabric, Pattern};

use crate::curve::{LEVEL_R, PLATEAU, resample, undulate};
use crate::{GenerateError, GeneratorParams, add_yarn, generated};

/// Smallest spacing of parallel yarns, in radii. Two limits meet here: where a weft and a warp
/// both change sides next to the same crossing, their mid-points (both at mid-plane height) are
/// `spacing / sqrt(2)` apart in plan; and a yarn passing under one crossing yarn and over the
/// next must climb `2 * LEVEL_R` between them. At 2.9 r all three weaves keep 1.9 r (2.9 r gives
/// 1.91-1.94 r, 3.0 r gives 1.97-1.99 r; the published jammed tiles are 2.2-2.7 r).
pub const MIN_SPACING_R: f64 = 2.9;
/// Fewest vertices per yarn spacing: a crossing's level stretch and the climb to the next.
pub const MIN_VERTICES_PER_SPACING: usize = 4;
/// Plan-view samples per yarn spacing before resampling to equal arc length.
const SAMPLES_PER_SPACING: usize = 64;

/// Build a woven tile from its interlacing chart: `warp_over[weft][warp]` is true where the warp
/// passes over the weft. Weft `j` lies at X2 = `(j + 1/2) * stitch_height_m`, warp `i` at
/// X1 = `(i + 1/2) * stitch_width_m`.
pub(crate) fn weave(
    name: &str,
    warp_over: &[&[bool]],
    p: &GeneratorParams,
) -> Result<Pattern, GenerateError> {
    let r = p.yarn_radius_m;
    p.require_stitch(MIN_SPACING_R * r, MIN_SPACING_R * r, MIN_VERTICES_PER_SPACING)?;
    let (wefts, warps) = (warp_over.len(), warp_over[0].len());
    let period = [warps as f64 * p.stitch_width_m, wefts as f64 * p.stitch_height_m];
    let centre = |k: usize, spacing: f64, period: f64| (k as f64 + 0.5) * spacing - period / 2.0;
    let mut positions = Vec::new();
    let mut yarns = Vec::new();
    for (j, row) in warp_over.iter().enumerate() {
        let y = centre(j, p.stitch_height_m, period[1]);
        let levels: Vec<(f64, f64)> = row
            .iter()
            .enumerate()
            .map(|(i, &over)| (centre(i, p.stitch_width_m, 0.0), if over { -1.0 } else { 1.0 }))
            .collect();
        let path = straight_yarn(&levels, period[0], warps * p.vertices_per_stitch, r);
        yarns.push(add_yarn(
            &mut positions,
            path.iter().map(|&(x, z)| [x - period[0] / 2.0, y, z]),
            [1, 0],
            r,
        ));
    }
    for i in 0..warps {
        let x = centre(i, p.stitch_width_m, period[0]);
        let levels: Vec<(f64, f64)> = warp_over
            .iter()
            .enumerate()
            .map(|(j, row)| (centre(j, p.stitch_height_m, 0.0), if row[i] { 1.0 } else { -1.0 }))
            .collect();
        let path = straight_yarn(&levels, period[1], wefts * p.vertices_per_stitch, r);
        yarns.push(add_yarn(
            &mut positions,
            path.iter().map(|&(y, z)| [x, y - period[1] / 2.0, z]),
            [0, 1],
            r,
        ));
    }
    Ok(generated(name, Fabric::Woven, period, positions, yarns, p))
}

/// `(position along the yarn, height)` at `n` points equally spaced in arc length along a
/// straight yarn of period `length` through crossings at `levels`.
fn straight_yarn(levels: &[(f64, f64)], length: f64, n: usize, r: f64) -> Vec<(f64, f64)> {
    let dense = n * SAMPLES_PER_SPACING;
    let along: Vec<f64> = (0..dense).map(|k| (k as f64 + 0.5) * length / dense as f64).collect();
    let z = undulate(&along, length, levels, LEVEL_R * r, PLATEAU);
    let curve: Vec<[f64; 3]> = along.into_iter().zip(z).map(|(s, z)| [s, 0.0, z]).collect();
    resample(&curve, [length, 0.0, 0.0], n).into_iter().map(|p| (p[0], p[2])).collect()
}
