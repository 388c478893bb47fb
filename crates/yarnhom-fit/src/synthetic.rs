//! A synthetic grid with the thesis' plan shape, sampled from a known cloth-like energy, for
//! tests of the fit and of what consumes fits (figures, simulations): five 1D terms and the
//! nine 2D terms of Alg. 3, non-uniform sampling as in Alg. 6 / Fig. A.2 (dense towards
//! compression for `sx`, `sy`, dense around 0 for `sa`, `kx`, `ky`).

use yarnhom_artifacts::grid::strain_values;
use yarnhom_artifacts::{Grid, GridSample, GridTerm};

/// Energy of the undeformed cloth (J/m²).
pub const F0: f64 = 0.5;
/// The curled rest curvature of the synthetic `kx` response (1/m), like stockinette.
pub const KX_MIN: f64 = 40.0;
/// The plan's lower and upper limits of `(sx, sa, sy, kx, ky)`.
pub const LOWER: [f64; 5] = [-0.3, -0.75, -0.3, -200.0, -230.0];
/// See [`LOWER`].
pub const UPPER: [f64; 5] = [0.8, 0.75, 0.8, 200.0, 230.0];
/// Samples per 1D term (symmetric axes get one more so that 0 is a sample).
pub const N_1D: usize = 40;
/// Samples per axis of a 2D term (symmetric axes get one more).
pub const N_2D: usize = 12;
/// The 2D terms of Alg. 3 line 8, in its order: 12, 13, 23, 1x, 2x, 3x, 1y, 2y, 3y.
pub const PAIRS: [[u8; 2]; 9] = [[0, 1], [0, 2], [1, 2], [0, 3], [1, 3], [2, 3], [0, 4], [1, 4], [2, 4]];

/// A cloth-like homogenized energy density (J/m²) of `(sx, sa, sy, kx, ky)`: stiffening in
/// stretch and soft in compression, shear quadratic-quartic and symmetric, bending quadratic
/// with a curled minimum at `kx = 40`, a Poisson-like `sx sy` coupling and stiffening of
/// shear and bending under stretch.
pub fn energy(v: [f64; 5]) -> f64 {
    let [sx, sa, sy, kx, ky] = v;
    let (px, py) = (sx.max(0.0), sy.max(0.0));
    let stretch_x = if sx > 0.0 { 5.0 * sx * sx + 20.0 * sx.powi(4) } else { 1.5 * sx * sx };
    let stretch_y = if sy > 0.0 { 4.0 * sy * sy + 15.0 * sy.powi(4) } else { 1.0 * sy * sy };
    let shear = 2.0 * sa * sa + 6.0 * sa.powi(4);
    let bend_x = 1.2e-4 * ((kx - KX_MIN).powi(2) - KX_MIN * KX_MIN);
    let bend_y = 8e-5 * ky * ky;
    let poisson = 3.0 * px * py;
    let stretch_bend = 1.5 * px * (kx / 200.0).powi(2) + 1.2 * py * (ky / 230.0).powi(2);
    let shear_stretch = sa * sa * (px + py);
    F0 + stretch_x + stretch_y + shear + bend_x + bend_y + poisson + stretch_bend + shear_stretch
}

/// `n` values from `a` to `b`.
pub fn linspace(a: f64, b: f64, n: usize) -> Vec<f64> {
    (0..n).map(|i| a + (b - a) * i as f64 / (n - 1) as f64).collect()
}

/// Alg. 6's sampling of an axis: `sx`, `sy` as `linspace((min+1)^(1/10), (max+1)^(1/10))^10 - 1`
/// (dense towards compression), the others as `sgn(z) z²` of a linspace of `±sqrt(|limit|)`
/// (dense around 0, `n + 1` values so 0 is one). The value nearest 0 is snapped to 0 and the
/// ends are exact.
pub fn axis_values(axis: usize, n: usize) -> Vec<f64> {
    let (lo, hi) = (LOWER[axis], UPPER[axis]);
    let mut values: Vec<f64> = if axis == 0 || axis == 2 {
        linspace((lo + 1.0).powf(0.1), (hi + 1.0).powf(0.1), n)
            .into_iter()
            .map(|z| z.powi(10) - 1.0)
            .collect()
    } else {
        let n = n + 1 - n % 2;
        linspace(-(-lo).sqrt(), hi.sqrt(), n).into_iter().map(|z| z.signum() * z * z).collect()
    };
    let nearest =
        (0..values.len()).min_by(|&a, &b| values[a].abs().total_cmp(&values[b].abs())).expect("values");
    values[nearest] = 0.0;
    let last = values.len() - 1;
    (values[0], values[last]) = (lo, hi);
    assert!(values.windows(2).all(|w| w[0] < w[1]), "axis {axis}: {values:?}");
    values
}

/// A converged sample of `energy` at the plan's strain.
fn sample(grid: &Grid, term: usize, index: [u32; 2], energy: &dyn Fn([f64; 5]) -> f64) -> GridSample {
    let strain = grid.strain_at(term, index).expect("index in the plan");
    GridSample {
        term: term as u32,
        index,
        strain,
        converged: true,
        stop_reason: "converged".into(),
        energy_density_j_m2: Some(energy(strain_values(&strain))),
        stress: None,
        iterations: 1,
        positions_m: None,
        edge_twist_rad: None,
    }
}

/// The thesis' plan (five 1D terms, the nine 2D terms) sampled from `energy`, validated.
pub fn synthetic_grid_of(energy: &dyn Fn([f64; 5]) -> f64) -> Grid {
    let mut terms: Vec<GridTerm> =
        (0..5).map(|a| GridTerm { axes: vec![a as u8], values: vec![axis_values(a, N_1D)] }).collect();
    terms.extend(PAIRS.iter().map(|&[u, v]| GridTerm {
        axes: vec![u, v],
        values: vec![axis_values(u as usize, N_2D), axis_values(v as usize, N_2D)],
    }));
    let mut grid =
        Grid { pattern: "synthetic".into(), model: "analytic".into(), terms, shard: None, samples: vec![] };
    for t in 0..grid.terms.len() {
        let n: Vec<usize> = grid.terms[t].values.iter().map(Vec::len).collect();
        for i in 0..n[0] {
            for j in 0..n.get(1).copied().unwrap_or(1) {
                let s = sample(&grid, t, [i as u32, j as u32], energy);
                grid.samples.push(s);
            }
        }
    }
    grid.validate().expect("the synthetic grid is valid");
    grid
}

/// The plan sampled from [`energy`].
pub fn synthetic_grid() -> Grid {
    synthetic_grid_of(&energy)
}
