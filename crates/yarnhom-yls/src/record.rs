//! A yarn-level run's frames as trace messages (`yarnhom-trace` topics): the yarns' rest
//! positions, node types (free or held by a handle) and segments once on `/yarn/nodes`, the
//! yarn centrelines per frame on `/yarn/frame`, the frame's energies and contact measures on `/metrics`, and each
//! time step's Newton statistics on `/solver`.

use std::collections::BTreeMap;

use yarnhom_trace::{Scalars, SolverStep, TraceError, TraceSink, YarnFrame, YarnNodes};

use crate::dynamics::Simulation;
use crate::run::FrameReport;

/// The yarns of `simulation` as graph nodes of yarn set `name`: its current positions as rest
/// positions, `HANDLE` for the vertices handles hold and `NORMAL` for the others, and every
/// segment (a closed yarn's last one back to its first).
pub fn yarn_nodes(simulation: &Simulation, name: &str) -> YarnNodes {
    let mut node_type = vec![YarnNodes::NORMAL; simulation.vertex_count()];
    for v in simulation.held_vertices() {
        node_type[v] = YarnNodes::HANDLE;
    }
    let edges = (0..simulation.yarn_count())
        .flat_map(|yarn| {
            let vertices = simulation.yarn_vertices(yarn);
            let n = vertices.len();
            let first = vertices.start;
            (0..simulation.yarn_edge_count(yarn)).map(move |e| [(first + e) as u32, (first + (e + 1) % n) as u32])
        })
        .collect();
    YarnNodes { yarns: name.into(), rest_positions_m: simulation.positions_m(), node_type, edges }
}

/// The yarn centrelines of `simulation` at `report`'s frame, as yarn set `name`: positions,
/// the twist of the edge leaving each vertex (0 at an open yarn's last vertex), radii and yarn
/// ranges.
pub fn yarn_frame(report: &FrameReport, simulation: &Simulation, name: &str) -> YarnFrame {
    let twists = simulation.edge_twists_rad();
    let (mut edge_twist_rad, mut radii_m, mut yarn_ranges) = (Vec::new(), Vec::new(), Vec::new());
    let mut edge = 0;
    for yarn in 0..simulation.yarn_count() {
        let vertices = simulation.yarn_vertices(yarn);
        let edges = simulation.yarn_edge_count(yarn);
        yarn_ranges.push([vertices.start as u32, vertices.len() as u32]);
        edge_twist_rad.extend((0..vertices.len()).map(|i| if i < edges { twists[edge + i] } else { 0.0 }));
        radii_m.extend(std::iter::repeat_n(simulation.yarn_radius_m(yarn), vertices.len()));
        edge += edges;
    }
    YarnFrame {
        yarns: name.into(),
        frame: report.frame,
        time_s: report.time_s,
        positions_m: simulation.positions_m(),
        edge_twist_rad,
        radii_m,
        yarn_ranges,
    }
}

/// The frame's scalars: every energy (J), the closest centreline distance (yarn radii), and
/// the Newton iterations, line-search cuts, step caps and Hessian shifts over its steps.
pub fn frame_metrics(report: &FrameReport) -> Scalars {
    let e = &report.energies;
    let sum = |f: fn(&crate::dynamics::StepReport) -> usize| report.steps.iter().map(f).sum::<usize>() as f64;
    let values = BTreeMap::from([
        ("kinetic_energy_j".to_string(), e.kinetic_j),
        ("elastic_energy_j".to_string(), e.elastic_j),
        ("glue_energy_j".to_string(), e.glue_j),
        ("contact_energy_j".to_string(), e.contact_j),
        ("obstacle_energy_j".to_string(), e.obstacle_j),
        ("gravity_energy_j".to_string(), e.gravity_j),
        ("closest_distance_radii".to_string(), report.closest_distance_radii),
        ("newton_iterations".to_string(), sum(|s| s.newton_iterations)),
        ("line_search_cuts".to_string(), sum(|s| s.line_search_cuts)),
        ("step_caps".to_string(), sum(|s| s.step_caps + s.reach_caps + s.obstacle_caps)),
        ("hessian_shifts".to_string(), sum(|s| s.hessian_shifts)),
    ]);
    Scalars { frame: report.frame, time_s: report.time_s, values }
}

/// One `/solver` record per time step of the frame (the residual is not tracked: NaN).
pub fn solver_steps(report: &FrameReport) -> Vec<SolverStep> {
    report
        .steps
        .iter()
        .map(|s| SolverStep {
            frame: report.frame,
            time_s: s.time_s,
            newton_iterations: s.newton_iterations as u32,
            residual: f64::NAN,
            line_search_steps: s.line_search_cuts as u32,
            converged: true,
            wall_time_s: s.wall_time_s,
        })
        .collect()
}

/// Records output frame `report` of yarn set `name` on `sink` (its [`yarn_nodes`] first, at
/// frame 0) and closes the frame.
pub fn record_frame(
    sink: &mut TraceSink,
    report: &FrameReport,
    simulation: &Simulation,
    name: &str,
) -> Result<(), TraceError> {
    if report.frame == 0 {
        sink.write(&yarn_nodes(simulation, name))?;
    }
    sink.write(&yarn_frame(report, simulation, name))?;
    sink.write(&frame_metrics(report))?;
    solver_steps(report).iter().try_for_each(|step| sink.write(step))?;
    sink.end_frame()
}

/// Run `simulation` for `frames` frames of `frame_time_s` (each of `steps_per_frame` steps),
/// recording every frame, the initial one included, as yarn set `name` on `sink`; `progress`
/// sees each frame's report after it is recorded.
pub fn record_run(
    sink: &mut TraceSink,
    simulation: &mut Simulation,
    name: &str,
    frames: u64,
    frame_time_s: f64,
    steps_per_frame: u32,
    mut progress: impl FnMut(&FrameReport),
) -> Result<(), crate::run::RunError> {
    crate::run::run(simulation, frames, frame_time_s, steps_per_frame, |report, sim| {
        record_frame(sink, report, sim, name).map_err(|e| e.to_string())?;
        progress(report);
        Ok(())
    })
}
