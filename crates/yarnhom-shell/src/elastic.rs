//! The elastic energy of a cloth mesh: per triangle `A Ψ(I, II)` over its stencil (4.8) with the
//! derivative split of App. A.5 and per-element eigenvalue clamping to positive semidefinite
//! Hessians (Sec. 4.2, after Teran et al. 2005), plus per-hinge bending (6.4) where the material
//! has it.

use nalgebra::{Matrix2, SMatrix, SVector, Vector3};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::forms::{
    RestTriangle, Stencil, first_form_of, first_form_stress_hessian, first_form_with_derivatives, forms,
    forms_with_derivatives, forms_with_gradient,
};
use crate::hinge::{HingeRest, anisotropic_stiffness, hinge_energy, hinge_energy_with_derivatives};
use crate::material::ShellMaterial;
use crate::mesh::ShellMesh;

/// Energy, gradient and (lower-triangle) Hessian triplets of some energy over all DOFs.
#[derive(Debug, Clone, Default)]
pub struct Assembly {
    /// Energy (J).
    pub energy: f64,
    /// Gradient over the `3 n` DOFs (N).
    pub gradient: Vec<f64>,
    /// Hessian entries `(row, col, value)`, `row >= col`, duplicates to be summed (N/m).
    pub triplets: Vec<(usize, usize, f64)>,
}

impl Assembly {
    /// An empty assembly over `dofs` degrees of freedom.
    pub fn new(dofs: usize) -> Self {
        Self { energy: 0.0, gradient: vec![0.0; dofs], triplets: Vec::new() }
    }

    /// Empty it, keeping its memory.
    pub fn clear(&mut self) {
        self.energy = 0.0;
        self.gradient.fill(0.0);
        self.triplets.clear();
    }

    /// Hold the `fixed` DOFs: zero gradient, identity rows and columns in the Hessian.
    pub fn pin(&mut self, fixed: &[bool]) {
        self.triplets.retain(|&(i, j, _)| !fixed[i] && !fixed[j]);
        for (dof, &f) in fixed.iter().enumerate() {
            if f {
                self.gradient[dof] = 0.0;
                self.triplets.push((dof, dof, 1.0));
            }
        }
    }
}

/// Where [`ElasticModel::assemble`] puts the elements it evaluates, in the model's element order
/// (see [`ElasticModel::element_vertices`]).
pub trait ElementSink {
    /// Take element `index`: its energy, gradient and (if asked for) Hessian over `vertices`
    /// (absent vertices contribute nothing).
    fn add<const N: usize>(
        &mut self,
        index: usize,
        vertices: &[Option<u32>],
        energy: f64,
        gradient: &SVector<f64, N>,
        hessian: Option<&SplitHessian<N>>,
    );
}

impl ElementSink for Assembly {
    /// The energy, gradient and clamped Hessian as triplets.
    fn add<const N: usize>(
        &mut self,
        _index: usize,
        vertices: &[Option<u32>],
        energy: f64,
        gradient: &SVector<f64, N>,
        hessian: Option<&SplitHessian<N>>,
    ) {
        self.energy += energy;
        let clamped = hessian.map(SplitHessian::clamped);
        for (a, va) in vertices.iter().enumerate() {
            let Some(va) = va else { continue };
            for k in 0..3 {
                self.gradient[3 * *va as usize + k] += gradient[3 * a + k];
            }
            let Some(h) = &clamped else { continue };
            for (b, vb) in vertices.iter().enumerate() {
                let Some(vb) = vb else { continue };
                for k in 0..3 {
                    for l in 0..3 {
                        let (row, col) = (3 * *va as usize + k, 3 * *vb as usize + l);
                        if row >= col {
                            self.triplets.push((row, col, h[(3 * a + k, 3 * b + l)]));
                        }
                    }
                }
            }
        }
    }
}

/// A symmetric element matrix `H` (the element Hessian, or its [`NewtonMatrix`] approximation)
/// with its negative eigenvalue part `N = Σ_{λ<0} λ v vᵀ` (`None` when `H` is positive
/// semidefinite): the clamped matrix `H - N` drops the negative curvature, the absolute one
/// `H - 2N` flips its sign (Chen et al. 2024, "Trust-region eigenvalue filtering for projected
/// Newton"); both are positive semidefinite.
#[derive(Debug, Clone)]
pub struct SplitHessian<const N: usize> {
    /// The matrix.
    pub matrix: SMatrix<f64, N, N>,
    /// Its negative eigenvalue part, if any.
    pub negative: Option<SMatrix<f64, N, N>>,
}

impl<const N: usize> SplitHessian<N> {
    /// `H` with its negative eigenvalues set to zero.
    pub fn clamped(&self) -> SMatrix<f64, N, N> {
        match &self.negative {
            Some(n) => self.matrix - n,
            None => self.matrix,
        }
    }

    /// `H` with its eigenvalues replaced by their absolute values.
    pub fn absolute(&self) -> SMatrix<f64, N, N> {
        match &self.negative {
            Some(n) => self.matrix - 2.0 * n,
            None => self.matrix,
        }
    }
}

/// The element matrices a Newton step takes, each positive semidefinite.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum NewtonMatrix {
    /// The exact element Hessians (A.44) with their eigenvalues made absolute (Sec. 4.2 projects
    /// them; Chen et al. 2024 flip rather than clamp): an 18 x 18 eigensolver for every element
    /// that is not positive semidefinite.
    Projected,
    /// Gauss-Newton in the forms, positive semidefinite by construction; the default, per time
    /// step 2.4 times faster than `projected` on the published stretch and drape scenes.
    ///
    /// (A.44) without the forms' second derivatives weighted by the
    /// stress, `Σ_k ∂Ψ/∂z_k ∇²z_k`, except the first form's, whose stress is kept where it
    /// stretches (`A (Jᵀ |∇²Ψ| J + (2 W S₊ Wᵀ) ⊗ Id₃)`, [`gauss_newton_matrix`]). Positive
    /// semidefinite by construction, from a 6 x 6 and a 2 x 2 eigen-decomposition instead of an
    /// 18 x 18 one, and the forms' six 18 x 18 Hessians are not computed. The dropped curvature
    /// term holds every negative eigenvalue of the element Hessians of a curling stockinette (its
    /// bending stress is not zero on the flat cloth). The gradient, and so the solution, is
    /// unchanged.
    #[default]
    GaussNewton,
}

/// Whether a symmetric matrix is positive semidefinite up to rounding: a Cholesky
/// factorization of `H + ε I` (`ε` at rounding level) succeeds.
fn is_psd<const N: usize>(h: &SMatrix<f64, N, N>) -> bool {
    let scale = h.diagonal().amax().max(f64::MIN_POSITIVE);
    nalgebra::Cholesky::new(h + SMatrix::<f64, N, N>::identity() * (1e-12 * scale)).is_some()
}

macro_rules! split_hessian {
    ($name:ident, $n:literal) => {
        /// `h` with its negative eigenvalue part; matrices that are already positive
        /// semidefinite skip the eigensolver.
        pub fn $name(h: SMatrix<f64, $n, $n>) -> SplitHessian<$n> {
            if is_psd(&h) {
                return SplitHessian { matrix: h, negative: None };
            }
            let eigen = nalgebra::SymmetricEigen::new(h);
            let mut negative = SMatrix::<f64, $n, $n>::zeros();
            for (l, v) in eigen.eigenvalues.iter().zip(eigen.eigenvectors.column_iter()) {
                if *l < 0.0 {
                    negative += *l * v * v.transpose();
                }
            }
            SplitHessian { matrix: h, negative: Some(negative) }
        }
    };
}

split_hessian!(split_hessian_3, 3);
split_hessian!(split_hessian_6, 6);
split_hessian!(split_hessian_9, 9);
split_hessian!(split_hessian_12, 12);
split_hessian!(split_hessian_18, 18);

/// The stress `s = ∂Ψ/∂I` as the symmetric `S = [[s_11, s_12/2], [s_12/2, s_22]]` with its
/// compressive (negative) eigenvalues set to zero.
fn tensile_stress(s: &[f64]) -> Matrix2<f64> {
    let eigen = nalgebra::SymmetricEigen::new(Matrix2::new(s[0], 0.5 * s[1], 0.5 * s[1], s[2]));
    let tension = eigen.eigenvalues.map(|l| l.max(0.0));
    eigen.eigenvectors * Matrix2::from_diagonal(&tension) * eigen.eigenvectors.transpose()
}

/// The Gauss-Newton element matrix (per unit rest area) of an energy density `Ψ(z)` of `M` forms
/// over `N` DOFs whose first 9 are the triangle's: `Jᵀ |∇²Ψ| J + (2 W S₊ Wᵀ) ⊗ Id₃`, where
/// `J = ∂z/∂q`, `|∇²Ψ|` has the material Hessian's eigenvalues made absolute (`material` is
/// `∇²Ψ` with its negative part) and `(2 W S₊ Wᵀ) ⊗ Id₃` is the first form's stress term
/// `Σ_k ∂Ψ/∂I_k ∇²I_k` at the tensile part of the stress ([`first_form_stress_hessian`]).
/// Positive semidefinite by construction.
pub fn gauss_newton_matrix<const M: usize, const N: usize>(
    rest: &RestTriangle,
    jacobian: &SMatrix<f64, M, N>,
    material: &SplitHessian<M>,
    first_form_stress: &[f64],
) -> SMatrix<f64, N, N> {
    let mut h = jacobian.transpose() * material.absolute() * jacobian;
    let k = first_form_stress_hessian(rest, &tensile_stress(first_form_stress));
    for a in 0..3 {
        for b in 0..3 {
            for c in 0..3 {
                h[(3 * a + c, 3 * b + c)] += k[(a, b)];
            }
        }
    }
    h
}

/// A cloth's elastic energy: mesh, rest data and material.
#[derive(Debug, Clone)]
pub struct ElasticModel {
    /// The mesh.
    pub mesh: ShellMesh,
    /// The material.
    pub material: ShellMaterial,
    rest: Vec<RestTriangle>,
    hinges: Vec<HingeRest>,
}

/// An element's energy, gradient and Hessian (if asked for).
pub type Element<const N: usize> = (f64, SVector<f64, N>, Option<SMatrix<f64, N, N>>);

/// An element's energy, gradient and Hessian with its negative part (if asked for).
type SplitElement<const N: usize> = (f64, SVector<f64, N>, Option<SplitHessian<N>>);

/// Elements evaluated in parallel per chunk, then handed on in order: a chunk's results stay
/// small (about 1 MB for 18-DOF elements) where all of a mesh's would take tens of MB.
const CHUNK: usize = 256;

/// Evaluate the elements `0..count` (`element` gives each one's vertices and values) and hand
/// them to `out` in order, element `k` as index `first_index + k`.
fn hand_on<const N: usize, const V: usize>(
    count: usize,
    first_index: usize,
    out: &mut impl ElementSink,
    element: impl Fn(usize) -> ([Option<u32>; V], SplitElement<N>) + Sync,
) {
    for start in (0..count).step_by(CHUNK) {
        let chunk: Vec<_> = (start..(start + CHUNK).min(count)).into_par_iter().map(&element).collect();
        for (k, (vertices, (e, g, h))) in chunk.iter().enumerate() {
            out.add(first_index + start + k, vertices, *e, g, h.as_ref());
        }
    }
}

impl ElasticModel {
    /// The model of `mesh` made of `material`, rest state flat at the material coordinates.
    pub fn new(mesh: ShellMesh, material: ShellMaterial) -> Self {
        let rest =
            mesh.triangles.iter().map(|t| RestTriangle::new(&t.map(|v| mesh.material[v as usize]))).collect();
        let hinges = match material.hinge_bending {
            Some(k) => mesh
                .hinges
                .iter()
                .map(|h| {
                    let m = h.vertices.map(|v| mesh.material[v as usize]);
                    let edge = m[1] - m[0];
                    HingeRest::new(
                        &m,
                        anisotropic_stiffness(&edge, k.k_weft, k.k_bias, k.k_warp),
                        anisotropic_stiffness(
                            &edge,
                            k.rest_curvature_weft,
                            k.rest_curvature_bias,
                            k.rest_curvature_warp,
                        ),
                    )
                })
                .collect(),
            None => Vec::new(),
        };
        Self { mesh, material, rest, hinges }
    }

    /// The stencil vertices of triangle `t`: its 3 vertices and the 3 far neighbours.
    fn stencil_vertices(&self, t: usize) -> [Option<u32>; 6] {
        let [a, b, c] = self.mesh.triangles[t];
        let [n0, n1, n2] = self.mesh.neighbours[t];
        [Some(a), Some(b), Some(c), n0, n1, n2]
    }

    fn stencil(&self, t: usize, x: &[Vector3<f64>]) -> Stencil {
        let [a, b, c] = self.mesh.triangles[t];
        Stencil {
            triangle: [a, b, c].map(|v| x[v as usize]),
            neighbours: self.mesh.neighbours[t].map(|n| n.map(|v| x[v as usize])),
        }
    }

    /// The discrete forms `(I, II)` of triangle `t` (`II` zero for a membrane material, which
    /// does not use it).
    pub fn triangle_forms(&self, t: usize, x: &[Vector3<f64>]) -> ([f64; 3], [f64; 3]) {
        if self.material.uses_second_form() {
            forms(&self.rest[t], &self.stencil(t, x))
        } else {
            (first_form_of(&self.rest[t], &self.mesh.triangles[t].map(|v| x[v as usize])), [0.0; 3])
        }
    }

    /// The elastic energy (J).
    pub fn energy(&self, x: &[Vector3<f64>]) -> f64 {
        let triangles: f64 = (0..self.rest.len())
            .into_par_iter()
            .map(|t| {
                let (first, second) = self.triangle_forms(t, x);
                self.rest[t].rest_area * self.material.energy_density(first, second)
            })
            .collect::<Vec<_>>()
            .iter()
            .sum();
        let hinges: f64 = self
            .hinges
            .iter()
            .zip(&self.mesh.hinges)
            .map(|(rest, h)| hinge_energy(rest, &h.vertices.map(|v| x[v as usize])))
            .sum();
        triangles + hinges
    }

    /// The vertices of every element in the order [`ElasticModel::assemble`] hands them on:
    /// the triangles (their stencils, or only their corners for a membrane material), then the
    /// hinges.
    pub fn element_vertices(&self) -> Vec<Vec<Option<u32>>> {
        let triangles = (0..self.rest.len()).map(|t| match self.material.uses_second_form() {
            true => self.stencil_vertices(t).to_vec(),
            false => self.mesh.triangles[t].map(Some).to_vec(),
        });
        let hinges = self.mesh.hinges.iter().take(self.hinges.len()).map(|h| h.vertices.map(Some).to_vec());
        triangles.chain(hinges).collect()
    }

    /// Energy, gradient and, if `matrix` asks for them, the element matrices with their negative
    /// parts, handed to `out` in element order. Elements are evaluated in parallel, in chunks,
    /// and handed on in order (identical for any thread count).
    pub fn assemble(&self, x: &[Vector3<f64>], matrix: Option<NewtonMatrix>, out: &mut impl ElementSink) {
        let triangles = self.rest.len();
        if self.material.uses_second_form() {
            hand_on(triangles, 0, out, |t| (self.stencil_vertices(t), self.triangle_element(t, x, matrix)));
        } else {
            hand_on(triangles, 0, out, |t| {
                (self.mesh.triangles[t].map(Some), self.membrane_element(t, x, matrix))
            });
        }
        hand_on(self.hinges.len(), triangles, out, |k| {
            let vertices = self.mesh.hinges[k].vertices;
            let d = hinge_energy_with_derivatives(&self.hinges[k], &vertices.map(|v| x[v as usize]));
            let h = matrix.map(|matrix| match matrix {
                NewtonMatrix::GaussNewton => SplitHessian { matrix: d.gauss_newton, negative: None },
                NewtonMatrix::Projected => split_hessian_12(d.hessian),
            });
            (vertices.map(Some), (d.energy, d.gradient, h))
        });
    }

    /// (4.8) for a membrane material (`Ψ(I)` only) over the triangle's 9 DOFs:
    /// `∇²E = A (Jᵀ ∇²Ψ J + Σ_k ∂Ψ/∂I_k ∇² I_k)` with its negative part, or the
    /// [`NewtonMatrix::GaussNewton`] matrix.
    fn membrane_element(
        &self,
        t: usize,
        x: &[Vector3<f64>],
        matrix: Option<NewtonMatrix>,
    ) -> SplitElement<9> {
        let rest = &self.rest[t];
        let forms = first_form_with_derivatives(rest, &self.mesh.triangles[t].map(|v| x[v as usize]));
        let jet = self.material.jet(forms.first, [0.0; 3]);
        let dpsi = jet.gradient.fixed_rows::<3>(0).into_owned();
        let area = rest.rest_area;
        let gradient = area * forms.gradient.transpose() * dpsi;
        let material = jet.hessian.fixed_view::<3, 3>(0, 0).into_owned();
        let h = matrix.map(|matrix| match matrix {
            NewtonMatrix::GaussNewton => {
                let h =
                    gauss_newton_matrix(rest, &forms.gradient, &split_hessian_3(material), dpsi.as_slice());
                SplitHessian { matrix: area * h, negative: None }
            }
            NewtonMatrix::Projected => {
                let mut h = forms.gradient.transpose() * material * forms.gradient;
                for (k, d2i) in forms.hessian.iter().enumerate() {
                    h += dpsi[k] * d2i;
                }
                split_hessian_9(area * h)
            }
        });
        (area * jet.value, gradient, h)
    }

    /// (4.8) with (A.43)-(A.44), the element matrix `matrix` asks for with its negative part.
    fn triangle_element(
        &self,
        t: usize,
        x: &[Vector3<f64>],
        matrix: Option<NewtonMatrix>,
    ) -> SplitElement<18> {
        match matrix {
            Some(NewtonMatrix::GaussNewton) => {
                let (e, g, h) = self.triangle_element_gauss_newton(t, x);
                (e, g, Some(SplitHessian { matrix: h, negative: None }))
            }
            _ => {
                let (e, g, h) = self.triangle_element_exact(t, x, matrix.is_some());
                (e, g, h.map(split_hessian_18))
            }
        }
    }

    /// (4.8) with (A.43) and the [`NewtonMatrix::GaussNewton`] matrix
    /// `A (Jᵀ |∇²Ψ| J + (2 W S₊ Wᵀ) ⊗ Id₃)` ([`gauss_newton_matrix`]).
    pub fn triangle_element_gauss_newton(
        &self,
        t: usize,
        x: &[Vector3<f64>],
    ) -> (f64, SVector<f64, 18>, SMatrix<f64, 18, 18>) {
        let rest = &self.rest[t];
        let area = rest.rest_area;
        let forms = forms_with_gradient(rest, &self.stencil(t, x));
        let jet = self.material.jet(forms.first, forms.second);
        let h = gauss_newton_matrix(
            rest,
            &forms.gradient,
            &split_hessian_6(jet.hessian),
            &jet.gradient.as_slice()[..3],
        );
        (area * jet.value, area * forms.gradient.transpose() * jet.gradient, area * h)
    }

    /// (4.8) with (A.43)-(A.44): `E = A Ψ(z(q))`, `∇E = A Jᵀ ∇Ψ`,
    /// `∇²E = A (Jᵀ ∇²Ψ J + Σ_k ∂Ψ/∂z_k ∇² z_k)` over the 18 stencil DOFs (absent neighbours'
    /// entries are zero).
    pub fn triangle_element_exact(&self, t: usize, x: &[Vector3<f64>], hessian: bool) -> Element<18> {
        let rest = &self.rest[t];
        let stencil = self.stencil(t, x);
        let area = rest.rest_area;
        if !hessian {
            let forms = forms_with_gradient(rest, &stencil);
            let jet = self.material.jet(forms.first, forms.second);
            return (area * jet.value, area * forms.gradient.transpose() * jet.gradient, None);
        }
        let forms = forms_with_derivatives(rest, &stencil);
        let jet = self.material.jet(forms.first, forms.second);
        let gradient = area * forms.gradient.transpose() * jet.gradient;
        let mut h = forms.gradient.transpose() * jet.hessian * forms.gradient;
        for (k, d2z) in forms.hessian.iter().enumerate() {
            if jet.gradient[k] != 0.0 {
                h += jet.gradient[k] * d2z;
            }
        }
        (area * jet.value, gradient, Some(area * h))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::HingeBending;

    fn stvk() -> ShellMaterial {
        ShellMaterial::stvk(
            0.3,
            crate::test_support::test_membrane(),
            HingeBending {
                k_weft: 1e-4,
                k_bias: 2e-4,
                k_warp: 3e-4,
                rest_curvature_weft: 2.0,
                rest_curvature_bias: -1.0,
                rest_curvature_warp: 0.5,
            },
        )
    }

    fn deformed(mesh: &ShellMesh) -> Vec<Vector3<f64>> {
        mesh.material
            .iter()
            .map(|m| Vector3::new(1.1 * m.x + 0.05 * m.y, 0.95 * m.y, 0.3 * (3.0 * m.x).sin() * m.y))
            .collect()
    }

    #[test]
    fn assembled_gradient_matches_finite_differences_of_the_energy() {
        let mesh = ShellMesh::rectangle(0.3, 0.2, 4, 3).expect("mesh");
        let model = ElasticModel::new(mesh.clone(), stvk());
        let x = deformed(&mesh);
        let mut a = Assembly::new(3 * x.len());
        model.assemble(&x, None, &mut a);
        assert!((a.energy - model.energy(&x)).abs() < 1e-12 * a.energy.abs().max(1.0));
        let h = 1e-7;
        for dof in 0..3 * x.len() {
            let (mut p, mut m) = (x.clone(), x.clone());
            p[dof / 3][dof % 3] += h;
            m[dof / 3][dof % 3] -= h;
            let fd = (model.energy(&p) - model.energy(&m)) / (2.0 * h);
            assert!(
                (a.gradient[dof] - fd).abs() < 1e-6 * (1.0 + fd.abs()),
                "dof {dof}: {} vs {fd}",
                a.gradient[dof]
            );
        }
    }

    #[test]
    fn the_membrane_element_is_the_stencil_element_without_its_zero_entries() {
        // StVK ignores II: the 9-DOF path must give the 18-DOF element's energy, gradient and
        // (unclamped, here PSD) Hessian on the triangle's DOFs, and zeros elsewhere.
        let mesh = ShellMesh::rectangle(0.3, 0.2, 4, 3).expect("mesh");
        let mut material = stvk();
        material.hinge_bending = None;
        let model = ElasticModel::new(mesh.clone(), material);
        let x: Vec<_> =
            mesh.material.iter().map(|m| Vector3::new(1.2 * m.x + 0.1 * m.y, 1.1 * m.y, 0.0)).collect();
        for t in 0..mesh.triangles.len() {
            let (e18, g18, h18) = model.triangle_element_exact(t, &x, true);
            let (e9, g9, h9) = model.membrane_element(t, &x, Some(NewtonMatrix::Projected));
            let (h18, h9) = (h18.expect("asked for"), h9.expect("asked for").matrix);
            assert!((e18 - e9).abs() < 1e-15 * e18.abs().max(1.0));
            assert!((g18.fixed_rows::<9>(0) - g9).amax() < 1e-12 * g9.amax().max(1.0));
            assert!(g18.fixed_rows::<9>(9).amax() == 0.0);
            assert!((h18.fixed_view::<9, 9>(0, 0) - h9).amax() < 1e-9 * h9.amax().max(1.0), "triangle {t}");
            // So is the Gauss-Newton matrix, the same construction on 3 forms instead of 6.
            let (_, _, gn18) = model.triangle_element_gauss_newton(t, &x);
            let (_, _, gn9) = model.membrane_element(t, &x, Some(NewtonMatrix::GaussNewton));
            let gn9 = gn9.expect("asked for");
            assert!(gn9.negative.is_none());
            assert!(
                (gn18.fixed_view::<9, 9>(0, 0) - gn9.matrix).amax() < 1e-9 * gn9.matrix.amax(),
                "triangle {t}"
            );
            assert!(
                gn18.fixed_view::<9, 9>(9, 0).amax() == 0.0 && gn18.fixed_view::<9, 9>(9, 9).amax() == 0.0
            );
        }
        let mut a = Assembly::new(3 * x.len());
        model.assemble(&x, None, &mut a);
        assert!((a.energy - model.energy(&x)).abs() < 1e-12 * a.energy.abs().max(1.0));
    }

    #[test]
    fn rigid_motions_leave_the_energy_unchanged() {
        let mesh = ShellMesh::rectangle(0.3, 0.2, 4, 3).expect("mesh");
        let model = ElasticModel::new(mesh.clone(), stvk());
        let x = deformed(&mesh);
        let rotation = nalgebra::Rotation3::from_euler_angles(0.3, -0.7, 1.1);
        let moved: Vec<_> = x.iter().map(|p| rotation * p + Vector3::new(1.0, -2.0, 0.5)).collect();
        assert!((model.energy(&x) - model.energy(&moved)).abs() < 1e-12);
        // The material curls at rest: flat costs bending energy, unless it is flat at rest.
        assert!(model.energy(&mesh.flat_positions()) > 0.0);
        let mut flat_at_rest = stvk();
        flat_at_rest.hinge_bending =
            flat_at_rest.hinge_bending.map(|b| HingeBending::anisotropic(b.k_weft, b.k_bias, b.k_warp));
        let flat_model = ElasticModel::new(mesh.clone(), flat_at_rest);
        assert!(flat_model.energy(&mesh.flat_positions()).abs() < 1e-15);
    }

    #[test]
    fn projected_hessians_are_psd_and_psd_ones_are_untouched() {
        let mut a = SMatrix::<f64, 12, 12>::identity();
        a[(1, 1)] = -1.0;
        a[(0, 1)] = 0.5;
        a[(1, 0)] = 0.5;
        let split = split_hessian_12(a);
        let p = split.clamped();
        assert!(p.symmetric_eigenvalues().iter().all(|&l| l >= -1e-14));
        assert!((p[(5, 5)] - 1.0).abs() < 1e-14 && p[(1, 1)] > -1.0);
        // The absolute Hessian has the absolute eigenvalues.
        let sorted = |mut l: Vec<f64>| {
            l.sort_by(f64::total_cmp);
            l
        };
        let flipped = sorted(split.absolute().symmetric_eigenvalues().iter().copied().collect());
        let expected = sorted(a.symmetric_eigenvalues().iter().map(|l| l.abs()).collect());
        assert!(flipped.iter().zip(&expected).all(|(f, e)| (f - e).abs() < 1e-12), "{flipped:?}");
        let spd = SMatrix::<f64, 18, 18>::identity() * 2.0;
        assert!(split_hessian_18(spd).negative.is_none());
    }

    /// The published honeycomb on a doubly curved, sheared, stretched mesh, and an interior
    /// triangle of it.
    fn honeycomb_on_a_curved_mesh() -> (ElasticModel, Vec<Vector3<f64>>, usize) {
        let path = format!("{}/../../../shared/data/hylc-materials/honey1.json", env!("CARGO_MANIFEST_DIR"));
        let spline = yarnhom_artifacts::open::open_artifact::<yarnhom_artifacts::Spline>(&path)
            .expect("published")
            .value;
        let material = ShellMaterial::spline(yarnhom_fit::SplineMaterial::from(&spline));
        let mesh = ShellMesh::rectangle(0.02, 0.02, 5, 5).expect("mesh");
        let model = ElasticModel::new(mesh.clone(), material);
        let x: Vec<_> = mesh
            .material
            .iter()
            .map(|m| {
                Vector3::new(
                    1.1 * m.x + 0.05 * m.y,
                    0.95 * m.y,
                    15.0 * m.x * m.x - 10.0 * m.y * m.y + 5.0 * m.x * m.y,
                )
            })
            .collect();
        let t = (0..mesh.triangles.len())
            .find(|&t| mesh.neighbours[t].iter().all(Option::is_some))
            .expect("interior");
        (model, x, t)
    }

    #[test]
    fn spline_element_derivatives_match_finite_differences() {
        let (model, x, t) = honeycomb_on_a_curved_mesh();
        let vertices = model.stencil_vertices(t).map(|v| v.expect("interior") as usize);
        let (_, gradient, hessian) = model.triangle_element_exact(t, &x, true);
        let hessian = hessian.expect("asked for");
        let h = 1e-8;
        for (a, &v) in vertices.iter().enumerate() {
            for k in 0..3 {
                let (mut p, mut m) = (x.clone(), x.clone());
                p[v][k] += h;
                m[v][k] -= h;
                let (ep, gp, _) = model.triangle_element_exact(t, &p, false);
                let (em, gm, _) = model.triangle_element_exact(t, &m, false);
                let i = 3 * a + k;
                let fd = (ep - em) / (2.0 * h);
                assert!(
                    (gradient[i] - fd).abs() < 1e-6 * gradient.amax(),
                    "dE/dq[{i}]: {} vs {fd}",
                    gradient[i]
                );
                let fd2 = (gp - gm) / (2.0 * h);
                for j in 0..18 {
                    assert!(
                        (hessian[(j, i)] - fd2[j]).abs() < 1e-5 * hessian.amax(),
                        "H[{j}][{i}]: {} vs {}",
                        hessian[(j, i)],
                        fd2[j]
                    );
                }
            }
        }
    }

    /// `m` with its eigenvalues made absolute, by a dense eigen-decomposition.
    fn absolute_valued<const N: usize>(m: &SMatrix<f64, N, N>) -> nalgebra::DMatrix<f64> {
        let eigen = nalgebra::DMatrix::from_fn(N, N, |i, j| m[(i, j)]).symmetric_eigen();
        let abs = nalgebra::DMatrix::from_diagonal(&eigen.eigenvalues.map(f64::abs));
        &eigen.eigenvectors * abs * eigen.eigenvectors.transpose()
    }

    #[test]
    fn the_gauss_newton_matrix_is_psd_and_drops_only_the_stress_weighted_form_hessians() {
        let (model, x, t) = honeycomb_on_a_curved_mesh();
        // As meshed (stretched along x), and compressed to 80% about the triangle.
        let centre = x[model.mesh.triangles[t][0] as usize];
        let compressed: Vec<_> = x.iter().map(|p| centre + 0.8 * (p - centre)).collect();
        let mut clamped_stress = false;
        for x in [x, compressed] {
            let (e, g, _) = model.triangle_element_exact(t, &x, false);
            let (e_gn, g_gn, h_gn) = model.triangle_element_gauss_newton(t, &x);
            assert_eq!((e, g), (e_gn, g_gn));
            let forms = forms_with_derivatives(&model.rest[t], &model.stencil(t, &x));
            let jet = model.material.jet(forms.first, forms.second);
            let j = nalgebra::DMatrix::from_fn(6, 18, |r, c| forms.gradient[(r, c)]);
            let mut expected = j.transpose() * absolute_valued(&jet.hessian) * j;
            // The first form's stress term at the stress's tensile part, in [11, 12, 22] entries.
            let s = tensile_stress(&jet.gradient.as_slice()[..3]);
            clamped_stress |= (s[(0, 0)] - jet.gradient[0]).abs() > 1e-9 * jet.gradient.amax();
            for (k, weight) in [s[(0, 0)], 2.0 * s[(0, 1)], s[(1, 1)]].into_iter().enumerate() {
                expected += weight * nalgebra::DMatrix::from_fn(18, 18, |r, c| forms.hessian[k][(r, c)]);
            }
            let expected = model.rest[t].rest_area * expected;
            let error = (nalgebra::DMatrix::from_fn(18, 18, |r, c| h_gn[(r, c)]) - &expected).amax();
            assert!(error < 1e-10 * expected.amax(), "{error}");
            let lowest = h_gn.symmetric_eigenvalues().min();
            assert!(lowest > -1e-12 * h_gn.amax(), "positive semidefinite: {lowest}");
        }
        assert!(clamped_stress, "compression leaves a stress to clamp");
    }
}
