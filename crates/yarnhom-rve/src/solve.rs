//! Elastostatic equilibrium of the tile (3.24): constrained Newton (3.32, A.2.3).
//!
//! - constraints `C g = d`, kept exactly from a feasible start: translation (3.19, the mean of
//!   the unrotated fluctuations is fixed), zero mean twist per yarn (3.28, the sum of edge twists
//!   is kept), and no sliding along the yarns: `Σ_i t_i · g_i = 0` per yarn, with `t_i` the
//!   yarn's unit tangents in the affinely deformed tile. This removes the sliding nullspace
//!   that (3.29) removes by pinning one vertex per yarn to the tile boundary; pinning a vertex
//!   breaks the tile's mirror symmetries (a mirrored yarn runs the other way, so the pinned
//!   vertex is not mirrored onto itself) and is a real constraint wherever rest shapes vary
//!   along the yarn, where sliding costs energy: the relaxed stockinette then slants and its
//!   shear response loses its symmetry. Periodicity (3.21, 3.26-3.27) holds by construction;
//! - each step solves the scaled, regularized system (A.30) `(M H M + α I) w = -M ∇E` under the
//!   constraints by the range-space method on one sparse Cholesky factorization, `δ = M w`, with
//!   `M = 1` for positions and `10⁶ r` for twists, and `α = α̂ ‖M ∇E‖∞` decaying `α̂` from 5000 to 5
//!   over 400 iterations; `α` grows tenfold whenever the factorization finds the matrix indefinite;
//! - steps are limited so that no vertex moves more than `p r`, `p = 0.05 + 0.15 clamp(λ_min(I))`,
//!   or, with [`StepControl::AdditiveCcd`], cut by additive continuous collision detection, then
//!   shortened tenfold until the energy decreases (A.2.3);
//! - convergence when the gradient projected on the constraints' tangent space falls below
//!   `ε_z = 1e-5` of its value at the affine start (A.31-A.33; measured against the affine start
//!   rather than the first iterate, so that a warm start is held to the same absolute accuracy,
//!   and at least against the forces of a 0.1% stretch of every edge) and the constraints
//!   hold to `ε_L r` (A.2.3).

use nalgebra::{DMatrix, DVector, Vector2, Vector3};

use crate::assembly::{Assembled, ContactCandidates, RveState, Want, assemble, assemble_with};
use crate::ccd::max_collision_free_step;
use crate::model::RveModel;
use crate::placement::Placement;
use yarnhom_sparse::SpdSolver;

/// `ε_L` of App. A.2.3: constraints hold to this fraction of the yarn radius at convergence.
const CONSTRAINT_TOLERANCE: f64 = 1e-4;

/// Solver settings (defaults: App. A.2.3).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolveOptions {
    /// Iteration limit.
    pub max_iterations: usize,
    /// `ε_z` of (A.33).
    pub tolerance: f64,
    /// `α̂_0` and `α̂_N` of the regularization schedule (A.30).
    pub regularization: (f64, f64),
    /// `N` of the regularization schedule.
    pub regularization_iterations: usize,
    /// How a Newton step is kept from tunnelling yarns through each other.
    pub step_control: StepControl,
    /// `μ` of a proximal anchor at the start (N/m; 0: none). The solve then finds the minimum
    /// of `E(g) + μ/2 ‖M⁻¹(g - g₀)‖²` instead of `E`: one implicit step of the energy's
    /// gradient flow from the start `g₀`, in the scaled coordinates of (A.30), so `μ` adds to
    /// the scaled Hessian's diagonal. For `μ` above the most negative curvature of `E` that
    /// minimum is unique and moves continuously with the tile's parameters (the rest-shape
    /// estimation's resets, [`crate::relax()`]).
    pub proximal_weight: f64,
}

/// Collision-safe steps (A.2.3).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum StepControl {
    /// No vertex moves more than `p r` per step, `p = 0.05 + 0.15 clamp(λ_min(I), 0, 1)`.
    StepLimit,
    /// Additive continuous collision detection (Li et al. 2021; [`crate::ccd`]): the step is cut
    /// where two yarn centrelines would come closer than `min_separation_radii` yarn radii.
    AdditiveCcd {
        /// Smallest centreline distance a step may reach, in yarn radii.
        min_separation_radii: f64,
    },
}

impl Default for SolveOptions {
    fn default() -> Self {
        SolveOptions {
            max_iterations: 2000,
            tolerance: 1e-5,
            regularization: (5000.0, 5.0),
            regularization_iterations: 400,
            step_control: StepControl::StepLimit,
            proximal_weight: 0.0,
        }
    }
}

impl SolveOptions {
    /// Settings for a warm start from a nearby solved state: the strong early regularization
    /// exists to resolve the collisions of the affine start (A.2.3), which a warm start does not
    /// have, so it starts at the schedule's end.
    pub fn warm_started() -> Self {
        let cold = SolveOptions::default();
        SolveOptions { regularization: (cold.regularization.1, cold.regularization.1), ..cold }
    }
}

/// Why a solve stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StopReason {
    /// (A.33) holds.
    Converged,
    /// The iteration limit was reached first.
    IterationLimit,
    /// No step length decreased the energy.
    LineSearchFailed,
    /// The regularized system stayed indefinite.
    FactorizationFailed,
}

impl StopReason {
    /// The reason as artifacts and traces write it (`converged`, `iteration_limit`, ...).
    pub fn as_str(self) -> &'static str {
        match self {
            StopReason::Converged => "converged",
            StopReason::IterationLimit => "iteration_limit",
            StopReason::LineSearchFailed => "line_search_failed",
            StopReason::FactorizationFailed => "factorization_failed",
        }
    }
}

/// What a solve did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolveReport {
    /// Whether the equilibrium was found.
    pub converged: bool,
    /// Why it stopped.
    pub reason: StopReason,
    /// Newton iterations taken.
    pub iterations: usize,
    /// Tile energy at the end (J).
    pub energy_j: f64,
    /// Homogenized energy density (3.22): energy per undeformed tile area (J/m²).
    pub energy_density_j_m2: f64,
    /// Final projected gradient over its first value (A.33).
    pub gradient_ratio: f64,
    /// Largest constraint violation at the end.
    pub constraint_residual: f64,
    /// Symbolic factorizations computed (the rest reused the analysis).
    pub symbolic_analyses: usize,
}

/// The constraint rows `C` (dense, few) of the tile under `placement`.
pub(crate) fn constraints(model: &RveModel, placement: &Placement) -> DMatrix<f64> {
    let n = model.dof_count();
    let m = 3 + 2 * model.yarns.len();
    let mut c = DMatrix::zeros(m, n);
    for v in 0..model.vertices as u32 {
        for k in 0..3 {
            c[(k, model.position_dof(v) + k)] = 1.0;
        }
    }
    let stretch = placement.in_plane_stretch();
    for (y, yarn) in model.yarns.iter().enumerate() {
        for &v in &yarn.vertices {
            c[(3 + 2 * y, model.twist_dof(v))] = 1.0;
        }
        for &v in &yarn.vertices {
            let t = model.material_tangents[v as usize];
            let deformed = (stretch * Vector2::new(t.x, t.y) + Vector3::z() * t.z).normalize();
            for k in 0..3 {
                c[(4 + 2 * y, model.position_dof(v) + k)] = deformed[k];
            }
        }
    }
    c
}

/// `(C Cᵀ)⁻¹ rhs` (zero if the constraints were dependent).
fn gram_solve(c: &DMatrix<f64>, rhs: &DVector<f64>) -> DVector<f64> {
    (c * c.transpose()).lu().solve(rhs).unwrap_or_else(|| DVector::zeros(c.nrows()))
}

/// The least-squares constraint multipliers `λ` of `∇E ≈ Cᵀλ`: the constraint forces.
pub(crate) fn multipliers(c: &DMatrix<f64>, gradient: &DVector<f64>) -> DVector<f64> {
    gram_solve(c, &(c * gradient))
}

/// Gradient projected onto the tangent space of `C g = d` (A.31-A.32).
pub(crate) fn projected(c: &DMatrix<f64>, gradient: &DVector<f64>) -> DVector<f64> {
    gradient - c.transpose() * multipliers(c, gradient)
}

/// One Newton iterate of a tile solve, as handed to the observer of [`solve_observed`].
#[derive(Debug, Clone, Copy)]
pub struct Iterate<'a> {
    /// Iteration number, from 0.
    pub iteration: usize,
    /// Tile energy at the iterate (J).
    pub energy_j: f64,
    /// Projected gradient over its reference (A.33).
    pub gradient_ratio: f64,
    /// Fraction of the Newton step taken from this iterate (0 where the solve stopped).
    pub step_length: f64,
    /// The iterate.
    pub state: &'a RveState,
}

/// Find the tile's equilibrium from `state` (warm or affine start), updating it in place.
pub fn solve(
    model: &RveModel,
    placement: &Placement,
    state: &mut RveState,
    options: &SolveOptions,
) -> SolveReport {
    solve_observed(model, placement, state, options, &mut |_| {})
}

/// [`solve`], showing every iterate to `observe`: once per Newton iteration with the step
/// length taken from it, and once more for the iterate where the solve stopped.
pub fn solve_observed(
    model: &RveModel,
    placement: &Placement,
    state: &mut RveState,
    options: &SolveOptions,
    observe: &mut dyn FnMut(&Iterate<'_>),
) -> SolveReport {
    let n = model.dof_count();
    let r = model.radius_m;
    let c = constraints(model, placement);
    let affine = RveState::affine(model, placement);
    // The constraint values are those of the affine start (zero mean fluctuation, the pattern's
    // total twist, no mean sliding), also for a warm start, whose sliding was measured along
    // another strain's tangents: move it onto these constraints first (the least-norm
    // correction); Newton steps then keep them exactly.
    let target = &c * &affine.g;
    let violation = &c * &state.g - &target;
    if violation.amax() > 0.0 {
        state.g -= c.transpose() * gram_solve(&c, &violation);
        state.update_frames(model, placement);
    }
    let scale = DVector::from_fn(n, |i, _| if i < 3 * model.vertices { 1.0 } else { 1e6 * r });
    let c_scaled = &c * DMatrix::from_diagonal(&scale);
    let largest_step_m = step_limit_m(model, placement);
    let mut solver = SpdSolver::default();
    let residual = |gradient: &DVector<f64>| projected(&c, gradient).norm();
    let first = residual(&assemble(model, placement, &affine, &affine.g, Want::EnergyGradient).gradient)
        .max(force_floor(model));
    let anchor =
        (options.proximal_weight > 0.0).then(|| Anchor::new(options.proximal_weight, &state.g, &scale));
    let mut assembler = Assembler { model, placement, candidates: None, anchor };
    let mut current = assembler.assemble(state, &state.g, Want::DerivativesLower);
    let (reason, iterations) = 'solve: {
        for iteration in 0..options.max_iterations {
            let ratio = residual(&current.gradient) / first;
            let feasible = (&c * &state.g - &target).amax() < CONSTRAINT_TOLERANCE * r;
            if ratio < options.tolerance && feasible {
                break 'solve (StopReason::Converged, iteration);
            }
            let (a0, an) = options.regularization;
            let t = iteration.min(options.regularization_iterations) as f64
                / options.regularization_iterations as f64;
            let scaled_gradient = current.gradient.component_mul(&scale);
            let alpha = a0 * (an / a0).powf(t) * scaled_gradient.amax();
            scale_hessian(&mut current.hessian, &scale);
            let shift = alpha + options.proximal_weight;
            if !(solver.load(n, &current.hessian).is_ok() && factor_regularized(&mut solver, shift)) {
                break 'solve (StopReason::FactorizationFailed, iteration);
            }
            let step = constrained_step(&solver, &c_scaled, &scaled_gradient, &(&c * &state.g - &target))
                .component_mul(&scale);
            let mut length = match options.step_control {
                StepControl::StepLimit => {
                    let largest_move = largest_vertex_move_m(model, &step);
                    if largest_move > largest_step_m { largest_step_m / largest_move } else { 1.0 }
                }
                StepControl::AdditiveCcd { min_separation_radii } => {
                    max_collision_free_step(model, placement, state, &step, min_separation_radii * r)
                }
            };
            let mut accepted = None;
            for _ in 0..12 {
                let trial = &state.g + &step * length;
                let e = assembler.assemble(state, &trial, Want::Energy).energy_j;
                if e < current.energy_j {
                    accepted = Some(trial);
                    break;
                }
                length *= 0.1;
            }
            let Some(trial) = accepted else {
                break 'solve (StopReason::LineSearchFailed, iteration);
            };
            let energy_j = current.energy_j;
            observe(&Iterate { iteration, energy_j, gradient_ratio: ratio, step_length: length, state });
            state.g = trial;
            state.update_frames(model, placement);
            current = assembler.assemble(state, &state.g, Want::DerivativesLower);
        }
        (StopReason::IterationLimit, options.max_iterations)
    };
    let ratio = residual(&current.gradient) / first;
    let energy_j = current.energy_j - assembler.anchor.as_ref().map_or(0.0, |a| a.energy_j(&state.g));
    observe(&Iterate { iteration: iterations, energy_j, gradient_ratio: ratio, step_length: 0.0, state });
    SolveReport {
        converged: reason == StopReason::Converged,
        reason,
        iterations,
        energy_j,
        energy_density_j_m2: energy_j / model.area_m2(),
        gradient_ratio: ratio,
        constraint_residual: (&c * &state.g - &target).amax(),
        symbolic_analyses: solver.symbolic_analyses,
    }
}

/// The step limit of A.2.3: the largest distance a vertex may move in one Newton step,
/// `p r` with `p = 0.05 + 0.15 λ_min` (`λ_min` the smallest eigenvalue of the macro strain's
/// first fundamental form, clamped to `[0, 1]`), so that a step cannot carry a yarn through
/// another.
pub(crate) fn step_limit_m(model: &RveModel, placement: &Placement) -> f64 {
    let p = 0.05 + 0.15 * placement.smallest_stretch_eigenvalue().clamp(0.0, 1.0);
    p * model.radius_m
}

/// The largest distance a change `delta` of the DOFs moves a vertex (its twists aside).
pub(crate) fn largest_vertex_move_m(model: &RveModel, delta: &DVector<f64>) -> f64 {
    (0..model.vertices).map(|v| delta.fixed_rows::<3>(3 * v).norm()).fold(0.0, f64::max)
}

/// Allowance of the contact candidates of a solve, in yarn radii: the broad phase is rerun
/// once some vertex has moved this far from where it last ran (a few step-limited iterations).
const CANDIDATE_ALLOWANCE_RADII: f64 = 0.5;

/// The assembly of one solve's iterates under its placement, reusing the contact candidates
/// ([`ContactCandidates`]) while they cover the iterate, with the proximal anchor's energy and
/// gradient added where the solve has one.
struct Assembler<'a> {
    model: &'a RveModel,
    placement: &'a Placement,
    candidates: Option<ContactCandidates>,
    anchor: Option<Anchor>,
}

impl Assembler<'_> {
    /// [`assemble`] at DOFs `g`, measured against `state`'s frames, plus the anchor's terms
    /// (its Hessian `μ M⁻²` is added as a shift of the scaled system).
    fn assemble(&mut self, state: &RveState, g: &DVector<f64>, want: Want) -> Assembled {
        let (model, placement) = (self.model, self.placement);
        let candidates = match self.candidates.take() {
            Some(c) if c.cover(model, g) => c,
            _ => ContactCandidates::new(model, placement, g, CANDIDATE_ALLOWANCE_RADII * model.radius_m),
        };
        let mut assembled = assemble_with(model, placement, state, g, want, &candidates);
        self.candidates = Some(candidates);
        if let Some(anchor) = &self.anchor {
            assembled.energy_j += anchor.energy_j(g);
            if want != Want::Energy {
                anchor.add_gradient(g, &mut assembled.gradient);
            }
        }
        assembled
    }
}

/// The proximal term `μ/2 ‖M⁻¹(g - g₀)‖²` of [`SolveOptions::proximal_weight`].
struct Anchor {
    /// `μ` (N/m).
    weight: f64,
    /// `g₀`.
    at: DVector<f64>,
    /// The diagonal of `M⁻²`.
    inverse_square_scale: DVector<f64>,
}

impl Anchor {
    fn new(weight: f64, at: &DVector<f64>, scale: &DVector<f64>) -> Self {
        Anchor { weight, at: at.clone(), inverse_square_scale: scale.map(|s| 1.0 / (s * s)) }
    }

    fn energy_j(&self, g: &DVector<f64>) -> f64 {
        let d = g - &self.at;
        0.5 * self.weight * d.component_mul(&d).dot(&self.inverse_square_scale)
    }

    /// Add the anchor's gradient `μ M⁻²(g - g₀)` to `gradient` in place.
    fn add_gradient(&self, g: &DVector<f64>, gradient: &mut DVector<f64>) {
        for (i, out) in gradient.iter_mut().enumerate() {
            *out += (g[i] - self.at[i]) * self.inverse_square_scale[i] * self.weight;
        }
    }
}

/// Factor the loaded `M H M + α I`, growing `α` tenfold while the matrix is indefinite (30
/// times at most); whether it was factored.
fn factor_regularized(solver: &mut SpdSolver, mut alpha: f64) -> bool {
    for _ in 0..30 {
        if solver.factor_shifted(alpha).is_ok() {
            return true;
        }
        alpha = (alpha * 10.0).max(1e-12);
    }
    false
}

/// Scale the Hessian triplets to `M H M` for the diagonal `M` of `scale`.
fn scale_hessian(hessian: &mut [(usize, usize, f64)], scale: &DVector<f64>) {
    for (i, j, v) in hessian.iter_mut() {
        *v = *v * scale[*i] * scale[*j];
    }
}

/// The smallest reference of (A.33): the force norm of a 0.1% stretch of every edge. A tile
/// whose affine start is already (nearly) in equilibrium, like a relaxed pattern at zero strain,
/// is held to this absolute accuracy instead of a fraction of its own vanishing first gradient.
fn force_floor(model: &RveModel) -> f64 {
    model.material_law.stretch.density(1e-3).1 * (model.vertices as f64).sqrt()
}

/// The proximal weight `μ` ([`SolveOptions::proximal_weight`]) whose step from `state` moves no
/// scaled coordinate by more than `step_radii` yarn radii where the energy has no curvature:
/// `μ = max(‖M ∇E‖∞, F₀) / (step_radii r)`, `F₀` the force floor of (A.33) ([`force_floor`]),
/// so that a tile nearly in equilibrium is still anchored. A continuous function of the state
/// and of the yarn's parameters.
pub(crate) fn proximal_weight(
    model: &RveModel,
    placement: &Placement,
    state: &RveState,
    step_radii: f64,
) -> f64 {
    let r = model.radius_m;
    let gradient = assemble(model, placement, state, &state.g, Want::EnergyGradient).gradient;
    let largest = (0..gradient.len())
        .map(|i| gradient[i].abs() * if i < 3 * model.vertices { 1.0 } else { 1e6 * r })
        .fold(0.0, f64::max);
    largest.max(force_floor(model)) / (step_radii * r)
}

/// Relative diagonal shift of the Hessian in [`equilibrium_response`]: enough to factor a
/// Hessian whose only soft directions are the ones the constraints remove, too little to bias
/// the response (a millionth of its largest diagonal).
const RESPONSE_SHIFT: f64 = 1e-6;

/// The linear response of the equilibrium `state` under `placement` to perturbations of the
/// forces: for each `b` in `forces` the `δ` of `H δ + Cᵀ μ = -b`, `C δ = 0` (the linearized
/// (3.24) under the constraints, `H` the energy Hessian the Newton solver assembles), all on
/// one factorization. With `b = ∂∇E/∂p` this is `dg/dp`, the equilibrium's sensitivity to a
/// parameter `p` of the energy. `None` if the Hessian cannot be factored.
pub fn equilibrium_response(
    model: &RveModel,
    placement: &Placement,
    state: &RveState,
    forces: &[DVector<f64>],
) -> Option<Vec<DVector<f64>>> {
    let n = model.dof_count();
    let c = constraints(model, placement);
    let scale = DVector::from_fn(n, |i, _| if i < 3 * model.vertices { 1.0 } else { 1e6 * model.radius_m });
    let c_scaled = &c * DMatrix::from_diagonal(&scale);
    let mut scaled_hessian = assemble(model, placement, state, &state.g, Want::DerivativesLower).hessian;
    scale_hessian(&mut scaled_hessian, &scale);
    let largest =
        scaled_hessian.iter().filter(|(i, j, _)| i == j).map(|(_, _, v)| v.abs()).fold(0.0, f64::max);
    let mut solver = SpdSolver::default();
    solver.load(n, &scaled_hessian).ok()?;
    let mut shift = RESPONSE_SHIFT * largest.max(1e-300);
    while solver.factor_shifted(shift).is_err() {
        shift *= 10.0;
        if shift > largest {
            return None;
        }
    }
    let feasible = DVector::zeros(c.nrows());
    Some(
        forces
            .iter()
            .map(|b| {
                constrained_step(&solver, &c_scaled, &b.component_mul(&scale), &feasible)
                    .component_mul(&scale)
            })
            .collect(),
    )
}

/// The step of the regularized, constrained Newton system by the range-space method:
/// `K w = -∇`, `K Y = Cᵀ`, `λ = (C Y)⁻¹ (C w + residual)`, step `w - Y λ` (so `C step = -residual`).
fn constrained_step(
    solver: &SpdSolver,
    c: &DMatrix<f64>,
    gradient: &DVector<f64>,
    residual: &DVector<f64>,
) -> DVector<f64> {
    let n = gradient.len();
    let mut w: Vec<f64> = gradient.iter().map(|x| -x).collect();
    solver.solve_in_place(&mut w, 1);
    let w = DVector::from_vec(w);
    let mut y: Vec<f64> = c.transpose().as_slice().to_vec();
    solver.solve_in_place(&mut y, c.nrows());
    let y = DMatrix::from_vec(n, c.nrows(), y);
    let lambda = (c * &y).lu().solve(&(c * &w + residual)).unwrap_or_else(|| DVector::zeros(c.nrows()));
    w - y * lambda
}
