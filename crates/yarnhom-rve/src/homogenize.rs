//! Homogenized energy density and stress of a tile at one macro strain (3.22-3.23).

use nalgebra::Vector3;
use rayon::prelude::*;
use yarnhom_geom::{MacroStrain, StrainError};

use yarnhom_artifacts::{RveSolve, StrainSample};

use crate::assembly::{ContactCandidates, RveState, Want, assemble, assemble_with, world_positions};
use crate::model::RveModel;
use crate::placement::Placement;
use crate::solve::{
    Iterate, SolveOptions, SolveReport, constraints, equilibrium_response, largest_vertex_move_m,
    multipliers, solve_observed, step_limit_m,
};

/// Central-difference steps of the solve-based stress: strain (dimensionless) and curvature (in
/// units of one over the tile's mean period, so that the step bends the tile by a similar amount).
const STRAIN_STEP: f64 = 1e-3;

/// The placement of the tile under `strain`.
pub fn placement(model: &RveModel, strain: &MacroStrain) -> Placement {
    let material: Vec<Vector3<f64>> = model.material.clone();
    Placement::new(material, model.period_m, strain)
}

/// Solve the tile at `strain`, from the affine start or warm-started from `start`.
pub fn solve_at(
    model: &RveModel,
    strain: &MacroStrain,
    start: Option<&RveState>,
    options: &SolveOptions,
) -> (SolveReport, RveState) {
    solve_at_observed(model, strain, start, options, &mut |_| {})
}

/// [`solve_at`], showing every Newton iterate to `observe` (see [`solve_observed`]).
pub fn solve_at_observed(
    model: &RveModel,
    strain: &MacroStrain,
    start: Option<&RveState>,
    options: &SolveOptions,
    observe: &mut dyn FnMut(&Iterate<'_>),
) -> (SolveReport, RveState) {
    let placement = placement(model, strain);
    let mut state = match start {
        Some(s) => {
            let mut s = s.clone();
            s.update_frames(model, &placement);
            s
        }
        None => RveState::affine(model, &placement),
    };
    let report = solve_observed(model, &placement, &mut state, options, observe);
    (report, state)
}

/// What [`solve_to_artifact`] computes besides the equilibrium.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Outputs {
    /// The stress at equilibrium (3.23c).
    pub stress: bool,
    /// Its check by finite differences of ten warm-started solves.
    pub fd_stress: bool,
}

/// Solves the tile at `strain` from the affine start, showing every Newton iterate to
/// `observe`, and reports it as an `rvesolve` artifact: the homogenized energy density (3.22)
/// and the `outputs` asked for where the solve converged, the equilibrium geometry, the solve's
/// statistics and wall time. `pattern` and `model` name the tile's pattern and yarn model.
pub fn solve_to_artifact(
    tile: &RveModel,
    [pattern, model]: [&str; 2],
    strain: &MacroStrain,
    options: &SolveOptions,
    outputs: Outputs,
    observe: &mut dyn FnMut(&Iterate<'_>),
) -> RveSolve {
    let started = std::time::Instant::now();
    let (report, state) = solve_at_observed(tile, strain, None, options, observe);
    let seconds = started.elapsed().as_secs_f64();
    let converged = report.converged;
    let [sx, sa, sy, kx, ky] = strain_vector(strain);
    RveSolve {
        pattern: pattern.into(),
        model: model.into(),
        strain: StrainSample { sx, sa, sy, kx, ky },
        converged,
        stop_reason: report.reason.as_str().into(),
        energy_density_j_m2: converged.then_some(report.energy_density_j_m2),
        stress: (converged && outputs.stress).then(|| stress_at_equilibrium(tile, strain, &state)),
        stress_fd: (converged && outputs.fd_stress)
            .then(|| stress_by_finite_differences(tile, strain, &state))
            .flatten(),
        iterations: report.iterations as u32,
        gradient_ratio: report.gradient_ratio,
        seconds,
        positions_m: world_positions(tile, &placement(tile, strain), &state),
        edge_twist_rad: (0..tile.vertices as u32).map(|v| state.g[tile.twist_dof(v)]).collect(),
    }
}

/// The start of a solve one step further along a sweep of strains: the secant predictor of a
/// continuation. From the equilibria `last` and `before` it came through, the fluctuations and
/// twists are extrapolated linearly to `strain`, `g = g_last + t (g_last - g_before)` with `t`
/// the projection of `strain - last` on `last - before` (the step ratio along a line of samples).
/// The extrapolation is shortened to the step limit of A.2.3, so it moves no vertex farther than
/// one Newton step could, and is kept only where it lowers the energy at `strain` below that of
/// the plain warm start from `last` (which is returned otherwise: after a snap-through the
/// secant points the wrong way). Along the sweeps of the sampler this leaves about one Newton
/// iteration per sample where a plain warm start needs two to four.
pub fn secant_start(
    model: &RveModel,
    strain: &MacroStrain,
    last: (&MacroStrain, &RveState),
    before: (&MacroStrain, &RveState),
) -> RveState {
    let placement = placement(model, strain);
    let mut warm = last.1.clone();
    warm.update_frames(model, &placement);
    let (target, a, b) = (strain_vector(strain), strain_vector(last.0), strain_vector(before.0));
    let secant: [f64; 5] = std::array::from_fn(|k| a[k] - b[k]);
    let length2: f64 = secant.iter().map(|d| d * d).sum();
    if length2 == 0.0 {
        return warm;
    }
    let t = (0..5).map(|k| (target[k] - a[k]) * secant[k]).sum::<f64>() / length2;
    let mut delta = (&last.1.g - &before.1.g) * t;
    let largest_move = largest_vertex_move_m(model, &delta);
    let limit = step_limit_m(model, &placement);
    if largest_move > limit {
        delta *= limit / largest_move;
    }
    let mut predicted = last.1.clone();
    predicted.g += delta;
    predicted.update_frames(model, &placement);
    // One broad phase for both starts: the prediction moves no vertex farther than `limit`.
    let candidates = ContactCandidates::new(model, &placement, &warm.g, limit);
    let energy = |s: &RveState| assemble_with(model, &placement, s, &s.g, Want::Energy, &candidates).energy_j;
    if energy(&predicted) < energy(&warm) { predicted } else { warm }
}

/// Strain steps of the embedding derivative in [`stress_at_equilibrium`]: no solve is repeated,
/// so the step only trades truncation against round-off of the energy.
const EMBEDDING_STEP: f64 = 1e-6;

/// Allowance of the contact candidates shared by the shifted placements of
/// [`stress_at_equilibrium`], in yarn radii (an embedding step moves the yarns by about
/// `10⁻⁶` of the tile's size).
const EMBEDDING_ALLOWANCE_RADII: f64 = 0.01;

/// Homogenized stress `dΨ/d(sx, sa, sy, kx, ky)` (3.23c) at the equilibrium `state` of `strain`,
/// from the forces the yarns exert at equilibrium, without another solve.
///
/// At equilibrium `∂E/∂g = Cᵀλ`, so the strain derivative of the equilibrium energy is the
/// derivative of the energy at fixed fluctuations `g` through the co-rotated embedding
/// `x̄(s) = φ(X) + h n(X) + R(X) g` (3.23c: `Σ ∂E/∂x · ∂x̄/∂s`, which interior equilibrium
/// reduces to the tile-boundary forces), minus the work of the constraint forces on the
/// strain-dependent sliding constraint (3.29): `dE/ds = ∂E/∂s|_g - λᵀ (∂C/∂s) g`. The
/// embedding derivative `∂x̄/∂s` is taken by central differences of the placement (pure
/// geometry, exact to `O(h²)`). Divided by the tile area (3.22).
pub fn stress_at_equilibrium(model: &RveModel, strain: &MacroStrain, state: &RveState) -> [f64; 5] {
    let here = placement(model, strain);
    let c = constraints(model, &here);
    let lambda = multipliers(&c, &assemble(model, &here, state, &state.g, Want::EnergyGradient).gradient);
    // The embedding steps move the yarns far less than this: one broad phase serves them all.
    let candidates =
        ContactCandidates::new(model, &here, &state.g, EMBEDDING_ALLOWANCE_RADII * model.radius_m);
    let base = strain_vector(strain);
    let mut stress = [0.0; 5];
    for (k, slot) in stress.iter_mut().enumerate() {
        let h = EMBEDDING_STEP * if k < 3 { 1.0 } else { curvature_unit(model) };
        let at = |sign: f64| {
            let mut s = base;
            s[k] += sign * h;
            let shifted = placement(model, &strain_from_vector(s).unwrap_or(*strain));
            let energy = if candidates.cover_placed(model, &shifted, &state.g) {
                assemble_with(model, &shifted, state, &state.g, Want::Energy, &candidates).energy_j
            } else {
                assemble(model, &shifted, state, &state.g, Want::Energy).energy_j
            };
            (energy, constraints(model, &shifted) * &state.g)
        };
        let ((e_plus, c_plus), (e_minus, c_minus)) = (at(1.0), at(-1.0));
        let constraint_work = lambda.dot(&(c_plus - c_minus));
        *slot = (e_plus - e_minus - constraint_work) / (2.0 * h) / model.area_m2();
    }
    stress
}

/// Sensitivities of the homogenized stress (3.23c) at the equilibrium `state` of `strain` to
/// the parameters of the energy: `perturbed[j]` is `model` with parameter `j` moved by `step`
/// (same tile and rest shape, another material law or contact). Returns `dσ/dp_j` for each.
///
/// The equilibrium moves with the parameter: the prediction `dg/dp_j = δ_j` comes from the
/// linearized equilibrium `H δ_j = -∂∇E/∂p_j` under the constraints ([`equilibrium_response`],
/// one factorization for every parameter, `∂∇E/∂p_j` by a forward difference of the gradient
/// at fixed `g`); a tight Newton correction from `g + step δ_j` then removes what the rods'
/// lagged-reference-twist Hessian misses (for stretch and contact parameters it converges at
/// once, for bending in a few iterations), and
/// `dσ/dp_j = (σ(p + step e_j, corrected) - σ(p, g)) / step` ([`stress_at_equilibrium`]).
/// The base state is first settled to the same tight tolerance, since a small step's stress
/// difference resolves the equilibrium far below the fits' tolerance (where round-off keeps a
/// solve from it, its last, lowest-energy iterate is used). `None` if the Hessian cannot be
/// factored.
pub fn stress_sensitivities(
    model: &RveModel,
    perturbed: &[RveModel],
    step: f64,
    strain: &MacroStrain,
    state: &RveState,
) -> Option<Vec<[f64; 5]>> {
    let here = placement(model, strain);
    // Stress differences over a small step resolve the equilibrium far below the fits'
    // tolerance: settle the base and each corrected prediction tightly.
    let tight = SolveOptions {
        tolerance: SENSITIVITY_TOLERANCE,
        max_iterations: 100,
        ..SolveOptions::warm_started()
    };
    // Where round-off keeps a solve from the tight tolerance, its last iterate is used: the
    // line search only accepts iterates of lower energy, so it is no worse than its start.
    let mut base = state.clone();
    solve_observed(model, &here, &mut base, &tight, &mut |_| {});
    let gradient = |m: &RveModel| assemble(m, &here, &base, &base.g, Want::EnergyGradient).gradient;
    let at_base = gradient(model);
    let forces: Vec<_> = perturbed.iter().map(|m| (gradient(m) - &at_base) / step).collect();
    let responses = equilibrium_response(model, &here, &base, &forces)?;
    let sigma = stress_at_equilibrium(model, strain, &base);
    let sensitivities = perturbed
        .par_iter()
        .zip(responses)
        .map(|(m, delta)| {
            let mut moved = base.clone();
            moved.g += delta * step;
            moved.update_frames(m, &here);
            // Correct the prediction: the rods' Hessian lags the reference twist (Bergou et
            // al. 2010), so the linear response is exact for stretch and contact but only
            // close for bending and twist.
            solve_observed(m, &here, &mut moved, &tight, &mut |_| {});
            let moved_sigma = stress_at_equilibrium(m, strain, &moved);
            std::array::from_fn(|k| (moved_sigma[k] - sigma[k]) / step)
        })
        .collect();
    Some(sensitivities)
}

/// Convergence tolerance (A.33) of the solves inside [`stress_sensitivities`].
const SENSITIVITY_TOLERANCE: f64 = 1e-9;

/// One over the tile's mean period (1/m): the curvature that bends the tile by about a radian,
/// the unit of curvature steps.
fn curvature_unit(model: &RveModel) -> f64 {
    2.0 / (model.period_m[0] + model.period_m[1])
}

/// `(sx, sa, sy, kx, ky)`.
pub fn strain_vector(strain: &MacroStrain) -> [f64; 5] {
    [strain.s.sx, strain.s.sa, strain.s.sy, strain.kx, strain.ky]
}

/// `dΨ/d(sx, sa, sy, kx, ky)` at `strain` by central differences of solves warm-started from the
/// equilibrium `state` (the check route of Sec. 3.2.2; the thesis used it for bending stress in
/// Ch. 6). `None` if any of the ten solves fails to converge.
pub fn stress_by_finite_differences(
    model: &RveModel,
    strain: &MacroStrain,
    state: &RveState,
) -> Option<[f64; 5]> {
    let curvature_step = STRAIN_STEP * curvature_unit(model);
    let base = strain_vector(strain);
    let options = SolveOptions::warm_started();
    let mut stress = [0.0; 5];
    for (k, slot) in stress.iter_mut().enumerate() {
        let h = if k < 3 { STRAIN_STEP } else { curvature_step };
        let mut energies = [0.0; 2];
        for (side, sign) in [1.0, -1.0].into_iter().enumerate() {
            let mut s = base;
            s[k] += sign * h;
            let shifted = strain_from_vector(s).ok()?;
            let (report, _) = solve_at(model, &shifted, Some(state), &options);
            energies[side] = if report.converged { report.energy_density_j_m2 } else { return None };
        }
        *slot = (energies[0] - energies[1]) / (2.0 * h);
    }
    Some(stress)
}

/// The macro strain `(sx, sa, sy, kx, ky)`, validated.
pub fn strain_from_vector(s: [f64; 5]) -> Result<MacroStrain, StrainError> {
    MacroStrain::new(s[0], s[1], s[2], s[3], s[4])
}
