//! Implicit, penetration-free dynamics of yarns as discrete elastic rods in contact (thesis
//! Sec. 4.3.1; Kaldor et al. 2008 for the yarn model, Bergou et al. 2010 for the rods, Li et al.
//! 2020 (IPC) for the time step as a minimization and the barriers).
//!
//! A [`Scene`] holds the yarns ([`YarnInput`]: state and rest shape, open or closed), glue
//! springs, the contact law, gravity, obstacles, handles and damping; a [`Simulation`] advances
//! it by backward Euler steps ([`Simulation::step`]), each the minimizer of the incremental
//! potential `1/(2h²) |x - x̃|²_M + V(q) + D(x)` over the DOFs `q` (all vertex positions, then
//! all edge twists), reporting a [`StepReport`] or a [`StepError`].
//!
//! The rules, in one place:
//! - **Masses**: lumped, linear density times half the adjacent rest lengths per vertex. Twists
//!   have no inertia (quasi-static), with a proximal term a billionth of the twist stiffness to
//!   fix the twists' gauge.
//! - **Contact** ([`ContactModel::Kaldor`]: Kaldor's law at the scene's largest yarn radius, or
//!   any [`ContactLaw`]; [`Scene::new`] starts without): between every two edges within the law's
//!   reach, except two edges of one yarn that share a vertex
//!   or are one edge apart, and two edges with ends joined by a glue spring.
//! - **Broad phase**: a uniform spatial hash, radius `reach + margin` (margin
//!   [`SolverOptions::broad_phase_margin_radii`], 2 yarn radii), kept over a step's Newton
//!   iterates as a Verlet list (found anew once a vertex has moved `margin / 4`).
//! - **Step cap**: `α ≤ 0.9 d_ef / (δ_e + δ_f)` per candidate pair (at least the global
//!   `0.9 d_min / (2δ)`), `α ≤ slack / δ` for pairs outside the list (`slack` = `margin / 2`
//!   less the largest move since the list was found), `α ≤ 0.9 gap / approach` per vertex and
//!   obstacle; so centrelines never cross and vertices never enter obstacles.
//! - **Obstacles** ([`Obstacle`]): planes, spheres and axis-aligned boxes, the IPC log barrier on
//!   the gap between the yarn's surface and the obstacle within an activation distance given per
//!   obstacle; Coulomb friction on the velocities after each step, as the shell simulator's.
//! - **Handles** ([`Handle`]): keyframed rigid translations, piecewise linear; held vertices are
//!   Dirichlet conditions, eliminated from the solve. They move to their new positions at a
//!   step's start, under the same caps: a move the caps would cut is an error.
//! - **Wind** ([`YarnWind`]): ARCSim's air drag carried to yarn segments, explicit over a step.
//! - **Damping** ([`Damping`]): Kaldor et al. (2008)'s damping of non-rigid motion over
//!   overlapping windows of 5 consecutive vertices (stride 1), projections fixed per step.
//! - **Convergence**: the Newton step moves no vertex more than `10⁻⁶ r` and no twist more than
//!   `10⁻⁶` rad (or, where the Hessian needed a shift, the residual scaled by `h² / m` and by
//!   the inverse twist stiffness does).
//! - **Determinism**: elements are evaluated in parallel into per-element slots and summed in
//!   element order; results are the same to the bit for any number of rayon threads.

mod caps;
mod checkpoint;
mod contact;
mod damping;
mod handles;
mod input;
mod obstacles;
mod potential;
mod simulation;
mod springs;
mod step;
mod system;
mod wind;

pub use checkpoint::Checkpoint;
pub use damping::Damping;
pub use handles::{Handle, Keyframe};
pub use input::{InputError, YarnInput};
pub use obstacles::{Obstacle, ObstacleShape};
pub use simulation::Simulation;
pub use step::{Energies, StepError, StepReport};
pub use system::{ContactModel, Scene, SolverOptions};
pub use wind::YarnWind;
pub use yarnhom_artifacts::GlueSpring;
pub use yarnhom_rod::{ContactLaw, RodMaterial, StretchLaw};

#[cfg(test)]
mod tests;
