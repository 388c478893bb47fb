//! The published ARCSim-HYLC fitted materials (`../shared/data/hylc-materials/*.json`, see
//! FORMAT.md there): read far enough to evaluate the 1D terms. The full spline model (2D
//! patches, bending split) belongs to the fitting stage.

use serde::Deserialize;

use crate::error::{Error, Result};

/// One 1D term: a cubic Hermite spline over `strain / strain scale`.
#[derive(Debug, Clone, Deserialize)]
pub struct Term1d {
    /// Strain index: 0 sx, 1 sa, 2 sy, 3 x-bending, 4 y-bending.
    pub k: usize,
    /// Knots (normalized strain).
    pub t: Vec<f64>,
    /// Values at the knots (J/m²).
    pub p: Vec<f64>,
    /// Slopes at the knots.
    pub m: Vec<f64>,
}

#[derive(Debug, Clone, Deserialize)]
struct Coefficients {
    #[serde(rename = "1D")]
    terms_1d: Vec<Term1d>,
}

/// A published HYLC fit, as far as its 1D terms.
#[derive(Debug, Clone, Deserialize)]
pub struct HylcFit {
    /// Normalization of (sx, sa, sy, kx, ky).
    #[serde(rename = "strain scale")]
    pub strain_scale: [f64; 5],
    coeffs: Coefficients,
}

impl HylcFit {
    /// Parse the JSON text of a fit.
    pub fn parse(text: &str) -> Result<Self> {
        let fit: HylcFit = serde_json::from_str(text).map_err(|e| Error::Format {
            format: "ARCSim-HYLC JSON",
            line: e.line(),
            message: e.to_string(),
        })?;
        for term in &fit.coeffs.terms_1d {
            let n = term.t.len();
            if term.k > 4
                || n < 2
                || term.p.len() != n
                || term.m.len() != n
                || term.t.windows(2).any(|w| w[1] <= w[0])
            {
                return Err(Error::Format {
                    format: "ARCSim-HYLC JSON",
                    line: 0,
                    message: format!(
                        "1D term {} is malformed (knots must increase, arrays agree in length)",
                        term.k
                    ),
                });
            }
        }
        Ok(fit)
    }

    /// The 1D term `k` at strain `x` (J/m²): cubic Hermite over `x / strain scale`, extrapolated
    /// linearly with the end slope. `None` if the fit has no such term.
    pub fn term_1d(&self, k: usize, x: f64) -> Option<f64> {
        let term = self.coeffs.terms_1d.iter().find(|t| t.k == k)?;
        let (t, p, m) = (&term.t, &term.p, &term.m);
        let (u, last) = (x / self.strain_scale[k], t.len() - 1);
        if u <= t[0] {
            return Some(p[0] + m[0] * (u - t[0]));
        }
        if u >= t[last] {
            return Some(p[last] + m[last] * (u - t[last]));
        }
        let i = t.iter().position(|&ti| ti > u).unwrap_or(last) - 1;
        let h = t[i + 1] - t[i];
        let s = (u - t[i]) / h;
        let (s2, s3) = (s * s, s * s * s);
        Some(
            (2.0 * s3 - 3.0 * s2 + 1.0) * p[i]
                + (s3 - 2.0 * s2 + s) * h * m[i]
                + (-2.0 * s3 + 3.0 * s2) * p[i + 1]
                + (s3 - s2) * h * m[i + 1],
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const FIT: &str = r#"{"strain scale": [0.5, 1, 1, 1, 1], "coeffs": {"const": 0.1,
        "1D": [{"k": 0, "t": [0, 1, 2], "p": [0, 1, 4], "m": [0, 2, 4]}]}}"#;

    #[test]
    fn hermite_terms_interpolate_knots_and_extrapolate_linearly() {
        let fit = HylcFit::parse(FIT).expect("parses");
        // p = u² with exact slopes: the Hermite spline reproduces the quadratic.
        for u in [0.0, 0.3, 1.0, 1.7, 2.0] {
            assert!((fit.term_1d(0, 0.5 * u).expect("term") - u * u).abs() < 1e-12, "u = {u}");
        }
        assert!((fit.term_1d(0, 0.5 * 3.0).expect("term") - (4.0 + 4.0)).abs() < 1e-12);
        assert!(fit.term_1d(2, 0.1).is_none());
    }

    #[test]
    fn malformed_fits_are_errors() {
        assert!(HylcFit::parse("{}").is_err());
        let bad = FIT.replace("[0, 1, 2]", "[0, 2, 1]");
        assert!(HylcFit::parse(&bad).is_err());
    }
}
