//! The yarn-level fit (thesis Sec. 6.5): the parameters of the Ch. 6 yarn model whose periodic
//! tile reproduces the uniform targets of a fitted shell.
//!
//! - [`params`]: the fitted and held parameters, their search box and switchable mechanisms.
//! - [`tile`]: the periodic tile under a uniaxial stretch (6.9), (6.10).
//! - [`objective`]: the targets and the objective (6.11).
//! - [`settings`]: how a fit runs (swarm, local step, targets per direction).
//! - [`problem`]: the estimation problem (geometry, fixed quantities, rest-shape estimation,
//!   target source) and the evaluation of a parameter set.
//! - [`local`]: the local step (COBYLA, Levenberg-Marquardt, Gauss-Newton).
//! - [`fit`]: the fit itself, swarm then local step, and `yarn-fit.json` ([`fit::YarnFit`]).
//! - [`confirm`]: the yarn-level confirmation of a diagnosed cause by nested fits.

pub mod confirm;
pub mod fit;
pub mod local;
pub mod objective;
pub mod params;
pub mod problem;
pub mod settings;
pub mod tile;
