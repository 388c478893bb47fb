//! The shell fit (thesis Sec. 6.3): the homogenized shell material fitted to a measurement set.
//!
//! - [`membrane`]: the membrane (6.1) and its extensions fitted by simulating the clamped
//!   swatches in the loop (6.2), with the errors of Sec. 6.3.1.
//! - [`bending`]: the hinge bending (6.4) fitted to the bending tests (Sec. 6.3.2).
//! - [`fit`]: `shell-fit.json` ([`fit::ShellFit`]): both fits, the mesh check and the uniform
//!   targets (6.3) the yarn-level fit starts from.

pub mod bending;
pub mod fit;
pub mod membrane;
