//! Colour scales of heat maps: the symmetric logarithm of App. A.3.3 and colour maps over it.

use crate::Colour;

pub use yarnhom_geom::symlog::{symexp, symlog};

/// Smallest and largest of the finite numbers; `None` if there is none.
pub fn finite_range(values: impl IntoIterator<Item = f64>) -> Option<(f64, f64)> {
    values
        .into_iter()
        .filter(|x| x.is_finite())
        .fold(None, |r, x| Some(r.map_or((x, x), |(lo, hi): (f64, f64)| (lo.min(x), hi.max(x)))))
}

/// Colour of missing values (not finite: no sample, or a failed one).
pub(crate) const MISSING: Colour = Colour::rgb(0xBB, 0xBB, 0xBB);

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
const BLUE_WHITE_RED: [(u8, u8, u8); 5] =
    [(33, 102, 172), (146, 197, 222), (247, 247, 247), (244, 165, 130), (178, 24, 43)];

/// A colour map over `[0, 1]`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ColourMap {
    /// Viridis (dark blue to yellow), for values of one sign.
    Viridis,
    /// Blue, white at the middle, red: for signed values.
    BlueWhiteRed,
}

impl ColourMap {
    /// The colour at `t` (clamped to `[0, 1]`; 0 if not finite): piecewise linear through the
    /// map's anchors at equally spaced `t`.
    fn at(self, t: f64) -> Colour {
        let anchors: &[(u8, u8, u8)] = match self {
            ColourMap::Viridis => &VIRIDIS,
            ColourMap::BlueWhiteRed => &BLUE_WHITE_RED,
        };
        let t = if t.is_finite() { t.clamp(0.0, 1.0) } else { 0.0 };
        let x = t * (anchors.len() - 1) as f64;
        let k = (x.floor() as usize).min(anchors.len() - 2);
        let f = x - k as f64;
        let (a, b) = (anchors[k], anchors[k + 1]);
        let mix = |p: u8, q: u8| (p as f64 + f * (q as f64 - p as f64)).round() as u8;
        Colour::rgb(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
    }
}

/// A colour map over the symlog values `[lo, hi]` (App. A.3.3): values are coloured by their
/// [`symlog`], the bar is labelled in values.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ColourScale {
    /// The symlog value at the map's start.
    pub lo: f64,
    /// The symlog value at the map's end.
    pub hi: f64,
    /// The colours.
    pub map: ColourMap,
}

impl ColourScale {
    /// Viridis over the symlog range of the finite values.
    pub fn sequential(values: impl IntoIterator<Item = f64>) -> Self {
        let (lo, hi) = finite_range(values.into_iter().map(symlog)).unwrap_or((0.0, 1.0));
        let (lo, hi) = if hi > lo { (lo, hi) } else { (lo - 1e-6, hi + 1e-6) };
        Self { lo, hi, map: ColourMap::Viridis }
    }

    /// Blue-white-red symmetric about 0 over the symlog range of the finite values.
    pub fn signed(values: impl IntoIterator<Item = f64>) -> Self {
        let m = finite_range(values.into_iter().map(|x| symlog(x).abs())).map_or(0.0, |r| r.1).max(1e-6);
        Self { lo: -m, hi: m, map: ColourMap::BlueWhiteRed }
    }

    /// The colour of a value (grey if it is not finite).
    pub fn colour(&self, value: f64) -> Colour {
        if !value.is_finite() {
            return MISSING;
        }
        self.colour_of_symlog(symlog(value))
    }

    /// The colour of the symlog value `s`.
    pub fn colour_of_symlog(&self, s: f64) -> Colour {
        self.map.at(self.position(s))
    }

    /// Where the symlog value `s` lies on the map: 0 at `lo`, 1 at `hi`.
    fn position(&self, s: f64) -> f64 {
        (s - self.lo) / (self.hi - self.lo)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn colours_are_clamped_to_the_ends_of_the_map() {
        let scale = ColourScale::sequential([0.1, 10.0]);
        assert_eq!(scale.colour(0.1), Colour::rgb(68, 1, 84));
        assert_eq!(scale.colour(1e9), Colour::rgb(253, 231, 37));
        assert_eq!(scale.colour(f64::NAN), MISSING);
    }

    #[test]
    fn the_signed_scale_maps_zero_to_the_centre_colour_and_is_odd_symmetric() {
        let scale = ColourScale::signed([-2.0, 0.5, 1.0]);
        assert_eq!(scale.colour(0.0), Colour::rgb(247, 247, 247), "white in the middle");
        assert_eq!((scale.lo, scale.hi), (-symlog(2.0), symlog(2.0)), "symmetric about 0");
        for x in [1e-3, 0.2, 0.5, 1.0, 1.7, 2.0] {
            let (plus, minus) = (scale.position(symlog(x)), scale.position(symlog(-x)));
            assert!((plus - 0.5 + (minus - 0.5)).abs() < 1e-12, "{x}: {plus} and {minus}");
            assert!(plus > 0.5, "{x}: positive values on the red side");
        }
        assert_eq!(scale.colour(2.0), Colour::rgb(178, 24, 43), "the largest magnitude: full red");
        assert_eq!(scale.colour(-2.0), Colour::rgb(33, 102, 172), "and full blue");
    }

    #[test]
    fn a_scale_of_one_value_or_none_is_not_degenerate() {
        for scale in [ColourScale::sequential([3.0]), ColourScale::sequential([f64::NAN])] {
            assert!(scale.hi > scale.lo, "{scale:?}");
        }
        assert!(ColourScale::signed([0.0]).hi > 0.0);
    }
}
