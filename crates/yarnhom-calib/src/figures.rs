//! The calibration figures as `yarnhom_figures` data: the shell fit (Fig. 6.6), the bending
//! fit, a diagnosis (measured against base and extension, and the residuals) and the yarn-level
//! fit (Fig. 6.13 style). Each is a grid of charts, a column per direction.

use yarnhom_figures::{Chart, ChartStyle, Colour, Figure, Mark, Panel, Series};

use crate::data::set::{Direction, Face, MeasurementSet, Phase};
use crate::data::targets::Target;
use crate::diagnosis::report::{BendingTrack, Diagnosis};
use crate::experiments::bending_tests::BendingTest;
use crate::experiments::swatch::SimulatedReading;
use crate::shell::fit::{ShellBending, ShellFit};
use crate::yarn::fit::YarnFit;

/// Size of one chart (px).
const PANEL_SIZE: (u32, u32) = (420, 380);
/// Raw readings.
const MEASURED: Colour = Colour::rgb(0xB0, 0xB8, 0xC8);
/// Targets and measured bending readings.
const TARGET: Colour = Colour::rgb(0x1F, 0x5F, 0xD0);
/// The fitted or extended model.
const FITTED: Colour = Colour::rgb(0xC0, 0x30, 0x30);
/// The uniform test of the fitted material.
const UNIFORM: Colour = Colour::rgb(0x1A, 0x9A, 0x3A);
/// Unloading.
const UNLOAD: Colour = Colour::rgb(0xE0, 0x90, 0x20);
/// The end of the comfort range.
const COMFORT: Colour = Colour::rgb(0x40, 0x40, 0x40);

fn series(label: impl Into<String>, mark: Mark, colour: Colour, points: Vec<(f64, f64)>) -> Series {
    Series { label: Some(label.into()), mark, colour, points }
}

/// A chart of `series` from stretch (or another x) 0 to 5% past the largest x, and over the
/// y values and 0 with 5% margins.
fn chart(title: String, x_label: &str, y_label: &str, series: Vec<Series>) -> Panel {
    let points = || series.iter().flat_map(|s| s.points.iter());
    let x_max = points().map(|p| p.0).fold(0.0_f64, f64::max).max(1e-6) * 1.05;
    let (lo, hi) = points().map(|p| p.1).fold((0.0_f64, 0.0_f64), |(a, b), y| (a.min(y), b.max(y)));
    let pad = 0.05 * (hi - lo).max(1e-9);
    Panel::Chart(Chart {
        title,
        x_label: x_label.into(),
        y_label: y_label.into(),
        x_range: (0.0, x_max),
        y_range: (lo - pad, hi + pad),
        series,
        style: ChartStyle::Compact,
    })
}

/// `panels` in a grid of `columns`, row by row.
fn grid(panels: Vec<Panel>, columns: usize) -> Figure {
    Figure { panel_size: PANEL_SIZE, columns, title: None, panels }
}

/// The quantity of a figure row: force or compression.
#[derive(Clone, Copy)]
enum Quantity {
    Force,
    Compression,
}

impl Quantity {
    fn label(self) -> &'static str {
        match self {
            Quantity::Force => "force (N)",
            Quantity::Compression => "compression",
        }
    }

    fn of(self, force_n: f64, compression: Option<f64>) -> Option<f64> {
        match self {
            Quantity::Force => Some(force_n),
            Quantity::Compression => compression,
        }
    }

    fn of_reading(self, r: &SimulatedReading) -> f64 {
        match self {
            Quantity::Force => r.force_n,
            Quantity::Compression => r.compression,
        }
    }
}

/// Raw readings of `direction` and `phase` up to `s_max`, thinned to about 1500 points.
fn raw_readings(
    set: &MeasurementSet,
    direction: Direction,
    phase: Phase,
    s_max: f64,
    q: Quantity,
) -> Vec<(f64, f64)> {
    let readings: Vec<_> = set
        .stretch
        .iter()
        .filter(|p| p.direction == direction && p.phase == phase && p.stretch <= s_max)
        .collect();
    let thin = (readings.len() / 1500).max(1);
    readings
        .iter()
        .step_by(thin)
        .filter_map(|p| q.of(p.force_n, p.compression).map(|v| (p.stretch, v)))
        .collect()
}

fn target_points<'a>(targets: impl Iterator<Item = &'a Target>, q: Quantity) -> Vec<(f64, f64)> {
    targets.filter_map(|t| q.of(t.force_n, t.compression).map(|v| (t.stretch, v))).collect()
}

/// Fig. 6.6: per direction a column, force vs stretch on top and compression vs stretch below;
/// raw loading readings (grey), targets (blue), the clamped-swatch fit (red), the uniform test
/// of the fitted material (green, (6.3)).
pub fn shell_fit_figure(set: &MeasurementSet, fit: &ShellFit) -> Figure {
    let directions: Vec<Direction> = fit.errors.by_direction.iter().map(|e| e.0).collect();
    let mut panels = Vec::new();
    for q in [Quantity::Force, Quantity::Compression] {
        for &direction in &directions {
            let title = format!("{} {direction}: {}", fit.fabric, q.label());
            panels.push(chart(title, "stretch", q.label(), shell_fit_series(set, fit, direction, q)));
        }
    }
    grid(panels, directions.len())
}

/// The series of one chart of [`shell_fit_figure`].
fn shell_fit_series(set: &MeasurementSet, fit: &ShellFit, direction: Direction, q: Quantity) -> Vec<Series> {
    let specimen = set.fabric.swatch.specimen(direction);
    let mine: Vec<(usize, &Target)> =
        fit.targets.iter().enumerate().filter(|(_, t)| t.direction == direction).collect();
    let s_max = mine.iter().map(|(_, t)| t.stretch).fold(0.0, f64::max) * 1.05;
    let uniform = std::iter::once((0.0, 0.0)).chain(
        fit.uniform_targets.iter().filter(|u| u.direction == direction).map(|u| {
            let p = u.point;
            (p.stretch, q.of(p.stress_n_m * specimen.width_m, Some(p.compression)).unwrap_or(0.0))
        }),
    );
    vec![
        series(
            "readings (load)",
            Mark::SPECKS,
            MEASURED,
            raw_readings(set, direction, Phase::Load, s_max, q),
        ),
        series("uniform test (6.3)", Mark::Polyline, UNIFORM, uniform.collect()),
        series("targets", Mark::DOTS, TARGET, target_points(mine.iter().map(|(_, t)| *t), q)),
        series(
            "clamped swatch, fitted",
            Mark::Crosses,
            FITTED,
            mine.iter().map(|(i, t)| (t.stretch, q.of_reading(&fit.simulated[*i]))).collect(),
        ),
    ]
}

/// The predictions of `id` at `direction`'s targets (load or unload).
fn predicted(d: &Diagnosis, id: &str, direction: Direction, unload: bool, q: Quantity) -> Vec<(f64, f64)> {
    let Some(p) = d.predictions.iter().find(|p| p.id == id) else { return Vec::new() };
    let (targets, readings) =
        if unload { (&d.unload_targets, &p.unload) } else { (&d.load_targets, &p.load) };
    targets
        .iter()
        .zip(readings)
        .filter(|(t, _)| t.direction == direction)
        .map(|(t, r)| (t.stretch, q.of_reading(r)))
        .collect()
}

/// The directions with loading targets in a diagnosis.
fn diagnosed_directions(d: &Diagnosis) -> Vec<Direction> {
    Direction::ALL.into_iter().filter(|x| d.load_targets.iter().any(|t| t.direction == *x)).collect()
}

/// Measured against base and extended: per direction force and compression, fitted targets
/// filled, held-out ones hollow, unloading in orange.
pub fn diagnosis_figure(set: &MeasurementSet, d: &Diagnosis) -> Figure {
    let directions = diagnosed_directions(d);
    let mut panels = Vec::new();
    for q in [Quantity::Force, Quantity::Compression] {
        for &direction in &directions {
            let mut all = loading_series(set, d, direction, q);
            if d.unload_targets.iter().any(|t| t.direction == direction) {
                all.extend(unloading_series(d, direction, q));
            }
            panels.push(chart(format!("{} {direction}: {}", d.fabric, q.label()), "stretch", q.label(), all));
        }
    }
    grid(panels, directions.len())
}

/// A diagnosis' loading readings, fitted and held-out targets, and the base's and the
/// extension's predictions.
fn loading_series(set: &MeasurementSet, d: &Diagnosis, direction: Direction, q: Quantity) -> Vec<Series> {
    let s_max =
        d.load_targets.iter().filter(|t| t.direction == direction).map(|t| t.stretch).fold(0.0, f64::max)
            * 1.05;
    let split = |fitted: bool| {
        target_points(
            d.load_targets
                .iter()
                .zip(&d.load_fitted)
                .filter(|(t, f)| t.direction == direction && **f == fitted)
                .map(|(t, _)| t),
            q,
        )
    };
    let mut all = vec![
        series(
            "readings (load)",
            Mark::SPECKS,
            MEASURED,
            raw_readings(set, direction, Phase::Load, s_max, q),
        ),
        series("fitted targets", Mark::DOTS, TARGET, split(true)),
        series("held-out targets", Mark::Rings, TARGET, split(false)),
        series("base", Mark::Polyline, Colour::BLACK, predicted(d, "base", direction, false, q)),
    ];
    if let Some(e) = &d.extended {
        all.push(series(&e.id, Mark::Polyline, FITTED, predicted(d, &e.id, direction, false, q)));
    }
    all
}

/// A diagnosis' unloading targets and the predictions of the extension (else the base).
fn unloading_series(d: &Diagnosis, direction: Direction, q: Quantity) -> [Series; 2] {
    let id = d.extended.as_ref().map_or("base", |e| e.id.as_str());
    [
        series(
            "unloading targets",
            Mark::Rings,
            UNLOAD,
            target_points(d.unload_targets.iter().filter(|t| t.direction == direction), q),
        ),
        series(format!("{id}, unloading"), Mark::Crosses, UNLOAD, predicted(d, id, direction, true, q)),
    ]
}

/// Residuals (model minus measured, over the measured value's scale) against stretch per
/// direction and quantity, for the base and the extension, loading targets.
pub fn residuals_figure(d: &Diagnosis) -> Figure {
    let directions = diagnosed_directions(d);
    let mut panels = Vec::new();
    for q in [Quantity::Force, Quantity::Compression] {
        for &direction in &directions {
            let residual = |id: &str| residuals(d, id, direction, q);
            let mut all = vec![series("base", Mark::DOTS, Colour::BLACK, residual("base"))];
            if let Some(e) = &d.extended {
                all.push(series(&e.id, Mark::Crosses, FITTED, residual(&e.id)));
            }
            let title = format!("{} {direction}: {} residual", d.fabric, q.label());
            panels.push(chart(title, "stretch", "(model - measured) / mean", all));
        }
    }
    grid(panels, directions.len())
}

/// `(stretch, (model - measured) / scale)` of `id` at `direction`'s loading targets; the scale
/// is the mean magnitude of the measured values (at least 0.01 for compression).
fn residuals(d: &Diagnosis, id: &str, direction: Direction, q: Quantity) -> Vec<(f64, f64)> {
    let mine: Vec<&Target> = d.load_targets.iter().filter(|t| t.direction == direction).collect();
    let scale = mine.iter().filter_map(|t| q.of(t.force_n, t.compression)).map(f64::abs).sum::<f64>()
        / mine.len().max(1) as f64;
    let scale = scale.max(if matches!(q, Quantity::Compression) { 0.01 } else { 1e-12 });
    predicted(d, id, direction, false, q)
        .into_iter()
        .zip(&mine)
        .filter_map(|((s, v), t)| q.of(t.force_n, t.compression).map(|m| (s, (v - m) / scale)))
        .collect()
}

/// The readings of bending tests and the models' simulations of them.
struct BendingReadings<'a> {
    tests: &'a [BendingTest],
    measured: &'a [f64],
    fitted: &'a [bool],
    predictions: &'a [(String, Vec<f64>)],
}

impl<'a> From<&'a BendingTrack> for BendingReadings<'a> {
    fn from(t: &'a BendingTrack) -> Self {
        Self { tests: &t.tests, measured: &t.measured, fitted: &t.fitted, predictions: &t.predictions }
    }
}

/// The bending figure of `calibrate shell`: every reading fitted, against the fitted model;
/// `None` without a bending fit.
pub fn shell_bending_figure(fit: &ShellFit) -> Option<Figure> {
    let Some(ShellBending { fit: Some(bending), tests, measured, .. }) = &fit.bending else { return None };
    let fitted = vec![true; tests.len()];
    let predictions = [("fitted".to_string(), bending.simulated.clone())];
    Some(bending_figure(
        &fit.fabric,
        BendingReadings { tests, measured, fitted: &fitted, predictions: &predictions },
    ))
}

/// The bending figure of a diagnosis: fitted and held-out readings against the base and the
/// chosen extension; `None` without bending tests.
pub fn diagnosis_bending_figure(d: &Diagnosis) -> Option<Figure> {
    d.bending.as_ref().map(|track| bending_figure(&d.fabric, track.into()))
}

/// The kinds of bending test, in the figure's row order: `(title, x label, y label)`.
const BENDING_KINDS: [(&str, &str, &str); 3] = [
    ("pear loop", "clamp distance (m)", "aspect ratio"),
    ("cantilever, face up", "overhang (m)", "tip drop (m)"),
    ("cantilever, face down", "overhang (m)", "tip drop (m)"),
];

/// The row of [`BENDING_KINDS`] of a test.
fn bending_kind(t: &BendingTest) -> usize {
    match t {
        BendingTest::PearLoop { .. } => 0,
        BendingTest::Cantilever { face: Face::Up, .. } => 1,
        BendingTest::Cantilever { face: Face::Down, .. } => 2,
    }
}

/// The x of a test: clamp distance or overhang (m).
fn bending_x(t: &BendingTest) -> f64 {
    match t {
        BendingTest::PearLoop { clamp_distance_m, .. } => *clamp_distance_m,
        BendingTest::Cantilever { overhang_m, .. } => *overhang_m,
    }
}

/// Bending tests: per direction, pear-loop aspect ratio against clamp distance and cantilever
/// tip drop against overhang (both faces), measured (fitted filled, held out hollow) against
/// the models (first black, second red).
fn bending_figure(fabric: &str, track: BendingReadings<'_>) -> Figure {
    let directions: Vec<Direction> =
        Direction::ALL.into_iter().filter(|d| track.tests.iter().any(|t| t.direction() == *d)).collect();
    let mut panels = Vec::new();
    for (k, (kind, x_label, y_label)) in BENDING_KINDS.iter().enumerate() {
        if !track.tests.iter().any(|t| bending_kind(t) == k) {
            continue;
        }
        for &direction in &directions {
            let mine: Vec<usize> = (0..track.tests.len())
                .filter(|&i| bending_kind(&track.tests[i]) == k && track.tests[i].direction() == direction)
                .collect();
            let title = format!("{fabric} {direction}: {kind}");
            panels.push(chart(title, x_label, y_label, bending_series(&track, &mine)));
        }
    }
    grid(panels, directions.len())
}

/// The measured readings of the tests `mine` (fitted, held out) and each model's simulations
/// of them in order of x.
fn bending_series(track: &BendingReadings<'_>, mine: &[usize]) -> Vec<Series> {
    let mut sorted = mine.to_vec();
    sorted.sort_by(|a, b| bending_x(&track.tests[*a]).total_cmp(&bending_x(&track.tests[*b])));
    let measured = |fitted: bool| {
        mine.iter()
            .filter(|&&i| track.fitted[i] == fitted)
            .map(|&i| (bending_x(&track.tests[i]), track.measured[i]))
            .collect()
    };
    let mut all = vec![
        series("measured, fitted", Mark::DOTS, TARGET, measured(true)),
        series("measured, held out", Mark::Rings, TARGET, measured(false)),
    ];
    for ((id, simulated), colour) in track.predictions.iter().zip([Colour::BLACK, FITTED]) {
        let points = sorted.iter().map(|&i| (bending_x(&track.tests[i]), simulated[i])).collect();
        all.push(series(id, Mark::Polyline, colour, points));
    }
    all
}

/// Fig. 6.13 style: per direction, the second Piola-Kirchhoff stretch stress and the
/// compression of the shell's uniform targets and of the yarn tile, with the comfort limit.
pub fn yarn_fit_figure(fit: &YarnFit) -> Figure {
    let mut panels = Vec::new();
    for quantity in ["stress σ_s/(1+s) [N/m]", "compression c"] {
        for (t, c) in fit.targets.iter().zip(&fit.simulated) {
            let value = |s: f64, sigma: f64, comp: f64| {
                if quantity.starts_with("stress") { sigma / (1.0 + s) } else { comp }
            };
            let target: Vec<(f64, f64)> = (0..t.stretch.len())
                .map(|i| (t.stretch[i], value(t.stretch[i], t.stress_n_m[i], t.compression[i])))
                .collect();
            let yarn: Vec<(f64, f64)> = (0..c.stretch.len())
                .map(|i| (c.stretch[i], value(c.stretch[i], c.stress_n_m[i], c.compression[i])))
                .collect();
            let top = target.iter().chain(&yarn).map(|p| p.1).fold(0.0, f64::max);
            let title =
                format!("{} {}: {}", fit.fabric, t.direction, quantity.split(' ').next().unwrap_or(quantity));
            let all = vec![
                series("shell targets (6.3)", Mark::Polyline, TARGET, target),
                series("yarn tile, estimated", Mark::Crosses, FITTED, yarn),
                series(
                    "end of comfort range (2 N)",
                    Mark::Polyline,
                    COMFORT,
                    vec![(t.comfort_stretch, 0.0), (t.comfort_stretch, top)],
                ),
            ];
            panels.push(chart(title, "stretch", quantity, all));
        }
    }
    grid(panels, fit.targets.len())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn titles(figure: &Figure) -> Vec<&str> {
        figure
            .panels
            .iter()
            .map(|p| match p {
                Panel::Chart(c) => c.title.as_str(),
                Panel::HeatMap(m) => m.title.as_str(),
            })
            .collect()
    }

    fn the_chart(panel: &Panel) -> &Chart {
        match panel {
            Panel::Chart(c) => c,
            Panel::HeatMap(_) => panic!("a heat map"),
        }
    }

    #[test]
    fn a_chart_starts_at_zero_and_covers_its_points_with_margins() {
        let points = vec![(0.1, -2.0), (0.4, 6.0)];
        let panel = chart("t".into(), "stretch", "force (N)", vec![series("s", Mark::DOTS, TARGET, points)]);
        let c = the_chart(&panel);
        assert_eq!(c.x_range, (0.0, 0.4 * 1.05));
        assert_eq!(c.y_range, (-2.0 - 0.4, 6.0 + 0.4), "5% of the y extent on either side");
        let empty = chart("t".into(), "stretch", "force (N)", Vec::new());
        let c = the_chart(&empty);
        assert!(c.x_range.1 > 0.0 && c.y_range.1 > c.y_range.0, "no points: still a non-empty range");
    }

    #[test]
    fn the_bending_figure_has_a_row_per_tested_kind_and_a_column_per_direction() {
        let pear = |direction, clamp_distance_m| BendingTest::PearLoop { direction, clamp_distance_m };
        let up = |direction, overhang_m| BendingTest::Cantilever { direction, face: Face::Up, overhang_m };
        let tests = [
            pear(Direction::Weft, 0.02),
            pear(Direction::Weft, 0.01),
            pear(Direction::Warp, 0.01),
            up(Direction::Weft, 0.03),
            up(Direction::Warp, 0.03),
        ];
        let measured = [1.2, 1.1, 1.3, 0.01, 0.02];
        let fitted = [true, false, true, true, true];
        let predictions = [("base".to_string(), vec![1.0, 0.9, 1.1, 0.011, 0.019])];
        let readings = BendingReadings {
            tests: &tests,
            measured: &measured,
            fitted: &fitted,
            predictions: &predictions,
        };
        let figure = bending_figure("knit", readings);
        assert_eq!(figure.columns, 2);
        assert_eq!(
            titles(&figure),
            [
                "knit weft: pear loop",
                "knit warp: pear loop",
                "knit weft: cantilever, face up",
                "knit warp: cantilever, face up"
            ]
        );
        let weft_pear = the_chart(&figure.panels[0]);
        let points: Vec<&[(f64, f64)]> = weft_pear.series.iter().map(|s| s.points.as_slice()).collect();
        assert_eq!(
            points,
            [&[(0.02, 1.2)][..], &[(0.01, 1.1)], &[(0.01, 0.9), (0.02, 1.0)]],
            "the model in order of x"
        );
        assert_eq!(weft_pear.x_label, "clamp distance (m)");
    }
}
