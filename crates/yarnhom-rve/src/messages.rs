//! The tile's states and samples as trace messages (`yarnhom-trace` topics): the yarns of an
//! iterate or a sample on `/yarn/frame`, a Newton iteration on `/solver/iteration`, a sample of
//! a sweep on `/rve/sample`.

use yarnhom_artifacts::Pattern;
use yarnhom_artifacts::grid::AXIS_NAMES;
use yarnhom_trace::{RveSample, SolverIteration, TraceError, TraceSink, YarnFrame};

use crate::assembly::{RveState, world_positions};
use crate::sample::{SampleOutcome, SamplePlan};
use crate::{Iterate, Placement, RveModel};

/// The tile's yarns at a state, yarn after yarn, as frame `frame` of `/yarn/frame`.
pub fn yarn_frame(
    pattern: &Pattern,
    tile: &RveModel,
    placement: &Placement,
    state: &RveState,
    frame: u64,
) -> YarnFrame {
    let twists: Vec<f64> = (0..tile.vertices as u32).map(|v| state.g[tile.twist_dof(v)]).collect();
    yarns_in_order(pattern, tile, &world_positions(tile, placement, state), &twists, frame)
}

/// Records a Newton iterate of the tile (of `pattern`, placed by `placement`) on `sink` as
/// one frame, numbered by the iteration: [`iteration_message`] and [`yarn_frame`].
pub fn record_iterate(
    sink: &mut TraceSink,
    pattern: &Pattern,
    tile: &RveModel,
    placement: &Placement,
    iterate: &Iterate<'_>,
) -> Result<(), TraceError> {
    sink.write(&iteration_message(iterate))?;
    sink.write(&yarn_frame(pattern, tile, placement, iterate.state, iterate.iteration as u64))?;
    sink.end_frame()
}

/// Per-vertex positions and edge twists of the tile (in the tile's vertex order) as frame
/// `frame` of `/yarn/frame`, yarn after yarn.
pub fn yarns_in_order(
    pattern: &Pattern,
    tile: &RveModel,
    positions_m: &[[f64; 3]],
    edge_twist_rad: &[f64],
    frame: u64,
) -> YarnFrame {
    let mut message = YarnFrame { yarns: pattern.name.clone(), frame, ..YarnFrame::default() };
    for (yarn, info) in pattern.yarns.iter().zip(&tile.yarns) {
        message.yarn_ranges.push([message.positions_m.len() as u32, info.vertices.len() as u32]);
        for &v in &info.vertices {
            message.positions_m.push(positions_m[v as usize]);
            message.edge_twist_rad.push(edge_twist_rad[v as usize]);
            message.radii_m.push(yarn.radius_m);
        }
    }
    message
}

/// A Newton iteration of a static solve as `/solver/iteration` (frame = iteration).
pub fn iteration_message(iterate: &Iterate<'_>) -> SolverIteration {
    SolverIteration {
        frame: iterate.iteration as u64,
        time_s: 0.0,
        iteration: iterate.iteration as u32,
        energy_j: iterate.energy_j,
        residual: iterate.gradient_ratio,
        step_length: iterate.step_length,
    }
}

/// A sample of a sweep over `plan` as frame `frame` of `/rve/sample`.
pub fn sample_message(plan: &SamplePlan, sample: &SampleOutcome, frame: u64) -> RveSample {
    RveSample {
        frame,
        time_s: 0.0,
        term: plan.terms[sample.term].axes.iter().map(|&a| AXIS_NAMES[a]).collect::<Vec<_>>().join(","),
        grid_index: sample.index,
        strain: sample.strain,
        converged: sample.converged,
        energy_density_j_m2: sample.energy_density_j_m2,
        stress: sample.stress,
        iterations: sample.iterations as u32,
    }
}
