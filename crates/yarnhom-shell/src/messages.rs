//! A simulation's states as trace messages (`yarnhom-trace` topics): the cloth's topology on
//! `/mesh/topology`, its positions per frame on `/mesh/frame`, the frame's energies and linear
//! solver counts on `/metrics`, and each time step's Newton statistics on `/solver`.

use std::collections::BTreeMap;

use yarnhom_trace::{MeshFrame, MeshTopology, Scalars, SolverStep, TraceError, TraceSink};

use crate::Simulation;
use crate::simulate::FrameReport;

/// The cloth's triangles and rest (material) positions, as mesh `name`.
pub fn topology(sim: &Simulation, name: &str) -> MeshTopology {
    MeshTopology {
        triangles: sim.model.mesh.triangles.clone(),
        rest_positions_m: sim.model.mesh.material.iter().map(|m| [m.x, m.y, 0.0]).collect(),
        name: name.into(),
    }
}

/// The messages of one output frame: the positions of mesh `name`, the frame's scalars (elastic,
/// kinetic and gravitational energy, deepest penetration, conjugate-gradient iterations and
/// Cholesky factorizations over its steps), and one solver record per time step.
pub fn frame_messages(
    report: &FrameReport,
    sim: &Simulation,
    name: &str,
) -> (MeshFrame, Scalars, Vec<SolverStep>) {
    let positions_m = sim.positions.iter().map(|p| [p.x, p.y, p.z]).collect();
    let mesh = MeshFrame { mesh: name.into(), frame: report.frame, time_s: report.time_s, positions_m };
    let values = BTreeMap::from([
        ("elastic_energy_j".to_string(), report.elastic_energy_j),
        ("kinetic_energy_j".to_string(), report.kinetic_energy_j),
        ("gravity_energy_j".to_string(), report.gravity_energy_j),
        ("penetration_m".to_string(), report.penetration_m),
        (
            "cg_iterations".to_string(),
            report.steps.iter().map(|s| f64::from(s.linear_solves.cg_iterations)).sum(),
        ),
        (
            "cholesky_factorizations".to_string(),
            report.steps.iter().map(|s| f64::from(s.linear_solves.factorizations)).sum(),
        ),
    ]);
    let scalars = Scalars { frame: report.frame, time_s: report.time_s, values };
    let steps = report
        .steps
        .iter()
        .map(|s| SolverStep {
            frame: report.frame,
            time_s: report.time_s,
            newton_iterations: s.newton_iterations,
            residual: s.residual_n,
            line_search_steps: s.line_search_steps,
            converged: s.converged,
            wall_time_s: s.wall_time_s,
        })
        .collect();
    (mesh, scalars, steps)
}

/// Records output frame `report` of the simulation of mesh `name` on `sink`: the topology
/// first (frame 0), then [`frame_messages`], and closes the frame.
pub fn record_frame(
    sink: &mut TraceSink,
    report: &FrameReport,
    sim: &Simulation,
    name: &str,
) -> Result<(), TraceError> {
    if report.frame == 0 {
        sink.write(&topology(sim, name))?;
    }
    let (mesh, scalars, steps) = frame_messages(report, sim, name);
    sink.write(&mesh)?;
    sink.write(&scalars)?;
    steps.iter().try_for_each(|step| sink.write(step))?;
    sink.end_frame()
}
