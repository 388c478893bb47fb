//! A fabric strip held in clamps and loaded by its weight: the common ground of the bending
//! tests (the pear loop, clamped at both ends, and the cantilever, clamped at one).
//!
//! The strip lies along `a` in its frame, its material coordinates rotated by the direction's
//! angle (as the swatch of the stretch tests), so its hinges take the stiffness and rest curvature of the
//! direction it is cut along. A clamp holds two columns of vertices one edge apart, fixing the
//! end's position and tangent; the free length is measured between the clamps' inner columns
//! (arc length `0` at the first clamp, `length_m` at the second).
//!
//! A uniform strip's reading does not depend on its width (its weight and its bending stiffness
//! both scale with it), so the tests simulate a narrow strip: [`STRIP_WIDTH_M`].

use nalgebra::{Rotation2, Vector2, Vector3};
use yarnhom_shell::elastic::ElasticModel;
use yarnhom_shell::statics::{StaticError, StaticSettings, StaticStats, solve_static};
use yarnhom_shell::{HingeBending, ShellMaterial, ShellMesh, StvkNeoHookean};
use yarnhom_sparse::SpdSolver;

use super::uniform::direction_angle;
use crate::data::set::Direction;

/// Standard gravity (m/s²).
pub const GRAVITY: f64 = 9.81;

/// Width of the simulated strips (m): the readings are independent of it (within 0.5% of a 6 cm
/// strip's), and a narrow strip is seven times cheaper.
pub const STRIP_WIDTH_M: f64 = 0.01;

/// The hinge bending of per-direction stiffnesses `k_j` (J) and rest curvatures
/// `rest_curvature_per_m` (1/m), each given as one value for every direction or as three
/// (weft, bias, warp); `None` for any other count.
pub fn hinge_bending(k_j: &[f64], rest_curvature_per_m: &[f64]) -> Option<HingeBending> {
    let [k_weft, k_bias, k_warp] = Direction::per_direction(k_j)?;
    let [rest_curvature_weft, rest_curvature_bias, rest_curvature_warp] =
        Direction::per_direction(rest_curvature_per_m)?;
    Some(HingeBending {
        rest_curvature_weft,
        rest_curvature_bias,
        rest_curvature_warp,
        ..HingeBending::anisotropic(k_weft, k_bias, k_warp)
    })
}

/// Which ends are clamped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Clamps {
    /// Both ends (the pear loop).
    Both,
    /// The first end only; the other hangs free (the cantilever).
    First,
}

/// A meshed strip with its clamps.
#[derive(Debug, Clone)]
pub struct Strip {
    /// Direction of the strip's long axis.
    pub direction: Direction,
    /// Free length (m).
    pub length_m: f64,
    mesh: ShellMesh,
    /// Arc length of each vertex from the first clamp's inner column (negative inside it), and
    /// its position across the strip.
    pub arc: Vec<(f64, f64)>,
    fixed: Vec<bool>,
    areal_density_kg_m2: f64,
}

impl Strip {
    /// A strip of free length `length_m` cut along `direction`, of `areal_density_kg_m2`,
    /// meshed with edges of about `spacing_m`, clamped as `clamps` says.
    pub fn new(
        direction: Direction,
        length_m: f64,
        areal_density_kg_m2: f64,
        spacing_m: f64,
        clamps: Clamps,
    ) -> Self {
        let columns = ((length_m / spacing_m).round() as usize).max(8);
        let h = length_m / columns as f64;
        let rows = ((STRIP_WIDTH_M / spacing_m).round() as usize + 1).max(2);
        // One extra column inside each clamp: a clamp holds two columns.
        let clamped_columns = match clamps {
            Clamps::Both => 2,
            Clamps::First => 1,
        };
        let total = length_m + clamped_columns as f64 * h;
        let frame = ShellMesh::rectangle(total, STRIP_WIDTH_M, columns + 1 + clamped_columns, rows)
            .expect("a rectangle is a valid mesh");
        let rotation = Rotation2::new(direction_angle(direction));
        let material: Vec<Vector2<f64>> = frame.material.iter().map(|m| rotation * m).collect();
        let mesh =
            ShellMesh::new(material, frame.triangles.clone()).expect("a rotation keeps the mesh valid");
        let start = -0.5 * total + h;
        let arc: Vec<(f64, f64)> = frame.material.iter().map(|m| (m.x - start, m.y)).collect();
        let held = |s: f64| match clamps {
            Clamps::Both => s < 1e-9 * length_m || s > length_m * (1.0 - 1e-9),
            Clamps::First => s < 1e-9 * length_m,
        };
        let fixed = arc.iter().flat_map(|(s, _)| [held(*s); 3]).collect();
        Self { direction, length_m, mesh, arc, fixed, areal_density_kg_m2 }
    }

    /// The elastic model of the strip with `membrane` and `bending`.
    pub fn model(&self, membrane: &StvkNeoHookean, bending: &HingeBending) -> ElasticModel {
        ElasticModel::new(
            self.mesh.clone(),
            ShellMaterial::stvk(self.areal_density_kg_m2, *membrane, *bending),
        )
    }

    /// The vertices' weights (N).
    pub fn weights(&self) -> Vec<Vector3<f64>> {
        self.mesh
            .vertex_areas()
            .iter()
            .map(|a| Vector3::new(0.0, 0.0, -GRAVITY * a * self.areal_density_kg_m2))
            .collect()
    }

    /// The static equilibrium under the weights, from `x` (whose clamped vertices stay put).
    pub fn settle(
        &self,
        model: &ElasticModel,
        x: &mut [Vector3<f64>],
        weights: &[Vector3<f64>],
        solver: &mut SpdSolver,
    ) -> Result<StaticStats, StaticError> {
        let settings = StaticSettings { max_iterations: 300, tolerance_m: 1e-9 };
        solve_static(model, x, &self.fixed, weights, settings, solver)
    }

    /// The positions of the free vertices (arc length strictly inside `(0, length]`).
    pub fn free<'a>(&'a self, x: &'a [Vector3<f64>]) -> impl Iterator<Item = &'a Vector3<f64>> + 'a {
        x.iter()
            .zip(&self.arc)
            .filter(|(_, (s, _))| *s > 0.0 && *s < self.length_m * (1.0 - 1e-9))
            .map(|(p, _)| p)
    }

    /// The largest curvature (1/m) along the strip's centre line (the row of vertices nearest
    /// its middle): turning angle over mean edge length at each vertex.
    pub fn max_curvature(&self, x: &[Vector3<f64>]) -> f64 {
        let centre = self.arc.iter().map(|(_, across)| across.abs()).fold(f64::INFINITY, f64::min);
        let mut line: Vec<(f64, Vector3<f64>)> = x
            .iter()
            .zip(&self.arc)
            .filter(|(_, (_, across))| (across.abs() - centre).abs() < 1e-9)
            .map(|(p, (s, _))| (*s, *p))
            .collect();
        line.sort_by(|a, b| a.0.total_cmp(&b.0));
        line.windows(3)
            .map(|w| {
                let (a, b) = (w[1].1 - w[0].1, w[2].1 - w[1].1);
                a.angle(&b) / (0.5 * (a.norm() + b.norm()))
            })
            .fold(0.0, f64::max)
    }

    /// The positions of the vertices at the far end (arc length `length_m`).
    pub fn far_end<'a>(&'a self, x: &'a [Vector3<f64>]) -> impl Iterator<Item = &'a Vector3<f64>> + 'a {
        x.iter()
            .zip(&self.arc)
            .filter(|(_, (s, _))| (*s - self.length_m).abs() < 1e-9 * self.length_m)
            .map(|(p, _)| p)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hinge_bending_takes_one_value_for_every_direction_or_three() {
        assert_eq!(hinge_bending(&[2e-6], &[0.0]), Some(HingeBending::isotropic(2e-6)));
        let b = hinge_bending(&[3e-6, 2e-6, 1e-6], &[10.0]).expect("three and one");
        assert_eq!((b.k_weft, b.k_bias, b.k_warp), (3e-6, 2e-6, 1e-6));
        assert_eq!((b.rest_curvature_weft, b.rest_curvature_bias, b.rest_curvature_warp), (10.0, 10.0, 10.0));
        assert_eq!(hinge_bending(&[1e-6, 2e-6], &[0.0]), None);
        assert_eq!(hinge_bending(&[1e-6], &[]), None);
    }
}
