//! The periodic yarn tile under the coarse deformations of thesis Sec. 6.5.1: a uniaxial
//! stretch `s` along a test direction `u` (the rotation `U`), a compression `c` across it, no
//! bending. The tile's equilibrium (6.9) comes from the constrained Newton solver of Ch. 3
//! ([`yarnhom_rve`]); this module adds the two ingredients the thesis names:
//!
//! - the compression of zero orthogonal stress, `∂Ψ/∂c = 0` at a given `s` (the thesis finds the
//!   energy minimum over `c` by COBYLA; here a safeguarded secant on the homogenized stress, which
//!   costs a few warm-started solves);
//! - the stretch stress `σ_s = dΨ/ds` (6.10), from the homogenized stress (3.23c) at equilibrium
//!   chained through the strain map of `F = (1 + s) u uᵀ + (1 - c) v vᵀ`.

use yarnhom_geom::MacroStrain;
use yarnhom_rve::assembly::RveState;
use yarnhom_rve::homogenize::{solve_at, stress_at_equilibrium};
use yarnhom_rve::{RveModel, SolveOptions};

use crate::data::set::Direction;
use crate::experiments::uniform::{first_form, pull_axis};

/// The in-plane strain `(sx, sa, sy)` (4.1) of a uniaxial state and its derivatives in `s` and `c`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UniaxialStrain {
    /// `(sx, sa, sy)`.
    pub strain: [f64; 3],
    /// `∂(sx, sa, sy)/∂s`.
    pub d_stretch: [f64; 3],
    /// `∂(sx, sa, sy)/∂c`.
    pub d_compression: [f64; 3],
}

impl UniaxialStrain {
    /// The tile's macro strain (no bending); `compression` names a strain that is not valid.
    pub fn macro_strain(&self, compression: f64) -> Result<MacroStrain, TileError> {
        let [sx, sa, sy] = self.strain;
        MacroStrain::new(sx, sa, sy, 0.0, 0.0).map_err(|_| TileError::BadStrain(compression))
    }

    /// `(σ_s, σ_c) = (∂Ψ/∂s, ∂Ψ/∂c)` from the homogenized stress `∂Ψ/∂(sx, sa, sy, kx, ky)`
    /// (or from its derivative by a parameter), by the chain rule through the strain map.
    pub fn stretch_and_compression(&self, stress: &[f64; 5]) -> (f64, f64) {
        let along = |d: [f64; 3]| (0..3).map(|k| stress[k] * d[k]).sum::<f64>();
        (along(self.d_stretch), along(self.d_compression))
    }
}

/// (4.1) of `I = Fᵀ F`, `F = (1 + s) u uᵀ + (1 - c) v vᵀ`, with its derivatives (closed form).
pub fn uniaxial_strain(direction: Direction, stretch: f64, compression: f64) -> UniaxialStrain {
    let u = pull_axis(direction);
    let [i11, i12, i22] = first_form(u, stretch, compression);
    let (l1, l2) = (i11.sqrt(), i22.sqrt());
    let sa = i12 / (l1 * l2);
    // ∂(sx, sa, sy)/∂(I11, I12, I22).
    let chain = |d: [f64; 3]| {
        [
            d[0] / (2.0 * l1),
            d[1] / (l1 * l2) - sa * (d[0] / (2.0 * i11) + d[2] / (2.0 * i22)),
            d[2] / (2.0 * l2),
        ]
    };
    // ∂I/∂s = 2 (1 + s) u uᵀ, ∂I/∂c = -2 (1 - c) v vᵀ.
    let (a, b) = (2.0 * (1.0 + stretch), -2.0 * (1.0 - compression));
    UniaxialStrain {
        strain: [l1 - 1.0, sa, l2 - 1.0],
        d_stretch: chain([a * u.x * u.x, a * u.x * u.y, a * u.y * u.y]),
        d_compression: chain([b * u.y * u.y, -b * u.x * u.y, b * u.x * u.x]),
    }
}

/// One solved uniaxial state of the tile.
#[derive(Debug, Clone)]
pub struct TileSample {
    /// Stretch `s`.
    pub stretch: f64,
    /// Compression `c`.
    pub compression: f64,
    /// Energy density `Ψ` (J/m², per undeformed area).
    pub energy_j_m2: f64,
    /// `σ_s = ∂Ψ/∂s` (N/m), (6.10).
    pub stretch_stress_n_m: f64,
    /// `σ_c = ∂Ψ/∂c` (N/m): zero at the compression of zero orthogonal stress.
    pub compression_stress_n_m: f64,
    /// The equilibrium, to warm-start nearby solves.
    pub state: RveState,
    /// Newton iterations taken.
    pub iterations: usize,
}

/// Why a tile state could not be found.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TileError {
    /// The equilibrium solve did not converge.
    #[error("no equilibrium at {direction} stretch {stretch:.4}, compression {compression:.4}")]
    NoEquilibrium {
        /// Direction.
        direction: Direction,
        /// Stretch.
        stretch: f64,
        /// Compression.
        compression: f64,
    },
    /// The compression search did not settle.
    #[error(
        "no compression of zero orthogonal stress found at {direction} stretch {stretch:.4} (last: c = {compression:.4}, σ_c = {stress:.3e} N/m)"
    )]
    NoZeroOrthogonalStress {
        /// Direction.
        direction: Direction,
        /// Stretch.
        stretch: f64,
        /// Last compression tried.
        compression: f64,
        /// Orthogonal stress there (N/m).
        stress: f64,
    },
    /// The strain is not valid (e.g. a compression of 100%).
    #[error("compression {0} out of range")]
    BadStrain(f64),
}

/// Solve the tile at `(s, c)` along `direction`, warm-started from `start` (cold if that fails).
pub fn solve_uniaxial(
    tile: &RveModel,
    direction: Direction,
    stretch: f64,
    compression: f64,
    start: Option<&RveState>,
) -> Result<TileSample, TileError> {
    let map = uniaxial_strain(direction, stretch, compression);
    let strain = map.macro_strain(compression)?;
    let options = if start.is_some() { SolveOptions::warm_started() } else { SolveOptions::default() };
    let (mut report, mut state) = solve_at(tile, &strain, start, &options);
    if !report.converged && start.is_some() {
        // A warm start can sit on a saddle of a slack tile: retry from the affine start with the
        // full regularization schedule.
        (report, state) = solve_at(tile, &strain, None, &SolveOptions::default());
    }
    if !report.converged {
        return Err(TileError::NoEquilibrium { direction, stretch, compression });
    }
    let (stretch_stress_n_m, compression_stress_n_m) =
        map.stretch_and_compression(&stress_at_equilibrium(tile, &strain, &state));
    Ok(TileSample {
        stretch,
        compression,
        energy_j_m2: report.energy_density_j_m2,
        stretch_stress_n_m,
        compression_stress_n_m,
        state,
        iterations: report.iterations,
    })
}

/// A compression and its orthogonal stress, if sampled.
type Sample = Option<(f64, f64)>;

/// Largest secant steps of [`zero_orthogonal_stress`].
const MAX_SECANT_STEPS: usize = 24;
/// First probe and largest step of the compression search.
const COMPRESSION_PROBE: f64 = 0.02;
const MAX_COMPRESSION_STEP: f64 = 0.15;
/// Compressions searched: `|c| <= 0.9` (a tenfold narrowing or a doubling of the width).
const COMPRESSION_LIMIT: f64 = 0.9;

/// The compression of zero orthogonal stress at stretch `s` (Sec. 6.5.1), starting the search
/// at `guess` from the equilibrium `start`: secant steps on `σ_c(c)` (at most
/// `MAX_COMPRESSION_STEP` each), regula falsi once samples of both signs bracket the root
/// (bisection where it would fall near the bracket's ends). Converged when `|σ_c|` is below 1% of the
/// stretch stress (at least of 1 N/m) or the bracket is narrower than `1e-5`.
pub fn zero_orthogonal_stress(
    tile: &RveModel,
    direction: Direction,
    stretch: f64,
    guess: f64,
    start: Option<&RveState>,
) -> Result<TileSample, TileError> {
    let converged =
        |s: &TileSample| s.compression_stress_n_m.abs() <= 1e-2 * s.stretch_stress_n_m.abs().max(1.0);
    let mut current =
        solve_uniaxial(tile, direction, stretch, guess.clamp(-COMPRESSION_LIMIT, COMPRESSION_LIMIT), start)?;
    // Samples `(c, σ_c)`: the latest with negative and with positive stress, and the one before.
    let (mut below, mut above, mut previous): (Sample, Sample, Sample) = (None, None, None);
    for _ in 0..MAX_SECANT_STEPS {
        if converged(&current) {
            return Ok(current);
        }
        let here = (current.compression, current.compression_stress_n_m);
        if here.1 < 0.0 {
            below = Some(here)
        } else {
            above = Some(here)
        }
        let next = match (below, above) {
            (Some(l), Some(h)) => {
                if (h.0 - l.0).abs() < 1e-5 {
                    return Ok(current);
                }
                let root = l.0 - l.1 * (h.0 - l.0) / (h.1 - l.1);
                let (lo, hi) = (l.0.min(h.0), l.0.max(h.0));
                // Regula falsi crawls when one end's stress is far larger (a jammed end):
                // bisect unless the root lies well inside the bracket.
                let margin = 0.1 * (hi - lo);
                if root > lo + margin && root < hi - margin { root } else { 0.5 * (lo + hi) }
            }
            _ => {
                // σ_c grows with c near the energy minimum: step against its sign.
                let slope = previous.map(|p| (here.1 - p.1) / (here.0 - p.0)).filter(|k| *k > 0.0);
                let step = slope.map_or(-COMPRESSION_PROBE * here.1.signum(), |k| -here.1 / k);
                here.0 + step.clamp(-MAX_COMPRESSION_STEP, MAX_COMPRESSION_STEP)
            }
        };
        previous = Some(here);
        current = solve_uniaxial(
            tile,
            direction,
            stretch,
            next.clamp(-COMPRESSION_LIMIT, COMPRESSION_LIMIT),
            Some(&current.state),
        )?;
    }
    Err(TileError::NoZeroOrthogonalStress {
        direction,
        stretch,
        compression: current.compression,
        stress: current.compression_stress_n_m,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_strain_map_matches_its_finite_differences() {
        let h = 1e-6;
        for direction in Direction::ALL {
            let (s, c) = (0.3, 0.12);
            let m = uniaxial_strain(direction, s, c);
            let fd = |ds: f64, dc: f64| {
                let (p, q) =
                    (uniaxial_strain(direction, s + ds, c + dc), uniaxial_strain(direction, s - ds, c - dc));
                std::array::from_fn::<f64, 3, _>(|k| (p.strain[k] - q.strain[k]) / (2.0 * h))
            };
            let (ds, dc) = (fd(h, 0.0), fd(0.0, h));
            for k in 0..3 {
                assert!((m.d_stretch[k] - ds[k]).abs() < 1e-8, "{direction} ∂s {k}: {m:?} vs {ds:?}");
                assert!((m.d_compression[k] - dc[k]).abs() < 1e-8, "{direction} ∂c {k}: {m:?} vs {dc:?}");
            }
        }
    }

    #[test]
    fn weft_and_warp_stretch_their_axes_and_bias_shears() {
        let weft = uniaxial_strain(Direction::Weft, 0.2, 0.1).strain;
        assert!((weft[0] - 0.2).abs() < 1e-12 && weft[1].abs() < 1e-12 && (weft[2] + 0.1).abs() < 1e-12);
        let warp = uniaxial_strain(Direction::Warp, 0.2, 0.1).strain;
        assert!((warp[2] - 0.2).abs() < 1e-12 && (warp[0] + 0.1).abs() < 1e-12);
        let bias = uniaxial_strain(Direction::Bias, 0.2, 0.1).strain;
        assert!((bias[0] - bias[2]).abs() < 1e-12 && bias[1] > 0.1);
    }
}
