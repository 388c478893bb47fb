//! The homogenized response of a swatch's interior, measured yarn by yarn, to compare with the
//! periodic tile's (`rve solve`, thesis Sec. 3.2): the interior's in-plane strain and its stored
//! energy per unit rest area.
//!
//! - The interior is a block of whole tile copies ([`Swatch::source_tile`]). Each copy holds one
//!   copy of every vertex of the tile, so the energy the copies' vertices carry
//!   ([`crate::dynamics::Simulation::vertex_energies_j`]) over the block's rest area is the
//!   tile's energy density (3.22) wherever the interior deforms periodically.
//! - Its strain is that of the deformation gradient `F` (3 x 2) of the least-squares affine map
//!   `x ≈ F X + c` from the vertices' rest positions `X` to their positions `x`:
//!   `I = FᵀF`, `sx = √I11 - 1`, `sa = I12 / √(I11 I22)`, `sy = √I22 - 1` (4.1).

use std::ops::Range;

use nalgebra::{Matrix3, Matrix3x2, Vector3};
use yarnhom_artifacts::Swatch;
use yarnhom_geom::{InPlaneStrain, StrainError};

/// A block of whole tile copies of a swatch: tiles `(i, j)` with `i` in `tiles[0]` and `j` in
/// `tiles[1]`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Interior {
    /// Tile ranges along X1 and X2.
    pub tiles: [Range<i32>; 2],
}

impl Interior {
    /// The block of a swatch of `tiles` whole tiles per side without `border` tiles along each
    /// side; `None` if nothing is left.
    pub fn inset(tiles: [u32; 2], border: u32) -> Option<Interior> {
        let range = |n: u32| (border < n.saturating_sub(border)).then(|| border as i32..(n - border) as i32);
        Some(Interior { tiles: [range(tiles[0])?, range(tiles[1])?] })
    }

    /// Number of tile copies.
    pub fn tile_count(&self) -> usize {
        self.tiles.iter().map(|r| r.len()).product()
    }

    /// The swatch's vertices in the block, ascending.
    pub fn vertices(&self, swatch: &Swatch) -> Vec<usize> {
        let inside = |t: &[i32; 2]| self.tiles[0].contains(&t[0]) && self.tiles[1].contains(&t[1]);
        swatch.source_tile.iter().enumerate().filter(|(_, t)| inside(t)).map(|(v, _)| v).collect()
    }

    /// The block's rest area (m²).
    pub fn rest_area_m2(&self, swatch: &Swatch) -> f64 {
        let [p1, p2] = swatch.pattern.period_m;
        self.tile_count() as f64 * p1 * p2
    }

    /// The stored energy per unit rest area (J/m²) of the block, from the energy per vertex of
    /// the swatch's vertices (J).
    pub fn energy_density_j_m2(&self, swatch: &Swatch, vertex_energies_j: &[f64]) -> f64 {
        let energy: f64 = self.vertices(swatch).iter().map(|&v| vertex_energies_j[v]).sum();
        energy / self.rest_area_m2(swatch)
    }

    /// The block's deformation gradient: the first two columns of the least-squares affine map
    /// `x ≈ G X + c` from the vertices' rest positions `X` (3D: the third column takes the
    /// yarns' heights, so their layout through the thickness biases nothing) to `positions_m`
    /// (the swatch's vertices, in its order).
    pub fn deformation_gradient(&self, swatch: &Swatch, positions_m: &[[f64; 3]]) -> Matrix3x2<f64> {
        let vertices = self.vertices(swatch);
        let rest = |v: usize| Vector3::from(swatch.positions_m[v]);
        let now = |v: usize| Vector3::from(positions_m[v]);
        let n = vertices.len() as f64;
        let rest_mean = vertices.iter().map(|&v| rest(v)).sum::<Vector3<f64>>() / n;
        let now_mean = vertices.iter().map(|&v| now(v)).sum::<Vector3<f64>>() / n;
        let (mut xx, mut yx) = (Matrix3::zeros(), Matrix3::zeros());
        for &v in &vertices {
            let (x, y) = (rest(v) - rest_mean, now(v) - now_mean);
            xx += x * x.transpose();
            yx += y * x.transpose();
        }
        let inverse = xx.pseudo_inverse(1e-12 * xx.norm()).unwrap_or_else(|_| Matrix3::zeros());
        (yx * inverse).fixed_columns::<2>(0).into_owned()
    }

    /// The block's in-plane strain (4.1) at `positions_m`.
    pub fn strain(&self, swatch: &Swatch, positions_m: &[[f64; 3]]) -> Result<InPlaneStrain, StrainError> {
        InPlaneStrain::from_deformation_gradient(&self.deformation_gradient(swatch, positions_m))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::swatch::{SwatchSize, cut_swatch};
    use yarnhom_artifacts::{GlueSettings, YarnModel, pyp};

    fn stock(tiles: u32) -> Swatch {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data/hylc-patterns/stock.pyp");
        let text = std::fs::read_to_string(path).expect("the published stockinette");
        let pattern = pyp::parse_pyp(&text, "stock", None).expect("a valid .pyp");
        let model = YarnModel::table_4_1("stock").expect("a Table 4.1 row");
        cut_swatch(&pattern, &model, SwatchSize::Tiles([tiles, tiles]), GlueSettings::default())
            .expect("cuts")
            .0
    }

    #[test]
    fn an_affine_map_of_the_interior_gives_back_its_strain_and_each_tile_copy_is_whole() {
        let swatch = stock(5);
        let interior = Interior::inset([5, 5], 1).expect("a 3 x 3 block");
        assert_eq!(interior.tile_count(), 9);
        assert_eq!(interior.vertices(&swatch).len(), 9 * swatch.pattern.positions_m.len());
        assert_eq!(Interior::inset([4, 4], 2), None);
        // Stretched by 20% along X1, sheared and contracted, rotated and moved: any affine map.
        let (sx, sa, sy): (f64, f64, f64) = (0.2, 0.1, -0.05);
        let a1 = Vector3::new(1.0 + sx, 0.0, 0.0);
        let a2 = Vector3::new(sa * (1.0 + sy), (1.0 - sa * sa).sqrt() * (1.0 + sy), 0.0);
        let rotation = nalgebra::Rotation3::from_euler_angles(0.3, -0.2, 1.1);
        let f = rotation * Matrix3x2::from_columns(&[a1, a2]);
        let moved: Vec<[f64; 3]> = swatch
            .positions_m
            .iter()
            .map(|p| {
                let x =
                    f * nalgebra::Vector2::new(p[0], p[1]) + rotation * Vector3::new(0.0, 0.0, 0.7 * p[2]);
                (x + Vector3::new(0.1, 2.0, -3.0)).into()
            })
            .collect();
        let s = interior.strain(&swatch, &moved).expect("a valid strain");
        assert!((s.sx - sx).abs() < 1e-6 && (s.sa - sa).abs() < 1e-6 && (s.sy - sy).abs() < 1e-6, "{s:?}");
        // The energy density: the block's share over its area.
        let energies = vec![1e-6; swatch.positions_m.len()];
        let density = interior.energy_density_j_m2(&swatch, &energies);
        let expected = 1e-6 * swatch.pattern.positions_m.len() as f64
            / (swatch.pattern.period_m[0] * swatch.pattern.period_m[1]);
        assert!((density / expected - 1.0).abs() < 1e-12, "{density} vs {expected}");
    }
}
