//! Two spline materials' 1D terms compared over the strains both were fitted on (`yarnhom fit
//! compare`): e.g. our fit of a published pattern against the published fit of it.

use yarnhom_artifacts::Spline;
use yarnhom_artifacts::grid::AXIS_NAMES;
use yarnhom_geom::stats::{correlation, root_mean_square};

use crate::SplineMaterial;

/// Points along each compared range.
const POINTS: u32 = 100;

/// How two materials' 1D term along one axis compare.
#[derive(Debug, Clone, PartialEq)]
pub struct TermComparison {
    /// The strain axis (0-4: `sx, sa, sy, kx, ky`).
    pub axis: usize,
    /// The strains compared: the overlap of both terms' knot ranges.
    pub range: [f64; 2],
    /// RMS of each term's energy relative to its value at zero strain (J/m²).
    pub rms: [f64; 2],
    /// RMS of their difference (J/m²).
    pub rms_difference: f64,
    /// Pearson correlation of the two curves: 1 for the same shape up to scale.
    pub shape_correlation: f64,
}

/// The 1D terms both `a` and `b` have, over the overlap of their knot ranges, each relative to
/// its value at zero strain, at 101 evenly spaced strains.
pub fn compare_1d_terms(a: &Spline, b: &Spline) -> Vec<TermComparison> {
    let (ma, mb) = (SplineMaterial::from(a), SplineMaterial::from(b));
    (0..5)
        .filter_map(|axis| {
            let (ra, rb) = (knot_range(a, axis)?, knot_range(b, axis)?);
            let (lo, hi) = (ra[0].max(rb[0]), ra[1].min(rb[1]));
            let xs: Vec<f64> =
                (0..=POINTS).map(|k| lo + (hi - lo) * f64::from(k) / f64::from(POINTS)).collect();
            let (ca, cb) = (relative_curve(&ma, axis, &xs)?, relative_curve(&mb, axis, &xs)?);
            let difference = ca.iter().zip(&cb).map(|(x, y)| x - y);
            Some(TermComparison {
                axis,
                range: [lo, hi],
                rms: [root_mean_square(ca.iter().copied()), root_mean_square(cb.iter().copied())],
                rms_difference: root_mean_square(difference),
                shape_correlation: correlation(&ca, &cb),
            })
        })
        .collect()
}

/// The comparison of `a` and `b` as `yarnhom fit compare` prints it: a table of
/// [`compare_1d_terms`], a row per term.
pub fn comparison_report(a: &Spline, b: &Spline) -> String {
    let mut report = format!(
        "1D terms of '{}' and '{}' (energy relative to rest, J/m²) over the strains both were fitted on:\n",
        a.name, b.name
    );
    report += "  term  range                 RMS first  RMS second  RMS difference  shape correlation";
    for c in compare_1d_terms(a, b) {
        report += &format!(
            "\n  {:4}  [{:8.3}, {:8.3}]  {:10.4e} {:11.4e} {:15.4e} {:18.3}",
            AXIS_NAMES[c.axis],
            c.range[0],
            c.range[1],
            c.rms[0],
            c.rms[1],
            c.rms_difference,
            c.shape_correlation
        );
    }
    report
}

/// The strain range `[lo, hi]` a spline's 1D term has knots over (its fitted range).
fn knot_range(spline: &Spline, axis: usize) -> Option<[f64; 2]> {
    let term = spline.terms_1d.iter().find(|t| t.axis as usize == axis)?;
    let scale = spline.strain_scale[axis];
    Some([term.knots[0] * scale, term.knots[term.knots.len() - 1] * scale])
}

/// A 1D term at `xs`, relative to its value at zero strain.
fn relative_curve(m: &SplineMaterial, axis: usize, xs: &[f64]) -> Option<Vec<f64>> {
    let zero = m.term_1d(axis, 0.0)?;
    xs.iter().map(|&x| m.term_1d(axis, x).map(|v| v - zero)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_material_matches_itself_and_a_scaled_copy_only_in_shape() {
        let spline =
            crate::fit_grid(&crate::synthetic::synthetic_grid(), &Default::default(), 0.3).expect("fit");
        let same = compare_1d_terms(&spline, &spline);
        assert_eq!(same.len(), 5);
        for c in &same {
            assert_eq!(c.rms_difference, 0.0);
            assert!((c.shape_correlation - 1.0).abs() < 1e-12, "{c:?}");
            assert!(c.rms[0] > 0.0);
        }
        let mut doubled = spline.clone();
        for term in &mut doubled.terms_1d {
            term.values.iter_mut().for_each(|v| *v *= 2.0);
            term.slopes.iter_mut().for_each(|v| *v *= 2.0);
        }
        for (c, d) in same.iter().zip(compare_1d_terms(&spline, &doubled)) {
            assert!((d.rms[1] - 2.0 * c.rms[0]).abs() <= 1e-12 * c.rms[0], "{d:?}");
            assert!((d.rms_difference - c.rms[0]).abs() <= 1e-12 * c.rms[0]);
            assert!((d.shape_correlation - 1.0).abs() < 1e-12);
        }
    }
}
