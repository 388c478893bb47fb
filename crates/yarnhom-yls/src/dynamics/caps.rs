//! Caps on the fraction `α` of a Newton direction `d` taken in one step, so that no yarn passes
//! through another or through an obstacle, whatever the energy between.
//!
//! - Contact: a point of an edge moves at most `α δ_e` along the step, `δ_e` the larger move of
//!   the edge's two vertices, so the centreline distance `d_ef` of two edges shrinks at most by
//!   `α (δ_e + δ_f)`. `α ≤ 0.9 d_ef / (δ_e + δ_f)` for every candidate pair keeps at least 10% of
//!   each distance, so no two edges can cross. With `δ` the largest vertex move and `d_min` the
//!   smallest distance, this is at least the global bound `α ≤ 0.9 d_min / (2δ)`.
//! - Reach: a pair outside the candidate list was at least the broad-phase radius
//!   `reach + margin` apart where the list was found, and has approached by at most twice the
//!   largest vertex move since; `α ≤ slack / δ` ([`CandidateList::slack_m`]) keeps it out of the
//!   contact law's reach, so the list holds every interacting pair of the line search (and
//!   every pair that could cross: the radius exceeds the approach).
//! - Obstacles: `α ≤ 0.9 gap / approach` per vertex and obstacle ([`super::Obstacle`]).

use nalgebra::DVector;

use super::contact::CandidateList;
use super::system::System;

/// The caps on one step: each the largest admissible `α` (∞ where nothing limits it).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Caps {
    /// Edge pairs in the candidate list.
    pub contact: f64,
    /// Edge pairs outside it.
    pub reach: f64,
    /// Vertices against obstacles.
    pub obstacle: f64,
}

impl Caps {
    /// The step fraction allowed: the smallest cap, at most 1.
    pub(crate) fn fraction(&self) -> f64 {
        self.contact.min(self.reach).min(self.obstacle).min(1.0)
    }
}

/// How far each vertex moves along the direction `d` (m).
pub(crate) fn vertex_moves(system: &System, d: &DVector<f64>) -> Vec<f64> {
    (0..system.vertex_count()).map(|v| System::position(d, v).norm()).collect()
}

/// The caps for the direction `d` from `q`, with the candidate list brought to `q`.
pub(crate) fn step_caps(system: &System, q: &DVector<f64>, d: &DVector<f64>, list: &CandidateList) -> Caps {
    let moves = vertex_moves(system, d);
    let edge_move = |e: usize| {
        let ends = system.topology.edges[e].ends;
        moves[ends[0]].max(moves[ends[1]])
    };
    let contact = list
        .pairs
        .iter()
        .map(|c| {
            let approach = edge_move(c.a) + edge_move(c.b);
            if approach > 0.0 { 0.9 * c.distance_m / approach } else { f64::INFINITY }
        })
        .fold(f64::INFINITY, f64::min);
    let largest = moves.iter().copied().fold(0.0, f64::max);
    let reach =
        if system.contact.is_some() && largest > 0.0 { list.slack_m / largest } else { f64::INFINITY };
    let mut obstacle = f64::INFINITY;
    for o in &system.obstacles {
        for (v, &radius) in system.vertex_radius_m.iter().enumerate() {
            if moves[v] > 0.0 {
                obstacle = obstacle.min(o.step_cap(&System::position(q, v), &System::position(d, v), radius));
            }
        }
    }
    Caps { contact, reach, obstacle }
}
