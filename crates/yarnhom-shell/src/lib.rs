#![doc = include_str!("../README.md")]

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
pub mod wind;

pub use elastic::{Assembly, ElasticModel};
pub use integrator::{Dynamics, Handle, Motion, Simulation, StepStats};
pub use linear_solver::{LinearSolver, LinearSolves};
pub use material::{HingeBending, ShellMaterial, Stiffening, StvkNeoHookean, open_material};
pub use mesh::ShellMesh;
pub use scene::Scene;
pub use wind::Wind;
