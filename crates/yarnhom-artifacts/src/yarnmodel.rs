//! The `yarnmodel` artifact: the mechanical parameters of a yarn.
//!
//! Two model families, as in the thesis:
//! - [`YarnMechanics::ElasticRod`]: discrete elastic rods with Kaldor et al. (2008) contact, the
//!   model of Ch. 3-5 whose parameters are the columns of Table 4.1;
//! - [`YarnMechanics::Biphasic`]: the Ch. 6 model estimated from fabric measurements: biphasic
//!   stretch (6.5), isotropic bending (6.6) and two-phase contact (6.7).

use serde::{Deserialize, Serialize};

use crate::check;
use crate::error::{Error, ValidationError};

/// A yarn model: geometry, density and one of the mechanical model families.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
pub struct YarnModel {
    /// Short name, e.g. `table4.1:rib`.
    pub name: String,
    /// Yarn radius (m).
    pub radius_m: f64,
    /// Yarn material density (kg/m^3).
    pub density_kg_m3: f64,
    /// The mechanical model and its parameters.
    pub mechanics: YarnMechanics,
}

/// The mechanical model of a yarn.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(tag = "model", rename_all = "snake_case")]
pub enum YarnMechanics {
    /// Discrete elastic rods (Bergou et al. 2008, 2010) with bending and twisting scaled by
    /// `gamma` (3.25) and Kaldor et al. (2008) contact: the rows of Table 4.1.
    ElasticRod {
        /// Young's modulus E (Pa).
        youngs_modulus_pa: f64,
        /// Shear modulus G (Pa).
        shear_modulus_pa: f64,
        /// Multiplier gamma of the bending and twisting energies (3.25).
        gamma: f64,
        /// Contact stiffness k_contact (kg/s^2) as Table 4.1 states it; the contact integral
        /// applies 0.64 of it, the convention measured from the published rest states
        /// (`yarnhom rve residual`).
        contact_stiffness_kg_s2: f64,
    },
    /// The Ch. 6 model: biphasic stretch (6.5), isotropic bending (6.6), two-phase contact (6.7).
    Biphasic {
        /// Low-stretch stiffness k_s1: force per unit yarn strain (N).
        k_s1_n: f64,
        /// High-stretch (and compression) stiffness k_s2 (N).
        k_s2_n: f64,
        /// Onset of high stretch, eps_bar_s (strain, dimensionless).
        eps_bar: f64,
        /// Bending stiffness k_b (N m^2).
        k_b_nm2: f64,
        /// Outer (soft) contact radius R_1 (m).
        r1_m: f64,
        /// Outer contact stiffness k_c1 (N/m).
        k_c1_n_m: f64,
        /// Inner (stiff) contact radius R_2 (m).
        r2_m: f64,
        /// Inner contact stiffness k_c2 (N/m); 0 leaves only the outer barrier (single-phase
        /// contact).
        k_c2_n_m: f64,
    },
}

/// Table 4.1 of the thesis: (row, E, G, gamma, k_contact, rho, radius). The radius is 1 mm for
/// the regular patterns and 0.1 mm for the small variants (Sec. 4.3).
const TABLE_4_1: [(&str, f64, f64, f64, f64, f64, f64); 7] = [
    ("basket", 1e5, 4e4, 0.1, 1.2e1, 1.2e2, 1e-3),
    ("honey", 5e5, 2e5, 0.1, 6e1, 1.2e2, 1e-3),
    ("rib", 5e5, 2e5, 0.001, 6e1, 6e1, 1e-3),
    ("satin", 1e5, 4e4, 0.1, 1.2e1, 1.2e2, 1e-3),
    ("stock", 5e5, 2e5, 0.001, 6e1, 1.2e2, 1e-3),
    ("satin-small", 1e6, 4e5, 1.0, 1e2, 1.2e3, 1e-4),
    ("stock-small", 1e6, 4e5, 1.0, 1e2, 1.2e3, 1e-4),
];

impl YarnModel {
    /// Names of the built-in Table 4.1 rows (`stock`, `rib`, ...).
    pub fn table_4_1_rows() -> impl Iterator<Item = &'static str> {
        TABLE_4_1.iter().map(|r| r.0)
    }

    /// The yarn model of one row of Table 4.1.
    pub fn table_4_1(row: &str) -> Option<YarnModel> {
        let &(name, e, g, gamma, k, rho, r) = TABLE_4_1.iter().find(|r| r.0 == row)?;
        Some(YarnModel {
            name: format!("table4.1:{name}"),
            radius_m: r,
            density_kg_m3: rho,
            mechanics: YarnMechanics::ElasticRod {
                youngs_modulus_pa: e,
                shear_modulus_pa: g,
                gamma,
                contact_stiffness_kg_s2: k,
            },
        })
    }

    /// Named parameters with units, in a stable order (for summaries and diffs).
    pub fn parameters(&self) -> Vec<(&'static str, f64)> {
        let mut out = vec![("radius_m", self.radius_m), ("density_kg_m3", self.density_kg_m3)];
        match self.mechanics {
            YarnMechanics::ElasticRod {
                youngs_modulus_pa,
                shear_modulus_pa,
                gamma,
                contact_stiffness_kg_s2,
            } => {
                out.extend([
                    ("youngs_modulus_pa", youngs_modulus_pa),
                    ("shear_modulus_pa", shear_modulus_pa),
                    ("gamma", gamma),
                    ("contact_stiffness_kg_s2", contact_stiffness_kg_s2),
                ]);
            }
            YarnMechanics::Biphasic { k_s1_n, k_s2_n, eps_bar, k_b_nm2, r1_m, k_c1_n_m, r2_m, k_c2_n_m } => {
                out.extend([
                    ("k_s1_n", k_s1_n),
                    ("k_s2_n", k_s2_n),
                    ("eps_bar", eps_bar),
                    ("k_b_nm2", k_b_nm2),
                    ("r1_m", r1_m),
                    ("k_c1_n_m", k_c1_n_m),
                    ("r2_m", r2_m),
                    ("k_c2_n_m", k_c2_n_m),
                ]);
            }
        }
        out
    }

    /// The small-strain stretch stiffness of the yarn, force per unit strain (N): `E π r²` for
    /// an elastic rod (as `yarnhom-rod` builds it), the low-stretch stiffness `k_s1` of (6.5)
    /// for the biphasic model.
    pub fn stretch_stiffness_n(&self) -> f64 {
        match self.mechanics {
            YarnMechanics::ElasticRod { youngs_modulus_pa, .. } => {
                youngs_modulus_pa * std::f64::consts::PI * self.radius_m * self.radius_m
            }
            YarnMechanics::Biphasic { k_s1_n, .. } => k_s1_n,
        }
    }

    /// Check that every parameter is physical.
    pub fn validate(&self) -> Result<(), ValidationError> {
        for (name, value) in self.parameters() {
            match name {
                // eps_bar = 0: stiff from the start; k_c2 = 0: single-phase contact.
                "eps_bar" | "k_c2_n_m" => check::non_negative(name, value)?,
                _ => check::positive(name, value)?,
            }
        }
        if let YarnMechanics::Biphasic { r1_m, r2_m, k_s1_n, k_s2_n, .. } = self.mechanics {
            if r2_m > r1_m {
                return Err(ValidationError::new(
                    "r2_m",
                    format!("the inner contact radius ({r2_m}) must not exceed the outer one ({r1_m})"),
                ));
            }
            if k_s1_n > k_s2_n {
                return Err(ValidationError::new(
                    "k_s1_n",
                    format!(
                        "the low-stretch stiffness ({k_s1_n}) must not exceed the high-stretch stiffness ({k_s2_n})"
                    ),
                ));
            }
        }
        Ok(())
    }

    /// A human summary (for `yarnhom inspect`).
    pub fn summary(&self) -> String {
        let family = match self.mechanics {
            YarnMechanics::ElasticRod { .. } => "elastic rod (Ch. 3-5, Table 4.1)",
            YarnMechanics::Biphasic { .. } => "biphasic (Ch. 6)",
        };
        let mut s = format!("yarn model '{}': {family}", self.name);
        for (name, value) in self.parameters() {
            s.push_str(&format!("\n  {name} = {value}"));
        }
        s
    }

    /// Read a payload of an older schema version.
    ///
    /// Version 0 was a flat Table 4.1 row (`e`, `g`, `gamma`, `k_contact`, `rho`, `radius`)
    /// without the Ch. 6 family; it becomes an [`YarnMechanics::ElasticRod`] model.
    pub fn migrate(version: u32, payload: &[u8]) -> Result<Self, Error> {
        match version {
            0 => {
                let v0: YarnModelV0 = rmp_serde::from_slice(payload)
                    .map_err(|e| Error::Decode { what: "yarnmodel v0", message: e.to_string() })?;
                Ok(v0.into())
            }
            _ => Err(Error::NoMigration { kind: "yarnmodel".into(), found: version, supported: 1 }),
        }
    }
}

/// Schema version 0 of `yarnmodel`: one flat Table 4.1 row.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
pub struct YarnModelV0 {
    /// Model name.
    pub name: String,
    /// Young's modulus (Pa).
    pub e: f64,
    /// Shear modulus (Pa).
    pub g: f64,
    /// Bending/twisting multiplier.
    pub gamma: f64,
    /// Contact stiffness (kg/s^2).
    pub k_contact: f64,
    /// Density (kg/m^3).
    pub rho: f64,
    /// Yarn radius (m).
    pub radius: f64,
}

impl From<YarnModelV0> for YarnModel {
    fn from(v0: YarnModelV0) -> Self {
        YarnModel {
            name: v0.name,
            radius_m: v0.radius,
            density_kg_m3: v0.rho,
            mechanics: YarnMechanics::ElasticRod {
                youngs_modulus_pa: v0.e,
                shear_modulus_pa: v0.g,
                gamma: v0.gamma,
                contact_stiffness_kg_s2: v0.k_contact,
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stretch_stiffness_is_the_axial_stiffness_of_each_family() {
        let stock = YarnModel::table_4_1("stock").expect("a Table 4.1 row");
        // E pi r^2 with E = 5e5 Pa and r = 1 mm.
        assert!((stock.stretch_stiffness_n() - 5e5 * std::f64::consts::PI * 1e-6).abs() < 1e-12);
        let biphasic = YarnModel {
            mechanics: YarnMechanics::Biphasic {
                k_s1_n: 2.5,
                k_s2_n: 40.0,
                eps_bar: 0.05,
                k_b_nm2: 1e-6,
                r1_m: 1e-3,
                k_c1_n_m: 10.0,
                r2_m: 5e-4,
                k_c2_n_m: 100.0,
            },
            ..stock
        };
        assert_eq!(biphasic.stretch_stiffness_n(), 2.5);
    }
}
