//! One discrete elastic rod, open or closed: stretching of every edge and bending-twisting at
//! every interior vertex, assembled over the DOFs `(x_0 .. x_{n-1}, θ_0 .. θ_{m-1})` (positions
//! first, then one twist per edge).

use nalgebra::{DVector, Vector3};

use crate::bend_twist::{BendTwist, BendTwistDofs, BendTwistReference, curvature_and_twist};
use crate::frames::EdgeFrame;
use crate::stretch::{StretchLaw, stretch_energy};

/// The stiffness of a yarn as a rod.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RodMaterial {
    /// Stretching law of the edges.
    pub stretch: StretchLaw,
    /// Bending stiffnesses about the two material directors (N m²).
    pub bend_stiffness_nm2: [f64; 2],
    /// Twisting stiffness (N m²).
    pub twist_stiffness_nm2: f64,
}

impl RodMaterial {
    /// A circular elastic rod of radius `r` with Young's modulus `E`, shear modulus `G` and
    /// bending/twisting multiplier `γ` (3.25): `k = E π r²`, `α = γ E π r⁴ / 4`, `β = γ G π r⁴ / 2`.
    pub fn circular(youngs_modulus_pa: f64, shear_modulus_pa: f64, gamma: f64, radius_m: f64) -> Self {
        let area = std::f64::consts::PI * radius_m * radius_m;
        let second_moment = area * radius_m * radius_m / 4.0;
        RodMaterial {
            stretch: StretchLaw::Linear { k_n: youngs_modulus_pa * area },
            bend_stiffness_nm2: [gamma * youngs_modulus_pa * second_moment; 2],
            twist_stiffness_nm2: gamma * shear_modulus_pa * 2.0 * second_moment,
        }
    }
}

/// A discrete elastic rod with its rest shape and reference frames.
#[derive(Debug, Clone, PartialEq)]
pub struct Rod {
    closed: bool,
    vertices: usize,
    material: RodMaterial,
    rest_lengths: Vec<f64>,
    elements: Vec<BendTwist>,
    references: Vec<BendTwistReference>,
}

/// Energy, gradient and Hessian triplets `(row, column, value)` (duplicates to be summed).
pub type Assembled = (f64, DVector<f64>, Vec<(usize, usize, f64)>);

/// The rest state of a rod given explicitly ([`Rod::with_rest_shape`]): per edge, per bend
/// vertex ([`Rod::bend_vertex_range`]).
#[derive(Debug, Clone, PartialEq)]
pub struct RestShape {
    /// Rest length of every edge (m).
    pub rest_lengths_m: Vec<f64>,
    /// First reference director of every edge.
    pub reference_directors: Vec<[f64; 3]>,
    /// Rest material curvature `κ̄` of every bend vertex.
    pub rest_curvature: Vec<[f64; 2]>,
    /// Rest twist `m̄` of every bend vertex (rad).
    pub rest_twist_rad: Vec<f64>,
    /// Reference twist of every bend vertex at the rod's configuration (rad).
    pub reference_twist_rad: Vec<f64>,
}

impl RestShape {
    /// The rest shape read off `positions` (twist angles zero): rest lengths the edge lengths,
    /// reference directors as close to `director_hint` as the first edge allows and parallel
    /// transported along the rod, rest curvature and twist those of the configuration.
    pub fn of(positions: &[[f64; 3]], closed: bool, director_hint: [f64; 3]) -> RestShape {
        let vertices = positions.len();
        let edges = if closed { vertices } else { vertices.saturating_sub(1) };
        let mut chained: Vec<EdgeFrame> = Vec::with_capacity(edges);
        for e in 0..edges {
            let vector = edge_vector(positions, e);
            let frame =
                chained.last().map_or_else(|| EdgeFrame::new(vector, director_hint), |f| f.updated(vector));
            chained.push(frame);
        }
        let reference_directors: Vec<[f64; 3]> = chained.iter().map(|f| f.director).collect();
        let frames = edge_frames(positions, &reference_directors);
        let (mut rest_curvature, mut rest_twist_rad) = (vec![], vec![]);
        for v in Rod::bend_vertex_range(vertices, closed) {
            let (e_in, e_out) = ((v + edges - 1) % edges, v % edges);
            let reference =
                BendTwistReference { frames: [frames[e_in], frames[e_out]], reference_twist_rad: 0.0 };
            let (prev, next) = (positions[(v + vertices - 1) % vertices], positions[(v + 1) % vertices]);
            let local: [f64; 11] = std::array::from_fn(|i| match i {
                0..3 => prev[i],
                3..6 => positions[v][i - 3],
                6..9 => next[i - 6],
                _ => 0.0,
            });
            let (kappa, twist) = curvature_and_twist(&reference, &local);
            rest_curvature.push(kappa);
            rest_twist_rad.push(twist);
        }
        RestShape {
            rest_lengths_m: (0..edges).map(|e| Vector3::from(edge_vector(positions, e)).norm()).collect(),
            reference_directors,
            reference_twist_rad: rest_twist_rad.clone(),
            rest_curvature,
            rest_twist_rad,
        }
    }
}

/// The vector of edge `e` of the rod through `positions` (closed or not: `e + 1` wraps).
fn edge_vector(positions: &[[f64; 3]], e: usize) -> [f64; 3] {
    let (a, b) = (positions[e], positions[(e + 1) % positions.len()]);
    [b[0] - a[0], b[1] - a[1], b[2] - a[2]]
}

/// The reference frame of every edge with first director `directors[e]` (projected onto its
/// normal plane).
fn edge_frames(positions: &[[f64; 3]], directors: &[[f64; 3]]) -> Vec<EdgeFrame> {
    directors.iter().enumerate().map(|(e, &d)| EdgeFrame::new(edge_vector(positions, e), d)).collect()
}

impl Rod {
    /// A rod through `positions` whose rest shape is that configuration (rest lengths,
    /// curvatures and twists read off it, twist angles zero): it is in equilibrium there.
    /// Reference directors start as close to `director_hint` as each edge allows and are
    /// parallel transported along the rod. The rod of [`Rod::with_rest_shape`] fed with
    /// [`RestShape::of`].
    pub fn at_rest(
        positions: &[[f64; 3]],
        closed: bool,
        material: RodMaterial,
        director_hint: [f64; 3],
    ) -> Rod {
        Rod::with_rest_shape(positions, closed, material, RestShape::of(positions, closed, director_hint))
    }

    /// A rod through `positions` (twist angles zero) with the explicit rest shape `rest`: rest
    /// lengths per edge, reference directors per edge (each projected onto its edge's normal plane
    /// at `positions`, as [`EdgeFrame::new`] does), and per bend vertex
    /// ([`Rod::bend_vertex_range`]) the rest curvature and twist and the reference twist at
    /// `positions`.
    ///
    /// # Panics
    /// If the lengths of `rest`'s lists disagree with the rod's edges and bend vertices.
    pub fn with_rest_shape(
        positions: &[[f64; 3]],
        closed: bool,
        material: RodMaterial,
        rest: RestShape,
    ) -> Rod {
        let vertices = positions.len();
        let edges = rest.rest_lengths_m.len();
        let bends = Rod::bend_vertex_range(vertices, closed).len();
        assert!(
            edges == if closed { vertices } else { vertices.saturating_sub(1) }
                && rest.reference_directors.len() == edges
                && [rest.rest_curvature.len(), rest.rest_twist_rad.len(), rest.reference_twist_rad.len()]
                    == [bends; 3],
            "rest shape of {edges} edges and {bends} bend vertices for a rod of {vertices} vertices"
        );
        let frames = edge_frames(positions, &rest.reference_directors);
        let mut rod = Rod {
            closed,
            vertices,
            material,
            rest_lengths: rest.rest_lengths_m,
            elements: vec![],
            references: vec![],
        };
        let bend_vertices: Vec<(usize, usize, usize)> = rod.bend_vertices().collect();
        for (k, (_, e_in, e_out)) in bend_vertices.into_iter().enumerate() {
            rod.references.push(BendTwistReference {
                frames: [frames[e_in], frames[e_out]],
                reference_twist_rad: rest.reference_twist_rad[k],
            });
            rod.elements.push(BendTwist {
                bend_stiffness_nm2: material.bend_stiffness_nm2,
                twist_stiffness_nm2: material.twist_stiffness_nm2,
                rest_curvature: rest.rest_curvature[k],
                rest_twist_rad: rest.rest_twist_rad[k],
                rest_length_sum_m: rod.rest_lengths[e_in] + rod.rest_lengths[e_out],
            });
        }
        rod
    }

    /// The bend vertices of a rod of `vertices` vertices, in the order of the per-bend-vertex
    /// lists of [`RestShape`]: `1..n-1` for an open rod, `0..n` for a closed one.
    pub fn bend_vertex_range(vertices: usize, closed: bool) -> std::ops::Range<usize> {
        if closed { 0..vertices } else { 1..vertices.saturating_sub(1).max(1) }
    }

    /// The same rod with a straight, untwisted rest shape (rest lengths kept).
    pub fn with_straight_rest_shape(mut self) -> Rod {
        for e in &mut self.elements {
            e.rest_curvature = [0.0, 0.0];
            e.rest_twist_rad = 0.0;
        }
        self
    }

    /// Number of DOFs: three per vertex and one twist per edge.
    pub fn dof_count(&self) -> usize {
        3 * self.vertices + self.rest_lengths.len()
    }

    /// The DOF vector of positions and edge twists.
    pub fn dofs_of(&self, positions: &[[f64; 3]], twists: &[f64]) -> DVector<f64> {
        DVector::from_iterator(
            self.dof_count(),
            positions.iter().flatten().copied().chain(twists.iter().copied()),
        )
    }

    fn edge_count(&self) -> usize {
        self.rest_lengths.len()
    }

    /// `(vertex, incoming edge, outgoing edge)` of every bending-twisting element.
    fn bend_vertices(&self) -> impl Iterator<Item = (usize, usize, usize)> + '_ {
        let m = self.edge_count();
        Rod::bend_vertex_range(self.vertices, self.closed).map(move |v| (v, (v + m - 1) % m, v % m))
    }

    /// Global DOF indices of an element `(x_prev, x_v, x_next, θ_in, θ_out)`.
    fn element_indices(&self, v: usize, e_in: usize, e_out: usize) -> [usize; 11] {
        let n = self.vertices;
        let (prev, next) = ((v + n - 1) % n, (v + 1) % n);
        let twist = 3 * n;
        let p = |u: usize, c: usize| 3 * u + c;
        [
            p(prev, 0),
            p(prev, 1),
            p(prev, 2),
            p(v, 0),
            p(v, 1),
            p(v, 2),
            p(next, 0),
            p(next, 1),
            p(next, 2),
            twist + e_in,
            twist + e_out,
        ]
    }

    fn element_dofs(&self, q: &DVector<f64>, v: usize, e_in: usize, e_out: usize) -> BendTwistDofs {
        BendTwistDofs::from_iterator(self.element_indices(v, e_in, e_out).iter().map(|&i| q[i]))
    }

    fn position(q: &DVector<f64>, v: usize) -> Vector3<f64> {
        Vector3::new(q[3 * v], q[3 * v + 1], q[3 * v + 2])
    }

    /// Total elastic energy, its gradient and Hessian triplets at `q`.
    pub fn assemble(&self, q: &DVector<f64>) -> Assembled {
        let mut energy = 0.0;
        let mut gradient = DVector::zeros(self.dof_count());
        let mut triplets = Vec::new();
        let mut scatter = |indices: &[usize], g: &[f64], h: &dyn Fn(usize, usize) -> f64| {
            for (a, &i) in indices.iter().enumerate() {
                gradient[i] += g[a];
                for (b, &j) in indices.iter().enumerate() {
                    triplets.push((i, j, h(a, b)));
                }
            }
        };
        for (e, &rest) in self.rest_lengths.iter().enumerate() {
            let (a, b) = (e, (e + 1) % self.vertices);
            let (w, g, h) =
                stretch_energy(&self.material.stretch, rest, &Self::position(q, a), &Self::position(q, b));
            energy += w;
            let indices = [3 * a, 3 * a + 1, 3 * a + 2, 3 * b, 3 * b + 1, 3 * b + 2];
            scatter(&indices, g.as_slice(), &|i, j| h[(i, j)]);
        }
        for ((v, e_in, e_out), (element, reference)) in
            self.bend_vertices().zip(self.elements.iter().zip(&self.references))
        {
            let local = self.element_dofs(q, v, e_in, e_out);
            let (w, g, h) = element.energy_gradient_hessian(reference, &local);
            energy += w;
            scatter(&self.element_indices(v, e_in, e_out), g.as_slice(), &|i, j| h[(i, j)]);
        }
        (energy, gradient, triplets)
    }

    /// The elastic energy at `q` attributed to the vertices (J): each edge's stretching
    /// half to either end, each bending-twisting element to its centre vertex. The values sum
    /// to [`Rod::assemble`]'s energy; over a region they give its energy.
    pub fn vertex_energies(&self, q: &DVector<f64>) -> Vec<f64> {
        let mut energies = vec![0.0; self.vertices];
        for (e, &rest) in self.rest_lengths.iter().enumerate() {
            let (a, b) = (e, (e + 1) % self.vertices);
            let (w, _, _) =
                stretch_energy(&self.material.stretch, rest, &Self::position(q, a), &Self::position(q, b));
            energies[a] += 0.5 * w;
            energies[b] += 0.5 * w;
        }
        for ((v, e_in, e_out), (element, reference)) in
            self.bend_vertices().zip(self.elements.iter().zip(&self.references))
        {
            energies[v] += element.energy(reference, &self.element_dofs(q, v, e_in, e_out));
        }
        energies
    }

    /// The reference frames of the bending-twisting elements, which
    /// [`Rod::update_references`] moves with the rod (a simulation's state besides its DOFs).
    pub fn references(&self) -> &[BendTwistReference] {
        &self.references
    }

    /// Put back reference frames read by [`Rod::references`] from this rod; `Err(expected
    /// count)` if their number differs.
    pub fn set_references(&mut self, references: &[BendTwistReference]) -> Result<(), usize> {
        if references.len() != self.references.len() {
            return Err(self.references.len());
        }
        self.references = references.to_vec();
        Ok(())
    }

    /// Move the reference frames to configuration `q` (time-parallel transport) and record the
    /// reference twists there; call after every accepted step.
    pub fn update_references(&mut self, q: &DVector<f64>) {
        let edge = |e: usize| {
            let d = Self::position(q, (e + 1) % self.vertices) - Self::position(q, e);
            [d.x, d.y, d.z]
        };
        let updated: Vec<BendTwistReference> = self
            .bend_vertices()
            .zip(&self.references)
            .map(|((v, e_in, e_out), reference)| {
                let moved = BendTwistReference {
                    frames: [
                        reference.frames[0].updated(edge(e_in)),
                        reference.frames[1].updated(edge(e_out)),
                    ],
                    ..*reference
                };
                let local = self.element_dofs(q, v, e_in, e_out);
                let (_, twist) = curvature_and_twist(&moved, &std::array::from_fn(|i| local[i]));
                BendTwistReference { reference_twist_rad: twist - (local[10] - local[9]), ..moved }
            })
            .collect();
        self.references = updated;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stretch::StretchLaw;

    fn material() -> RodMaterial {
        RodMaterial {
            stretch: StretchLaw::Linear { k_n: 100.0 },
            bend_stiffness_nm2: [2.0, 3.0],
            twist_stiffness_nm2: 1.5,
        }
    }

    fn helix(n: usize) -> Vec<[f64; 3]> {
        (0..n).map(|i| 0.3 * i as f64).map(|s| [s.cos(), s.sin(), 0.2 * s]).collect()
    }

    /// The rest data of the rod through `p`, read off with the public pieces alone: edge lengths,
    /// reference directors parallel transported from `hint`, and the curvature and twist of
    /// every bend vertex in the frames those directors give.
    fn rest_data_read_off(p: &[[f64; 3]], closed: bool, hint: [f64; 3]) -> RestShape {
        let n = p.len();
        let m = if closed { n } else { n - 1 };
        let edge = |e: usize| -> [f64; 3] { std::array::from_fn(|k| p[(e + 1) % n][k] - p[e][k]) };
        let mut transported = vec![EdgeFrame::new(edge(0), hint)];
        for e in 1..m {
            transported.push(transported[e - 1].updated(edge(e)));
        }
        let directors: Vec<[f64; 3]> = transported.iter().map(|f| f.director).collect();
        let frames: Vec<EdgeFrame> = (0..m).map(|e| EdgeFrame::new(edge(e), directors[e])).collect();
        let bends = if closed { 0..n } else { 1..n - 1 };
        let (kappa, twist): (Vec<[f64; 2]>, Vec<f64>) = bends
            .map(|v| {
                let (e_in, e_out) = ((v + m - 1) % m, v % m);
                let reference =
                    BendTwistReference { frames: [frames[e_in], frames[e_out]], reference_twist_rad: 0.0 };
                let points = [p[(v + n - 1) % n], p[v], p[(v + 1) % n]];
                let q: [f64; 11] = std::array::from_fn(|i| if i < 9 { points[i / 3][i % 3] } else { 0.0 });
                curvature_and_twist(&reference, &q)
            })
            .unzip();
        RestShape {
            rest_lengths_m: (0..m).map(|e| Vector3::from(edge(e)).norm()).collect(),
            reference_directors: directors,
            rest_curvature: kappa,
            reference_twist_rad: twist.clone(),
            rest_twist_rad: twist,
        }
    }

    #[test]
    fn the_vertex_energies_sum_to_the_rod_energy_in_any_configuration() {
        for (positions, closed) in [(helix(17), false), (helix(12), true)] {
            let rod = Rod::at_rest(&positions, closed, material(), [0.2, -0.4, 1.0]);
            let m = if closed { 12 } else { 16 };
            let moved: Vec<[f64; 3]> = positions
                .iter()
                .enumerate()
                .map(|(i, p)| [p[0] * 1.1, p[1] + 0.01 * i as f64, p[2]])
                .collect();
            let twists: Vec<f64> = (0..m).map(|e| 0.05 * e as f64).collect();
            let q = rod.dofs_of(&moved, &twists);
            let (energy, _, _) = rod.assemble(&q);
            let sum: f64 = rod.vertex_energies(&q).iter().sum();
            assert!(energy > 0.0 && (sum - energy).abs() <= 1e-12 * energy, "{sum} vs {energy}");
        }
    }

    #[test]
    fn at_rest_is_the_explicit_constructor_fed_with_the_rest_data_read_off_the_positions() {
        let hint = [0.2, -0.4, 1.0];
        for (positions, closed) in [(helix(17), false), (helix(12), true)] {
            let rest = rest_data_read_off(&positions, closed, hint);
            let explicit = Rod::with_rest_shape(&positions, closed, material(), rest.clone());
            assert_eq!(Rod::at_rest(&positions, closed, material(), hint), explicit);
            assert_eq!(RestShape::of(&positions, closed, hint), rest);
            // A straight rest shape given explicitly is the straightened rod.
            let bends = Rod::bend_vertex_range(positions.len(), closed).len();
            let straight =
                RestShape { rest_curvature: vec![[0.0; 2]; bends], rest_twist_rad: vec![0.0; bends], ..rest };
            assert_eq!(
                Rod::with_rest_shape(&positions, closed, material(), straight),
                Rod::at_rest(&positions, closed, material(), hint).with_straight_rest_shape()
            );
        }
    }

    #[test]
    fn a_straight_rod_with_an_explicit_curved_rest_shape_stores_the_energy_of_its_curvature() {
        // Straight and untwisted, its curvature and twist are zero, so every bend vertex stores
        // (α1 κ̄1² + α2 κ̄2² + β m̄²) / (L̄_in + L̄_out) of the rest data given.
        let positions: Vec<[f64; 3]> = (0..9).map(|i| [0.25 * i as f64, 0.0, 0.0]).collect();
        let bends = Rod::bend_vertex_range(9, false).len();
        let rest = RestShape {
            rest_lengths_m: (0..8).map(|e| 0.2 + 0.01 * e as f64).collect(),
            reference_directors: vec![[0.0, 1.0, 0.0]; 8],
            rest_curvature: (0..bends).map(|k| [0.1 * k as f64, -0.05 * k as f64]).collect(),
            rest_twist_rad: (0..bends).map(|k| 0.02 * k as f64).collect(),
            reference_twist_rad: vec![0.0; bends],
        };
        let expected: f64 = (0..bends)
            .map(|k| {
                let ([k1, k2], m) = (rest.rest_curvature[k], rest.rest_twist_rad[k]);
                (2.0 * k1 * k1 + 3.0 * k2 * k2 + 1.5 * m * m)
                    / (rest.rest_lengths_m[k] + rest.rest_lengths_m[k + 1])
            })
            .sum();
        let stretch: f64 =
            rest.rest_lengths_m.iter().map(|&l| 0.5 * 100.0 * (0.25 / l - 1.0).powi(2) * l).sum();
        let rod = Rod::with_rest_shape(&positions, false, material(), rest.clone());
        let (energy, _, _) = rod.assemble(&rod.dofs_of(&positions, &[0.0; 8]));
        assert!((energy - expected - stretch).abs() < 1e-12 * energy, "{energy} vs {}", expected + stretch);
        // Per vertex: half of each adjacent edge's stretching, and the bend vertex's own term.
        let energies = rod.vertex_energies(&rod.dofs_of(&positions, &[0.0; 8]));
        let edge =
            |e: usize| 0.5 * 100.0 * (0.25 / rest.rest_lengths_m[e] - 1.0).powi(2) * rest.rest_lengths_m[e];
        assert!((energies[0] - 0.5 * edge(0)).abs() < 1e-15 && (energies[8] - 0.5 * edge(7)).abs() < 1e-15);
        let ([k1, k2], m) = (rest.rest_curvature[2], rest.rest_twist_rad[2]);
        let bend =
            (2.0 * k1 * k1 + 3.0 * k2 * k2 + 1.5 * m * m) / (rest.rest_lengths_m[2] + rest.rest_lengths_m[3]);
        assert!((energies[3] - bend - 0.5 * (edge(2) + edge(3))).abs() < 1e-14, "{}", energies[3]);
    }
}
