//! 3-vectors over any dual number (or plain `f64`), so that one energy function serves for the
//! value and, evaluated on hyper-dual numbers, for exact gradients and Hessians.

use std::ops::{Add, Sub};

use num_dual::DualNum;

/// A 3-vector of dual numbers.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct V3<T>(pub [T; 3]);

impl<T: DualNum<Primitive = f64> + Copy> V3<T> {
    /// Lift a plain vector (constant: zero derivatives).
    pub fn constant(v: [f64; 3]) -> Self {
        V3(v.map(T::from))
    }

    /// `s * self`.
    pub fn scale(self, s: T) -> Self {
        V3(self.0.map(|c| c * s))
    }

    /// Dot product.
    pub fn dot(self, o: Self) -> T {
        self.0[0] * o.0[0] + self.0[1] * o.0[1] + self.0[2] * o.0[2]
    }

    /// Cross product.
    pub fn cross(self, o: Self) -> Self {
        let (a, b) = (self.0, o.0);
        V3([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])
    }

    /// Euclidean length.
    pub fn norm(self) -> T {
        self.dot(self).sqrt()
    }

    /// `self / |self|`.
    pub fn normalized(self) -> Self {
        self.scale(self.norm().recip())
    }

    /// The real part.
    pub fn re(self) -> [f64; 3] {
        self.0.map(|c| c.re())
    }
}

impl<T: DualNum<Primitive = f64> + Copy> Add for V3<T> {
    type Output = Self;
    fn add(self, o: Self) -> Self {
        V3([self.0[0] + o.0[0], self.0[1] + o.0[1], self.0[2] + o.0[2]])
    }
}

impl<T: DualNum<Primitive = f64> + Copy> Sub for V3<T> {
    type Output = Self;
    fn sub(self, o: Self) -> Self {
        V3([self.0[0] - o.0[0], self.0[1] - o.0[1], self.0[2] - o.0[2]])
    }
}
