//! The `rvesolve` artifact: one periodic tile solve (thesis Ch. 3) and what came out of it.

use serde::{Deserialize, Serialize};

use crate::check;
use crate::error::ValidationError;

/// A macroscale strain as sampled: in-plane strain (4.1) and curvatures along X1, X2 (1/m).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
pub struct StrainSample {
    /// Stretch along X1 (weft).
    pub sx: f64,
    /// Shear: cosine of the angle between the deformed axes.
    pub sa: f64,
    /// Stretch along X2 (warp).
    pub sy: f64,
    /// Curvature along X1 (1/m): `II = diag(kx, ky)`.
    pub kx: f64,
    /// Curvature along X2 (1/m).
    pub ky: f64,
}

/// The result of a tile solve. A solve that did not converge carries no energy or stress.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
pub struct RveSolve {
    /// Pattern name.
    pub pattern: String,
    /// Yarn model name.
    pub model: String,
    /// The macroscale strain imposed.
    pub strain: StrainSample,
    /// Whether the equilibrium was found (A.33).
    pub converged: bool,
    /// Why the solver stopped (`converged`, `iteration_limit`, `line_search_failed`,
    /// `factorization_failed`).
    pub stop_reason: String,
    /// Homogenized energy density (3.22) (J/m²); absent when not converged.
    pub energy_density_j_m2: Option<f64>,
    /// Homogenized stress `dΨ/d(sx, sa, sy, kx, ky)` (3.23c) from the yarn forces at equilibrium
    /// (J/m² per unit strain; J/m per unit curvature); absent when not converged or not asked
    /// for. New in schema version 2 (absent in files of version 1).
    #[serde(default)]
    pub stress: Option<[f64; 5]>,
    /// The same stress by central differences of warm-started solves (the check route of
    /// Sec. 3.2.2); absent when not converged or not asked for.
    pub stress_fd: Option<[f64; 5]>,
    /// Newton iterations.
    pub iterations: u32,
    /// Final projected gradient relative to the affine start's (A.33).
    pub gradient_ratio: f64,
    /// Wall time of the solve (s).
    pub seconds: f64,
    /// Equilibrium yarn centreline vertices of the tile (m, world frame of the deformed RVE).
    pub positions_m: Vec<[f64; 3]>,
    /// Equilibrium edge twists (rad), by source vertex.
    pub edge_twist_rad: Vec<f64>,
}

impl RveSolve {
    /// Check the invariants: finite values, sizes, and no numbers from failed solves.
    pub fn validate(&self) -> Result<(), ValidationError> {
        let s = self.strain;
        check::finite("strain", &[s.sx, s.sa, s.sy, s.kx, s.ky])?;
        check::finite_rows("positions_m", &self.positions_m)?;
        check::len("edge_twist_rad", self.edge_twist_rad.len(), self.positions_m.len(), "vertices")?;
        check::finite("edge_twist_rad", &self.edge_twist_rad)?;
        if self.converged != self.energy_density_j_m2.is_some() {
            return Err(ValidationError::new(
                "energy_density_j_m2",
                "present exactly when the solve converged (a failed solve reports no number)",
            ));
        }
        for (name, stress) in [("stress", &self.stress), ("stress_fd", &self.stress_fd)] {
            match stress {
                Some(_) if !self.converged => {
                    return Err(ValidationError::new(name, "a failed solve reports no stress"));
                }
                Some(values) => check::finite(name, values)?,
                None => {}
            }
        }
        if let Some(e) = self.energy_density_j_m2 {
            check::finite("energy_density_j_m2", &[e])?;
        }
        Ok(())
    }

    /// A human summary.
    pub fn summary(&self) -> String {
        let s = self.strain;
        let energy = match self.energy_density_j_m2 {
            Some(e) => format!("{e:.6e} J/m²"),
            None => "none (not converged)".into(),
        };
        let mut out = format!(
            "rve solve of '{}' with '{}'\n  strain: sx={} sa={} sy={} kx={} ky={}\n  {}: {} after {} iterations ({:.2} s), gradient ratio {:.1e}\n  energy density: {energy}",
            self.pattern,
            self.model,
            s.sx,
            s.sa,
            s.sy,
            s.kx,
            s.ky,
            if self.converged { "converged" } else { "NOT CONVERGED" },
            self.stop_reason,
            self.iterations,
            self.seconds,
            self.gradient_ratio,
        );
        for (label, stress) in [("(3.23c)", self.stress), ("(finite differences)", self.stress_fd)] {
            if let Some(st) = stress {
                out.push_str(&format!(
                    "\n  stress {label}: dsx {:.4e}, dsa {:.4e}, dsy {:.4e}, dkx {:.4e}, dky {:.4e}",
                    st[0], st[1], st[2], st[3], st[4]
                ));
            }
        }
        out
    }
}
