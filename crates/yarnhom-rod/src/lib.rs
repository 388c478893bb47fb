//! Yarn mechanics as element energies with exact gradients and Hessians.
//!
//! - [`stretch`]: edge stretching, linear (discrete elastic rods) and biphasic (6.5);
//! - [`bend_twist`]: bending and twisting of discrete elastic rods (Bergou et al. 2008, 2010)
//!   with rest curvature and twist, `γ`-scaled stiffness (3.25) or isotropic `k_b` (6.6);
//! - [`frames`]: parallel transport and time-parallel reference frames;
//! - [`contact`]: yarn-yarn contact between edges, Kaldor et al. (2008) and the two-phase
//!   barrier (6.7);
//! - [`rod`]: one open or closed rod assembled from the stretch and bend-twist elements.

pub mod bend_twist;
pub mod contact;
pub mod frames;
pub mod rod;
pub mod stretch;
#[cfg(test)]
mod testing;
pub mod vec3;

pub use bend_twist::{BendTwist, BendTwistDofs, BendTwistReference, curvature_and_twist};
pub use contact::{ContactLaw, contact_energy, contact_energy_only};
pub use frames::EdgeFrame;
pub use rod::{Rod, RodMaterial};
pub use stretch::{StretchLaw, stretch_energy};
