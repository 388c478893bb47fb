//! The strain ranges a fitted material was sampled over, recovered from its control points.
//!
//! A fit places each term's control points over a fixed share ("span") of the range the term was
//! sampled on ([`crate::fit::control_points`]): 0.95 for 1D terms (Alg. 4), 0.9 for 2D terms
//! (Alg. 5) and 0.3 for the stockinette's bending terms (Sec. 4.3, [`STOCKINETTE_SPAN_2D_BENDING`]).
//! Dividing a term's knot extent by its span gives the range back. A material fitted by yarnhom
//! records its spans; an imported ARCSim-HYLC material does not, and the span of its bending
//! terms is the one that gives their in-plane axis the range that axis has in the in-plane
//! terms (Alg. 6 samples a strain over one range in all planes whose partner is of one kind).

use yarnhom_artifacts::grid::AXIS_NAMES;
use yarnhom_artifacts::{FitSettings, Spline, SplineOrigin};

use crate::fit::SHEAR;

/// The span of the stockinette's 2D bending control points (Sec. 4.3: concentrated near the
/// origin for curling knits); `yarnhom fit --stockinette` uses it.
pub const STOCKINETTE_SPAN_2D_BENDING: f64 = 0.3;

/// Relative tolerance for two recovered ranges to be the same.
const SAME_RANGE: f64 = 1e-6;

/// A material's sampled ranges, `[lower, upper]` of each axis.
#[derive(Debug, Clone, PartialEq)]
pub struct SampledRanges {
    /// The range of each 1D term, by axis of `(sx, sa, sy, kx, ky)`.
    pub single: [[f64; 2]; 5],
    /// Per 2D term: its axes (ascending) and the range of each.
    pub planes: Vec<([u8; 2], [[f64; 2]; 2])>,
}

/// Why the sampled ranges cannot be recovered.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RangeError {
    /// A term the recovery needs is missing.
    #[error("the material has no term {0}")]
    MissingTerm(String),
    /// No candidate span gives a bending term's in-plane axis its in-plane range.
    #[error(
        "cannot tell the span of the 2D term {term}: neither 0.9 nor 0.3 gives {axis} the range it has in \
         the in-plane terms"
    )]
    UnknownSpan {
        /// The 2D term, e.g. `sx,kx`.
        term: String,
        /// Its in-plane axis.
        axis: &'static str,
    },
}

/// The ranges `spline` was sampled over (see the module documentation).
pub fn sampled_ranges(spline: &Spline) -> Result<SampledRanges, RangeError> {
    let spans = match &spline.origin {
        SplineOrigin::Fitted { settings } => settings.clone(),
        SplineOrigin::ImportedArcsim { .. } => FitSettings::default(),
    };
    let extent = |knots: &[f64], axis: u8, span: f64| {
        let scale = spline.strain_scale[axis as usize] / span;
        [knots[0] * scale, knots[knots.len() - 1] * scale]
    };
    let mut single = [[0.0; 2]; 5];
    for (axis, range) in single.iter_mut().enumerate() {
        let term = spline
            .terms_1d
            .iter()
            .find(|t| t.axis as usize == axis)
            .ok_or_else(|| RangeError::MissingTerm(AXIS_NAMES[axis].into()))?;
        *range = extent(&term.knots, term.axis, spans.span_1d);
    }
    let in_plane: Vec<([u8; 2], [[f64; 2]; 2])> = spline
        .terms_2d
        .iter()
        .filter(|t| t.axes[1] < 3)
        .map(|t| {
            (
                t.axes,
                [extent(&t.u_knots, t.axes[0], spans.span_2d), extent(&t.v_knots, t.axes[1], spans.span_2d)],
            )
        })
        .collect();
    let mut planes = in_plane.clone();
    for t in spline.terms_2d.iter().filter(|t| t.axes[1] >= 3) {
        let span = match &spline.origin {
            SplineOrigin::Fitted { settings } => settings.span_2d_bending,
            SplineOrigin::ImportedArcsim { .. } => bending_span(&in_plane, t.axes, &t.u_knots, &extent)?,
        };
        planes.push((t.axes, [extent(&t.u_knots, t.axes[0], span), extent(&t.v_knots, t.axes[1], span)]));
    }
    planes.sort_by_key(|(axes, _)| *axes);
    Ok(SampledRanges { single, planes })
}

/// The span of an imported bending term over `axes` (in-plane axis first): the candidate that
/// gives the in-plane axis the range it has in the in-plane term it shares with `sa` (for `sa`
/// itself, with `sx`).
fn bending_span(
    in_plane: &[([u8; 2], [[f64; 2]; 2])],
    axes: [u8; 2],
    u_knots: &[f64],
    extent: &impl Fn(&[f64], u8, f64) -> [f64; 2],
) -> Result<f64, RangeError> {
    let axis = axes[0];
    let shear = SHEAR as u8;
    let partner = if axis == shear { 0 } else { shear };
    let pair = if axis < partner { [axis, partner] } else { [partner, axis] };
    let reference =
        in_plane.iter().find(|(a, _)| *a == pair).map(|(a, r)| r[usize::from(a[1] == axis)]).ok_or_else(
            || {
                RangeError::MissingTerm(format!(
                    "{},{}",
                    AXIS_NAMES[pair[0] as usize], AXIS_NAMES[pair[1] as usize]
                ))
            },
        )?;
    let same =
        |r: [f64; 2]| r.iter().zip(reference).all(|(a, b)| (a - b).abs() <= SAME_RANGE * b.abs().max(1e-12));
    [FitSettings::default().span_2d_bending, STOCKINETTE_SPAN_2D_BENDING]
        .into_iter()
        .find(|&span| same(extent(u_knots, axis, span)))
        .ok_or_else(|| RangeError::UnknownSpan {
            term: format!("{},{}", AXIS_NAMES[axes[0] as usize], AXIS_NAMES[axes[1] as usize]),
            axis: AXIS_NAMES[axis as usize],
        })
}
