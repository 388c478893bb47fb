//! A measurement set's bending tests, simulated together: the pear loops ([`super::pear_loop`])
//! and cantilevers ([`super::cantilever`], both faces) of its `bending.csv` and `cantilever.csv`,
//! their readings, and the normalized errors of simulated readings that the bending fit
//! minimizes and the diagnosis scores. Synthetic sets simulate their bending tests through it too.
//!
//! Residuals are each reading's error over the mean measured value of its test and direction
//! (the percentage error of Fig. 6.13); pear loops and cantilevers of one direction count
//! separately.
//!
//! The hinge energy's response depends on its mesh ([`yarnhom_shell::hinge`]: boundary edges
//! carry no hinge, and the strip's readings move by up to 20% between 1 cm and 1.25 mm edges),
//! so a fitted `k_θ` is the stiffness on one mesh: every bending test is simulated with edges
//! of [`BENDING_SPACING_M`], in fits and syntheses alike.

use rayon::prelude::*;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use yarnhom_geom::stats::root_mean_square;
use yarnhom_shell::{HingeBending, StvkNeoHookean};

use super::cantilever::CantileverTest;
use super::pear_loop::PearLoopTest;
use crate::data::set::{Direction, Face, MeasurementSet};

/// Edge length of every simulated bending strip (m).
pub const BENDING_SPACING_M: f64 = 0.005;

/// Why a set's bending tests cannot be simulated.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BendingTestsError {
    /// The set has no bending tests.
    #[error("the measurement set has no bending tests (bending.csv, cantilever.csv)")]
    NoTests,
    /// Weight against stiffness is what the tests measure: without the areal density only
    /// `k / ρ` is known.
    #[error(
        "the bending tests measure stiffness against weight: fabric.toml needs `swatch.areal_density_kg_m2`"
    )]
    NoDensity,
}

/// One bending test to simulate.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case", tag = "test")]
pub enum BendingTest {
    /// Pear loop: reads the aspect ratio.
    PearLoop {
        /// Direction.
        direction: Direction,
        /// Clamp distance (m).
        clamp_distance_m: f64,
    },
    /// Cantilever: reads the tip drop (m).
    Cantilever {
        /// Direction.
        direction: Direction,
        /// Face up.
        face: Face,
        /// Overhang (m).
        overhang_m: f64,
    },
}

impl BendingTest {
    /// The direction tested.
    pub fn direction(&self) -> Direction {
        match self {
            BendingTest::PearLoop { direction, .. } | BendingTest::Cantilever { direction, .. } => *direction,
        }
    }

    fn is_cantilever(&self) -> bool {
        matches!(self, BendingTest::Cantilever { .. })
    }
}

/// A set's bending tests with their readings.
#[derive(Debug, Clone, PartialEq)]
pub struct BendingTests {
    /// The tests, pear loops first, in file order.
    pub tests: Vec<BendingTest>,
    /// The measured readings (aspect ratio, or tip drop in m).
    pub measured: Vec<f64>,
    /// Each reading's normalizer: the mean |reading| of its test kind and direction.
    scale: Vec<f64>,
    /// Whether each reading is fitted (else held out).
    pub fitted: Vec<bool>,
    /// Pear-loop free length per direction (m), in [`Direction::ALL`] order.
    lengths_m: [f64; 3],
    areal_density_kg_m2: f64,
}

impl BendingTests {
    /// The bending tests of `set`; within each test kind, direction and face the `k`-th reading
    /// by abscissa is fitted when `fit(k)`.
    pub fn of_set(set: &MeasurementSet, fit: impl Fn(usize) -> bool) -> Result<Self, BendingTestsError> {
        if set.bending.is_empty() && set.cantilever.is_empty() {
            return Err(BendingTestsError::NoTests);
        }
        let areal_density_kg_m2 =
            set.fabric.swatch.areal_density_kg_m2.ok_or(BendingTestsError::NoDensity)?;
        let mut tests = Vec::new();
        let mut measured = Vec::new();
        for p in &set.bending {
            tests
                .push(BendingTest::PearLoop { direction: p.direction, clamp_distance_m: p.clamp_distance_m });
            measured.push(p.aspect_ratio);
        }
        for p in &set.cantilever {
            tests.push(BendingTest::Cantilever {
                direction: p.direction,
                face: p.face,
                overhang_m: p.overhang_m,
            });
            measured.push(p.tip_drop_m);
        }
        let scale = group_mean_magnitudes(&tests, &measured).into_iter().map(|m| m.max(1e-6)).collect();
        let lengths_m = Direction::ALL.map(|d| set.fabric.swatch.specimen(d).length_m);
        let mut tests =
            Self { fitted: vec![true; tests.len()], tests, measured, scale, lengths_m, areal_density_kg_m2 };
        for group in tests.groups() {
            for (rank, i) in group.into_iter().enumerate() {
                tests.fitted[i] = fit(rank);
            }
        }
        Ok(tests)
    }

    /// The directions with tests, and those with cantilever tests, in [`Direction::ALL`] order.
    pub(crate) fn directions(&self, cantilever_only: bool) -> Vec<Direction> {
        Direction::ALL
            .into_iter()
            .filter(|d| {
                self.tests.iter().any(|t| t.direction() == *d && (!cantilever_only || t.is_cantilever()))
            })
            .collect()
    }

    /// The simulated reading of every test (`None` if one has no equilibrium).
    pub fn simulate(&self, membrane: &StvkNeoHookean, bending: &HingeBending) -> Option<Vec<f64>> {
        Some(self.simulate_with_curvature(membrane, bending)?.into_iter().map(|(r, _)| r).collect())
    }

    /// The simulated reading of every test with the largest curvature along its strip (1/m).
    fn simulate_with_curvature(
        &self,
        membrane: &StvkNeoHookean,
        bending: &HingeBending,
    ) -> Option<Vec<(f64, f64)>> {
        self.tests
            .par_iter()
            .map(|t| match *t {
                BendingTest::PearLoop { direction, clamp_distance_m } => {
                    let length = self.lengths_m[Direction::ALL.iter().position(|d| *d == direction)?];
                    let test =
                        PearLoopTest::new(direction, length, self.areal_density_kg_m2, BENDING_SPACING_M);
                    let r = test.run(membrane, bending, &[clamp_distance_m]).ok()?[0];
                    Some((r.aspect_ratio, r.max_curvature_per_m))
                }
                BendingTest::Cantilever { direction, face, overhang_m } => {
                    let test = CantileverTest {
                        direction,
                        areal_density_kg_m2: self.areal_density_kg_m2,
                        spacing_m: BENDING_SPACING_M,
                    };
                    let r = test.run(membrane, bending, &[(face, overhang_m)]).ok()?[0];
                    Some((r.tip_drop_m, r.max_curvature_per_m))
                }
            })
            .collect()
    }

    /// The uniform bending targets `{κ, σ_κ}` of `bending` per tested direction (Sec. 6.3.2):
    /// `σ_κ = ∂Ψ/∂κ = 2 k_θ κ` (N) at `count` curvatures from 0 to the largest the simulated
    /// tests reach along that direction (`None` if a test has no equilibrium).
    pub fn uniform_targets(
        &self,
        membrane: &StvkNeoHookean,
        bending: &HingeBending,
        count: usize,
    ) -> Option<Vec<BendingTarget>> {
        let simulated = self.simulate_with_curvature(membrane, bending)?;
        let mut targets = Vec::new();
        for direction in self.directions(false) {
            let largest = self
                .tests
                .iter()
                .zip(&simulated)
                .filter(|(t, _)| t.direction() == direction)
                .map(|(_, (_, k))| *k)
                .fold(0.0, f64::max);
            let k = match direction {
                Direction::Weft => bending.k_weft,
                Direction::Bias => bending.k_bias,
                Direction::Warp => bending.k_warp,
            };
            targets.extend((0..count).map(|i| {
                let curvature_per_m = largest * i as f64 / (count.max(2) - 1) as f64;
                BendingTarget { direction, curvature_per_m, stress_n: 2.0 * k * curvature_per_m }
            }));
        }
        Some(targets)
    }

    /// The readings over their normalizers.
    pub fn normalized_readings(&self) -> Vec<f64> {
        self.measured.iter().zip(&self.scale).map(|(m, s)| m / s).collect()
    }

    /// Each test's abscissa: its clamp distance or overhang (m).
    pub fn abscissas(&self) -> Vec<f64> {
        self.tests
            .iter()
            .map(|t| match t {
                BendingTest::PearLoop { clamp_distance_m, .. } => *clamp_distance_m,
                BendingTest::Cantilever { overhang_m, .. } => *overhang_m,
            })
            .collect()
    }

    /// The readings' indices grouped by test kind, direction and face, each group in the order
    /// of its abscissa (clamp distance or overhang).
    pub fn groups(&self) -> Vec<Vec<usize>> {
        let key = |t: &BendingTest| match t {
            BendingTest::PearLoop { direction, .. } => (false, *direction, None),
            BendingTest::Cantilever { direction, face, .. } => (true, *direction, Some(*face)),
        };
        let abscissa = self.abscissas();
        let mut groups: Vec<Vec<usize>> = Vec::new();
        for (i, t) in self.tests.iter().enumerate() {
            match groups.iter_mut().find(|g| key(&self.tests[g[0]]) == key(t)) {
                Some(g) => g.push(i),
                None => groups.push(vec![i]),
            }
        }
        for g in &mut groups {
            g.sort_by(|a, b| abscissa[*a].total_cmp(&abscissa[*b]));
        }
        groups
    }

    /// Normalized residuals of `simulated` on the fitted (`fitted`) or the held-out readings.
    pub fn residuals(&self, simulated: &[f64], fitted: bool) -> Vec<f64> {
        (0..self.tests.len())
            .filter(|&i| self.fitted[i] == fitted)
            .map(|i| (simulated[i] - self.measured[i]) / self.scale[i])
            .collect()
    }

    /// RMS normalized error of `simulated` per direction and test kind, over every reading:
    /// `(direction, pear-loop error, cantilever error)`.
    pub fn errors_by_direction(&self, simulated: &[f64]) -> Vec<BendingDirectionError> {
        self.directions(false)
            .into_iter()
            .map(|direction| {
                let error = |cantilever: bool| {
                    let r: Vec<f64> = (0..self.tests.len())
                        .filter(|&i| {
                            self.tests[i].direction() == direction
                                && self.tests[i].is_cantilever() == cantilever
                        })
                        .map(|i| (simulated[i] - self.measured[i]) / self.scale[i])
                        .collect();
                    (!r.is_empty()).then(|| root_mean_square(r.iter().copied()))
                };
                BendingDirectionError { direction, pear_loop: error(false), cantilever: error(true) }
            })
            .collect()
    }
}

/// For each test, the mean `|value|` over the tests of its kind and direction.
pub fn group_mean_magnitudes(tests: &[BendingTest], values: &[f64]) -> Vec<f64> {
    tests
        .iter()
        .map(|t| {
            let same =
                |u: &BendingTest| u.is_cantilever() == t.is_cantilever() && u.direction() == t.direction();
            let group: Vec<f64> =
                tests.iter().zip(values).filter(|(u, _)| same(u)).map(|(_, v)| v.abs()).collect();
            group.iter().sum::<f64>() / group.len() as f64
        })
        .collect()
}

/// A uniform bending target (6.3): the bending stress at a curvature along a direction.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct BendingTarget {
    /// Direction bent.
    pub direction: Direction,
    /// Curvature `κ` (1/m).
    pub curvature_per_m: f64,
    /// Bending stress `σ_κ = ∂Ψ/∂κ` (N).
    pub stress_n: f64,
}

/// A direction's bending errors (RMS over the mean measured reading).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct BendingDirectionError {
    /// Direction.
    pub direction: Direction,
    /// Pear-loop aspect ratio error (absent without pear-loop tests).
    pub pear_loop: Option<f64>,
    /// Cantilever tip-drop error (absent without cantilever tests).
    pub cantilever: Option<f64>,
}
