#![doc = include_str!("../README.md")]

mod scale;
#[cfg(feature = "svg")]
mod svg;

pub use scale::{ColourMap, ColourScale, finite_range, symexp, symlog};
#[cfg(feature = "svg")]
pub use svg::{FigureError, render_svg};

/// A figure: panels in a grid of `columns`, filled row by row, under an optional title.
#[derive(Debug, Clone, PartialEq)]
pub struct Figure {
    /// Size of one cell of the grid (px); the figure is `columns` cells wide and as many rows
    /// high as the panels need (the title takes the top of it).
    pub panel_size: (u32, u32),
    /// Panels per row.
    pub columns: usize,
    /// A title over all panels.
    pub title: Option<String>,
    /// The panels, row by row.
    pub panels: Vec<Panel>,
}

/// One panel of a figure.
#[derive(Debug, Clone, PartialEq)]
pub enum Panel {
    /// Series of points against two axes.
    Chart(Chart),
    /// Coloured cells over two axes, with the colour bar below.
    HeatMap(HeatMap),
}

/// Series of points against two linear axes, with a legend of the labelled series.
#[derive(Debug, Clone, PartialEq)]
pub struct Chart {
    /// Caption above the chart.
    pub title: String,
    /// Description of the horizontal axis (with its unit).
    pub x_label: String,
    /// Description of the vertical axis (with its unit).
    pub y_label: String,
    /// The horizontal axis' range `(lo, hi)`.
    pub x_range: (f64, f64),
    /// The vertical axis' range `(lo, hi)`.
    pub y_range: (f64, f64),
    /// The series, drawn in order (later ones on top).
    pub series: Vec<Series>,
    /// Sizes of text and margins, and where the legend is.
    pub style: ChartStyle,
}

/// The look of a chart: sizes of its text and margins, and the legend's place.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ChartStyle {
    /// A chart alone in a large figure (Fig. 4.4): large text, the legend at the top middle.
    Large,
    /// One chart of a grid (the calibration figures): small text, the legend at the top left.
    Compact,
}

/// Points drawn with one mark and colour.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// The legend's entry; `None`: not in the legend.
    pub label: Option<String>,
    /// How the points are drawn.
    pub mark: Mark,
    /// Colour of the marks.
    pub colour: Colour,
    /// `(x, y)` in the chart's coordinates.
    pub points: Vec<(f64, f64)>,
}

/// How the points of a series are drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mark {
    /// Filled circles of `radius` px; the legend shows one of `legend_radius` px.
    Dots {
        /// Radius on the chart (px).
        radius: u32,
        /// Radius in the legend (px).
        legend_radius: u32,
    },
    /// Hollow circles (4 px, 2 px stroke).
    Rings,
    /// Crosses (5 px, 2 px stroke).
    Crosses,
    /// A polyline through the points (2 px stroke).
    Polyline,
    /// A line between the points of each pair, `[p0, p1], [p2, p3], ...` (1 px stroke):
    /// dashes.
    Segments,
}

impl Mark {
    /// Small dots (1 px; 3 px in the legend): many raw readings.
    pub const SPECKS: Mark = Mark::Dots { radius: 1, legend_radius: 3 };
    /// Dots (4 px; 3 px in the legend).
    pub const DOTS: Mark = Mark::Dots { radius: 4, legend_radius: 3 };
}

/// An sRGB colour with an opacity.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Colour {
    /// Red, 0 to 255.
    pub red: u8,
    /// Green, 0 to 255.
    pub green: u8,
    /// Blue, 0 to 255.
    pub blue: u8,
    /// Opacity, 0 (transparent) to 1 (opaque).
    pub opacity: f64,
}

impl Colour {
    /// Black.
    pub const BLACK: Colour = Colour::rgb(0, 0, 0);

    /// The opaque colour `(red, green, blue)`.
    pub const fn rgb(red: u8, green: u8, blue: u8) -> Self {
        Self { red, green, blue, opacity: 1.0 }
    }

    /// The colour with `opacity` (0 to 1).
    pub const fn with_opacity(self, opacity: f64) -> Self {
        Self { opacity, ..self }
    }
}

/// Coloured rectangles over two axes, a rectangle outlined on top, and a colour bar below.
#[derive(Debug, Clone, PartialEq)]
pub struct HeatMap {
    /// Caption above the map.
    pub title: String,
    /// Description of the horizontal axis (with its unit).
    pub x_label: String,
    /// Description of the vertical axis (with its unit).
    pub y_label: String,
    /// The horizontal axis' range `(lo, hi)`.
    pub x_range: (f64, f64),
    /// The vertical axis' range `(lo, hi)`.
    pub y_range: (f64, f64),
    /// The cells, coloured by `scale`.
    pub cells: Vec<Cell>,
    /// Opposite corners of a rectangle outlined in black over the cells (Fig. 4.5: the
    /// sampled range).
    pub outline: [(f64, f64); 2],
    /// The colours of the cells' values, shown in the bar.
    pub scale: ColourScale,
}

/// A rectangle `[x.0, x.1] × [y.0, y.1]` of a heat map and its value.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cell {
    /// Horizontal extent.
    pub x: (f64, f64),
    /// Vertical extent.
    pub y: (f64, f64),
    /// The value; not finite: missing (grey).
    pub value: f64,
}
