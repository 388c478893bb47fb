//! Homogenized yarn-level cloth materials (thesis Ch. 4, App. A.3-A.5, B).
//!
//! - [`hermite`]: cubic and bicubic Hermite splines with derivatives and linear extrapolation.
//! - [`curvature`]: principal curvatures of `II` robust at umbilics (A.39)-(A.41).
//! - [`material`]: the spline material `Ψ(I, II)` (4.3), (A.34) with exact derivatives.

pub mod curvature;
pub mod hermite;
pub mod material;

pub use material::{EnergyJet, SplineMaterial};
