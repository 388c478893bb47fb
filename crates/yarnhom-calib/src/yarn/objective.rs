//! The objective of the yarn-level estimation (thesis Sec. 6.5.3, (6.11)): the uniform targets
//! `{s, c, σ_s}` of the fitted shell against the periodic yarn tile under the same stretches.
//!
//! - Stretch errors are in the second Piola-Kirchhoff stress `σ_s / (1 + s)`, compression errors
//!   in `c`; each normalized by its largest target in the comfort range (stretches whose clamp
//!   force stays under 2 N, Sec. 6.2.3) and weighted by `v_comfort / max(v_comfort, v_target)`,
//!   which is 1 in the comfort range and decays beyond it.
//! - The tile's compression of zero orthogonal stress is found at both ends of the stretch range
//!   and linearly interpolated in between, as the thesis does (it also smooths the buckling noise
//!   near the optimal compression).
//! - Compressions are normalized by at least [`COMPRESSION_FLOOR`]: a fabric that barely narrows
//!   in the comfort range (the stockinette's weft: 0.3% at 2 N) would otherwise turn measurement
//!   noise into a dominant error.

use rayon::prelude::*;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use yarnhom_rve::RveModel;
use yarnhom_rve::assembly::RveState;
use yarnhom_rve::homogenize::stress_sensitivities;
use yarnhom_shell::StvkNeoHookean;

use super::tile::{TileError, TileSample, solve_uniaxial, uniaxial_strain, zero_orthogonal_stress};
use crate::data::set::Direction;
use crate::experiments::uniform::uniaxial;

/// Smallest normalization of compression errors.
pub const COMPRESSION_FLOOR: f64 = 0.02;

/// The clamp force bounding the comfort range (N, Sec. 6.2.3).
pub const COMFORT_FORCE_N: f64 = 2.0;

/// The uniform targets of one direction.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct DirectionTargets {
    /// Direction.
    pub direction: Direction,
    /// Largest stretch of the comfort range.
    pub comfort_stretch: f64,
    /// Target stretches (increasing).
    pub stretch: Vec<f64>,
    /// Target compressions.
    pub compression: Vec<f64>,
    /// Target stretch stresses `σ_s` (N/m).
    pub stress_n_m: Vec<f64>,
    /// `v_comfort` of the stretch errors: the second Piola-Kirchhoff stress at the comfort
    /// stretch (N/m); also their normalization.
    pub comfort_stress_n_m: f64,
    /// `v_comfort` of the compression errors.
    pub comfort_compression: f64,
}

impl DirectionTargets {
    /// `n` targets of the shell `material` along `direction`, evenly up to `max_stretch`; the
    /// comfort range ends where the clamp force `σ_s w` of a swatch of width `width_m` reaches
    /// `comfort_force_n`.
    pub fn of_shell(
        material: &StvkNeoHookean,
        direction: Direction,
        max_stretch: f64,
        width_m: f64,
        n: usize,
        comfort_force_n: f64,
    ) -> Self {
        let force = |s: f64| uniaxial(material, direction, s).stress_n_m * width_m;
        let comfort_stretch = if force(max_stretch) <= comfort_force_n {
            max_stretch
        } else {
            let (mut lo, mut hi) = (0.0, max_stretch);
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                if force(mid) < comfort_force_n { lo = mid } else { hi = mid }
            }
            0.5 * (lo + hi)
        };
        let points: Vec<_> =
            (1..=n).map(|i| uniaxial(material, direction, max_stretch * i as f64 / n as f64)).collect();
        let at_comfort = uniaxial(material, direction, comfort_stretch);
        DirectionTargets {
            direction,
            comfort_stretch,
            stretch: points.iter().map(|p| p.stretch).collect(),
            compression: points.iter().map(|p| p.compression).collect(),
            stress_n_m: points.iter().map(|p| p.stress_n_m).collect(),
            comfort_stress_n_m: at_comfort.stress_n_m / (1.0 + comfort_stretch),
            comfort_compression: at_comfort.compression,
        }
    }

    /// The targets whose index `keep` accepts (the comfort range and normalizations unchanged).
    pub fn subset(&self, keep: impl Fn(usize) -> bool) -> Self {
        let pick = |v: &[f64]| v.iter().enumerate().filter(|(i, _)| keep(*i)).map(|(_, x)| *x).collect();
        DirectionTargets {
            stretch: pick(&self.stretch),
            compression: pick(&self.compression),
            stress_n_m: pick(&self.stress_n_m),
            ..self.clone()
        }
    }

    /// Targets read off a simulated curve (a yarn model as ground truth); the comfort range ends
    /// where the clamp force `σ_s w` of a swatch of width `width_m` reaches `comfort_force_n`
    /// (linear interpolation between the curve's points).
    pub fn of_curve(curve: &SimulatedCurve, width_m: f64, comfort_force_n: f64) -> Self {
        let (s, c, sigma) = (&curve.stretch, &curve.compression, &curve.stress_n_m);
        let n = s.len();
        let limit = comfort_force_n / width_m;
        let comfort_stretch = match (0..n).find(|&i| sigma[i] >= limit) {
            None => s[n - 1],
            Some(0) => s[0] * limit / sigma[0].max(f64::MIN_POSITIVE),
            Some(i) => s[i - 1] + (s[i] - s[i - 1]) * (limit - sigma[i - 1]) / (sigma[i] - sigma[i - 1]),
        };
        let at = |v: &[f64]| {
            let i = s.iter().position(|&x| x >= comfort_stretch).unwrap_or(n - 1).max(1).min(n - 1);
            let t = ((comfort_stretch - s[i - 1]) / (s[i] - s[i - 1])).clamp(0.0, 1.0);
            if n == 1 { v[0] } else { v[i - 1] + t * (v[i] - v[i - 1]) }
        };
        DirectionTargets {
            direction: curve.direction,
            comfort_stretch,
            stretch: s.clone(),
            compression: c.clone(),
            stress_n_m: sigma.clone(),
            comfort_stress_n_m: at(sigma) / (1.0 + comfort_stretch),
            comfort_compression: at(c),
        }
    }

    /// The weights `v_comfort / max(v_comfort, v)` of the stretch and compression errors at
    /// target `i`.
    fn weights(&self, i: usize) -> (f64, f64) {
        let decay = |comfort: f64, v: f64| if comfort > 0.0 { comfort / comfort.max(v) } else { 1.0 };
        (
            decay(self.comfort_stress_n_m, self.stress_n_m[i] / (1.0 + self.stretch[i])),
            decay(self.comfort_compression, self.compression[i]),
        )
    }

    /// Normalization of compression errors.
    fn compression_scale(&self) -> f64 {
        self.comfort_compression.max(COMPRESSION_FLOOR)
    }
}

/// The tile's response at the targets of one direction.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct SimulatedCurve {
    /// Direction.
    pub direction: Direction,
    /// Stretches (the targets').
    pub stretch: Vec<f64>,
    /// Compressions: of zero orthogonal stress at both ends, interpolated in between.
    pub compression: Vec<f64>,
    /// Stretch stresses `σ_s` (N/m), (6.10).
    pub stress_n_m: Vec<f64>,
    /// Newton iterations of all solves.
    pub iterations: usize,
}

/// Simulate the tile (with its zero-strain equilibrium `rest`) at the stretches of `targets`:
/// the compressions of zero orthogonal stress at the first and last stretch (marching between
/// them by warm-started solves at the last compression), then every stretch at the interpolated compression,
/// warm-started from the march.
pub fn simulate_direction(
    tile: &RveModel,
    rest: &RveState,
    targets: &DirectionTargets,
) -> Result<SimulatedCurve, TileError> {
    Ok(simulate_samples(tile, rest, targets)?.0)
}

/// [`simulate_direction`], with the solved tile states behind the curve.
fn simulate_samples(
    tile: &RveModel,
    rest: &RveState,
    targets: &DirectionTargets,
) -> Result<(SimulatedCurve, Vec<TileSample>), TileError> {
    let (direction, s) = (targets.direction, &targets.stretch);
    let n = s.len();
    let first = zero_orthogonal_stress(tile, direction, s[0], 0.0, Some(rest))?;
    let mut iterations = first.iterations;
    let mut march: Vec<TileSample> = vec![first];
    for i in 1..n {
        let previous = &march[i - 1];
        let sample = if i + 1 == n {
            zero_orthogonal_stress(tile, direction, s[i], previous.compression, Some(&previous.state))?
        } else {
            solve_uniaxial(tile, direction, s[i], previous.compression, Some(&previous.state))?
        };
        iterations += sample.iterations;
        march.push(sample);
    }
    let (c0, c1) = (march[0].compression, march[n - 1].compression);
    // The stretches in between, at the interpolated compression: independent solves, in parallel.
    let samples = march
        .into_par_iter()
        .enumerate()
        .map(|(i, marched)| {
            if i == 0 || i + 1 == n {
                return Ok((marched, 0));
            }
            let w = interpolation_weight(s, i);
            let sample = solve_uniaxial(tile, direction, s[i], c0 + (c1 - c0) * w, Some(&marched.state))?;
            let iterations = sample.iterations;
            Ok((sample, iterations))
        })
        .collect::<Result<Vec<_>, TileError>>()?;
    let curve = SimulatedCurve {
        direction,
        stretch: s.clone(),
        compression: samples.iter().map(|(sample, _)| sample.compression).collect(),
        stress_n_m: samples.iter().map(|(sample, _)| sample.stretch_stress_n_m).collect(),
        iterations: iterations + samples.iter().map(|(_, it)| it).sum::<usize>(),
    };
    Ok((curve, samples.into_iter().map(|(sample, _)| sample).collect()))
}

/// The weight of the last stretch's compression in the interpolated compression at stretch `i`.
fn interpolation_weight(s: &[f64], i: usize) -> f64 {
    let n = s.len();
    if n == 1 { 0.0 } else { (s[i] - s[0]) / (s[n - 1] - s[0]) }
}

/// Derivatives of a simulated curve by the fitted parameters: `[i][j]` is the derivative of
/// the `i`-th stretch's value by parameter `j`.
#[derive(Debug, Clone, PartialEq)]
pub struct CurveSensitivity {
    /// `dc_i/dp_j`.
    pub compression: Vec<Vec<f64>>,
    /// `dσ_s,i/dp_j` (N/m).
    pub stress_n_m: Vec<Vec<f64>>,
}

/// Compression step of the finite difference `∂σ/∂c` at a solved state.
const COMPRESSION_STEP: f64 = 1e-3;

/// [`simulate_direction`] with the curve's sensitivities to the parameters that turn `tile`
/// into each of `perturbed` (moved by `step`, same rest shape).
///
/// At each solved state the stresses' partial derivatives come from the linearized equilibrium
/// ([`yarnhom_rve::homogenize::stress_sensitivities`]), and `∂σ/∂c` from one warm-started
/// solve at `c + 10⁻³`. The end compressions keep `σ_c = 0`, so
/// `dc/dp = -(∂σ_c/∂p) / (∂σ_c/∂c)` there; in between `c` is interpolated, and so is `dc/dp`;
/// then `dσ_s/dp = ∂σ_s/∂p + (∂σ_s/∂c) dc/dp`.
pub fn simulate_direction_with_sensitivity(
    tile: &RveModel,
    perturbed: &[RveModel],
    step: f64,
    rest: &RveState,
    targets: &DirectionTargets,
) -> Result<(SimulatedCurve, CurveSensitivity), TileError> {
    let (curve, samples) = simulate_samples(tile, rest, targets)?;
    let direction = targets.direction;
    let s = &targets.stretch;
    // Per sample: (∂σ_s/∂p, ∂σ_c/∂p) and (∂σ_s/∂c, ∂σ_c/∂c).
    let partials = samples
        .par_iter()
        .map(|sample| {
            let map = uniaxial_strain(direction, sample.stretch, sample.compression);
            let strain = map.macro_strain(sample.compression)?;
            let no_equilibrium = || TileError::NoEquilibrium {
                direction,
                stretch: sample.stretch,
                compression: sample.compression,
            };
            let d_sigma = stress_sensitivities(tile, perturbed, step, &strain, &sample.state)
                .ok_or_else(no_equilibrium)?;
            let by_p: Vec<(f64, f64)> = d_sigma.iter().map(|d| map.stretch_and_compression(d)).collect();
            let h = COMPRESSION_STEP;
            let moved =
                solve_uniaxial(tile, direction, sample.stretch, sample.compression + h, Some(&sample.state))?;
            let by_c = (
                (moved.stretch_stress_n_m - sample.stretch_stress_n_m) / h,
                (moved.compression_stress_n_m - sample.compression_stress_n_m) / h,
            );
            Ok((by_p, by_c))
        })
        .collect::<Result<Vec<_>, TileError>>()?;
    let n = s.len();
    let parameters = perturbed.len();
    let end_compression = |i: usize| -> Vec<f64> {
        let (by_p, (_, dsc_dc)) = &partials[i];
        by_p.iter().map(|(_, dsc_dp)| -dsc_dp / dsc_dc).collect()
    };
    let (first, last) = (end_compression(0), end_compression(n - 1));
    let mut sensitivity =
        CurveSensitivity { compression: Vec::with_capacity(n), stress_n_m: Vec::with_capacity(n) };
    for (i, (by_p, (dss_dc, _))) in partials.iter().enumerate() {
        let w = interpolation_weight(s, i);
        let dc: Vec<f64> = (0..parameters).map(|j| first[j] + (last[j] - first[j]) * w).collect();
        sensitivity.stress_n_m.push((0..parameters).map(|j| by_p[j].0 + dss_dc * dc[j]).collect());
        sensitivity.compression.push(dc);
    }
    Ok((curve, sensitivity))
}

/// The Jacobian of [`residuals`] from the curves' sensitivities (rows in residual order).
pub fn residual_jacobian(targets: &[DirectionTargets], sensitivities: &[CurveSensitivity]) -> Vec<Vec<f64>> {
    let mut rows = Vec::new();
    for (t, d) in targets.iter().zip(sensitivities) {
        for i in 0..t.stretch.len() {
            let (ws, wc) = t.weights(i);
            let scale_s = ws / (1.0 + t.stretch[i]) / t.comfort_stress_n_m;
            rows.push(d.stress_n_m[i].iter().map(|x| scale_s * x).collect());
            rows.push(d.compression[i].iter().map(|x| wc * x / t.compression_scale()).collect());
        }
    }
    rows
}

/// [`simulate_direction`] for every direction, in parallel.
pub fn simulate(
    tile: &RveModel,
    rest: &RveState,
    targets: &[DirectionTargets],
) -> Result<Vec<SimulatedCurve>, TileError> {
    targets.par_iter().map(|t| simulate_direction(tile, rest, t)).collect()
}

/// The residuals of (6.11) (`g = Σ r²`): per direction, the weighted, normalized stretch errors,
/// then the compression errors.
pub fn residuals(targets: &[DirectionTargets], curves: &[SimulatedCurve]) -> Vec<f64> {
    let mut r = Vec::new();
    for (t, c) in targets.iter().zip(curves) {
        for i in 0..t.stretch.len() {
            let (ws, wc) = t.weights(i);
            let pk2 = |sigma: f64| sigma / (1.0 + t.stretch[i]);
            r.push(ws * (pk2(c.stress_n_m[i]) - pk2(t.stress_n_m[i])) / t.comfort_stress_n_m);
            r.push(wc * (c.compression[i] - t.compression[i]) / t.compression_scale());
        }
    }
    r
}

/// Errors of a yarn-level fit (fractions, as Fig. 6.15: relative to the largest target in the
/// comfort range).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct YarnErrors {
    /// Direction.
    pub direction: Direction,
    /// RMS stretch-stress error over the comfort range.
    pub comfort_stress: f64,
    /// RMS stretch-stress error beyond it (absent if every target is within it).
    pub power_stress: Option<f64>,
    /// RMS compression error over all targets.
    pub compression: f64,
}

/// The errors of `curves` against `targets`, per direction.
pub fn errors(targets: &[DirectionTargets], curves: &[SimulatedCurve]) -> Vec<YarnErrors> {
    let rms =
        |v: &[f64]| (!v.is_empty()).then(|| (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt());
    targets
        .iter()
        .zip(curves)
        .map(|(t, c)| {
            let (mut comfort, mut power, mut compression) = (Vec::new(), Vec::new(), Vec::new());
            for i in 0..t.stretch.len() {
                let e = (c.stress_n_m[i] - t.stress_n_m[i]) / (1.0 + t.stretch[i]) / t.comfort_stress_n_m;
                if t.stretch[i] <= t.comfort_stretch * (1.0 + 1e-9) {
                    comfort.push(e)
                } else {
                    power.push(e)
                }
                compression.push((c.compression[i] - t.compression[i]) / t.compression_scale());
            }
            YarnErrors {
                direction: t.direction,
                comfort_stress: rms(&comfort).unwrap_or(0.0),
                power_stress: rms(&power),
                compression: rms(&compression).unwrap_or(0.0),
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::knit_membrane;

    #[test]
    fn comfort_ends_at_two_newtons_and_weights_decay_past_it() {
        let t = DirectionTargets::of_shell(&knit_membrane(), Direction::Weft, 0.6, 0.06, 12, COMFORT_FORCE_N);
        let force = uniaxial(&knit_membrane(), Direction::Weft, t.comfort_stretch).stress_n_m * 0.06;
        assert!((force - COMFORT_FORCE_N).abs() < 1e-6, "{force}");
        for i in 0..t.stretch.len() {
            let (ws, _) = t.weights(i);
            if t.stretch[i] <= t.comfort_stretch {
                assert_eq!(ws, 1.0);
            } else {
                assert!(ws < 1.0 && ws > 0.0);
            }
        }
    }

    #[test]
    fn a_curve_equal_to_its_targets_has_no_residual() {
        let t = DirectionTargets::of_shell(&knit_membrane(), Direction::Bias, 0.4, 0.06, 5, COMFORT_FORCE_N);
        let curve = SimulatedCurve {
            direction: t.direction,
            stretch: t.stretch.clone(),
            compression: t.compression.clone(),
            stress_n_m: t.stress_n_m.clone(),
            iterations: 0,
        };
        assert!(residuals(std::slice::from_ref(&t), std::slice::from_ref(&curve)).iter().all(|r| *r == 0.0));
        let mut off = curve.clone();
        off.stress_n_m.iter_mut().for_each(|s| *s *= 1.1);
        let e = &errors(std::slice::from_ref(&t), &[off])[0];
        assert!(e.comfort_stress > 0.0 && e.compression == 0.0);
    }
}
