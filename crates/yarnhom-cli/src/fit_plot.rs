//! `yarnhom fit plot`: figures of a spline fit against the grid it was fitted to, like the
//! thesis' Fig. 4.4 (1D terms: data, fit and control points) and Fig. 4.5 (2D terms: data, sum
//! of the 1D fits, 2D residual, cumulative fit and its error), written as SVG.
//!
//! SVG only: text is written as SVG `<text>` elements, so no font is needed (plotters is built
//! without `ttf`/`font-kit`; its bitmap backend cannot draw text without a font rasterizer).

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use plotters::coord::Shift;
use plotters::prelude::*;
use yarnhom_artifacts::grid::{AXIS_NAMES, strain_from_values};
use yarnhom_artifacts::{Grid, GridTerm, Spline};
use yarnhom_fit::SplineMaterial;
// The colour scale of Fig. 4.5 is the symlog of App. A.3.3.
use yarnhom_fit::mls::{symexp, symlog};

/// Size of a 1D figure (px).
const SIZE_1D: (u32, u32) = (820, 580);
/// Width of one panel of a 2D figure and the figure's height (px).
const PANEL_2D: (u32, u32) = (380, 540);
/// Height of the colour bar under each 2D panel (px).
const BAR_HEIGHT: u32 = 70;
/// Points of the fitted line of a 1D figure.
const LINE_POINTS: usize = 400;
/// Cells per axis of the fitted panels of a 2D figure.
const CELLS_2D: usize = 40;
/// A 1D figure shows this multiple of the sampled range (each end scaled) to show extrapolation.
const EXTEND_1D: f64 = 1.2;
/// A 2D figure shows the sampled range widened by this fraction of its width on each side.
const MARGIN_2D: f64 = 0.08;
/// Missing or non-converged samples.
const MISSING: RGBColor = RGBColor(0xBB, 0xBB, 0xBB);
/// Data points (Fig. 4.4: blue).
const DATA: RGBColor = RGBColor(0x1F, 0x5F, 0xD0);
/// The fit (Fig. 4.4: green).
const FIT: RGBColor = RGBColor(0x1A, 0x9A, 0x3A);
pub(crate) const FONT: &str = "sans-serif";

/// Write the figures of `spline` fitted to `grid` into `out_dir` (created if needed): one
/// `1d-<axis>.svg` per 1D term of the grid (Fig. 4.4) and one `2d-<u>-<v>.svg` per 2D term
/// (Fig. 4.5). Returns the paths written, in the order of the grid's terms.
pub fn plot_fit(grid: &Grid, spline: &Spline, out_dir: &Path) -> Result<Vec<PathBuf>> {
    std::fs::create_dir_all(out_dir)
        .with_context(|| format!("cannot create the folder {}", out_dir.display()))?;
    let material = SplineMaterial::from(spline);
    let mut written = Vec::new();
    for (t, term) in grid.terms.iter().enumerate() {
        let (file, svg) = match *term.axes.as_slice() {
            [axis] => (format!("1d-{}.svg", axis_name(axis)), plot_1d(grid, t, spline, &material)?),
            [u, v] => (format!("2d-{}-{}.svg", axis_name(u), axis_name(v)), plot_2d(grid, t, &material)?),
            _ => continue,
        };
        let path = out_dir.join(file);
        std::fs::write(&path, svg).with_context(|| format!("cannot write {}", path.display()))?;
        written.push(path);
    }
    Ok(written)
}

fn axis_name(axis: u8) -> &'static str {
    AXIS_NAMES.get(axis as usize).copied().unwrap_or("unknown")
}

/// Axis description with units: in-plane strains are dimensionless, curvatures in 1/m.
fn axis_label(axis: u8) -> String {
    let unit = if axis < 3 { "-" } else { "1/m" };
    format!("{} [{unit}]", axis_name(axis))
}

const ENERGY_LABEL: &str = "energy density Ψ [J/m²]";

/// A number for a tick label: three significant digits without trailing zeros for moderate
/// magnitudes (so neighbouring ticks 0.005 apart stay distinct), else scientific.
pub(crate) fn format_value(x: f64) -> String {
    let a = x.abs();
    if a == 0.0 || !a.is_finite() {
        format!("{x}")
    } else if (1e-2..1e4).contains(&a) {
        let digits = (2 - a.log10().floor() as i32).clamp(0, 4) as usize;
        let fixed = format!("{x:.digits$}");
        if fixed.contains('.') {
            fixed.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            fixed
        }
    } else {
        format!("{x:.1e}")
    }
}

/// The strain with `axes[k] = values[k]`, all other parameters 0.
fn strain(axes: &[u8], values: &[f64]) -> yarnhom_artifacts::StrainSample {
    let mut v = [0.0; 5];
    for (&a, &x) in axes.iter().zip(values) {
        v[a as usize] = x;
    }
    strain_from_values(v)
}

/// Smallest and largest of the finite numbers; `None` if there is none.
fn finite_range(values: impl IntoIterator<Item = f64>) -> Option<(f64, f64)> {
    values
        .into_iter()
        .filter(|x| x.is_finite())
        .fold(None, |r, x| Some(r.map_or((x, x), |(lo, hi): (f64, f64)| (lo.min(x), hi.max(x)))))
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

/// The sampled range of each of a term's axes.
fn sampled_range(values: &[f64]) -> (f64, f64) {
    (values.first().copied().unwrap_or(0.0), values.last().copied().unwrap_or(0.0))
}

/// Render into an SVG string.
pub(crate) fn render(
    size: (u32, u32),
    draw: impl FnOnce(&DrawingArea<SVGBackend<'_>, Shift>) -> Result<()>,
) -> Result<String> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        root.fill(&WHITE).map_err(plot_error)?;
        draw(&root)?;
        root.present().map_err(plot_error)?;
    }
    Ok(svg)
}

pub(crate) fn plot_error(e: impl std::fmt::Display) -> anyhow::Error {
    anyhow::anyhow!("drawing failed: {e}")
}

/// Fig. 4.4 for term `t` (1D): converged samples, the fitted energy along the axis, and the
/// spline's control points.
fn plot_1d(grid: &Grid, t: usize, spline: &Spline, material: &SplineMaterial) -> Result<String> {
    let term = &grid.terms[t];
    let axis = term.axes[0];
    let a = axis as usize;
    let data: Vec<(f64, f64)> = grid
        .samples
        .iter()
        .filter(|s| s.term as usize == t && s.converged)
        .filter_map(|s| {
            s.energy_density_j_m2
                .map(|e| ([s.strain.sx, s.strain.sa, s.strain.sy, s.strain.kx, s.strain.ky][a], e))
        })
        .collect();
    let (lo, hi) = sampled_range(&term.values[0]);
    let (x_lo, x_hi) = non_degenerate((EXTEND_1D * lo.min(0.0), EXTEND_1D * hi.max(0.0)));
    let energy = |x: f64| material.energy_at(&strain(&[axis], &[x]));
    let line: Vec<(f64, f64)> = (0..LINE_POINTS)
        .map(|k| x_lo + (x_hi - x_lo) * k as f64 / (LINE_POINTS - 1) as f64)
        .map(|x| (x, energy(x)))
        .filter(|p| p.1.is_finite())
        .collect();
    let control: Vec<(f64, f64)> = spline
        .terms_1d
        .iter()
        .find(|c| c.axis == axis)
        .map(|c| c.knots.iter().map(|k| k * spline.strain_scale[a]).map(|x| (x, energy(x))).collect())
        .unwrap_or_default();
    let (y_lo, y_hi) = non_degenerate(
        finite_range(data.iter().chain(&line).chain(&control).map(|p| p.1)).unwrap_or((0.0, 1.0)),
    );
    let pad = 0.05 * (y_hi - y_lo);
    let title = format!("{}: 1D term {} (data, fit, control points)", grid.pattern, term.name());
    render(SIZE_1D, |root| {
        let mut chart = ChartBuilder::on(root)
            .caption(&title, (FONT, 20))
            .margin(12)
            .x_label_area_size(45)
            .y_label_area_size(65)
            .build_cartesian_2d(x_lo..x_hi, (y_lo - pad)..(y_hi + pad))
            .map_err(plot_error)?;
        chart
            .configure_mesh()
            .x_desc(axis_label(axis))
            .y_desc(ENERGY_LABEL)
            .label_style((FONT, 13))
            .axis_desc_style((FONT, 15))
            .x_label_formatter(&|x| format_value(*x))
            .y_label_formatter(&|y| format_value(*y))
            .light_line_style(WHITE.mix(0.0))
            .draw()
            .map_err(plot_error)?;
        chart
            .draw_series(LineSeries::new(line.iter().copied(), FIT.stroke_width(2)))
            .map_err(plot_error)?
            .label("fit (total energy)")
            .legend(|(x, y)| PathElement::new(vec![(x - 8, y), (x + 8, y)], FIT.stroke_width(2)));
        chart
            .draw_series(data.iter().map(|&p| Circle::new(p, 3, DATA.filled())))
            .map_err(plot_error)?
            .label("data (converged samples)")
            .legend(|p| Circle::new(p, 3, DATA.filled()));
        chart
            .draw_series(control.iter().map(|&p| Circle::new(p, 4, BLACK.filled())))
            .map_err(plot_error)?
            .label("control points")
            .legend(|p| Circle::new(p, 4, BLACK.filled()));
        // The sampled range: the fit beyond it is extrapolated.
        for x in [lo, hi] {
            let dashed = (0..20).map(|k| {
                let y0 = y_lo - pad + (y_hi - y_lo + 2.0 * pad) * k as f64 / 20.0;
                PathElement::new(
                    vec![(x, y0), (x, y0 + 0.5 * (y_hi - y_lo + 2.0 * pad) / 20.0)],
                    BLACK.mix(0.4),
                )
            });
            chart.draw_series(dashed).map_err(plot_error)?;
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperMiddle)
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK.mix(0.5))
            .label_font((FONT, 14))
            .draw()
            .map_err(plot_error)
    })
}

/// A colour map: piecewise linear through anchors at equally spaced `t ∈ [0, 1]`.
fn ramp(anchors: &[(u8, u8, u8)], t: f64) -> RGBColor {
    let t = if t.is_finite() { t.clamp(0.0, 1.0) } else { 0.0 };
    let x = t * (anchors.len() - 1) as f64;
    let k = (x.floor() as usize).min(anchors.len() - 2);
    let f = x - k as f64;
    let (a, b) = (anchors[k], anchors[k + 1]);
    let mix = |p: u8, q: u8| (p as f64 + f * (q as f64 - p as f64)).round() as u8;
    RGBColor(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

/// Viridis, sampled at nine points.
const VIRIDIS: [(u8, u8, u8); 9] = [
    (68, 1, 84),
    (71, 44, 122),
    (59, 81, 139),
    (44, 113, 142),
    (33, 144, 141),
    (39, 173, 129),
    (92, 200, 99),
    (170, 220, 50),
    (253, 231, 37),
];

/// Blue, white, red (for signed values, symmetric about 0).
const DIVERGING: [(u8, u8, u8); 5] =
    [(33, 102, 172), (146, 197, 222), (247, 247, 247), (244, 165, 130), (178, 24, 43)];

/// A colour scale over symlog values `[lo, hi]`.
#[derive(Clone, Copy)]
struct ColorScale {
    lo: f64,
    hi: f64,
    diverging: bool,
}

impl ColorScale {
    /// Viridis over the symlog range of the values.
    fn sequential(values: impl IntoIterator<Item = f64>) -> Self {
        let (lo, hi) = finite_range(values.into_iter().map(symlog)).unwrap_or((0.0, 1.0));
        let (lo, hi) = if hi > lo { (lo, hi) } else { (lo - 1e-6, hi + 1e-6) };
        Self { lo, hi, diverging: false }
    }

    /// Blue-white-red symmetric about 0 over the symlog range of the values.
    fn signed(values: impl IntoIterator<Item = f64>) -> Self {
        let m = finite_range(values.into_iter().map(|x| symlog(x).abs())).map_or(0.0, |r| r.1).max(1e-6);
        Self { lo: -m, hi: m, diverging: true }
    }

    /// The colour of a value (grey if it is not finite).
    fn color(&self, value: f64) -> RGBColor {
        if !value.is_finite() {
            return MISSING;
        }
        self.color_of_symlog(symlog(value))
    }

    fn color_of_symlog(&self, s: f64) -> RGBColor {
        let t = (s - self.lo) / (self.hi - self.lo);
        if self.diverging { ramp(&DIVERGING, t) } else { ramp(&VIRIDIS, t) }
    }
}

/// Cell boundaries around sampled values: midpoints, the outer ones at `[lo, hi]`.
fn cell_bounds(values: &[f64], lo: f64, hi: f64) -> Vec<f64> {
    let mut bounds = vec![lo];
    bounds.extend(values.windows(2).map(|w| 0.5 * (w[0] + w[1])));
    bounds.push(hi);
    bounds
}

/// One heat map of a 2D figure: colored rectangles `[u0, u1] × [v0, v1]`.
struct Panel {
    title: &'static str,
    cells: Vec<([f64; 4], f64)>,
    scale: ColorScale,
}

/// Fig. 4.5 for term `t` (2D): data, sum of 1D fits, 2D residual, cumulative fit, |fit − data|.
fn plot_2d(grid: &Grid, t: usize, material: &SplineMaterial) -> Result<String> {
    let term: &GridTerm = &grid.terms[t];
    let (u_axis, v_axis) = (term.axes[0], term.axes[1]);
    let (us, vs) = (&term.values[0], &term.values[1]);
    let widen = |(lo, hi): (f64, f64)| {
        let (lo, hi) = non_degenerate((lo, hi));
        (lo - MARGIN_2D * (hi - lo), hi + MARGIN_2D * (hi - lo))
    };
    let (u_range, v_range) = (sampled_range(us), sampled_range(vs));
    let ((u_lo, u_hi), (v_lo, v_hi)) = (widen(u_range), widen(v_range));

    // Data at the samples (NaN where missing or not converged), on cells around them.
    let mut data = vec![f64::NAN; us.len() * vs.len()];
    for s in grid.samples.iter().filter(|s| s.term as usize == t) {
        let (i, j) = (s.index[0] as usize, s.index[1] as usize);
        if let (Some(e), true, true) =
            (s.energy_density_j_m2.filter(|_| s.converged), i < us.len(), j < vs.len())
        {
            data[j * us.len() + i] = e;
        }
    }
    let (ub, vb) = (cell_bounds(us, u_lo, u_hi), cell_bounds(vs, v_lo, v_hi));
    let sample_cells = |value: &dyn Fn(usize, usize) -> f64| -> Vec<([f64; 4], f64)> {
        let mut cells = Vec::with_capacity(us.len() * vs.len());
        for j in 0..vs.len() {
            for i in 0..us.len() {
                cells.push(([ub[i], ub[i + 1], vb[j], vb[j + 1]], value(i, j)));
            }
        }
        cells
    };
    let cumulative = |u: f64, v: f64| material.energy_at(&strain(&term.axes, &[u, v]));
    let data_cells = sample_cells(&|i, j| data[j * us.len() + i]);
    let error_cells = sample_cells(&|i, j| (cumulative(us[i], vs[j]) - data[j * us.len() + i]).abs());

    // Fitted functions on a dense grid of cells.
    let (du, dv) = ((u_hi - u_lo) / CELLS_2D as f64, (v_hi - v_lo) / CELLS_2D as f64);
    let dense_cells = |f: &dyn Fn(f64, f64) -> f64| -> Vec<([f64; 4], f64)> {
        let mut cells = Vec::with_capacity(CELLS_2D * CELLS_2D);
        for j in 0..CELLS_2D {
            for i in 0..CELLS_2D {
                let (u0, v0) = (u_lo + i as f64 * du, v_lo + j as f64 * dv);
                cells.push(([u0, u0 + du, v0, v0 + dv], f(u0 + 0.5 * du, v0 + 0.5 * dv)));
            }
        }
        cells
    };
    let f0 = material.energy_at(&strain(&[], &[]));
    let term_1d = |axis: u8, x: f64| material.term_1d(axis as usize, x).unwrap_or(0.0);
    let axes = [u_axis as usize, v_axis as usize];
    let sum_1d = dense_cells(&|u, v| f0 + term_1d(u_axis, u) + term_1d(v_axis, v));
    let residual = dense_cells(&|u, v| material.term_2d(axes, u, v).unwrap_or(f64::NAN));
    let fit = dense_cells(&|u, v| cumulative(u, v));

    let values = |cells: &[([f64; 4], f64)]| cells.iter().map(|c| c.1).collect::<Vec<_>>();
    let energy_scale =
        ColorScale::sequential(values(&data_cells).into_iter().chain(values(&sum_1d)).chain(values(&fit)));
    let panels = [
        Panel { title: "data (nearest sample)", cells: data_cells, scale: energy_scale },
        Panel { title: "sum of 1D fits f0 + fu + fv", cells: sum_1d, scale: energy_scale },
        Panel {
            title: "2D residual term fuv",
            scale: ColorScale::signed(values(&residual)),
            cells: residual,
        },
        Panel { title: "cumulative fit", cells: fit, scale: energy_scale },
        Panel {
            title: "|fit − data| at the samples",
            scale: ColorScale::sequential(values(&error_cells)),
            cells: error_cells,
        },
    ];

    let title = format!(
        "{}: 2D term {} (energy density Ψ in J/m², colour scale sgn(Ψ) ln(1 + |Ψ|); box: sampled range; grey: no data)",
        grid.pattern,
        term.name()
    );
    let size = (PANEL_2D.0 * panels.len() as u32, PANEL_2D.1);
    render(size, |root| {
        let body = root.titled(&title, (FONT, 18)).map_err(plot_error)?;
        for (panel, area) in panels.iter().zip(body.split_evenly((1, panels.len()))) {
            let (top, bar) = area.split_vertically(area.dim_in_pixel().1.saturating_sub(BAR_HEIGHT));
            let mut chart = ChartBuilder::on(&top)
                .caption(panel.title, (FONT, 15))
                .margin(8)
                .x_label_area_size(40)
                .y_label_area_size(55)
                .build_cartesian_2d(u_lo..u_hi, v_lo..v_hi)
                .map_err(plot_error)?;
            chart
                .configure_mesh()
                .disable_mesh()
                .x_desc(axis_label(u_axis))
                .y_desc(axis_label(v_axis))
                .label_style((FONT, 12))
                .axis_desc_style((FONT, 13))
                .x_labels(5)
                .y_labels(5)
                .x_label_formatter(&|x| format_value(*x))
                .y_label_formatter(&|y| format_value(*y))
                .draw()
                .map_err(plot_error)?;
            chart
                .draw_series(panel.cells.iter().map(|&([u0, u1, v0, v1], value)| {
                    Rectangle::new([(u0, v0), (u1, v1)], panel.scale.color(value).filled())
                }))
                .map_err(plot_error)?;
            chart
                .draw_series(std::iter::once(Rectangle::new(
                    [(u_range.0, v_range.0), (u_range.1, v_range.1)],
                    BLACK.stroke_width(1),
                )))
                .map_err(plot_error)?;
            draw_color_bar(&bar, panel.scale)?;
        }
        Ok(())
    })
}

/// A horizontal colour bar with ticks in J/m² (the scale is symlog).
fn draw_color_bar(area: &DrawingArea<SVGBackend<'_>, Shift>, scale: ColorScale) -> Result<()> {
    let mut chart = ChartBuilder::on(area)
        .margin_left(63)
        .margin_right(16)
        .margin_top(6)
        .margin_bottom(4)
        .x_label_area_size(24)
        .build_cartesian_2d(scale.lo..scale.hi, 0.0..1.0)
        .map_err(plot_error)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .disable_y_axis()
        .x_labels(5)
        .label_style((FONT, 11))
        .x_label_formatter(&|s| {
            // a tick at 0 up to rounding reads 0
            let s = if s.abs() < 1e-9 * (scale.hi - scale.lo) { 0.0 } else { *s };
            format_value(symexp(s))
        })
        .draw()
        .map_err(plot_error)?;
    let n = 60;
    let step = (scale.hi - scale.lo) / n as f64;
    chart
        .draw_series((0..n).map(|k| {
            let s0 = scale.lo + k as f64 * step;
            Rectangle::new([(s0, 0.0), (s0 + step, 1.0)], scale.color_of_symlog(s0 + 0.5 * step).filled())
        }))
        .map_err(plot_error)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use yarnhom_artifacts::FitSettings;

    /// The synthetic thesis-shaped grid, with one failed solve in the `sx,kx` term (drawn grey).
    fn grid() -> Grid {
        let mut grid = yarnhom_fit::synthetic::synthetic_grid();
        let term = grid.terms.iter().position(|t| t.axes == [0, 3]).expect("sx,kx term") as u32;
        let failed = grid.samples.iter_mut().rfind(|s| s.term == term).expect("corner sample");
        failed.converged = false;
        failed.stop_reason = "iteration_limit".into();
        failed.energy_density_j_m2 = None;
        grid.validate().expect("valid synthetic grid");
        grid
    }

    #[test]
    fn writes_one_well_formed_svg_per_term() {
        let grid = grid();
        let spline = yarnhom_fit::fit_grid(&grid, &FitSettings::default(), 0.3).expect("fit");
        let dir = tempfile::tempdir().expect("temp dir");
        let out = dir.path().join("figures");
        let paths = plot_fit(&grid, &spline, &out).expect("plots");
        let names: Vec<String> =
            paths.iter().map(|p| p.file_name().expect("file").to_string_lossy().into_owned()).collect();
        let expected: Vec<String> = grid
            .terms
            .iter()
            .map(|t| format!("{}d-{}.svg", t.axes.len(), t.name().replace(',', "-")))
            .collect();
        assert_eq!(names, expected);
        for (path, term) in paths.iter().zip(&grid.terms) {
            let svg = std::fs::read_to_string(path).expect("readable");
            assert!(svg.starts_with("<svg"), "{}: {}", path.display(), &svg[..svg.len().min(80)]);
            assert!(svg.trim_end().ends_with("</svg>"), "{}", path.display());
            assert!(svg.contains(&term.name()), "{} lacks the term name {}", path.display(), term.name());
            assert!(svg.contains("synthetic"), "{} lacks the pattern name", path.display());
            assert_eq!(svg.matches("<svg").count(), 1);
            if term.axes.len() == 1 {
                assert!(
                    svg.contains("<circle") && svg.contains("<polyline"),
                    "{}: dots and a line",
                    path.display()
                );
            } else {
                assert!(
                    svg.matches("<rect").count() > 3 * CELLS_2D * CELLS_2D,
                    "{}: heat maps",
                    path.display()
                );
            }
        }
        let with_failure = std::fs::read_to_string(out.join("2d-sx-kx.svg")).expect("readable");
        assert!(with_failure.contains("#BBBBBB"), "the failed sample is grey");
    }

    #[test]
    fn unwritable_folder_is_an_error() {
        let grid = grid();
        let spline = yarnhom_fit::fit_grid(&grid, &FitSettings::default(), 0.3).expect("fit");
        let dir = tempfile::tempdir().expect("temp dir");
        let file = dir.path().join("not-a-folder");
        std::fs::write(&file, "x").expect("file");
        let err = plot_fit(&grid, &spline, &file.join("sub")).expect_err("a file is in the way");
        assert!(format!("{err:#}").contains("cannot create the folder"), "{err:#}");
    }

    #[test]
    fn symlog_inverts_and_colours_are_clamped() {
        for x in [-12.5, -1.0, 0.0, 0.3, 7.0] {
            assert!((symexp(symlog(x)) - x).abs() < 1e-12);
        }
        let scale = ColorScale::sequential([0.1, 10.0]);
        assert_eq!(scale.color(0.1), RGBColor(68, 1, 84));
        assert_eq!(scale.color(1e9), RGBColor(253, 231, 37));
        assert_eq!(scale.color(f64::NAN), MISSING);
        assert_eq!(ColorScale::signed([-2.0, 1.0]).color(0.0), RGBColor(247, 247, 247));
    }
}
