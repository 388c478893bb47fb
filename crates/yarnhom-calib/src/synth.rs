//! Synthetic measurement sets: the clamped stretch tests of a known membrane simulated
//! ([`crate::swatch`]) at evenly spaced stretches, with Gaussian noise on the force and the
//! compression, written as a real set would be. Fits run on these must recover the membrane,
//! and a diagnosis must find the effect hidden in it ([`HiddenEffect`], [`ground_truth`]).

use nalgebra::Vector2;
use yarnhom_shell::{Stiffening, StvkNeoHookean};

use crate::measure::{Direction, Fabric, MeasurementSet, Phase, StretchPoint, Swatch};
use crate::swatch::{SimulatedReading, SwatchError, SwatchTest};

/// An effect hidden in a synthetic set, beyond the plain anisotropic StVK base.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HiddenEffect {
    /// Nothing: the base model is the truth.
    None,
    /// The Neo-Hookean area terms of (6.1).
    AreaPreservation,
    /// Stiffening past an onset strain ([`yarnhom_shell::Stiffening`]).
    BiphasicStretch,
    /// Unloading readings below loading: a friction force `2 h f_max` opposes the unloading
    /// swatch (a constant offset, not the multiplicative form the diagnosis fits).
    FrictionHysteresis,
}

/// The truth of a synthetic set: a knit-like anisotropic StVK (weft 60, warp 25 J/m²) with
/// `effect` at `strength` (1: clearly visible at 2% noise), and the friction `h` of the
/// unloading readings (0 without hysteresis).
pub fn ground_truth(effect: HiddenEffect, strength: f64) -> (StvkNeoHookean, f64) {
    let base = StvkNeoHookean {
        k_xx: 60.0,
        k_xy: 6.0,
        k_yy: 25.0,
        k_ss: 10.0,
        k_n1: 0.0,
        k_n2: 0.0,
        stiffening: None,
    };
    match effect {
        HiddenEffect::None => (base, 0.0),
        HiddenEffect::AreaPreservation => {
            (StvkNeoHookean { k_n1: 40.0 * strength, k_n2: 40.0 * strength, ..base }, 0.0)
        }
        HiddenEffect::BiphasicStretch => (
            StvkNeoHookean {
                stiffening: Some(Stiffening {
                    k_weft: 240.0 * strength,
                    k_warp: 100.0 * strength,
                    onset: 0.08,
                }),
                ..base
            },
            0.0,
        ),
        HiddenEffect::FrictionHysteresis => (base, 0.08 * strength),
    }
}

/// What to simulate.
#[derive(Debug, Clone, PartialEq)]
pub struct SynthPlan {
    /// The fabric name and pattern, and the swatch.
    pub fabric: Fabric,
    /// Directions tested.
    pub directions: Vec<Direction>,
    /// Largest marker stretch per direction, in `directions` order.
    pub max_stretch: Vec<f64>,
    /// Readings per direction.
    pub readings: usize,
    /// Standard deviation of the force noise (N).
    pub force_noise_n: f64,
    /// Standard deviation of the compression noise.
    pub compression_noise: f64,
    /// Unloading readings too, with this friction `h` (`None`: loading only).
    pub unload_friction: Option<f64>,
    /// Seed of the noise.
    pub seed: u64,
    /// Mesh edge length (m).
    pub spacing_m: f64,
}

impl SynthPlan {
    /// A plan for the default 10 cm x 6 cm swatch along every direction up to `max_stretch`.
    pub fn new(name: &str, max_stretch: f64) -> Self {
        Self {
            fabric: Fabric {
                name: name.into(),
                pattern: "stockinette".into(),
                swatch: Swatch::default(),
                yarn: vec![],
            },
            directions: Direction::ALL.to_vec(),
            max_stretch: vec![max_stretch; 3],
            readings: 60,
            force_noise_n: 0.0,
            compression_noise: 0.0,
            unload_friction: None,
            seed: 1,
            spacing_m: 0.005,
        }
    }
}

/// The readings of `material` under `plan`: loading, then unloading if asked for.
pub fn synthesize(material: &StvkNeoHookean, plan: &SynthPlan) -> Result<MeasurementSet, SwatchError> {
    let mut noise = Normal::new(plan.seed);
    let mut stretch = Vec::new();
    for (&direction, &s_max) in plan.directions.iter().zip(&plan.max_stretch) {
        let test = SwatchTest::new(direction, plan.fabric.swatch.specimen(direction), plan.spacing_m);
        let stretches: Vec<f64> =
            (1..=plan.readings).map(|k| s_max * k as f64 / plan.readings as f64).collect();
        let readings = test.run(material, &stretches)?;
        let f_max = readings.iter().map(|r| r.force_n).fold(0.0, f64::max);
        let mut point = |r: &SimulatedReading, force_n: f64, phase: Phase| StretchPoint {
            direction,
            stretch: r.stretch,
            force_n: force_n + plan.force_noise_n * noise.sample(),
            compression: Some(r.compression + plan.compression_noise * noise.sample()),
            phase,
            repeat: Some(1),
        };
        let load: Vec<StretchPoint> = readings.iter().map(|r| point(r, r.force_n, Phase::Load)).collect();
        stretch.extend(load);
        if let Some(h) = plan.unload_friction {
            let unload: Vec<StretchPoint> = readings
                .iter()
                .rev()
                .skip(1)
                .map(|r| point(r, (r.force_n - 2.0 * h * f_max).max(0.0), Phase::Unload))
                .collect();
            stretch.extend(unload);
        }
    }
    Ok(MeasurementSet { fabric: plan.fabric.clone(), stretch, bending: Vec::new() })
}

/// Standard normal samples: splitmix64 uniforms through Box-Muller (reproducible per seed on
/// every platform, no dependency).
struct Normal {
    state: u64,
    spare: Option<f64>,
}

impl Normal {
    fn new(seed: u64) -> Self {
        Self { state: seed, spare: None }
    }

    fn uniform(&mut self) -> f64 {
        self.state = self.state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        ((z >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }

    fn sample(&mut self) -> f64 {
        if let Some(s) = self.spare.take() {
            return s;
        }
        let (u, v) = (self.uniform(), self.uniform());
        let radius = (-2.0 * u.ln()).sqrt();
        let p = Vector2::new(
            radius * (std::f64::consts::TAU * v).cos(),
            radius * (std::f64::consts::TAU * v).sin(),
        );
        self.spare = Some(p.y);
        p.x
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normal_samples_have_unit_variance() {
        let mut n = Normal::new(7);
        let samples: Vec<f64> = (0..20000).map(|_| n.sample()).collect();
        let mean = samples.iter().sum::<f64>() / samples.len() as f64;
        let variance = samples.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / samples.len() as f64;
        assert!(mean.abs() < 0.03 && (variance - 1.0).abs() < 0.03, "{mean} {variance}");
    }
}
