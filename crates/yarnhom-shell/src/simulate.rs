//! Running a scene: build the mesh, handles and integrator, step to the end time and report
//! each output frame.

use std::path::Path;

use yarnhom_artifacts::AtomicFile;

use crate::elastic::ElasticModel;
use crate::integrator::{Simulation, StepError, StepStats};
use crate::material::ShellMaterial;
use crate::scene::{Scene, SceneError};

/// What happened up to an output frame.
#[derive(Debug, Clone, PartialEq)]
pub struct FrameReport {
    /// Frame number (0 is the initial state).
    pub frame: u64,
    /// Simulated time (s).
    pub time_s: f64,
    /// The steps since the previous frame.
    pub steps: Vec<StepStats>,
    /// Elastic energy (J).
    pub elastic_energy_j: f64,
    /// Kinetic energy (J).
    pub kinetic_energy_j: f64,
    /// Gravitational energy (J).
    pub gravity_energy_j: f64,
    /// Deepest obstacle penetration (m).
    pub penetration_m: f64,
}

/// Counts over the frames of a run, for its closing summary.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct RunTotals {
    /// Time steps.
    pub steps: u64,
    /// Newton iterations over all steps.
    pub newton_iterations: u64,
    /// Conjugate-gradient iterations over all linear solves.
    pub cg_iterations: u64,
    /// Cholesky factorizations over all linear solves.
    pub factorizations: u64,
}

impl RunTotals {
    /// Adds a frame's steps.
    pub fn add(&mut self, report: &FrameReport) {
        for s in &report.steps {
            self.steps += 1;
            self.newton_iterations += u64::from(s.newton_iterations);
            self.cg_iterations += u64::from(s.linear_solves.cg_iterations);
            self.factorizations += u64::from(s.linear_solves.factorizations);
        }
    }

    /// The closing line of a run that ended in state `sim`.
    pub fn summary(&self, sim: &Simulation) -> String {
        format!(
            "simulated {} s in {} steps ({} Newton iterations; linear solves: {} conjugate gradient iterations, \
             {} Cholesky factorizations), {} vertices; elastic energy {:.4e} J",
            sim.time_s,
            self.steps,
            self.newton_iterations,
            self.cg_iterations,
            self.factorizations,
            sim.positions.len(),
            sim.model.energy(&sim.positions)
        )
    }
}

/// Writes the state `sim` as a Wavefront OBJ file (positions, the material coordinates as
/// texture coordinates, the triangles), atomically.
pub fn write_obj(path: &Path, sim: &Simulation) -> std::io::Result<()> {
    let positions: Vec<[f64; 3]> = sim.positions.iter().map(|p| [p.x, p.y, p.z]).collect();
    let texcoords: Vec<[f64; 2]> = sim.model.mesh.material.iter().map(|m| [m.x, m.y]).collect();
    let mut out = AtomicFile::create(path)?;
    yarnhom_trace::export::write_obj(&mut out, &positions, &texcoords, &sim.model.mesh.triangles)?;
    out.commit()
}

/// Why a run stopped.
#[derive(Debug, thiserror::Error)]
pub enum SimulateError {
    /// The scene is not usable.
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// A step failed.
    #[error(transparent)]
    Step(#[from] StepError),
    /// The frame callback failed.
    #[error("{0}")]
    Output(String),
}

/// The simulation of `scene` with `material`, at rest at the flat cloth.
pub fn prepare(scene: &Scene, material: ShellMaterial) -> Result<Simulation, SceneError> {
    scene.validate()?;
    let mesh = scene.mesh();
    let handles = scene.handles(&mesh)?;
    let positions = mesh.flat_positions();
    let model = ElasticModel::new(mesh, material);
    Ok(Simulation::new(model, positions, handles, scene.obstacles.clone(), scene.contact, scene.dynamics()))
}

/// The report of the current state with the steps since the last frame.
pub fn report(sim: &Simulation, frame: u64, steps: Vec<StepStats>) -> FrameReport {
    FrameReport {
        frame,
        time_s: sim.time_s,
        steps,
        elastic_energy_j: sim.model.energy(&sim.positions),
        kinetic_energy_j: sim.kinetic_energy(),
        gravity_energy_j: sim.gravity_energy(),
        penetration_m: sim.obstacle_penetration_m(),
    }
}

/// Run `scene` to its end time (or `frames` output frames if given), calling `on_frame` with
/// the initial state and after every frame.
pub fn run(
    scene: &Scene,
    material: ShellMaterial,
    frames: Option<u64>,
    mut on_frame: impl FnMut(&FrameReport, &Simulation) -> Result<(), String>,
) -> Result<Simulation, SimulateError> {
    let mut sim = prepare(scene, material)?;
    let total = frames.unwrap_or_else(|| (scene.end_time_s / scene.frame_time_s).round() as u64);
    on_frame(&report(&sim, 0, Vec::new()), &sim).map_err(SimulateError::Output)?;
    for frame in 1..=total {
        let steps = (0..scene.steps_per_frame).map(|_| sim.step()).collect::<Result<Vec<_>, _>>()?;
        on_frame(&report(&sim, frame, steps), &sim).map_err(SimulateError::Output)?;
    }
    Ok(sim)
}
