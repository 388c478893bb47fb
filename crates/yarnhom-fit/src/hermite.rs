//! Cubic and bicubic Hermite splines with first and second derivatives, extrapolated linearly
//! past their end knots (thesis App. A.3.5, B).
//!
//! A 1D spline interpolates values `p` and slopes `m` at knots `t`; a 2D patch interpolates
//! values, both first derivatives and the cross derivative at the nodes of a rectilinear grid,
//! nodal arrays row-major with `v` outer (`[j * nu + i]`). Outside the knots a spline continues
//! linearly with the value and slope of its end knot; a patch does so in each extrapolated
//! direction, "a cell with an edge at infinity", exactly as ARCSim-HYLC evaluates the published
//! materials.

/// Value, first and second derivative of a 1D function at a point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Jet1 {
    /// `f`.
    pub value: f64,
    /// `f'`.
    pub d1: f64,
    /// `f''`.
    pub d2: f64,
}

/// Value, gradient and Hessian of a 2D function at a point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Jet2 {
    /// `f`.
    pub value: f64,
    /// `(f_u, f_v)`.
    pub d1: [f64; 2],
    /// `(f_uu, f_uv, f_vv)`.
    pub d2: [f64; 3],
}

/// Where `x` falls among a spline's knots: inside the interval `knots[i]..knots[i + 1]` at
/// `s = (x - knots[i]) / h`, or past an end knot by `d` (the linear continuation).
#[derive(Debug, Clone, Copy)]
enum Place {
    Below(f64),
    Inside { s: f64, h: f64 },
    Above(f64),
}

/// The interval index `i` (`knots[i]..knots[i + 1]`, the first or last past the ends) of `x`.
fn locate(knots: &[f64], x: f64) -> (usize, Place) {
    let last = knots.len() - 1;
    let i = knots.partition_point(|&t| t <= x).clamp(1, last) - 1;
    let place = if x < knots[0] {
        Place::Below(x - knots[0])
    } else if x > knots[last] {
        Place::Above(x - knots[last])
    } else {
        let h = knots[i + 1] - knots[i];
        Place::Inside { s: (x - knots[i]) / h, h }
    };
    (i, place)
}

impl Place {
    /// The cubic Hermite weights of `[value at left, value at right, slope at left, slope at
    /// right]` for the value; past an end knot, its value plus slope times distance.
    fn value_weights(self) -> [f64; 4] {
        match self {
            Place::Below(d) => [1.0, 0.0, d, 0.0],
            Place::Above(d) => [0.0, 1.0, 0.0, d],
            Place::Inside { s, h } => {
                let (s2, s3) = (s * s, s * s * s);
                [2.0 * s3 - 3.0 * s2 + 1.0, -2.0 * s3 + 3.0 * s2, h * (s3 - 2.0 * s2 + s), h * (s3 - s2)]
            }
        }
    }

    /// The weights of the value, first and second derivative (in the knot coordinate).
    fn basis(self) -> [[f64; 4]; 3] {
        let value = self.value_weights();
        match self {
            Place::Below(_) => [value, [0.0, 0.0, 1.0, 0.0], [0.0; 4]],
            Place::Above(_) => [value, [0.0, 0.0, 0.0, 1.0], [0.0; 4]],
            Place::Inside { s, h } => {
                let s2 = s * s;
                [
                    value,
                    [
                        (6.0 * s2 - 6.0 * s) / h,
                        (-6.0 * s2 + 6.0 * s) / h,
                        3.0 * s2 - 4.0 * s + 1.0,
                        3.0 * s2 - 2.0 * s,
                    ],
                    [
                        (12.0 * s - 6.0) / (h * h),
                        (-12.0 * s + 6.0) / (h * h),
                        (6.0 * s - 4.0) / h,
                        (6.0 * s - 2.0) / h,
                    ],
                ]
            }
        }
    }
}

/// A cubic Hermite spline with linear extrapolation.
#[derive(Debug, Clone, PartialEq)]
pub struct Cubic {
    /// Knots, strictly ascending, at least two.
    pub knots: Vec<f64>,
    /// Values at the knots.
    pub values: Vec<f64>,
    /// Slopes at the knots.
    pub slopes: Vec<f64>,
}

impl Cubic {
    /// Value and derivatives at `x`.
    pub fn jet(&self, x: f64) -> Jet1 {
        let (i, place) = locate(&self.knots, x);
        let [w0, w1, w2] = place.basis();
        let c = self.coefficients(i);
        Jet1 { value: dot4(&w0, &c), d1: dot4(&w1, &c), d2: dot4(&w2, &c) }
    }

    /// The value at `x` (the same as [`Cubic::jet`]'s, to the last bit).
    pub fn value(&self, x: f64) -> f64 {
        let (i, place) = locate(&self.knots, x);
        dot4(&place.value_weights(), &self.coefficients(i))
    }

    /// Interval `i`'s Hermite coefficients: values and slopes at its ends.
    fn coefficients(&self, i: usize) -> [f64; 4] {
        [self.values[i], self.values[i + 1], self.slopes[i], self.slopes[i + 1]]
    }
}

/// `Σ w_k c_k`.
fn dot4(w: &[f64; 4], c: &[f64; 4]) -> f64 {
    w.iter().zip(c).map(|(w, c)| w * c).sum()
}

impl From<&yarnhom_artifacts::CubicTerm> for Cubic {
    /// The spline of a stored 1D term (in normalized strain).
    fn from(term: &yarnhom_artifacts::CubicTerm) -> Self {
        Self { knots: term.knots.clone(), values: term.values.clone(), slopes: term.slopes.clone() }
    }
}

/// A bicubic Hermite patch with linear extrapolation.
#[derive(Debug, Clone, PartialEq)]
pub struct Bicubic {
    /// Knots of `u`, strictly ascending, at least two.
    pub u_knots: Vec<f64>,
    /// Knots of `v`, strictly ascending, at least two.
    pub v_knots: Vec<f64>,
    /// Values at the nodes, `[j * nu + i]`.
    pub values: Vec<f64>,
    /// `f_u` at the nodes.
    pub du: Vec<f64>,
    /// `f_v` at the nodes.
    pub dv: Vec<f64>,
    /// `f_uv` at the nodes.
    pub duv: Vec<f64>,
}

impl From<&yarnhom_artifacts::BicubicTerm> for Bicubic {
    /// The patch of a stored 2D term (in normalized strains).
    fn from(term: &yarnhom_artifacts::BicubicTerm) -> Self {
        Self {
            u_knots: term.u_knots.clone(),
            v_knots: term.v_knots.clone(),
            values: term.values.clone(),
            du: term.du.clone(),
            dv: term.dv.clone(),
            duv: term.duv.clone(),
        }
    }
}

impl Bicubic {
    /// Value, gradient and Hessian at `(u, v)`.
    pub fn jet(&self, u: f64, v: f64) -> Jet2 {
        let (i, pu) = locate(&self.u_knots, u);
        let (j, pv) = locate(&self.v_knots, v);
        let c = self.coefficients(i, j);
        let [u0, u1, u2] = pu.basis();
        let [v0, v1, v2] = pv.basis();
        Jet2 {
            value: contract(&c, &u0, &v0),
            d1: [contract(&c, &u1, &v0), contract(&c, &u0, &v1)],
            d2: [contract(&c, &u2, &v0), contract(&c, &u1, &v1), contract(&c, &u0, &v2)],
        }
    }

    /// The value at `(u, v)` (the same as [`Bicubic::jet`]'s, to the last bit).
    pub fn value(&self, u: f64, v: f64) -> f64 {
        let (i, pu) = locate(&self.u_knots, u);
        let (j, pv) = locate(&self.v_knots, v);
        contract(&self.coefficients(i, j), &pu.value_weights(), &pv.value_weights())
    }

    /// Cell `(i, j)`'s coefficients `c[a][b]`: `a` over the u-basis (value left/right, slope
    /// left/right), `b` over v.
    fn coefficients(&self, i: usize, j: usize) -> [[f64; 4]; 4] {
        let nu = self.u_knots.len();
        let mut c = [[0.0; 4]; 4];
        for (di, dj) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
            let k = (j + dj) * nu + i + di;
            c[di][dj] = self.values[k];
            c[2 + di][dj] = self.du[k];
            c[di][2 + dj] = self.dv[k];
            c[2 + di][2 + dj] = self.duv[k];
        }
        c
    }
}

/// `Σ_ab wu_a c_ab wv_b`.
fn contract(c: &[[f64; 4]; 4], wu: &[f64; 4], wv: &[f64; 4]) -> f64 {
    let mut sum = 0.0;
    for a in 0..4 {
        for b in 0..4 {
            sum += wu[a] * c[a][b] * wv[b];
        }
    }
    sum
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cubic() -> Cubic {
        Cubic {
            knots: vec![-1.0, -0.2, 0.5, 2.0],
            values: vec![1.0, 0.1, 0.3, 2.0],
            slopes: vec![-3.0, 0.2, 0.5, 1.5],
        }
    }

    fn bicubic() -> Bicubic {
        let (u_knots, v_knots) = (vec![-1.0, 0.0, 0.7], vec![-0.5, 0.0, 0.4, 1.0]);
        let n = u_knots.len() * v_knots.len();
        let wave = |k: usize, a: f64| (0..n).map(|i| ((i * 7 + k) as f64 * a).sin()).collect::<Vec<_>>();
        Bicubic {
            u_knots,
            v_knots,
            values: wave(0, 0.9),
            du: wave(1, 1.3),
            dv: wave(2, 0.4),
            duv: wave(3, 2.1),
        }
    }

    #[test]
    fn cubic_interpolates_and_reproduces_cubics() {
        let f = cubic();
        for (k, &t) in f.knots.iter().enumerate() {
            let jet = f.jet(t);
            assert!((jet.value - f.values[k]).abs() < 1e-14 && (jet.d1 - f.slopes[k]).abs() < 1e-12);
        }
        // Hermite data of x³ - x reproduces it exactly inside the knots.
        let g = |x: f64| x * x * x - x;
        let knots = vec![-1.0, 0.3, 1.0];
        let exact = Cubic {
            values: knots.iter().map(|&x| g(x)).collect(),
            slopes: knots.iter().map(|&x| 3.0 * x * x - 1.0).collect(),
            knots,
        };
        for x in [-0.9, -0.1, 0.5, 0.99] {
            let jet = exact.jet(x);
            assert!((jet.value - g(x)).abs() < 1e-12 && (jet.d2 - 6.0 * x).abs() < 1e-10, "x = {x}");
        }
    }

    #[test]
    fn cubic_extrapolates_linearly_with_the_end_slopes() {
        let f = cubic();
        let left = f.jet(-3.0);
        assert!((left.value - (1.0 + 2.0 * 3.0)).abs() < 1e-12 && left.d1 == -3.0 && left.d2 == 0.0);
        let right = f.jet(3.0);
        assert!((right.value - (2.0 + 1.5)).abs() < 1e-12 && right.d1 == 1.5);
    }

    #[test]
    fn derivatives_match_finite_differences() {
        let (f, h) = (cubic(), 1e-6);
        for x in [-2.0, -0.7, 0.0, 0.49, 1.2, 2.5] {
            let jet = f.jet(x);
            let (p, m) = (f.jet(x + h), f.jet(x - h));
            assert!((jet.d1 - (p.value - m.value) / (2.0 * h)).abs() < 1e-6, "x = {x}");
            assert!((jet.d2 - (p.d1 - m.d1) / (2.0 * h)).abs() < 1e-5, "x = {x}");
        }
        let g = bicubic();
        for (u, v) in [(-0.5, 0.2), (0.3, -0.3), (-1.5, 0.7), (1.0, 1.4), (0.2, -1.0), (-2.0, 2.0)] {
            let jet = g.jet(u, v);
            let (up, um, vp, vm) = (g.jet(u + h, v), g.jet(u - h, v), g.jet(u, v + h), g.jet(u, v - h));
            let fd = [(up.value - um.value) / (2.0 * h), (vp.value - vm.value) / (2.0 * h)];
            let fd2 = [
                (up.d1[0] - um.d1[0]) / (2.0 * h),
                (vp.d1[0] - vm.d1[0]) / (2.0 * h),
                (vp.d1[1] - vm.d1[1]) / (2.0 * h),
            ];
            for (k, (d, f)) in jet.d1.iter().zip(fd).enumerate() {
                assert!((d - f).abs() < 1e-6, "({u}, {v}) d1[{k}]");
            }
            for (k, (d, f)) in jet.d2.iter().zip(fd2).enumerate() {
                assert!((d - f).abs() < 1e-5, "({u}, {v}) d2[{k}]");
            }
        }
    }

    #[test]
    fn bicubic_interpolates_nodal_data() {
        let g = bicubic();
        let nu = g.u_knots.len();
        for (j, &v) in g.v_knots.iter().enumerate() {
            for (i, &u) in g.u_knots.iter().enumerate() {
                let (jet, k) = (g.jet(u, v), j * nu + i);
                assert!((jet.value - g.values[k]).abs() < 1e-12);
                assert!((jet.d1[0] - g.du[k]).abs() < 1e-12 && (jet.d1[1] - g.dv[k]).abs() < 1e-12);
                assert!((jet.d2[1] - g.duv[k]).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn bicubic_is_continuous_where_extrapolation_begins() {
        let g = bicubic();
        for v in [-0.3, 0.1, 0.8] {
            for u in [-1.0, 0.7] {
                let (a, b) = (g.jet(u - 1e-9, v), g.jet(u + 1e-9, v));
                assert!(
                    (a.value - b.value).abs() < 1e-8 && (a.d1[0] - b.d1[0]).abs() < 1e-6,
                    "u = {u}, v = {v}"
                );
            }
        }
    }
}
