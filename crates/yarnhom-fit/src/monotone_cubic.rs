//! Piecewise monotone cubic Hermite interpolation after Fritsch and Carlson (1980), the
//! "monotone cubic algorithm" of Alg. 4 line 18 (thesis App. A.3).
//!
//! On an interval `[x_i, x_{i+1}]` with secant `Δ_i / h_i`, the Hermite cubic is monotone in the
//! sense of the data if both end slopes lie between 0 and `3 Δ_i / h_i` — the "box" sufficient
//! condition of Fritsch and Carlson, which is (B.2) of App. B in one dimension. Where
//! `Δ_i = 0` this forces both slopes to zero; at a data extremum (adjacent secants of opposite
//! sign) it forces the slope to zero. Slopes are only ever shrunk towards zero, so slopes that
//! already satisfy the condition are returned untouched.

/// Clamps `m` into the closed interval spanned by `a` and `b` (in either order).
///
/// All constraints of App. B are of this form ("reversed inequalities" for decreasing data
/// simply swap the ends), so callers never need to sort the bounds themselves.
pub(crate) fn clamp_between(m: f64, a: f64, b: f64) -> f64 {
    m.clamp(a.min(b), a.max(b))
}

/// The slope bound `3 Δ / h` of (B.2) for one interval: admissible slopes at either end of the
/// interval lie between 0 and this value.
pub(crate) fn slope_bound(h: f64, delta: f64) -> f64 {
    3.0 * delta / h
}

/// Limits `slopes` so that the cubic Hermite spline through `(knots, values, slopes)` is
/// monotone on every interval in the sense of its data (Fritsch–Carlson box condition, (B.2)).
///
/// Each slope is clamped into `[0, 3 Δ_i / h_i]` (or `[3 Δ_i / h_i, 0]` for a decreasing
/// interval) for both adjacent intervals in turn. Consequences:
/// - on an interval with `Δ_i = 0` both end slopes become 0;
/// - a slope whose sign disagrees with an adjacent secant becomes 0, in particular at a data
///   extremum where the adjacent secants differ in sign;
/// - `|slope| ≤ 3 |Δ_i / h_i|` for both adjacent intervals.
///
/// Slopes are only shrunk towards zero, never flipped, so admissible slopes are untouched.
/// `knots` must be strictly increasing and all three slices of equal length.
pub fn limit_slopes_monotone(knots: &[f64], values: &[f64], slopes: &mut [f64]) {
    for i in 0..knots.len().saturating_sub(1) {
        let bound = slope_bound(knots[i + 1] - knots[i], values[i + 1] - values[i]);
        slopes[i] = clamp_between(slopes[i], 0.0, bound);
        slopes[i + 1] = clamp_between(slopes[i + 1], 0.0, bound);
    }
}

/// Test helpers shared by the modules of this crate.
#[cfg(test)]
pub(crate) mod test_util {
    /// A tiny xorshift64* generator, deterministic across platforms.
    pub(crate) struct Rng(u64);

    impl Rng {
        /// A generator from a nonzero seed.
        pub(crate) fn new(seed: u64) -> Self {
            Rng(seed.max(1))
        }

        /// A uniform sample in `[0, 1)`.
        pub(crate) fn unit(&mut self) -> f64 {
            self.0 ^= self.0 >> 12;
            self.0 ^= self.0 << 25;
            self.0 ^= self.0 >> 27;
            let bits = self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11;
            bits as f64 / (1u64 << 53) as f64
        }

        /// A uniform sample in `[a, b)`.
        pub(crate) fn range(&mut self, a: f64, b: f64) -> f64 {
            a + (b - a) * self.unit()
        }

        /// A standard normal sample (Box–Muller).
        pub(crate) fn normal(&mut self) -> f64 {
            let u = self.unit().max(1e-300);
            let v = self.unit();
            (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
        }
    }

    /// `n` strictly increasing knots starting at a random point of `[lo, hi)` with random
    /// spacings in `[0.2, 1.2)`.
    pub(crate) fn random_knots(rng: &mut Rng, n: usize, (lo, hi): (f64, f64)) -> Vec<f64> {
        let mut t = rng.range(lo, hi);
        (0..n)
            .map(|_| {
                let here = t;
                t += rng.range(0.2, 1.2);
                here
            })
            .collect()
    }

    /// `n` equally spaced samples covering `[a, b]`.
    pub(crate) fn linspace(a: f64, b: f64, n: usize) -> Vec<f64> {
        (0..n).map(|k| a + (b - a) * k as f64 / (n - 1) as f64).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::test_util::{Rng, random_knots};
    use super::*;
    use crate::hermite::Cubic;

    /// Whether the dense samples of `f` on every interval follow the sense of its data.
    fn monotone_on_every_interval(f: &Cubic) -> bool {
        (0..f.knots.len() - 1).all(|i| {
            let (a, b) = (f.knots[i], f.knots[i + 1]);
            let sense = (f.values[i + 1] - f.values[i]).signum();
            let samples: Vec<f64> = (0..=200).map(|k| f.value(a + (b - a) * k as f64 / 200.0)).collect();
            let scale = f.values[i].abs().max(f.values[i + 1].abs()).max(1.0);
            samples.windows(2).all(|w| {
                let step = w[1] - w[0];
                if sense == 0.0 { step.abs() <= 1e-12 * scale } else { step * sense >= -1e-12 * scale }
            })
        })
    }

    #[test]
    fn random_data_becomes_monotone_on_every_interval() {
        let mut rng = Rng::new(7);
        for trial in 0..200 {
            let n = 2 + trial % 12;
            let knots = random_knots(&mut rng, n, (-3.0, 3.0));
            let mut values: Vec<f64> = (0..n).map(|_| rng.range(-2.0, 2.0)).collect();
            if trial % 5 == 0 && n > 2 {
                values[1] = values[0]; // a flat interval
            }
            let mut slopes: Vec<f64> = (0..n).map(|_| 10.0 * rng.normal()).collect();
            limit_slopes_monotone(&knots, &values, &mut slopes);
            let f = Cubic { knots, values, slopes };
            assert!(monotone_on_every_interval(&f), "trial {trial}: {f:?}");
        }
    }

    #[test]
    fn flat_intervals_and_extrema_get_zero_slopes() {
        let knots = [0.0, 1.0, 2.0, 3.0];
        let values = [0.0, 1.0, 1.0, 0.5];
        let mut slopes = [0.7, 2.0, -1.0, 5.0];
        limit_slopes_monotone(&knots, &values, &mut slopes);
        assert_eq!(slopes, [0.7, 0.0, 0.0, 0.0]);
        // data maximum at knot 1 with secants of opposite sign
        let mut slopes = [1.0, 0.5, -0.2];
        limit_slopes_monotone(&knots[..3], &[0.0, 1.0, 0.0], &mut slopes);
        assert_eq!(slopes, [1.0, 0.0, -0.2]);
    }

    #[test]
    fn admissible_slopes_are_untouched_and_large_ones_clamped() {
        let knots = [0.0, 0.5, 2.0];
        let values = [0.0, 1.0, 4.0]; // secants 2 and 2
        let mut slopes = [0.0, 6.0, 5.9];
        limit_slopes_monotone(&knots, &values, &mut slopes);
        assert_eq!(slopes, [0.0, 6.0, 5.9]);
        let mut slopes = [7.0, 8.0, 9.0];
        limit_slopes_monotone(&knots, &values, &mut slopes);
        assert_eq!(slopes, [6.0, 6.0, 6.0]);
    }
}
