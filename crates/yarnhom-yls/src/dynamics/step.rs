//! One time step: the minimizer of the incremental potential ([`super::potential`]) by Newton's
//! method with a backtracking line search (IPC, Li et al. 2020, Alg. 1), the step capped so that
//! no yarn passes through another ([`super::caps`]).
//!
//! - Handles: their vertices are first moved to their positions at the step's end (checked
//!   against the same caps: a handle that would carry a yarn through another in one step is an
//!   error, [`StepError::HandleMoveTooFar`]), then held: their DOFs are left out of the solve.
//! - Newton: the Hessian on the free DOFs is factored by [`SpdSolver`] (sparse Cholesky, the
//!   symbolic analysis reused across iterations and steps while the pattern stays within it);
//!   rod and contact Hessians are not projected, so where the factorization fails the diagonal
//!   is shifted by `σ = 10⁻⁸ max|H_ii|`, then tenfold more, up to 20 times.
//! - Convergence: the unshifted Newton step `d = -H⁻¹ ∇Φ` (the residual scaled by the inverse
//!   Hessian) moves no free vertex more than `tolerance · r` and no twist more than
//!   `tolerance` rad ([`SolverOptions::tolerance`], default `10⁻⁶`; `r` the largest yarn radius).
//!   Where the Hessian had to be shifted, the step shrinks with the shift rather than the
//!   residual, so the residual is scaled by the inertia and the twist stiffness instead:
//!   `|∇_v Φ| h² / m_v ≤ tolerance · r` and `|∂Φ/∂θ_e| ≤ tolerance · k_e`.
//! - Line search: from the capped fraction `α₀`, halve `α` until
//!   `Φ(q + α d) ≤ Φ(q) + 10⁻⁴ α ∇Φ · d` (to the round-off of `Φ`'s parts) with `Φ` finite.
//! - Contact pairs: the step's candidate list ([`super::contact::CandidateList`]) is brought
//!   to every Newton iterate; the Hessian and gradient take the pairs within the law's reach
//!   there (the others contribute exactly nothing), the caps and the line search all of them.

use nalgebra::DVector;
use yarnhom_sparse::SpdSolver;

use super::caps::{Caps, step_caps, vertex_moves};
use super::contact::Candidate;
use super::potential::{Evaluation, PotentialParts, StepContext, Want};
use super::system::{SolverOptions, System};

/// Energies of a state (J).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Energies {
    /// `½ vᵀ M v`.
    pub kinetic_j: f64,
    /// Rods: stretching, bending and twisting.
    pub elastic_j: f64,
    /// Glue springs.
    pub glue_j: f64,
    /// Yarn-yarn contact.
    pub contact_j: f64,
    /// Obstacle barriers.
    pub obstacle_j: f64,
    /// Gravity `-Σ m_v g · x_v`.
    pub gravity_j: f64,
}

impl Energies {
    /// The sum of all.
    pub fn total_j(&self) -> f64 {
        self.kinetic_j + self.elastic_j + self.glue_j + self.contact_j + self.obstacle_j + self.gravity_j
    }
}

/// What one step did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepReport {
    /// Time at the step's end (s).
    pub time_s: f64,
    /// Newton iterations (factorizations; the last one found convergence).
    pub newton_iterations: usize,
    /// Halvings of the step in the line searches.
    pub line_search_cuts: usize,
    /// Iterations whose step the contact cap `α ≤ 0.9 d / (δ_e + δ_f)` shortened.
    pub step_caps: usize,
    /// Iterations whose step the broad-phase margin shortened.
    pub reach_caps: usize,
    /// Iterations whose step an obstacle shortened.
    pub obstacle_caps: usize,
    /// Factorizations that needed a diagonal shift.
    pub hessian_shifts: usize,
    /// Smallest centreline distance of two candidate edges at the step's end, in yarn radii
    /// (∞ where no pair is within the broad-phase radius).
    pub closest_distance_radii: f64,
    /// Energies at the step's end.
    pub energies: Energies,
    /// Wall-clock time of the step (s).
    pub wall_time_s: f64,
}

/// Why a step failed (the simulation's state is then unchanged).
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum StepError {
    /// The time step is not positive and finite.
    #[error("time step {time_step_s} s must be positive and finite")]
    InvalidTimeStep {
        /// The time step given (s).
        time_step_s: f64,
    },
    /// The handles move so far in one step that they could carry a yarn through another or
    /// into an obstacle.
    #[error(
        "the handles move too far in one step: only {safe_fraction} of their move is safe; shorten the time step"
    )]
    HandleMoveTooFar {
        /// The fraction of the handles' move the caps allow.
        safe_fraction: f64,
    },
    /// The energy, its gradient or the Newton step is not finite.
    #[error("non-finite {what} at Newton iteration {iteration}")]
    Diverged {
        /// The iteration.
        iteration: usize,
        /// What went non-finite.
        what: &'static str,
    },
    /// No diagonal shift made the Hessian factorable.
    #[error("the Hessian could not be factored at Newton iteration {iteration}, even shifted")]
    Factorization {
        /// The iteration.
        iteration: usize,
    },
    /// The line search found no sufficient decrease.
    #[error("the line search found no decrease at Newton iteration {iteration} (Newton step {step_m} m)")]
    LineSearchFailed {
        /// The iteration.
        iteration: usize,
        /// Largest vertex move of the Newton direction (m).
        step_m: f64,
    },
    /// Newton's method did not converge in the iterations allowed.
    #[error("Newton's method did not converge in {iterations} iterations (last step {step_m} m)")]
    NotConverged {
        /// Iterations taken.
        iterations: usize,
        /// Largest vertex move of the last Newton direction (m).
        step_m: f64,
    },
}

/// The state of a simulation: DOFs, vertex velocities (positions only) and time.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct State {
    pub q: DVector<f64>,
    pub velocity: DVector<f64>,
    pub time_s: f64,
}

/// Counters of one step.
#[derive(Debug, Clone, Copy, Default)]
struct Counters {
    line_search_cuts: usize,
    step_caps: usize,
    reach_caps: usize,
    obstacle_caps: usize,
    hessian_shifts: usize,
}

impl Counters {
    fn count_caps(&mut self, caps: &Caps) {
        self.step_caps += usize::from(caps.contact < 1.0);
        self.reach_caps += usize::from(caps.reach < 1.0);
        self.obstacle_caps += usize::from(caps.obstacle < 1.0);
    }
}

/// The candidate contact pairs at `q` (none without contact).
pub(crate) fn candidates_at(system: &System, q: &DVector<f64>) -> Vec<Candidate> {
    system.candidate_list(q).pairs
}

/// The state after a step of `time_step_s` from `state`, and what it took.
pub(crate) fn advance(
    system: &System,
    state: &State,
    solver: &mut SpdSolver,
    time_step_s: f64,
) -> Result<(State, StepReport), StepError> {
    let started = std::time::Instant::now();
    if !(time_step_s > 0.0 && time_step_s.is_finite()) {
        return Err(StepError::InvalidTimeStep { time_step_s });
    }
    let context = StepContext::new(system, &state.q, &state.velocity, time_step_s);
    let time_s = state.time_s + time_step_s;
    let mut q = move_handles(system, &state.q, time_s)?;
    let mut counters = Counters::default();
    let options = system.options;
    let mut step_m = f64::NAN;
    let mut list = system.candidate_list(&q);
    let reach_m = system.contact.map_or(0.0, |law| law.reach_m());
    for iteration in 0..options.max_newton_iterations {
        let x = &q.as_slice()[..3 * system.vertex_count()];
        list.update(&system.topology, x, system.broad_phase_m());
        let evaluation = context.evaluate(&q, &list.within(reach_m), Want::Derivatives);
        if !evaluation.parts.total().is_finite() {
            return Err(StepError::Diverged { iteration, what: "incremental potential" });
        }
        if !evaluation.gradient.iter().all(|g| g.is_finite()) {
            return Err(StepError::Diverged { iteration, what: "gradient" });
        }
        let (direction, shifted) = newton_direction(system, solver, &evaluation, iteration)?;
        counters.hessian_shifts += usize::from(shifted);
        step_m = vertex_moves(system, &direction).into_iter().fold(0.0, f64::max);
        if converged(system, &options, &evaluation.gradient, &direction, shifted, time_step_s) {
            let report = Report {
                started,
                iterations: iteration + 1,
                counters,
                parts: evaluation.parts,
                closest_m: list.closest_m(),
            };
            return finish(system, state, q, time_s, time_step_s, report);
        }
        let caps = step_caps(system, &q, &direction, &list);
        counters.count_caps(&caps);
        let search =
            LineSearch { context: &context, candidates: &list.pairs, max_cuts: options.max_line_search_cuts };
        q = search
            .run(&q, &direction, &evaluation, caps.fraction(), &mut counters.line_search_cuts)
            .ok_or(StepError::LineSearchFailed { iteration, step_m })?;
    }
    Err(StepError::NotConverged { iterations: options.max_newton_iterations, step_m })
}

/// `q_n` with the held vertices moved to their positions at `time_s`, if the caps allow the
/// whole move.
fn move_handles(system: &System, q_n: &DVector<f64>, time_s: f64) -> Result<DVector<f64>, StepError> {
    let mut q = q_n.clone();
    for &(v, h, x0) in &system.held {
        let target = x0 + nalgebra::Vector3::from(system.handles[h].translation_at(time_s));
        q.fixed_rows_mut::<3>(3 * v).copy_from(&target);
    }
    let d = &q - q_n;
    if d.amax() > 0.0 {
        let caps = step_caps(system, q_n, &d, &system.candidate_list(q_n));
        let safe_fraction = caps.contact.min(caps.reach).min(caps.obstacle);
        if safe_fraction < 1.0 {
            return Err(StepError::HandleMoveTooFar { safe_fraction });
        }
    }
    Ok(q)
}

/// Smallest relative diagonal shift tried, and the number of tenfold increases.
const SHIFT_START: f64 = 1e-8;
const SHIFT_TRIES: usize = 20;

/// The Newton direction on the free DOFs (zero on held ones) and whether the Hessian needed a
/// shift.
fn newton_direction(
    system: &System,
    solver: &mut SpdSolver,
    evaluation: &Evaluation,
    iteration: usize,
) -> Result<(DVector<f64>, bool), StepError> {
    let free = &system.free_index;
    let reduced: Vec<(usize, usize, f64)> =
        evaluation.triplets.iter().filter_map(|&(i, j, v)| Some((free[i]?, free[j]?, v))).collect();
    let n = system.free_count;
    let mut diagonal = vec![0.0; n];
    for &(i, j, v) in &reduced {
        if i == j {
            diagonal[i] += v;
        }
    }
    let largest = diagonal.iter().fold(0.0, |m: f64, d| m.max(d.abs()));
    solver.load(n, &reduced).map_err(|_| StepError::Factorization { iteration })?;
    let mut shift = 0.0;
    let mut tries = 0;
    while solver.factor_shifted(shift).is_err() {
        if tries == SHIFT_TRIES {
            return Err(StepError::Factorization { iteration });
        }
        shift = if shift == 0.0 { SHIFT_START * largest.max(f64::MIN_POSITIVE) } else { 10.0 * shift };
        tries += 1;
    }
    let mut rhs: Vec<f64> = vec![0.0; n];
    for (i, f) in free.iter().enumerate() {
        if let Some(k) = *f {
            rhs[k] = -evaluation.gradient[i];
        }
    }
    solver.solve_in_place(&mut rhs, 1);
    if !rhs.iter().all(|x| x.is_finite()) {
        return Err(StepError::Diverged { iteration, what: "Newton step" });
    }
    let direction = DVector::from_iterator(free.len(), free.iter().map(|f| f.map_or(0.0, |k| rhs[k])));
    Ok((direction, shift > 0.0))
}

/// Whether the iterate is converged (the module's test): the Newton step `d` within the
/// tolerance, or where the Hessian was shifted (`d` then shrinks with the shift, not with the
/// residual) the free gradient scaled by the inertia `h² / m_v` and the twist stiffness `1 / k_e`.
/// The second test also accepts a saddle of the incremental potential, such as a perfectly
/// symmetric impact, which the shifted Newton steps would only approach linearly.
fn converged(
    system: &System,
    options: &SolverOptions,
    gradient: &DVector<f64>,
    d: &DVector<f64>,
    shifted: bool,
    time_step_s: f64,
) -> bool {
    let (tolerance, positions) = (options.tolerance, 3 * system.vertex_count());
    if !shifted {
        let largest_move = vertex_moves(system, d).into_iter().fold(0.0, f64::max);
        return largest_move <= tolerance * system.radius_m
            && d.rows(positions, d.len() - positions).amax() <= tolerance;
    }
    let free_force = |v: usize| {
        (0..3)
            .filter(|&k| system.free_index[3 * v + k].is_some())
            .map(|k| gradient[3 * v + k].powi(2))
            .sum::<f64>()
            .sqrt()
    };
    let h2 = time_step_s * time_step_s;
    let vertices = system
        .masses_kg
        .iter()
        .enumerate()
        .all(|(v, &m)| free_force(v) * h2 <= tolerance * system.radius_m * m);
    let twists = system
        .twist_scale_nm
        .iter()
        .enumerate()
        .all(|(e, &k)| gradient[positions + e].abs() <= tolerance * k);
    vertices && twists
}

/// The Armijo constant of the line search.
const ARMIJO: f64 = 1e-4;

/// A backtracking line search along a Newton direction, with the candidates of its start.
struct LineSearch<'a> {
    context: &'a StepContext<'a>,
    candidates: &'a [Candidate],
    max_cuts: usize,
}

impl LineSearch<'_> {
    /// The accepted iterate, or `None`.
    fn run(
        &self,
        q: &DVector<f64>,
        d: &DVector<f64>,
        start: &Evaluation,
        fraction: f64,
        cuts: &mut usize,
    ) -> Option<DVector<f64>> {
        let energy = start.parts.total();
        let slope = start.gradient.dot(d);
        let round_off = 8.0 * f64::EPSILON * start.parts.magnitude();
        let mut alpha = fraction;
        for _ in 0..=self.max_cuts {
            let trial = q + d * alpha;
            let trial_energy = self.context.evaluate(&trial, self.candidates, Want::Energy).parts.total();
            if trial_energy.is_finite() && trial_energy <= energy + ARMIJO * alpha * slope + round_off {
                return Some(trial);
            }
            alpha *= 0.5;
            *cuts += 1;
        }
        None
    }
}

/// What a converged solve hands to [`finish`].
struct Report {
    iterations: usize,
    counters: Counters,
    parts: PotentialParts,
    /// The smallest centreline distance of the candidate pairs (m).
    closest_m: f64,
    /// When the step started (for its wall time).
    started: std::time::Instant,
}

/// The state and report of a step converged at `q`.
fn finish(
    system: &System,
    state: &State,
    q: DVector<f64>,
    time_s: f64,
    time_step_s: f64,
    report: Report,
) -> Result<(State, StepReport), StepError> {
    let positions = 3 * system.vertex_count();
    let mut velocity = (q.rows(0, positions) - state.q.rows(0, positions)) / time_step_s;
    apply_friction(system, &q, &mut velocity, time_step_s);
    if !(q.iter().all(|x| x.is_finite()) && velocity.iter().all(|x| x.is_finite())) {
        return Err(StepError::Diverged { iteration: report.iterations, what: "state" });
    }
    let energies = Energies {
        kinetic_j: kinetic_energy_j(system, &velocity),
        elastic_j: report.parts.elastic,
        glue_j: report.parts.glue,
        contact_j: report.parts.contact,
        obstacle_j: report.parts.obstacle,
        gravity_j: gravity_energy_j(system, &q),
    };
    let c = report.counters;
    let step = StepReport {
        time_s,
        newton_iterations: report.iterations,
        line_search_cuts: c.line_search_cuts,
        step_caps: c.step_caps,
        reach_caps: c.reach_caps,
        obstacle_caps: c.obstacle_caps,
        hessian_shifts: c.hessian_shifts,
        closest_distance_radii: report.closest_m / system.radius_m,
        energies,
        wall_time_s: report.started.elapsed().as_secs_f64(),
    };
    Ok((State { q, velocity, time_s }, step))
}

/// Obstacle friction ([`super::Obstacle::apply_friction`]) on the end velocities of the free
/// vertices at `q`.
fn apply_friction(system: &System, q: &DVector<f64>, velocity: &mut DVector<f64>, time_step_s: f64) {
    for obstacle in system.obstacles.iter().filter(|o| o.friction > 0.0) {
        for (v, (&m, &radius)) in system.masses_kg.iter().zip(&system.vertex_radius_m).enumerate() {
            if system.free_index[3 * v].is_some() {
                let mut u = System::position(velocity, v);
                obstacle.apply_friction(&System::position(q, v), radius, &mut u, m, time_step_s);
                velocity.fixed_rows_mut::<3>(3 * v).copy_from(&u);
            }
        }
    }
}

/// `½ Σ m_v |v_v|²`.
pub(crate) fn kinetic_energy_j(system: &System, velocity: &DVector<f64>) -> f64 {
    system
        .masses_kg
        .iter()
        .enumerate()
        .map(|(v, &m)| 0.5 * m * System::position(velocity, v).norm_squared())
        .sum()
}

/// `-Σ m_v g · x_v`.
pub(crate) fn gravity_energy_j(system: &System, q: &DVector<f64>) -> f64 {
    -system
        .masses_kg
        .iter()
        .enumerate()
        .map(|(v, &m)| m * system.gravity.dot(&System::position(q, v)))
        .sum::<f64>()
}
