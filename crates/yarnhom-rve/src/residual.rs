//! How far a pattern's stored state is from an equilibrium of a yarn model, and which contact
//! stiffness would make it one.
//!
//! A published rest state (e.g. `hylc-patterns/*.pyp`) is an equilibrium of the code that made
//! it. Evaluated in this model at its own periods and zero strain, its remaining force tells
//! whether the two models agree: split by energy term, the generalized forces (gradient
//! projected on the solver's constraints, [`mod@crate::solve`]) of stretching `f_s`, bending and
//! twisting `f_b` and contact `f_c` should cancel. The contact scale `c` minimizing
//! `|f_s + f_b + c f_c|` names how much harder or softer this model's contact is than the one
//! the state balances. Pooled over patterns (weighted by their stretching forces), it is the
//! estimate behind [`yarnhom_rod::contact::KALDOR_TABLE_4_1_NORMALIZATION`].

use nalgebra::DVector;
use yarnhom_artifacts::{Pattern, YarnMechanics, YarnModel};
use yarnhom_geom::MacroStrain;

use crate::assembly::{RveState, Want, assemble};
use crate::homogenize::placement;
use crate::model::{RveError, RveModel};
use crate::solve::{constraints, projected};

/// The forces left at a pattern's stored state under a yarn model, by energy term.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EquilibriumResidual {
    /// Norm of the projected stretching force `|f_s|` (N; twist entries in N m).
    pub stretch: f64,
    /// Norm of the projected bending and twisting force `|f_b|`.
    pub bend_twist: f64,
    /// Norm of the projected contact force `|f_c|`.
    pub contact: f64,
    /// Norm of the projected total force `|f_s + f_b + f_c|`.
    pub total: f64,
    /// `|f_s + f_b|²`, `(f_s + f_b)·f_c` and `|f_c|²` over `|f_s|²`: the pieces of
    /// `|f_s + f_b + c f_c|² / |f_s|²` as a quadratic in the contact scale `c`.
    pub quadratic: [f64; 3],
}

impl EquilibriumResidual {
    /// `|f_s + f_b + c f_c| / |f_s|`: the residual relative to the stretching force, with the
    /// contact scaled by `c`.
    pub fn relative_at(&self, contact_scale: f64) -> f64 {
        let [aa, ab, bb] = self.quadratic;
        (aa + 2.0 * contact_scale * ab + contact_scale * contact_scale * bb).max(0.0).sqrt()
    }

    /// The contact scale that leaves the smallest residual; `None` without contact forces.
    pub fn best_contact_scale(&self) -> Option<f64> {
        let [_, ab, bb] = self.quadratic;
        (bb > 0.0).then(|| -ab / bb)
    }

    /// The residual as `yarnhom rve residual` prints it: the generalized forces of each kind,
    /// their total relative to the stretching force, and the contact scale that balances the
    /// state best.
    pub fn report(&self) -> String {
        let mut lines = vec![
            format!("  stretching          {:.4e} N", self.stretch),
            format!("  bending, twisting   {:.4e} N", self.bend_twist),
            format!("  contact             {:.4e} N", self.contact),
            format!(
                "  total               {:.4e} N ({:.3} of the stretching force)",
                self.total,
                self.relative_at(1.0)
            ),
        ];
        lines.push(match self.best_contact_scale() {
            Some(c) => format!(
                "  best contact scale  {c:.3} (the contact that balances this state best), leaving {:.3} of the stretching force",
                self.relative_at(c)
            ),
            None => "  no contact force: no yarns within reach of each other".into(),
        });
        lines.join("\n")
    }
}

/// The contact scale that best balances several stored states together: least squares over
/// their residuals relative to their stretching forces; `None` without contact forces.
pub fn pooled_contact_scale(residuals: &[EquilibriumResidual]) -> Option<f64> {
    let (ab, bb) =
        residuals.iter().fold((0.0, 0.0), |(ab, bb), r| (ab + r.quadratic[1], bb + r.quadratic[2]));
    (bb > 0.0).then(|| -ab / bb)
}

/// The forces left at `pattern`'s stored geometry (its own periods, zero strain) under `yarn`.
pub fn equilibrium_residual(pattern: &Pattern, yarn: &YarnModel) -> Result<EquilibriumResidual, RveError> {
    let force = |bending: bool, contact: bool| -> Result<DVector<f64>, RveError> {
        let model = RveModel::new(pattern, &with_terms(yarn, bending, contact))?;
        let zero = MacroStrain::new(0.0, 0.0, 0.0, 0.0, 0.0).expect("zero strain is valid");
        let placement = placement(&model, &zero);
        let state = RveState::affine(&model, &placement);
        let gradient = assemble(&model, &placement, &state, &state.g, Want::EnergyGradient).gradient;
        Ok(projected(&constraints(&model, &placement), &gradient))
    };
    let stretch = force(false, false)?;
    let elastic = force(true, false)?;
    let total = force(true, true)?;
    let bend_twist = &elastic - &stretch;
    let contact = &total - &elastic;
    let scale = stretch.norm_squared().max(f64::MIN_POSITIVE);
    Ok(EquilibriumResidual {
        stretch: stretch.norm(),
        bend_twist: bend_twist.norm(),
        contact: contact.norm(),
        total: total.norm(),
        quadratic: [
            elastic.norm_squared() / scale,
            elastic.dot(&contact) / scale,
            contact.norm_squared() / scale,
        ],
    })
}

/// `yarn` with its bending and twisting, or its contact, switched off.
fn with_terms(yarn: &YarnModel, bending: bool, contact: bool) -> YarnModel {
    let keep = |on: bool, value: f64| if on { value } else { 0.0 };
    let mechanics = match yarn.mechanics {
        YarnMechanics::ElasticRod { youngs_modulus_pa, shear_modulus_pa, gamma, contact_stiffness_kg_s2 } => {
            YarnMechanics::ElasticRod {
                youngs_modulus_pa,
                shear_modulus_pa,
                gamma: keep(bending, gamma),
                contact_stiffness_kg_s2: keep(contact, contact_stiffness_kg_s2),
            }
        }
        YarnMechanics::Biphasic { k_s1_n, k_s2_n, eps_bar, k_b_nm2, r1_m, k_c1_n_m, r2_m, k_c2_n_m } => {
            YarnMechanics::Biphasic {
                k_s1_n,
                k_s2_n,
                eps_bar,
                k_b_nm2: keep(bending, k_b_nm2),
                r1_m,
                k_c1_n_m: keep(contact, k_c1_n_m),
                r2_m,
                k_c2_n_m: keep(contact, k_c2_n_m),
            }
        }
    };
    YarnModel { mechanics, ..yarn.clone() }
}
