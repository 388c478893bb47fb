//! Synthetic measurement sets: the clamped stretch tests of a known membrane simulated
//! ([`super::swatch`]) at evenly spaced stretches, with Gaussian noise on the force and the
//! compression, and, if asked for, its bending tests (pear loops and cantilevers on both faces,
//! [`super::bending_tests`]) with noise on their readings; written as a real set would be. Fits
//! run on these must recover the truth, and a diagnosis must find the effect hidden in it
//! ([`HiddenEffect`], [`ground_truth`]; [`SynthRequest`] is the set `calibrate synth` writes).

use nalgebra::Vector2;
use yarnhom_shell::{HingeBending, Stiffening, StvkNeoHookean};

use super::bending_tests::{BendingTests, group_mean_magnitudes};
use super::swatch::{SimulatedReading, SwatchError, SwatchTest};
use crate::data::set::{
    BendingPoint, CantileverPoint, Direction, Fabric, Face, MeasurementSet, Phase, StretchPoint, Swatch,
};

/// An effect hidden in a synthetic set, beyond the plain anisotropic StVK base.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum HiddenEffect {
    /// Nothing: the base model is the truth.
    None,
    /// The Neo-Hookean area terms of (6.1).
    AreaPreservation,
    /// Stiffening past an onset strain.
    ///
    /// See [`yarnhom_shell::Stiffening`].
    BiphasicStretch,
    /// Jamming past an onset compression, the shell-level trace of two-phase yarn contact: the
    /// contraction across the pull stops growing near 2%.
    ///
    /// See [`StvkNeoHookean::jamming`].
    TwoPhaseContact,
    /// Unloading readings below loading: a friction force `2 h f_max` opposes the unloading
    /// swatch (a constant offset, not the multiplicative form the diagnosis fits).
    FrictionHysteresis,
    /// The fabric curls: a rest curvature in every direction.
    RestCurvature,
    /// Bending stiffness differs by direction (weft stiffer than warp).
    AnisotropicBending,
    /// Off the diagnosis' catalog: the fabric softens past an onset strain, so the force rises
    /// slower than any strain-independent membrane allows; an honest diagnosis says
    /// `unexplained`.
    ///
    /// A negative [`Stiffening`] taking 70% of the weft and warp stiffness away.
    Softening,
}

/// The truth of a synthetic set.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct GroundTruth {
    /// The membrane (6.1).
    pub membrane: StvkNeoHookean,
    /// Friction `h` of the unloading readings (0 without hysteresis).
    pub unload_friction: f64,
    /// The hinge bending (6.4).
    pub bending: HingeBending,
}

impl GroundTruth {
    /// `membrane` with no friction and the base truth's isotropic flat bending.
    pub fn of_membrane(membrane: StvkNeoHookean) -> Self {
        Self { membrane, unload_friction: 0.0, bending: HingeBending::isotropic(BASE_BENDING_J) }
    }
}

/// Bending stiffness of the base truth (J): a soft knit, whose pear loop responds to it.
const BASE_BENDING_J: f64 = 1e-6;

/// The membrane of the base truth: a knit-like anisotropic StVK (weft 60, warp 25 J/m²).
const BASE_MEMBRANE: StvkNeoHookean = StvkNeoHookean {
    k_xx: 60.0,
    k_xy: 6.0,
    k_yy: 25.0,
    k_ss: 10.0,
    k_n1: 0.0,
    k_n2: 0.0,
    stiffening: None,
    jamming: None,
};

/// The truth of a synthetic set: a knit-like anisotropic StVK (weft 60, warp 25 J/m²) and an
/// isotropic, flat bending of 1e-6 J, with `effect` at `strength` (1: clearly visible at 2%
/// noise).
pub fn ground_truth(effect: HiddenEffect, strength: f64) -> GroundTruth {
    let base = GroundTruth::of_membrane(BASE_MEMBRANE);
    match effect {
        HiddenEffect::None => base,
        HiddenEffect::FrictionHysteresis => GroundTruth { unload_friction: 0.08 * strength, ..base },
        HiddenEffect::RestCurvature | HiddenEffect::AnisotropicBending => {
            GroundTruth { bending: hidden_bending(effect, strength), ..base }
        }
        HiddenEffect::AreaPreservation
        | HiddenEffect::BiphasicStretch
        | HiddenEffect::TwoPhaseContact
        | HiddenEffect::Softening => GroundTruth { membrane: hidden_membrane(effect, strength), ..base },
    }
}

/// The base membrane with a membrane `effect` at `strength`.
fn hidden_membrane(effect: HiddenEffect, strength: f64) -> StvkNeoHookean {
    let membrane = BASE_MEMBRANE;
    match effect {
        HiddenEffect::AreaPreservation => {
            StvkNeoHookean { k_n1: 40.0 * strength, k_n2: 40.0 * strength, ..membrane }
        }
        HiddenEffect::BiphasicStretch => StvkNeoHookean {
            stiffening: Some(Stiffening { k_weft: 240.0 * strength, k_warp: 100.0 * strength, onset: 0.08 }),
            ..membrane
        },
        HiddenEffect::TwoPhaseContact => StvkNeoHookean {
            jamming: Some(Stiffening { k_weft: 400.0 * strength, k_warp: 400.0 * strength, onset: 0.02 }),
            ..membrane
        },
        HiddenEffect::Softening => StvkNeoHookean {
            stiffening: Some(Stiffening {
                k_weft: -0.7 * strength.min(1.0) * membrane.k_xx,
                k_warp: -0.7 * strength.min(1.0) * membrane.k_yy,
                onset: 0.03,
            }),
            ..membrane
        },
        _ => membrane,
    }
}

/// The base truth's isotropic flat bending with a bending `effect` at `strength`.
fn hidden_bending(effect: HiddenEffect, strength: f64) -> HingeBending {
    let base = HingeBending::isotropic(BASE_BENDING_J);
    match effect {
        HiddenEffect::RestCurvature => {
            let curl = 25.0 * strength;
            HingeBending {
                rest_curvature_weft: curl,
                rest_curvature_bias: curl,
                rest_curvature_warp: curl,
                ..base
            }
        }
        HiddenEffect::AnisotropicBending => HingeBending::anisotropic(
            BASE_BENDING_J * (1.0 + 3.0 * strength),
            BASE_BENDING_J * (1.0 + 1.5 * strength),
            BASE_BENDING_J,
        ),
        _ => base,
    }
}

/// The bending tests of a synthetic set.
#[derive(Debug, Clone, PartialEq)]
pub struct BendingPlan {
    /// Pear-loop clamp distances (m), per direction.
    pub clamp_distances_m: Vec<f64>,
    /// Cantilever overhangs (m), per direction and face.
    pub overhangs_m: Vec<f64>,
    /// Standard deviation of the reading noise, as a fraction of the mean clean reading of its
    /// test and direction.
    pub noise: f64,
}

impl Default for BendingPlan {
    /// The thesis' 7 clamp distances from 0.3 to 3.4 cm (Sec. 6.3.2), and 7 overhangs from 0.8
    /// to 3.2 cm, around the bending length `(2k/ρg)^⅓` of soft knits (about 1 cm), where the
    /// cantilever is sensitive (ASTM D1388 reads the overhang whose tip dips 41.5°, about twice
    /// the bending length); no noise.
    fn default() -> Self {
        Self {
            clamp_distances_m: (0..7).map(|k| 0.003 + 0.031 * k as f64 / 6.0).collect(),
            overhangs_m: (0..7).map(|k| 0.008 + 0.004 * k as f64).collect(),
            noise: 0.0,
        }
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
    /// Unloading readings too (with the truth's friction).
    pub unload: bool,
    /// Bending tests too (the fabric's areal density must be set).
    pub bending: Option<BendingPlan>,
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
                stitch: None,
                yarn: vec![],
            },
            directions: Direction::ALL.to_vec(),
            max_stretch: vec![max_stretch; 3],
            readings: 60,
            force_noise_n: 0.0,
            compression_noise: 0.0,
            unload: false,
            bending: None,
            seed: 1,
            spacing_m: 0.005,
        }
    }
}

/// Why a synthetic set could not be made.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SynthError {
    /// A stretch test failed.
    #[error(transparent)]
    Swatch(#[from] SwatchError),
    /// A bending test has no equilibrium, or the plan has no areal density.
    #[error("the bending tests of the truth cannot be simulated: {0}")]
    Bending(String),
}

/// The readings of `truth` under `plan`: loading, then unloading and bending tests if asked
/// for.
pub fn synthesize(truth: &GroundTruth, plan: &SynthPlan) -> Result<MeasurementSet, SynthError> {
    let material = &truth.membrane;
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
        if plan.unload {
            let h = truth.unload_friction;
            let unload: Vec<StretchPoint> = readings
                .iter()
                .rev()
                .skip(1)
                .map(|r| point(r, (r.force_n - 2.0 * h * f_max).max(0.0), Phase::Unload))
                .collect();
            stretch.extend(unload);
        }
    }
    let mut set =
        MeasurementSet { fabric: plan.fabric.clone(), stretch, bending: Vec::new(), cantilever: Vec::new() };
    if let Some(bending) = &plan.bending {
        add_bending_tests(&mut set, truth, plan, bending, &mut noise)?;
    }
    Ok(set)
}

/// Simulate the bending tests of `bending` along the plan's directions and add them to `set`.
fn add_bending_tests(
    set: &mut MeasurementSet,
    truth: &GroundTruth,
    plan: &SynthPlan,
    bending: &BendingPlan,
    noise: &mut Normal,
) -> Result<(), SynthError> {
    for &direction in &plan.directions {
        set.bending.extend(bending.clamp_distances_m.iter().map(|&clamp_distance_m| BendingPoint {
            direction,
            clamp_distance_m,
            aspect_ratio: 1.0,
        }));
        for face in Face::ALL {
            set.cantilever.extend(bending.overhangs_m.iter().map(|&overhang_m| CantileverPoint {
                direction,
                face,
                overhang_m,
                tip_drop_m: 0.0,
            }));
        }
    }
    let tests = BendingTests::of_set(set, |_| true).map_err(|e| SynthError::Bending(e.to_string()))?;
    let clean = tests
        .simulate(&truth.membrane, &truth.bending)
        .ok_or_else(|| SynthError::Bending("a test has no equilibrium".into()))?;
    let scale = group_mean_magnitudes(&tests.tests, &clean);
    let noisy: Vec<f64> =
        clean.iter().zip(&scale).map(|(r, m)| r + bending.noise * m * noise.sample()).collect();
    let (pear, cantilever) = noisy.split_at(set.bending.len());
    for (p, r) in set.bending.iter_mut().zip(pear) {
        p.aspect_ratio = *r;
    }
    for (p, r) in set.cantilever.iter_mut().zip(cantilever) {
        p.tip_drop_m = r.clamp(-p.overhang_m, p.overhang_m);
    }
    Ok(())
}

/// Areal density of synthetic sets with bending tests (kg/m²): a mid-weight knit.
pub const SYNTH_AREAL_DENSITY_KG_M2: f64 = 0.25;

/// The synthetic set `yarnhom calibrate synth` writes: `effect` hidden at `strength`, 120
/// loading and unloading readings per direction up to `max_stretch`, the noise `noise` times the
/// clean set's mean |force| and mean |compression|, and the bending tests
/// ([`BendingPlan::default`], the same relative noise, [`SYNTH_AREAL_DENSITY_KG_M2`]) when
/// asked for or when the effect is a bending one.
#[derive(Debug, Clone, PartialEq)]
pub struct SynthRequest {
    /// The fabric's name.
    pub name: String,
    /// The effect hidden in the data.
    pub effect: HiddenEffect,
    /// Its strength (1: clearly visible at 2% noise).
    pub strength: f64,
    /// Standard deviation of the noise, as a fraction of the mean clean value.
    pub noise: f64,
    /// Seed of the noise.
    pub seed: u64,
    /// Largest stretch of every direction.
    pub max_stretch: f64,
    /// Bending tests too.
    pub bending_tests: bool,
}

impl SynthRequest {
    /// The truth and its noisy set (the clean set is simulated first, to scale the noise).
    pub fn synthesize(&self) -> Result<(GroundTruth, MeasurementSet), SynthError> {
        let truth = ground_truth(self.effect, self.strength);
        let bending_tests = self.bending_tests
            || matches!(self.effect, HiddenEffect::RestCurvature | HiddenEffect::AnisotropicBending);
        let mut clean_plan = SynthPlan {
            readings: 120,
            unload: true,
            bending: bending_tests.then(|| BendingPlan { noise: self.noise, ..BendingPlan::default() }),
            ..SynthPlan::new(&self.name, self.max_stretch)
        };
        if bending_tests {
            clean_plan.fabric.swatch.areal_density_kg_m2 = Some(SYNTH_AREAL_DENSITY_KG_M2);
        }
        let clean = synthesize(&truth, &clean_plan)?;
        let mean = |f: &dyn Fn(&StretchPoint) -> f64| {
            clean.stretch.iter().map(|p| f(p).abs()).sum::<f64>() / clean.stretch.len() as f64
        };
        let plan = SynthPlan {
            force_noise_n: self.noise * mean(&|p| p.force_n),
            compression_noise: self.noise * mean(&|p| p.compression.unwrap_or(0.0)),
            seed: self.seed,
            ..clean_plan
        };
        Ok((truth, synthesize(&truth, &plan)?))
    }
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
