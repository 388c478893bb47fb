//! Contact: rigid obstacles (sphere, plane, box) and cloth self-collision, both as penalty
//! repulsion within a thickness, with Coulomb friction against obstacles applied to the
//! velocities of contacting vertices after each step.
//!
//! Obstacle contact: a vertex closer than the thickness `δ` to an obstacle surface (signed
//! distance `d`, outward normal `n`) stores `½ k (δ - d)²`; its Hessian `k n nᵀ` omits the
//! surface-curvature term (positive semidefinite Gauss-Newton part).
//!
//! Self-collision (repulsion method, not a barrier): every pair of vertices closer than the
//! self thickness `δ_s` in space whose material distance is at least [`SELF_EXCLUSION`] `δ_s`
//! (so mesh neighbours never repel) stores `½ k_s (δ_s - r)²`. Pairs are found with a uniform
//! grid of cells (sorted by column, see [`SelfCollision::pairs`]). Only the vertex-diagonal blocks `k_s u uᵀ` of its Hessian enter the Newton matrix,
//! which keeps the sparsity pattern fixed; the line search uses the exact energy. Being
//! vertex-vertex, it does not stop an edge or a face from passing between two vertices that
//! are further apart than `δ_s`: choose `δ_s` near the mesh spacing.

use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

/// Self-collision pairs need a material distance of at least this many thicknesses.
pub const SELF_EXCLUSION: f64 = 3.0;

/// A rigid obstacle.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "shape", rename_all = "snake_case")]
pub enum Obstacle {
    /// A sphere.
    Sphere {
        /// Centre (m).
        center: [f64; 3],
        /// Radius (m).
        radius: f64,
    },
    /// A half-space bounded by a plane; `normal` points to the free side.
    Plane {
        /// A point on the plane (m).
        point: [f64; 3],
        /// Normal towards the free side.
        normal: [f64; 3],
    },
    /// An axis-aligned box.
    Box {
        /// Lowest corner (m).
        min: [f64; 3],
        /// Highest corner (m).
        max: [f64; 3],
    },
}

impl Obstacle {
    /// Signed distance of `p` to the surface (negative inside) and the outward unit normal.
    pub fn distance(&self, p: &Vector3<f64>) -> (f64, Vector3<f64>) {
        match *self {
            Obstacle::Sphere { center, radius } => {
                let r = p - Vector3::from(center);
                let norm = r.norm();
                let n = if norm > 0.0 { r / norm } else { Vector3::z() };
                (norm - radius, n)
            }
            Obstacle::Plane { point, normal } => {
                let n = Vector3::from(normal).normalize();
                ((p - Vector3::from(point)).dot(&n), n)
            }
            Obstacle::Box { min, max } => box_distance(p, &Vector3::from(min), &Vector3::from(max)),
        }
    }
}

/// Signed distance to an axis-aligned box and its gradient.
fn box_distance(p: &Vector3<f64>, min: &Vector3<f64>, max: &Vector3<f64>) -> (f64, Vector3<f64>) {
    let center = 0.5 * (min + max);
    let half = 0.5 * (max - min);
    let q = (p - center).abs() - half;
    let sign = (p - center).map(|c| if c < 0.0 { -1.0 } else { 1.0 });
    let outside = q.map(|c| c.max(0.0));
    if outside.norm() > 0.0 {
        let n = outside.component_mul(&sign).normalize();
        return (outside.norm(), n);
    }
    let axis = q.imax();
    let mut n = Vector3::zeros();
    n[axis] = sign[axis];
    (q[axis], n)
}

/// Penalty parameters of contact.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ContactSettings {
    /// Obstacle thickness `δ` (m).
    pub thickness_m: f64,
    /// Obstacle penalty stiffness `k` (N/m per vertex).
    pub stiffness_n_m: f64,
    /// Coulomb friction coefficient against obstacles.
    pub friction: f64,
    /// Self-collision thickness `δ_s` (m); 0 disables self-collision.
    pub self_thickness_m: f64,
    /// Self-collision stiffness `k_s` (N/m per pair).
    pub self_stiffness_n_m: f64,
}

/// A vertex's contact with an obstacle: penalty force magnitude and normal.
#[derive(Debug, Clone, Copy)]
pub struct ObstacleContact {
    /// Vertex.
    pub vertex: usize,
    /// Normal force (N).
    pub force_n: f64,
    /// Outward normal.
    pub normal: Vector3<f64>,
}

/// Obstacle contacts of all vertices within the thickness.
pub fn obstacle_contacts(
    obstacles: &[Obstacle],
    settings: &ContactSettings,
    x: &[Vector3<f64>],
) -> Vec<ObstacleContact> {
    let mut contacts = Vec::new();
    for (vertex, p) in x.iter().enumerate() {
        for o in obstacles {
            let (d, normal) = o.distance(p);
            if d < settings.thickness_m {
                contacts.push(ObstacleContact {
                    vertex,
                    force_n: settings.stiffness_n_m * (settings.thickness_m - d),
                    normal,
                });
            }
        }
    }
    contacts
}

/// Obstacle penalty energy (J).
pub fn obstacle_energy(obstacles: &[Obstacle], settings: &ContactSettings, x: &[Vector3<f64>]) -> f64 {
    obstacle_contacts(obstacles, settings, x)
        .iter()
        .map(|c| 0.5 * c.force_n * c.force_n / settings.stiffness_n_m)
        .sum()
}

/// Pairs of vertices that may repel: far enough apart in the material.
#[derive(Debug, Clone)]
pub struct SelfCollision {
    thickness: f64,
    stiffness: f64,
    material: Vec<nalgebra::Vector2<f64>>,
}

/// One repelling pair: vertices and penalty.
#[derive(Debug, Clone, Copy)]
pub struct RepulsionPair {
    /// The two vertices.
    pub vertices: [usize; 2],
    /// Distance (m).
    pub distance: f64,
    /// Unit vector from the first to the second vertex.
    pub direction: Vector3<f64>,
}

impl SelfCollision {
    /// Self-collision of a mesh with material coordinates `material`; `None` if disabled.
    pub fn new(settings: &ContactSettings, material: &[nalgebra::Vector2<f64>]) -> Option<Self> {
        (settings.self_thickness_m > 0.0).then(|| Self {
            thickness: settings.self_thickness_m,
            stiffness: settings.self_stiffness_n_m,
            material: material.to_vec(),
        })
    }

    /// The repelling pairs at positions `x`, sorted. Candidates come from a grid of cells at
    /// least one thickness wide: vertices sorted by their cell's `(x, y)` column and then by
    /// height, a dense index of where each column starts, so each vertex finds the vertices of
    /// its 27 neighbouring cells in 9 column slices.
    pub fn pairs(&self, x: &[Vector3<f64>]) -> Vec<RepulsionPair> {
        let grid = ColumnGrid::new(x, self.thickness);
        let mut pairs = Vec::new();
        for (i, p) in x.iter().enumerate() {
            let ([column_x, column_y], height) = grid.cell(p);
            for (dx, dy) in (-1..=1).flat_map(|a| (-1..=1).map(move |b| (a, b))) {
                for j in grid.neighbours(column_x + dx, column_y + dy, height).filter(|&j| j > i) {
                    let r = x[j] - p;
                    let distance = r.norm();
                    let apart =
                        (self.material[j] - self.material[i]).norm() >= SELF_EXCLUSION * self.thickness;
                    if distance < self.thickness && distance > 0.0 && apart {
                        pairs.push(RepulsionPair { vertices: [i, j], distance, direction: r / distance });
                    }
                }
            }
        }
        pairs.sort_by_key(|p| p.vertices);
        pairs
    }

    /// Repulsion energy (J) of `pairs`.
    pub fn energy(&self, pairs: &[RepulsionPair]) -> f64 {
        pairs.iter().map(|p| 0.5 * self.stiffness * (self.thickness - p.distance).powi(2)).sum()
    }

    /// Gradient of the repulsion energy, and the vertex-diagonal Hessian blocks.
    pub fn forces(
        &self,
        pairs: &[RepulsionPair],
        gradient: &mut [f64],
        blocks: &mut Vec<(usize, Matrix3<f64>)>,
    ) {
        for p in pairs {
            let magnitude = self.stiffness * (self.thickness - p.distance);
            let block = self.stiffness * p.direction * p.direction.transpose();
            for (v, sign) in [(p.vertices[0], 1.0), (p.vertices[1], -1.0)] {
                for k in 0..3 {
                    // E = ½ k (δ - r)², ∂r/∂x_j = u, ∂r/∂x_i = -u.
                    gradient[3 * v + k] += sign * magnitude * p.direction[k];
                }
                blocks.push((v, block));
            }
        }
    }
}

/// Points binned in cubic cells, sorted by `(x, y)` column and then by height, with a dense
/// index of the columns over the points' bounding box.
struct ColumnGrid {
    width: f64,
    origin: [f64; 2],
    columns: [i64; 2],
    /// `(height cell, point)` sorted by column, then height.
    sorted: Vec<(i64, usize)>,
    /// Where each column's points start in `sorted` (one more entry than columns).
    starts: Vec<usize>,
}

impl ColumnGrid {
    /// The grid of `x` with cells `min_width` wide, or wider where the box would need more
    /// than 4 columns per point (a far-flung vertex must not allocate a huge index).
    fn new(x: &[Vector3<f64>], min_width: f64) -> Self {
        let (mut low, mut high) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for p in x {
            for k in 0..2 {
                low[k] = low[k].min(p[k]);
                high[k] = high[k].max(p[k]);
            }
        }
        let mut width = min_width;
        let count = |width: f64| {
            [0, 1].map(|k| (((high[k] - low[k]) / width).floor().max(0.0) as i64).saturating_add(1))
        };
        while count(width)[0].saturating_mul(count(width)[1]) > 4 * x.len().max(1) as i64 {
            width *= 2.0;
        }
        let mut grid =
            Self { width, origin: low, columns: count(width), sorted: Vec::new(), starts: Vec::new() };
        let mut keyed: Vec<(usize, i64, usize)> = x
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let ([cx, cy], height) = grid.cell(p);
                ((cx + grid.columns[0] * cy) as usize, height, i)
            })
            .collect();
        keyed.sort_unstable();
        let column_count = (grid.columns[0] * grid.columns[1]) as usize;
        grid.starts = vec![0; column_count + 1];
        for &(column, _, _) in &keyed {
            grid.starts[column + 1] += 1;
        }
        for c in 0..column_count {
            grid.starts[c + 1] += grid.starts[c];
        }
        grid.sorted = keyed.into_iter().map(|(_, height, i)| (height, i)).collect();
        grid
    }

    /// The `(x, y)` column and the height cell of `p`.
    fn cell(&self, p: &Vector3<f64>) -> ([i64; 2], i64) {
        let column = [0, 1].map(|k| ((p[k] - self.origin[k]) / self.width).floor() as i64);
        (column, (p[2] / self.width).floor() as i64)
    }

    /// The points in column `(cx, cy)` within one cell of height `height`.
    fn neighbours(&self, cx: i64, cy: i64, height: i64) -> impl Iterator<Item = usize> + '_ {
        let inside = (0..self.columns[0]).contains(&cx) && (0..self.columns[1]).contains(&cy);
        let slice = match inside {
            true => {
                let column = (cx + self.columns[0] * cy) as usize;
                let points = &self.sorted[self.starts[column]..self.starts[column + 1]];
                let first = points.partition_point(|&(h, _)| h < height - 1);
                let end = points.partition_point(|&(h, _)| h <= height + 1);
                &points[first..end]
            }
            false => &[],
        };
        slice.iter().map(|&(_, i)| i)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn signed_distances_of_the_obstacles() {
        let sphere = Obstacle::Sphere { center: [0.0, 0.0, -0.04], radius: 0.03 };
        let (d, n) = sphere.distance(&Vector3::new(0.0, 0.0, 0.0));
        assert!((d - 0.01).abs() < 1e-15 && (n - Vector3::z()).norm() < 1e-15);
        let plane = Obstacle::Plane { point: [0.0, 0.0, -1.0], normal: [0.0, 0.0, 2.0] };
        assert!((plane.distance(&Vector3::new(3.0, 1.0, -0.5)).0 - 0.5).abs() < 1e-15);
        let b = Obstacle::Box { min: [-1.0, -1.0, -1.0], max: [1.0, 1.0, 0.0] };
        let (d, n) = b.distance(&Vector3::new(0.2, 0.1, -0.1));
        assert!((d + 0.1).abs() < 1e-15 && n == Vector3::z());
        let (d, _) = b.distance(&Vector3::new(2.0, 0.0, 1.0));
        assert!((d - 2f64.sqrt()).abs() < 1e-15);
    }

    #[test]
    fn repulsion_gradient_matches_finite_differences_and_skips_mesh_neighbours() {
        let settings = ContactSettings {
            thickness_m: 0.0,
            stiffness_n_m: 0.0,
            friction: 0.0,
            self_thickness_m: 0.01,
            self_stiffness_n_m: 100.0,
        };
        let material = vec![
            nalgebra::Vector2::new(0.0, 0.0),
            nalgebra::Vector2::new(1.0, 0.0),
            nalgebra::Vector2::new(0.001, 0.0),
        ];
        let self_collision = SelfCollision::new(&settings, &material).expect("enabled");
        let x = vec![
            Vector3::new(0.0, 0.0, 0.0),
            Vector3::new(0.004, 0.003, 0.001),
            Vector3::new(0.001, 0.0, 0.0),
        ];
        let pairs = self_collision.pairs(&x);
        assert_eq!(pairs.len(), 2, "vertex 2 is a material neighbour of 0 and does not repel it");
        let mut gradient = vec![0.0; 9];
        self_collision.forces(&pairs, &mut gradient, &mut Vec::new());
        let h = 1e-8;
        for dof in 0..9 {
            let (mut p, mut m) = (x.clone(), x.clone());
            p[dof / 3][dof % 3] += h;
            m[dof / 3][dof % 3] -= h;
            let fd = (self_collision.energy(&self_collision.pairs(&p))
                - self_collision.energy(&self_collision.pairs(&m)))
                / (2.0 * h);
            assert!((gradient[dof] - fd).abs() < 1e-6, "dof {dof}: {} vs {fd}", gradient[dof]);
        }
    }

    #[test]
    fn the_column_grid_finds_every_pair_a_brute_force_search_finds() {
        use crate::test_support::XorShift;
        let mut rng = XorShift::new(7);
        let settings = ContactSettings {
            thickness_m: 0.0,
            stiffness_n_m: 0.0,
            friction: 0.0,
            self_thickness_m: 0.01,
            self_stiffness_n_m: 1.0,
        };
        // A crumpled sheet: material coordinates on a grid, positions folded into a small box;
        // then the same with one vertex far away, which coarsens the grid.
        let material: Vec<_> = (0..400)
            .map(|i| nalgebra::Vector2::new((i % 20) as f64 * 0.01, (i / 20) as f64 * 0.01))
            .collect();
        let mut x: Vec<_> = (0..400)
            .map(|_| {
                Vector3::new(rng.uniform(-0.04, 0.04), rng.uniform(-0.04, 0.04), rng.uniform(-0.02, 0.02))
            })
            .collect();
        let collision = SelfCollision::new(&settings, &material).expect("enabled");
        for far in [None, Some(Vector3::new(1e3, -2e3, 5.0))] {
            if let Some(p) = far {
                x[17] = p;
            }
            let mut expected = Vec::new();
            for i in 0..x.len() {
                for j in i + 1..x.len() {
                    let d = (x[j] - x[i]).norm();
                    if d < 0.01 && d > 0.0 && (material[j] - material[i]).norm() >= SELF_EXCLUSION * 0.01 {
                        expected.push([i, j]);
                    }
                }
            }
            let found: Vec<_> = collision.pairs(&x).iter().map(|p| p.vertices).collect();
            assert!(expected.len() > 100, "{}", expected.len());
            assert_eq!(found, expected);
        }
    }
}
