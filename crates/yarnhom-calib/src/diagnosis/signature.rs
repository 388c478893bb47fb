//! The signature of each stretch-track cause: what the effect changes in the data, measured on
//! the targets, so a candidate is judged by whether it fixes its own effect and not only by the
//! total error it removes ([`super::rule::DecisionRule::explains_signature`]).
//!
//! Each signature is a list of linear functionals of the target values; a model's signature
//! error is the RMS over them of `(model - measured) / scale` (the scale of (6.2): the
//! direction's mean force or compression), and the signature's noise the RMS of the measured
//! functionals' standard errors over the same scale (from the targets' standard errors,
//! [`crate::data::targets`]).
//!
//! - `friction-hysteresis`: the paired load/unload force difference at equal stretch: at every
//!   unloading target, its force minus the loading targets' force linearly interpolated there.
//!   A model without friction predicts none.
//! - `biphasic-stretch`: the change of slope of the loading force: per direction, the `s²`
//!   coefficient of the least-squares quadratic through the targets, times `s_max²`.
//! - `area-preservation`: the contraction curve: every loading target's compression.
//! - `two-phase-contact`: the change of slope of the contraction, as for the force.

use super::report::SignatureScore;
use super::stretch::{Fitted, Phases};
use crate::cause::CauseId;
use crate::data::targets::Target;
use crate::experiments::swatch::SimulatedReading;
use crate::shell::membrane::DirectionData;
use yarnhom_geom::stats::root_mean_square;

/// A normalized signature residual and the standard error of its measured part.
type Component = (f64, f64);

/// What the signature of `id` measures, for reports.
fn measure(id: CauseId) -> Option<&'static str> {
    match id {
        CauseId::FrictionHysteresis => Some("paired load/unload force difference"),
        CauseId::BiphasicStretch => Some("change of slope of the force"),
        CauseId::AreaPreservation => Some("contraction curve"),
        CauseId::TwoPhaseContact => Some("change of slope of the contraction"),
        _ => None,
    }
}

/// The signature of `id` with `before` (the model a candidate extends) and `after` (the
/// candidate); `None` for a cause without a stretch signature or a set that cannot show it.
pub(super) fn score(id: CauseId, phases: &Phases, before: &Fitted, after: &Fitted) -> Option<SignatureScore> {
    let measure = measure(id)?;
    let (before, noise) = error(id, phases, before)?;
    let (after, _) = error(id, phases, after)?;
    Some(SignatureScore { measure: measure.into(), before, after, noise })
}

/// The signature error of `id` with `model`, and its noise.
fn error(id: CauseId, phases: &Phases, model: &Fitted) -> Option<(f64, f64)> {
    let components = match id {
        CauseId::FrictionHysteresis => paired_differences(phases, model)?,
        CauseId::BiphasicStretch => slope_changes(phases, model, Quantity::Force),
        CauseId::AreaPreservation => contractions(phases, model),
        CauseId::TwoPhaseContact => slope_changes(phases, model, Quantity::Compression),
        _ => return None,
    };
    (!components.is_empty()).then(|| {
        (root_mean_square(components.iter().map(|c| c.0)), root_mean_square(components.iter().map(|c| c.1)))
    })
}

#[derive(Clone, Copy, PartialEq)]
enum Quantity {
    Force,
    Compression,
}

impl Quantity {
    /// The measured value, its standard error, and the direction's scale (`None` without a
    /// measured compression).
    fn measured(self, d: &DirectionData, t: &Target) -> Option<(f64, f64, f64)> {
        match self {
            Quantity::Force => Some((t.force_n, t.force_standard_error_n, d.force_scale)),
            Quantity::Compression => {
                Some((t.compression?, t.compression_standard_error.unwrap_or(0.0), d.compression_scale?))
            }
        }
    }

    fn simulated(self, r: &SimulatedReading) -> f64 {
        match self {
            Quantity::Force => r.force_n,
            Quantity::Compression => r.compression,
        }
    }
}

/// Every loading target's compression residual.
fn contractions(phases: &Phases, model: &Fitted) -> Vec<Component> {
    let mut out = Vec::new();
    for (d, readings) in phases.load.data.iter().zip(&model.load) {
        for (t, r) in d.targets.iter().zip(readings) {
            if let Some((c, se, scale)) = Quantity::Compression.measured(d, t) {
                out.push(((r.compression - c) / scale, se / scale));
            }
        }
    }
    out
}

/// Per direction, the `s²` coefficient of the quadratic through the loading targets' `q`,
/// model against measured, times `s_max²`.
fn slope_changes(phases: &Phases, model: &Fitted, q: Quantity) -> Vec<Component> {
    let mut out = Vec::new();
    for (d, readings) in phases.load.data.iter().zip(&model.load) {
        let measured: Option<Vec<(f64, f64, f64)>> = d.targets.iter().map(|t| q.measured(d, t)).collect();
        let Some(measured) = measured else { continue };
        let stretches = d.stretches();
        let Some(weights) = quadratic_coefficient_weights(&stretches) else { continue };
        let s_max = stretches.iter().copied().fold(0.0, f64::max);
        let scale = measured[0].2 / (s_max * s_max);
        let residual: f64 =
            weights.iter().zip(readings).zip(&measured).map(|((w, r), m)| w * (q.simulated(r) - m.0)).sum();
        let se = weights.iter().zip(&measured).map(|(w, m)| (w * m.1).powi(2)).sum::<f64>().sqrt();
        out.push((residual / scale, se / scale));
    }
    out
}

/// The weights `w` with `c = Σ w_i y_i` the `x²` coefficient of the least-squares quadratic
/// through `(x_i, y_i)` (`None` with fewer than three distinct abscissae).
fn quadratic_coefficient_weights(x: &[f64]) -> Option<Vec<f64>> {
    let rows: Vec<[f64; 3]> = x.iter().map(|&x| [1.0, x, x * x]).collect();
    let mut normal = nalgebra::Matrix3::<f64>::zeros();
    for r in &rows {
        let v = nalgebra::Vector3::from(*r);
        normal += v * v.transpose();
    }
    let inverse = normal.try_inverse()?;
    let last = inverse.row(2);
    let weights: Vec<f64> = rows.iter().map(|r| last.dot(&nalgebra::Vector3::from(*r).transpose())).collect();
    weights.iter().all(|w| w.is_finite()).then_some(weights)
}

/// At every unloading target: its force minus the loading force interpolated at its stretch,
/// model against measured (`None` without unloading targets).
fn paired_differences(phases: &Phases, model: &Fitted) -> Option<Vec<Component>> {
    let unload = phases.unload.as_ref()?;
    let mut out = Vec::new();
    for (u, readings) in unload.data.iter().zip(&model.unload) {
        let Some(load) = phases.load.data.iter().find(|d| d.direction == u.direction) else { continue };
        let forces: Vec<f64> = readings.iter().map(|r| r.force_n).collect();
        let unloading = model.hysteresis.unloading(&forces);
        for ((t, f), unloading) in u.targets.iter().zip(&forces).zip(unloading) {
            let (load_force, load_se) = interpolate_force(&load.targets, t.stretch);
            let measured = t.force_n - load_force;
            // The model's loading force at the unloading stretch is its simulated force there.
            let predicted = unloading - f;
            let se = t.force_standard_error_n.hypot(load_se);
            out.push(((predicted - measured) / u.force_scale, se / u.force_scale));
        }
    }
    Some(out)
}

/// The loading force at `stretch`, linear between the two targets around it (or the nearest
/// two), and the larger of their standard errors.
fn interpolate_force(targets: &[Target], stretch: f64) -> (f64, f64) {
    let k = targets
        .iter()
        .position(|t| t.stretch >= stretch)
        .unwrap_or(targets.len() - 1)
        .clamp(1, targets.len() - 1);
    let (a, b) = (&targets[k - 1], &targets[k]);
    let w = (stretch - a.stretch) / (b.stretch - a.stretch);
    ((1.0 - w) * a.force_n + w * b.force_n, a.force_standard_error_n.max(b.force_standard_error_n))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_quadratic_weights_recover_the_curvature_of_a_parabola() {
        let x: Vec<f64> = (1..=6).map(|i| 0.05 * i as f64).collect();
        let w = quadratic_coefficient_weights(&x).expect("six abscissae");
        let c: f64 = w.iter().zip(&x).map(|(w, x)| w * (1.0 + 2.0 * x + 7.0 * x * x)).sum();
        assert!((c - 7.0).abs() < 1e-9, "{c}");
        let line: f64 = w.iter().zip(&x).map(|(w, x)| w * (3.0 - x)).sum();
        assert!(line.abs() < 1e-9, "a line has no curvature: {line}");
    }
}
