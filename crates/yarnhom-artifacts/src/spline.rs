//! The `spline` artifact: a homogenized cloth material as a sum of regularized Hermite splines
//! (thesis Sec. 4.1, (4.2), (4.3), App. A.3, (A.34)).
//!
//! The energy density is `f0 + Σ f_i + Σ f_ij` over the strain parameters
//! `(sx, sa, sy, kx, ky)` ([`crate::grid::AXIS_NAMES`]), each spline evaluated at the
//! strain divided by [`Spline::strain_scale`]; the bending terms are evaluated on the principal
//! curvatures and blended by (4.3). The same layout as the published ARCSim-HYLC JSON
//! ([`crate::arcsim`]), so published materials and our fits are interchangeable.

use serde::{Deserialize, Serialize};

use crate::check;
use crate::error::ValidationError;
use crate::grid::AXIS_NAMES;

/// A fitted (or imported) homogenized cloth material.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
pub struct Spline {
    /// A name (the pattern's, or the imported file's stem).
    pub name: String,
    /// Areal mass density of the cloth (kg/m²).
    pub areal_density_kg_m2: f64,
    /// Normalization of `(sx, sa, sy, kx, ky)`: each spline is evaluated at `strain / scale`
    /// (dimensionless for `sx, sa, sy`; 1/m for the curvatures).
    pub strain_scale: [f64; 5],
    /// `f0`: the energy density of the undeformed cloth (J/m²).
    pub rest_energy_density_j_m2: f64,
    /// The 1D terms `f_i` (A.34), at most one per axis.
    pub terms_1d: Vec<CubicTerm>,
    /// The 2D residual terms `f_ij` (A.34), at most one per pair; the first axis is in-plane.
    pub terms_2d: Vec<BicubicTerm>,
    /// Where the material came from.
    pub origin: SplineOrigin,
}

/// A cubic Hermite spline of one strain parameter, extrapolated linearly with its end slopes
/// (App. A.3.5).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
pub struct CubicTerm {
    /// The axis, an index into [`AXIS_NAMES`].
    pub axis: u8,
    /// Knots in normalized strain, strictly ascending.
    pub knots: Vec<f64>,
    /// Values at the knots (J/m²).
    pub values: Vec<f64>,
    /// Slopes at the knots (J/m² per unit normalized strain).
    pub slopes: Vec<f64>,
}

/// A bicubic Hermite patch of two strain parameters `(u, v)` (App. B), extrapolated linearly
/// across its boundary (App. A.3.5). Nodal arrays are row-major with `v` outer: the node
/// `(i, j)` (`u_knots[i]`, `v_knots[j]`) is at `j * u_knots.len() + i`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
pub struct BicubicTerm {
    /// The axes `[u, v]`, indices into [`AXIS_NAMES`], `u < v`, `u` in-plane.
    pub axes: [u8; 2],
    /// Knots of `u` in normalized strain, strictly ascending.
    pub u_knots: Vec<f64>,
    /// Knots of `v` in normalized strain, strictly ascending.
    pub v_knots: Vec<f64>,
    /// Values at the nodes (J/m²).
    pub values: Vec<f64>,
    /// `∂f/∂u` at the nodes.
    pub du: Vec<f64>,
    /// `∂f/∂v` at the nodes.
    pub dv: Vec<f64>,
    /// `∂²f/∂u∂v` at the nodes.
    pub duv: Vec<f64>,
}

/// Where a spline material came from.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum SplineOrigin {
    /// Fitted by `yarnhom fit` from a sampled grid with these settings.
    Fitted {
        /// The settings of the fit.
        settings: FitSettings,
    },
    /// Imported from an ARCSim-HYLC material JSON.
    ImportedArcsim {
        /// The file name it was read from.
        file: String,
    },
}

/// The settings of a spline fit (App. A.3).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
pub struct FitSettings {
    /// Control points on each side of 0 for 1D terms (Alg. 4 line 5).
    pub knots_per_side_1d: u32,
    /// Control points on each side of 0 for each axis of 2D terms (Alg. 5 lines 5-6).
    pub knots_per_side_2d: u32,
    /// Fraction of the sampled range the 1D control points span (Alg. 4: 0.95).
    pub span_1d: f64,
    /// Fraction of the sampled range the 2D control points span (Alg. 5: 0.9; 0.3 for
    /// stockinette bending terms).
    pub span_2d: f64,
    /// Fraction of the sampled range the 2D control points of bending terms span (Sec. 4.3:
    /// concentrated near the origin for curling knits).
    pub span_2d_bending: f64,
    /// The quasiconvexity slope `p_min^x` of the marching (A.36) (0.001; 0.01 for stockinette).
    pub min_slope: f64,
    /// MLS support radius in normalized strain (A.35).
    pub mls_radius: f64,
    /// Whether the data were symmetrized in `sa` (Sec. 4.3).
    pub symmetrize_shear: bool,
    /// Strain limits the grid was restricted to before fitting (the thesis chooses sampling
    /// limits below self-intersection and jamming, App. A.3.1); samples outside were not used.
    #[serde(default)]
    pub limits: Vec<AxisLimit>,
}

/// A closed strain interval of one axis.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
pub struct AxisLimit {
    /// The axis, an index into [`AXIS_NAMES`].
    pub axis: u8,
    /// Lowest value kept (must be <= 0).
    pub min: f64,
    /// Highest value kept (must be >= 0).
    pub max: f64,
}

impl Default for FitSettings {
    /// The thesis' settings (App. A.3).
    fn default() -> Self {
        Self {
            knots_per_side_1d: 5,
            knots_per_side_2d: 4,
            span_1d: 0.95,
            span_2d: 0.9,
            span_2d_bending: 0.9,
            min_slope: 0.001,
            mls_radius: 0.12,
            symmetrize_shear: true,
            limits: Vec::new(),
        }
    }
}

impl Spline {
    /// Check the invariants: positive scales and density, well-formed terms, at most one term
    /// per axis or pair.
    pub fn validate(&self) -> Result<(), ValidationError> {
        check::positive("areal_density_kg_m2", self.areal_density_kg_m2)?;
        for (k, &s) in self.strain_scale.iter().enumerate() {
            check::positive(&format!("strain_scale[{k}]"), s)?;
        }
        check::finite("rest_energy_density_j_m2", [&self.rest_energy_density_j_m2])?;
        for (t, term) in self.terms_1d.iter().enumerate() {
            term.validate(&format!("terms_1d[{t}]"))?;
            if let Some(first) = self.terms_1d[..t].iter().position(|x| x.axis == term.axis) {
                return Err(ValidationError::new(
                    format!("terms_1d[{t}]"),
                    format!("repeats terms_1d[{first}]"),
                ));
            }
        }
        for (t, term) in self.terms_2d.iter().enumerate() {
            term.validate(&format!("terms_2d[{t}]"))?;
            if let Some(first) = self.terms_2d[..t].iter().position(|x| x.axes == term.axes) {
                return Err(ValidationError::new(
                    format!("terms_2d[{t}]"),
                    format!("repeats terms_2d[{first}]"),
                ));
            }
        }
        Ok(())
    }

    /// A human summary.
    pub fn summary(&self) -> String {
        let names_1d: Vec<&str> = self.terms_1d.iter().map(|t| axis_name(t.axis)).collect();
        let names_2d: Vec<String> = self.terms_2d.iter().map(BicubicTerm::name).collect();
        let origin = match &self.origin {
            SplineOrigin::Fitted { .. } => "fitted by yarnhom".to_string(),
            SplineOrigin::ImportedArcsim { file } => format!("imported from ARCSim-HYLC '{file}'"),
        };
        format!(
            "spline material '{}' ({origin})\n  areal density: {} kg/m²\n  f0: {:.6e} J/m²\n  strain scale (sx, sa, sy, kx, ky): {:?}\n  1D terms: {}\n  2D terms: {}",
            self.name,
            self.areal_density_kg_m2,
            self.rest_energy_density_j_m2,
            self.strain_scale,
            names_1d.join(", "),
            names_2d.join("; "),
        )
    }
}

fn axis_name(axis: u8) -> &'static str {
    AXIS_NAMES.get(axis as usize).copied().unwrap_or("?")
}

/// Knots are finite and strictly ascending, at least two.
fn validate_knots(field: &str, knots: &[f64]) -> Result<(), ValidationError> {
    check::finite(field, knots)?;
    if knots.len() < 2 {
        return Err(ValidationError::new(field, "needs at least 2 knots"));
    }
    match knots.windows(2).position(|w| w[0] >= w[1]) {
        Some(i) => Err(ValidationError::new(
            format!("{field}[{}]", i + 1),
            format!("knots must increase strictly, but {} follows {}", knots[i + 1], knots[i]),
        )),
        None => Ok(()),
    }
}

impl CubicTerm {
    fn validate(&self, field: &str) -> Result<(), ValidationError> {
        if self.axis >= 5 {
            return Err(ValidationError::new(
                format!("{field}.axis"),
                format!("must be below 5, got {}", self.axis),
            ));
        }
        validate_knots(&format!("{field}.knots"), &self.knots)?;
        let n = self.knots.len();
        for (name, values) in [("values", &self.values), ("slopes", &self.slopes)] {
            check::len(&format!("{field}.{name}"), values.len(), n, "knots")?;
            check::finite(&format!("{field}.{name}"), values)?;
        }
        Ok(())
    }
}

impl BicubicTerm {
    /// The term's name, e.g. `sx,kx`.
    pub fn name(&self) -> String {
        format!("{},{}", axis_name(self.axes[0]), axis_name(self.axes[1]))
    }

    fn validate(&self, field: &str) -> Result<(), ValidationError> {
        let [u, v] = self.axes;
        if !(u < v && v < 5 && u < 3) {
            return Err(ValidationError::new(
                format!("{field}.axes"),
                format!(
                    "must be two ascending axis indices below 5, the first in-plane (< 3); got {:?}",
                    self.axes
                ),
            ));
        }
        validate_knots(&format!("{field}.u_knots"), &self.u_knots)?;
        validate_knots(&format!("{field}.v_knots"), &self.v_knots)?;
        let n = self.u_knots.len() * self.v_knots.len();
        for (name, values) in
            [("values", &self.values), ("du", &self.du), ("dv", &self.dv), ("duv", &self.duv)]
        {
            check::len(&format!("{field}.{name}"), values.len(), n, "nodes")?;
            check::finite(&format!("{field}.{name}"), values)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn material() -> Spline {
        Spline {
            name: "test".into(),
            areal_density_kg_m2: 0.3,
            strain_scale: [1.0; 5],
            rest_energy_density_j_m2: 0.0,
            terms_1d: vec![CubicTerm {
                axis: 0,
                knots: vec![-1.0, 0.0, 1.0],
                values: vec![1.0, 0.0, 1.0],
                slopes: vec![-2.0, 0.0, 2.0],
            }],
            terms_2d: vec![BicubicTerm {
                axes: [0, 2],
                u_knots: vec![-1.0, 1.0],
                v_knots: vec![-1.0, 0.0, 1.0],
                values: vec![0.0; 6],
                du: vec![0.0; 6],
                dv: vec![0.0; 6],
                duv: vec![0.0; 6],
            }],
            origin: SplineOrigin::Fitted { settings: FitSettings::default() },
        }
    }

    #[test]
    fn a_well_formed_material_validates() {
        material().validate().expect("valid");
    }

    #[test]
    fn malformed_terms_are_named() {
        let mut m = material();
        m.terms_1d[0].knots = vec![0.0, -1.0, 1.0];
        assert_eq!(m.validate().expect_err("unsorted").field, "terms_1d[0].knots[1]");
        let mut m = material();
        m.terms_2d[0].duv.pop();
        assert_eq!(m.validate().expect_err("short").field, "terms_2d[0].duv");
        let mut m = material();
        m.terms_2d[0].axes = [3, 4];
        assert_eq!(m.validate().expect_err("bending pair").field, "terms_2d[0].axes");
        let mut m = material();
        m.terms_1d.push(m.terms_1d[0].clone());
        assert_eq!(m.validate().expect_err("repeat").field, "terms_1d[1]");
    }
}
