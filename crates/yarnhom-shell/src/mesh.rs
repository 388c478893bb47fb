//! Triangle meshes of a cloth: material (rest) coordinates in the plane, triangles
//! counter-clockwise in material space, and the adjacency the discrete shell needs: for each
//! triangle the far vertex across each edge (the stencil of (4.5)), and the interior edges
//! (hinges of (6.4)).

use std::collections::HashMap;

use nalgebra::{Vector2, Vector3};

/// An interior edge `(e0, e1)` with the far vertices `a` (left of `e0 -> e1` in material space)
/// and `b` (right), the layout of [`crate::hinge`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Hinge {
    /// `[e0, e1, a, b]`.
    pub vertices: [u32; 4],
}

/// A cloth mesh.
#[derive(Debug, Clone, PartialEq)]
pub struct ShellMesh {
    /// Material coordinates of the vertices (m).
    pub material: Vec<Vector2<f64>>,
    /// Triangles, counter-clockwise in material space.
    pub triangles: Vec<[u32; 3]>,
    /// Per triangle, the far vertex of the neighbour across edge `i` (opposite vertex `i`).
    pub neighbours: Vec<[Option<u32>; 3]>,
    /// The interior edges.
    pub hinges: Vec<Hinge>,
}

/// Why a mesh is not usable.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MeshError {
    /// A triangle indexes past the vertices.
    #[error("triangle {triangle} uses vertex {vertex}, but there are {count} vertices")]
    VertexOutOfRange {
        /// The triangle.
        triangle: usize,
        /// The vertex index.
        vertex: u32,
        /// Number of vertices.
        count: usize,
    },
    /// A triangle is degenerate or clockwise in material space.
    #[error("triangle {0} is degenerate or clockwise in material space")]
    BadOrientation(usize),
    /// More than two triangles share an edge.
    #[error("edge ({0}, {1}) is shared by more than two triangles (the mesh must be a manifold)")]
    NonManifold(u32, u32),
}

impl ShellMesh {
    /// A mesh of the given triangles over material coordinates, with its adjacency.
    pub fn new(material: Vec<Vector2<f64>>, triangles: Vec<[u32; 3]>) -> Result<Self, MeshError> {
        for (t, tri) in triangles.iter().enumerate() {
            if let Some(&vertex) = tri.iter().find(|&&v| v as usize >= material.len()) {
                return Err(MeshError::VertexOutOfRange { triangle: t, vertex, count: material.len() });
            }
            let [a, b, c] = tri.map(|v| material[v as usize]);
            if (b - a).perp(&(c - a)) <= 0.0 {
                return Err(MeshError::BadOrientation(t));
            }
        }
        let (neighbours, hinges) = adjacency(&triangles)?;
        Ok(Self { material, triangles, neighbours, hinges })
    }

    /// A `width x height` (m) rectangle centred on the origin, `nx x ny` vertices, each grid
    /// cell split along alternating diagonals (so the mesh has no preferred shear direction).
    pub fn rectangle(width: f64, height: f64, nx: usize, ny: usize) -> Result<Self, MeshError> {
        let (nx, ny) = (nx.max(2), ny.max(2));
        let mut material = Vec::with_capacity(nx * ny);
        for j in 0..ny {
            for i in 0..nx {
                let x = width * (i as f64 / (nx - 1) as f64 - 0.5);
                let y = height * (j as f64 / (ny - 1) as f64 - 0.5);
                material.push(Vector2::new(x, y));
            }
        }
        let id = |i: usize, j: usize| (j * nx + i) as u32;
        let mut triangles = Vec::with_capacity(2 * (nx - 1) * (ny - 1));
        for j in 0..ny - 1 {
            for i in 0..nx - 1 {
                let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
                if (i + j) % 2 == 0 {
                    triangles.extend([[a, b, c], [a, c, d]]);
                } else {
                    triangles.extend([[a, b, d], [b, c, d]]);
                }
            }
        }
        Self::new(material, triangles)
    }

    /// Number of vertices.
    pub fn vertex_count(&self) -> usize {
        self.material.len()
    }

    /// The rest placement in 3D: material coordinates in the plane `z = 0`.
    pub fn flat_positions(&self) -> Vec<Vector3<f64>> {
        self.material.iter().map(|m| Vector3::new(m.x, m.y, 0.0)).collect()
    }

    /// The material area of each triangle.
    pub fn rest_areas(&self) -> Vec<f64> {
        self.triangles
            .iter()
            .map(|tri| {
                let [a, b, c] = tri.map(|v| self.material[v as usize]);
                0.5 * (b - a).perp(&(c - a))
            })
            .collect()
    }

    /// Lumped vertex areas: a third of each incident triangle's material area.
    pub fn vertex_areas(&self) -> Vec<f64> {
        let mut areas = vec![0.0; self.vertex_count()];
        for (tri, area) in self.triangles.iter().zip(self.rest_areas()) {
            for &v in tri {
                areas[v as usize] += area / 3.0;
            }
        }
        areas
    }

    /// Pairs of vertices sharing a triangle (each once, smaller index first).
    pub fn edges(&self) -> Vec<[u32; 2]> {
        let mut edges: Vec<[u32; 2]> = self
            .triangles
            .iter()
            .flat_map(|t| [[t[0], t[1]], [t[1], t[2]], [t[2], t[0]]])
            .map(|[a, b]| [a.min(b), a.max(b)])
            .collect();
        edges.sort_unstable();
        edges.dedup();
        edges
    }
}

/// Neighbours across each triangle edge and the interior hinges.
#[allow(clippy::type_complexity)]
fn adjacency(triangles: &[[u32; 3]]) -> Result<(Vec<[Option<u32>; 3]>, Vec<Hinge>), MeshError> {
    // directed edge (from, to) -> (triangle, opposite vertex); edge i of a triangle is opposite
    // vertex i: (v[i+1], v[i+2]).
    let mut owners: HashMap<(u32, u32), (usize, u32)> = HashMap::with_capacity(3 * triangles.len());
    for (t, tri) in triangles.iter().enumerate() {
        for i in 0..3 {
            let edge = (tri[(i + 1) % 3], tri[(i + 2) % 3]);
            if owners.insert(edge, (t, tri[i])).is_some() {
                return Err(MeshError::NonManifold(edge.0, edge.1));
            }
        }
    }
    let mut neighbours = vec![[None; 3]; triangles.len()];
    let mut hinges = Vec::new();
    for (t, tri) in triangles.iter().enumerate() {
        for i in 0..3 {
            let (from, to) = (tri[(i + 1) % 3], tri[(i + 2) % 3]);
            if let Some(&(_, far)) = owners.get(&(to, from)) {
                neighbours[t][i] = Some(far);
                if from < to {
                    hinges.push(Hinge { vertices: [from, to, tri[i], far] });
                }
            }
        }
    }
    Ok((neighbours, hinges))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rectangle_has_the_expected_counts_and_adjacency() {
        let mesh = ShellMesh::rectangle(0.3, 0.3, 5, 4).expect("mesh");
        assert_eq!(mesh.vertex_count(), 20);
        assert_eq!(mesh.triangles.len(), 2 * 4 * 3);
        // Euler: interior edges = total edges - boundary edges.
        let boundary = 2 * (4 + 3);
        assert_eq!(mesh.hinges.len(), mesh.edges().len() - boundary);
        let open: usize = mesh.neighbours.iter().flatten().filter(|n| n.is_none()).count();
        assert_eq!(open, boundary);
        let total: f64 = mesh.rest_areas().iter().sum();
        assert!((total - 0.09).abs() < 1e-15);
        assert!((mesh.vertex_areas().iter().sum::<f64>() - 0.09).abs() < 1e-15);
    }

    #[test]
    fn hinge_far_vertices_lie_on_either_side() {
        let mesh = ShellMesh::rectangle(1.0, 1.0, 4, 4).expect("mesh");
        for h in &mesh.hinges {
            let [e0, e1, a, b] = h.vertices.map(|v| mesh.material[v as usize]);
            assert!((e1 - e0).perp(&(a - e0)) > 0.0 && (e1 - e0).perp(&(b - e0)) < 0.0);
        }
    }

    #[test]
    fn bad_meshes_are_errors() {
        let m = vec![Vector2::new(0.0, 0.0), Vector2::new(1.0, 0.0), Vector2::new(0.0, 1.0)];
        assert_eq!(ShellMesh::new(m.clone(), vec![[0, 2, 1]]), Err(MeshError::BadOrientation(0)));
        assert!(matches!(
            ShellMesh::new(m.clone(), vec![[0, 1, 3]]),
            Err(MeshError::VertexOutOfRange { .. })
        ));
        let four = [m.clone(), vec![Vector2::new(1.0, 1.0)]].concat();
        assert!(matches!(
            ShellMesh::new(four, vec![[0, 1, 2], [0, 1, 3], [1, 0, 2]]),
            Err(MeshError::BadOrientation(_) | MeshError::NonManifold(..))
        ));
    }
}
