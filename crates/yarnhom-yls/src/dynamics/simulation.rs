//! A simulation: the system, its state and the factorization reused across steps.

use nalgebra::DVector;
use yarnhom_sparse::SpdSolver;

use super::input::InputError;
use super::potential::{StepContext, Want};
use super::springs::glue_energy;
use super::step::{
    Energies, State, StepError, StepReport, advance, candidates_at, gravity_energy_j, kinetic_energy_j,
};
use super::system::{Scene, System};
use yarnhom_rod::contact_energy_only;

/// A scene being simulated.
pub struct Simulation {
    pub(super) system: System,
    pub(super) state: State,
    pub(super) solver: SpdSolver,
}

impl Simulation {
    /// Validate `scene` and start it at time 0 from its yarns' positions and twists, at rest.
    /// Vertices must clear the obstacles and non-neighbouring edges must not touch.
    pub fn new(scene: &Scene) -> Result<Simulation, InputError> {
        let system = System::new(scene)?;
        let q = system.initial_q(scene);
        check_clearances(&system, &q)?;
        let velocity = DVector::zeros(3 * system.vertex_count());
        Ok(Simulation { system, state: State { q, velocity, time_s: 0.0 }, solver: SpdSolver::default() })
    }

    /// Advance by one backward Euler step of `time_step_s`. On error the state is unchanged.
    pub fn step(&mut self, time_step_s: f64) -> Result<StepReport, StepError> {
        let (state, report) = advance(&self.system, &self.state, &mut self.solver, time_step_s)?;
        self.system.update_references(&state.q);
        self.state = state;
        Ok(report)
    }

    /// The time (s).
    pub fn time_s(&self) -> f64 {
        self.state.time_s
    }

    /// Number of vertices of the scene.
    pub fn vertex_count(&self) -> usize {
        self.system.vertex_count()
    }

    /// The vertices whose motion handles prescribe, ascending.
    pub fn held_vertices(&self) -> Vec<usize> {
        let mut held: Vec<usize> = self.system.held.iter().map(|&(v, _, _)| v).collect();
        held.sort_unstable();
        held
    }

    /// Number of yarns.
    pub fn yarn_count(&self) -> usize {
        self.system.vertex_offsets.len() - 1
    }

    /// Number of edges of yarn `yarn` (its edges follow those of the yarns before it).
    pub fn yarn_edge_count(&self, yarn: usize) -> usize {
        self.system.edge_offsets[yarn + 1] - self.system.edge_offsets[yarn]
    }

    /// Radius of yarn `yarn` (m).
    pub fn yarn_radius_m(&self, yarn: usize) -> f64 {
        self.system.vertex_radius_m[self.system.vertex_offsets[yarn]]
    }

    /// The global indices of yarn `yarn`'s vertices.
    pub fn yarn_vertices(&self, yarn: usize) -> std::ops::Range<usize> {
        self.system.vertex_offsets[yarn]..self.system.vertex_offsets[yarn + 1]
    }

    /// All vertex positions (m), yarn after yarn.
    pub fn positions_m(&self) -> Vec<[f64; 3]> {
        triples(&self.state.q, self.system.vertex_count())
    }

    /// All edge twists (rad), yarn after yarn.
    pub fn edge_twists_rad(&self) -> Vec<f64> {
        self.state.q.as_slice()[3 * self.system.vertex_count()..].to_vec()
    }

    /// All vertex velocities (m/s).
    pub fn velocities_m_s(&self) -> Vec<[f64; 3]> {
        triples(&self.state.velocity, self.system.vertex_count())
    }

    /// Set all vertex velocities (m/s; one per vertex, finite).
    pub fn set_velocities_m_s(&mut self, velocities: &[[f64; 3]]) -> Result<(), InputError> {
        let expected = self.system.vertex_count();
        if velocities.len() != expected {
            return Err(InputError::Length { what: "velocities", got: velocities.len(), expected });
        }
        if !velocities.iter().flatten().all(|v| v.is_finite()) {
            return Err(InputError::Parameter {
                what: "velocities".into(),
                range: "finite",
                value: f64::NAN,
            });
        }
        self.state.velocity = DVector::from_iterator(3 * expected, velocities.iter().flatten().copied());
        Ok(())
    }

    /// Lumped mass of every vertex (kg): linear density times half the adjacent rest lengths.
    pub fn vertex_masses_kg(&self) -> &[f64] {
        &self.system.masses_kg
    }

    /// The energies of the current state.
    pub fn energies(&self) -> Energies {
        let q = &self.state.q;
        let parts = StepContext::at_rest(&self.system, q)
            .evaluate(q, &candidates_at(&self.system, q), Want::Energy)
            .parts;
        Energies {
            kinetic_j: kinetic_energy_j(&self.system, &self.state.velocity),
            elastic_j: parts.elastic,
            glue_j: parts.glue,
            contact_j: parts.contact,
            obstacle_j: parts.obstacle,
            gravity_j: gravity_energy_j(&self.system, q),
        }
    }

    /// The smallest centreline distance of two edges within the broad-phase radius, in yarn
    /// radii (∞ for none, or without contact).
    pub fn closest_distance_radii(&self) -> f64 {
        let closest = candidates_at(&self.system, &self.state.q)
            .iter()
            .map(|c| c.distance_m)
            .fold(f64::INFINITY, f64::min);
        closest / self.system.radius_m
    }

    /// The stored energy of the current state attributed to the vertices (J): the rods'
    /// ([`yarnhom_rod::Rod::vertex_energies`]), half of each glue spring's to either end, and a
    /// quarter of each contact pair's to each of its edges' ends. Summed over a region (the
    /// copies of one tile, say) they give its energy; over all vertices, the elastic, glue and
    /// contact energies of [`Simulation::energies`].
    pub fn vertex_energies_j(&self) -> Vec<f64> {
        let (system, q) = (&self.system, &self.state.q);
        let mut energies = vec![0.0; system.vertex_count()];
        for (y, rod) in system.rods.iter().enumerate() {
            let first = system.vertex_offsets[y];
            for (k, w) in rod.vertex_energies(&system.rod_q(y, q)).into_iter().enumerate() {
                energies[first + k] += w;
            }
        }
        for spring in &system.glue {
            let [a, b] = spring.vertices.map(|v| v as usize);
            let (xa, xb) = (System::position(q, a), System::position(q, b));
            let (w, _, _) = glue_energy(spring.stiffness_n_m, spring.rest_length_m, &xa, &xb);
            energies[a] += 0.5 * w;
            energies[b] += 0.5 * w;
        }
        if let Some(law) = system.contact {
            let edges = &system.topology.edges;
            for c in candidates_at(system, q) {
                let ends = [edges[c.a].ends, edges[c.b].ends].concat();
                let x = ends.iter().map(|&v| System::position(q, v)).collect::<Vec<_>>();
                let (ra, rb) = (edges[c.a].rest_length_m, edges[c.b].rest_length_m);
                let w = contact_energy_only(&law, [&x[0], &x[1], &x[2], &x[3]], ra, rb);
                ends.iter().for_each(|&v| energies[v] += 0.25 * w);
            }
        }
        energies
    }

    /// Per handle, the force (N) it applies to its vertices to hold them in static equilibrium
    /// in the current state: the sum over its vertices of `∂(V - gravity's work)/∂x_v`, with `V`
    /// the stored energy and the obstacles' barriers. Inertia and damping are left out, so at
    /// rest (a quasi-static run) it is the handle's reaction.
    pub fn handle_forces_n(&self) -> Vec<[f64; 3]> {
        let (system, q) = (&self.system, &self.state.q);
        let gradient = StepContext::at_rest(system, q)
            .evaluate(q, &candidates_at(system, q), Want::Derivatives)
            .gradient;
        let mut forces = vec![[0.0; 3]; system.handles.len()];
        for &(v, h, _) in &system.held {
            (0..3).for_each(|k| forces[h][k] += gradient[3 * v + k]);
        }
        forces
    }

    /// Symbolic analyses of the Hessian's pattern so far (reused while the pattern stays within
    /// the analysed one).
    pub fn symbolic_analyses(&self) -> usize {
        self.solver.symbolic_analyses
    }
}

/// The first `n` triples of `v`.
fn triples(v: &DVector<f64>, n: usize) -> Vec<[f64; 3]> {
    (0..n).map(|i| [v[3 * i], v[3 * i + 1], v[3 * i + 2]]).collect()
}

/// Every vertex clears every obstacle, and no two candidate edges touch.
fn check_clearances(system: &System, q: &DVector<f64>) -> Result<(), InputError> {
    for (obstacle, o) in system.obstacles.iter().enumerate() {
        for (vertex, &radius) in system.vertex_radius_m.iter().enumerate() {
            let gap_m = o.gap_m(&System::position(q, vertex), radius);
            if gap_m <= 0.0 {
                return Err(InputError::InsideObstacle { vertex, obstacle, gap_m });
            }
        }
    }
    match candidates_at(system, q).into_iter().find(|c| c.distance_m <= 0.0) {
        Some(c) => Err(InputError::EdgesTouch { a: c.a, b: c.b, distance_m: c.distance_m }),
        None => Ok(()),
    }
}
