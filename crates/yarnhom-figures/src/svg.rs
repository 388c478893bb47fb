//! Figures drawn as SVG with plotters.

use plotters::coord::Shift;
use plotters::coord::types::RangedCoordf64;
use plotters::element::DynElement;
use plotters::prelude::*;

use crate::{Chart, ChartStyle, Colour, ColourScale, Figure, HeatMap, Mark, Panel, Series};

/// Why a figure could not be drawn.
#[derive(Debug, thiserror::Error)]
pub enum FigureError {
    /// The figure has nothing to draw.
    #[error("the figure has no panels")]
    NoPanels,
    /// The grid of panels has no area.
    #[error("the figure's grid is empty: {columns} columns of {width} x {height} px")]
    EmptyGrid {
        /// Panels per row.
        columns: usize,
        /// Width of a panel (px).
        width: u32,
        /// Height of a panel (px).
        height: u32,
    },
    /// An axis cannot be drawn.
    #[error("panel '{title}': the {axis} range [{lo}, {hi}] is empty or not finite")]
    Range {
        /// The panel's title.
        title: String,
        /// `x`, `y` or `colour`.
        axis: &'static str,
        /// Start of the range.
        lo: f64,
        /// End of the range.
        hi: f64,
    },
    /// plotters failed.
    #[error("drawing failed: {0}")]
    Drawing(String),
}

/// Font of all text.
const FONT: &str = "sans-serif";
/// Size of the figure's title (px).
const TITLE_SIZE: u32 = 18;
/// Height of the colour bar under a heat map (px).
const BAR_HEIGHT: u32 = 70;
/// Boxes of the colour bar.
const BAR_STEPS: usize = 60;

type Area<'a> = DrawingArea<SVGBackend<'a>, Shift>;
type Plot<'a, 'b> = ChartContext<'a, SVGBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// The figure as an SVG document.
pub fn render_svg(figure: &Figure) -> Result<String, FigureError> {
    let (rows, size) = grid_size(figure)?;
    for panel in &figure.panels {
        check_ranges(panel)?;
    }
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        root.fill(&WHITE).map_err(drawing)?;
        let body = match &figure.title {
            Some(title) => root.titled(title, (FONT, TITLE_SIZE)).map_err(drawing)?,
            None => root.clone(),
        };
        for (area, panel) in body.split_evenly((rows, figure.columns)).iter().zip(&figure.panels) {
            match panel {
                Panel::Chart(chart) => draw_chart(area, chart)?,
                Panel::HeatMap(map) => draw_heat_map(area, map)?,
            }
        }
        root.present().map_err(drawing)?;
    }
    Ok(svg)
}

fn drawing(e: impl std::fmt::Display) -> FigureError {
    FigureError::Drawing(e.to_string())
}

/// Rows of the figure's grid and the figure's size (px).
fn grid_size(figure: &Figure) -> Result<(usize, (u32, u32)), FigureError> {
    let (width, height) = figure.panel_size;
    if figure.panels.is_empty() {
        return Err(FigureError::NoPanels);
    }
    if figure.columns == 0 || width == 0 || height == 0 {
        return Err(FigureError::EmptyGrid { columns: figure.columns, width, height });
    }
    let rows = figure.panels.len().div_ceil(figure.columns);
    Ok((rows, (width * figure.columns as u32, height * rows as u32)))
}

/// Every axis of the panel has a finite, non-empty range.
fn check_ranges(panel: &Panel) -> Result<(), FigureError> {
    let (title, ranges) = match panel {
        Panel::Chart(c) => (&c.title, vec![("x", c.x_range), ("y", c.y_range)]),
        Panel::HeatMap(m) => {
            (&m.title, vec![("x", m.x_range), ("y", m.y_range), ("colour", (m.scale.lo, m.scale.hi))])
        }
    };
    match ranges.into_iter().find(|(_, (lo, hi))| !(lo.is_finite() && hi.is_finite() && lo < hi)) {
        Some((axis, (lo, hi))) => Err(FigureError::Range { title: title.clone(), axis, lo, hi }),
        None => Ok(()),
    }
}

/// A number for a tick label: three significant digits without trailing zeros for moderate
/// magnitudes (so neighbouring ticks 0.005 apart stay distinct), else scientific.
fn format_value(x: f64) -> String {
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

fn rgba(c: Colour) -> RGBAColor {
    RGBAColor(c.red, c.green, c.blue, c.opacity)
}

/// Text sizes and margins of a chart (px), and the legend's place.
struct ChartLayout {
    title: u32,
    ticks: u32,
    axis_labels: u32,
    legend: u32,
    margin: u32,
    x_axis_area: u32,
    y_axis_area: u32,
    legend_position: SeriesLabelPosition,
}

impl ChartLayout {
    fn of(style: ChartStyle) -> Self {
        match style {
            ChartStyle::Large => Self {
                title: 20,
                ticks: 13,
                axis_labels: 15,
                legend: 14,
                margin: 12,
                x_axis_area: 45,
                y_axis_area: 65,
                legend_position: SeriesLabelPosition::UpperMiddle,
            },
            ChartStyle::Compact => Self {
                title: 16,
                ticks: 12,
                axis_labels: 12,
                legend: 12,
                margin: 10,
                x_axis_area: 40,
                y_axis_area: 55,
                legend_position: SeriesLabelPosition::UpperLeft,
            },
        }
    }
}

/// Axes with ticks and their descriptions, the series, the legend.
fn draw_chart(area: &Area<'_>, chart: &Chart) -> Result<(), FigureError> {
    let layout = ChartLayout::of(chart.style);
    let ((x_lo, x_hi), (y_lo, y_hi)) = (chart.x_range, chart.y_range);
    let mut plot = ChartBuilder::on(area)
        .caption(&chart.title, (FONT, layout.title))
        .margin(layout.margin)
        .x_label_area_size(layout.x_axis_area)
        .y_label_area_size(layout.y_axis_area)
        .build_cartesian_2d(x_lo..x_hi, y_lo..y_hi)
        .map_err(drawing)?;
    plot.configure_mesh()
        .x_desc(chart.x_label.as_str())
        .y_desc(chart.y_label.as_str())
        .label_style((FONT, layout.ticks))
        .axis_desc_style((FONT, layout.axis_labels))
        .x_label_formatter(&|x| format_value(*x))
        .y_label_formatter(&|y| format_value(*y))
        .light_line_style(WHITE.mix(0.0))
        .draw()
        .map_err(drawing)?;
    for series in &chart.series {
        draw_series(&mut plot, series)?;
    }
    plot.configure_series_labels()
        .position(layout.legend_position)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK.mix(0.5))
        .label_font((FONT, layout.legend))
        .draw()
        .map_err(drawing)
}

/// The series' marks, and its legend entry if it has a label.
fn draw_series<'a, 'b: 'a>(plot: &mut Plot<'a, 'b>, series: &Series) -> Result<(), FigureError> {
    let colour = rgba(series.colour);
    let points = series.points.iter().copied();
    let drawn = match series.mark {
        Mark::Dots { radius, .. } => {
            plot.draw_series(points.map(|p| Circle::new(p, radius, colour.filled())))
        }
        Mark::Rings => plot.draw_series(points.map(|p| Circle::new(p, 4, colour.stroke_width(2)))),
        Mark::Crosses => plot.draw_series(points.map(|p| Cross::new(p, 5, colour.stroke_width(2)))),
        Mark::Polyline => plot.draw_series(LineSeries::new(points, colour.stroke_width(2))),
        Mark::Segments => plot
            .draw_series(series.points.chunks_exact(2).map(|pair| PathElement::new(pair.to_vec(), colour))),
    }
    .map_err(drawing)?;
    if let Some(label) = &series.label {
        let mark = series.mark;
        drawn.label(label.as_str()).legend(move |p| legend_glyph(mark, colour, p));
    }
    Ok(())
}

/// The legend's picture of a mark at `(x, y)` (px).
fn legend_glyph<'b>(
    mark: Mark,
    colour: RGBAColor,
    (x, y): (i32, i32),
) -> DynElement<'static, SVGBackend<'b>, (i32, i32)> {
    match mark {
        Mark::Dots { legend_radius, .. } => Circle::new((x, y), legend_radius, colour.filled()).into_dyn(),
        Mark::Rings => Circle::new((x, y), 4, colour.stroke_width(2)).into_dyn(),
        Mark::Crosses => Cross::new((x, y), 5, colour.stroke_width(2)).into_dyn(),
        Mark::Polyline => PathElement::new(vec![(x - 8, y), (x + 8, y)], colour.stroke_width(2)).into_dyn(),
        Mark::Segments => PathElement::new(vec![(x - 8, y), (x + 8, y)], colour).into_dyn(),
    }
}

/// The cells, the outline on top, the colour bar below.
fn draw_heat_map(area: &Area<'_>, map: &HeatMap) -> Result<(), FigureError> {
    let (top, bar) = area.split_vertically(area.dim_in_pixel().1.saturating_sub(BAR_HEIGHT));
    let ((x_lo, x_hi), (y_lo, y_hi)) = (map.x_range, map.y_range);
    let mut plot = ChartBuilder::on(&top)
        .caption(&map.title, (FONT, 15))
        .margin(8)
        .x_label_area_size(40)
        .y_label_area_size(55)
        .build_cartesian_2d(x_lo..x_hi, y_lo..y_hi)
        .map_err(drawing)?;
    plot.configure_mesh()
        .disable_mesh()
        .x_desc(map.x_label.as_str())
        .y_desc(map.y_label.as_str())
        .label_style((FONT, 12))
        .axis_desc_style((FONT, 13))
        .x_labels(5)
        .y_labels(5)
        .x_label_formatter(&|x| format_value(*x))
        .y_label_formatter(&|y| format_value(*y))
        .draw()
        .map_err(drawing)?;
    plot.draw_series(
        map.cells.iter().map(|c| {
            Rectangle::new([(c.x.0, c.y.0), (c.x.1, c.y.1)], rgba(map.scale.colour(c.value)).filled())
        }),
    )
    .map_err(drawing)?;
    plot.draw_series(std::iter::once(Rectangle::new(map.outline, BLACK.stroke_width(1)))).map_err(drawing)?;
    draw_colour_bar(&bar, map.scale)
}

/// A horizontal colour bar with ticks in values (the scale is symlog).
fn draw_colour_bar(area: &Area<'_>, scale: ColourScale) -> Result<(), FigureError> {
    let mut plot = ChartBuilder::on(area)
        .margin_left(63)
        .margin_right(16)
        .margin_top(6)
        .margin_bottom(4)
        .x_label_area_size(24)
        .build_cartesian_2d(scale.lo..scale.hi, 0.0..1.0)
        .map_err(drawing)?;
    plot.configure_mesh()
        .disable_mesh()
        .disable_y_axis()
        .x_labels(5)
        .label_style((FONT, 11))
        .x_label_formatter(&|s| {
            // a tick at 0 up to rounding reads 0
            let s = if s.abs() < 1e-9 * (scale.hi - scale.lo) { 0.0 } else { *s };
            format_value(crate::symexp(s))
        })
        .draw()
        .map_err(drawing)?;
    let step = (scale.hi - scale.lo) / BAR_STEPS as f64;
    plot.draw_series((0..BAR_STEPS).map(|k| {
        let s0 = scale.lo + k as f64 * step;
        Rectangle::new([(s0, 0.0), (s0 + step, 1.0)], rgba(scale.colour_of_symlog(s0 + 0.5 * step)).filled())
    }))
    .map_err(drawing)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Cell;

    fn chart(series: Vec<Series>) -> Chart {
        Chart {
            title: "a chart".into(),
            x_label: "stretch".into(),
            y_label: "force (N)".into(),
            x_range: (0.0, 1.0),
            y_range: (-1.0, 1.0),
            series,
            style: ChartStyle::Compact,
        }
    }

    fn figure(panels: Vec<Panel>) -> Figure {
        Figure { panel_size: (420, 380), columns: 2, title: None, panels }
    }

    /// `n` points in the chart's range.
    fn points(n: usize) -> Vec<(f64, f64)> {
        (0..n).map(|k| (k as f64 / n as f64, (k as f64).sin())).collect()
    }

    /// A labelled series of `n` points in the colour `#0000{blue:02X}`.
    fn series(label: &str, mark: Mark, blue: u8, n: usize) -> Series {
        Series { label: Some(label.into()), mark, colour: Colour::rgb(0, 0, blue), points: points(n) }
    }

    /// The SVG elements in the colour `#0000{blue:02X}`.
    fn in_colour(svg: &str, blue: u8) -> Vec<&str> {
        svg.lines().filter(|l| l.contains(&format!("\"#0000{blue:02X}\""))).collect()
    }

    #[test]
    fn a_chart_shows_every_label_and_a_mark_per_point() {
        let mut all = vec![
            series("readings", Mark::SPECKS, 1, 9),
            series("targets", Mark::DOTS, 2, 5),
            series("held out", Mark::Rings, 3, 4),
            series("fitted", Mark::Crosses, 4, 3),
            series("uniform test", Mark::Polyline, 5, 7),
            series("dashes", Mark::Segments, 6, 6),
        ];
        all[5].label = None;
        let svg = render_svg(&figure(vec![Panel::Chart(chart(all))])).expect("drawn");
        assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
        for label in
            ["a chart", "stretch", "force (N)", "readings", "targets", "held out", "fitted", "uniform test"]
        {
            assert!(svg.contains(&format!("\n{label}\n")), "{label}");
        }
        let elements =
            |blue: u8, tag: &str| in_colour(&svg, blue).iter().filter(|l| l.starts_with(tag)).count();
        // a mark per point, and one in the legend
        assert_eq!(elements(1, "<circle"), 9 + 1);
        assert_eq!(elements(2, "<circle"), 5 + 1);
        assert_eq!(elements(3, "<circle"), 4 + 1);
        assert_eq!(elements(4, "<line"), 2 * (3 + 1), "a cross is two lines");
        let polylines = in_colour(&svg, 5);
        assert_eq!(polylines.len(), 2, "the line and its legend");
        assert_eq!(polylines[0].matches(',').count(), 7, "the line through the 7 points: {}", polylines[0]);
        assert_eq!(elements(6, "<polyline"), 3, "three dashes, not in the legend");
        assert!(!svg.contains("\ndashes\n"));
    }

    #[test]
    fn a_heat_map_has_its_cells_outline_and_colour_bar() {
        let cells = (0..4)
            .map(|k| Cell {
                x: (k as f64 * 0.25, (k + 1) as f64 * 0.25),
                y: (0.0, 1.0),
                value: if k == 3 { f64::NAN } else { k as f64 },
            })
            .collect();
        let map = HeatMap {
            title: "a map".into(),
            x_label: "sx [-]".into(),
            y_label: "kx [1/m]".into(),
            x_range: (0.0, 1.0),
            y_range: (0.0, 1.0),
            cells,
            outline: [(0.1, 0.1), (0.9, 0.9)],
            scale: ColourScale::sequential([0.0, 2.0]),
        };
        let figure = Figure {
            panel_size: (380, 540),
            columns: 1,
            title: Some("a title".into()),
            panels: vec![Panel::HeatMap(map)],
        };
        let svg = render_svg(&figure).expect("drawn");
        for label in ["a title", "a map", "sx [-]", "kx [1/m]"] {
            assert!(svg.contains(&format!("\n{label}\n")), "{label}");
        }
        // the background, 4 cells, the outline, the bar's boxes
        assert_eq!(svg.matches("<rect").count(), 1 + 4 + 1 + BAR_STEPS);
        assert_eq!(svg.matches("fill=\"#BBBBBB\"").count(), 1, "the missing cell is grey");
        assert!(svg.contains("fill=\"#440154\""), "0 is the start of viridis");
    }

    #[test]
    fn an_empty_figure_is_an_error() {
        assert!(matches!(render_svg(&figure(Vec::new())), Err(FigureError::NoPanels)));
        let no_columns = Figure { columns: 0, ..figure(vec![Panel::Chart(chart(Vec::new()))]) };
        assert!(matches!(render_svg(&no_columns), Err(FigureError::EmptyGrid { columns: 0, .. })));
    }

    #[test]
    fn an_axis_without_a_finite_range_is_an_error() {
        for range in [(1.0, 1.0), (0.0, f64::INFINITY), (f64::NAN, 1.0)] {
            let bad = Chart { y_range: range, ..chart(Vec::new()) };
            let err = render_svg(&figure(vec![Panel::Chart(bad)])).expect_err("no y axis");
            assert!(matches!(err, FigureError::Range { axis: "y", .. }), "{err}");
            assert!(err.to_string().contains("'a chart'"), "{err}");
        }
    }

    #[test]
    fn tick_labels_have_three_significant_digits() {
        assert_eq!(format_value(0.0), "0");
        assert_eq!(format_value(0.005), "5.0e-3");
        assert_eq!(format_value(0.015), "0.015");
        assert_eq!(format_value(-1.25), "-1.25");
        assert_eq!(format_value(120.0), "120");
        assert_eq!(format_value(2.5e5), "2.5e5");
    }
}
