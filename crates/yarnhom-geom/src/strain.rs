//! The macroscale strain of a thin shell as yarnhom samples it: the in-plane strain
//! `s = (sx, sa, sy)` of (4.1) and curvatures along the two material axes.
//!
//! (4.1): `sx = sqrt(I11) - 1`, `sa = I12 / sqrt(I11 I22)`, `sy = sqrt(I22) - 1`, with `I` the
//! first fundamental form. Each parameter has a fixed valid range independent of the others
//! (`sx, sy > -1`, `|sa| < 1`), which is what makes rectilinear sampling grids possible. Bending is
//! sampled along the two axes only (Sec. 4.1.1): `II = diag(kx, ky)`.

use nalgebra::{Matrix2, Matrix3x2};

/// Why a strain is not valid.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum StrainError {
    /// A value is NaN or infinite.
    #[error("{name} = {value} is not a finite number")]
    NotFinite {
        /// Parameter name.
        name: &'static str,
        /// The value.
        value: f64,
    },
    /// A stretch of -100% or less (a fibre of zero or negative length).
    #[error("{name} = {value} must be > -1 (a stretch of -100% collapses the fabric)")]
    Collapsed {
        /// `sx` or `sy`.
        name: &'static str,
        /// The value.
        value: f64,
    },
    /// A shear whose cosine is not in (-1, 1): the two material axes would be parallel.
    #[error("sa = {0} must satisfy |sa| < 1 (sa is the cosine of the angle between the deformed axes)")]
    Degenerate(f64),
    /// The first fundamental form is not symmetric positive definite.
    #[error("the first fundamental form is not symmetric positive definite")]
    NotPositiveDefinite,
    /// A malformed `key=value,...` strain text.
    #[error("strain '{text}': {problem} (expected e.g. sx=0.2,sa=0,sy=-0.05,kx=0,ky=0)")]
    Syntax {
        /// The text given.
        text: String,
        /// What is wrong with it.
        problem: String,
    },
}

/// In-plane strain (4.1): weft stretch `sx`, shear `sa`, warp stretch `sy`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InPlaneStrain {
    /// Stretch along X1 (weft): `|a1| - 1`.
    pub sx: f64,
    /// Cosine of the angle between the deformed axes `a1`, `a2`.
    pub sa: f64,
    /// Stretch along X2 (warp): `|a2| - 1`.
    pub sy: f64,
}

impl InPlaneStrain {
    /// A validated in-plane strain.
    pub fn new(sx: f64, sa: f64, sy: f64) -> Result<Self, StrainError> {
        for (name, value) in [("sx", sx), ("sa", sa), ("sy", sy)] {
            if !value.is_finite() {
                return Err(StrainError::NotFinite { name, value });
            }
        }
        for (name, value) in [("sx", sx), ("sy", sy)] {
            if value <= -1.0 {
                return Err(StrainError::Collapsed { name, value });
            }
        }
        if sa.abs() >= 1.0 {
            return Err(StrainError::Degenerate(sa));
        }
        Ok(Self { sx, sa, sy })
    }

    /// The strain of a first fundamental form `I = [[I11, I12], [I12, I22]]` (4.1).
    pub fn from_first_fundamental_form(i: &Matrix2<f64>) -> Result<Self, StrainError> {
        let symmetric = (i[(0, 1)] - i[(1, 0)]).abs() <= 1e-12 * i.norm();
        if !(symmetric && i[(0, 0)] > 0.0 && i.determinant() > 0.0) {
            return Err(StrainError::NotPositiveDefinite);
        }
        let (l1, l2) = (i[(0, 0)].sqrt(), i[(1, 1)].sqrt());
        Self::new(l1 - 1.0, i[(0, 1)] / (l1 * l2), l2 - 1.0)
    }

    /// The strain of a midsurface deformation gradient `F = [a1 a2]` (3x2): `I = F^T F`.
    pub fn from_deformation_gradient(f: &Matrix3x2<f64>) -> Result<Self, StrainError> {
        Self::from_first_fundamental_form(&(f.transpose() * f))
    }

    /// The first fundamental form: `I11 = (1+sx)^2`, `I22 = (1+sy)^2`, `I12 = sa (1+sx)(1+sy)`.
    pub fn first_fundamental_form(&self) -> Matrix2<f64> {
        let (l1, l2) = (1.0 + self.sx, 1.0 + self.sy);
        let off = self.sa * l1 * l2;
        Matrix2::new(l1 * l1, off, off, l2 * l2)
    }
}

/// A sampled macroscale strain: in-plane strain and curvatures `II = diag(kx, ky)` (1/m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MacroStrain {
    /// In-plane strain.
    pub s: InPlaneStrain,
    /// Curvature along X1 (1/m).
    pub kx: f64,
    /// Curvature along X2 (1/m).
    pub ky: f64,
}

impl MacroStrain {
    /// A validated macro strain.
    pub fn new(sx: f64, sa: f64, sy: f64, kx: f64, ky: f64) -> Result<Self, StrainError> {
        for (name, value) in [("kx", kx), ("ky", ky)] {
            if !value.is_finite() {
                return Err(StrainError::NotFinite { name, value });
            }
        }
        Ok(Self { s: InPlaneStrain::new(sx, sa, sy)?, kx, ky })
    }

    /// The second fundamental form `diag(kx, ky)`.
    pub fn second_fundamental_form(&self) -> Matrix2<f64> {
        Matrix2::new(self.kx, 0.0, 0.0, self.ky)
    }
}

impl std::str::FromStr for MacroStrain {
    type Err = StrainError;

    /// Parse `sx=0.2,sa=0,sy=-0.05,kx=0,ky=0`; omitted parameters are 0, each may appear once.
    fn from_str(text: &str) -> Result<Self, StrainError> {
        let syntax = |problem: String| StrainError::Syntax { text: text.into(), problem };
        const KEYS: [&str; 5] = ["sx", "sa", "sy", "kx", "ky"];
        let mut values: [Option<f64>; 5] = [None; 5];
        for item in text.split(',').map(str::trim).filter(|s| !s.is_empty()) {
            let (key, value) =
                item.split_once('=').ok_or_else(|| syntax(format!("'{item}' is not key=value")))?;
            let slot = KEYS
                .iter()
                .position(|k| *k == key.trim())
                .ok_or_else(|| syntax(format!("unknown parameter '{}'", key.trim())))?;
            let v: f64 =
                value.trim().parse().map_err(|_| syntax(format!("'{}' is not a number", value.trim())))?;
            if values[slot].replace(v).is_some() {
                return Err(syntax(format!("'{}' given twice", KEYS[slot])));
            }
        }
        let [sx, sa, sy, kx, ky] = values.map(|v| v.unwrap_or(0.0));
        Self::new(sx, sa, sy, kx, ky)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Rotation3, Vector3};
    use proptest::prelude::*;

    fn strain() -> impl Strategy<Value = InPlaneStrain> {
        (-0.9..3.0f64, -0.99..0.99f64, -0.9..3.0f64).prop_map(|(sx, sa, sy)| InPlaneStrain { sx, sa, sy })
    }

    #[test]
    fn identity_is_zero_strain() {
        let s = InPlaneStrain::from_first_fundamental_form(&Matrix2::identity()).expect("valid");
        assert_eq!(s, InPlaneStrain { sx: 0.0, sa: 0.0, sy: 0.0 });
    }

    #[test]
    fn stretch_and_shear_read_off_the_deformed_axes() {
        // a1 = 1.2 e1, a2 at 60 degrees to a1 with length 0.9: sx = 0.2, sy = -0.1, sa = cos 60.
        let a2 = 0.9 * Vector3::new(0.5, 3f64.sqrt() / 2.0, 0.0);
        let f = Matrix3x2::from_columns(&[Vector3::new(1.2, 0.0, 0.0), a2]);
        let s = InPlaneStrain::from_deformation_gradient(&f).expect("valid");
        assert!((s.sx - 0.2).abs() < 1e-15 && (s.sy + 0.1).abs() < 1e-15 && (s.sa - 0.5).abs() < 1e-15);
    }

    proptest! {
        #[test]
        fn round_trip_through_the_first_fundamental_form(s in strain()) {
            let i = s.first_fundamental_form();
            prop_assert!(i[(0, 0)] > 0.0 && i.determinant() > 0.0, "valid strains give SPD forms");
            let back = InPlaneStrain::from_first_fundamental_form(&i).expect("valid");
            prop_assert!((back.sx - s.sx).abs() < 1e-12 && (back.sa - s.sa).abs() < 1e-12 && (back.sy - s.sy).abs() < 1e-12);
        }

        #[test]
        fn strain_ignores_rigid_rotations(s in strain(), axis in prop::array::uniform3(-1.0..1.0f64), angle in -3.0..3.0f64) {
            // Build F with F^T F = I(s), then rotate it.
            let i = s.first_fundamental_form();
            let a1 = Vector3::new(i[(0, 0)].sqrt(), 0.0, 0.0);
            let c = i[(0, 1)] / a1.x;
            let a2 = Vector3::new(c, (i[(1, 1)] - c * c).sqrt(), 0.0);
            let r = Rotation3::new(Vector3::from(axis) * angle);
            let f = Matrix3x2::from_columns(&[r * a1, r * a2]);
            let back = InPlaneStrain::from_deformation_gradient(&f).expect("valid");
            prop_assert!((back.sx - s.sx).abs() < 1e-10 && (back.sa - s.sa).abs() < 1e-10 && (back.sy - s.sy).abs() < 1e-10);
        }
    }

    #[test]
    fn invalid_strains_are_named() {
        assert!(matches!(InPlaneStrain::new(-1.0, 0.0, 0.0), Err(StrainError::Collapsed { name: "sx", .. })));
        assert!(matches!(InPlaneStrain::new(0.0, 0.0, -1.5), Err(StrainError::Collapsed { name: "sy", .. })));
        assert!(matches!(InPlaneStrain::new(0.0, 1.0, 0.0), Err(StrainError::Degenerate(_))));
        assert!(matches!(
            InPlaneStrain::new(f64::NAN, 0.0, 0.0),
            Err(StrainError::NotFinite { name: "sx", .. })
        ));
        assert!(matches!(
            MacroStrain::new(0.0, 0.0, 0.0, f64::INFINITY, 0.0),
            Err(StrainError::NotFinite { name: "kx", .. })
        ));
        let singular = Matrix2::new(1.0, 1.0, 1.0, 1.0);
        assert!(matches!(
            InPlaneStrain::from_first_fundamental_form(&singular),
            Err(StrainError::NotPositiveDefinite)
        ));
    }

    #[test]
    fn strain_text_parses_and_rejects_mistakes() {
        let m: MacroStrain = "sx=0.2,sa=0,sy=-0.05,kx=0,ky=12.5".parse().expect("valid");
        assert_eq!((m.s.sx, m.s.sa, m.s.sy, m.kx, m.ky), (0.2, 0.0, -0.05, 0.0, 12.5));
        let m: MacroStrain = " sy = 0.3 ".parse().expect("omitted parameters are zero");
        assert_eq!((m.s.sx, m.s.sy), (0.0, 0.3));
        assert_eq!(m.second_fundamental_form(), Matrix2::zeros());
        for (text, problem) in [
            ("sx=0.2,sz=1", "unknown parameter 'sz'"),
            ("sx=0.2,sx=0.3", "'sx' given twice"),
            ("sx", "'sx' is not key=value"),
            ("sx=abc", "'abc' is not a number"),
        ] {
            let e = text.parse::<MacroStrain>().expect_err(text).to_string();
            assert!(e.contains(problem), "{text}: {e}");
        }
        assert!(matches!("sx=-1".parse::<MacroStrain>(), Err(StrainError::Collapsed { .. })));
        assert!(matches!("sa=-1.2".parse::<MacroStrain>(), Err(StrainError::Degenerate(_))));
        assert!(matches!("sx=nan".parse::<MacroStrain>(), Err(StrainError::NotFinite { .. })));
    }
}
