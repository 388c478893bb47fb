//! Optimizers and model comparison, shared by every fit of the crate.
//!
//! - [`lm`]: Levenberg-Marquardt for small least-squares problems whose residuals come from
//!   simulations (the shell and bending fits, the yarn-level local step).
//! - [`swarm`]: a particle swarm over a box (the yarn-level global step).
//! - [`akaike`]: the Akaike criterion by which nested models are compared (the diagnosis and the
//!   yarn-level confirmation).
//!
//! Nothing here knows about fabrics: the rooms above call these with their own residuals.

pub mod akaike;
pub mod lm;
pub mod swarm;
