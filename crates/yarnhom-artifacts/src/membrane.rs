//! The Ch. 6 shell material as data: the anisotropic StVK membrane with Neo-Hookean area terms
//! (6.1), its optional one-sided stiffening and jamming terms, and the anisotropic hinge bending
//! (6.4); and [`MembraneMaterial`], the JSON file that names a whole Ch. 6 cloth material
//! (`tools/materials/ch6-example.json`). The energies are `yarnhom-shell`'s; the parameters live
//! here so that every stage reads and writes them the same way.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// A Ch. 6 cloth material as a file: areal density, membrane (6.1), hinge bending (6.4).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct MembraneMaterial {
    /// Areal mass density (kg/m²).
    pub areal_density_kg_m2: f64,
    /// The membrane (6.1).
    pub membrane: StvkNeoHookean,
    /// The hinge bending (6.4).
    pub bending: HingeBending,
}

impl MembraneMaterial {
    /// A human summary for `yarnhom inspect`.
    pub fn summary(&self) -> String {
        let m = &self.membrane;
        let b = &self.bending;
        let mut text = format!(
            "Ch. 6 material: areal density {} kg/m²\n  membrane (6.1): k_xx {}, k_xy {}, k_yy {}, k_ss {}, k_n1 {}, k_n2 {} J/m²\n  hinge bending (6.4): k_weft {}, k_bias {}, k_warp {} J; rest curvatures {}, {}, {} 1/m",
            self.areal_density_kg_m2,
            m.k_xx,
            m.k_xy,
            m.k_yy,
            m.k_ss,
            m.k_n1,
            m.k_n2,
            b.k_weft,
            b.k_bias,
            b.k_warp,
            b.rest_curvature_weft,
            b.rest_curvature_bias,
            b.rest_curvature_warp
        );
        for (name, term) in [("stiffening", &m.stiffening), ("jamming", &m.jamming)] {
            if let Some(t) = term {
                text += &format!(
                    "\n  {name}: k_weft {}, k_warp {} J/m² past Green strain {}",
                    t.k_weft, t.k_warp, t.onset
                );
            }
        }
        text
    }
}

/// The (6.1) parameters (J/m²): `k_xx, k_xy, k_yy, k_ss` of the StVK stiffness matrix on the
/// Voigt Green strain `(E11, E22, 2 E12)`, and the Neo-Hookean area terms `k_n1 (J-1)²` and
/// `k_n2 log² J`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct StvkNeoHookean {
    /// Weft stiffness.
    pub k_xx: f64,
    /// Weft-warp coupling.
    pub k_xy: f64,
    /// Warp stiffness.
    pub k_yy: f64,
    /// Shear stiffness.
    pub k_ss: f64,
    /// `(J - 1)²` weight.
    pub k_n1: f64,
    /// `log² J` weight.
    pub k_n2: f64,
    /// Stiffening past an onset strain, if any (not part of (6.1)).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stiffening: Option<Stiffening>,
    /// Jamming past an onset compression, if any (not part of (6.1)): the same one-sided term
    /// on the compressive Green strain, `½ k_weft ⟨-E11 - onset⟩₊² + ½ k_warp ⟨-E22 - onset⟩₊²`,
    /// the shell-level analogue of the two-phase contact (6.7): the fabric contracts freely
    /// across a pull while its yarns' soft outer contact layers give, and stiffly once they are
    /// pressed onto the hard inner cores.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub jamming: Option<Stiffening>,
}

/// A biphasic membrane: `½ k_weft ⟨E11 - onset⟩₊² + ½ k_warp ⟨E22 - onset⟩₊²` added to (6.1),
/// the shell-level analogue of the biphasic yarn stretch (6.5): the fabric stiffens once its
/// Green strain along an axis passes `onset`. As [`StvkNeoHookean::jamming`] the same term
/// acts on compression, `⟨-E - onset⟩₊`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Stiffening {
    /// Added stiffness along the weft past the onset (J/m²).
    pub k_weft: f64,
    /// Added stiffness along the warp past the onset (J/m²).
    pub k_warp: f64,
    /// Onset Green strain.
    pub onset: f64,
}

/// The (6.4) bending stiffnesses `k_θ` (J) for bends across weft, bias and warp, and the rest
/// curvatures `κ̄` (1/m) of a fabric that curls (0: flat at rest, the thesis' model).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct HingeBending {
    /// Bending that curves the weft (X) direction.
    pub k_weft: f64,
    /// Bending at 45°.
    pub k_bias: f64,
    /// Bending that curves the warp (Y) direction.
    pub k_warp: f64,
    /// Rest curvature of the weft direction, positive towards the fabric's normal (1/m).
    #[serde(default)]
    pub rest_curvature_weft: f64,
    /// Rest curvature at 45° (1/m).
    #[serde(default)]
    pub rest_curvature_bias: f64,
    /// Rest curvature of the warp direction (1/m).
    #[serde(default)]
    pub rest_curvature_warp: f64,
}

impl Stiffening {
    /// The same onset with a thousandth of the stiffness: where a nested fit starts the term,
    /// so that the extended model starts where the model without it ended.
    pub fn faint(self) -> Self {
        Self { k_weft: 1e-3 * self.k_weft, k_warp: 1e-3 * self.k_warp, ..self }
    }
}

impl HingeBending {
    /// Flat at rest, the same stiffness `k` (J) in every direction.
    pub fn isotropic(k: f64) -> Self {
        Self::anisotropic(k, k, k)
    }

    /// Flat at rest, stiffnesses per direction (J).
    pub fn anisotropic(k_weft: f64, k_bias: f64, k_warp: f64) -> Self {
        Self {
            k_weft,
            k_bias,
            k_warp,
            rest_curvature_weft: 0.0,
            rest_curvature_bias: 0.0,
            rest_curvature_warp: 0.0,
        }
    }
}
