//! The catalog of causes a diagnosis screens: what a base model can get wrong about a measured
//! fabric, each with its id in reports and what it means physically. (The diagnosis screens
//! them at the shell level; the yarn-level confirmation maps a cause to its yarn mechanism.)

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// The catalog of causes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum CauseId {
    /// The yarn stiffens past an onset strain (e.g. plated yarns).
    BiphasicStretch,
    /// Soft then hard yarn compression.
    TwoPhaseContact,
    /// Stronger transverse contraction than the base shell can give.
    AreaPreservation,
    /// The fabric curls: an offset bending response.
    RestCurvature,
    /// Bending stiffness differs by direction.
    AnisotropicBending,
    /// Loading and unloading curves differ.
    FrictionHysteresis,
    /// Nothing significant at the noise level.
    None,
    /// Structured residuals that no candidate fixes.
    Unexplained,
}

impl CauseId {
    /// The id as written in reports.
    pub fn as_str(self) -> &'static str {
        match self {
            CauseId::BiphasicStretch => "biphasic-stretch",
            CauseId::TwoPhaseContact => "two-phase-contact",
            CauseId::AreaPreservation => "area-preservation",
            CauseId::RestCurvature => "rest-curvature",
            CauseId::AnisotropicBending => "anisotropic-bending",
            CauseId::FrictionHysteresis => "friction-hysteresis",
            CauseId::None => "none",
            CauseId::Unexplained => "unexplained",
        }
    }

    /// What the cause means physically.
    pub fn explanation(self) -> &'static str {
        match self {
            CauseId::BiphasicStretch => {
                "the fabric stiffens past an onset strain, as yarns do whose fibres or plies straighten and then \
                 stretch (plated yarns, Sec. 6.4.1): the force grows faster at large stretch than one \
                 strain-independent membrane allows"
            }
            CauseId::TwoPhaseContact => {
                "the fabric contracts freely across the pull and then jams: its yarn contacts are soft and then \
                 hard under compression (two-phase contact, (6.7)), so the transverse contraction stops growing \
                 once the soft outer layers are pressed onto the hard cores, and the force rises with it"
            }
            CauseId::AreaPreservation => {
                "the fabric contracts across the pull more than a plain anisotropic StVK membrane can while \
                 matching the force: it preserves area (the Neo-Hookean terms of (6.1))"
            }
            CauseId::RestCurvature => "the fabric curls at rest: its bending response is offset",
            CauseId::AnisotropicBending => "the bending stiffness differs between directions",
            CauseId::FrictionHysteresis => {
                "unloading takes less force than loading at the same stretch: inter-yarn friction dissipates \
                 energy (hysteresis, Sec. 6.2.3)"
            }
            CauseId::None => "the base model reproduces the held-out measurements within their noise",
            CauseId::Unexplained => {
                "the base model misses the held-out measurements by more than their noise, and no candidate \
                 in the catalog fixes it"
            }
        }
    }

    /// The candidates screened, in report order.
    pub const CANDIDATES: [CauseId; 6] = [
        CauseId::AreaPreservation,
        CauseId::BiphasicStretch,
        CauseId::FrictionHysteresis,
        CauseId::TwoPhaseContact,
        CauseId::RestCurvature,
        CauseId::AnisotropicBending,
    ];
}
