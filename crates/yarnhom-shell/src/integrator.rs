//! Implicit Euler time stepping as minimization of the incremental potential (Sec. 4.2): each
//! step minimizes
//!
//! `Φ(x) = Σ m_i |x_i - x̂_i|² / (2h²) + E(x) + E_contact(x) - Σ (m_i g + f_i)·x_i + Φ_damp(x)`,
//! `x̂ = x_n + h v_n`,
//!
//! by Newton's method with a backtracking line search, from `x̂` or `x_n`
//! ([`Simulation::step`]). `E` is the elastic energy; the Newton matrix takes its element
//! matrices as [`Dynamics::newton_matrix`] says: Gauss-Newton in the forms (the default,
//! positive semidefinite without an 18 x 18 eigensolver), or the exact Hessians with their
//! eigenvalues replaced by their absolute values (Chen et al. 2024; from the same states of the
//! published stretch and drape scenes, about a fifth fewer Newton iterations than with the
//! eigenvalues clamped to zero). Either changes the path to the minimum of `Φ`, not the minimum.
//! Rayleigh damping `D = α M + β K` (`K` the elastic Gauss-Newton matrix at Newton's starting
//! point, positive semidefinite by construction) enters as `Φ_damp = (x - x_n)ᵀ D (x - x_n) / (2h)`.
//! Handle vertices follow their scripted positions and are removed from the unknowns. The
//! Newton matrices are assembled straight into one sparsity pattern (the mesh's element
//! couplings and vertex blocks) and solved by faer's sparse Cholesky on its symbolic analysis,
//! both computed once, in memory kept from step to step (module `newton_matrix`), or by
//! conjugate gradients where the inertia term makes them cheaper ([`crate::linear_solver`]). Friction
//! against obstacles is applied to the new velocities ([`crate::contact`]). The air drag `f`
//! ([`crate::wind`]) is explicit, as in ARCSim: evaluated once per step at `x_n`, `v_n` and held
//! constant over it, so it adds to the gradient and nothing to the Newton matrix.

use std::time::Instant;

use nalgebra::{Matrix3, Vector3};

use crate::contact::{ContactSettings, Obstacle, SelfCollision, obstacle_contacts};
use crate::elastic::{Assembly, ElasticModel, NewtonMatrix};
use crate::line_search::backtrack;
use crate::linear_solver::{
    CG_ERROR_SHARE, LinearSolver, LinearSolves, conjugate_gradient, factorization_cost_in_iterations,
    jacobi_condition_bound, predicted_iterations,
};
use crate::newton_matrix::{CholeskyWorkspace, HessianPattern, NewtonAssembly};
use crate::wind::Wind;

/// Newton starts at the inertial prediction when it moves no vertex by more than this many
/// Newton tolerances ([`Simulation::step`]).
pub const INERTIAL_START_TOLERANCES: f64 = 10.0;

/// A piecewise linear translation over time (keyframes `(time_s, translation_m)`), constant
/// before the first and after the last key.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Motion {
    /// Keyframes, ascending in time.
    pub keys: Vec<(f64, [f64; 3])>,
}

impl Motion {
    /// The translation at `time_s`.
    pub fn translation(&self, time_s: f64) -> Vector3<f64> {
        let Some(first) = self.keys.first() else { return Vector3::zeros() };
        if time_s <= first.0 {
            return Vector3::from(first.1);
        }
        for w in self.keys.windows(2) {
            let ((t0, a), (t1, b)) = (w[0], w[1]);
            if time_s <= t1 {
                let s = if t1 > t0 { (time_s - t0) / (t1 - t0) } else { 1.0 };
                return Vector3::from(a) * (1.0 - s) + Vector3::from(b) * s;
            }
        }
        Vector3::from(self.keys[self.keys.len() - 1].1)
    }
}

/// Vertices held at their initial positions plus a scripted translation.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Handle {
    /// The held vertices.
    pub vertices: Vec<usize>,
    /// Their translation over time.
    pub motion: Motion,
}

/// Time step, forces and solver settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dynamics {
    /// Time step `h` (s).
    pub dt_s: f64,
    /// Gravity (m/s²).
    pub gravity: [f64; 3],
    /// Rayleigh mass damping `α` (1/s).
    pub mass_damping: f64,
    /// Rayleigh stiffness damping `β` (s).
    pub stiffness_damping: f64,
    /// Air drag, explicit ([`crate::wind`]).
    pub wind: Wind,
    /// Most Newton iterations per step.
    pub max_newton_iterations: u32,
    /// Newton stops when the largest position update is below this (m).
    pub tolerance_m: f64,
    /// The element matrices of the Newton matrix (the stiffness damping matrix always takes the
    /// Gauss-Newton ones).
    pub newton_matrix: NewtonMatrix,
    /// How the Newton system is solved.
    pub linear_solver: LinearSolver,
}

/// What one step did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepStats {
    /// Newton iterations.
    pub newton_iterations: u32,
    /// Largest free-DOF force imbalance at the last Newton iterate, before its update (N).
    pub residual_n: f64,
    /// Line-search halvings over all iterations.
    pub line_search_steps: u32,
    /// The linear solves' work over all iterations.
    pub linear_solves: LinearSolves,
    /// Whether Newton met its tolerance.
    pub converged: bool,
    /// Wall time (s).
    pub wall_time_s: f64,
}

/// Why a step failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum StepError {
    /// The Newton matrix could not be factored.
    #[error("the Newton matrix is not positive definite at t = {time_s} s")]
    Factorization {
        /// Simulated time.
        time_s: f64,
    },
    /// The state became non-finite.
    #[error("the simulation diverged (non-finite positions) at t = {time_s} s")]
    Diverged {
        /// Simulated time.
        time_s: f64,
    },
}

/// A running cloth simulation.
pub struct Simulation {
    /// Elastic model.
    pub model: ElasticModel,
    /// Positions (m).
    pub positions: Vec<Vector3<f64>>,
    /// Velocities (m/s).
    pub velocities: Vec<Vector3<f64>>,
    /// Simulated time (s).
    pub time_s: f64,
    masses: Vec<f64>,
    /// Material area of each triangle (m²), for the air drag.
    rest_areas: Vec<f64>,
    handles: Vec<Handle>,
    handle_origins: Vec<Vec<Vector3<f64>>>,
    fixed: Vec<bool>,
    obstacles: Vec<Obstacle>,
    contact: ContactSettings,
    self_collision: Option<SelfCollision>,
    dynamics: Dynamics,
    pattern: HessianPattern,
    /// The slots of the Newton matrix in the rows and columns of the fixed DOFs.
    pinned: Vec<usize>,
    /// Per DOF, the inertia term of the Newton matrix's diagonal, `m/h² + α m/h` (fixed DOFs:
    /// 1, their whole diagonal).
    inertia: Vec<f64>,
    /// The smallest inertia term of a free DOF, the bound on `λ_min` of the Newton matrix.
    smallest_inertia: f64,
    /// The Cholesky factor's memory, kept from step to step once a step factors.
    cholesky: Option<CholeskyWorkspace>,
}

/// The parts of `Φ` that do not change within a step.
struct StepTerms {
    predicted: Vec<Vector3<f64>>,
    start: Vec<Vector3<f64>>,
    /// `β K_n` on the pattern (empty without stiffness damping).
    stiffness_damping: Vec<f64>,
    /// The air drag on each vertex at `x_n`, `v_n` (N; empty without wind).
    wind: Vec<Vector3<f64>>,
}

impl Simulation {
    /// A simulation starting at rest at `positions`.
    pub fn new(
        model: ElasticModel,
        positions: Vec<Vector3<f64>>,
        handles: Vec<Handle>,
        obstacles: Vec<Obstacle>,
        contact: ContactSettings,
        dynamics: Dynamics,
    ) -> Self {
        let masses: Vec<f64> =
            model.mesh.vertex_areas().iter().map(|a| a * model.material.areal_density_kg_m2).collect();
        let mut fixed = vec![false; 3 * positions.len()];
        for &v in handles.iter().flat_map(|h| &h.vertices) {
            fixed[3 * v..3 * v + 3].fill(true);
        }
        let handle_origins =
            handles.iter().map(|h| h.vertices.iter().map(|&v| positions[v]).collect()).collect();
        let self_collision = SelfCollision::new(&contact, &model.mesh.material);
        let pattern = HessianPattern::new(positions.len(), &model.element_vertices());
        let pinned = pattern.slots_touching(&fixed);
        let (h, alpha) = (dynamics.dt_s, dynamics.mass_damping);
        let inertia: Vec<f64> = (0..fixed.len())
            .map(|dof| if fixed[dof] { 1.0 } else { masses[dof / 3] * (1.0 / (h * h) + alpha / h) })
            .collect();
        let smallest_inertia =
            inertia.iter().zip(&fixed).filter(|(_, f)| !**f).fold(f64::INFINITY, |m, (c, _)| m.min(*c));
        Self {
            velocities: vec![Vector3::zeros(); positions.len()],
            positions,
            time_s: 0.0,
            masses,
            rest_areas: model.mesh.rest_areas(),
            handles,
            handle_origins,
            fixed,
            obstacles,
            contact,
            self_collision,
            dynamics,
            pattern,
            pinned,
            inertia,
            smallest_inertia,
            cholesky: None,
            model,
        }
    }

    /// Kinetic energy (J).
    pub fn kinetic_energy(&self) -> f64 {
        self.velocities.iter().zip(&self.masses).map(|(v, m)| 0.5 * m * v.norm_squared()).sum()
    }

    /// Gravitational potential energy relative to the origin (J).
    pub fn gravity_energy(&self) -> f64 {
        let g = Vector3::from(self.dynamics.gravity);
        -self.positions.iter().zip(&self.masses).map(|(x, m)| m * g.dot(x)).sum::<f64>()
    }

    /// The elastic force the cloth exerts on handle `k` (N): the elastic energy gradient summed
    /// over its vertices (the force the handle must apply to hold them is its negative).
    pub fn handle_force_n(&self, k: usize) -> Vector3<f64> {
        let mut a = Assembly::new(3 * self.positions.len());
        self.model.assemble(&self.positions, None, &mut a);
        self.handles[k]
            .vertices
            .iter()
            .map(|&v| -Vector3::new(a.gradient[3 * v], a.gradient[3 * v + 1], a.gradient[3 * v + 2]))
            .sum()
    }

    /// Deepest penetration of any vertex into an obstacle (m), 0 if none.
    pub fn obstacle_penetration_m(&self) -> f64 {
        let deepest = self
            .positions
            .iter()
            .flat_map(|p| self.obstacles.iter().map(move |o| o.distance(p).0))
            .fold(f64::INFINITY, f64::min);
        (-deepest).max(0.0)
    }

    /// Advance by one time step.
    pub fn step(&mut self) -> Result<StepStats, StepError> {
        let started = Instant::now();
        let h = self.dynamics.dt_s;
        let next_time = self.time_s + h;
        let start = self.positions.clone();
        let predicted: Vec<_> = start.iter().zip(&self.velocities).map(|(x, v)| x + h * v).collect();
        let wind = self.wind_forces();
        let mut terms = StepTerms { predicted, start, stiffness_damping: Vec::new(), wind };
        let mut x = self.newton_start(&terms, next_time);
        let mut stats = StepStats {
            newton_iterations: 0,
            residual_n: 0.0,
            line_search_steps: 0,
            linear_solves: LinearSolves::default(),
            converged: false,
            wall_time_s: 0.0,
        };
        // One buffer for every iteration's assembly, so its memory is allocated once per step.
        let mut a = NewtonAssembly::new(&self.pattern);
        let mut cholesky = self.cholesky.take();
        // Φ at the current iterate, when the last line search computed it.
        let mut phi: Option<f64> = None;
        for iteration in 0..self.dynamics.max_newton_iterations {
            self.assemble(&x, &mut terms, iteration == 0, &mut a);
            self.pin(&mut a);
            stats.residual_n = a.gradient.iter().fold(0.0_f64, |m, g| m.max(g.abs()));
            let mut dx: Vec<f64> = a.gradient.iter().map(|g| -g).collect();
            self.solve_newton_system(&a.matrix, &mut dx, &mut cholesky, &mut stats.linear_solves)?;
            // The assembly's energy is `E(x)` (the first iteration's; later ones reuse the line
            // search's `Φ`).
            let phi0 = phi.unwrap_or_else(|| a.energy + self.potential_besides_elastic(&x, &terms));
            let slope = dot(&a.gradient, &dx);
            let (alpha, halvings, accepted) =
                backtrack(&x, &dx, phi0, slope, |trial| self.potential(trial, &terms));
            phi = accepted;
            stats.line_search_steps += halvings;
            stats.newton_iterations = iteration + 1;
            let mut largest: f64 = 0.0;
            for (p, d) in x.iter_mut().zip(dx.chunks_exact(3)) {
                let step = alpha * Vector3::new(d[0], d[1], d[2]);
                largest = largest.max(step.amax());
                *p += step;
            }
            if x.iter().any(|p| !p.iter().all(|c| c.is_finite())) {
                return Err(StepError::Diverged { time_s: self.time_s });
            }
            if largest < self.dynamics.tolerance_m {
                stats.converged = true;
                break;
            }
        }
        self.cholesky = cholesky;
        self.finish_step(x, &terms.start, next_time);
        stats.wall_time_s = started.elapsed().as_secs_f64();
        Ok(stats)
    }

    /// Replace `b` by the solution of `A x = b`, `A` the Newton matrix with lower-triangle
    /// `matrix` on the pattern, as [`Dynamics::linear_solver`] says (a factorization's memory
    /// in `cholesky`, allocated on the first).
    fn solve_newton_system(
        &self,
        matrix: &[f64],
        b: &mut Vec<f64>,
        cholesky: &mut Option<CholeskyWorkspace>,
        solves: &mut LinearSolves,
    ) -> Result<(), StepError> {
        let cg = match self.dynamics.linear_solver {
            LinearSolver::Auto => self.conjugate_gradient_solve(matrix, b, true, solves),
            LinearSolver::ConjugateGradient => self.conjugate_gradient_solve(matrix, b, false, solves),
            LinearSolver::Cholesky => None,
        };
        if let Some(x) = cg {
            *b = x;
            return Ok(());
        }
        let workspace = cholesky.get_or_insert_with(|| self.pattern.workspace());
        let mut factor = self
            .pattern
            .factor(matrix, workspace)
            .map_err(|_| StepError::Factorization { time_s: self.time_s })?;
        solves.factorizations += 1;
        factor.solve_in_place(b);
        Ok(())
    }

    /// The solution of `A x = b` by Jacobi-preconditioned conjugate gradients, to an error
    /// below [`CG_ERROR_SHARE`] Newton tolerances, if they converge. With `within_cost`, only
    /// when the bound on their iterations is below the cost of a factorization, and within that
    /// cost ([`crate::linear_solver`]); else within as many iterations as DOFs.
    fn conjugate_gradient_solve(
        &self,
        matrix: &[f64],
        b: &[f64],
        within_cost: bool,
        solves: &mut LinearSolves,
    ) -> Option<Vec<f64>> {
        let tolerance = CG_ERROR_SHARE * self.dynamics.tolerance_m * self.smallest_inertia;
        let mut x = vec![0.0; b.len()];
        let b_norm = dot(b, b).sqrt();
        if b_norm <= tolerance {
            return Some(x);
        }
        let mut budget = b.len() as f64;
        if within_cost {
            budget = factorization_cost_in_iterations(&self.pattern);
            let kappa = jacobi_condition_bound(&self.pattern, matrix, &self.inertia);
            if predicted_iterations(kappa, tolerance / b_norm) > budget {
                return None;
            }
        }
        let run = conjugate_gradient(&self.pattern, matrix, b, &mut x, tolerance, budget as u32);
        solves.cg_iterations += run.iterations;
        run.converged.then_some(x)
    }

    /// The air drag on each vertex in the current state (N; empty without wind).
    pub fn wind_forces(&self) -> Vec<Vector3<f64>> {
        let wind = self.dynamics.wind;
        if wind.is_none() {
            return Vec::new();
        }
        wind.vertex_forces_n(&self.model.mesh, &self.rest_areas, &self.positions, &self.velocities)
    }

    /// Where Newton starts, handles at their positions at `time_s`: at the inertial prediction
    /// `x̂ = x_n + h v_n` when no vertex's `h |v_i|` exceeds [`INERTIAL_START_TOLERANCES`]
    /// Newton tolerances, else at `x_n`. From `x̂` the first update is of the order of `h² a`,
    /// from `x_n` at least `h v`: with short steps `x̂` is far closer (at the published
    /// Δt = 0.209 ms, one Newton iteration per step instead of two), while with long ones it
    /// overshoots a swinging cloth (at 4.2 ms from `x̂`: 5.1 iterations per step against 4.9 in
    /// `stretch-x`, 6.0 against 4.6 in `drape`).
    fn newton_start(&self, terms: &StepTerms, time_s: f64) -> Vec<Vector3<f64>> {
        let h = self.dynamics.dt_s;
        let fastest = self.velocities.iter().fold(0.0_f64, |m, v| m.max(v.amax()));
        let short = h * fastest <= INERTIAL_START_TOLERANCES * self.dynamics.tolerance_m;
        let mut x = if short { terms.predicted.clone() } else { terms.start.clone() };
        self.move_handles(&mut x, time_s);
        x
    }

    /// Handle vertices at their scripted positions at `time_s`.
    fn move_handles(&self, x: &mut [Vector3<f64>], time_s: f64) {
        for (handle, origins) in self.handles.iter().zip(&self.handle_origins) {
            let shift = handle.motion.translation(time_s) - handle.motion.translation(0.0);
            for (&v, origin) in handle.vertices.iter().zip(origins) {
                x[v] = origin + shift;
            }
        }
    }

    /// New velocities with obstacle friction, then the new state.
    fn finish_step(&mut self, x: Vec<Vector3<f64>>, start: &[Vector3<f64>], time_s: f64) {
        let h = self.dynamics.dt_s;
        let mut v: Vec<Vector3<f64>> = x.iter().zip(start).map(|(a, b)| (a - b) / h).collect();
        for c in obstacle_contacts(&self.obstacles, &self.contact, &x) {
            // Coulomb: the friction impulse μ f_n h at most stops the tangential velocity.
            let vn = c.normal * c.normal.dot(&v[c.vertex]);
            let vt = v[c.vertex] - vn;
            let speed = vt.norm();
            if speed > 0.0 {
                let slowdown = self.contact.friction * c.force_n * h / (self.masses[c.vertex] * speed);
                v[c.vertex] = vn + vt * (1.0 - slowdown).max(0.0);
            }
        }
        for (i, f) in self.fixed.chunks_exact(3).enumerate() {
            if f[0] {
                v[i] = (x[i] - start[i]) / h;
            }
        }
        self.positions = x;
        self.velocities = v;
        self.time_s = time_s;
    }

    /// `Φ(x)` without the damping term's constant parts.
    fn potential(&self, x: &[Vector3<f64>], terms: &StepTerms) -> f64 {
        self.model.energy(x) + self.potential_besides_elastic(x, terms)
    }

    /// The terms of `Φ(x)` other than the elastic energy `E(x)`.
    fn potential_besides_elastic(&self, x: &[Vector3<f64>], terms: &StepTerms) -> f64 {
        let h = self.dynamics.dt_s;
        let g = Vector3::from(self.dynamics.gravity);
        let (alpha, mut phi) = (self.dynamics.mass_damping, 0.0);
        for (i, p) in x.iter().enumerate() {
            let m = self.masses[i];
            phi += m * (p - terms.predicted[i]).norm_squared() / (2.0 * h * h) - m * g.dot(p);
            phi += alpha * m * (p - terms.start[i]).norm_squared() / (2.0 * h);
        }
        phi -= terms.wind.iter().zip(x).map(|(f, p)| f.dot(p)).sum::<f64>();
        phi += crate::contact::obstacle_energy(&self.obstacles, &self.contact, x);
        if let Some(s) = &self.self_collision {
            phi += s.energy(&s.pairs(x));
        }
        if !terms.stiffness_damping.is_empty() {
            let d = flatten_difference(x, &terms.start);
            phi += 0.5 * dot(&d, &self.pattern.symmetric_product(&terms.stiffness_damping, &d)) / h;
        }
        phi
    }

    /// Hold the fixed DOFs: zero gradient, identity rows and columns in the Newton matrix.
    fn pin(&self, a: &mut NewtonAssembly) {
        for &slot in &self.pinned {
            a.matrix[slot] = 0.0;
        }
        for (dof, _) in self.fixed.iter().enumerate().filter(|(_, f)| **f) {
            a.gradient[dof] = 0.0;
            a.matrix[self.pattern.diagonal_slot(dof)] = 1.0;
        }
    }

    /// Gradient and Newton matrix of `Φ`. On the step's first iteration (with stiffness damping)
    /// the elastic [`NewtonMatrix::GaussNewton`] matrix is also kept, scaled by `β`, as the
    /// stiffness damping matrix `β K_n`, whatever [`Dynamics::newton_matrix`] says, so that `Φ`
    /// does not depend on it.
    fn assemble(&self, x: &[Vector3<f64>], terms: &mut StepTerms, first: bool, a: &mut NewtonAssembly) {
        let h = self.dynamics.dt_s;
        let beta = self.dynamics.stiffness_damping;
        let matrix = self.dynamics.newton_matrix;
        if first && beta > 0.0 {
            a.clear();
            self.model.assemble(x, Some(NewtonMatrix::GaussNewton), a);
            terms.stiffness_damping = a.matrix.iter().map(|v| beta * v).collect();
            if matrix != NewtonMatrix::GaussNewton {
                a.clear();
                self.model.assemble(x, Some(matrix), a);
            }
        } else {
            a.clear();
            self.model.assemble(x, Some(matrix), a);
        }
        let g = Vector3::from(self.dynamics.gravity);
        let alpha = self.dynamics.mass_damping;
        for (i, p) in x.iter().enumerate() {
            let m = self.masses[i];
            let mut force =
                m * (p - terms.predicted[i]) / (h * h) - m * g + alpha * m * (p - terms.start[i]) / h;
            if let Some(wind) = terms.wind.get(i) {
                force -= wind;
            }
            let diagonal = m / (h * h) + alpha * m / h;
            for k in 0..3 {
                a.gradient[3 * i + k] += force[k];
                a.matrix[self.pattern.diagonal_slot(3 * i + k)] += diagonal;
            }
        }
        let mut blocks: Vec<(usize, Matrix3<f64>)> = Vec::new();
        for c in obstacle_contacts(&self.obstacles, &self.contact, x) {
            for k in 0..3 {
                a.gradient[3 * c.vertex + k] -= c.force_n * c.normal[k];
            }
            blocks.push((c.vertex, self.contact.stiffness_n_m * c.normal * c.normal.transpose()));
        }
        if let Some(s) = &self.self_collision {
            s.forces(&s.pairs(x), &mut a.gradient, &mut blocks);
        }
        for (v, block) in blocks {
            for k in 0..3 {
                for l in 0..=k {
                    a.matrix[self.pattern.vertex_block_slot(v, k, l)] += block[(k, l)];
                }
            }
        }
        if !terms.stiffness_damping.is_empty() {
            self.add_damping(x, terms, a);
        }
    }

    /// `β K_n (x - x_n) / h` into the gradient and `β K_n / h` into the matrix.
    fn add_damping(&self, x: &[Vector3<f64>], terms: &StepTerms, a: &mut NewtonAssembly) {
        let h = self.dynamics.dt_s;
        let d = flatten_difference(x, &terms.start);
        for (g, kd) in a.gradient.iter_mut().zip(self.pattern.symmetric_product(&terms.stiffness_damping, &d))
        {
            *g += kd / h;
        }
        for (m, k) in a.matrix.iter_mut().zip(&terms.stiffness_damping) {
            *m += k / h;
        }
    }
}

fn flatten_difference(x: &[Vector3<f64>], y: &[Vector3<f64>]) -> Vec<f64> {
    x.iter().zip(y).flat_map(|(a, b)| (a - b).iter().copied().collect::<Vec<_>>()).collect()
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn motions_interpolate_their_keys() {
        let m = Motion { keys: vec![(0.0, [0.0; 3]), (0.4, [0.035, 0.0, 0.0])] };
        assert_eq!(m.translation(-1.0), Vector3::zeros());
        assert!((m.translation(0.2).x - 0.0175).abs() < 1e-15);
        assert!((m.translation(1.0).x - 0.035).abs() < 1e-15);
        assert_eq!(Motion::default().translation(3.0), Vector3::zeros());
    }
}
