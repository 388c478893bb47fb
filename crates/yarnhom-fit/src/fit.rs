//! Fitting a sampled grid into a spline material: Algorithm 3 with Algorithms 4 and 5 of the
//! thesis (App. A.3): normalization, `f0`, MLS smoothing in symlog space (A.35), control points
//! through the origin (A.3.2), quasiconvex marching (A.36), monotone cubic and bicubic
//! interpolation (Fritsch-Carlson; App. B), increasing extrapolation (A.3.5) and residualization
//! (A.37, A.38).

use std::collections::HashMap;

use yarnhom_artifacts::grid::strain_values;
use yarnhom_artifacts::{
    AxisLimit, BicubicTerm, CubicTerm, FitSettings, Grid, GridSample, GridTerm, Spline, SplineOrigin,
};
use yarnhom_geom::stats::root_mean_square;

use crate::hermite::Cubic;
use crate::march::{
    bending_minimum_index, bending_minimum_row, clamp_boundary_for_extrapolation_2d, march_2d,
    quasiconvexify_1d, zero_knot_index,
};
use crate::mls::{HermiteGrid, SmoothedEnergy1d, SmoothedEnergy2d, symexp, symlog};
use crate::monotone_bicubic::make_monotone_bicubic;
use crate::residual::{residualize_1d, residualize_2d, zero_compressed};

/// The shear axis, symmetrized when [`FitSettings::symmetrize_shear`] (Sec. 4.3).
pub(crate) const SHEAR: usize = 1;
/// The pair `(sx, sy)` whose residual keeps its shape: no marching, no zeroed compression
/// (A.3.4, A.3.6), so it carries the Poisson effect.
pub(crate) const POISSON_PAIR: [u8; 2] = [0, 2];
/// Fewest converged samples a term is fitted from.
const MIN_SAMPLES: usize = 4;
/// The MLS support spans at least this many of the widest gaps between sampled values, so a
/// reduced plan still has enough data under every stencil.
const RADIUS_IN_GAPS: f64 = 2.5;

/// Why a grid cannot be fitted.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FitError {
    /// The grid has no converged sample at zero strain, so `f0` is unknown.
    #[error("the grid has no converged sample at zero strain (f0 = Ψ(0) is needed, Alg. 3 line 3)")]
    NoRestSample,
    /// A term has too few converged samples.
    #[error("term {term} has {converged} converged samples; at least {MIN_SAMPLES} are needed")]
    TooFewSamples {
        /// The term's name.
        term: String,
        /// Converged samples.
        converged: usize,
    },
    /// The smoothed energy is undefined at a control point (no data within the MLS radius).
    #[error("term {term}: no data within the MLS radius of a control point; raise --mls-radius")]
    NoSupport {
        /// The term's name.
        term: String,
    },
    /// A term's values do not include 0.
    #[error("term {term}: its control points must include 0 (A.3.2)")]
    NoZeroKnot {
        /// The term's name.
        term: String,
    },
}

/// Fit a whole grid (Alg. 3), restricted to the settings' limits ([`restrict_grid`]).
/// `areal_density_kg_m2` is the cloth's mass per area.
pub fn fit_grid(grid: &Grid, settings: &FitSettings, areal_density_kg_m2: f64) -> Result<Spline, FitError> {
    fit_grid_with_regularized_terms(grid, settings, areal_density_kg_m2).map(|fit| fit.spline)
}

/// A fitted material with the regularized 2D fits `f*_uv` (A.3.6) its residual terms came from:
/// the quasiconvexified terms, which the marching (A.36) gives a single minimum each. (The 1D
/// terms differ from their `f*_u` by a constant, A.37.)
#[derive(Debug, Clone, PartialEq)]
pub struct RegularizedFit {
    /// The material.
    pub spline: Spline,
    /// `f*_uv` per 2D term, in the order of `spline.terms_2d`, on the same control points.
    pub regularized_2d: Vec<BicubicTerm>,
}

/// [`fit_grid`] keeping the regularized 2D fits.
pub fn fit_grid_with_regularized_terms(
    grid: &Grid,
    settings: &FitSettings,
    areal_density_kg_m2: f64,
) -> Result<RegularizedFit, FitError> {
    let restricted;
    let grid = if settings.limits.is_empty() {
        grid
    } else {
        restricted = restrict_grid(grid, &settings.limits);
        &restricted
    };
    let scale = strain_scale(grid);
    // The 1D terms first: the 2D terms take their axis lines from them.
    let mut terms_1d = Vec::new();
    for (t, term) in grid.terms.iter().enumerate() {
        if let [axis] = *term.axes.as_slice() {
            terms_1d.push(fit_1d(
                axis as usize,
                &TermData::gather(grid, t, &scale, settings.mls_radius)?,
                settings,
            )?);
        }
    }
    let (mut terms_2d, mut regularized_2d) = (Vec::new(), Vec::new());
    for (t, term) in grid.terms.iter().enumerate() {
        if let [u, v] = *term.axes.as_slice() {
            let data = TermData::gather(grid, t, &scale, settings.mls_radius)?;
            let along = |axis: u8| terms_1d.iter().find(|f: &&CubicTerm| f.axis == axis);
            let (residual, regularized) =
                fit_2d([u as usize, v as usize], &data, [along(u), along(v)], settings)?;
            terms_2d.push(residual);
            regularized_2d.push(regularized);
        }
    }
    let spline = Spline {
        name: grid.pattern.clone(),
        areal_density_kg_m2,
        strain_scale: scale,
        rest_energy_density_j_m2: rest_energy(grid).ok_or(FitError::NoRestSample)?,
        terms_1d,
        terms_2d,
        origin: SplineOrigin::Fitted { settings: settings.clone() },
    };
    Ok(RegularizedFit { spline, regularized_2d })
}

/// The normalization of each strain axis: its largest magnitude in the plan (Alg. 3 line 2);
/// 1 for an axis the plan does not sample.
pub fn strain_scale(grid: &Grid) -> [f64; 5] {
    let mut scale = [0.0_f64; 5];
    for term in &grid.terms {
        for (&axis, values) in term.axes.iter().zip(&term.values) {
            let largest = values.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
            scale[axis as usize] = scale[axis as usize].max(largest);
        }
    }
    scale.map(|s| if s > 0.0 { s } else { 1.0 })
}

/// `f0`: the energy density of a converged sample at zero strain.
fn rest_energy(grid: &Grid) -> Option<f64> {
    grid.samples
        .iter()
        .find(|s| s.converged && strain_values(&s.strain).iter().all(|&v| v == 0.0))
        .and_then(|s| s.energy_density_j_m2)
}

/// A term's converged samples in normalized strain.
struct TermData {
    name: String,
    /// Normalized strains along the term's axes (one list per axis, per sample).
    strains: Vec<Vec<f64>>,
    energies: Vec<f64>,
    /// MLS radius for this term.
    radius: f64,
    /// Normalized sampled range `[min, max]` per axis.
    ranges: Vec<[f64; 2]>,
}

impl TermData {
    fn gather(grid: &Grid, t: usize, scale: &[f64; 5], min_radius: f64) -> Result<Self, FitError> {
        let term = &grid.terms[t];
        let mut strains = vec![Vec::new(); term.axes.len()];
        let mut energies = Vec::new();
        for sample in grid.samples.iter().filter(|s| s.term as usize == t) {
            let Some(energy) = sample.energy_density_j_m2.filter(|_| sample.converged) else { continue };
            let values = strain_values(&sample.strain);
            for (k, &axis) in term.axes.iter().enumerate() {
                strains[k].push(values[axis as usize] / scale[axis as usize]);
            }
            energies.push(energy);
        }
        if energies.len() < MIN_SAMPLES {
            return Err(FitError::TooFewSamples { term: term.name(), converged: energies.len() });
        }
        let ranges = normalized_ranges(term, scale);
        let radius = mls_radius(term, scale, min_radius);
        Ok(Self { name: term.name(), strains, energies, radius, ranges })
    }
}

fn normalized_ranges(term: &GridTerm, scale: &[f64; 5]) -> Vec<[f64; 2]> {
    term.axes
        .iter()
        .zip(&term.values)
        .map(|(&axis, values)| {
            let s = scale[axis as usize];
            [values[0] / s, values[values.len() - 1] / s]
        })
        .collect()
}

/// The larger of the configured radius and [`RADIUS_IN_GAPS`] widest gaps of the term's axes.
fn mls_radius(term: &GridTerm, scale: &[f64; 5], min_radius: f64) -> f64 {
    let widest_gap = term
        .axes
        .iter()
        .zip(&term.values)
        .flat_map(|(&axis, values)| values.windows(2).map(move |w| (w[1] - w[0]) / scale[axis as usize]))
        .fold(0.0_f64, f64::max);
    (RADIUS_IN_GAPS * widest_gap).max(min_radius)
}

/// Control points: two linearly spaced ranges left and right of 0 (A.3.2) spanning `span` of
/// the sampled range `[min, max]`, `per_side` intervals each (a side of zero extent is omitted).
pub fn control_points(range: [f64; 2], span: f64, per_side: usize) -> Vec<f64> {
    let per_side = per_side.max(1);
    let side = |end: f64| -> Vec<f64> {
        if end == 0.0 {
            return Vec::new();
        }
        (1..=per_side).map(|k| span * end * k as f64 / per_side as f64).collect()
    };
    let mut knots: Vec<f64> = side(range[0].min(0.0)).into_iter().rev().collect();
    knots.push(0.0);
    knots.extend(side(range[1].max(0.0)));
    knots
}

/// Alg. 4: one 1D term.
fn fit_1d(axis: usize, data: &TermData, settings: &FitSettings) -> Result<CubicTerm, FitError> {
    let mut smoothed = SmoothedEnergy1d::new(&data.strains[0], &data.energies, data.radius);
    if axis == SHEAR && settings.symmetrize_shear {
        smoothed = smoothed.symmetric();
    }
    let knots = control_points(data.ranges[0], settings.span_1d, settings.knots_per_side_1d as usize);
    let (mut values, mut slopes) =
        smoothed.hermite_data(&knots).ok_or_else(|| FitError::NoSupport { term: data.name.clone() })?;
    let zero = zero_knot_index(&knots).ok_or_else(|| FitError::NoZeroKnot { term: data.name.clone() })?;
    let i_min = if axis < 3 { zero } else { bending_minimum_index(&values) };
    quasiconvexify_1d(&knots, &mut values, &mut slopes, i_min, settings.min_slope);
    residualize_1d(&knots, &mut values).map_err(|_| FitError::NoZeroKnot { term: data.name.clone() })?;
    Ok(CubicTerm { axis: axis as u8, knots, values, slopes })
}

/// Alg. 5: one 2D residual term over axes `[u, v]` and the regularized fit `f*_uv` it is the
/// residual of (A.38); `axis_terms` are the fitted 1D terms of `u` and `v`, if the grid has them
/// (see [`move_onto_1d_terms`]).
fn fit_2d(
    axes: [usize; 2],
    data: &TermData,
    axis_terms: [Option<&CubicTerm>; 2],
    settings: &FitSettings,
) -> Result<(BicubicTerm, BicubicTerm), FitError> {
    let no_support = || FitError::NoSupport { term: data.name.clone() };
    let no_zero = || FitError::NoZeroKnot { term: data.name.clone() };
    let span = if axes[1] >= 3 { settings.span_2d_bending } else { settings.span_2d };
    let per_side = settings.knots_per_side_2d as usize;
    let (u_knots, v_knots) =
        (control_points(data.ranges[0], span, per_side), control_points(data.ranges[1], span, per_side));
    let mut h = smoothed_hermite_2d(axes, data, settings, &u_knots, &v_knots).ok_or_else(no_support)?;
    let i_min = zero_knot_index(&u_knots).ok_or_else(no_zero)?;
    let j0 = zero_knot_index(&v_knots).ok_or_else(no_zero)?;
    move_onto_1d_terms(&mut h, [&u_knots, &v_knots], [i_min, j0], axis_terms);
    if axes.map(|a| a as u8) == POISSON_PAIR {
        // A.3.5: f13 is not marched; its boundary tangents are only made non-decreasing outward.
        clamp_boundary_for_extrapolation_2d(&u_knots, &v_knots, &mut h.du, &mut h.dv, &mut h.duv, 0.0);
    } else {
        let nu = u_knots.len();
        let j_min = if axes[1] < 3 {
            zero_knot_index(&v_knots).ok_or_else(no_zero)?
        } else {
            bending_minimum_row(&h.values, nu, i_min)
        };
        march_2d(&u_knots, &v_knots, &mut h.values, &mut h.du, &mut h.dv, i_min, j_min, settings.min_slope);
        let min_slope = settings.min_slope;
        clamp_boundary_for_extrapolation_2d(&u_knots, &v_knots, &mut h.du, &mut h.dv, &mut h.duv, min_slope);
    }
    make_monotone_bicubic(&u_knots, &v_knots, &h.values, &mut h.du, &mut h.dv, &mut h.duv);
    let axes = [axes[0] as u8, axes[1] as u8];
    let term = |h: HermiteGrid| BicubicTerm {
        axes,
        u_knots: u_knots.clone(),
        v_knots: v_knots.clone(),
        values: h.values,
        du: h.du,
        dv: h.dv,
        duv: h.duv,
    };
    let regularized = term(h.clone());
    residualize_2d(&u_knots, &v_knots, &mut h.values, &mut h.du, &mut h.dv).map_err(|_| no_zero())?;
    if axes != POISSON_PAIR {
        let compressible = |axis: u8| axis == 0 || axis == 2;
        let (cu, cv) = (compressible(axes[0]), compressible(axes[1]));
        zero_compressed(&u_knots, &v_knots, &mut h.values, &mut h.du, &mut h.dv, &mut h.duv, cu, cv);
    }
    Ok((term(h), regularized))
}

/// The regularized plane `f*` moved onto the fitted 1D terms: `f* + g(u) + h(v)` with `g`, `h`
/// the differences between the 1D terms and `f*`'s own axis lines, so that its axis lines
/// become `f*(0, 0) + f_u(u)` and `f*(0, 0) + f_v(v)` at the nodes (values and slopes).
///
/// The residual (A.38) does not change (it removes functions of one variable), but the energy
/// on the plane, `f0 + f_u + f_v + r`, is now this `f*` up to re-interpolating `f_u`, `f_v` on
/// the plane's control points and up to the axis lines' slopes that the monotone step (App. B)
/// then projects, so the marching (A.36) acts on nearly the energy the material shows.
/// Marching the plane's own `f*` left that sum with the difference between two fits of the
/// same axis data on different control points, which made second minima where `f*` is flat.
/// (Putting the 1D terms' slopes back on the axis lines after the monotone step, tried, removes
/// some of the sum's second minima but breaks App. B's guarantee in the cells beside the axes:
/// `f*` itself then has second minima, see README "Spline fits".)
fn move_onto_1d_terms(
    h: &mut HermiteGrid,
    [u_knots, v_knots]: [&[f64]; 2],
    [i0, j0]: [usize; 2],
    [f_u, f_v]: [Option<&CubicTerm>; 2],
) {
    let nu = u_knots.len();
    let origin = h.values[j0 * nu + i0];
    // (g, g') at the u knots and (h, h') at the v knots; zero without a 1D term.
    let shift = |f: Option<Cubic>, knots: &[f64], line: &dyn Fn(usize) -> (f64, f64)| -> Vec<(f64, f64)> {
        (0..knots.len())
            .map(|k| match &f {
                Some(f) => {
                    let (jet, (value, slope)) = (f.jet(knots[k]), line(k));
                    (origin + jet.value - value, jet.d1 - slope)
                }
                None => (0.0, 0.0),
            })
            .collect()
    };
    let g = shift(f_u.map(Cubic::from), u_knots, &|i| (h.values[j0 * nu + i], h.du[j0 * nu + i]));
    let hv = shift(f_v.map(Cubic::from), v_knots, &|j| (h.values[j * nu + i0], h.dv[j * nu + i0]));
    for (j, &(hj, dhj)) in hv.iter().enumerate() {
        for (i, &(gi, dgi)) in g.iter().enumerate() {
            let n = j * nu + i;
            h.values[n] += gi + hj;
            h.du[n] += dgi;
            h.dv[n] += dhj;
        }
    }
}

/// Alg. 5 lines 2-9: MLS-smoothed Hermite data at the nodes, symmetrized in `sa` where it is
/// one of the axes (the smoother symmetrizes its first argument, so `(sx, sa)` is smoothed
/// transposed).
fn smoothed_hermite_2d(
    axes: [usize; 2],
    data: &TermData,
    settings: &FitSettings,
    u_knots: &[f64],
    v_knots: &[f64],
) -> Option<HermiteGrid> {
    let radius = data.radius;
    let (us, vs) = (&data.strains[0], &data.strains[1]);
    let symmetric = settings.symmetrize_shear;
    if symmetric && axes[1] == SHEAR {
        let smoothed = SmoothedEnergy2d::new(vs, us, &data.energies, radius).symmetric_in_u();
        return smoothed.hermite_data(v_knots, u_knots).map(|h| transpose(&h, v_knots.len(), u_knots.len()));
    }
    let mut smoothed = SmoothedEnergy2d::new(us, vs, &data.energies, radius);
    if symmetric && axes[0] == SHEAR {
        smoothed = smoothed.symmetric_in_u();
    }
    smoothed.hermite_data(u_knots, v_knots)
}

/// Nodal data of the transposed grid: `nu` nodes per row in the input become `nu` rows.
fn transpose(h: &HermiteGrid, nu: usize, nv: usize) -> HermiteGrid {
    let t = |a: &[f64]| (0..nu).flat_map(|i| (0..nv).map(move |j| a[j * nu + i])).collect::<Vec<_>>();
    HermiteGrid { values: t(&h.values), du: t(&h.dv), dv: t(&h.du), duv: t(&h.duv) }
}

/// The grid restricted to the strain limits: each term keeps the axis values within its axes'
/// limits (0 always stays) and the samples at them, re-indexed. The thesis chooses its sampling
/// limits below self-intersection and jamming (App. A.3.1); this applies such limits to a grid
/// sampled wider.
pub fn restrict_grid(grid: &Grid, limits: &[AxisLimit]) -> Grid {
    let inside =
        |axis: u8, v: f64| limits.iter().filter(|l| l.axis == axis).all(|l| v >= l.min && v <= l.max);
    // Per term and axis: the new index of each old value, or None if it is dropped.
    let maps: Vec<Vec<Vec<Option<u32>>>> = grid
        .terms
        .iter()
        .map(|term| {
            term.axes
                .iter()
                .zip(&term.values)
                .map(|(&axis, values)| {
                    let mut next = 0;
                    values
                        .iter()
                        .map(|&v| {
                            inside(axis, v).then(|| {
                                next += 1;
                                next - 1
                            })
                        })
                        .collect()
                })
                .collect()
        })
        .collect();
    let terms = grid
        .terms
        .iter()
        .map(|term| GridTerm {
            axes: term.axes.clone(),
            values: term
                .axes
                .iter()
                .zip(&term.values)
                .map(|(&axis, values)| values.iter().copied().filter(|&v| inside(axis, v)).collect())
                .collect(),
        })
        .collect();
    let samples = grid
        .samples
        .iter()
        .filter_map(|s| {
            let map = &maps[s.term as usize];
            let i = map[0][s.index[0] as usize]?;
            let j = match map.get(1) {
                Some(m) => m[s.index[1] as usize]?,
                None => 0,
            };
            Some(GridSample { index: [i, j], ..s.clone() })
        })
        .collect();
    Grid { terms, samples, ..grid.clone() }
}

/// How well a spline reproduces the grid it was fitted to, per term.
#[derive(Debug, Clone, PartialEq)]
pub struct TermError {
    /// The term's name.
    pub term: String,
    /// Number of converged samples compared.
    pub samples: usize,
    /// RMS of (fit - data) over the term's samples divided by the RMS of the data (J/m²).
    pub relative_rms: f64,
    /// RMS of (fit - data) divided by the RMS of the deformation energy `data - f0`: the
    /// stricter figure, blind to the constant.
    pub relative_rms_deformation: f64,
    /// `relative_rms` against the response the model is built to represent: for 2D terms other
    /// than `sx,sy`, only the samples without compression (`sx, sy >= 0`), whose combined
    /// response the thesis leaves to the 1D terms (A.3.6); for terms with `sa`, when the fit
    /// symmetrizes shear, the data averaged with its mirror sample (`sa -> -sa`) in the symlog
    /// space where the fit symmetrizes (A.35, Sec. 4.1: a tile that is not mirror symmetric
    /// responds differently to the two senses of shear, and the fit represents their mean);
    /// `None` when no such samples remain.
    pub relative_rms_modelled: Option<f64>,
    /// Number of samples in `relative_rms_modelled`.
    pub samples_modelled: usize,
}

/// The fit's error on each term of its grid; `symmetrized_shear` as the fit's
/// [`FitSettings::symmetrize_shear`].
pub fn fit_errors(
    grid: &Grid,
    material: &crate::SplineMaterial,
    f0: f64,
    symmetrized_shear: bool,
) -> Vec<TermError> {
    grid.terms
        .iter()
        .enumerate()
        .map(|(t, term)| {
            let samples: Vec<&GridSample> =
                grid.samples.iter().filter(|s| s.term as usize == t && s.converged).collect();
            let by_index: HashMap<[u32; 2], f64> =
                samples.iter().filter_map(|s| Some((s.index, s.energy_density_j_m2?))).collect();
            let energy = |index: [u32; 2]| by_index.get(&index).copied();
            let shear_axis = term.axes.iter().position(|&a| a as usize == SHEAR);
            let modelled_energy = |s: &GridSample| match shear_axis {
                Some(k) if symmetrized_shear => {
                    let mirrored = mirrored_symlog_energy(&term.values[k], s.index, k, &energy)?;
                    Some(symexp(0.5 * (symlog(s.energy_density_j_m2?) + mirrored)))
                }
                _ => s.energy_density_j_m2,
            };
            let pairs = |keep: &dyn Fn(&GridSample) -> bool,
                         data: &dyn Fn(&GridSample) -> Option<f64>|
             -> Vec<(f64, f64)> {
                samples
                    .iter()
                    .filter(|s| keep(s))
                    .filter_map(|s| data(s).map(|e| (material.energy_at(&s.strain), e)))
                    .collect()
            };
            let all = pairs(&|_| true, &|s| s.energy_density_j_m2);
            let uncompressed = term.axes.len() == 1 || term.axes.as_slice() == POISSON_PAIR;
            let modelled = pairs(
                &|s: &GridSample| uncompressed || (s.strain.sx >= 0.0 && s.strain.sy >= 0.0),
                &modelled_energy,
            );
            TermError {
                term: term.name(),
                samples: all.len(),
                relative_rms: relative_rms(&all, 0.0),
                relative_rms_deformation: relative_rms(&all, f0),
                relative_rms_modelled: (!modelled.is_empty()).then(|| relative_rms(&modelled, 0.0)),
                samples_modelled: modelled.len(),
            }
        })
        .collect()
}

/// `symlog Ψ` at the mirror image of the sample at `index` along axis `k` (values `values`):
/// the sampled axis value `-values[index[k]]`, or the linear interpolation in symlog space
/// between the two sampled values around it (a symmetric range sampled at an even count has
/// no exact mirror); `None` beyond the sampled range or next to a sample that did not converge.
fn mirrored_symlog_energy(
    values: &[f64],
    index: [u32; 2],
    k: usize,
    energy: &dyn Fn([u32; 2]) -> Option<f64>,
) -> Option<f64> {
    let target = -values[index[k] as usize];
    let at = |j: usize| {
        let mut i = index;
        i[k] = j as u32;
        energy(i).map(symlog)
    };
    let upper = values.iter().position(|&v| v >= target)?;
    if values[upper] == target {
        return at(upper);
    }
    let lower = upper.checked_sub(1)?;
    let t = (target - values[lower]) / (values[upper] - values[lower]);
    Some((1.0 - t) * at(lower)? + t * at(upper)?)
}

/// RMS of (fit - data) over RMS of (data - offset), for `(fit, data)` pairs.
fn relative_rms(pairs: &[(f64, f64)], offset: f64) -> f64 {
    root_mean_square(pairs.iter().map(|(fit, data)| fit - data))
        / root_mean_square(pairs.iter().map(|(_, data)| data - offset))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn restricting_a_grid_keeps_the_samples_within_the_limits() {
        let grid = crate::synthetic::synthetic_grid();
        let limits = [AxisLimit { axis: 3, min: -100.0, max: 150.0 }];
        let restricted = restrict_grid(&grid, &limits);
        restricted.validate().expect("a valid grid");
        assert!(restricted.is_complete());
        assert!(restricted.samples.iter().all(|s| s.strain.kx >= -100.0 && s.strain.kx <= 150.0));
        let dropped = grid.samples.iter().filter(|s| s.strain.kx < -100.0 || s.strain.kx > 150.0).count();
        assert!(dropped > 0);
        assert_eq!(restricted.samples.len() + dropped, grid.samples.len());
        assert_eq!(restrict_grid(&grid, &[]), grid);
    }

    #[test]
    fn the_mirror_of_a_sample_is_interpolated_in_symlog_space_between_its_neighbours() {
        // An axis sampled at an even count: 0.4 has no mirror, -0.4 lies between -0.5 and 0.
        let values = [-1.0, -0.5, 0.0, 0.4, 1.0];
        let symlog_energy = |sa: f64| 2.0 + sa;
        let energy = |i: [u32; 2]| (i[1] != 9).then(|| symexp(symlog_energy(values[i[0] as usize])));
        let mirrored = |i: u32| mirrored_symlog_energy(&values, [i, 0], 0, &energy);
        assert_eq!(mirrored(4), Some(symlog_energy(-1.0)));
        assert_eq!(mirrored(2), Some(symlog_energy(0.0)));
        let at_minus_04 = mirrored(3).expect("within the range");
        assert!((at_minus_04 - symlog_energy(-0.4)).abs() < 1e-12, "{at_minus_04}");
        assert_eq!(mirrored_symlog_energy(&[-0.5, 0.0, 1.0], [2, 0], 0, &energy), None, "beyond the range");
        assert_eq!(mirrored_symlog_energy(&values, [3, 9], 0, &energy), None, "a neighbour failed");
    }

    #[test]
    fn control_points_include_zero_and_span_the_range() {
        let knots = control_points([-0.3, 0.8], 0.95, 5);
        assert_eq!(knots.len(), 11);
        assert_eq!(knots[5], 0.0);
        assert!((knots[0] + 0.95 * 0.3).abs() < 1e-15 && (knots[10] - 0.95 * 0.8).abs() < 1e-15);
        assert!(knots.windows(2).all(|w| w[0] < w[1]));
        assert_eq!(control_points([0.0, 1.0], 0.9, 4), vec![0.0, 0.225, 0.45, 0.675, 0.9]);
    }
}
