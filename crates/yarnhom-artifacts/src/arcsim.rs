//! The ARCSim-HYLC material JSON (`../shared/data/hylc-materials/*.json`, FORMAT.md there): the
//! published fitted materials of thesis Ch. 4, read into and written from the [`Spline`]
//! artifact, so published materials run in our simulator and our fits run in theirs.
//!
//! The layout, as read by ARCSim-HYLC's `SplineMaterial`:
//! - `density` (kg/m²), `strain scale` (5 numbers), `strain shift` = `[1, 0, 1, 0, 0]` (the in-plane
//!   strains are stretch ratios minus 1);
//! - `coeffs.const` = `f0`;
//! - `coeffs.1D[]` = `{k, t, p, m}`: knots, values, slopes of term `k`;
//! - `coeffs.2D[]` = `{k0, k1, tu, tv, p, mu, mv, muv}`, nodal arrays row-major with `tv` outer
//!   (`p[iv * len(tu) + iu]`), the layout of [`BicubicTerm`].

use serde::{Deserialize, Serialize};

use crate::Artifact;
use crate::error::{Error, Result};
use crate::spline::{BicubicTerm, CubicTerm, Spline, SplineOrigin};

/// The strain shift ARCSim-HYLC applies: `sx = sqrt(I11) - 1`, `sy = sqrt(I22) - 1`.
const STRAIN_SHIFT: [f64; 5] = [1.0, 0.0, 1.0, 0.0, 0.0];

/// An ARCSim-HYLC material file.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ArcsimMaterial {
    /// Areal mass density (kg/m²).
    pub density: f64,
    /// Normalization of `(sx, sa, sy, kx, ky)`.
    #[serde(rename = "strain scale")]
    pub strain_scale: [f64; 5],
    /// Shift of the strains before normalization; `[1, 0, 1, 0, 0]`.
    #[serde(rename = "strain shift")]
    pub strain_shift: [f64; 5],
    /// The spline coefficients.
    pub coeffs: Coefficients,
}

/// The coefficients of an ARCSim-HYLC material.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Coefficients {
    /// `f0` (J/m²).
    #[serde(rename = "const")]
    pub constant: f64,
    /// The 1D terms.
    #[serde(rename = "1D")]
    pub terms_1d: Vec<Term1d>,
    /// The 2D terms.
    #[serde(rename = "2D", default)]
    pub terms_2d: Vec<Term2d>,
}

/// One 1D term.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Term1d {
    /// Strain index: 0 sx, 1 sa, 2 sy, 3 x-bending, 4 y-bending.
    pub k: u8,
    /// Knots.
    pub t: Vec<f64>,
    /// Values.
    pub p: Vec<f64>,
    /// Slopes.
    pub m: Vec<f64>,
}

/// One 2D term.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Term2d {
    /// First strain index (in-plane).
    pub k0: u8,
    /// Second strain index.
    pub k1: u8,
    /// Knots of the first strain.
    pub tu: Vec<f64>,
    /// Knots of the second strain.
    pub tv: Vec<f64>,
    /// Values.
    pub p: Vec<f64>,
    /// u-derivatives.
    pub mu: Vec<f64>,
    /// v-derivatives.
    pub mv: Vec<f64>,
    /// Cross derivatives.
    pub muv: Vec<f64>,
}

fn format_error(line: usize, message: impl Into<String>) -> Error {
    Error::Format { format: "ARCSim-HYLC JSON", line, message: message.into() }
}

impl ArcsimMaterial {
    /// Parse the JSON text of a material (ARCSim's JSON allows `//` and `/* */` comments; so do we).
    pub fn parse(text: &str) -> Result<Self> {
        let text = strip_comments(text);
        let material: Self =
            serde_json::from_str(&text).map_err(|e| format_error(e.line(), e.to_string()))?;
        if material.strain_shift != STRAIN_SHIFT {
            return Err(format_error(
                0,
                format!(
                    "strain shift must be {STRAIN_SHIFT:?} (stretch ratio minus 1), got {:?}",
                    material.strain_shift
                ),
            ));
        }
        Ok(material)
    }

    /// The material as a [`Spline`] artifact named `name`, validated.
    pub fn to_spline(&self, name: &str, file: &str) -> Result<Spline> {
        let spline = Spline {
            name: name.into(),
            areal_density_kg_m2: self.density,
            strain_scale: self.strain_scale,
            rest_energy_density_j_m2: self.coeffs.constant,
            terms_1d: self
                .coeffs
                .terms_1d
                .iter()
                .map(|t| CubicTerm {
                    axis: t.k,
                    knots: t.t.clone(),
                    values: t.p.clone(),
                    slopes: t.m.clone(),
                })
                .collect(),
            terms_2d: self
                .coeffs
                .terms_2d
                .iter()
                .map(|t| BicubicTerm {
                    axes: [t.k0, t.k1],
                    u_knots: t.tu.clone(),
                    v_knots: t.tv.clone(),
                    values: t.p.clone(),
                    du: t.mu.clone(),
                    dv: t.mv.clone(),
                    duv: t.muv.clone(),
                })
                .collect(),
            origin: SplineOrigin::ImportedArcsim { file: file.into() },
        };
        spline.validate().map_err(|e| format_error(0, format!("{}: {}", e.field, e.problem)))?;
        Ok(spline)
    }

    /// A [`Spline`] in the ARCSim-HYLC layout.
    pub fn from_spline(spline: &Spline) -> Self {
        Self {
            density: spline.areal_density_kg_m2,
            strain_scale: spline.strain_scale,
            strain_shift: STRAIN_SHIFT,
            coeffs: Coefficients {
                constant: spline.rest_energy_density_j_m2,
                terms_1d: spline
                    .terms_1d
                    .iter()
                    .map(|t| Term1d {
                        k: t.axis,
                        t: t.knots.clone(),
                        p: t.values.clone(),
                        m: t.slopes.clone(),
                    })
                    .collect(),
                terms_2d: spline
                    .terms_2d
                    .iter()
                    .map(|t| Term2d {
                        k0: t.axes[0],
                        k1: t.axes[1],
                        tu: t.u_knots.clone(),
                        tv: t.v_knots.clone(),
                        p: t.values.clone(),
                        mu: t.du.clone(),
                        mv: t.dv.clone(),
                        muv: t.duv.clone(),
                    })
                    .collect(),
            },
        }
    }

    /// The JSON text ARCSim-HYLC reads.
    pub fn to_json(&self) -> Result<String> {
        serde_json::to_string_pretty(self)
            .map_err(|e| Error::Encode { what: "ARCSim-HYLC JSON", message: e.to_string() })
    }
}

/// The ARCSim-HYLC material `text` of the file `path` as a validated [`Spline`] named after the
/// file's stem (read files with [`crate::open::open_artifact`]).
pub fn parse_spline(path: &std::path::Path, text: &str) -> Result<Spline> {
    let stem = path.file_stem().and_then(|s| s.to_str()).unwrap_or("material");
    let file = path.file_name().and_then(|s| s.to_str()).unwrap_or(stem);
    ArcsimMaterial::parse(text).and_then(|m| m.to_spline(stem, file))
}

/// Remove `//` line comments and `/* */` block comments outside strings (ARCSim's JSON
/// dialect); line breaks are kept so parse errors keep their line numbers.
pub fn strip_comments(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut chars = text.chars().peekable();
    let (mut in_string, mut escaped) = (false, false);
    while let Some(c) = chars.next() {
        if in_string {
            out.push(c);
            if escaped {
                escaped = false;
            } else if c == '\\' {
                escaped = true;
            } else if c == '"' {
                in_string = false;
            }
            continue;
        }
        match (c, chars.peek()) {
            ('/', Some('/')) => {
                while chars.peek().is_some_and(|&n| n != '\n') {
                    chars.next();
                }
            }
            ('/', Some('*')) => {
                chars.next();
                let mut last = ' ';
                for n in chars.by_ref() {
                    if n == '\n' {
                        out.push('\n');
                    }
                    if last == '*' && n == '/' {
                        break;
                    }
                    last = n;
                }
            }
            _ => {
                in_string = c == '"';
                out.push(c);
            }
        }
    }
    out
}

impl Artifact for Spline {
    const KIND: &'static str = "spline";
    const SCHEMA_VERSION: u32 = 1;
    fn validate(&self) -> std::result::Result<(), crate::ValidationError> {
        Spline::validate(self)
    }
    fn summary(&self) -> String {
        Spline::summary(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const FIT: &str = r#"{"density": 0.3, "strain scale": [0.5, 1, 1, 1, 1], "strain shift": [1, 0, 1, 0, 0],
        "coeffs": {"const": 0.1,
        "1D": [{"k": 0, "t": [0, 1, 2], "p": [0, 1, 4], "m": [0, 2, 4]}], // a comment "with quotes"
        /* a block
           comment */
        "2D": [{"k0": 0, "k1": 3, "tu": [0, 1], "tv": [0, 1, 2], "p": [0,0,0,0,0,1], "mu": [0,0,0,0,0,0], "mv": [0,0,0,0,0,0], "muv": [0,0,0,0,0,0]}]}}"#;

    #[test]
    fn round_trip_keeps_every_coefficient() {
        let material = ArcsimMaterial::parse(FIT).expect("parses");
        let spline = material.to_spline("fit", "fit.json").expect("valid");
        assert_eq!(spline.terms_1d[0].values, vec![0.0, 1.0, 4.0]);
        assert_eq!(spline.terms_2d[0].axes, [0, 3]);
        let back = ArcsimMaterial::parse(&ArcsimMaterial::from_spline(&spline).to_json().expect("json"))
            .expect("parses");
        assert_eq!(back.to_spline("fit", "fit.json").expect("valid"), spline);
    }

    #[test]
    fn comments_are_stripped_outside_strings_only() {
        let text = "{\"a\": \"x \\\" // y\", // gone\n /* gone\n too */ \"b\": 1}";
        let value: serde_json::Value = serde_json::from_str(&strip_comments(text)).expect("json");
        assert_eq!(value["a"], "x \" // y");
        assert_eq!(value["b"], 1);
        assert_eq!(strip_comments(text).lines().count(), 3, "line breaks are kept");
    }

    #[test]
    fn malformed_materials_are_errors() {
        assert!(ArcsimMaterial::parse("{}").is_err());
        let bad = ArcsimMaterial::parse(&FIT.replace("[0, 1, 2]", "[0, 2, 1]")).expect("parses");
        let message = bad.to_spline("fit", "fit.json").expect_err("unsorted knots").to_string();
        assert!(message.contains("terms_1d[0].knots"), "{message}");
        assert!(ArcsimMaterial::parse(&FIT.replace("[1, 0, 1, 0, 0]", "[0, 0, 0, 0, 0]")).is_err());
    }

    #[test]
    fn every_published_material_imports() {
        let dir =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data/hylc-materials");
        let mut count = 0;
        for entry in std::fs::read_dir(&dir).expect("the published materials").flatten() {
            let path = entry.path();
            if path.extension().is_some_and(|e| e == "json") {
                let spline =
                    crate::open::open_artifact::<Spline>(&path).expect("published material imports").value;
                assert_eq!(spline.terms_1d.len(), 5, "{}", path.display());
                assert_eq!(spline.terms_2d.len(), 9, "{}", path.display());
                count += 1;
            }
        }
        assert_eq!(count, 7);
    }
}
