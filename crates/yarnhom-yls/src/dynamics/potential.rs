//! The incremental potential of one backward Euler step, as a minimization (IPC, Li et al.
//! 2020, eq. 3; Kaldor et al. 2008 for the yarn terms):
//!
//! `Φ(q) = 1/(2h²) (x - x̃)ᵀ M (x - x̃) + V(q) + D(x)`, `x̃ = x_n + h v_n`,
//!
//! with `V` the rods' stretching, bending and twisting (Bergou et al. 2010), yarn-yarn contact,
//! glue springs, obstacle barriers and gravity `-Σ m_v g · (x_v - x_n,v)` (measured from the
//! step's start, so the line search compares small numbers), and `D` the damping of non-rigid
//! motion ([`super::damping`]). Twists carry no inertia: they are quasi-static, at equilibrium
//! at the end of every step (up to the gauge term of [`super::system::System::twist_anchor`]).
//!
//! Terms are evaluated in parallel per element (rods, contact pairs, damping windows) into
//! per-element slots, then summed and scattered in element order, so the result is the same
//! to the bit for any number of threads.

use nalgebra::{DVector, Vector3};
use rayon::prelude::*;
use yarnhom_rod::{contact_energy, contact_energy_only};

use super::contact::Candidate;
use super::damping::DampingTerm;
use super::springs::glue_energy;
use super::system::System;
use super::wind::wind_forces;

/// The parts of the incremental potential (J).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct PotentialParts {
    /// `1/(2h²) |x - x̃|²_M`.
    pub inertia: f64,
    /// Rods: stretching, bending, twisting.
    pub elastic: f64,
    /// Glue springs.
    pub glue: f64,
    /// Yarn-yarn contact.
    pub contact: f64,
    /// Obstacle barriers.
    pub obstacle: f64,
    /// Gravity, from the step's start.
    pub gravity: f64,
    /// Work of the wind's force (held over the step), from the step's start.
    pub wind: f64,
    /// Dissipation potential `D`.
    pub damping: f64,
    /// The twist gauge term.
    pub twist_anchor: f64,
}

impl PotentialParts {
    /// `Φ`.
    pub(crate) fn total(&self) -> f64 {
        self.inertia
            + self.elastic
            + self.glue
            + self.contact
            + self.obstacle
            + self.gravity
            + self.wind
            + self.damping
            + self.twist_anchor
    }

    /// The sum of the parts' magnitudes: the scale of `Φ`'s round-off.
    pub(crate) fn magnitude(&self) -> f64 {
        [
            self.inertia,
            self.elastic,
            self.glue,
            self.contact,
            self.obstacle,
            self.gravity,
            self.wind,
            self.damping,
            self.twist_anchor,
        ]
        .iter()
        .map(|x| x.abs())
        .sum()
    }
}

/// What to evaluate.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Want {
    /// The energy only (line search).
    Energy,
    /// Energy, gradient and Hessian (lower-triangle triplets, global DOFs).
    Derivatives,
}

/// `Φ` at some `q`: its parts, and where wanted its gradient and Hessian.
pub(crate) struct Evaluation {
    pub parts: PotentialParts,
    pub gradient: DVector<f64>,
    pub triplets: Vec<(usize, usize, f64)>,
}

impl Evaluation {
    /// Scatter an element's gradient and the lower triangle of its Hessian.
    fn add(&mut self, dofs: &[usize], gradient: &[f64], hessian: impl Fn(usize, usize) -> f64) {
        for (a, &i) in dofs.iter().enumerate() {
            self.gradient[i] += gradient[a];
            for (b, &j) in dofs.iter().enumerate() {
                if i >= j {
                    self.triplets.push((i, j, hessian(a, b)));
                }
            }
        }
    }
}

/// One step's incremental potential.
pub(crate) struct StepContext<'a> {
    pub system: &'a System,
    /// DOFs at the step's start.
    pub q_n: &'a DVector<f64>,
    /// `x̃ = x_n + h v_n` (positions only).
    pub predicted: DVector<f64>,
    /// `h` (s).
    pub time_step_s: f64,
    pub damping: Option<DampingTerm>,
    /// The wind's force on every vertex over the step (empty without wind).
    pub wind_forces: Vec<Vector3<f64>>,
}

impl<'a> StepContext<'a> {
    /// The potential of a step of `time_step_s` from `q_n` with position velocities `v_n`.
    pub(crate) fn new(
        system: &'a System,
        q_n: &'a DVector<f64>,
        v_n: &DVector<f64>,
        time_step_s: f64,
    ) -> Self {
        let positions = 3 * system.vertex_count();
        let predicted = DVector::from_fn(positions, |i, _| q_n[i] + time_step_s * v_n[i]);
        let damping = system
            .damping
            .as_ref()
            .map(|(d, windows)| DampingTerm::new(windows, &system.masses_kg, q_n, d.rate_per_s, time_step_s));
        let wind_forces = system.wind.map(|w| wind_forces(system, &w, q_n, v_n)).unwrap_or_default();
        StepContext { system, q_n, predicted, time_step_s, damping, wind_forces }
    }

    /// The potential of a state `q` at rest, without damping: its parts other than inertia and
    /// gravity (both zero there) are the state's energies.
    pub(crate) fn at_rest(system: &'a System, q: &'a DVector<f64>) -> Self {
        let predicted = q.rows(0, 3 * system.vertex_count()).into_owned();
        StepContext { system, q_n: q, predicted, time_step_s: 1.0, damping: None, wind_forces: vec![] }
    }

    /// `Φ(q)`, with the contact of the pairs `candidates`.
    pub(crate) fn evaluate(&self, q: &DVector<f64>, candidates: &[Candidate], want: Want) -> Evaluation {
        let n = if want == Want::Derivatives { self.system.dof_count() } else { 0 };
        let mut out =
            Evaluation { parts: PotentialParts::default(), gradient: DVector::zeros(n), triplets: vec![] };
        self.add_inertia_and_gravity(q, want, &mut out);
        self.add_twist_anchor(q, want, &mut out);
        self.add_rods(q, want, &mut out);
        self.add_glue(q, want, &mut out);
        self.add_obstacles(q, want, &mut out);
        self.add_contact(q, candidates, want, &mut out);
        self.add_damping(q, want, &mut out);
        out
    }

    /// `1/(2h²) |x - x̃|²_M`, `-Σ m g · (x - x_n)` and the wind's `-Σ f · (x - x_n)`.
    fn add_inertia_and_gravity(&self, q: &DVector<f64>, want: Want, out: &mut Evaluation) {
        let h2 = self.time_step_s * self.time_step_s;
        let g = self.system.gravity;
        for (v, &m) in self.system.masses_kg.iter().enumerate() {
            let x = System::position(q, v);
            let offset = x - self.predicted.fixed_rows::<3>(3 * v);
            let moved = x - System::position(self.q_n, v);
            let wind = self.wind_forces.get(v).copied().unwrap_or_else(Vector3::zeros);
            out.parts.inertia += 0.5 * m / h2 * offset.norm_squared();
            out.parts.gravity -= m * g.dot(&moved);
            out.parts.wind -= wind.dot(&moved);
            if want == Want::Derivatives {
                let gradient = offset * (m / h2) - g * m - wind;
                out.add(&[3 * v, 3 * v + 1, 3 * v + 2], gradient.as_slice(), |a, b| {
                    if a == b { m / h2 } else { 0.0 }
                });
            }
        }
    }

    /// `Σ w_e (θ_e - θ_e,n)² / 2`.
    fn add_twist_anchor(&self, q: &DVector<f64>, want: Want, out: &mut Evaluation) {
        let first = 3 * self.system.vertex_count();
        for (e, &w) in self.system.twist_anchor.iter().enumerate() {
            let i = first + e;
            let d = q[i] - self.q_n[i];
            out.parts.twist_anchor += 0.5 * w * d * d;
            if want == Want::Derivatives {
                out.add(&[i], &[w * d], |_, _| w);
            }
        }
    }

    /// The rods (in parallel, one slot per yarn).
    fn add_rods(&self, q: &DVector<f64>, want: Want, out: &mut Evaluation) {
        let system = self.system;
        let assembled: Vec<_> =
            system.rods.par_iter().enumerate().map(|(y, rod)| rod.assemble(&system.rod_q(y, q))).collect();
        for (y, (energy, gradient, triplets)) in assembled.into_iter().enumerate() {
            out.parts.elastic += energy;
            if want == Want::Derivatives {
                let dofs = system.rod_dofs(y);
                for (i, g) in gradient.iter().enumerate() {
                    out.gradient[dofs[i]] += g;
                }
                out.triplets.extend(
                    triplets.into_iter().filter(|t| t.0 >= t.1).map(|(i, j, v)| (dofs[i], dofs[j], v)),
                );
            }
        }
    }

    /// Glue springs.
    fn add_glue(&self, q: &DVector<f64>, want: Want, out: &mut Evaluation) {
        for spring in &self.system.glue {
            let [a, b] = spring.vertices.map(|v| v as usize);
            let (xa, xb) = (System::position(q, a), System::position(q, b));
            let (energy, gradient, hessian) =
                glue_energy(spring.stiffness_n_m, spring.rest_length_m, &xa, &xb);
            out.parts.glue += energy;
            if want == Want::Derivatives {
                let dofs = [3 * a, 3 * a + 1, 3 * a + 2, 3 * b, 3 * b + 1, 3 * b + 2];
                out.add(&dofs, gradient.as_slice(), |i, j| hessian[(i, j)]);
            }
        }
    }

    /// Vertex-obstacle barriers.
    fn add_obstacles(&self, q: &DVector<f64>, want: Want, out: &mut Evaluation) {
        let system = self.system;
        for obstacle in &system.obstacles {
            for (v, &radius) in system.vertex_radius_m.iter().enumerate() {
                let x = System::position(q, v);
                if want == Want::Energy {
                    out.parts.obstacle += obstacle.energy(&x, radius);
                } else if let Some((energy, gradient, hessian)) = obstacle.energy_gradient_hessian(&x, radius)
                {
                    out.parts.obstacle += energy;
                    out.add(&[3 * v, 3 * v + 1, 3 * v + 2], gradient.as_slice(), |i, j| hessian[(i, j)]);
                }
            }
        }
    }

    /// Yarn-yarn contact over the candidate pairs (in parallel, one slot per pair).
    fn add_contact(&self, q: &DVector<f64>, candidates: &[Candidate], want: Want, out: &mut Evaluation) {
        let Some(law) = self.system.contact else { return };
        let edges = &self.system.topology.edges;
        let ends = |c: &Candidate| {
            let (a, b) = (&edges[c.a], &edges[c.b]);
            [a.ends[0], a.ends[1], b.ends[0], b.ends[1]]
        };
        let points = |vertices: [usize; 4]| vertices.map(|v| System::position(q, v));
        if want == Want::Energy {
            let energies: Vec<f64> = candidates
                .par_iter()
                .map(|c| {
                    let x: [Vector3<f64>; 4] = points(ends(c));
                    contact_energy_only(
                        &law,
                        [&x[0], &x[1], &x[2], &x[3]],
                        edges[c.a].rest_length_m,
                        edges[c.b].rest_length_m,
                    )
                })
                .collect();
            out.parts.contact += energies.iter().sum::<f64>();
            return;
        }
        let elements: Vec<_> = candidates
            .par_iter()
            .map(|c| {
                let x = points(ends(c));
                contact_energy(
                    &law,
                    [&x[0], &x[1], &x[2], &x[3]],
                    edges[c.a].rest_length_m,
                    edges[c.b].rest_length_m,
                )
            })
            .collect();
        for (c, (energy, gradient, hessian)) in candidates.iter().zip(elements) {
            out.parts.contact += energy;
            if energy != 0.0 || gradient.amax() != 0.0 {
                let dofs: Vec<usize> = ends(c).iter().flat_map(|&v| [3 * v, 3 * v + 1, 3 * v + 2]).collect();
                out.add(&dofs, gradient.as_slice(), |i, j| hessian[(i, j)]);
            }
        }
    }

    /// The damping of non-rigid motion (in parallel, one slot per window).
    fn add_damping(&self, q: &DVector<f64>, want: Want, out: &mut Evaluation) {
        let Some(damping) = &self.damping else { return };
        if want == Want::Energy {
            let energies: Vec<f64> =
                (0..damping.len()).into_par_iter().map(|w| damping.energy(w, q, self.q_n)).collect();
            out.parts.damping += energies.iter().sum::<f64>();
            return;
        }
        let elements: Vec<_> =
            (0..damping.len()).into_par_iter().map(|w| damping.element(w, q, self.q_n)).collect();
        for (energy, dofs, gradient, hessian) in elements {
            out.parts.damping += energy;
            out.add(&dofs, gradient.as_slice(), |i, j| hessian[(i, j)]);
        }
    }
}
