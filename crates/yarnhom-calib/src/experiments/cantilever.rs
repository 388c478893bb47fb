//! The cantilever bending test (Peirce 1930; ASTM D1388), simulated: a strip held flat at one
//! end, its free length overhanging and drooping under its weight. The reading is the drop of
//! the free end below the clamp.
//!
//! The test is run with the fabric's reference face up and face down, because a fabric that
//! curls (a rest curvature `κ̄`, positive towards the reference face) droops differently on its
//! two faces, and its clamped-clamped pear loop cannot show it (the clamps fix both end tangents). Turning
//! the strip over negates its rest curvature relative to gravity, which is how face down is
//! simulated.
//!
//! The strip ([`super::strip`]) starts flat and settles under its weight with the (6.1)
//! membrane and the (6.4) hinges; when the full weight gives no equilibrium from flat (a soft,
//! long overhang), the weight is ramped up in steps.

use nalgebra::Vector3;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use yarnhom_shell::statics::StaticError;
use yarnhom_shell::{HingeBending, StvkNeoHookean};
use yarnhom_sparse::SpdSolver;

use super::strip::{Clamps, Strip};
use crate::data::set::{Direction, Face};

/// A simulated cantilever reading.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct CantileverReading {
    /// Which face was up.
    pub face: Face,
    /// Free length beyond the clamp (m).
    pub overhang_m: f64,
    /// Drop of the free end's middle below the clamp (m; negative when it curls up).
    pub tip_drop_m: f64,
    /// Largest curvature along the strip's centre line (1/m).
    pub max_curvature_per_m: f64,
}

/// Why a simulated cantilever failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CantileverError {
    /// The static solve failed.
    #[error(transparent)]
    Static(#[from] StaticError),
    /// No equilibrium even with the weight ramped up.
    #[error("{direction} cantilever of overhang {overhang_m} m, face {face}: no equilibrium")]
    NotConverged {
        /// Direction.
        direction: Direction,
        /// Overhang.
        overhang_m: f64,
        /// Face up.
        face: Face,
    },
}

/// One direction's cantilever test.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CantileverTest {
    /// Direction of the strip's long axis.
    pub direction: Direction,
    /// Areal density (kg/m²).
    pub areal_density_kg_m2: f64,
    /// Mesh edge length (m).
    pub spacing_m: f64,
}

/// Fractions of the weight tried, in turn, when the full weight fails from flat.
const WEIGHT_RAMP: [f64; 4] = [0.125, 0.25, 0.5, 1.0];

impl CantileverTest {
    /// Simulate the strip at each `(face, overhang)`.
    pub fn run(
        &self,
        membrane: &StvkNeoHookean,
        bending: &HingeBending,
        tests: &[(Face, f64)],
    ) -> Result<Vec<CantileverReading>, CantileverError> {
        tests.iter().map(|&(face, overhang_m)| self.run_one(membrane, bending, face, overhang_m)).collect()
    }

    fn run_one(
        &self,
        membrane: &StvkNeoHookean,
        bending: &HingeBending,
        face: Face,
        overhang_m: f64,
    ) -> Result<CantileverReading, CantileverError> {
        let strip =
            Strip::new(self.direction, overhang_m, self.areal_density_kg_m2, self.spacing_m, Clamps::First);
        let model = strip.model(membrane, &face_up_bending(bending, face));
        let weights = strip.weights();
        let flat: Vec<Vector3<f64>> =
            strip.arc.iter().map(|&(s, across)| Vector3::new(s, across, 0.0)).collect();
        let mut solver = SpdSolver::default();
        let mut x = flat.clone();
        let converged = strip.settle(&model, &mut x, &weights, &mut solver)?.converged || {
            x = flat;
            let mut all = true;
            for fraction in WEIGHT_RAMP {
                let scaled: Vec<Vector3<f64>> = weights.iter().map(|w| w * fraction).collect();
                all = strip.settle(&model, &mut x, &scaled, &mut solver)?.converged;
            }
            all
        };
        if !converged {
            return Err(CantileverError::NotConverged { direction: self.direction, overhang_m, face });
        }
        let (sum, count) = strip.far_end(&x).fold((0.0, 0), |(s, n), p| (s + p.z, n + 1));
        Ok(CantileverReading {
            face,
            overhang_m,
            tip_drop_m: -sum / count as f64,
            max_curvature_per_m: strip.max_curvature(&x),
        })
    }
}

/// The bending of a strip lying with `face` up: face down turns the rest curvatures over.
fn face_up_bending(bending: &HingeBending, face: Face) -> HingeBending {
    match face {
        Face::Up => *bending,
        Face::Down => HingeBending {
            rest_curvature_weft: -bending.rest_curvature_weft,
            rest_curvature_bias: -bending.rest_curvature_bias,
            rest_curvature_warp: -bending.rest_curvature_warp,
            ..*bending
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::knit_membrane;

    fn test(direction: Direction) -> CantileverTest {
        CantileverTest { direction, areal_density_kg_m2: 0.25, spacing_m: 0.005 }
    }

    #[test]
    fn a_flat_stiff_strip_droops_like_a_clamped_beam() {
        // Small deflection of a clamped beam under its weight: δ = q L⁴ / (8 B), so twice the
        // overhang, meshed with the same number of edges, droops 16 times as far.
        let bending = HingeBending::isotropic(2e-3);
        let drop = |overhang: f64| {
            let test = CantileverTest { spacing_m: 0.00125, ..test(Direction::Weft) };
            test.run(&knit_membrane(), &bending, &[(Face::Up, overhang)]).expect("equilibrium")[0].tip_drop_m
        };
        let (short, long) = (drop(0.04), drop(0.08));
        assert!((long / short / 16.0 - 1.0).abs() < 0.02, "drops {short} and {long} m");
        assert!(long < 0.03 * 0.08, "small deflection: {long} m");
    }

    #[test]
    fn a_curling_fabric_droops_differently_on_its_two_faces() {
        let flat = HingeBending::isotropic(2e-6);
        let curled = HingeBending {
            rest_curvature_weft: 30.0,
            rest_curvature_bias: 30.0,
            rest_curvature_warp: 30.0,
            ..flat
        };
        let tests = [(Face::Up, 0.05), (Face::Down, 0.05)];
        let flat = test(Direction::Weft).run(&knit_membrane(), &flat, &tests).expect("equilibrium");
        let curled = test(Direction::Weft).run(&knit_membrane(), &curled, &tests).expect("equilibrium");
        assert!((flat[0].tip_drop_m - flat[1].tip_drop_m).abs() < 1e-6 * flat[0].tip_drop_m, "{flat:?}");
        // Face up it curls up against its weight: less drop; face down more.
        assert!(
            curled[0].tip_drop_m < flat[0].tip_drop_m && curled[1].tip_drop_m > flat[1].tip_drop_m,
            "{curled:?} vs {flat:?}"
        );
    }

    #[test]
    fn a_soft_long_overhang_droops_far_and_still_settles() {
        let r = test(Direction::Bias)
            .run(&knit_membrane(), &HingeBending::isotropic(2e-7), &[(Face::Up, 0.1)])
            .expect("equilibrium");
        assert!(r[0].tip_drop_m > 0.05, "{r:?}");
    }
}
