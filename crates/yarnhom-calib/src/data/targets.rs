//! Fit targets from raw stretch readings (thesis Sec. 6.3.1: "6 target deformations for each
//! weft, bias, and warp direction, distributed evenly along the stretch range").
//!
//! A real test has thousands of noisy readings over several repeats; another set has one reading
//! per stretch level. For each direction and phase the readings up to the end of the stretch
//! range `s_max` (the largest stretch, or where the force first reaches a cap, default 5 N, the
//! top of the thesis' tested range, Sec. 6.2.3) are reduced to at most `n` targets, by one of two
//! rules ([`TargetMethod`]), chosen from the readings the direction has:
//!
//! - **Windows** (dense readings): targets at evenly spaced stretches `s_i = i s_max / n`; force
//!   and compression at `s_i` are the values at `s_i` of a least-squares line through the
//!   readings within half a spacing of it (a local linear fit, so uneven sampling inside the
//!   window does not bias the value). Used when every window holds at least
//!   [`MIN_WINDOW_READINGS`] readings.
//! - **Groups** (sparse readings): the readings sorted by stretch are cut into `min(n, count)`
//!   consecutive groups of near-equal size; a target is a group's mean stretch, force and
//!   compression (the least-squares line through a group, evaluated at its mean stretch, is its
//!   mean). With one reading per level and `n` levels, the targets are the readings.
//!
//! A direction needs at least [`MIN_TARGETS`] targets (two fitted, two held out in a
//! diagnosis); one with fewer readings is refused ([`TargetError::TooFew`]), one with none is
//! skipped. [`TargetSet::choices`] says what was chosen.
//!
//! Every target carries the standard error of its force and compression, what a model's error
//! is compared against:
//! - windows: the readings' scatter about the local line over the square root of their count,
//!   or, where at least two repeats have readings in the window, the spread of the repeats' own
//!   local lines at `s_i` over the square root of the repeats, whichever is larger (repeats of
//!   one swatch differ from each other more than each curve is noisy);
//! - groups: the direction's reading scatter (each reading against the line through its two
//!   neighbours in stretch, within its repeat: `d = (y - ŷ) / √(1 + w₁² + w₂²)` with `w` the
//!   interpolation weights, and `σ = median |d| / 0.6745`, robust to a kink or a glitch; an
//!   upper bound where the curve bends) over the square root of the group's size.

use std::fmt;

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use crate::data::set::{Direction, MeasurementSet, Phase, StretchPoint};

/// Fewest targets a direction may have.
pub const MIN_TARGETS: usize = 4;

/// Fewest readings in every window for the windows rule.
pub const MIN_WINDOW_READINGS: usize = 3;

/// How the targets are chosen.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct TargetPlan {
    /// Targets per direction (at most).
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
    /// Scatter of the force readings about the local line (N); for a group, the direction's
    /// reading scatter.
    pub force_noise_n: f64,
    /// Measured compression, if the readings have it.
    pub compression: Option<f64>,
    /// Scatter of the compression readings, as `force_noise_n`.
    pub compression_noise: Option<f64>,
    /// Readings behind the target.
    pub readings: usize,
    /// Standard error of the force (N): scatter over the square root of the readings, or the
    /// spread between repeats over the square root of the repeats, whichever is larger.
    #[serde(default)]
    pub force_standard_error_n: f64,
    /// Standard error of the compression, as `force_standard_error_n`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub compression_standard_error: Option<f64>,
}

/// The rule that made a direction's targets.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum TargetMethod {
    /// Local lines over evenly spaced windows (dense readings).
    Windows,
    /// Means of consecutive groups of readings (sparse readings).
    Groups,
}

/// What was chosen for one direction and phase.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct TargetChoice {
    /// Direction.
    pub direction: Direction,
    /// Phase.
    pub phase: Phase,
    /// Readings up to the end of the stretch range.
    pub readings: usize,
    /// Targets made.
    pub targets: usize,
    /// End of the stretch range.
    pub stretch_max: f64,
    /// The rule.
    pub method: TargetMethod,
}

impl fmt::Display for TargetChoice {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let how = match self.method {
            TargetMethod::Windows => "local lines over even windows",
            TargetMethod::Groups => "means of consecutive groups of readings: too few for even windows",
        };
        write!(
            f,
            "{} {}: {} targets up to stretch {:.4} from {} readings ({how})",
            self.direction, self.phase, self.targets, self.stretch_max, self.readings
        )
    }
}

/// The targets of a set and how they were chosen.
#[derive(Debug, Clone, PartialEq)]
pub struct TargetSet {
    /// Targets in direction then stretch order.
    pub targets: Vec<Target>,
    /// One choice per direction with readings.
    pub choices: Vec<TargetChoice>,
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
    /// Too few readings in a direction to fit and hold out.
    #[error(
        "{direction}: only {readings} {phase} readings at positive stretch up to {stretch_max:.4} \
         (at least {MIN_TARGETS} are needed per direction: two fitted, two held out)"
    )]
    TooFew {
        /// The direction.
        direction: Direction,
        /// The phase.
        phase: Phase,
        /// Readings found.
        readings: usize,
        /// End of the stretch range.
        stretch_max: f64,
    },
}

/// The targets of every direction with readings, in direction then stretch order.
pub fn targets(set: &MeasurementSet, plan: &TargetPlan) -> Result<TargetSet, TargetError> {
    let mut out = TargetSet { targets: Vec::new(), choices: Vec::new() };
    for direction in Direction::ALL {
        let readings: Vec<&StretchPoint> = set
            .stretch
            .iter()
            .filter(|p| p.direction == direction && p.phase == plan.phase && p.stretch > 0.0)
            .collect();
        if readings.is_empty() {
            continue;
        }
        let (targets, choice) = direction_targets(direction, &readings, plan)?;
        out.targets.extend(targets);
        out.choices.push(choice);
    }
    if out.targets.is_empty() {
        return Err(TargetError::NoReadings { phase: plan.phase });
    }
    Ok(out)
}

fn direction_targets(
    direction: Direction,
    readings: &[&StretchPoint],
    plan: &TargetPlan,
) -> Result<(Vec<Target>, TargetChoice), TargetError> {
    let n = plan.per_direction.max(1);
    let s_max = stretch_range(readings, plan.force_cap_n);
    let in_range: Vec<&StretchPoint> =
        readings.iter().copied().filter(|p| p.stretch <= s_max * (1.0 + 1e-12)).collect();
    let choice = |targets: usize, method| TargetChoice {
        direction,
        phase: plan.phase,
        readings: in_range.len(),
        targets,
        stretch_max: s_max,
        method,
    };
    if let Some(targets) = window_targets(direction, readings, s_max, n) {
        return Ok((targets, choice(n, TargetMethod::Windows)));
    }
    if in_range.len() < MIN_TARGETS {
        return Err(TargetError::TooFew {
            direction,
            phase: plan.phase,
            readings: in_range.len(),
            stretch_max: s_max,
        });
    }
    let targets = group_targets(direction, &in_range, n);
    Ok((targets.clone(), choice(targets.len(), TargetMethod::Groups)))
}

/// `n` targets at even stretches up to `s_max` by local lines, if every window has
/// [`MIN_WINDOW_READINGS`] readings.
fn window_targets(
    direction: Direction,
    readings: &[&StretchPoint],
    s_max: f64,
    n: usize,
) -> Option<Vec<Target>> {
    let spacing = s_max / n as f64;
    (1..=n)
        .map(|i| {
            let stretch = s_max * i as f64 / n as f64;
            let near: Vec<&StretchPoint> =
                readings.iter().copied().filter(|p| (p.stretch - stretch).abs() <= 0.5 * spacing).collect();
            (near.len() >= MIN_WINDOW_READINGS).then(|| window_target(direction, &near, stretch))
        })
        .collect()
}

/// The target at `stretch` from the readings `near` it.
fn window_target(direction: Direction, near: &[&StretchPoint], stretch: f64) -> Target {
    let count = near.len() as f64;
    let (force_n, force_noise_n) = local_line(near.iter().map(|p| (p.stretch, p.force_n)), stretch);
    let with_compression: Vec<&StretchPoint> =
        near.iter().copied().filter(|p| p.compression.is_some()).collect();
    let compression_of = |p: &StretchPoint| p.compression.unwrap_or(0.0);
    let compression = (with_compression.len() >= MIN_WINDOW_READINGS)
        .then(|| local_line(with_compression.iter().map(|p| (p.stretch, compression_of(p))), stretch));
    let force_spread = repeat_spread(near, stretch, |p| Some(p.force_n));
    let compression_spread = repeat_spread(&with_compression, stretch, |p| p.compression);
    Target {
        direction,
        stretch,
        force_n,
        force_noise_n,
        compression: compression.map(|c| c.0),
        compression_noise: compression.map(|c| c.1),
        readings: near.len(),
        force_standard_error_n: (force_noise_n / count.sqrt()).max(force_spread),
        compression_standard_error: compression
            .map(|c| (c.1 / (with_compression.len() as f64).sqrt()).max(compression_spread)),
    }
}

/// The standard error of the mean of the repeats' local lines at `stretch`: their sample
/// standard deviation over the square root of their count (0 with fewer than two repeats having
/// two readings each).
fn repeat_spread(near: &[&StretchPoint], stretch: f64, value: impl Fn(&StretchPoint) -> Option<f64>) -> f64 {
    let mut repeats: Vec<Option<u32>> = near.iter().map(|p| p.repeat).collect();
    repeats.sort_unstable();
    repeats.dedup();
    let lines: Vec<f64> = repeats
        .iter()
        .filter_map(|r| {
            let mine: Vec<(f64, f64)> =
                near.iter().filter(|p| p.repeat == *r).filter_map(|p| Some((p.stretch, value(p)?))).collect();
            (mine.len() >= 2).then(|| local_line(mine.into_iter(), stretch).0)
        })
        .collect();
    if lines.len() < 2 {
        return 0.0;
    }
    let k = lines.len() as f64;
    let mean = lines.iter().sum::<f64>() / k;
    let variance = lines.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (k - 1.0);
    (variance / k).sqrt()
}

/// `min(n, count)` targets: the means of consecutive groups of the readings sorted by stretch.
fn group_targets(direction: Direction, readings: &[&StretchPoint], n: usize) -> Vec<Target> {
    let mut sorted = readings.to_vec();
    sorted.sort_by(|a, b| a.stretch.total_cmp(&b.stretch));
    let force_noise_n = neighbour_scatter(&sorted, |p| Some(p.force_n)).unwrap_or(0.0);
    let compression_noise = neighbour_scatter(&sorted, |p| p.compression);
    let groups = n.min(sorted.len());
    (0..groups)
        .map(|g| {
            let group = &sorted[g * sorted.len() / groups..(g + 1) * sorted.len() / groups];
            let count = group.len() as f64;
            let mean = |f: &dyn Fn(&StretchPoint) -> f64| group.iter().map(|p| f(p)).sum::<f64>() / count;
            let compressions: Vec<f64> = group.iter().filter_map(|p| p.compression).collect();
            let compression =
                (compressions.len() == group.len()).then(|| compressions.iter().sum::<f64>() / count);
            Target {
                direction,
                stretch: mean(&|p| p.stretch),
                force_n: mean(&|p| p.force_n),
                force_noise_n,
                compression,
                compression_noise: compression.and(compression_noise),
                readings: group.len(),
                force_standard_error_n: force_noise_n / count.sqrt(),
                compression_standard_error: compression.and(compression_noise).map(|c| c / count.sqrt()),
            }
        })
        .collect()
}

/// The readings' scatter about the line through their two neighbours in stretch, within each
/// repeat (see the module docs), from the median of the scaled deviations (a kink or a
/// glitch moves one or two of them, not the median); `None` without a value on three readings
/// of one repeat.
fn neighbour_scatter(sorted: &[&StretchPoint], value: impl Fn(&StretchPoint) -> Option<f64>) -> Option<f64> {
    let mut repeats: Vec<Option<u32>> = sorted.iter().map(|p| p.repeat).collect();
    repeats.sort_unstable();
    repeats.dedup();
    let mut deviations = Vec::new();
    for r in repeats {
        let mine: Vec<(f64, f64)> =
            sorted.iter().filter(|p| p.repeat == r).filter_map(|p| Some((p.stretch, value(p)?))).collect();
        for w in mine.windows(3) {
            let ((x0, y0), (x, y), (x1, y1)) = (w[0], w[1], w[2]);
            if x1 <= x0 {
                continue;
            }
            let t = (x - x0) / (x1 - x0);
            let d = y - ((1.0 - t) * y0 + t * y1);
            deviations.push(d.abs() / (1.0 + t * t + (1.0 - t) * (1.0 - t)).sqrt());
        }
    }
    if deviations.is_empty() {
        return None;
    }
    deviations.sort_by(f64::total_cmp);
    let n = deviations.len();
    let median =
        if n % 2 == 1 { deviations[n / 2] } else { 0.5 * (deviations[n / 2 - 1] + deviations[n / 2]) };
    // The median absolute value of a normal deviate is 0.6745 of its standard deviation.
    Some(median / 0.674_489_750_196_081_7)
}

/// The end of the stretch range: the largest stretch, or the first stretch (on a 400-step
/// scan) where the force reaches `force_cap_n`, the force being the local line through the
/// readings within a fortieth of the range, or through the three nearest where fewer are.
fn stretch_range(readings: &[&StretchPoint], force_cap_n: f64) -> f64 {
    let largest = readings.iter().map(|p| p.stretch).fold(0.0, f64::max);
    let window = largest / 40.0;
    (1..=400)
        .map(|k| largest * k as f64 / 400.0)
        .find(|&s| {
            let mut near: Vec<(f64, f64)> = readings
                .iter()
                .filter(|p| (p.stretch - s).abs() <= window)
                .map(|p| (p.stretch, p.force_n))
                .collect();
            if near.len() < MIN_WINDOW_READINGS {
                near = nearest(readings, s, MIN_WINDOW_READINGS);
            }
            near.len() >= MIN_WINDOW_READINGS && local_line(near.into_iter(), s).0 >= force_cap_n
        })
        .unwrap_or(largest)
}

/// The `k` readings nearest to stretch `s`, as `(stretch, force)`.
fn nearest(readings: &[&StretchPoint], s: f64, k: usize) -> Vec<(f64, f64)> {
    let mut by_distance: Vec<&&StretchPoint> = readings.iter().collect();
    by_distance.sort_by(|a, b| (a.stretch - s).abs().total_cmp(&(b.stretch - s).abs()));
    by_distance.into_iter().take(k).map(|p| (p.stretch, p.force_n)).collect()
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
                stitch: None,
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
        let chosen = targets(&set(points), &TargetPlan::default()).expect("targets");
        let t = &chosen.targets;
        assert_eq!(t.len(), 6);
        assert_eq!(chosen.choices[0].method, TargetMethod::Windows);
        let last = t.last().expect("six");
        assert!((last.stretch - 0.5).abs() < 0.003, "{}", last.stretch);
        for target in t {
            let s = target.stretch;
            // A line through a parabola over a window of width h errs by about 20 h²/12.
            assert!((target.force_n - 20.0 * s * s).abs() < 0.02, "{s}: {}", target.force_n);
            assert!((target.compression.expect("measured") - 0.3 * s).abs() < 1e-9);
            assert!((target.force_noise_n - 0.05).abs() < 0.01);
            let standard_error = target.force_noise_n / (target.readings as f64).sqrt();
            assert_eq!(target.force_standard_error_n, standard_error, "one repeat: the scatter's");
        }
    }

    #[test]
    fn one_reading_per_level_makes_the_readings_the_targets() {
        // Ten levels, force 10 s with ±0.02 N alternating noise.
        let points: Vec<_> = (1..=10)
            .map(|k| {
                let s = 0.04 * k as f64;
                point(Direction::Weft, s, 10.0 * s + if k % 2 == 0 { 0.02 } else { -0.02 }, 0.2 * s)
            })
            .collect();
        let chosen =
            targets(&set(points.clone()), &TargetPlan { per_direction: 10, ..TargetPlan::default() })
                .expect("targets");
        assert_eq!(chosen.choices[0].method, TargetMethod::Groups);
        assert_eq!(chosen.targets.len(), 10);
        for (t, p) in chosen.targets.iter().zip(&points) {
            assert_eq!((t.stretch, t.force_n, t.readings), (p.stretch, p.force_n, 1));
        }
        // Against its neighbours' line each reading is off by 0.04 N; the rule divides it by
        // √(1 + 1/4 + 1/4) and takes the median as 0.6745 standard deviations.
        let noise = chosen.targets[0].force_noise_n;
        assert!((noise - 0.04 / 1.5f64.sqrt() / 0.674_489_750_196_081_7).abs() < 1e-12, "{noise}");
        // Five targets from ten readings: pairs.
        let five =
            targets(&set(points), &TargetPlan { per_direction: 5, ..TargetPlan::default() }).expect("five");
        assert_eq!(five.targets.len(), 5);
        assert!(five.targets.iter().all(|t| t.readings == 2));
        assert!(
            five.choices[0].to_string().contains("5 targets up to stretch 0.4000 from 10 readings (means of")
        );
    }

    #[test]
    fn repeats_that_differ_set_the_standard_error() {
        // Two repeats of a clean line, 2% apart: the scatter about one line through both is
        // ~1%, its standard error over 200 readings tiny; the repeats' spread is what counts.
        let points: Vec<_> = (1..=200)
            .flat_map(|k| {
                let s = 0.002 * k as f64;
                [(1, 1.01), (2, 0.99)].map(|(repeat, scale)| StretchPoint {
                    repeat: Some(repeat),
                    ..point(Direction::Weft, s, scale * 10.0 * s, 0.2 * s)
                })
            })
            .collect();
        let t = targets(&set(points), &TargetPlan::default()).expect("targets").targets;
        for target in &t {
            // Two values 2% apart: standard deviation √2 %, over √2.
            let expected = 0.01 * 10.0 * target.stretch;
            assert!((target.force_standard_error_n / expected - 1.0).abs() < 0.02, "{target:?}");
        }
    }

    #[test]
    fn directions_without_readings_are_skipped_and_sparse_ones_refused() {
        let sparse = vec![
            point(Direction::Weft, 0.1, 1.0, 0.0),
            point(Direction::Weft, 0.2, 2.0, 0.0),
            point(Direction::Weft, 0.3, 3.0, 0.0),
        ];
        let error =
            targets(&set(sparse), &TargetPlan::default()).expect_err("three readings cannot be split");
        assert!(
            matches!(error, TargetError::TooFew { direction: Direction::Weft, readings: 3, .. }),
            "{error}"
        );
        assert_eq!(
            error.to_string(),
            "weft: only 3 load readings at positive stretch up to 0.3000 (at least 4 are needed per \
             direction: two fitted, two held out)"
        );
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
