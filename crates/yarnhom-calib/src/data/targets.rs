//! Fit targets from raw stretch readings (thesis Sec. 6.3.1: "6 target deformations for each
//! weft, bias, and warp direction, distributed evenly along the stretch range").
//!
//! A real test has thousands of noisy readings over several repeats. For each direction the
//! loading readings are reduced to `n` targets at evenly spaced stretches `s_i = i s_max / n`:
//! force and compression at `s_i` are the values at `s_i` of a least-squares line through the
//! readings within half a spacing of it (a local linear fit, so uneven sampling inside the
//! window does not bias the value), with the readings' scatter about that line as the noise.
//! The range ends at the largest loading stretch or where the force first reaches a cap
//! (default 5 N, the top of the thesis' tested range, Sec. 6.2.3), whichever comes first.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use crate::data::set::{Direction, MeasurementSet, Phase, StretchPoint};

/// How the targets are chosen.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct TargetPlan {
    /// Targets per direction.
    pub per_direction: usize,
    /// The stretch range ends where the measured force reaches this (N).
    pub force_cap_n: f64,
    /// Which phase's readings to use.
    pub phase: Phase,
}

impl Default for TargetPlan {
    fn default() -> Self {
        Self { per_direction: 6, force_cap_n: 5.0, phase: Phase::Load }
    }
}

/// One target: a stretch and the measured response there.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct Target {
    /// Pull direction.
    pub direction: Direction,
    /// Stretch.
    pub stretch: f64,
    /// Measured clamp force (N).
    pub force_n: f64,
    /// Scatter of the force readings about the local line (N).
    pub force_noise_n: f64,
    /// Measured compression, if the readings have it.
    pub compression: Option<f64>,
    /// Scatter of the compression readings about the local line.
    pub compression_noise: Option<f64>,
    /// Readings behind the target.
    pub readings: usize,
}

/// Why targets could not be made.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TargetError {
    /// No readings of the phase at positive stretch.
    #[error("no {phase} readings at positive stretch in any direction")]
    NoReadings {
        /// The phase asked for.
        phase: Phase,
    },
    /// Too few readings near a target stretch.
    #[error(
        "{direction}: only {readings} readings near stretch {stretch:.4} (at least 3 are needed per target)"
    )]
    Sparse {
        /// The direction.
        direction: Direction,
        /// The target stretch.
        stretch: f64,
        /// Readings found.
        readings: usize,
    },
}

/// The targets of every direction with readings, in direction then stretch order.
pub fn targets(set: &MeasurementSet, plan: &TargetPlan) -> Result<Vec<Target>, TargetError> {
    let mut out = Vec::new();
    for direction in Direction::ALL {
        let readings: Vec<&StretchPoint> = set
            .stretch
            .iter()
            .filter(|p| p.direction == direction && p.phase == plan.phase && p.stretch > 0.0)
            .collect();
        if readings.len() < 3 {
            continue;
        }
        out.extend(direction_targets(direction, &readings, plan)?);
    }
    if out.is_empty() {
        return Err(TargetError::NoReadings { phase: plan.phase });
    }
    Ok(out)
}

fn direction_targets(
    direction: Direction,
    readings: &[&StretchPoint],
    plan: &TargetPlan,
) -> Result<Vec<Target>, TargetError> {
    let n = plan.per_direction.max(1);
    let s_max = stretch_range(readings, plan.force_cap_n);
    let spacing = s_max / n as f64;
    (1..=n)
        .map(|i| {
            let stretch = s_max * i as f64 / n as f64;
            let near: Vec<&&StretchPoint> =
                readings.iter().filter(|p| (p.stretch - stretch).abs() <= 0.5 * spacing).collect();
            if near.len() < 3 {
                return Err(TargetError::Sparse { direction, stretch, readings: near.len() });
            }
            let (force_n, force_noise_n) = local_line(near.iter().map(|p| (p.stretch, p.force_n)), stretch);
            let with_compression: Vec<(f64, f64)> =
                near.iter().filter_map(|p| p.compression.map(|c| (p.stretch, c))).collect();
            let compression =
                (with_compression.len() >= 3).then(|| local_line(with_compression.iter().copied(), stretch));
            Ok(Target {
                direction,
                stretch,
                force_n,
                force_noise_n,
                compression: compression.map(|c| c.0),
                compression_noise: compression.map(|c| c.1),
                readings: near.len(),
            })
        })
        .collect()
}

/// The end of the stretch range: the largest stretch, or the first stretch (on a 400-step
/// scan) where the local-line force reaches `force_cap_n`.
fn stretch_range(readings: &[&StretchPoint], force_cap_n: f64) -> f64 {
    let largest = readings.iter().map(|p| p.stretch).fold(0.0, f64::max);
    let window = largest / 40.0;
    (1..=400)
        .map(|k| largest * k as f64 / 400.0)
        .find(|&s| {
            let near: Vec<(f64, f64)> = readings
                .iter()
                .filter(|p| (p.stretch - s).abs() <= window)
                .map(|p| (p.stretch, p.force_n))
                .collect();
            near.len() >= 3 && local_line(near.into_iter(), s).0 >= force_cap_n
        })
        .unwrap_or(largest)
}

/// The least-squares line through `(x, y)` evaluated at `at`, and the RMS scatter about it.
fn local_line(points: impl Iterator<Item = (f64, f64)>, at: f64) -> (f64, f64) {
    let points: Vec<(f64, f64)> = points.collect();
    let n = points.len() as f64;
    let (mx, my) = points.iter().fold((0.0, 0.0), |(a, b), (x, y)| (a + x / n, b + y / n));
    let sxx: f64 = points.iter().map(|(x, _)| (x - mx).powi(2)).sum();
    let sxy: f64 = points.iter().map(|(x, y)| (x - mx) * (y - my)).sum();
    let slope = if sxx > 0.0 { sxy / sxx } else { 0.0 };
    let line = |x: f64| my + slope * (x - mx);
    let scatter = (points.iter().map(|(x, y)| (y - line(*x)).powi(2)).sum::<f64>() / n).sqrt();
    (line(at), scatter)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::set::Fabric;

    fn set(points: Vec<StretchPoint>) -> MeasurementSet {
        MeasurementSet {
            fabric: Fabric {
                name: "t".into(),
                pattern: "rib".into(),
                swatch: Default::default(),
                yarn: vec![],
            },
            stretch: points,
            bending: vec![],
            cantilever: vec![],
        }
    }

    fn point(direction: Direction, stretch: f64, force_n: f64, compression: f64) -> StretchPoint {
        StretchPoint {
            direction,
            stretch,
            force_n,
            compression: Some(compression),
            phase: Phase::Load,
            repeat: Some(1),
        }
    }

    #[test]
    fn targets_recover_a_noisy_curve_and_stop_at_the_force_cap() {
        // force = 20 s², compression = 0.3 s, with alternating ±0.05 N noise; 5 N at s = 0.5.
        let points: Vec<_> = (1..=2000)
            .map(|k| {
                let s = k as f64 * 0.0005;
                let noise = if k % 2 == 0 { 0.05 } else { -0.05 };
                point(Direction::Warp, s, 20.0 * s * s + noise, 0.3 * s)
            })
            .collect();
        let t = targets(&set(points), &TargetPlan::default()).expect("targets");
        assert_eq!(t.len(), 6);
        let last = t.last().expect("six");
        assert!((last.stretch - 0.5).abs() < 0.003, "{}", last.stretch);
        for target in &t {
            let s = target.stretch;
            // A line through a parabola over a window of width h errs by about 20 h²/12.
            assert!((target.force_n - 20.0 * s * s).abs() < 0.02, "{s}: {}", target.force_n);
            assert!((target.compression.expect("measured") - 0.3 * s).abs() < 1e-9);
            assert!((target.force_noise_n - 0.05).abs() < 0.01);
        }
    }

    #[test]
    fn directions_without_readings_are_skipped_and_sparse_ones_refused() {
        let sparse = vec![
            point(Direction::Weft, 0.1, 1.0, 0.0),
            point(Direction::Weft, 0.2, 2.0, 0.0),
            point(Direction::Weft, 0.3, 3.0, 0.0),
        ];
        let error = targets(&set(sparse), &TargetPlan::default()).expect_err("three points for six targets");
        assert!(matches!(error, TargetError::Sparse { direction: Direction::Weft, .. }), "{error}");
        let unload: Vec<_> = (1..50)
            .map(|k| StretchPoint {
                phase: Phase::Unload,
                ..point(Direction::Bias, k as f64 * 0.01, 1.0, 0.0)
            })
            .collect();
        assert_eq!(
            targets(&set(unload), &TargetPlan::default()),
            Err(TargetError::NoReadings { phase: Phase::Load })
        );
    }
}
