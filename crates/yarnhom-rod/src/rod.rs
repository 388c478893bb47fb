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

impl Rod {
    /// A rod through `positions` whose rest shape is that configuration (rest lengths,
    /// curvatures and twists read off it, twist angles zero): it is in equilibrium there.
    /// Reference directors start as close to `director_hint` as each edge allows and are
    /// parallel transported along the rod.
    pub fn at_rest(
        positions: &[[f64; 3]],
        closed: bool,
        material: RodMaterial,
        director_hint: [f64; 3],
    ) -> Rod {
        let vertices = positions.len();
        let edges = if closed { vertices } else { vertices - 1 };
        let edge = |i: usize| {
            let (a, b) = (positions[i], positions[(i + 1) % vertices]);
            [b[0] - a[0], b[1] - a[1], b[2] - a[2]]
        };
        let mut frames = vec![EdgeFrame::new(edge(0), director_hint)];
        for i in 1..edges {
            let previous = frames[i - 1];
            frames.push(previous.updated(edge(i)));
        }
        let rest_lengths: Vec<f64> = (0..edges).map(|i| Vector3::from(edge(i)).norm()).collect();
        let mut rod = Rod { closed, vertices, material, rest_lengths, elements: vec![], references: vec![] };
        let q = rod.dofs_of(positions, &vec![0.0; edges]);
        let bend_vertices: Vec<(usize, usize, usize)> = rod.bend_vertices().collect();
        for (v, e_in, e_out) in bend_vertices {
            let reference =
                BendTwistReference { frames: [frames[e_in], frames[e_out]], reference_twist_rad: 0.0 };
            let local = rod.element_dofs(&q, v, e_in, e_out);
            let (kappa, twist) = curvature_and_twist(&reference, &std::array::from_fn(|i| local[i]));
            rod.references.push(BendTwistReference { reference_twist_rad: twist, ..reference });
            rod.elements.push(BendTwist {
                bend_stiffness_nm2: material.bend_stiffness_nm2,
                twist_stiffness_nm2: material.twist_stiffness_nm2,
                rest_curvature: kappa,
                rest_twist_rad: twist,
                rest_length_sum_m: rod.rest_lengths[e_in] + rod.rest_lengths[e_out],
            });
        }
        rod
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
        let (n, m) = (self.vertices, self.edge_count());
        let range = if self.closed { 0..n } else { 1..n - 1 };
        range.map(move |v| (v, (v + m - 1) % m, v % m))
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
