//! Simulated experiments: the tests of a measurement set, run on a shell material.
//!
//! - [`uniform`]: the uniform uniaxial state (6.3) of a membrane, the cheap stand-in for a
//!   stretch test and the source of the uniform targets.
//! - [`swatch`]: the clamped stretch test, simulated to equilibrium (6.2).
//! - [`strip`]: a clamped strip under its weight, the ground of the bending tests:
//!   [`pear_loop`] (both ends clamped, thesis Sec. 6.2.3) and [`cantilever`] (one end clamped,
//!   both faces).
//! - [`bending_tests`]: a set's bending tests simulated together, with their normalized errors.
//! - [`synth`]: synthetic measurement sets, the tests simulated on a known truth with a hidden
//!   effect and noise.

pub mod bending_tests;
pub mod cantilever;
pub mod pear_loop;
pub mod strip;
pub mod swatch;
pub mod synth;
pub mod uniform;
