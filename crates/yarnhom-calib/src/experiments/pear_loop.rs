//! The pear-loop bending test (Peirce 1930; thesis Sec. 6.2.3, Fig. 6.4, and the bending fit of
//! Sec. 6.3.2), simulated: the swatch's two ends held in clamps that point the same way, the
//! clamps brought to a distance `d` much shorter than the swatch, so it forms a pear-shaped
//! loop hanging under its weight. The reading is the loop's aspect ratio `h / p`: its height
//! below the clamps over its largest width.
//!
//! Without gravity the loop's shape depends on `d / L` only (an elastica has no length scale);
//! its weight against its bending stiffness (the bending length `(B / w)^⅓`) sets how far it
//! sags, which is what the test measures.
//!
//! The strip ([`super::strip`]) is clamped at both ends. The loop starts from the shape
//! `θ(s) = α sin(2π s / L)` (tangent angle along the arc), whose ends are `L J₀(α)` apart with
//! horizontal tangents, `α` chosen so that this is `d`, hanging downwards; then the static
//! equilibrium with gravity is solved ([`yarnhom_shell::statics`]) with the (6.1) membrane and
//! the (6.4) hinges.
//!
//! A uniform rest curvature `κ̄` does not change the loop: the bending energy
//! `k ∫ (κ - κ̄)² ds = k ∫ κ² ds - 2 k κ̄ (θ(L) - θ(0)) + const`, and the clamps fix the
//! tangents at both ends. (A curling fabric shows in the cantilever test.)

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};
use yarnhom_shell::statics::StaticError;
use yarnhom_shell::{HingeBending, StvkNeoHookean};
use yarnhom_sparse::SpdSolver;

use super::strip::{Clamps, Strip};
use crate::data::set::Direction;

/// A simulated pear-loop reading.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
pub struct PearLoopReading {
    /// Clamp distance (m).
    pub clamp_distance_m: f64,
    /// Depth of the loop's lowest point below the clamps (m).
    pub height_m: f64,
    /// Largest horizontal width of the loop (m).
    pub width_m: f64,
    /// `height / width`.
    pub aspect_ratio: f64,
    /// Largest curvature along the strip's centre line (1/m).
    pub max_curvature_per_m: f64,
}

/// Why a simulated pear loop failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PearLoopError {
    /// The static solve failed.
    #[error(transparent)]
    Static(#[from] StaticError),
    /// No equilibrium.
    #[error(
        "{direction} pear loop at clamp distance {clamp_distance_m} m: no equilibrium after {iterations} Newton iterations"
    )]
    NotConverged {
        /// Direction.
        direction: Direction,
        /// Clamp distance.
        clamp_distance_m: f64,
        /// Iterations taken.
        iterations: u32,
    },
    /// The clamp distance is not shorter than the strip.
    #[error("a clamp distance of {clamp_distance_m} m does not form a loop of a {length_m} m strip")]
    NoLoop {
        /// Clamp distance.
        clamp_distance_m: f64,
        /// Free length.
        length_m: f64,
    },
}

/// One direction's pear-loop strip, meshed.
#[derive(Debug, Clone)]
pub struct PearLoopTest {
    strip: Strip,
}

impl PearLoopTest {
    /// A strip of free length `length_m` cut along `direction`, of `areal_density_kg_m2`,
    /// meshed with edges of about `spacing_m`.
    pub fn new(direction: Direction, length_m: f64, areal_density_kg_m2: f64, spacing_m: f64) -> Self {
        Self { strip: Strip::new(direction, length_m, areal_density_kg_m2, spacing_m, Clamps::Both) }
    }

    /// Simulate the loop at each clamp distance with the membrane and the hinge bending.
    pub fn run(
        &self,
        membrane: &StvkNeoHookean,
        bending: &HingeBending,
        clamp_distances_m: &[f64],
    ) -> Result<Vec<PearLoopReading>, PearLoopError> {
        let model = self.strip.model(membrane, bending);
        let weights = self.strip.weights();
        let mut solver = SpdSolver::default();
        clamp_distances_m
            .iter()
            .map(|&d| {
                let mut x = self.initial_loop(d)?;
                let stats = self.strip.settle(&model, &mut x, &weights, &mut solver)?;
                if !stats.converged {
                    return Err(PearLoopError::NotConverged {
                        direction: self.strip.direction,
                        clamp_distance_m: d,
                        iterations: stats.iterations,
                    });
                }
                Ok(self.read(&x, d))
            })
            .collect()
    }

    /// The starting loop for clamp distance `d`: `θ(s) = α sin(2π s / L)` with `L J₀(α) = d`,
    /// hanging downwards; the clamped columns straight along `x`.
    fn initial_loop(&self, d: f64) -> Result<Vec<Vector3<f64>>, PearLoopError> {
        let length = self.strip.length_m;
        if !(d > 0.0 && d < length) {
            return Err(PearLoopError::NoLoop { clamp_distance_m: d, length_m: length });
        }
        let alpha = bisect(|a| mean_cos(a) - d / length, 0.0, 2.404_825_557_695_773);
        // The curve sampled finely: (x, z) at arc lengths k L / n.
        let n = 4000;
        let mut curve = vec![(0.0, 0.0); n + 1];
        for k in 1..=n {
            let mid = (k as f64 - 0.5) / n as f64;
            let theta = alpha * (std::f64::consts::TAU * mid).sin();
            let (x, z) = curve[k - 1];
            curve[k] = (x + theta.cos() * length / n as f64, z - theta.sin() * length / n as f64);
        }
        let at = |s: f64| {
            let t = (s / length).clamp(0.0, 1.0) * n as f64;
            let k = (t.floor() as usize).min(n - 1);
            let f = t - k as f64;
            let (a, b) = (curve[k], curve[k + 1]);
            (a.0 + f * (b.0 - a.0), a.1 + f * (b.1 - a.1))
        };
        let x0 = -0.5 * d;
        Ok(self
            .strip
            .arc
            .iter()
            .map(|&(s, across)| {
                let (x, z) = if s < 0.0 {
                    (s, 0.0)
                } else if s > length {
                    (curve[n].0 + (s - length), curve[n].1)
                } else {
                    at(s)
                };
                Vector3::new(x0 + x, across, z)
            })
            .collect())
    }

    fn read(&self, x: &[Vector3<f64>], d: f64) -> PearLoopReading {
        let free = || self.strip.free(x);
        let height_m = -free().map(|p| p.z).fold(f64::INFINITY, f64::min);
        let (lo, hi) = free().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| (a.min(p.x), b.max(p.x)));
        let width_m = hi - lo;
        PearLoopReading {
            clamp_distance_m: d,
            height_m,
            width_m,
            aspect_ratio: height_m / width_m,
            max_curvature_per_m: self.strip.max_curvature(x),
        }
    }
}

/// `J₀(α) = (1/2π) ∫ cos(α sin t) dt` over a period (the midpoint rule is spectrally accurate
/// for periodic integrands).
fn mean_cos(alpha: f64) -> f64 {
    let n = 256;
    (0..n).map(|k| (alpha * (std::f64::consts::TAU * (k as f64 + 0.5) / n as f64).sin()).cos()).sum::<f64>()
        / n as f64
}

/// The root of a decreasing `f` in `[lo, hi]` by bisection.
fn bisect(f: impl Fn(f64) -> f64, mut lo: f64, mut hi: f64) -> f64 {
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if f(mid) > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::knit_membrane;

    fn bending(k: f64) -> HingeBending {
        HingeBending::isotropic(k)
    }

    #[test]
    fn the_starting_loop_has_the_clamp_distance_and_the_strip_length() {
        assert!((mean_cos(0.0) - 1.0).abs() < 1e-15 && mean_cos(2.404_825_557_695_773).abs() < 1e-12);
        let test = PearLoopTest::new(Direction::Weft, 0.1, 0.2, 0.004);
        let x = test.initial_loop(0.02).expect("a loop");
        let ends: Vec<f64> = x
            .iter()
            .zip(&test.strip.arc)
            .filter(|(_, (s, _))| s.abs() < 1e-12 || (s - 0.1).abs() < 1e-12)
            .map(|(p, _)| p.x)
            .collect();
        let (lo, hi) =
            ends.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| (a.min(*x), b.max(*x)));
        assert!((hi - lo - 0.02).abs() < 1e-4, "clamp distance {}", hi - lo);
    }

    #[test]
    fn a_stiffer_or_lighter_strip_sags_less() {
        let test = PearLoopTest::new(Direction::Weft, 0.1, 0.2, 0.005);
        let distances = [0.01, 0.03];
        let soft = test.run(&knit_membrane(), &bending(2e-6), &distances).expect("equilibrium");
        let stiff = test.run(&knit_membrane(), &bending(2e-5), &distances).expect("equilibrium");
        for (s, t) in soft.iter().zip(&stiff) {
            assert!(s.aspect_ratio > t.aspect_ratio, "softer sags more: {s:?} vs {t:?}");
            assert!(t.height_m > 0.0 && t.width_m > 0.0);
        }
        // Clamps farther apart make a wider, rounder loop.
        assert!(soft[1].width_m > soft[0].width_m && soft[1].aspect_ratio < soft[0].aspect_ratio);
        // Without weight the shape is the elastica's and does not depend on the stiffness.
        let weightless = PearLoopTest::new(Direction::Weft, 0.1, 1e-9, 0.005);
        let a = weightless.run(&knit_membrane(), &bending(2e-6), &[0.02]).expect("equilibrium")[0];
        let b = weightless.run(&knit_membrane(), &bending(2e-5), &[0.02]).expect("equilibrium")[0];
        assert!((a.aspect_ratio - b.aspect_ratio).abs() < 0.01 * a.aspect_ratio, "{a:?} vs {b:?}");
    }

    #[test]
    fn a_uniform_rest_curvature_does_not_change_the_loop() {
        let test = PearLoopTest::new(Direction::Warp, 0.1, 0.25, 0.005);
        let flat = test.run(&knit_membrane(), &bending(1e-6), &[0.005, 0.02]).expect("equilibrium");
        let curled = HingeBending { rest_curvature_warp: 40.0, rest_curvature_bias: 40.0, ..bending(1e-6) };
        let curled = test.run(&knit_membrane(), &curled, &[0.005, 0.02]).expect("equilibrium");
        for (f, c) in flat.iter().zip(&curled) {
            assert!((f.aspect_ratio - c.aspect_ratio).abs() < 0.01 * f.aspect_ratio, "{f:?} vs {c:?}");
        }
    }
}
