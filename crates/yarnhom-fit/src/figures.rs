//! Figures of a spline fit against the grid it was fitted to, like the thesis' Fig. 4.4 (1D
//! terms: data, fit and control points) and Fig. 4.5 (2D terms: data, sum of the 1D fits, 2D
//! residual, cumulative fit and its error), as figure data for `yarnhom_figures`.

use yarnhom_artifacts::grid::{AXIS_NAMES, strain_from_values};
use yarnhom_artifacts::{Grid, GridTerm, Spline, StrainSample};
use yarnhom_figures::{
    Cell, Chart, ChartStyle, Colour, ColourScale, Figure, HeatMap, Mark, Panel, Series, finite_range,
};

use crate::SplineMaterial;

/// Size of a 1D figure (px).
const SIZE_1D: (u32, u32) = (820, 580);
/// Width of one panel of a 2D figure and the figure's height (px).
const PANEL_2D: (u32, u32) = (380, 540);
/// Points of the fitted line of a 1D figure.
const LINE_POINTS: usize = 400;
/// Cells per axis of the fitted panels of a 2D figure.
const CELLS_2D: usize = 40;
/// A 1D figure shows this multiple of the sampled range (each end scaled) to show extrapolation.
const EXTEND_1D: f64 = 1.2;
/// A 2D figure shows the sampled range widened by this fraction of its width on each side.
const MARGIN_2D: f64 = 0.08;
/// Dashes of each line that marks an end of the sampled range in a 1D figure.
const DASHES: usize = 20;
/// Data points (Fig. 4.4: blue).
const DATA: Colour = Colour::rgb(0x1F, 0x5F, 0xD0);
/// The fit (Fig. 4.4: green).
const FIT: Colour = Colour::rgb(0x1A, 0x9A, 0x3A);
const ENERGY_LABEL: &str = "energy density Ψ [J/m²]";

/// The figures of `spline` fitted to `grid`, each with its file name: one `1d-<axis>.svg` per
/// 1D term of the grid (Fig. 4.4) and one `2d-<u>-<v>.svg` per 2D term (Fig. 4.5), in the
/// order of the grid's terms.
pub fn fit_figures(grid: &Grid, spline: &Spline) -> Vec<(String, Figure)> {
    let material = SplineMaterial::from(spline);
    let figure = |t: usize, term: &GridTerm| match *term.axes.as_slice() {
        [axis] => Some((format!("1d-{}.svg", axis_name(axis)), figure_1d(grid, t, spline, &material))),
        [u, v] => Some((format!("2d-{}-{}.svg", axis_name(u), axis_name(v)), figure_2d(grid, t, &material))),
        _ => None,
    };
    grid.terms.iter().enumerate().filter_map(|(t, term)| figure(t, term)).collect()
}

fn axis_name(axis: u8) -> &'static str {
    AXIS_NAMES.get(axis as usize).copied().unwrap_or("unknown")
}

/// Axis description with units: in-plane strains are dimensionless, curvatures in 1/m.
fn axis_label(axis: u8) -> String {
    let unit = if axis < 3 { "-" } else { "1/m" };
    format!("{} [{unit}]", axis_name(axis))
}

/// The strain with `axes[k] = values[k]`, all other parameters 0.
fn strain(axes: &[u8], values: &[f64]) -> StrainSample {
    let mut v = [0.0; 5];
    for (&a, &x) in axes.iter().zip(values) {
        v[a as usize] = x;
    }
    strain_from_values(v)
}

/// `[lo, hi]` made non-degenerate.
fn non_degenerate((lo, hi): (f64, f64)) -> (f64, f64) {
    if hi > lo {
        (lo, hi)
    } else {
        let pad = if lo == 0.0 { 1.0 } else { 0.1 * lo.abs() };
        (lo - pad, hi + pad)
    }
}

/// The sampled range of one of a term's axes.
fn sampled_range(values: &[f64]) -> (f64, f64) {
    (values.first().copied().unwrap_or(0.0), values.last().copied().unwrap_or(0.0))
}

/// The converged samples of the 1D term `t` along axis `a`: `(strain, energy density)`.
fn converged_samples_1d(grid: &Grid, t: usize, a: usize) -> Vec<(f64, f64)> {
    grid.samples
        .iter()
        .filter(|s| s.term as usize == t && s.converged)
        .filter_map(|s| {
            s.energy_density_j_m2
                .map(|e| ([s.strain.sx, s.strain.sa, s.strain.sy, s.strain.kx, s.strain.ky][a], e))
        })
        .collect()
}

/// `energy` at `LINE_POINTS` evenly spaced points of `[x_lo, x_hi]`, where it is finite.
fn fitted_line(x_lo: f64, x_hi: f64, energy: impl Fn(f64) -> f64) -> Vec<(f64, f64)> {
    (0..LINE_POINTS)
        .map(|k| x_lo + (x_hi - x_lo) * k as f64 / (LINE_POINTS - 1) as f64)
        .map(|x| (x, energy(x)))
        .filter(|p| p.1.is_finite())
        .collect()
}

/// The control points of the spline's 1D term of `axis` (in strain), on the fitted energy.
fn control_points(spline: &Spline, axis: u8, energy: impl Fn(f64) -> f64) -> Vec<(f64, f64)> {
    let scale = spline.strain_scale[axis as usize];
    spline
        .terms_1d
        .iter()
        .find(|c| c.axis == axis)
        .map(|c| c.knots.iter().map(|k| k * scale).map(|x| (x, energy(x))).collect())
        .unwrap_or_default()
}

/// A dashed vertical line at `x` over `[y_lo, y_lo + height]`.
fn dashed_vertical(x: f64, y_lo: f64, height: f64) -> Series {
    let points = (0..DASHES)
        .flat_map(|k| {
            let y0 = y_lo + height * k as f64 / DASHES as f64;
            [(x, y0), (x, y0 + 0.5 * height / DASHES as f64)]
        })
        .collect();
    Series { label: None, mark: Mark::Segments, colour: Colour::BLACK.with_opacity(0.4), points }
}

fn labelled(label: &str, mark: Mark, colour: Colour, points: Vec<(f64, f64)>) -> Series {
    Series { label: Some(label.into()), mark, colour, points }
}

/// Fig. 4.4 for term `t` (1D): converged samples, the fitted energy along the axis (beyond the
/// sampled range, marked by dashed lines), and the spline's control points.
fn figure_1d(grid: &Grid, t: usize, spline: &Spline, material: &SplineMaterial) -> Figure {
    let term = &grid.terms[t];
    let axis = term.axes[0];
    let data = converged_samples_1d(grid, t, axis as usize);
    let (lo, hi) = sampled_range(&term.values[0]);
    let (x_lo, x_hi) = non_degenerate((EXTEND_1D * lo.min(0.0), EXTEND_1D * hi.max(0.0)));
    let energy = |x: f64| material.energy_at(&strain(&[axis], &[x]));
    let line = fitted_line(x_lo, x_hi, energy);
    let control = control_points(spline, axis, energy);
    let (y_lo, y_hi) = non_degenerate(
        finite_range(data.iter().chain(&line).chain(&control).map(|p| p.1)).unwrap_or((0.0, 1.0)),
    );
    let pad = 0.05 * (y_hi - y_lo);
    let height = y_hi - y_lo + 2.0 * pad;
    let chart = Chart {
        title: format!("{}: 1D term {} (data, fit, control points)", grid.pattern, term.name()),
        x_label: axis_label(axis),
        y_label: ENERGY_LABEL.into(),
        x_range: (x_lo, x_hi),
        y_range: (y_lo - pad, y_hi + pad),
        series: vec![
            labelled("fit (total energy)", Mark::Polyline, FIT, line),
            labelled("data (converged samples)", Mark::Dots { radius: 3, legend_radius: 3 }, DATA, data),
            labelled("control points", Mark::Dots { radius: 4, legend_radius: 4 }, Colour::BLACK, control),
            // The sampled range: the fit beyond it is extrapolated.
            dashed_vertical(lo, y_lo - pad, height),
            dashed_vertical(hi, y_lo - pad, height),
        ],
        style: ChartStyle::Large,
    };
    Figure { panel_size: SIZE_1D, columns: 1, title: None, panels: vec![Panel::Chart(chart)] }
}

/// Cell boundaries around sampled values: midpoints, the outer ones at `[lo, hi]`.
fn cell_bounds(values: &[f64], lo: f64, hi: f64) -> Vec<f64> {
    let mut bounds = vec![lo];
    bounds.extend(values.windows(2).map(|w| 0.5 * (w[0] + w[1])));
    bounds.push(hi);
    bounds
}

/// The energy density of the 2D term `t`'s converged samples, `[j * us + i]` for sample
/// `(i, j)`; NaN where missing or not converged.
fn sampled_energies(grid: &Grid, t: usize, (nu, nv): (usize, usize)) -> Vec<f64> {
    let mut data = vec![f64::NAN; nu * nv];
    for s in grid.samples.iter().filter(|s| s.term as usize == t) {
        let (i, j) = (s.index[0] as usize, s.index[1] as usize);
        if let (Some(e), true, true) = (s.energy_density_j_m2.filter(|_| s.converged), i < nu, j < nv) {
            data[j * nu + i] = e;
        }
    }
    data
}

/// A cell around each of the `nu × nv` samples `(i, j)` (cell bounds `ub`, `vb`) with
/// `value(i, j)`, row by row.
fn cells_at_samples(
    (ub, vb): (&[f64], &[f64]),
    (nu, nv): (usize, usize),
    value: impl Fn(usize, usize) -> f64,
) -> Vec<Cell> {
    let mut cells = Vec::with_capacity(nu * nv);
    for j in 0..nv {
        for i in 0..nu {
            cells.push(Cell { x: (ub[i], ub[i + 1]), y: (vb[j], vb[j + 1]), value: value(i, j) });
        }
    }
    cells
}

/// `CELLS_2D × CELLS_2D` cells over `[u_lo, u_hi] × [v_lo, v_hi]`, each with `f` at its centre.
fn dense_cells((u_lo, u_hi): (f64, f64), (v_lo, v_hi): (f64, f64), f: impl Fn(f64, f64) -> f64) -> Vec<Cell> {
    let (du, dv) = ((u_hi - u_lo) / CELLS_2D as f64, (v_hi - v_lo) / CELLS_2D as f64);
    let mut cells = Vec::with_capacity(CELLS_2D * CELLS_2D);
    for j in 0..CELLS_2D {
        for i in 0..CELLS_2D {
            let (u0, v0) = (u_lo + i as f64 * du, v_lo + j as f64 * dv);
            cells.push(Cell { x: (u0, u0 + du), y: (v0, v0 + dv), value: f(u0 + 0.5 * du, v0 + 0.5 * dv) });
        }
    }
    cells
}

/// The five maps of Fig. 4.5, `(title, cells, scale)`: data, sum of the 1D fits, 2D residual,
/// cumulative fit, |fit − data|.
fn maps_2d(
    grid: &Grid,
    t: usize,
    material: &SplineMaterial,
    ranges: ((f64, f64), (f64, f64)),
) -> [(&'static str, Vec<Cell>, ColourScale); 5] {
    let term: &GridTerm = &grid.terms[t];
    let (u_axis, v_axis) = (term.axes[0], term.axes[1]);
    let (us, vs) = (&term.values[0], &term.values[1]);
    let ((u_lo, u_hi), (v_lo, v_hi)) = ranges;
    let size = (us.len(), vs.len());
    let data = sampled_energies(grid, t, size);
    let (ub, vb) = (cell_bounds(us, u_lo, u_hi), cell_bounds(vs, v_lo, v_hi));
    let bounds = (ub.as_slice(), vb.as_slice());
    let cumulative = |u: f64, v: f64| material.energy_at(&strain(&term.axes, &[u, v]));
    let data_cells = cells_at_samples(bounds, size, |i, j| data[j * us.len() + i]);
    let error_cells =
        cells_at_samples(bounds, size, |i, j| (cumulative(us[i], vs[j]) - data[j * us.len() + i]).abs());
    let f0 = material.energy_at(&strain(&[], &[]));
    let term_1d = |axis: u8, x: f64| material.term_1d(axis as usize, x).unwrap_or(0.0);
    let axes = [u_axis as usize, v_axis as usize];
    let sum_1d = dense_cells(ranges.0, ranges.1, |u, v| f0 + term_1d(u_axis, u) + term_1d(v_axis, v));
    let residual = dense_cells(ranges.0, ranges.1, |u, v| material.term_2d(axes, u, v).unwrap_or(f64::NAN));
    let fit = dense_cells(ranges.0, ranges.1, cumulative);
    let values = |cells: &[Cell]| cells.iter().map(|c| c.value).collect::<Vec<_>>();
    let energy_scale =
        ColourScale::sequential(values(&data_cells).into_iter().chain(values(&sum_1d)).chain(values(&fit)));
    let (residual_scale, error_scale) =
        (ColourScale::signed(values(&residual)), ColourScale::sequential(values(&error_cells)));
    [
        ("data (nearest sample)", data_cells, energy_scale),
        ("sum of 1D fits f0 + fu + fv", sum_1d, energy_scale),
        ("2D residual term fuv", residual, residual_scale),
        ("cumulative fit", fit, energy_scale),
        ("|fit − data| at the samples", error_cells, error_scale),
    ]
}

/// Fig. 4.5 for term `t` (2D): heat maps of data, sum of 1D fits, 2D residual, cumulative fit,
/// |fit − data|, over the sampled range (outlined) widened by `MARGIN_2D`.
fn figure_2d(grid: &Grid, t: usize, material: &SplineMaterial) -> Figure {
    let term = &grid.terms[t];
    let widen = |(lo, hi): (f64, f64)| {
        let (lo, hi) = non_degenerate((lo, hi));
        (lo - MARGIN_2D * (hi - lo), hi + MARGIN_2D * (hi - lo))
    };
    let (u_range, v_range) = (sampled_range(&term.values[0]), sampled_range(&term.values[1]));
    let (x_range, y_range) = (widen(u_range), widen(v_range));
    let panels: Vec<Panel> = maps_2d(grid, t, material, (x_range, y_range))
        .into_iter()
        .map(|(title, cells, scale)| {
            Panel::HeatMap(HeatMap {
                title: title.into(),
                x_label: axis_label(term.axes[0]),
                y_label: axis_label(term.axes[1]),
                x_range,
                y_range,
                cells,
                outline: [(u_range.0, v_range.0), (u_range.1, v_range.1)],
                scale,
            })
        })
        .collect();
    let title = format!(
        "{}: 2D term {} (energy density Ψ in J/m², colour scale sgn(Ψ) ln(1 + |Ψ|); box: sampled range; grey: no data)",
        grid.pattern,
        term.name()
    );
    Figure { panel_size: PANEL_2D, columns: panels.len(), title: Some(title), panels }
}

#[cfg(test)]
mod tests {
    use super::*;
    use yarnhom_artifacts::FitSettings;

    /// The synthetic thesis-shaped grid, with one failed solve in the `sx,kx` term.
    fn grid() -> Grid {
        let mut grid = crate::synthetic::synthetic_grid();
        let term = grid.terms.iter().position(|t| t.axes == [0, 3]).expect("sx,kx term") as u32;
        let failed = grid.samples.iter_mut().rfind(|s| s.term == term).expect("corner sample");
        failed.converged = false;
        failed.stop_reason = "iteration_limit".into();
        failed.energy_density_j_m2 = None;
        grid.validate().expect("valid synthetic grid");
        grid
    }

    fn title(panel: &Panel) -> &str {
        match panel {
            Panel::Chart(c) => &c.title,
            Panel::HeatMap(m) => &m.title,
        }
    }

    #[test]
    fn a_figure_per_term_named_by_its_axes() {
        let grid = grid();
        let spline = crate::fit_grid(&grid, &FitSettings::default(), 0.3).expect("fit");
        let figures = fit_figures(&grid, &spline);
        let names: Vec<&str> = figures.iter().map(|(name, _)| name.as_str()).collect();
        let expected: Vec<String> = grid
            .terms
            .iter()
            .map(|t| format!("{}d-{}.svg", t.axes.len(), t.name().replace(',', "-")))
            .collect();
        assert_eq!(names, expected);
        for ((name, figure), term) in figures.iter().zip(&grid.terms) {
            let shown = figure.title.iter().map(String::as_str).chain(figure.panels.iter().map(title));
            let text: String = shown.collect();
            assert!(text.contains(&term.name()) && text.contains("synthetic"), "{name}: {text}");
            assert_eq!(figure.panels.len(), if term.axes.len() == 1 { 1 } else { 5 }, "{name}");
        }
    }

    #[test]
    fn a_1d_figure_shows_the_samples_the_extrapolated_fit_and_the_control_points() {
        let grid = grid();
        let spline = crate::fit_grid(&grid, &FitSettings::default(), 0.3).expect("fit");
        let t = grid.terms.iter().position(|t| t.axes == [0]).expect("sx term");
        let Panel::Chart(chart) = &figure_1d(&grid, t, &spline, &SplineMaterial::from(&spline)).panels[0]
        else {
            panic!("a chart")
        };
        let samples = grid.samples.iter().filter(|s| s.term as usize == t).count();
        let [line, data, control, low, high] = chart.series.as_slice() else { panic!("five series") };
        assert_eq!(data.points.len(), samples);
        assert_eq!(line.points.len(), LINE_POINTS);
        let (lo, hi) = sampled_range(&grid.terms[t].values[0]);
        assert!(line.points[0].0 < lo && line.points[LINE_POINTS - 1].0 > hi, "beyond the sampled range");
        assert_eq!(
            control.points.len(),
            spline.terms_1d.iter().find(|c| c.axis == 0).expect("sx").knots.len()
        );
        for (dashes, x) in [(low, lo), (high, hi)] {
            assert_eq!((dashes.label.as_deref(), dashes.points.len()), (None, 2 * DASHES));
            assert!(dashes.points.iter().all(|p| p.0 == x));
        }
    }

    #[test]
    fn a_2d_figure_leaves_a_failed_sample_missing() {
        let grid = grid();
        let spline = crate::fit_grid(&grid, &FitSettings::default(), 0.3).expect("fit");
        let t = grid.terms.iter().position(|t| t.axes == [0, 3]).expect("sx,kx term");
        let figure = figure_2d(&grid, t, &SplineMaterial::from(&spline));
        let maps: Vec<&HeatMap> = figure
            .panels
            .iter()
            .map(|p| match p {
                Panel::HeatMap(m) => m,
                Panel::Chart(_) => panic!("a chart"),
            })
            .collect();
        let samples = grid.samples.iter().filter(|s| s.term as usize == t).count();
        let missing = |m: &HeatMap| m.cells.iter().filter(|c| !c.value.is_finite()).count();
        assert_eq!(
            (maps[0].cells.len(), missing(maps[0])),
            (samples, 1),
            "data: the failed sample is missing"
        );
        assert_eq!((maps[4].cells.len(), missing(maps[4])), (samples, 1), "and so is its error");
        for m in &maps[1..4] {
            assert_eq!((m.cells.len(), missing(m)), (CELLS_2D * CELLS_2D, 0), "{}", m.title);
        }
        assert_eq!(maps[1].scale, maps[0].scale, "data and fits on one scale");
        assert_eq!(maps[2].scale.lo, -maps[2].scale.hi, "the residual's scale is symmetric");
        let (lo, hi) = sampled_range(&grid.terms[t].values[0]);
        assert!(maps[0].x_range.0 < lo && maps[0].outline[0].0 == lo && maps[0].outline[1].0 == hi);
    }
}
