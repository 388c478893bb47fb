#![doc = include_str!("../README.md")]

pub mod assembly;
pub mod broadphase;
pub mod ccd;
pub mod checkpoint;
pub mod homogenize;
pub mod messages;
pub mod model;
pub mod placement;
pub mod relax;
pub mod residual;
pub mod sample;
pub mod solve;
pub mod sweep;

pub use assembly::Assembled;
pub use model::{RveError, RveModel};
pub use placement::Placement;
pub use relax::{RelaxError, RelaxMethod, RelaxOptions, RelaxReport, relax};
pub use solve::{Iterate, SolveOptions, SolveReport, StepControl, StopReason, solve, solve_observed};
