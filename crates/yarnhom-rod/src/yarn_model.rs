//! The rod and contact laws of a `yarnmodel` artifact: what one yarn model means wherever its
//! yarns are simulated (the periodic tile, the swatch, the calibration).

use yarnhom_artifacts::{YarnMechanics, YarnModel};

use crate::{ContactLaw, RodMaterial, StretchLaw};

/// The rod and contact laws of a yarn model: Table 4.1's elastic rods with Kaldor contact
/// (Ch. 3-5), or the Ch. 6 model: biphasic stretch (6.5), isotropic bending without twisting
/// stiffness (6.6) and the two-phase contact barrier (6.7).
pub fn rod_laws(model: &YarnModel) -> (RodMaterial, ContactLaw) {
    match model.mechanics {
        YarnMechanics::ElasticRod { youngs_modulus_pa, shear_modulus_pa, gamma, contact_stiffness_kg_s2 } => {
            (
                RodMaterial::circular(youngs_modulus_pa, shear_modulus_pa, gamma, model.radius_m),
                ContactLaw::Kaldor { stiffness: contact_stiffness_kg_s2, radius_m: model.radius_m },
            )
        }
        YarnMechanics::Biphasic { k_s1_n, k_s2_n, eps_bar, k_b_nm2, r1_m, k_c1_n_m, r2_m, k_c2_n_m } => (
            RodMaterial {
                stretch: StretchLaw::Biphasic { k_s1_n, k_s2_n, eps_bar },
                bend_stiffness_nm2: [k_b_nm2; 2],
                twist_stiffness_nm2: 0.0,
            },
            ContactLaw::TwoPhase { outer: (r1_m, k_c1_n_m), inner: (r2_m, k_c2_n_m) },
        ),
    }
}
