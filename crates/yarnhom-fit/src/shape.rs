//! Checks of a fitted material's shape (A.36), along the lines of each marched term's axis or
//! plane: every line through its control points, halfway between them and along the edges of
//! the checked region, over 1.5 times the sampled range.
//!
//! - [`regularized_term_shapes`]: each quasiconvexified term has a single minimum, the thesis'
//!   criterion ("we want to enforce that individual terms `f_i` and `f_ij` have a single
//!   well-defined minimum", Sec. 4.1.2): a 1D term along its axis, a 2D term's regularized fit
//!   `f*_uv` (A.3.6) on its plane.
//! - [`term_shapes`]: the same of the material's energy on each plane, `f0 + f_u + f_v + f_uv`,
//!   the aggregate of the terms, which "can still produce multiple minima" (ibid.).

use yarnhom_artifacts::grid::{AXIS_NAMES, strain_from_values};
use yarnhom_artifacts::{BicubicTerm, Grid, GridTerm, Spline, StrainSample};

use crate::SplineMaterial;
use crate::fit::POISSON_PAIR;
use crate::hermite::Bicubic;

/// Points per line.
const POINTS: usize = 1501;

/// The shape check of one term.
#[derive(Debug, Clone, PartialEq)]
pub struct TermShape {
    /// The term's name.
    pub term: String,
    /// Lines checked.
    pub lines: usize,
    /// Where a line stops being unimodal: `(line, strain)` descriptions.
    pub violations: Vec<String>,
}

/// Where `ys` (ordered) stops being unimodal: `None` if it does not rise more than `tol` above
/// its running minimum before its global minimum, nor fall more than `tol` below its running
/// maximum after it (plateaus are allowed); else the offending index.
pub fn unimodality_violation(ys: &[f64], tol: f64) -> Option<usize> {
    let m = (0..ys.len()).min_by(|&a, &b| ys[a].total_cmp(&ys[b]))?;
    let mut low = ys[0];
    for (i, &y) in ys.iter().enumerate().take(m + 1) {
        if y > low + tol {
            return Some(i);
        }
        low = low.min(y);
    }
    let mut high = ys[m];
    for (i, &y) in ys.iter().enumerate().skip(m) {
        if y < high - tol {
            return Some(i);
        }
        high = high.max(y);
    }
    None
}

/// `n` values from `a` to `b`.
fn linspace(a: f64, b: f64, n: usize) -> Vec<f64> {
    (0..n).map(|i| a + (b - a) * i as f64 / (n - 1) as f64).collect()
}

fn strain_along(axes: &[u8], values: &[f64]) -> StrainSample {
    let mut v = [0.0; 5];
    for (&a, &x) in axes.iter().zip(values) {
        v[a as usize] = x;
    }
    strain_from_values(v)
}

fn value_range(ys: &[f64]) -> f64 {
    ys.iter().copied().fold(f64::NEG_INFINITY, f64::max) - ys.iter().copied().fold(f64::INFINITY, f64::min)
}

/// The shape check of the material's energy on every marched term's axis or plane, over the
/// ranges of `grid`; plateaus up to `relative_tolerance` of a term's energy range are allowed.
pub fn term_shapes(grid: &Grid, spline: &Spline, relative_tolerance: f64) -> Vec<TermShape> {
    let material = SplineMaterial::from(spline);
    shapes(grid, spline, relative_tolerance, |term, values| {
        material.energy_at(&strain_along(&term.axes, values))
    })
}

/// The shape check of every quasiconvexified term of a fit: its 1D terms along their axes and
/// its regularized 2D fits `regularized_2d` (see [`crate::fit::RegularizedFit`]) on their planes,
/// over the ranges of `grid`; tolerance as in [`term_shapes`].
pub fn regularized_term_shapes(
    grid: &Grid,
    spline: &Spline,
    regularized_2d: &[BicubicTerm],
    relative_tolerance: f64,
) -> Vec<TermShape> {
    let material = SplineMaterial::from(spline);
    let patches: Vec<([u8; 2], Bicubic)> =
        regularized_2d.iter().map(|t| (t.axes, Bicubic::from(t))).collect();
    let scale = |axis: u8| spline.strain_scale[axis as usize];
    shapes(grid, spline, relative_tolerance, |term, values| match term.axes.as_slice() {
        &[u, v] => match patches.iter().find(|(axes, _)| *axes == [u, v]) {
            Some((_, patch)) => patch.value(values[0] / scale(u), values[1] / scale(v)),
            // Reported as a term without a finite energy.
            None => f64::NAN,
        },
        _ => material.energy_at(&strain_along(&term.axes, values)),
    })
}

/// The shape check of `energy(term, strain values on its axes)` along each marched term's lines.
fn shapes(
    grid: &Grid,
    spline: &Spline,
    relative_tolerance: f64,
    energy: impl Fn(&GridTerm, &[f64]) -> f64,
) -> Vec<TermShape> {
    grid.terms
        .iter()
        .filter(|t| t.axes.as_slice() != POISSON_PAIR)
        .map(|term| {
            let ranges: Vec<Vec<f64>> =
                term.values.iter().map(|v| linspace(1.5 * v[0], 1.5 * v[v.len() - 1], POINTS)).collect();
            let lines = checked_lines(spline, &term.axes, &ranges);
            let energies: Vec<Vec<f64>> =
                lines.iter().map(|line| line.iter().map(|p| energy(term, p)).collect()).collect();
            let tol = relative_tolerance * value_range(&energies.concat());
            let violations = lines
                .iter()
                .zip(&energies)
                .filter_map(|(line, ys)| match ys.iter().position(|y| !y.is_finite()) {
                    Some(i) => Some(format!("no finite energy at {}", at(&term.axes, &line[i]))),
                    None => unimodality_violation(ys, tol)
                        .map(|i| format!("a second minimum near {}", at(&term.axes, &line[i]))),
                })
                .collect();
            TermShape { term: term.name(), lines: lines.len(), violations }
        })
        .collect()
}

/// The lines of a term: its axis for a 1D term; for a 2D term, along `u` at every `v` control
/// point, halfway between neighbouring ones and at both ends of the checked `v` range (where
/// the patch extrapolates, A.3.5), and likewise along `v` (points as strain values of the axes).
fn checked_lines(spline: &Spline, axes: &[u8], ranges: &[Vec<f64>]) -> Vec<Vec<Vec<f64>>> {
    let Some(term) = spline.terms_2d.iter().find(|t| t.axes.as_slice() == axes) else {
        return vec![ranges[0].iter().map(|&x| vec![x]).collect()];
    };
    let at = |knots: &[f64], axis: u8, range: &[f64]| -> Vec<f64> {
        let scale = spline.strain_scale[axis as usize];
        let mut at: Vec<f64> = knots.iter().map(|&k| k * scale).collect();
        at.extend(knots.windows(2).map(|w| 0.5 * (w[0] + w[1]) * scale));
        at.extend([range[0], range[range.len() - 1]]);
        at
    };
    let along_u = at(&term.v_knots, axes[1], &ranges[1])
        .into_iter()
        .map(|v| ranges[0].iter().map(|&u| vec![u, v]).collect::<Vec<_>>());
    let along_v = at(&term.u_knots, axes[0], &ranges[0])
        .into_iter()
        .map(|u| ranges[1].iter().map(|&v| vec![u, v]).collect::<Vec<_>>());
    along_u.chain(along_v).collect()
}

/// A point of a term's plane or axis, e.g. `sx = 0.1000, kx = -20.0000`.
fn at(axes: &[u8], point: &[f64]) -> String {
    let name = |a: u8| AXIS_NAMES.get(a as usize).copied().unwrap_or("?");
    let parts: Vec<String> = axes.iter().zip(point).map(|(&a, x)| format!("{} = {x:.4}", name(a))).collect();
    parts.join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unimodality_allows_plateaus_and_finds_second_minima() {
        assert_eq!(unimodality_violation(&[3.0, 2.0, 2.0, 1.0, 1.0, 4.0], 0.0), None);
        assert_eq!(unimodality_violation(&[3.0, 1.0, 2.0, 0.5, 4.0], 0.0), Some(2));
        assert_eq!(unimodality_violation(&[0.0, 2.0, 1.0, 3.0], 0.0), Some(2));
        assert_eq!(unimodality_violation(&[0.0, 2.0, 1.9, 3.0], 0.2), None);
    }
}
