//! Shell materials: an energy density of the discrete fundamental forms (the membrane-and-
//! bending part, evaluated per triangle (4.8)) and an optional edge-hinge bending energy (6.4).
//!
//! - [`ShellMaterial::spline`]: the homogenized yarn-level material of Ch. 4 (a
//!   [`SplineMaterial`] fitted by `yarnhom fit` or imported from ARCSim-HYLC).
//! - [`ShellMaterial::stvk`]: the Ch. 6 anisotropic StVK with a Neo-Hookean area term (6.1),
//!   with the anisotropic edge bending (6.4).

use nalgebra::{Matrix3, Vector3, Vector6};
pub use yarnhom_artifacts::membrane::{HingeBending, MembraneMaterial, Stiffening, StvkNeoHookean};
use yarnhom_fit::{EnergyJet, SplineMaterial};

/// The energy density of the forms.
#[derive(Debug, Clone)]
pub enum FormsEnergy {
    /// A homogenized spline material (4.3), (A.34): membrane and bending.
    Spline(Box<SplineMaterial>),
    /// Anisotropic StVK + Neo-Hookean (6.1): membrane only.
    Stvk(StvkNeoHookean),
}

/// A cloth material: mass, the energy density of the forms, optional hinge bending.
#[derive(Debug, Clone)]
pub struct ShellMaterial {
    /// Areal mass density (kg/m²).
    pub areal_density_kg_m2: f64,
    /// The per-triangle energy density.
    pub forms: FormsEnergy,
    /// The per-edge bending energy (6.4), if any.
    pub hinge_bending: Option<HingeBending>,
}

impl ShellMaterial {
    /// A spline material with its own areal density.
    pub fn spline(material: SplineMaterial) -> Self {
        Self {
            areal_density_kg_m2: material.areal_density_kg_m2(),
            forms: FormsEnergy::Spline(Box::new(material)),
            hinge_bending: None,
        }
    }

    /// The Ch. 6 model: (6.1) membrane and (6.4) bending.
    pub fn stvk(areal_density_kg_m2: f64, membrane: StvkNeoHookean, bending: HingeBending) -> Self {
        Self { areal_density_kg_m2, forms: FormsEnergy::Stvk(membrane), hinge_bending: Some(bending) }
    }

    /// The energy density (J/m²) with derivatives in `(I11, I12, I22, II11, II12, II22)`.
    pub fn jet(&self, first: [f64; 3], second: [f64; 3]) -> EnergyJet {
        match &self.forms {
            FormsEnergy::Spline(m) => m.jet(first, second),
            FormsEnergy::Stvk(m) => membrane_jet(m, first),
        }
    }

    /// The energy density only.
    pub fn energy_density(&self, first: [f64; 3], second: [f64; 3]) -> f64 {
        match &self.forms {
            FormsEnergy::Spline(m) => m.energy_density(first, second),
            FormsEnergy::Stvk(m) => membrane_jet(m, first).value,
        }
    }

    /// Whether the forms energy depends on `II` (else the bending comes from hinges only).
    pub fn uses_second_form(&self) -> bool {
        matches!(self.forms, FormsEnergy::Spline(_))
    }
}

/// The shell material of a file: a spline (`.spline.yh` or another form of it, or an ARCSim-HYLC
/// material JSON) or a Ch. 6 material JSON ([`MembraneMaterial`]).
pub fn open_material(path: impl AsRef<std::path::Path>) -> Result<ShellMaterial, yarnhom_artifacts::Error> {
    let path = path.as_ref();
    let input = yarnhom_artifacts::open::open(path)?;
    if let yarnhom_artifacts::open::Contents::Membrane(m) = input.contents {
        return Ok(ShellMaterial::stvk(m.areal_density_kg_m2, m.membrane, m.bending));
    }
    let (_, artifact) = input.into_artifact()?;
    let spline = yarnhom_artifacts::Spline::try_from(artifact).map_err(|other| {
        yarnhom_artifacts::Error::WrongKind { expected: "spline", found: other.kind().into() }.at(path)
    })?;
    Ok(ShellMaterial::spline(SplineMaterial::from(&spline)))
}

/// The membrane energy (6.1) of `m` with derivatives in `(I11, I12, I22, ·, ·, ·)` (no dependence
/// on `II`).
pub fn membrane_jet(m: &StvkNeoHookean, first: [f64; 3]) -> EnergyJet {
    let [a, b, c] = first;
    // Voigt Green strain ε = ((I11 - 1)/2, (I22 - 1)/2, I12), linear in I.
    let eps = Vector3::new(0.5 * (a - 1.0), 0.5 * (c - 1.0), b);
    let d_eps = Matrix3::new(0.5, 0.0, 0.0, 0.0, 0.0, 0.5, 0.0, 1.0, 0.0);
    let k = Matrix3::new(m.k_xx, m.k_xy, 0.0, m.k_xy, m.k_yy, 0.0, 0.0, 0.0, m.k_ss);
    let stvk_gradient = d_eps.transpose() * k * eps;
    let stvk_hessian = d_eps.transpose() * k * d_eps;
    // J = sqrt(det I).
    let det = a * c - b * b;
    let j = det.max(1e-300).sqrt();
    let d_det = Vector3::new(c, -2.0 * b, a);
    let dd_det = Matrix3::new(0.0, 0.0, 1.0, 0.0, -2.0, 0.0, 1.0, 0.0, 0.0);
    let d_j = d_det / (2.0 * j);
    let dd_j = dd_det / (2.0 * j) - d_det * d_det.transpose() / (4.0 * j * j * j);
    let log_j = j.ln();
    let g = m.k_n1 * (j - 1.0).powi(2) + m.k_n2 * log_j * log_j;
    let dg = 2.0 * m.k_n1 * (j - 1.0) + 2.0 * m.k_n2 * log_j / j;
    let ddg = 2.0 * m.k_n1 + 2.0 * m.k_n2 * (1.0 - log_j) / (j * j);
    let mut gradient = stvk_gradient + dg * d_j;
    let mut hessian = stvk_hessian + ddg * d_j * d_j.transpose() + dg * dd_j;
    let mut one_sided = 0.0;
    for (term, sign) in [(&m.stiffening, 1.0), (&m.jamming, -1.0)] {
        if let Some(b) = term {
            one_sided += add_one_sided_term(b, sign, &eps, &mut gradient, &mut hessian);
        }
    }
    let mut jet = EnergyJet {
        value: 0.5 * eps.dot(&(k * eps)) + g + one_sided,
        gradient: Vector6::zeros(),
        hessian: Default::default(),
    };
    jet.gradient.fixed_rows_mut::<3>(0).copy_from(&gradient);
    jet.hessian.fixed_view_mut::<3, 3>(0, 0).copy_from(&hessian);
    jet
}

/// Add `½ k ⟨sign E - onset⟩₊²` on `E11` (`k_weft`) and `E22` (`k_warp`) to the derivatives in
/// `(I11, I12, I22)`, returning its value; `sign` is 1 for [`StvkNeoHookean::stiffening`], -1
/// for [`StvkNeoHookean::jamming`].
fn add_one_sided_term(
    b: &Stiffening,
    sign: f64,
    eps: &Vector3<f64>,
    gradient: &mut Vector3<f64>,
    hessian: &mut Matrix3<f64>,
) -> f64 {
    let mut value = 0.0;
    // E11 = (I11 - 1)/2 and E22 = (I22 - 1)/2: dE/dI = 1/2.
    for (index, strain, k) in [(0, eps[0], b.k_weft), (2, eps[1], b.k_warp)] {
        let excess = (sign * strain - b.onset).max(0.0);
        value += 0.5 * k * excess * excess;
        gradient[index] += 0.5 * sign * k * excess;
        if excess > 0.0 {
            hessian[(index, index)] += 0.25 * k;
        }
    }
    value
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stvk_derivatives_match_finite_differences_and_rest_is_stress_free() {
        let m = StvkNeoHookean {
            stiffening: Some(Stiffening { k_weft: 5.0, k_warp: 2.0, onset: 0.1 }),
            jamming: Some(Stiffening { k_weft: 4.0, k_warp: 3.0, onset: 0.02 }),
            ..crate::test_support::test_membrane()
        };
        let rest = membrane_jet(&m, [1.0, 0.0, 1.0]);
        assert!(rest.value.abs() < 1e-15 && rest.gradient.norm() < 1e-15);
        let first = [1.3, 0.2, 0.9];
        let jet = membrane_jet(&m, first);
        let h = 1e-6;
        for j in 0..3 {
            let (mut p, mut q) = (first, first);
            p[j] += h;
            q[j] -= h;
            let (jp, jq) = (membrane_jet(&m, p), membrane_jet(&m, q));
            assert!((jet.gradient[j] - (jp.value - jq.value) / (2.0 * h)).abs() < 1e-7);
            for i in 0..3 {
                assert!((jet.hessian[(i, j)] - (jp.gradient[i] - jq.gradient[i]) / (2.0 * h)).abs() < 1e-6);
            }
        }
    }

    /// The transverse Green strain `E22` of zero transverse stress at `E11` (Newton on `I22`).
    fn free_transverse_strain(m: &StvkNeoHookean, e11: f64) -> f64 {
        let mut i22 = 1.0;
        for _ in 0..50 {
            let jet = membrane_jet(m, [1.0 + 2.0 * e11, 0.0, i22]);
            i22 -= jet.gradient[2] / jet.hessian[(2, 2)];
        }
        0.5 * (i22 - 1.0)
    }

    #[test]
    fn jamming_stops_the_transverse_contraction_past_its_onset() {
        let free = StvkNeoHookean {
            k_xx: 2.0,
            k_xy: 0.8,
            k_yy: 1.0,
            k_ss: 1.0,
            k_n1: 0.0,
            k_n2: 0.0,
            stiffening: None,
            jamming: None,
        };
        let jammed =
            StvkNeoHookean { jamming: Some(Stiffening { k_weft: 0.0, k_warp: 100.0, onset: 0.05 }), ..free };
        // Before the onset nothing changes; past it the contraction stops near the onset.
        assert!((free_transverse_strain(&jammed, 0.05) - free_transverse_strain(&free, 0.05)).abs() < 1e-12);
        assert!((free_transverse_strain(&free, 0.3) + 0.24).abs() < 1e-9);
        let e22 = free_transverse_strain(&jammed, 0.3);
        assert!(e22 < -0.05 && e22 > -0.052, "{e22}");
    }

    #[test]
    fn the_area_term_resists_inversion() {
        // Uniaxial compression of an isotropic StVK sheet: the Neo-Hookean log term grows
        // without bound as the area vanishes (Fig. 6.5).
        let m = StvkNeoHookean {
            k_xx: 1.0,
            k_xy: 0.0,
            k_yy: 1.0,
            k_ss: 1.0,
            k_n1: 0.0,
            k_n2: 0.1,
            stiffening: None,
            jamming: None,
        };
        let energy = |s: f64| membrane_jet(&m, [s * s, 0.0, 1.0]).value;
        assert!(energy(1e-3) > energy(0.1) && energy(0.1) > energy(0.5));
    }
}
