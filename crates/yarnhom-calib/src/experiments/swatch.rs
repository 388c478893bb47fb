//! The clamped stretch test, simulated (thesis Sec. 6.2.3, Fig. 6.4, and the simulation in the
//! loop of Sec. 6.3.1): a planar swatch held rigidly by two clamps at its ends, the clamps
//! pulled apart, the sides free, so the deformation is non-uniform (it necks in the middle and
//! not at the clamps, Fig. 6.2). The readings mirror the rig's: the clamp force along the pull,
//! the stretch between two markers on the pull axis (or the clamps), the compression between
//! two markers across the middle (or the free edges).
//!
//! The swatch lies in its own frame `(a, b)`: `a` along the pull, clamps at `a = ±L/2`. Its
//! material coordinates are that frame rotated by the test direction's angle from the weft, so
//! a bias swatch is cut at 45° from the material axes. The simulation is in-plane (every `z`
//! held at 0): the in-plane tests do not involve bending (Sec. 6.3.1).

use nalgebra::{Rotation2, Vector2, Vector3};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use yarnhom_shell::elastic::{Assembly, ElasticModel};
use yarnhom_shell::material::{FormsEnergy, ShellMaterial};
use yarnhom_shell::statics::{StaticError, StaticSettings, solve_static};
use yarnhom_shell::{ShellMesh, StvkNeoHookean};
use yarnhom_sparse::SpdSolver;

use super::uniform::direction_angle;
use crate::data::set::{Direction, Specimen};

/// A simulated reading of the stretch test.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct SimulatedReading {
    /// Stretch between the stretch markers.
    pub stretch: f64,
    /// Stretch between the clamps.
    pub clamp_stretch: f64,
    /// Clamp force along the pull (N).
    pub force_n: f64,
    /// Compression between the compression markers.
    pub compression: f64,
}

/// Why a simulated test failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SwatchError {
    /// The static solve failed.
    #[error(transparent)]
    Static(#[from] StaticError),
    /// The static solve did not converge.
    #[error(
        "{direction} swatch at clamp stretch {clamp_stretch:.4}: no equilibrium after {iterations} Newton iterations"
    )]
    NotConverged {
        /// Direction.
        direction: Direction,
        /// Clamp stretch.
        clamp_stretch: f64,
        /// Iterations taken.
        iterations: u32,
    },
    /// The marker stretch could not be matched.
    #[error(
        "{direction} swatch: the marker stretch {target:.4} is not reached (the material may be unstable)"
    )]
    Unreached {
        /// Direction.
        direction: Direction,
        /// The stretch asked for.
        target: f64,
    },
}

/// A point of the swatch, as the triangle holding it and its barycentric weights.
#[derive(Debug, Clone, Copy)]
struct Marker {
    vertices: [usize; 3],
    weights: [f64; 3],
}

impl Marker {
    fn position(&self, x: &[Vector3<f64>]) -> Vector3<f64> {
        (0..3).map(|k| self.weights[k] * x[self.vertices[k]]).sum()
    }
}

/// One direction's clamped swatch, meshed.
#[derive(Debug, Clone)]
pub struct SwatchTest {
    /// The direction of the pull.
    pub direction: Direction,
    /// The swatch.
    pub specimen: Specimen,
    mesh: ShellMesh,
    /// Rest positions in the swatch frame.
    rest: Vec<Vector3<f64>>,
    fixed: Vec<bool>,
    /// Vertices held by the `+a` clamp.
    pulled: Vec<usize>,
    stretch_markers: [Marker; 2],
    compression_markers: [Marker; 2],
}

impl SwatchTest {
    /// The swatch of `specimen` pulled along `direction`, meshed with edges of about
    /// `spacing_m` (at least 4 x 3 vertices).
    pub fn new(direction: Direction, specimen: Specimen, spacing_m: f64) -> Self {
        let (length, width) = (specimen.length_m, specimen.width_m);
        let nx = ((length / spacing_m).round() as usize + 1).max(4);
        let ny = ((width / spacing_m).round() as usize + 1).max(3);
        let frame = ShellMesh::rectangle(length, width, nx, ny).expect("a rectangle is a valid mesh");
        let rest: Vec<Vector3<f64>> = frame.material.iter().map(|m| Vector3::new(m.x, m.y, 0.0)).collect();
        let rotation = Rotation2::new(direction_angle(direction));
        let material: Vec<Vector2<f64>> = frame.material.iter().map(|m| rotation * m).collect();
        let mesh =
            ShellMesh::new(material, frame.triangles.clone()).expect("a rotation keeps the mesh valid");
        let clamp = |p: &Vector3<f64>| (p.x.abs() - 0.5 * length).abs() < 1e-9 * length;
        let mut fixed = vec![false; 3 * rest.len()];
        for (v, p) in rest.iter().enumerate() {
            fixed[3 * v + 2] = true;
            if clamp(p) {
                fixed[3 * v] = true;
                fixed[3 * v + 1] = true;
            }
        }
        let pulled = rest.iter().enumerate().filter(|(_, p)| clamp(p) && p.x > 0.0).map(|(v, _)| v).collect();
        let half_gauge = 0.5 * specimen.stretch_gauge_m.unwrap_or(length);
        let half_across = 0.5 * specimen.compression_gauge_m.unwrap_or(width);
        let marker = |a: f64, b: f64| locate(&frame, Vector2::new(a, b));
        Self {
            direction,
            specimen,
            stretch_markers: [marker(-half_gauge, 0.0), marker(half_gauge, 0.0)],
            compression_markers: [marker(0.0, -half_across), marker(0.0, half_across)],
            mesh,
            rest,
            fixed,
            pulled,
        }
    }

    /// Vertices of the mesh.
    pub fn vertex_count(&self) -> usize {
        self.rest.len()
    }

    /// Simulate the test of `material` at each of the marker `stretches` (increasing), each
    /// equilibrium warm-starting the next. The clamp stretch giving each marker stretch is
    /// found by secant steps.
    pub fn run(
        &self,
        material: &StvkNeoHookean,
        stretches: &[f64],
    ) -> Result<Vec<SimulatedReading>, SwatchError> {
        let model = ElasticModel::new(
            self.mesh.clone(),
            ShellMaterial {
                areal_density_kg_m2: 0.0,
                forms: FormsEnergy::Stvk(*material),
                hinge_bending: None,
            },
        );
        let mut state = State { x: self.rest.clone(), clamp_stretch: 0.0, solver: SpdSolver::default() };
        let mut readings = Vec::with_capacity(stretches.len());
        // Marker stretch per unit clamp stretch, from the last solve.
        let mut gain = 1.0;
        let mut last = (0.0, 0.0);
        for &target in stretches {
            let mut guess = last.1 + (target - last.0) / gain;
            let mut reading = self.solve(&model, &mut state, guess)?;
            let mut previous = last;
            for _ in 0..20 {
                let error = reading.stretch - target;
                if error.abs() <= 1e-6 * target.abs().max(1e-3) {
                    break;
                }
                let slope = (reading.stretch - previous.0) / (reading.clamp_stretch - previous.1);
                if !(slope.is_finite() && slope > 0.0) {
                    return Err(SwatchError::Unreached { direction: self.direction, target });
                }
                gain = slope;
                previous = (reading.stretch, reading.clamp_stretch);
                guess = reading.clamp_stretch - error / slope;
                reading = self.solve(&model, &mut state, guess)?;
            }
            if (reading.stretch - target).abs() > 1e-4 * target.abs().max(1e-2) {
                return Err(SwatchError::Unreached { direction: self.direction, target });
            }
            last = (reading.stretch, reading.clamp_stretch);
            readings.push(reading);
        }
        Ok(readings)
    }

    /// The equilibrium with the clamps at `clamp_stretch`, predicted from the current state by
    /// scaling its `a` coordinates.
    fn solve(
        &self,
        model: &ElasticModel,
        state: &mut State,
        clamp_stretch: f64,
    ) -> Result<SimulatedReading, SwatchError> {
        let scale = (1.0 + clamp_stretch) / (1.0 + state.clamp_stretch);
        for (v, p) in state.x.iter_mut().enumerate() {
            p.x *= scale;
            if self.fixed[3 * v] {
                p.x = self.rest[v].x * (1.0 + clamp_stretch);
                p.y = self.rest[v].y;
            }
        }
        state.clamp_stretch = clamp_stretch;
        let stats = solve_static(
            model,
            &mut state.x,
            &self.fixed,
            &[],
            StaticSettings::default(),
            &mut state.solver,
        )?;
        if !stats.converged {
            return Err(SwatchError::NotConverged {
                direction: self.direction,
                clamp_stretch,
                iterations: stats.iterations,
            });
        }
        Ok(self.read(model, &state.x, clamp_stretch))
    }

    /// The rig's readings of the equilibrium `x`.
    fn read(&self, model: &ElasticModel, x: &[Vector3<f64>], clamp_stretch: f64) -> SimulatedReading {
        let mut a = Assembly::new(3 * x.len());
        model.assemble(x, None, &mut a);
        let force_n: f64 = self.pulled.iter().map(|&v| a.gradient[3 * v]).sum();
        let distance = |m: &[Marker; 2]| (m[1].position(x) - m[0].position(x)).norm();
        let rest_distance = |m: &[Marker; 2]| (m[1].position(&self.rest) - m[0].position(&self.rest)).norm();
        SimulatedReading {
            stretch: distance(&self.stretch_markers) / rest_distance(&self.stretch_markers) - 1.0,
            clamp_stretch,
            force_n,
            compression: 1.0 - distance(&self.compression_markers) / rest_distance(&self.compression_markers),
        }
    }
}

/// A running simulated test: positions, clamp stretch, the factorization's symbolic analysis.
struct State {
    x: Vec<Vector3<f64>>,
    clamp_stretch: f64,
    solver: SpdSolver,
}

/// The triangle of `mesh` holding the point `p` of material space (the nearest if outside).
fn locate(mesh: &ShellMesh, p: Vector2<f64>) -> Marker {
    let mut best = (f64::INFINITY, Marker { vertices: [0; 3], weights: [1.0, 0.0, 0.0] });
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|v| mesh.material[v as usize]);
        let area = (b - a).perp(&(c - a));
        let wa = (b - p).perp(&(c - p)) / area;
        let wb = (c - p).perp(&(a - p)) / area;
        let wc = 1.0 - wa - wb;
        let outside = -[wa, wb, wc].into_iter().fold(f64::INFINITY, f64::min);
        if outside < best.0 {
            best = (outside, Marker { vertices: t.map(|v| v as usize), weights: [wa, wb, wc] });
        }
    }
    best.1
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::experiments::uniform::uniaxial;
    use crate::test_support::knit_membrane as material;

    fn specimen(length_m: f64, width_m: f64) -> Specimen {
        Specimen { length_m, width_m, stretch_gauge_m: None, compression_gauge_m: None }
    }

    #[test]
    fn a_long_narrow_swatch_matches_the_uniform_uniaxial_test() {
        // Far from the clamps a slender strip is in uniaxial stress: the force is the uniform
        // stress times the width, and the middle's compression is the uniform one (6.3). At
        // bias the uniform test allows no shear, so it is only uniaxial stress where the 45°
        // axes are material symmetry axes (k_xx = k_yy); otherwise a free strip shears.
        for direction in [Direction::Weft, Direction::Warp, Direction::Bias] {
            let material = match direction {
                Direction::Bias => StvkNeoHookean { k_yy: 120.0, ..material() },
                _ => material(),
            };
            let test = SwatchTest::new(direction, specimen(0.3, 0.02), 0.004);
            let stretches = [0.05, 0.15, 0.3];
            let readings = test.run(&material, &stretches).expect("runs");
            for (r, &s) in readings.iter().zip(&stretches) {
                assert!((r.stretch - s).abs() < 1e-4 * s.max(1e-2), "marker stretch matched");
                let u = uniaxial(&material, direction, s);
                let force = u.stress_n_m * 0.02;
                assert!(
                    (r.force_n - force).abs() < 0.06 * force,
                    "{direction} {s}: {} vs {force}",
                    r.force_n
                );
                assert!(
                    (r.compression - u.compression).abs() < 0.1 * u.compression.abs() + 2e-3,
                    "{direction} {s}: {} vs {}",
                    r.compression,
                    u.compression
                );
            }
        }
    }

    #[test]
    fn a_short_wide_swatch_is_stiffer_than_uniform_and_necks_less_at_its_gauge() {
        // The clamps stop the transverse contraction near them, so a square swatch needs more
        // force than the uniform test for the same clamp stretch (Fig. 6.2's non-uniformity).
        let test = SwatchTest::new(Direction::Weft, specimen(0.06, 0.06), 0.003);
        let r = test.run(&material(), &[0.2]).expect("runs")[0];
        let u = uniaxial(&material(), Direction::Weft, 0.2);
        assert!(r.force_n > 1.05 * u.stress_n_m * 0.06, "{} vs {}", r.force_n, u.stress_n_m * 0.06);
        assert!(r.compression < u.compression);
    }

    #[test]
    fn a_stretch_gauge_inside_the_swatch_reads_the_marker_distance() {
        let gauged =
            Specimen { stretch_gauge_m: Some(0.03), compression_gauge_m: Some(0.04), ..specimen(0.08, 0.06) };
        let test = SwatchTest::new(Direction::Warp, gauged, 0.004);
        let r = test.run(&material(), &[0.1]).expect("runs")[0];
        assert!((r.stretch - 0.1).abs() < 1e-5);
        // The middle stretches more than the clamped ends, so the clamps move less than the
        // markers' stretch alone would say.
        assert!(r.clamp_stretch < r.stretch, "{r:?}");
    }
}
