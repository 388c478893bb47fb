#![doc = include_str!("../README.md")]

pub mod bend_twist;
pub mod contact;
pub mod frames;
pub mod rod;
pub mod stretch;
#[cfg(test)]
mod testing;
pub mod vec3;
pub mod yarn_model;

pub use bend_twist::{BendTwist, BendTwistDofs, BendTwistReference, curvature_and_twist};
pub use contact::{ContactLaw, contact_energy, contact_energy_only};
pub use frames::EdgeFrame;
pub use rod::{RestShape, Rod, RodMaterial};
pub use stretch::{StretchLaw, stretch_energy};
pub use yarn_model::rod_laws;
