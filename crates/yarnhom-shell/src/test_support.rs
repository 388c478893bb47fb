//! Test helpers: a tiny xorshift RNG, random well-shaped hinges and finite differences.

use crate::dihedral::Vec3;
use nalgebra::{SMatrix, SVector, Vector2};
use std::collections::HashMap;

/// xorshift64* generator, enough for reproducible random test geometry.
pub struct XorShift(u64);

impl XorShift {
    pub fn new(seed: u64) -> Self {
        Self(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1)
    }

    /// Uniform in `[0, 1)`.
    pub fn unit(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
    }

    pub fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }

    pub fn vector(&mut self) -> Vec3 {
        Vec3::new(self.uniform(-1.0, 1.0), self.uniform(-1.0, 1.0), self.uniform(-1.0, 1.0))
    }
}

/// A random triangle `(p0, p1, a)` whose altitudes are all at least 0.3 × its longest edge.
pub fn random_triangle(rng: &mut XorShift) -> [Vec3; 3] {
    loop {
        let t = [rng.vector(), rng.vector(), rng.vector()];
        let double_area = (t[1] - t[0]).cross(&(t[2] - t[0])).norm();
        let longest = (0..3).map(|i| (t[(i + 1) % 3] - t[i]).norm()).fold(0.0, f64::max);
        if double_area / longest >= 0.3 * longest {
            return t;
        }
    }
}

/// The apex of a wing across the edge `p0 → p1` of the counter-clockwise triangle
/// `(p0, p1, a)`, placed so that the hinge `[p0, p1, a, b]` has signed dihedral angle `angle`.
pub fn apex_across(rng: &mut XorShift, p0: &Vec3, p1: &Vec3, a: &Vec3, angle: f64) -> Vec3 {
    let edge = p1 - p0;
    let normal = edge.cross(&(a - p0)).normalize();
    let inward = normal.cross(&edge.normalize());
    let foot = p0 + rng.uniform(-0.2, 1.2) * edge;
    let altitude = rng.uniform(0.4, 1.2) * edge.norm();
    foot + altitude * (-angle.cos() * inward + angle.sin() * normal)
}

/// A random hinge `[p0, p1, a, b]` with dihedral angle uniform in `[-max_angle, max_angle]`.
pub fn random_hinge(rng: &mut XorShift, max_angle: f64) -> [Vec3; 4] {
    let [p0, p1, a] = random_triangle(rng);
    let angle = rng.uniform(-max_angle, max_angle);
    let b = apex_across(rng, &p0, &p1, &a, angle);
    [p0, p1, a, b]
}

const STEP: f64 = 1e-5;

/// Central-difference gradient of a scalar function.
pub fn fd_gradient<const N: usize>(
    f: impl Fn(&SVector<f64, N>) -> f64,
    q: &SVector<f64, N>,
) -> SVector<f64, N> {
    SVector::from_fn(|k, _| {
        let (mut plus, mut minus) = (*q, *q);
        plus[k] += STEP;
        minus[k] -= STEP;
        (f(&plus) - f(&minus)) / (2.0 * STEP)
    })
}

/// Central-difference Jacobian of a vector function (column `k` = ∂f/∂q_k).
pub fn fd_jacobian<const N: usize, const M: usize>(
    f: impl Fn(&SVector<f64, N>) -> SVector<f64, M>,
    q: &SVector<f64, N>,
) -> SMatrix<f64, M, N> {
    let mut jacobian = SMatrix::<f64, M, N>::zeros();
    for k in 0..N {
        let (mut plus, mut minus) = (*q, *q);
        plus[k] += STEP;
        minus[k] -= STEP;
        jacobian.set_column(k, &((f(&plus) - f(&minus)) / (2.0 * STEP)));
    }
    jacobian
}

/// Entry-wise `|a - b| ≤ rel · max|b|` (with a floor of `rel · 1e-9` for all-zero references).
pub fn assert_all_close<const R: usize, const C: usize>(
    actual: &SMatrix<f64, R, C>,
    expected: &SMatrix<f64, R, C>,
    rel: f64,
) {
    let scale = expected.amax().max(1e-9);
    let error = (actual - expected).amax();
    assert!(
        error <= rel * scale,
        "max error {error:e} > {rel:e} × {scale:e}\nactual {actual}\nexpected {expected}"
    );
}

/// `|a - b| ≤ tol`.
pub fn assert_close(actual: f64, expected: f64, tol: f64) {
    assert!((actual - expected).abs() <= tol, "{actual} vs {expected} (tol {tol:e})");
}

/// A regular grid on `[-half_x, half_x] × [-half_y, half_y]` with spacing `h`, each square split
/// by its (1,0)–(0,1) diagonal into two counter-clockwise triangles.
pub struct GridMesh {
    pub material: Vec<Vector2<f64>>,
    pub triangles: Vec<[usize; 3]>,
}

impl GridMesh {
    pub fn new(half_x: f64, half_y: f64, h: f64) -> Self {
        let (nx, ny) = ((2.0 * half_x / h).round() as usize, (2.0 * half_y / h).round() as usize);
        let index = |i: usize, j: usize| i * (ny + 1) + j;
        let material = (0..=nx)
            .flat_map(|i| (0..=ny).map(move |j| (i, j)))
            .map(|(i, j)| Vector2::new(-half_x + i as f64 * h, -half_y + j as f64 * h))
            .collect();
        let mut triangles = Vec::new();
        for i in 0..nx {
            for j in 0..ny {
                triangles.push([index(i, j), index(i + 1, j), index(i, j + 1)]);
                triangles.push([index(i + 1, j), index(i + 1, j + 1), index(i, j + 1)]);
            }
        }
        Self { material, triangles }
    }

    /// Directed edge `(p, q)` → apex of the triangle traversing `q → p`, i.e. the far vertex
    /// across the edge `p → q` of the triangle that traverses `p → q`.
    pub fn far_vertices(&self) -> HashMap<(usize, usize), usize> {
        let mut far = HashMap::new();
        for t in &self.triangles {
            for i in 0..3 {
                far.insert((t[(i + 2) % 3], t[(i + 1) % 3]), t[i]);
            }
        }
        far
    }
}

/// An anisotropic (6.1) membrane with area terms and nothing else, for tests.
pub fn test_membrane() -> crate::material::StvkNeoHookean {
    crate::material::StvkNeoHookean {
        k_xx: 3.0,
        k_xy: 0.5,
        k_yy: 1.0,
        k_ss: 0.7,
        k_n1: 0.2,
        k_n2: 0.1,
        stiffening: None,
        jamming: None,
    }
}
