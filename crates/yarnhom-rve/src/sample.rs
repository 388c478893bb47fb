//! The sampling plan and sweep engine of the homogenized energy database (Sec. 4.1.1, App. A.3.1).
//!
//! The energy density is sampled only along the coordinate axes and coordinate planes of the
//! strain `(sx, sa, sy, kx, ky)`, as the additive split (4.2) needs: five 1D terms `f_i` and the
//! nine 2D terms `f_ij` of all pairs except `(kx, ky)`, since bending is sampled along one
//! direction at a time (Sec. 4.1.1). Each axis is sampled non-uniformly (App. A.3.1, Fig. A.2):
//! symmetric ranges (`sa`, `kx`, `ky`) more densely around 0, `sx` and `sy` more densely towards
//! compression.
//!
//! The samples are solved along [`SweepLine`]s walking outward from the origin, each solve
//! warm-started from the previous one (extrapolated along the line from the two before it,
//! [`secant_start`]); lines are independent and run in parallel
//! ([`sample_lines`]), and can be dealt to separate processes ([`shard_lines`]).

use std::time::Instant;

use rayon::prelude::*;
use yarnhom_artifacts::grid::{GridSample, GridTerm, strain_from_values};
use yarnhom_geom::MacroStrain;

use crate::assembly::{RveState, world_positions};
use crate::homogenize::{
    placement, secant_start, solve_at, strain_from_vector, strain_vector, stress_at_equilibrium,
};
use crate::model::RveModel;
use crate::solve::{SolveOptions, StopReason};

/// Names of the strain parameters, in the order of every `[f64; 5]` here.
pub const PARAMETERS: [&str; 5] = ["sx", "sa", "sy", "kx", "ky"];

/// Indices of the two bending parameters, never sampled together (Sec. 4.1.1).
const BENDING: [usize; 2] = [3, 4];

/// Rate `β` of the axis maps of [`axis_values`] over a unit span of the uniform parameter.
const SYMMETRIC_RATE: f64 = 4.0;
/// See [`SYMMETRIC_RATE`].
const COMPRESSION_RATE: f64 = 3.0;

/// Why a sampling plan is invalid.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SampleError {
    /// A range does not contain 0 strictly inside, is not finite, or leaves the valid strains.
    #[error(
        "invalid range [{lower}, {upper}] for {name}: a range must be finite with 0 strictly inside, \
         and sx, sy > -1, |sa| < 1 (4.1)"
    )]
    Range {
        /// The parameter.
        name: &'static str,
        /// Its lower bound.
        lower: f64,
        /// Its upper bound.
        upper: f64,
    },
    /// An axis needs at least 3 values: both ends and 0.
    #[error("an axis needs at least 3 values, got {0}")]
    TooFewValues(usize),
    /// The 2D ranges are not one per term of [`plane_axes`], in its order.
    #[error("2D ranges given for {0:?}, expected one per term of {expected:?}", expected = plane_axes())]
    Planes(Vec<[usize; 2]>),
}

/// Check one sampled range: finite, `lower < 0 < upper`, `sx, sy > -1` and `|sa| < 1` (4.1).
fn check_range(axis: usize, lower: f64, upper: f64) -> Result<(), SampleError> {
    let valid = lower.is_finite() && upper.is_finite() && lower < 0.0 && upper > 0.0;
    let strain_valid = match axis {
        0 | 2 => lower > -1.0,
        1 => lower > -1.0 && upper < 1.0,
        _ => true,
    };
    if valid && strain_valid {
        Ok(())
    } else {
        Err(SampleError::Range { name: PARAMETERS[axis], lower, upper })
    }
}

/// The sampled range of each strain parameter `(sx, sa, sy, kx, ky)` (`kx`, `ky` in 1/m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SampleRanges {
    /// Lower bounds, all negative.
    pub lower: [f64; 5],
    /// Upper bounds, all positive.
    pub upper: [f64; 5],
}

impl SampleRanges {
    /// Validated ranges: each finite with `lower < 0 < upper`, and `sx, sy > -1`, `|sa| < 1`
    /// (4.1).
    pub fn new(lower: [f64; 5], upper: [f64; 5]) -> Result<Self, SampleError> {
        (0..5).try_for_each(|k| check_range(k, lower[k], upper[k]))?;
        Ok(SampleRanges { lower, upper })
    }
}

impl Default for SampleRanges {
    /// The 1D ranges of the published HYLC stockinette fit (`stock1.json`): its 1D control
    /// points span 0.95 of the sampled range (Alg. 4), so the range is their extent / 0.95.
    fn default() -> Self {
        SampleRanges { lower: [-0.52, -0.75, -0.52, -200.0, -230.0], upper: [0.78, 0.75, 0.78, 200.0, 230.0] }
    }
}

/// The sampled ranges of one 2D term (Alg. 6 takes "2D-sampling ranges" per pair, apart from
/// the 1D ones).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlaneRange {
    /// The two axes, ascending, not `(kx, ky)`.
    pub axes: [usize; 2],
    /// `[lower, upper]` of each axis.
    pub ranges: [[f64; 2]; 2],
}

/// The sampled ranges of the whole plan: Alg. 6's 1D ranges and the ranges of each of the
/// nine 2D terms.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanRanges {
    /// The ranges of the 1D terms.
    pub single: SampleRanges,
    /// The ranges of the 2D terms, one per pair of [`plane_axes`], in that order.
    pub planes: Vec<PlaneRange>,
}

/// The published stockinette's 2D ranges, recovered from `stock1.json`: each patch's control
/// points span 0.9 of its sampled ranges, and 0.3 for the stockinette's bending terms (Alg. 5,
/// Sec. 4.3), so a range is the patch's extent divided by that span. Every recovered value is
/// round, and each strain gets the same range in every plane whose partner is of one kind.
const STOCKINETTE_PLANES: [PlaneRange; 9] = [
    PlaneRange { axes: [0, 1], ranges: [[-0.1, 0.67], [-0.6, 0.6]] },
    PlaneRange { axes: [0, 2], ranges: [[-0.37, 0.8], [-0.37, 0.8]] },
    PlaneRange { axes: [0, 3], ranges: [[-0.1, 0.67], [-144.0, 144.0]] },
    PlaneRange { axes: [0, 4], ranges: [[-0.1, 0.67], [-184.0, 184.0]] },
    PlaneRange { axes: [1, 2], ranges: [[-0.6, 0.6], [-0.1, 0.67]] },
    PlaneRange { axes: [1, 3], ranges: [[-0.6, 0.6], [-160.0, 160.0]] },
    PlaneRange { axes: [1, 4], ranges: [[-0.6, 0.6], [-184.0, 184.0]] },
    PlaneRange { axes: [2, 3], ranges: [[-0.1, 0.67], [-160.0, 160.0]] },
    PlaneRange { axes: [2, 4], ranges: [[-0.1, 0.67], [-165.6, 165.6]] },
];

/// The nine 2D terms of (4.2): all pairs of `(sx, sa, sy, kx, ky)` but `(kx, ky)`, ascending.
pub fn plane_axes() -> Vec<[usize; 2]> {
    (0..5).flat_map(|a| (a + 1..5).map(move |b| [a, b])).filter(|axes| *axes != BENDING).collect()
}

impl PlanRanges {
    /// Validated ranges: every 1D and 2D range valid, and one plane per pair of
    /// [`plane_axes`], in that order.
    pub fn new(single: SampleRanges, planes: Vec<PlaneRange>) -> Result<Self, SampleError> {
        let single = SampleRanges::new(single.lower, single.upper)?;
        let axes: Vec<[usize; 2]> = planes.iter().map(|p| p.axes).collect();
        if axes != plane_axes() {
            return Err(SampleError::Planes(axes));
        }
        for plane in &planes {
            for (&axis, [lower, upper]) in plane.axes.iter().zip(plane.ranges) {
                check_range(axis, lower, upper)?;
            }
        }
        Ok(PlanRanges { single, planes })
    }

    /// Ranges from bounds: `single[axis]` of each 1D term, and per 2D term its axes (ascending)
    /// and `[lower, upper]` of each (as `yarnhom_fit::ranges::sampled_ranges` recovers them from
    /// a fitted material), in any order; every plane of [`plane_axes`] must be there.
    pub fn from_bounds(
        single: [[f64; 2]; 5],
        planes: &[([u8; 2], [[f64; 2]; 2])],
    ) -> Result<Self, SampleError> {
        let single =
            SampleRanges { lower: single.map(|[lower, _]| lower), upper: single.map(|[_, upper]| upper) };
        let planes = plane_axes()
            .into_iter()
            .map(|axes| {
                let found = planes.iter().find(|(p, _)| p.map(usize::from) == axes);
                found.map(|&(_, ranges)| PlaneRange { axes, ranges }).ok_or_else(|| {
                    SampleError::Planes(planes.iter().map(|(p, _)| p.map(usize::from)).collect())
                })
            })
            .collect::<Result<Vec<_>, _>>()?;
        Self::new(single, planes)
    }

    /// The plane of `axes`, if it is one of [`plane_axes`].
    pub fn plane_mut(&mut self, axes: [usize; 2]) -> Option<&mut PlaneRange> {
        self.planes.iter_mut().find(|p| p.axes == axes)
    }
}

impl Default for PlanRanges {
    /// The published stockinette's ranges ([`SampleRanges::default`], and the planes' recovered
    /// from `stock1.json`).
    fn default() -> Self {
        PlanRanges { single: SampleRanges::default(), planes: STOCKINETTE_PLANES.to_vec() }
    }
}

/// How the samples of an axis are spread (App. A.3.1, Fig. A.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AxisKind {
    /// Densest around 0 (`sa`, `kx`, `ky`).
    Symmetric,
    /// Densest at the lower, compressive end (`sx`, `sy`).
    Compression,
}

impl AxisKind {
    /// The kind of parameter `k` of `(sx, sa, sy, kx, ky)`.
    pub fn of(parameter: usize) -> Self {
        if parameter == 0 || parameter == 2 { AxisKind::Compression } else { AxisKind::Symmetric }
    }

    /// The smooth, strictly increasing map `φ` with `φ(0) = 0` of [`axis_values`].
    fn map(self, t: f64) -> f64 {
        match self {
            AxisKind::Symmetric => (SYMMETRIC_RATE * t).sinh(),
            AxisKind::Compression => (COMPRESSION_RATE * t).exp_m1(),
        }
    }

    /// Where, as a fraction of the uniform parameter's span, the map puts 0 for `[lower, upper]`.
    fn zero_fraction(self, lower: f64, upper: f64) -> f64 {
        match self {
            AxisKind::Symmetric => -lower / (upper - lower),
            AxisKind::Compression => {
                let b = COMPRESSION_RATE;
                (-lower / (upper - lower) * b.exp_m1()).ln_1p() / b
            }
        }
    }
}

/// `n` strictly ascending samples of `[lower, upper]`, the ends and 0 exact (App. A.3.1).
///
/// The uniform parameter `t_i = (i - k) / (n - 1)` is mapped by `x_i = c φ(t_i)`, with
/// `φ(t) = sinh(4 t)` for [`AxisKind::Symmetric`] (spacing grows by `cosh 2 ≈ 3.8` from 0 to the
/// ends of a symmetric range) and `φ(t) = exp(3 t) - 1` for [`AxisKind::Compression`] (spacing
/// grows by `e³ ≈ 20` from the lower to the upper end). `k` is the index nearest to where the
/// map over the whole span `lower + (upper - lower) (φ(τ) - φ(0)) / (φ(1) - φ(0))`, `τ ∈ [0, 1]`,
/// crosses 0 (for the symmetric map, the linear share `-lower / (upper - lower)`), so that
/// sample `k` is exactly 0; the scale `c` is fitted separately on each side of 0 so that the
/// ends are exact.
///
/// # Panics
/// If `n < 3` or not `lower < 0 < upper` (see [`SampleRanges::new`]).
pub fn axis_values(lower: f64, upper: f64, n: usize, kind: AxisKind) -> Vec<f64> {
    assert!(n >= 3 && lower < 0.0 && upper > 0.0, "axis [{lower}, {upper}] with {n} values");
    let last = n - 1;
    let k = ((kind.zero_fraction(lower, upper) * last as f64).round() as usize).clamp(1, last - 1);
    let t = |i: usize| (i as f64 - k as f64) / last as f64;
    let (below, above) = (lower / kind.map(t(0)), upper / kind.map(t(last)));
    (0..n)
        .map(|i| match i {
            0 => lower,
            _ if i == last => upper,
            _ if i == k => 0.0,
            _ if i < k => below * kind.map(t(i)),
            _ => above * kind.map(t(i)),
        })
        .collect()
}

/// One term of (4.2): the samples of one parameter (`f_i`) or the grid of two (`f_ij`), with
/// every other parameter 0.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanTerm {
    /// One or two ascending indices into `(sx, sa, sy, kx, ky)`.
    pub axes: Vec<usize>,
    /// The sampled values of each axis, ascending.
    pub values: Vec<Vec<f64>>,
}

impl PlanTerm {
    /// The term of `axes` with [`axis_values`] of `n` values each over `ranges` (`[lower,
    /// upper]` of each axis).
    fn new(axes: Vec<usize>, ranges: &[[f64; 2]], n: usize) -> Self {
        let values = axes
            .iter()
            .zip(ranges)
            .map(|(&a, &[lower, upper])| axis_values(lower, upper, n, AxisKind::of(a)))
            .collect();
        PlanTerm { axes, values }
    }

    /// Number of samples: the product of the axes' value counts.
    pub fn sample_count(&self) -> usize {
        self.values.iter().map(Vec::len).product()
    }

    /// The strain `(sx, sa, sy, kx, ky)` of the sample `index` (the second index is 0 for a 1D
    /// term).
    pub fn strain(&self, index: [usize; 2]) -> [f64; 5] {
        let mut strain = [0.0; 5];
        for (slot, &axis) in self.axes.iter().enumerate() {
            strain[axis] = self.values[slot][index[slot]];
        }
        strain
    }

    /// The index of the first axis's value nearest 0.
    fn origin(&self) -> usize {
        let nearest = |(_, a): &(usize, &f64), (_, b): &(usize, &f64)| a.abs().total_cmp(&b.abs());
        self.values[0].iter().enumerate().min_by(nearest).map_or(0, |(i, _)| i)
    }
}

/// The samples of the 1D and 2D terms of (4.2) (App. A.3.1).
#[derive(Debug, Clone, PartialEq)]
pub struct SamplePlan {
    /// The terms: first the 1D, then the 2D ones.
    pub terms: Vec<PlanTerm>,
}

impl SamplePlan {
    /// The thesis's plan (App. A.3.1, Alg. 6): the five 1D terms with `n_1d` values each
    /// (thesis: 150) over `ranges.single` and the nine 2D terms of [`plane_axes`] on
    /// `n_2d × n_2d` grids (thesis: 50) over their `ranges.planes`.
    pub fn thesis(ranges: &PlanRanges, n_1d: usize, n_2d: usize) -> Result<Self, SampleError> {
        let ranges = PlanRanges::new(ranges.single, ranges.planes.clone())?;
        if let Some(&n) = [n_1d, n_2d].iter().find(|&&n| n < 3) {
            return Err(SampleError::TooFewValues(n));
        }
        let single = ranges.single;
        let singles = (0..5).map(|a| PlanTerm::new(vec![a], &[[single.lower[a], single.upper[a]]], n_1d));
        let pairs = ranges.planes.iter().map(|p| PlanTerm::new(p.axes.to_vec(), &p.ranges, n_2d));
        Ok(SamplePlan { terms: singles.chain(pairs).collect() })
    }

    /// The terms as a `grid` artifact stores them.
    pub fn grid_terms(&self) -> Vec<GridTerm> {
        self.terms
            .iter()
            .map(|t| GridTerm { axes: t.axes.iter().map(|&a| a as u8).collect(), values: t.values.clone() })
            .collect()
    }

    /// Number of samples over all terms (thesis: `5 · 150 + 9 · 50² = 23250`).
    pub fn sample_count(&self) -> usize {
        self.terms.iter().map(PlanTerm::sample_count).sum()
    }

    /// Every sample exactly once, as lines walking outward from the origin along each term's
    /// first axis: per term, and for a 2D term per index `j` of its second axis, the line from
    /// the value nearest 0 up to the upper end, then the line from the next value down to the
    /// lower end (empty lines are left out). The order is fixed; [`SweepLine::index`] is the
    /// position in it.
    pub fn lines(&self) -> Vec<SweepLine> {
        let mut lines = Vec::new();
        for (t, term) in self.terms.iter().enumerate() {
            let (n, origin) = (term.values[0].len(), term.origin());
            let columns = term.values.get(1).map_or(1, Vec::len);
            for j in 0..columns {
                let up: Vec<[usize; 2]> = (origin..n).map(|i| [i, j]).collect();
                let down = (0..origin).rev().map(|i| [i, j]).collect();
                for points in [up, down] {
                    if !points.is_empty() {
                        lines.push(SweepLine { index: lines.len(), term: t, points });
                    }
                }
            }
        }
        lines
    }
}

/// A sequence of neighbouring samples of one term, solved in order with warm starts.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SweepLine {
    /// Position in [`SamplePlan::lines`].
    pub index: usize,
    /// Index into [`SamplePlan::terms`].
    pub term: usize,
    /// Sample indices `[i, j]` into the term's axis values (`j = 0` for a 1D term).
    pub points: Vec<[usize; 2]>,
}

/// Shard `index` of `count`: the lines dealt round-robin in their order, so that the shards
/// together hold every line exactly once.
///
/// # Panics
/// If `index >= count`.
pub fn shard_lines(lines: &[SweepLine], index: usize, count: usize) -> Vec<SweepLine> {
    assert!(index < count, "shard {index} of {count}");
    lines.iter().skip(index).step_by(count).cloned().collect()
}

/// What the engine computes per sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SampleOptions {
    /// Newton iteration limit of each solve.
    pub max_iterations: usize,
    /// Whether to compute the homogenized stress of converged samples.
    pub stress: bool,
    /// Whether to keep the equilibrium geometry of each sample.
    pub geometry: bool,
}

impl Default for SampleOptions {
    fn default() -> Self {
        SampleOptions {
            max_iterations: SolveOptions::default().max_iterations,
            stress: true,
            geometry: false,
        }
    }
}

/// The result of one sample.
#[derive(Debug, Clone, PartialEq)]
pub struct SampleOutcome {
    /// Index into [`SamplePlan::terms`].
    pub term: usize,
    /// Sample index into the term's axis values.
    pub index: [u32; 2],
    /// `(sx, sa, sy, kx, ky)`.
    pub strain: [f64; 5],
    /// Whether the solve started from the previous sample's equilibrium, possibly extrapolated
    /// along the line ([`secant_start`]); else from the affine start: the line's first sample,
    /// or after a solve that did not converge.
    pub warm_started: bool,
    /// Whether the equilibrium was found.
    pub converged: bool,
    /// Why the solve stopped.
    pub stop_reason: StopReason,
    /// Homogenized energy density (3.22), when converged (J/m²).
    pub energy_density_j_m2: Option<f64>,
    /// `dΨ/d(sx, sa, sy, kx, ky)` (3.23c), when converged and asked for.
    pub stress: Option<[f64; 5]>,
    /// Newton iterations.
    pub iterations: usize,
    /// Wall time of the solve, stress and geometry (s).
    pub seconds: f64,
    /// World positions of the tile's vertices at the end of the solve, when asked for (m).
    pub positions_m: Option<Vec<[f64; 3]>>,
    /// Twist of each edge (by source vertex) at the end of the solve, when asked for (rad).
    pub edge_twist_rad: Option<Vec<f64>>,
}

impl SampleOutcome {
    /// The sample as a `grid` artifact stores it.
    pub fn to_grid_sample(&self) -> GridSample {
        GridSample {
            term: self.term as u32,
            index: self.index,
            strain: strain_from_values(self.strain),
            converged: self.converged,
            stop_reason: self.stop_reason.as_str().into(),
            energy_density_j_m2: self.energy_density_j_m2,
            stress: self.stress,
            iterations: self.iterations as u32,
            positions_m: self.positions_m.clone(),
            edge_twist_rad: self.edge_twist_rad.clone(),
        }
    }
}

/// The samples of one line, in the line's order.
#[derive(Debug, Clone, PartialEq)]
pub struct LineResult {
    /// [`SweepLine::index`].
    pub line: usize,
    /// One per point of the line.
    pub samples: Vec<SampleOutcome>,
}

/// Solve the samples of `lines` (of `plan`): lines in parallel on the current rayon pool, each
/// line in order, warm-starting every solve from the previous converged one (App. A.3.1).
/// `on_line_done` is called once per finished line, from the thread that ran it. The results are
/// sorted by line index, so they do not depend on the thread count or the sharding.
///
/// # Panics
/// If a sample of `plan` is not a valid strain (never for [`SamplePlan::thesis`]).
pub fn sample_lines(
    model: &RveModel,
    plan: &SamplePlan,
    lines: &[SweepLine],
    options: &SampleOptions,
    on_line_done: &(dyn Fn(&LineResult) + Sync),
) -> Vec<LineResult> {
    let mut results: Vec<LineResult> = lines
        .par_iter()
        .map(|line| {
            let result = sample_line(model, plan, line, options);
            on_line_done(&result);
            result
        })
        .collect();
    results.sort_by_key(|r| r.line);
    results
}

/// The samples of one line, in order: each warm-started from the previous converged one, by the
/// secant predictor ([`secant_start`]) once two neighbouring samples have converged.
fn sample_line(model: &RveModel, plan: &SamplePlan, line: &SweepLine, options: &SampleOptions) -> LineResult {
    // The line's last two converged equilibria, with their strains: the latest and the one
    // before it.
    let mut last: Option<(MacroStrain, RveState)> = None;
    let mut before: Option<(MacroStrain, RveState)> = None;
    let samples = line
        .points
        .iter()
        .map(|&index| {
            let values = plan.terms[line.term].strain(index);
            let strain = strain_from_vector(values).expect("plan samples are valid strains");
            let start = match (&last, &before) {
                (Some((a, l)), Some((b, p))) => Some(secant_start(model, &strain, (a, l), (b, p))),
                (Some((_, l)), None) => Some(l.clone()),
                _ => None,
            };
            let (outcome, state) = sample_point(model, &strain, line.term, index, start.as_ref(), options);
            if outcome.converged {
                before = last.replace((strain, state));
            } else {
                (last, before) = (None, None);
            }
            outcome
        })
        .collect();
    LineResult { line: line.index, samples }
}

/// Solve sample `index` of term `term` at `strain`, from `start` if given, else from the affine
/// start.
fn sample_point(
    model: &RveModel,
    strain: &MacroStrain,
    term: usize,
    index: [usize; 2],
    start: Option<&RveState>,
    options: &SampleOptions,
) -> (SampleOutcome, RveState) {
    let started = Instant::now();
    let base = if start.is_some() { SolveOptions::warm_started() } else { SolveOptions::default() };
    let solve_options = SolveOptions { max_iterations: options.max_iterations, ..base };
    let (report, state) = solve_at(model, strain, start, &solve_options);
    let stress = (report.converged && options.stress).then(|| stress_at_equilibrium(model, strain, &state));
    let geometry = options.geometry.then(|| {
        let positions = world_positions(model, &placement(model, strain), &state);
        let twists = (0..model.vertices as u32).map(|v| state.g[model.twist_dof(v)]).collect();
        (positions, twists)
    });
    let (positions_m, edge_twist_rad) = geometry.unzip();
    let outcome = SampleOutcome {
        term,
        index: index.map(|i| i as u32),
        strain: strain_vector(strain),
        warm_started: start.is_some(),
        converged: report.converged,
        stop_reason: report.reason,
        energy_density_j_m2: report.converged.then_some(report.energy_density_j_m2),
        stress,
        iterations: report.iterations,
        seconds: started.elapsed().as_secs_f64(),
        positions_m,
        edge_twist_rad,
    };
    (outcome, state)
}
