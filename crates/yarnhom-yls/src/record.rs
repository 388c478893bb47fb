//! A yarn-level run's frames as trace messages (`yarnhom-trace` topics): the yarns' rest
//! positions, node types (free or held by a handle) and segments once on `/yarn/nodes`, the
//! yarn centrelines per frame on `/yarn/frame`, the frame's energies and contact measures on `/metrics`, and each
//! time step's Newton statistics on `/solver`.

use std::collections::BTreeMap;

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use yarnhom_artifacts::write_atomic;
use yarnhom_trace::{
    Scalars, SolverStep, TraceError, TraceMetadata, TraceSink, YarnFrame, YarnNodes, open_records,
};

use crate::dynamics::{Checkpoint, Simulation};
use crate::run::{FrameReport, Frames, RunError};

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
            (0..simulation.yarn_edge_count(yarn))
                .map(move |e| [(first + e) as u32, (first + (e + 1) % n) as u32])
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

/// Where a resumable recording keeps its state while it runs: `T.checkpoint` and the traces
/// of the finished stretches of frames, `T.partNNNN`.
fn checkpoint_path(trace: &Path) -> PathBuf {
    PathBuf::from(format!("{}.checkpoint", trace.display()))
}

fn part_path(trace: &Path, part: u32) -> PathBuf {
    PathBuf::from(format!("{}.part{part:04}", trace.display()))
}

/// What a resumable recording saved after its last finished stretch of frames.
#[derive(Serialize, Deserialize)]
struct Saved {
    /// The run it belongs to (its trace metadata).
    run: String,
    /// The last frame recorded.
    frame: u64,
    /// Stretches recorded (`T.part0000` ...).
    parts: u32,
    /// The simulation at `frame`.
    state: Checkpoint,
}

/// Why a resumable recording stopped.
#[derive(Debug, thiserror::Error)]
pub enum RecordError {
    /// The run failed.
    #[error(transparent)]
    Run(#[from] RunError),
    /// A trace could not be written or read.
    #[error(transparent)]
    Trace(#[from] TraceError),
    /// The checkpoint could not be written or read.
    #[error("{path}: {problem}")]
    Checkpoint {
        /// The checkpoint file.
        path: String,
        /// What went wrong.
        problem: String,
    },
}

/// Record the frames of `plan` of `simulation` (from its start) into the trace at `path`, as
/// [`record_run`] does, resumable after a kill: every `every` frames the frames so far are
/// finished as a part trace beside `path` and the simulation's whole state is saved to
/// `path.checkpoint`; a later call with the same `metadata` continues from the last
/// checkpoint, to the bit. At the end the parts are merged into `path` and removed. Returns the
/// frame it started from (0 unless resumed).
pub fn record_resumable(
    path: &Path,
    metadata: &TraceMetadata,
    simulation: &mut Simulation,
    name: &str,
    plan: &Frames,
    every: u64,
    mut progress: impl FnMut(&FrameReport),
) -> Result<u64, RecordError> {
    let run_id = format!("{:?}", metadata.entries);
    let saved = read_saved(&checkpoint_path(path), &run_id)?;
    let (mut first, mut part) = match &saved {
        Some(s) => {
            simulation.restore(&s.state).map_err(|e| checkpoint_error(path, e))?;
            (s.frame + 1, s.parts)
        }
        None => (0, 0),
    };
    let started = first;
    while first <= plan.count {
        let last = (first + every.max(1) - 1).min(plan.count);
        let part_file = part_path(path, part);
        let mut sink = TraceSink::open(&part_file.display().to_string(), metadata)?;
        crate::run::run(simulation, first..=last, plan, |report, sim| {
            record_frame(&mut sink, report, sim, name).map_err(|e| e.to_string())?;
            progress(report);
            Ok(())
        })?;
        sink.finish()?;
        part += 1;
        let saved = Saved { run: run_id.clone(), frame: last, parts: part, state: simulation.checkpoint() };
        let bytes = rmp_serde::to_vec_named(&saved).map_err(|e| checkpoint_error(path, e))?;
        write_atomic(checkpoint_path(path), bytes).map_err(|e| checkpoint_error(path, e))?;
        first = last + 1;
    }
    merge_parts(path, metadata, part)?;
    Ok(started)
}

/// The saved state of the run `run_id`, if a checkpoint is there; a checkpoint of another run
/// is an error (delete it to start over).
fn read_saved(path: &Path, run_id: &str) -> Result<Option<Saved>, RecordError> {
    let bytes = match std::fs::read(path) {
        Ok(bytes) => bytes,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(checkpoint_error(path, e)),
    };
    let saved: Saved = rmp_serde::from_slice(&bytes).map_err(|e| checkpoint_error(path, e))?;
    if saved.run != run_id {
        return Err(checkpoint_error(
            path,
            "the checkpoint of another run (other scene, swatch or settings): delete it to start over",
        ));
    }
    Ok(Some(saved))
}

/// Merge the `parts` part traces into the trace at `path`, then remove them and the checkpoint.
fn merge_parts(path: &Path, metadata: &TraceMetadata, parts: u32) -> Result<(), RecordError> {
    let files: Vec<String> = (0..parts).map(|k| part_path(path, k).display().to_string()).collect();
    let mut sink = TraceSink::open(&path.display().to_string(), metadata)?;
    sink.merge(files.iter().map(|f| open_records(f)).collect::<Result<Vec<_>, _>>()?)?;
    sink.finish()?;
    for file in files.iter().map(PathBuf::from).chain([checkpoint_path(path)]) {
        std::fs::remove_file(&file).map_err(|e| checkpoint_error(&file, e))?;
    }
    Ok(())
}

fn checkpoint_error(path: &Path, problem: impl std::fmt::Display) -> RecordError {
    RecordError::Checkpoint { path: path.display().to_string(), problem: problem.to_string() }
}

/// Run `simulation` through the frames of `plan`, recording every frame, the initial one
/// included, as yarn set `name` on `sink`; `progress`
/// sees each frame's report after it is recorded.
pub fn record_run(
    sink: &mut TraceSink,
    simulation: &mut Simulation,
    name: &str,
    plan: &Frames,
    mut progress: impl FnMut(&FrameReport),
) -> Result<(), RunError> {
    crate::run::run(simulation, 0..=plan.count, plan, |report, sim| {
        record_frame(sink, report, sim, name).map_err(|e| e.to_string())?;
        progress(report);
        Ok(())
    })
}
