//! Moving least squares smoothing in symlog space (thesis App. A.3.3, (A.35); Alg. 4 lines 2-7,
//! Alg. 5 lines 2-9).
//!
//! At an evaluation point the data within `radius` is fitted in the weighted least-squares sense
//! by a quadratic polynomial centred at that point (1D: `1, x, x²`; 2D: `1, u, v, u², uv, v²`),
//! with the compactly supported, C² Wendland weight `w(r) = (1 - r/R)⁴ (4 r/R + 1)`; the MLS value
//! is the fitted polynomial's constant term. Where the weighted normal equations are
//! ill-conditioned or have too few points in the support, the fit falls back to the linear and
//! then the constant polynomial. The 2D radius is isotropic: the coordinates are expected to be
//! normalized per axis (Alg. 3 line 2) so one radius suits both.
//!
//! [`SmoothedEnergy1d`] and [`SmoothedEnergy2d`] are the smoothed energies
//! `g = symexp(MLS(· | X, symlog(Ψ)))` of (A.35), optionally symmetrized in the first argument
//! (for `s_a`: `MLS(u, ·) ← ½ (MLS(u, ·) + MLS(-u, ·))`), together with the finite-difference
//! estimates of the Hermite derivatives at the control points.

use nalgebra::{DMatrix, DVector};

/// Smallest admissible ratio of the extreme eigenvalues of the weighted normal matrix of a local
/// fit (in offsets scaled by the radius, so monomials are O(1)); below it the fit drops a degree.
/// This is a condition number of about `10⁵` for the weighted design matrix itself.
const MIN_EIGENVALUE_RATIO: f64 = 1e-10;

/// Central-difference step as a fraction of the smaller knot spacing next to a control point.
///
/// The MLS function is C² and varies on the scale of the radius (at least the knot spacing), so
/// the truncation error of the central difference is `O((0.1 h)² g''')`, i.e. about 1% of the
/// cubic term over one interval, while the rounding error `ε |g| / (0.1 h)` stays negligible.
/// The stencil stays well inside the neighbouring intervals.
pub const FD_STEP_FRACTION: f64 = 0.1;

/// The symmetric logarithm of App. A.3.3, the space of the smoothing, and its inverse.
pub use yarnhom_geom::symlog::{symexp, symlog};

/// The Wendland C² weight `(1 - r/R)⁴ (4 r/R + 1)` for `r < R`, else 0.
pub fn wendland(r: f64, radius: f64) -> f64 {
    let q = r / radius;
    if q < 1.0 { (1.0 - q).powi(4) * (4.0 * q + 1.0) } else { 0.0 }
}

/// One data point in the support: the monomials of its scaled offset (lowest degree first),
/// its weight and its value.
type SupportPoint = ([f64; 6], f64, f64);

/// The weighted least-squares fit with the first `terms` monomials; its constant term, or
/// `None` if the support is too small or the normal equations are ill-conditioned.
fn weighted_fit(support: &[SupportPoint], terms: usize) -> Option<f64> {
    if support.len() < terms {
        return None;
    }
    let mut normal = DMatrix::<f64>::zeros(terms, terms);
    let mut rhs = DVector::<f64>::zeros(terms);
    for (basis, w, y) in support {
        for a in 0..terms {
            rhs[a] += w * basis[a] * y;
            for b in 0..terms {
                normal[(a, b)] += w * basis[a] * basis[b];
            }
        }
    }
    let eigenvalues = normal.symmetric_eigenvalues();
    let (lo, hi) = (eigenvalues.min(), eigenvalues.max());
    if !(hi > 0.0 && lo >= MIN_EIGENVALUE_RATIO * hi) {
        return None;
    }
    normal.cholesky().map(|c| c.solve(&rhs)[0])
}

/// Tries the fits with `ladder[0]`, `ladder[1]`, … monomials and returns the first that works.
fn fit_with_fallback(support: &[SupportPoint], ladder: &[usize]) -> Option<f64> {
    ladder.iter().find_map(|&terms| weighted_fit(support, terms))
}

/// MLS value at `x` of the 1D data `(xs, ys)`: local weighted quadratic fit within `radius`,
/// falling back to linear then constant; `None` if no data lies within `radius`.
pub fn mls_1d(xs: &[f64], ys: &[f64], x: f64, radius: f64) -> Option<f64> {
    let support: Vec<SupportPoint> = xs
        .iter()
        .zip(ys)
        .filter_map(|(&xk, &yk)| {
            let w = wendland((xk - x).abs(), radius);
            let s = (xk - x) / radius;
            (w > 0.0).then_some(([1.0, s, s * s, 0.0, 0.0, 0.0], w, yk))
        })
        .collect();
    fit_with_fallback(&support, &[3, 2, 1])
}

/// MLS value at `(u, v)` of the scattered 2D data `(us, vs, ys)`: local weighted quadratic fit
/// (`1, u, v, u², uv, v²`) within the isotropic `radius`, falling back to linear (`1, u, v`)
/// then constant; `None` if no data lies within `radius`.
pub fn mls_2d(us: &[f64], vs: &[f64], ys: &[f64], u: f64, v: f64, radius: f64) -> Option<f64> {
    let support: Vec<SupportPoint> = us
        .iter()
        .zip(vs)
        .zip(ys)
        .filter_map(|((&uk, &vk), &yk)| {
            let w = wendland((uk - u).hypot(vk - v), radius);
            let (s, t) = ((uk - u) / radius, (vk - v) / radius);
            (w > 0.0).then_some(([1.0, s, t, s * s, s * t, t * t], w, yk))
        })
        .collect();
    fit_with_fallback(&support, &[6, 3, 1])
}

/// `½ (a + b)` where both exist, else whichever exists (the symmetrization of Alg. 4/5 line 3,
/// tolerant of data covering only one side).
fn symmetrize(a: Option<f64>, b: Option<f64>) -> Option<f64> {
    match (a, b) {
        (Some(a), Some(b)) => Some(0.5 * (a + b)),
        (a, b) => a.or(b),
    }
}

/// The central-difference step at knot `i`: [`FD_STEP_FRACTION`] of the smaller adjacent
/// spacing (of `fallback` for a single knot).
pub fn fd_step(knots: &[f64], i: usize, fallback: f64) -> f64 {
    let left = i.checked_sub(1).map(|l| knots[i] - knots[l]);
    let right = knots.get(i + 1).map(|r| r - knots[i]);
    let h = match (left, right) {
        (Some(a), Some(b)) => a.min(b),
        (a, b) => a.or(b).unwrap_or(fallback),
    };
    FD_STEP_FRACTION * h
}

/// The smoothed 1D energy `g(x) = symexp(MLS(x | X, symlog(Ψ)))` of (A.35), Alg. 4 line 3.
#[derive(Debug, Clone, PartialEq)]
pub struct SmoothedEnergy1d {
    xs: Vec<f64>,
    log_energies: Vec<f64>,
    radius: f64,
    symmetric: bool,
}

impl SmoothedEnergy1d {
    /// Smoothing of the samples `(strains, energies)` with MLS support `radius`.
    pub fn new(strains: &[f64], energies: &[f64], radius: f64) -> Self {
        let log_energies = energies.iter().map(|&e| symlog(e)).collect();
        SmoothedEnergy1d { xs: strains.to_vec(), log_energies, radius, symmetric: false }
    }

    /// Symmetrized in `x` (the `s_a` case of Alg. 4 line 3): `MLS(x) ← ½ (MLS(x) + MLS(-x))`.
    pub fn symmetric(mut self) -> Self {
        self.symmetric = true;
        self
    }

    /// The MLS value in symlog space (symmetrized if requested).
    pub fn mls(&self, x: f64) -> Option<f64> {
        let at = |x| mls_1d(&self.xs, &self.log_energies, x, self.radius);
        if self.symmetric { symmetrize(at(x), at(-x)) } else { at(x) }
    }

    /// `g(x)`; `None` where no data lies within the radius.
    pub fn value(&self, x: f64) -> Option<f64> {
        self.mls(x).map(symexp)
    }

    /// Hermite data at the control points (Alg. 4 lines 6-7): values `p = g(x)` and slopes
    /// `p^x` by central differences with step [`fd_step`]. `None` if `g` is undefined anywhere
    /// on a stencil.
    pub fn hermite_data(&self, knots: &[f64]) -> Option<(Vec<f64>, Vec<f64>)> {
        let mut values = Vec::with_capacity(knots.len());
        let mut slopes = Vec::with_capacity(knots.len());
        for (i, &x) in knots.iter().enumerate() {
            let d = fd_step(knots, i, self.radius);
            values.push(self.value(x)?);
            slopes.push((self.value(x + d)? - self.value(x - d)?) / (2.0 * d));
        }
        Some((values, slopes))
    }
}

/// Nodal Hermite data on a rectilinear grid, row-major with `v` outer (`[j * nu + i]`), as in
/// [`crate::hermite::Bicubic`].
#[derive(Debug, Clone, PartialEq)]
pub struct HermiteGrid {
    /// `p`.
    pub values: Vec<f64>,
    /// `p^u` (the text's `p^x`).
    pub du: Vec<f64>,
    /// `p^v` (the text's `p^y`).
    pub dv: Vec<f64>,
    /// `p^{uv}` (the text's `p^{xy}`).
    pub duv: Vec<f64>,
}

/// The smoothed 2D energy `g(u, v) = symexp(MLS(u, v | U, V, symlog(Ψ)))` of (A.35), Alg. 5
/// line 3.
#[derive(Debug, Clone, PartialEq)]
pub struct SmoothedEnergy2d {
    us: Vec<f64>,
    vs: Vec<f64>,
    log_energies: Vec<f64>,
    radius: f64,
    symmetric_u: bool,
}

impl SmoothedEnergy2d {
    /// Smoothing of the samples `(us, vs, energies)` with isotropic MLS support `radius`.
    pub fn new(us: &[f64], vs: &[f64], energies: &[f64], radius: f64) -> Self {
        let log_energies = energies.iter().map(|&e| symlog(e)).collect();
        SmoothedEnergy2d { us: us.to_vec(), vs: vs.to_vec(), log_energies, radius, symmetric_u: false }
    }

    /// Symmetrized in the first argument (the `s_a` case of Alg. 5 line 3):
    /// `MLS(u, v) ← ½ (MLS(u, v) + MLS(-u, v))`.
    pub fn symmetric_in_u(mut self) -> Self {
        self.symmetric_u = true;
        self
    }

    /// The MLS value in symlog space (symmetrized if requested).
    pub fn mls(&self, u: f64, v: f64) -> Option<f64> {
        let at = |u| mls_2d(&self.us, &self.vs, &self.log_energies, u, v, self.radius);
        if self.symmetric_u { symmetrize(at(u), at(-u)) } else { at(u) }
    }

    /// `g(u, v)`; `None` where no data lies within the radius.
    pub fn value(&self, u: f64, v: f64) -> Option<f64> {
        self.mls(u, v).map(symexp)
    }

    /// Hermite data at the grid nodes (Alg. 5 lines 8-9): `p = g`, and `p^u`, `p^v`, `p^{uv}` by
    /// central differences with per-axis steps [`fd_step`] (`p^{uv}` from the four diagonal
    /// neighbours). `None` if `g` is undefined anywhere on a stencil.
    pub fn hermite_data(&self, u_knots: &[f64], v_knots: &[f64]) -> Option<HermiteGrid> {
        let n = u_knots.len() * v_knots.len();
        let mut grid = HermiteGrid {
            values: Vec::with_capacity(n),
            du: Vec::with_capacity(n),
            dv: Vec::with_capacity(n),
            duv: Vec::with_capacity(n),
        };
        for (j, &v) in v_knots.iter().enumerate() {
            let dv = fd_step(v_knots, j, self.radius);
            for (i, &u) in u_knots.iter().enumerate() {
                let du = fd_step(u_knots, i, self.radius);
                let g = |a: f64, b: f64| self.value(u + a * du, v + b * dv);
                grid.values.push(g(0.0, 0.0)?);
                grid.du.push((g(1.0, 0.0)? - g(-1.0, 0.0)?) / (2.0 * du));
                grid.dv.push((g(0.0, 1.0)? - g(0.0, -1.0)?) / (2.0 * dv));
                grid.duv
                    .push((g(1.0, 1.0)? - g(1.0, -1.0)? - g(-1.0, 1.0)? + g(-1.0, -1.0)?) / (4.0 * du * dv));
            }
        }
        Some(grid)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::monotone_cubic::test_util::Rng;

    fn quadratic_1d(x: f64) -> f64 {
        0.7 - 1.3 * x + 2.1 * x * x
    }

    fn quadratic_2d(u: f64, v: f64) -> f64 {
        0.4 + 0.9 * u - 1.1 * v + 1.7 * u * u - 0.6 * u * v + 0.8 * v * v
    }

    fn scattered_2d(rng: &mut Rng, n: usize) -> (Vec<f64>, Vec<f64>) {
        (0..n).map(|_| (rng.range(-1.0, 1.0), rng.range(-1.0, 1.0))).unzip()
    }

    #[test]
    fn reproduces_quadratics_on_scattered_data() {
        let mut rng = Rng::new(41);
        let xs: Vec<f64> = (0..60).map(|_| rng.range(-1.0, 1.0)).collect();
        let ys: Vec<f64> = xs.iter().map(|&x| quadratic_1d(x)).collect();
        for _ in 0..50 {
            let x = rng.range(-0.9, 0.9);
            let got = mls_1d(&xs, &ys, x, 0.3).expect("support");
            assert!((got - quadratic_1d(x)).abs() < 1e-10, "{x}: {got}");
        }
        let (us, vs) = scattered_2d(&mut rng, 800);
        let ys: Vec<f64> = us.iter().zip(&vs).map(|(&u, &v)| quadratic_2d(u, v)).collect();
        for _ in 0..50 {
            let (u, v) = (rng.range(-0.9, 0.9), rng.range(-0.9, 0.9));
            let got = mls_2d(&us, &vs, &ys, u, v, 0.3).expect("support");
            assert!((got - quadratic_2d(u, v)).abs() < 1e-10, "({u}, {v}): {got}");
        }
    }

    #[test]
    fn smooths_noise() {
        let mut rng = Rng::new(43);
        let truth = |x: f64| (3.0 * x).sin() + x * x;
        let xs: Vec<f64> = (0..400).map(|k| -1.0 + 2.0 * k as f64 / 399.0).collect();
        let noisy: Vec<f64> = xs.iter().map(|&x| truth(x) + 0.1 * rng.normal()).collect();
        let rms = |f: &dyn Fn(f64, f64) -> f64| {
            yarnhom_geom::stats::root_mean_square(xs.iter().zip(&noisy).map(|(&x, &y)| f(x, y) - truth(x)))
        };
        let raw = rms(&|_, y| y);
        let smoothed = rms(&|x, _| mls_1d(&xs, &noisy, x, 0.25).unwrap_or(f64::NAN));
        assert!(smoothed < 0.4 * raw, "1D: {smoothed} vs {raw}");

        let truth2 = |u: f64, v: f64| (2.0 * u).sin() * (1.0 + v) + v * v;
        let (us, vs) = scattered_2d(&mut rng, 2500);
        let noisy: Vec<f64> = us.iter().zip(&vs).map(|(&u, &v)| truth2(u, v) + 0.1 * rng.normal()).collect();
        let (mut raw, mut smoothed) = (0.0, 0.0);
        for k in 0..us.len() {
            let got = mls_2d(&us, &vs, &noisy, us[k], vs[k], 0.35).unwrap_or(f64::NAN);
            raw += (noisy[k] - truth2(us[k], vs[k])).powi(2);
            smoothed += (got - truth2(us[k], vs[k])).powi(2);
        }
        assert!(smoothed.sqrt() < 0.4 * raw.sqrt(), "2D: {smoothed} vs {raw}");
    }

    #[test]
    fn falls_back_to_lower_degree_and_none_without_support() {
        let (xs, ys) = ([0.0, 1.0, 5.0], [1.0, 3.0, 0.0]);
        // two points in support: linear through them
        assert!((mls_1d(&xs, &ys, 0.5, 2.0).expect("linear") - 2.0).abs() < 1e-12);
        // one point: constant
        assert_eq!(mls_1d(&xs, &ys, 5.2, 1.0), Some(0.0));
        assert_eq!(mls_1d(&xs, &ys, 3.0, 1.0), None);
        // collinear 2D data: the quadratic and linear fits are singular, a plane along the line is
        // not identifiable; but data on a line gives a constant-or-better finite answer
        let us: Vec<f64> = (0..10).map(|k| k as f64 * 0.1).collect();
        let vs = vec![0.0; 10];
        let ys: Vec<f64> = us.iter().map(|u| 2.0 * u).collect();
        let got = mls_2d(&us, &vs, &ys, 0.45, 0.0, 0.3).expect("support");
        assert!(got.is_finite() && (got - 0.9).abs() < 0.2, "{got}");
        assert_eq!(mls_2d(&us, &vs, &ys, 0.45, 2.0, 0.3), None);
    }

    #[test]
    fn symmetrized_smoothing_is_even() {
        let mut rng = Rng::new(47);
        let xs: Vec<f64> = (0..100).map(|_| rng.range(-1.0, 1.0)).collect();
        let es: Vec<f64> = xs.iter().map(|&x| 3.0 * x + x * x + 0.1 * rng.normal()).collect();
        let g = SmoothedEnergy1d::new(&xs, &es, 0.3).symmetric();
        for x in [0.0, 0.1, 0.33, 0.8] {
            assert_eq!(g.value(x), g.value(-x));
        }
        let (us, vs) = scattered_2d(&mut rng, 600);
        let es: Vec<f64> = us.iter().zip(&vs).map(|(&u, &v)| u + 2.0 * u * v + v * v).collect();
        let g = SmoothedEnergy2d::new(&us, &vs, &es, 0.4).symmetric_in_u();
        for (u, v) in [(0.2, 0.1), (0.7, -0.5), (0.0, 0.3)] {
            assert_eq!(g.value(u, v), g.value(-u, v));
            assert!(g.value(u, v).expect("support").is_finite());
        }
    }

    #[test]
    fn hermite_data_matches_derivatives_of_the_smoothed_energy() {
        // energies whose symlog is quadratic: MLS reproduces it, so g is known exactly
        let q = |x: f64| 0.3 + 1.5 * x + 2.0 * x * x;
        let xs: Vec<f64> = (0..150).map(|k| -1.0 + 2.0 * k as f64 / 149.0).collect();
        let es: Vec<f64> = xs.iter().map(|&x| symexp(q(x))).collect();
        let g = SmoothedEnergy1d::new(&xs, &es, 0.2);
        let knots = [-0.9, -0.45, 0.0, 0.45, 0.9];
        let (p, m) = g.hermite_data(&knots).expect("support");
        for (k, &x) in knots.iter().enumerate() {
            let gx = q(x); // > 0 everywhere
            let slope = gx.exp() * (1.5 + 4.0 * x);
            assert!((p[k] - symexp(gx)).abs() < 1e-9 * p[k].abs().max(1.0));
            assert!((m[k] - slope).abs() < 2e-2 * slope.abs().max(1.0), "{x}: {} vs {slope}", m[k]);
        }

        let q2 = |u: f64, v: f64| 1.0 + 0.5 * u - 0.3 * v + 0.4 * u * u + 0.9 * u * v + 0.2 * v * v;
        let mut rng = Rng::new(53);
        let (us, vs) = scattered_2d(&mut rng, 1500);
        let es: Vec<f64> = us.iter().zip(&vs).map(|(&u, &v)| symexp(q2(u, v))).collect();
        let g = SmoothedEnergy2d::new(&us, &vs, &es, 0.35);
        let (uk, vk) = ([-0.6, 0.0, 0.6], [-0.5, 0.0, 0.5]);
        let grid = g.hermite_data(&uk, &vk).expect("support");
        for (j, &v) in vk.iter().enumerate() {
            for (i, &u) in uk.iter().enumerate() {
                let n = j * 3 + i;
                let e = q2(u, v).exp(); // q2 > 0 on this box
                let (qu, qv) = (0.5 + 0.8 * u + 0.9 * v, -0.3 + 0.9 * u + 0.4 * v);
                let (gu, gv, guv) = (e * qu, e * qv, e * (qu * qv + 0.9));
                assert!((grid.values[n] - (e - 1.0)).abs() < 1e-9);
                assert!((grid.du[n] - gu).abs() < 1e-2 * gu.abs().max(1.0), "du at ({u}, {v})");
                assert!((grid.dv[n] - gv).abs() < 1e-2 * gv.abs().max(1.0), "dv at ({u}, {v})");
                assert!((grid.duv[n] - guv).abs() < 2e-2 * guv.abs().max(1.0), "duv at ({u}, {v})");
            }
        }
    }
}
