//! How to diagnose: the targets, the swatch mesh and the optimizer iterations per model
//! ([`DiagnoseSettings`]), and the budgets `calibrate diagnose` offers ([`Budget`]), which also
//! size the yarn-level confirmation.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use crate::optimize::lm::LmSettings;
use crate::yarn::confirm::SearchSize;
use crate::yarn::settings::YarnFitSettings;

/// How to diagnose.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct DiagnoseSettings {
    /// Targets per direction (even ones fitted, odd ones held out).
    pub targets_per_direction: usize,
    /// The stretch range ends where the measured force reaches this (N).
    pub force_cap_n: f64,
    /// Mesh edge length of the simulated swatches (m).
    pub spacing_m: f64,
    /// The simulation-in-the-loop iterations per model.
    pub lm: LmSettings,
}

impl Default for DiagnoseSettings {
    fn default() -> Self {
        Self {
            targets_per_direction: 10,
            force_cap_n: 5.0,
            spacing_m: 0.005,
            lm: LmSettings { max_iterations: 30, ..LmSettings::default() },
        }
    }
}

/// Time against confidence: the swatch mesh and optimizer iterations of every model, and the
/// size of the yarn-level confirmation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum Budget {
    /// Coarse swatches (8 mm), 10 optimizer iterations per model; no yarn-level confirmation.
    Quick,
    /// 5 mm swatches, 30 iterations per model; the cause confirmed on the tile by a reduced
    /// yarn-level fit (swarm 16 x 3 on 5 targets per direction, Gauss-Newton 8 Jacobians on 8).
    ///
    /// See [`SearchSize::Reduced`].
    Normal,
    /// 3.5 mm swatches, 80 iterations per model; the confirmation by the full yarn-level fit
    /// (swarm 64 x 10 on 7 targets, Gauss-Newton 20 Jacobians on 20).
    ///
    /// See [`SearchSize::Full`].
    Thorough,
}

impl Budget {
    /// The settings of this budget with `targets_per_direction` targets up to `force_cap_n`.
    pub fn settings(self, targets_per_direction: usize, force_cap_n: f64) -> DiagnoseSettings {
        let (spacing_m, max_iterations) = match self {
            Budget::Quick => (0.008, 10),
            Budget::Normal => (0.005, 30),
            Budget::Thorough => (0.0035, 80),
        };
        DiagnoseSettings {
            targets_per_direction,
            force_cap_n,
            spacing_m,
            lm: LmSettings { max_iterations, ..LmSettings::default() },
        }
    }

    /// The yarn-level confirmation's fit settings (none for `quick`).
    pub fn confirmation(self) -> Option<YarnFitSettings> {
        match self {
            Budget::Quick => None,
            Budget::Normal => Some(SearchSize::Reduced.settings()),
            Budget::Thorough => Some(SearchSize::Full.settings()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn budgets_trade_mesh_and_iterations_and_size_the_confirmation() {
        let quick = Budget::Quick.settings(10, 5.0);
        let normal = Budget::Normal.settings(10, 5.0);
        let thorough = Budget::Thorough.settings(12, 4.0);
        assert_eq!((quick.spacing_m, quick.lm.max_iterations), (0.008, 10));
        // The normal budget is the library's default diagnosis.
        assert_eq!(normal, DiagnoseSettings::default());
        assert_eq!((thorough.spacing_m, thorough.lm.max_iterations), (0.0035, 80));
        assert_eq!((thorough.targets_per_direction, thorough.force_cap_n), (12, 4.0));
        assert_eq!(Budget::Quick.confirmation(), None);
        assert_eq!(Budget::Normal.confirmation(), Some(SearchSize::Reduced.settings()));
        assert_eq!(Budget::Thorough.confirmation(), Some(SearchSize::Full.settings()));
    }
}
