//! The periodic yarn tile of thesis Ch. 3.
//!
//! Implementation choice: the "alternative implementation" of Sec. 3.3.3. The unknowns are only
//! the tile's own DOFs `g = (Rᵀũ, θ)`: the unrotated fluctuation of every vertex and the twist of
//! every edge. Periodic images are copies placed by the co-rotated map
//! `x = φ(X) + h n(X) + R(X) g` (3.13, 3.21), with `X` the vertex's material point in its tile
//! image, so the periodicity constraints (3.21, 3.27) hold by construction and every element is
//! counted exactly once (no ghost segments, no fractional counting).
//!
//! - [`model`]: the tile's elements and rest state, built from a pattern and a yarn model;
//! - [`placement`]: where vertex instances go under a macro strain;
//! - [`assembly`]: energy, gradient and Hessian over `g`;
//! - [`broadphase`]: the uniform-grid search for edge pairs within contact reach, among the pairs
//!   that are near each other in the fabric ([`RveModel::can_touch`]: a tile bent round onto
//!   itself does not collide with itself);
//! - [`ccd`]: additive continuous collision detection for collision-safe steps (A.2.3);
//! - [`mod@solve`]: the constrained Newton solve for the tile's equilibrium;
//! - [`homogenize`]: energy density and stress at a macro strain, and a solve reported as an
//!   `rvesolve` artifact;
//! - [`messages`]: the tile's states and samples as trace messages;
//! - [`mod@relax`]: rest states (Algorithm 2, Sec. 6.5.2);
//! - [`residual`]: the forces left at a stored state (is a published rest state an equilibrium
//!   of this model, and of which contact stiffness?);
//! - [`sample`]: the sampling plan and parallel sweep engine of the energy database (App. A.3.1);
//! - [`checkpoint`]: the resumable record of a sampling run's finished lines.

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

pub use assembly::Assembled;
pub use model::{RveError, RveModel};
pub use placement::Placement;
pub use relax::{RelaxError, RelaxMethod, RelaxOptions, RelaxReport, relax};
pub use solve::{Iterate, SolveOptions, SolveReport, StepControl, StopReason, solve, solve_observed};
