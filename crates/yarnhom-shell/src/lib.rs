//! yarnhom's thin-shell cloth simulator (thesis Sec. 4.2, Ch. 6).
//!
//! - [`mesh`]: cloth triangle meshes and their adjacency.
//! - [`forms`], [`dihedral`], [`hinge`]: discrete fundamental forms (4.4)-(4.7) and the edge
//!   bending (6.4), with exact derivatives.
//! - [`material`]: spline materials (Ch. 4) and anisotropic StVK + Neo-Hookean (6.1), and
//!   [`open_material`], the material of a file.
//! - [`elastic`]: per-element energies, the derivative split (A.43)-(A.44), PSD clamping.
//! - [`contact`]: obstacles, friction and self-collision.
//! - [`scene`], [`arcsim_scene`]: scene files, built-ins and the published ARCSim scenes.
//! - [`simulate`]: running a scene frame by frame; [`messages`]: its frames as trace messages.
//! - [`integrator`]: implicit Euler with Newton and line search, handles, Rayleigh damping;
//!   its Newton matrices on one sparsity pattern (`newton_matrix`), solved by Cholesky or
//!   conjugate gradients ([`linear_solver`]).
//! - [`statics`]: static equilibrium with held DOFs (clamped swatch tests).

pub mod arcsim_scene;
pub mod contact;
pub mod dihedral;
pub mod elastic;
pub mod forms;
pub mod hinge;
pub mod integrator;
mod line_search;
pub mod linear_solver;
pub mod material;
pub mod mesh;
pub mod messages;
mod newton_matrix;
pub mod scene;
mod scene_source;
pub mod simulate;
pub mod statics;
#[cfg(test)]
mod test_support;

pub use elastic::{Assembly, ElasticModel};
pub use integrator::{Dynamics, Handle, Motion, Simulation, StepStats};
pub use linear_solver::{LinearSolver, LinearSolves};
pub use material::{HingeBending, ShellMaterial, Stiffening, StvkNeoHookean, open_material};
pub use mesh::ShellMesh;
pub use scene::Scene;
