//! Rest states of yarn patterns: the reference-configuration heuristic of Algorithm 2
//! (App. A.2.4, used for Ch. 3-5) and the rest-shape estimation of Sec. 6.5.2 (Ch. 6).
//!
//! Both alternate equilibrium solves at zero macro strain with *rest-shape resets*: rest lengths,
//! rest curvatures and rest twists are set to their values in the current configuration, so the
//! rods are at rest and only contact forces remain; the next solve lets those push the yarns
//! apart. Algorithm 2 repeats this until the relaxed tile has (almost) no energy left (a
//! stress-free state), then pre-tensions the yarns (knits: rest lengths x0.9, rest curvatures
//! x0.8; wovens: rest curvatures x0.9) and finally shrinks or grows the periods to the in-plane
//! energy minimum, so that the relaxed tile carries no in-plane stress at zero strain but keeps
//! its tendency to curl. Sec. 6.5.2 instead bounds the change of every rest length to 20% of its
//! input value and moves the yarns little per reset, so the estimated rest state stays close to
//! the input geometry and keeps a balanced pre-tension. Where the thesis cuts the early resets'
//! solves after a few Newton steps, each reset here is one implicit step of the tile's gradient
//! flow (a proximal solve with a unique minimum), so the estimate, and the yarn-level objective
//! (6.11) built on it, is a continuous function of the yarn's parameters.

use nalgebra::{Matrix2, Vector2};
use yarnhom_artifacts::{Fabric, Pattern, RestState, YarnModel};
use yarnhom_geom::MacroStrain;
use yarnhom_rod::EdgeFrame;

use crate::assembly::{RveState, bend_strains, edge_lengths, world_positions};
use crate::homogenize::{placement, solve_at, stress_at_equilibrium};
use crate::model::{RveError, RveModel};
use crate::solve::{SolveOptions, SolveReport, StopReason, largest_vertex_move_m, proximal_weight, solve};

/// Which rest-state procedure to run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RelaxMethod {
    /// Algorithm 2 (App. A.2.4): stress-free state, pre-tension, in-plane energy minimum.
    Reference,
    /// Sec. 6.5.2: rest-shape resets with every rest length kept within `max_length_change`
    /// (relative) of its input value; few iterations per early reset.
    Estimation {
        /// Bound on the relative change of rest lengths (the thesis uses 0.2).
        max_length_change: f64,
    },
}

/// Settings of a relaxation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RelaxOptions {
    /// The procedure.
    pub method: RelaxMethod,
    /// Stop resetting once a relaxed tile holds less than this energy (J); Algorithm 2: `1e-10`.
    pub stress_free_energy_j: f64,
    /// Largest number of rest-shape resets.
    pub max_resets: usize,
    /// Keep the input's rest shape and only find the in-plane minimum (Algorithm 2's last stage),
    /// for patterns that already carry a rest state relaxed elsewhere (e.g. the published ones).
    pub keep_rest_shape: bool,
    /// Equilibrium solves.
    pub solve: SolveOptions,
}

impl Default for RelaxOptions {
    fn default() -> Self {
        RelaxOptions {
            method: RelaxMethod::Reference,
            stress_free_energy_j: 1e-10,
            max_resets: 40,
            keep_rest_shape: false,
            solve: SolveOptions::default(),
        }
    }
}

/// Why a relaxation failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RelaxError {
    /// The tile could not be built.
    #[error(transparent)]
    Tile(#[from] RveError),
    /// An equilibrium solve failed.
    #[error("{stage}: the equilibrium solve did not converge ({reason:?} after {iterations} iterations)")]
    NotConverged {
        /// Which stage.
        stage: &'static str,
        /// Why the solve stopped.
        reason: StopReason,
        /// Iterations taken.
        iterations: usize,
    },
    /// The in-plane minimum was not found.
    #[error("the in-plane energy minimum was not found within {0} steps")]
    NoInPlaneMinimum(usize),
}

/// What a relaxation did.
#[derive(Debug, Clone, PartialEq)]
pub struct RelaxReport {
    /// Rest-shape resets performed.
    pub resets: usize,
    /// Energy of the tile after the last reset's solve (J): below
    /// [`RelaxOptions::stress_free_energy_j`] when a stress-free state was reached.
    pub stress_free_energy_j: f64,
    /// In-plane strain `(sx, sy)` applied to the periods in all (Algorithm 2, line 14).
    pub period_strain: [f64; 2],
    /// Homogenized in-plane stress `dΨ/d(sx, sa, sy)` (J/m²) of the result at zero strain.
    pub residual_stress_j_m2: [f64; 3],
    /// Newton iterations over all solves.
    pub iterations: usize,
}

impl RelaxReport {
    /// What `yarnhom rve relax` prints of the relaxation that made `relaxed` in `seconds`.
    pub fn summary(&self, relaxed: &Pattern, seconds: f64) -> String {
        let [sx, sa, sy] = self.residual_stress_j_m2;
        format!(
            "relaxed '{}': {} resets, periods {:.4} x {:.4} mm (period strain {:+.4}, {:+.4}), {} Newton \
             iterations, {seconds:.1} s\n  in-plane stress at zero strain: dsx {sx:.3e}, dsa {sa:.3e}, dsy {sy:.3e} J/m²",
            relaxed.name,
            self.resets,
            relaxed.period_m[0] * 1e3,
            relaxed.period_m[1] * 1e3,
            self.period_strain[0],
            self.period_strain[1],
            self.iterations,
        )
    }
}

/// Progress of a relaxation, for a caller's progress display.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RelaxEvent {
    /// A rest-shape reset finished: its index and the relaxed tile's energy (J).
    Reset(usize, f64),
    /// A step of the in-plane minimization: the period strain and the in-plane stress there.
    PeriodStep([f64; 2], [f64; 2]),
}

impl std::fmt::Display for RelaxEvent {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            RelaxEvent::Reset(k, energy) => {
                write!(f, "reset {:>3}: relaxed tile energy {energy:.3e} J", k + 1)
            }
            RelaxEvent::PeriodStep(s, sigma) => write!(
                f,
                "periods: sx {:+.5} sy {:+.5}, stress {:+.3e} {:+.3e} J/m²",
                s[0], s[1], sigma[0], sigma[1]
            ),
        }
    }
}

/// The rest state of `pattern` for `yarn`, computed with `options`; `progress` sees each stage.
pub fn relax(
    pattern: &Pattern,
    yarn: &YarnModel,
    options: &RelaxOptions,
    progress: &mut dyn FnMut(RelaxEvent),
) -> Result<(Pattern, RelaxReport), RelaxError> {
    let mut report = RelaxReport {
        resets: 0,
        stress_free_energy_j: f64::NAN,
        period_strain: [0.0; 2],
        residual_stress_j_m2: [0.0; 3],
        iterations: 0,
    };
    let mut current = match (&pattern.rest, options.keep_rest_shape) {
        (Some(_), true) => pattern.clone(),
        _ => at_rest(pattern, yarn, None)?,
    };
    if !options.keep_rest_shape {
        let input_lengths = current.rest.as_ref().map(|r| r.edge_length_m.clone()).unwrap_or_default();
        for reset in 0..options.max_resets {
            let tile = RveModel::new(&current, yarn)?;
            let solve_options = reset_solve_options(options, &tile);
            let (solved, state) = solve_at(&tile, &zero_strain(), None, &solve_options);
            report.iterations += solved.iterations;
            if !solved.converged && solved.reason != StopReason::IterationLimit {
                return Err(not_converged("stress-free state", &solved));
            }
            current = configured(&current, &tile, &zero_strain(), &state);
            let bound = match options.method {
                RelaxMethod::Estimation { max_length_change } => {
                    Some((&input_lengths[..], max_length_change))
                }
                RelaxMethod::Reference => None,
            };
            current = at_rest(&current, yarn, bound)?;
            report.resets = reset + 1;
            report.stress_free_energy_j = solved.energy_j;
            progress(RelaxEvent::Reset(reset, solved.energy_j));
            if solved.converged && solved.energy_j < options.stress_free_energy_j {
                break;
            }
        }
    }
    if options.method == RelaxMethod::Reference {
        if !options.keep_rest_shape {
            pre_tension(&mut current);
        }
        // Moving the pattern to the minimum changes the tangents of the sliding constraint,
        // whose force then shifts the equilibrium a little: repeat until the moved pattern is
        // itself at the minimum.
        let mut total = [1.0, 1.0];
        for _ in 0..MAX_PERIOD_ROUNDS {
            let (strain, iterations) = in_plane_minimum(&mut current, yarn, options, progress)?;
            report.iterations += iterations;
            total = [total[0] * (1.0 + strain[0]), total[1] * (1.0 + strain[1])];
            if strain == [0.0, 0.0] {
                break;
            }
        }
        report.period_strain = [total[0] - 1.0, total[1] - 1.0];
    } else {
        let tile = RveModel::new(&current, yarn)?;
        let (solved, state) = flow_to_equilibrium(&tile, options)?;
        report.iterations += solved.iterations;
        current = configured(&current, &tile, &zero_strain(), &state);
    }
    centre(&mut current);
    let tile = RveModel::new(&current, yarn)?;
    let (solved, state) = solve_at(&tile, &zero_strain(), None, &options.solve);
    report.iterations += solved.iterations;
    if !solved.converged {
        return Err(not_converged("final check", &solved));
    }
    let stress = stress_at_equilibrium(&tile, &zero_strain(), &state);
    report.residual_stress_j_m2 = [stress[0], stress[1], stress[2]];
    current.origin = format!("{} | relaxed ({})", current.origin, method_name(options));
    Ok((current, report))
}

fn method_name(options: &RelaxOptions) -> String {
    match (options.method, options.keep_rest_shape) {
        (RelaxMethod::Reference, false) => "Algorithm 2".into(),
        (RelaxMethod::Reference, true) => "Algorithm 2, in-plane minimum only".into(),
        (RelaxMethod::Estimation { max_length_change }, _) => {
            format!("Sec. 6.5.2, rest lengths within {:.0}%", 100.0 * max_length_change)
        }
    }
}

fn zero_strain() -> MacroStrain {
    MacroStrain::new(0.0, 0.0, 0.0, 0.0, 0.0).expect("zero strain is valid")
}

fn not_converged(stage: &'static str, solved: &SolveReport) -> RelaxError {
    RelaxError::NotConverged { stage, reason: solved.reason, iterations: solved.iterations }
}

/// How far one reset of the estimation moves the yarns where nothing resists, in yarn radii.
const REST_FLOW_STEP_RADII: f64 = 0.25;

/// The solve of one rest-shape reset. Algorithm 2 relaxes fully every time. Sec. 6.5.2 runs
/// "only a few simulation steps" per early reset, then "toward convergence"; a solve cut off
/// after a few Newton steps, or run to convergence on a tile whose rods were just put at rest
/// (where contact alone drives the yarns through a nearly flat landscape), ends wherever its
/// step decisions lead, and round-off then picks among equilibria (a relative change of 1e-13
/// in one yarn parameter moved (6.11) by 25%). Instead each reset is one implicit step of the
/// tile's gradient flow: the solve converges to the unique minimum of the energy plus a
/// proximal anchor at the reset's start ([`SolveOptions::proximal_weight`]), sized so that no
/// yarn moves more than [`REST_FLOW_STEP_RADII`] radii where nothing resists. Each reset is
/// then a continuous map of the parameters, and so is the estimation.
fn reset_solve_options(options: &RelaxOptions, tile: &RveModel) -> SolveOptions {
    match options.method {
        RelaxMethod::Reference => options.solve,
        RelaxMethod::Estimation { .. } => {
            let place = placement(tile, &zero_strain());
            let start = RveState::affine(tile, &place);
            let weight = proximal_weight(tile, &place, &start, REST_FLOW_STEP_RADII);
            // The anchor, not the cold regularization schedule, keeps the first steps short.
            let regularization = SolveOptions::warm_started().regularization;
            SolveOptions { proximal_weight: weight, regularization, ..options.solve }
        }
    }
}

/// Implicit gradient-flow steps of the estimation's last equilibrium at most.
const MAX_FLOW_STEPS: usize = 400;
/// The flow has settled once a step moves no vertex farther than this, in yarn radii; a plain
/// Newton solve then finishes from there.
const FLOW_SETTLED_RADII: f64 = 1e-3;

/// The estimation's last equilibrium, where the rods take the pre-tension that balances the
/// contacts, as the end of the tile's implicit gradient flow from the last reset (the rule that
/// picks among its equilibria): proximal steps as in the resets until a step moves no vertex
/// farther than [`FLOW_SETTLED_RADII`] radii, then a warm Newton solve. A cold solve from the
/// reset crawls for hundreds of iterations under its regularization schedule through the nearly
/// flat landscape of a tile whose rods were just put at rest, and ends where its step decisions
/// lead. On slack tiles the final Newton solve can still crawl (docs/validation.md).
fn flow_to_equilibrium(
    tile: &RveModel,
    options: &RelaxOptions,
) -> Result<(SolveReport, RveState), RelaxError> {
    let place = placement(tile, &zero_strain());
    let mut state = RveState::affine(tile, &place);
    let warm = SolveOptions { regularization: SolveOptions::warm_started().regularization, ..options.solve };
    let mut iterations = 0;
    for _ in 0..MAX_FLOW_STEPS {
        let before = state.g.clone();
        let weight = proximal_weight(tile, &place, &state, REST_FLOW_STEP_RADII);
        let step = solve(tile, &place, &mut state, &SolveOptions { proximal_weight: weight, ..warm });
        iterations += step.iterations;
        if !step.converged {
            return Err(not_converged("rest-shape estimation (gradient flow)", &step));
        }
        if largest_vertex_move_m(tile, &(&state.g - before)) < FLOW_SETTLED_RADII * tile.radius_m {
            break;
        }
    }
    let mut solved = solve(tile, &place, &mut state, &warm);
    solved.iterations += iterations;
    if !solved.converged {
        return Err(not_converged("rest-shape estimation", &solved));
    }
    Ok((solved, state))
}

/// `pattern` moved to the tile's configuration `state` under the flat in-plane `strain`: the
/// deformed positions become the new material positions (`R = 1`, `n = e3` for a flat strain),
/// the periods stretch with the strain, and edge twists and reference frames are the state's.
/// The rest lengths, curvatures and twists are kept.
fn configured(pattern: &Pattern, tile: &RveModel, strain: &MacroStrain, state: &RveState) -> Pattern {
    let place = placement(tile, strain);
    let mut out = pattern.clone();
    out.positions_m = world_positions(tile, &place, state);
    out.period_m = [pattern.period_m[0] * (1.0 + strain.s.sx), pattern.period_m[1] * (1.0 + strain.s.sy)];
    out.edge_twist_rad = (0..tile.vertices as u32).map(|v| state.g[tile.twist_dof(v)]).collect();
    if let Some(rest) = out.rest.as_mut() {
        rest.edge_reference_director = state.frames.iter().map(|f| f.director).collect();
        rest.vertex_reference_twist_rad = state.reference_twists.clone();
    }
    out
}

/// `pattern` with its rest shape reset to its current geometry: rest lengths, curvatures and
/// twists read off the configuration (reference frames from the pattern's rest state, or fresh
/// ones closest to the normal `e3`). With `bound = (input lengths, b)`, every rest length stays
/// within the relative change `b` of its input value (Sec. 6.5.2).
fn at_rest(pattern: &Pattern, yarn: &YarnModel, bound: Option<(&[f64], f64)>) -> Result<Pattern, RelaxError> {
    let mut framed = pattern.clone();
    if framed.rest.is_none() {
        framed.rest = Some(fresh_frames(pattern));
    }
    let tile = RveModel::new(&framed, yarn)?;
    let place = placement(&tile, &zero_strain());
    let state = RveState::affine(&tile, &place);
    let strains = bend_strains(&tile, &place, &state);
    let mut lengths = edge_lengths(&tile, &place, &state);
    if let Some((input, b)) = bound.filter(|(input, _)| input.len() == lengths.len()) {
        for (l, l0) in lengths.iter_mut().zip(input) {
            *l = l.clamp(l0 * (1.0 - b), l0 * (1.0 + b));
        }
    }
    let rest = framed.rest.as_mut().expect("framed above");
    rest.edge_length_m = lengths;
    rest.vertex_curvature = strains.iter().map(|s| s.0).collect();
    rest.vertex_twist_rad = strains.iter().map(|s| s.1).collect();
    rest.edge_reference_director = state.frames.iter().map(|f| f.director).collect();
    rest.vertex_reference_twist_rad = state.reference_twists;
    Ok(framed)
}

/// Reference frames for a pattern without rest state: each edge's first director as close to
/// the fabric normal `e3` as the edge allows; placeholder rest values (replaced by [`at_rest`]).
fn fresh_frames(pattern: &Pattern) -> RestState {
    let mut directors = vec![[0.0; 3]; pattern.vertex_count()];
    let mut lengths = vec![0.0; pattern.vertex_count()];
    for e in pattern.edges() {
        let edge = pattern.edge_vector(&e);
        directors[e.from as usize] = EdgeFrame::new(edge, [0.0, 0.0, 1.0]).director;
        lengths[e.from as usize] = edge.iter().map(|c| c * c).sum::<f64>().sqrt();
    }
    let n = pattern.vertex_count();
    RestState {
        edge_length_m: lengths,
        vertex_curvature: vec![[0.0; 2]; n],
        vertex_twist_rad: vec![0.0; n],
        edge_reference_director: directors,
        vertex_reference_twist_rad: vec![0.0; n],
    }
}

/// Algorithm 2, lines 7-13: pre-tension by shortening rest lengths and flattening rest
/// curvatures.
fn pre_tension(pattern: &mut Pattern) {
    let (length, curvature) = match pattern.fabric {
        Fabric::Knit => (0.9, 0.8),
        Fabric::Woven => (1.0, 0.9),
    };
    if let Some(rest) = pattern.rest.as_mut() {
        rest.edge_length_m.iter_mut().for_each(|l| *l *= length);
        rest.vertex_curvature.iter_mut().for_each(|k| *k = k.map(|c| c * curvature));
    }
}

/// Rounds of in-plane minimization and pattern update.
const MAX_PERIOD_ROUNDS: usize = 4;
/// Newton steps of the in-plane minimization.
const MAX_PERIOD_STEPS: usize = 40;
/// Largest change of a period strain in one step.
const MAX_PERIOD_STEP: f64 = 0.05;
/// Forward-difference step of the stress derivative.
const PERIOD_PROBE: f64 = 1e-3;
/// Stop when each in-plane stress is below this fraction of its response to a 10% stretch.
const PERIOD_TOLERANCE: f64 = 1e-4;

/// Algorithm 2, lines 14-15: the period strain `(sx, sy)` minimizing the equilibrium energy, by
/// Newton steps on the homogenized stress (3.23c) with its derivative from forward differences
/// of warm-started solves; `pattern` is moved to that minimum.
fn in_plane_minimum(
    pattern: &mut Pattern,
    yarn: &YarnModel,
    options: &RelaxOptions,
    progress: &mut dyn FnMut(RelaxEvent),
) -> Result<([f64; 2], usize), RelaxError> {
    let tile = RveModel::new(pattern, yarn)?;
    let warm = SolveOptions { max_iterations: options.solve.max_iterations, ..SolveOptions::warm_started() };
    let flat = |s: Vector2<f64>| MacroStrain::new(s.x, 0.0, s.y, 0.0, 0.0);
    let mut iterations = 0;
    let mut solve = |s: Vector2<f64>, start: Option<&RveState>| -> Result<(f64, RveState), RelaxError> {
        let strain = flat(s).map_err(|_| RelaxError::NoInPlaneMinimum(0))?;
        let opts = if start.is_some() { warm } else { options.solve };
        let (solved, state) = solve_at(&tile, &strain, start, &opts);
        iterations += solved.iterations;
        if !solved.converged {
            return Err(not_converged("in-plane minimum", &solved));
        }
        Ok((solved.energy_density_j_m2, state))
    };
    let stress = |s: Vector2<f64>, state: &RveState| {
        let st = stress_at_equilibrium(&tile, &flat(s).expect("validated by the solve"), state);
        Vector2::new(st[0], st[2])
    };
    let mut s = Vector2::zeros();
    let (mut energy, mut state) = solve(s, None)?;
    for _ in 0..MAX_PERIOD_STEPS {
        let sigma = stress(s, &state);
        let mut hessian = Matrix2::zeros();
        for k in 0..2 {
            let probe = s + Vector2::ith(k, PERIOD_PROBE);
            let (_, probed) = solve(probe, Some(&state))?;
            hessian.set_column(k, &((stress(probe, &probed) - sigma) / PERIOD_PROBE));
        }
        let hessian = (hessian + hessian.transpose()) * 0.5;
        progress(RelaxEvent::PeriodStep([s.x, s.y], [sigma.x, sigma.y]));
        let converged = (0..2).all(|k| sigma[k].abs() <= PERIOD_TOLERANCE * 0.1 * hessian[(k, k)].abs());
        if converged {
            *pattern = configured(pattern, &tile, &flat(s).expect("valid"), &state);
            return Ok(([s.x, s.y], iterations));
        }
        let mut step = descent_step(&hessian, &sigma);
        let (mut next_energy, mut next_state) = solve(s + step, Some(&state))?;
        let mut halvings = 0;
        while next_energy > energy && halvings < 8 {
            step *= 0.5;
            halvings += 1;
            (next_energy, next_state) = solve(s + step, Some(&state))?;
        }
        s += step;
        (energy, state) = (next_energy, next_state);
    }
    Err(RelaxError::NoInPlaneMinimum(MAX_PERIOD_STEPS))
}

/// The Newton step `-H⁻¹σ` when `H` is positive definite, else the steepest-descent step
/// scaled by the diagonal; at most [`MAX_PERIOD_STEP`] in each component.
fn descent_step(hessian: &Matrix2<f64>, sigma: &Vector2<f64>) -> Vector2<f64> {
    let newton = hessian
        .cholesky()
        .map(|c| -c.solve(sigma))
        .unwrap_or_else(|| -sigma.component_div(&hessian.diagonal().map(|d| d.abs().max(1e-12))));
    let largest = newton.amax();
    if largest > MAX_PERIOD_STEP { newton * (MAX_PERIOD_STEP / largest) } else { newton }
}

/// Algorithm 2, line 16: translate the tile so that its vertices' mean is the origin.
fn centre(pattern: &mut Pattern) {
    let n = pattern.positions_m.len() as f64;
    let mean = pattern.positions_m.iter().fold([0.0; 3], |m, p| [m[0] + p[0], m[1] + p[1], m[2] + p[2]]);
    for p in &mut pattern.positions_m {
        for k in 0..3 {
            p[k] -= mean[k] / n;
        }
    }
}
