//! What `yarnhom fit` prints about a fit: its relative RMS error on every term of its grid (the
//! acceptance figure of Sec. 4.3), and whether each quasiconvexified term, and the material's
//! energy on each term's axis or plane, has a single minimum along its lines (A.36).

use yarnhom_artifacts::{BicubicTerm, Grid, Spline};

use crate::{SplineMaterial, TermShape, fit_errors, regularized_term_shapes, term_shapes};

/// Shape checks' tolerance on a rise between neighbouring points (J/m²).
const SHAPE_TOLERANCE: f64 = 1e-6;

/// The error table and the shape table of `spline` fitted to `grid` (with its regularized 2D
/// fits `regularized_2d`); errors of the shear terms against the mirror-averaged data when the
/// fit symmetrized shear.
pub fn fit_report(
    grid: &Grid,
    spline: &Spline,
    regularized_2d: &[BicubicTerm],
    symmetrized_shear: bool,
) -> String {
    format!("{}\n{}", error_table(grid, spline, symmetrized_shear), shape_table(grid, spline, regularized_2d))
}

/// The fit's relative RMS error on each term of its grid: of Ψ, of Ψ - f0, and as modelled.
fn error_table(grid: &Grid, spline: &Spline, symmetrized_shear: bool) -> String {
    let material = SplineMaterial::from(spline);
    let mut lines = vec![format!(
        "relative RMS error of the fit on its grid: of Ψ; of Ψ - f0; of Ψ as modelled (2D terms without compression, A.3.6{}):",
        if symmetrized_shear { "; symmetrized in sa, Sec. 4.1" } else { "" }
    )];
    for e in fit_errors(grid, &material, spline.rest_energy_density_j_m2, symmetrized_shear) {
        let modelled = e
            .relative_rms_modelled
            .map_or("-".to_string(), |r| format!("{:6.2}% ({} samples)", 100.0 * r, e.samples_modelled));
        lines.push(format!(
            "  {:8} {:5} samples  {:6.2}%  {:6.2}%  {modelled}",
            e.term,
            e.samples,
            100.0 * e.relative_rms,
            100.0 * e.relative_rms_deformation
        ));
    }
    lines.join("\n")
}

/// Per term: a single minimum along every line, of the quasiconvexified term and of the
/// material's energy on the term's axis or plane.
fn shape_table(grid: &Grid, spline: &Spline, regularized_2d: &[BicubicTerm]) -> String {
    let mut lines = vec![
        "single minimum along every line through each term's control points, halfway between them and \
         along the edges, over 1.5x the sampled range (A.36); of each quasiconvexified term (the 1D \
         terms, the 2D terms' regularized fits f*, Sec. 4.1.2) / of the material's energy on the term's \
         axis or plane (f0 + f_u + f_v + f_uv, their sum, which the thesis allows more minima):"
            .to_string(),
    ];
    let terms = regularized_term_shapes(grid, spline, regularized_2d, SHAPE_TOLERANCE);
    for (term, material) in terms.iter().zip(term_shapes(grid, spline, SHAPE_TOLERANCE)) {
        lines.push(format!("  {:8} {} / {}", term.term, verdict(term), verdict(&material)));
    }
    lines.join("\n")
}

/// `yes (N lines)` or `NO on K of N lines, e.g. ...`.
fn verdict(shape: &TermShape) -> String {
    match shape.violations.first() {
        None => format!("yes ({} lines)", shape.lines),
        Some(first) => format!("NO on {} of {} lines, e.g. {first}", shape.violations.len(), shape.lines),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::POISSON_PAIR;

    #[test]
    fn the_report_has_a_row_per_term_in_each_table() {
        let grid = crate::synthetic::synthetic_grid();
        let fit = crate::fit_grid_with_regularized_terms(&grid, &Default::default(), 0.3).expect("fit");
        let report = fit_report(&grid, &fit.spline, &fit.regularized_2d, true);
        let rows =
            |term: &str| report.lines().filter(|l| l.trim_start().starts_with(&format!("{term} "))).count();
        assert_eq!(grid.terms.len(), 14);
        // An error row for every term; a shape row for every term but the Poisson pair sx,sy,
        // whose fit is not marched (A.3.6).
        for term in &grid.terms {
            let expected = if term.axes.as_slice() == POISSON_PAIR { 1 } else { 2 };
            assert_eq!(rows(&term.name()), expected, "{}: error and shape rows\n{report}", term.name());
        }
        assert!(report.contains("symmetrized in sa"));
    }
}
