//! Shared test fixtures.

use yarnhom_shell::StvkNeoHookean;

/// An anisotropic knit-like membrane with area terms (J/m²).
pub(crate) fn knit_membrane() -> StvkNeoHookean {
    StvkNeoHookean {
        k_xx: 120.0,
        k_xy: 30.0,
        k_yy: 40.0,
        k_ss: 25.0,
        k_n1: 5.0,
        k_n2: 2.0,
        stiffening: None,
        jamming: None,
    }
}
