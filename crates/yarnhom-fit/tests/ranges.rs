//! The sampled ranges recovered from a fitted material's control points.

use yarnhom_artifacts::{FitSettings, Spline};
use yarnhom_fit::fit::fit_grid;
use yarnhom_fit::ranges::STOCKINETTE_SPAN_2D_BENDING;
use yarnhom_fit::synthetic::synthetic_grid;
use yarnhom_fit::{RangeError, sampled_ranges};

fn published(name: &str) -> Spline {
    let path = format!("{}/../../../shared/data/hylc-materials/{name}.json", env!("CARGO_MANIFEST_DIR"));
    yarnhom_artifacts::open::open_artifact::<yarnhom_artifacts::Spline>(&path)
        .map(|o| o.value)
        .unwrap_or_else(|e| panic!("{path}: {e}"))
}

/// Whether `x` is a whole multiple of `step` (to rounding).
fn multiple_of(x: f64, step: f64) -> bool {
    ((x / step).round() * step - x).abs() <= 1e-9 * step.max(x.abs())
}

/// Every recovered bound of the published materials is round (strains in steps of 0.005,
/// curvatures of 0.1 1/m); the wrong span would not give round numbers (0.741 / 0.9 = 0.8233...).
#[test]
fn the_published_materials_were_sampled_over_round_ranges() {
    for name in ["stock1", "stock01", "rib1", "honey1", "basket1", "satin1", "satin01"] {
        let ranges = sampled_ranges(&published(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(ranges.planes.len(), 9, "{name}");
        let bounds = ranges
            .single
            .iter()
            .enumerate()
            .map(|(axis, r)| (axis as u8, *r))
            .chain(ranges.planes.iter().flat_map(|(axes, r)| [(axes[0], r[0]), (axes[1], r[1])]));
        for (axis, [lower, upper]) in bounds {
            let step = if axis < 3 { 0.005 } else { 0.1 };
            assert!(lower < 0.0 && upper > 0.0, "{name}: axis {axis} [{lower}, {upper}]");
            assert!(
                multiple_of(lower, step) && multiple_of(upper, step),
                "{name}: axis {axis} [{lower}, {upper}]"
            );
        }
    }
}

#[test]
fn only_the_stockinettes_bending_terms_span_three_tenths_of_their_range() {
    for (name, stockinette) in
        [("stock1", true), ("stock01", true), ("rib1", false), ("honey1", false), ("satin1", false)]
    {
        let spline = published(name);
        let ranges = sampled_ranges(&spline).expect("ranges");
        let term = spline.terms_2d.iter().find(|t| t.axes == [0, 3]).expect("sx,kx");
        let (_, [_, kx]) = ranges.planes.iter().find(|(a, _)| *a == [0, 3]).copied().expect("sx,kx");
        let span = term.v_knots[term.v_knots.len() - 1] * spline.strain_scale[3] / kx[1];
        let expected =
            if stockinette { STOCKINETTE_SPAN_2D_BENDING } else { FitSettings::default().span_2d_bending };
        assert!((span - expected).abs() < 1e-9, "{name}: span {span}");
    }
}

#[test]
fn a_fit_gives_back_the_ranges_of_its_grid() {
    let grid = synthetic_grid();
    for stockinette in [false, true] {
        let mut settings = FitSettings::default();
        if stockinette {
            settings.span_2d_bending = STOCKINETTE_SPAN_2D_BENDING;
        }
        let spline = fit_grid(&grid, &settings, 0.3).expect("fit");
        let ranges = sampled_ranges(&spline).expect("ranges");
        for term in &grid.terms {
            let sampled: Vec<[f64; 2]> = term.values.iter().map(|v| [v[0], v[v.len() - 1]]).collect();
            let recovered: Vec<[f64; 2]> = match term.axes[..] {
                [a] => vec![ranges.single[a as usize]],
                [a, b] => ranges.planes.iter().find(|(p, _)| *p == [a, b]).expect("plane").1.to_vec(),
                _ => unreachable!("terms have one or two axes"),
            };
            for (s, r) in sampled.iter().zip(&recovered) {
                assert!(
                    (s[0] - r[0]).abs() <= 1e-9 * s[0].abs() && (s[1] - r[1]).abs() <= 1e-9 * s[1],
                    "{:?}: {s:?} vs {r:?}",
                    term.axes
                );
            }
        }
    }
}

#[test]
fn a_bending_term_of_no_known_span_is_refused() {
    let mut spline = published("rib1");
    let term = spline.terms_2d.iter_mut().find(|t| t.axes == [2, 4]).expect("sy,ky");
    term.u_knots.iter_mut().for_each(|k| *k *= 0.5);
    let error = sampled_ranges(&spline).expect_err("no span fits");
    assert!(matches!(&error, RangeError::UnknownSpan { term, axis: "sy" } if term == "sy,ky"), "{error}");
    spline.terms_1d.retain(|t| t.axis != 4);
    assert_eq!(sampled_ranges(&spline), Err(RangeError::MissingTerm("ky".into())));
}
