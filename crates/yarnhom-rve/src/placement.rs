//! The co-rotated placement of vertex instances: `x = φ(X) + h n(X) + R(X) g` (3.13) with
//! `g = Rᵀũ` the tile DOF (periodic by construction, (3.21)).

use std::sync::OnceLock;

use nalgebra::{Matrix3, Vector2, Vector3};
use yarnhom_geom::{MacroStrain, Midsurface};

/// A vertex of the tile in one periodic image.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Instance {
    /// Vertex index in the tile.
    pub vertex: u32,
    /// Tile image offset.
    pub image: [i32; 2],
}

/// Material points of the tile's vertices and the midsurface they are placed on.
#[derive(Debug, Clone)]
pub struct Placement {
    /// Material coordinates `(X1, X2, h)` of each vertex in the tile (rest geometry, centred).
    material: Vec<Vector3<f64>>,
    period_m: [f64; 2],
    midsurface: Midsurface,
    /// Images `|o_k| <= reach[k]` whose embeddings are cached.
    reach: [i32; 2],
    /// The embedding `(φ(X) + h n(X), R(X))` of each instance within `reach`, computed on first
    /// use: it depends on the strain only, and the solver asks for it at every evaluation.
    embeddings: Vec<OnceLock<Embedding>>,
}

/// Where an instance sits on the midsurface and how its frame is rotated: `(φ + h n, R)`.
type Embedding = (Vector3<f64>, Matrix3<f64>);

impl Placement {
    /// The placement of a tile with material points `material` (m) and periods `period_m`
    /// under `strain`.
    ///
    /// The midsurface covers every instance the tile's elements and contacts place: the
    /// material points' box widened on each side by its own extent plus two periods (images
    /// within contact reach lie inside it). For doubly curved strains it is the least-squares
    /// solution of (3.17-3.18) on that box; otherwise the exact closed form.
    pub fn new(material: Vec<Vector3<f64>>, period_m: [f64; 2], strain: &MacroStrain) -> Self {
        let (lo, hi) = material
            .iter()
            .fold((Vector2::repeat(f64::INFINITY), Vector2::repeat(f64::NEG_INFINITY)), |(lo, hi), m| {
                (lo.inf(&m.xy()), hi.sup(&m.xy()))
            });
        let margin = (hi - lo) + Vector2::new(period_m[0], period_m[1]) * 2.0;
        let midsurface = Midsurface::over_domain(strain, lo - margin, hi + margin);
        let reach: [i32; 2] = std::array::from_fn(|k| {
            let r = (margin[k] / period_m[k]).ceil();
            if r.is_finite() { r.clamp(0.0, 8.0) as i32 } else { 0 }
        });
        let slots = material.len() * ((2 * reach[0] + 1) * (2 * reach[1] + 1)) as usize;
        Placement { material, period_m, midsurface, reach, embeddings: vec![OnceLock::new(); slots] }
    }

    /// The cache slot of an instance, if it lies within `reach`.
    fn slot(&self, i: Instance) -> Option<usize> {
        let [rx, ry] = self.reach;
        let [ox, oy] = i.image;
        if ox.abs() > rx || oy.abs() > ry {
            return None;
        }
        let image = ((ox + rx) * (2 * ry + 1) + (oy + ry)) as usize;
        Some(image * self.material.len() + i.vertex as usize)
    }

    /// `(φ(X) + h n(X), R(X))` of an instance (3.13).
    fn embedding(&self, i: Instance) -> Embedding {
        let compute = || {
            let (x, h) = self.material_point(i);
            (self.midsurface.position(&x) + self.midsurface.normal(&x) * h, self.midsurface.rotation(&x))
        };
        match self.slot(i) {
            Some(k) => *self.embeddings[k].get_or_init(compute),
            None => compute(),
        }
    }

    fn material_point(&self, i: Instance) -> (Vector2<f64>, f64) {
        let m = self.material[i.vertex as usize];
        let x = Vector2::new(
            m.x + f64::from(i.image[0]) * self.period_m[0],
            m.y + f64::from(i.image[1]) * self.period_m[1],
        );
        (x, m.z)
    }

    /// The in-plane stretch `S̄` (3x2) of the macro strain (A.11).
    pub fn in_plane_stretch(&self) -> nalgebra::Matrix3x2<f64> {
        self.midsurface.stretch
    }

    /// The smallest eigenvalue of the first fundamental form (`λ_min` of the step limit, A.2.3).
    pub fn smallest_stretch_eigenvalue(&self) -> f64 {
        let s = self.midsurface.stretch;
        (s.transpose() * s).symmetric_eigenvalues().min()
    }

    /// The rotation `R(X)` at an instance: maps its DOF `g` to the world fluctuation `ũ`.
    pub fn rotation(&self, i: Instance) -> Matrix3<f64> {
        self.embedding(i).1
    }

    /// World position of an instance with tile DOF `g`.
    pub fn position(&self, i: Instance, g: &Vector3<f64>) -> Vector3<f64> {
        let (base, rotation) = self.embedding(i);
        base + rotation * g
    }
}
