//! Synthetic measurement sets: the clamped stretch tests of a known membrane simulated
//! ([`crate::swatch`]) at evenly spaced stretches, with Gaussian noise on the force and the
//! compression, written as a real set would be. Fits run on these must recover the membrane.

use nalgebra::Vector2;
use yarnhom_shell::StvkNeoHookean;

use crate::measure::{Direction, Fabric, MeasurementSet, Phase, StretchPoint, Swatch};
use crate::swatch::{SwatchError, SwatchTest};

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
            seed: 1,
            spacing_m: 0.005,
        }
    }
}

/// The loading readings of `material` under `plan`.
pub fn synthesize(material: &StvkNeoHookean, plan: &SynthPlan) -> Result<MeasurementSet, SwatchError> {
    let mut noise = Normal::new(plan.seed);
    let mut stretch = Vec::new();
    for (&direction, &s_max) in plan.directions.iter().zip(&plan.max_stretch) {
        let test = SwatchTest::new(direction, plan.fabric.swatch.specimen(direction), plan.spacing_m);
        let stretches: Vec<f64> =
            (1..=plan.readings).map(|k| s_max * k as f64 / plan.readings as f64).collect();
        for r in test.run(material, &stretches)? {
            stretch.push(StretchPoint {
                direction,
                stretch: r.stretch,
                force_n: r.force_n + plan.force_noise_n * noise.sample(),
                compression: Some(r.compression + plan.compression_noise * noise.sample()),
                phase: Phase::Load,
                repeat: Some(1),
            });
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
