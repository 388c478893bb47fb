//! Discrete first and second fundamental forms of a triangle with its edge neighbours
//! (thesis Ch. 4.2, eqs. 4.4–4.7), with exact gradients and Hessians.
//!
//! A stencil has six vertices `[x0, x1, x2, n0, n1, n2]`: the triangle, counter-clockwise in
//! material space, and for each edge `i` (opposite `x_i`: edge 0 = (x1, x2), edge 1 = (x2, x0),
//! edge 2 = (x0, x1)) the far vertex `n_i` of the neighbouring triangle, if any. The 18 DOFs
//! are these positions in that order; a missing neighbour contributes nothing and its
//! gradient/Hessian entries are zero.
//!
//! * (4.4) `F = (x1 - x0, x2 - x0) · rest_inverse`.
//! * (4.5) `Λ = Σ_i θ_i/(2 A l_i) t_i ⊗ t_i`, `θ_i` the signed dihedral angle across edge `i`
//!   ([`crate::dihedral`]), `A` the current area, `l_i` the current edge length, `t_i` the
//!   in-plane edge normal of length `l_i`.
//! * (4.6) `I = Fᵀ F`, (4.7) `II = Fᵀ Λ F`.
//!
//! Since `t_i · (x_j - x_0)` is `±2A` or `0`, (4.7) collapses to
//! `II = Σ_i θ_i h_i w_i ⊗ w_i` with `h_i = 2A/l_i` the altitude over edge `i` and
//! `w_i = ∇_X λ_i = rest_inverseᵀ s_i` (`s_0 = (-1, -1)`, `s_1 = (1, 0)`, `s_2 = (0, 1)`) the
//! material gradient of the barycentric coordinate `λ_i`; likewise `F = Σ_j x_j ⊗ w_j`.
//! The derivatives follow from those of `θ_i` and `h_i`.
//!
//! Sign convention: `II_ab ≈ n · ∂²φ/∂X_a∂X_b` with `n = normalize((x1 - x0) × (x2 - x0))`,
//! so a surface bending towards `n` has positive `II` (pinned by the parabola, cylinder and
//! paraboloid tests below).

use crate::dihedral::{Hinge, Vec3, add_symmetric_block, angle_between_normals};
use nalgebra::{ArrayStorage, Matrix2, Matrix3, Matrix3x2, SMatrix, Vector2};

/// Index pairs `(a, b)` of the stored entries `[11, 12, 22]` of a symmetric 2×2 form.
const FORM_ENTRIES: [(usize, usize); 3] = [(0, 0), (0, 1), (1, 1)];

/// Rest data of one triangle; its material coordinates must be counter-clockwise.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RestTriangle {
    /// `(X1 - X0, X2 - X0)⁻¹`.
    pub rest_inverse: Matrix2<f64>,
    /// Material area (m²).
    pub rest_area: f64,
}

impl RestTriangle {
    /// Panics if the material triangle is degenerate or clockwise.
    pub fn new(material: &[Vector2<f64>; 3]) -> Self {
        let edges = Matrix2::from_columns(&[material[1] - material[0], material[2] - material[0]]);
        let rest_area = 0.5 * edges.determinant();
        assert!(rest_area > 0.0, "rest triangle must be counter-clockwise and non-degenerate");
        let rest_inverse = edges.try_inverse().expect("non-degenerate rest triangle");
        Self { rest_inverse, rest_area }
    }

    /// `w_j = ∇_X λ_j`, the material gradients of the barycentric coordinates.
    fn barycentric_gradients(&self) -> [Vector2<f64>; 3] {
        let w1 = self.rest_inverse.row(0).transpose();
        let w2 = self.rest_inverse.row(1).transpose();
        [-w1 - w2, w1, w2]
    }
}

/// Current positions of one stencil.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stencil {
    /// `[x0, x1, x2]`.
    pub triangle: [Vec3; 3],
    /// `n_i`: far vertex of the neighbour across edge `i`, `None` on a boundary edge.
    pub neighbours: [Option<Vec3>; 3],
}

/// `I`, `II` and their exact derivatives over the 18 stencil DOFs.
#[derive(Clone, Debug)]
pub struct FormsWithDerivatives {
    /// `[I11, I12, I22]`, eq. (4.6).
    pub first: [f64; 3],
    /// `[II11, II12, II22]`, eq. (4.7).
    pub second: [f64; 3],
    /// Current (world) area of the triangle.
    pub area: f64,
    /// Rows: `I11, I12, I22, II11, II12, II22`.
    pub gradient: SMatrix<f64, 6, 18>,
    /// One symmetric 18×18 Hessian per row of `gradient`.
    pub hessian: [SMatrix<f64, 18, 18>; 6],
}

/// `I`, `II` and their exact gradients over the 18 stencil DOFs: what a gradient needs, without
/// the 15 KB of Hessians.
#[derive(Clone, Debug)]
pub struct FormsWithGradient {
    /// `[I11, I12, I22]`, eq. (4.6).
    pub first: [f64; 3],
    /// `[II11, II12, II22]`, eq. (4.7).
    pub second: [f64; 3],
    /// Rows: `I11, I12, I22, II11, II12, II22`.
    pub gradient: SMatrix<f64, 6, 18>,
}

/// Current (world) area of a triangle.
pub fn current_area(triangle: &[Vec3; 3]) -> f64 {
    0.5 * triangle_normal(triangle).norm()
}

/// `(x1 - x0) × (x2 - x0)`, twice the area times the unit normal.
fn triangle_normal(x: &[Vec3; 3]) -> Vec3 {
    (x[1] - x[0]).cross(&(x[2] - x[0]))
}

/// Deformation gradient `F = (x1 - x0, x2 - x0) · rest_inverse`, eq. (4.4).
pub fn deformation_gradient(rest: &RestTriangle, triangle: &[Vec3; 3]) -> Matrix3x2<f64> {
    let [x0, x1, x2] = triangle;
    Matrix3x2::from_columns(&[x1 - x0, x2 - x0]) * rest.rest_inverse
}

/// `(I, II)` as `[11, 12, 22]` entries, eqs. (4.6)–(4.7); value only (for line searches).
pub fn forms(rest: &RestTriangle, stencil: &Stencil) -> ([f64; 3], [f64; 3]) {
    let x = &stencil.triangle;
    let w = rest.barycentric_gradients();
    let normal = triangle_normal(x);
    let double_area = normal.norm();
    let mut second = [0.0; 3];
    for (i, neighbour) in stencil.neighbours.iter().enumerate() {
        let Some(far) = neighbour else { continue };
        let [p0, p1, _] = hinge_edge(x, i);
        let edge = p1 - p0;
        let neighbour_normal = (p0 - p1).cross(&(far - p1));
        let angle = angle_between_normals(&normal, &neighbour_normal, &edge);
        let weight = angle * double_area / edge.norm();
        for (entry, factor) in second.iter_mut().zip(outer_entries(&w[i])) {
            *entry += factor * weight;
        }
    }
    (first_form(&deformation_gradient(rest, x)), second)
}

/// `(I, II)` with exact gradients and Hessians over the 18 stencil DOFs.
pub fn forms_with_derivatives(rest: &RestTriangle, stencil: &Stencil) -> FormsWithDerivatives {
    let mut out = FormsWithDerivatives::zeroed();
    out.evaluate(rest, stencil);
    out
}

impl FormsWithDerivatives {
    /// All zeros; a reusable buffer for [`FormsWithDerivatives::evaluate`].
    pub fn zeroed() -> Self {
        Self {
            first: [0.0; 3],
            second: [0.0; 3],
            area: 0.0,
            gradient: SMatrix::from_array_storage(ArrayStorage([[0.0; 6]; 18])),
            hessian: [SMatrix::from_array_storage(ArrayStorage([[0.0; 18]; 18])); 6],
        }
    }

    /// Overwrites `self` with the forms of `stencil` and their derivatives (no 15 KB move,
    /// unlike [`forms_with_derivatives`]).
    pub fn evaluate(&mut self, rest: &RestTriangle, stencil: &Stencil) {
        for hessian in &mut self.hessian {
            hessian.as_mut_slice().fill(0.0);
        }
        let forms = accumulate_forms(rest, stencil, Some(&mut self.hessian));
        self.first = forms.first;
        self.second = forms.second;
        self.gradient = forms.gradient;
        self.area = current_area(&stencil.triangle);
    }
}

/// `(I, II)` with exact gradients over the 18 stencil DOFs.
pub fn forms_with_gradient(rest: &RestTriangle, stencil: &Stencil) -> FormsWithGradient {
    accumulate_forms(rest, stencil, None)
}

/// The forms of `stencil` with their gradients, adding their Hessians to `hessian` if given.
fn accumulate_forms(
    rest: &RestTriangle,
    stencil: &Stencil,
    mut hessian: Option<&mut [SMatrix<f64, 18, 18>; 6]>,
) -> FormsWithGradient {
    let w = rest.barycentric_gradients();
    let x = &stencil.triangle;
    let mut out = FormsWithGradient {
        first: [0.0; 3],
        second: [0.0; 3],
        gradient: SMatrix::from_array_storage(ArrayStorage([[0.0; 6]; 18])),
    };
    add_first_form(&mut out, hessian.as_deref_mut(), rest, x);
    for (i, neighbour) in stencil.neighbours.iter().enumerate() {
        if let Some(far) = neighbour {
            add_edge_term(&mut out, hessian.as_deref_mut(), &w[i], x, i, far);
        }
    }
    out
}

/// `I` of a triangle, eq. (4.6); value only.
pub fn first_form_of(rest: &RestTriangle, triangle: &[Vec3; 3]) -> [f64; 3] {
    first_form(&deformation_gradient(rest, triangle))
}

/// `[I11, I12, I22]` from `F`.
fn first_form(f: &Matrix3x2<f64>) -> [f64; 3] {
    FORM_ENTRIES.map(|(a, b)| f.column(a).dot(&f.column(b)))
}

/// `[w_1², w_1 w_2, w_2²]`: the entries of `w ⊗ w`.
fn outer_entries(w: &Vector2<f64>) -> [f64; 3] {
    FORM_ENTRIES.map(|(a, b)| w[a] * w[b])
}

/// Edge `i` as the hinge wing `[x_{i+1}, x_{i+2}, x_i]`: counter-clockwise, apex `x_i`.
fn hinge_edge(x: &[Vec3; 3], i: usize) -> [Vec3; 3] {
    [x[(i + 1) % 3], x[(i + 2) % 3], x[i]]
}

/// Stencil vertex slots of the hinge `[x_{i+1}, x_{i+2}, x_i, n_i]`.
fn hinge_slots(i: usize) -> [usize; 4] {
    [(i + 1) % 3, (i + 2) % 3, i, 3 + i]
}

/// `I` (4.6) and its exact derivatives over the triangle's 9 DOFs: what membrane materials,
/// which do not depend on `II`, need.
#[derive(Clone, Debug)]
pub struct FirstFormWithDerivatives {
    /// `[I11, I12, I22]`.
    pub first: [f64; 3],
    /// Rows: `I11, I12, I22`.
    pub gradient: SMatrix<f64, 3, 9>,
    /// One symmetric 9×9 Hessian per row (constant in `x`).
    pub hessian: [SMatrix<f64, 9, 9>; 3],
}

/// `I_ab = f_a · f_b` with `f_a = Σ_j w_j^a x_j`: `∂I_ab/∂x_j = w_j^a f_b + w_j^b f_a`,
/// `∂²I_ab/∂x_j∂x_k = (w_j^a w_k^b + w_j^b w_k^a) Id₃`.
pub fn first_form_with_derivatives(rest: &RestTriangle, x: &[Vec3; 3]) -> FirstFormWithDerivatives {
    let w = rest.barycentric_gradients();
    let f = [0, 1].map(|a| (0..3).map(|j| x[j] * w[j][a]).sum::<Vec3>());
    let mut out = FirstFormWithDerivatives {
        first: [0.0; 3],
        gradient: SMatrix::zeros(),
        hessian: [SMatrix::zeros(); 3],
    };
    for (row, &(a, b)) in FORM_ENTRIES.iter().enumerate() {
        out.first[row] = f[a].dot(&f[b]);
        for j in 0..3 {
            let gradient = f[b] * w[j][a] + f[a] * w[j][b];
            out.gradient.fixed_view_mut::<1, 3>(row, 3 * j).copy_from(&gradient.transpose());
            for k in 0..3 {
                let coefficient = w[j][a] * w[k][b] + w[j][b] * w[k][a];
                out.hessian[row].fixed_view_mut::<3, 3>(3 * j, 3 * k).fill_diagonal(coefficient);
            }
        }
    }
    out
}

/// `Σ_k s_k ∇²I_k = K ⊗ Id₃` over the triangle's 9 DOFs (from [`first_form_with_derivatives`]'s
/// Hessians) for the stress `s = ∂Ψ/∂I` as the symmetric `S = [[s_11, s_12/2], [s_12/2, s_22]]`:
/// `K = 2 W S Wᵀ`, `W` the 3 x 2 matrix of barycentric gradients, so `K` is positive
/// semidefinite exactly when `S` is.
pub fn first_form_stress_hessian(rest: &RestTriangle, stress: &Matrix2<f64>) -> Matrix3<f64> {
    let w = rest.barycentric_gradients();
    let w = Matrix3x2::from_rows(&w.map(|r| r.transpose()));
    2.0 * w * stress * w.transpose()
}

/// The first form's rows of the gradient, and of the Hessians if given: the triangle's DOFs are
/// the stencil's first 9.
fn add_first_form(
    out: &mut FormsWithGradient,
    hessian: Option<&mut [SMatrix<f64, 18, 18>; 6]>,
    rest: &RestTriangle,
    x: &[Vec3; 3],
) {
    let first = first_form_with_derivatives(rest, x);
    out.first = first.first;
    out.gradient.fixed_view_mut::<3, 9>(0, 0).copy_from(&first.gradient);
    for (hessian, block) in hessian.into_iter().flatten().zip(&first.hessian) {
        hessian.fixed_view_mut::<9, 9>(0, 0).copy_from(block);
    }
}

/// Adds edge `i`'s term `c_i w_i ⊗ w_i` of (4.7), `c_i = θ_i h_i`, with its derivatives:
/// `∇c = h ∇θ + θ ∇h`, `∇²c = h ∇²θ + θ ∇²h + ∇θ ⊗ ∇h + ∇h ⊗ ∇θ` over the hinge
/// `[x_{i+1}, x_{i+2}, x_i, n_i]` (`h` = altitude of `x_i`, independent of `n_i`).
fn add_edge_term(
    out: &mut FormsWithGradient,
    mut hessian: Option<&mut [SMatrix<f64, 18, 18>; 6]>,
    w_i: &Vector2<f64>,
    x: &[Vec3; 3],
    i: usize,
    far: &Vec3,
) {
    let [p0, p1, apex] = hinge_edge(x, i);
    let hinge = Hinge::new(&[p0, p1, apex, *far]);
    let (angle, altitude) = (hinge.angle(), hinge.wing_a.altitude);
    let angle_gradient = hinge.angle_gradient();
    let altitude_gradient =
        [0, 1, 2, 3].map(|s| if s < 3 { hinge.wing_a.altitude_gradient(s) } else { Vec3::zeros() });
    let factors = outer_entries(w_i);
    let slots = hinge_slots(i);
    for s in 0..4 {
        let gradient = angle_gradient[s] * altitude + altitude_gradient[s] * angle;
        for (k, &factor) in factors.iter().enumerate() {
            let mut row = out.gradient.fixed_view_mut::<1, 3>(3 + k, 3 * slots[s]);
            row += (gradient * factor).transpose();
        }
        let Some(hessian) = hessian.as_deref_mut() else { continue };
        for t in s..4 {
            let cross = angle_gradient[s] * altitude_gradient[t].transpose()
                + altitude_gradient[s] * angle_gradient[t].transpose();
            let mut block = hinge.angle_hessian_block(s, t) * altitude + cross;
            if t < 3 {
                block += hinge.wing_a.altitude_hessian_block(s, t) * angle;
            }
            for (k, &factor) in factors.iter().enumerate() {
                add_symmetric_block(&mut hessian[3 + k], slots[s], slots[t], &(block * factor));
            }
        }
    }
    for (entry, factor) in out.second.iter_mut().zip(factors) {
        *entry += factor * angle * altitude;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::{
        GridMesh, XorShift, apex_across, assert_all_close, assert_close, fd_jacobian, random_triangle,
    };
    use nalgebra::{Matrix3, Rotation3, SVector, Unit};

    type Dofs = SVector<f64, 18>;

    /// Stencil positions as DOFs; missing neighbours read as zeros.
    fn dofs_of(stencil: &Stencil) -> Dofs {
        Dofs::from_fn(|k, _| {
            let slot = k / 3;
            let vertex = match slot {
                0..3 => Some(stencil.triangle[slot]),
                _ => stencil.neighbours[slot - 3],
            };
            vertex.map_or(0.0, |v| v[k % 3])
        })
    }

    /// The stencil at `q` with the neighbour mask of `like`.
    fn stencil_at(q: &Dofs, like: &Stencil) -> Stencil {
        let vertex = |slot: usize| q.fixed_rows::<3>(3 * slot).into_owned();
        Stencil {
            triangle: [0, 1, 2].map(vertex),
            neighbours: [0, 1, 2].map(|i| like.neighbours[i].map(|_| vertex(3 + i))),
        }
    }

    fn values(rest: &RestTriangle, stencil: &Stencil) -> SVector<f64, 6> {
        let (first, second) = forms(rest, stencil);
        SVector::from_iterator(first.into_iter().chain(second))
    }

    /// A random counter-clockwise rest triangle whose area is at least 0.1 × longest edge².
    fn random_rest(rng: &mut XorShift) -> RestTriangle {
        loop {
            let [a, b, c] = random_triangle(rng).map(|v| Vector2::new(v.x, v.y));
            let signed = (b - a).perp(&(c - a));
            let material = if signed > 0.0 { [a, b, c] } else { [a, c, b] };
            let longest = (0..3).map(|i| (material[(i + 1) % 3] - material[i]).norm()).fold(0.0, f64::max);
            if signed.abs() >= 0.2 * longest * longest {
                return RestTriangle::new(&material);
            }
        }
    }

    /// A random stencil; neighbour `i` is present iff bit `i` of `mask` is set, with dihedral
    /// angles up to `max_angle` (2.6 rad ≈ 150° unless a test says otherwise).
    fn random_stencil_folded(rng: &mut XorShift, mask: usize, max_angle: f64) -> Stencil {
        let triangle = random_triangle(rng);
        let neighbours = [0, 1, 2].map(|i| {
            let [p0, p1, apex] = hinge_edge(&triangle, i);
            let angle = rng.uniform(-max_angle, max_angle);
            let far = apex_across(rng, &p0, &p1, &apex, angle);
            (mask >> i & 1 == 1).then_some(far)
        });
        Stencil { triangle, neighbours }
    }

    fn random_stencil(rng: &mut XorShift, mask: usize) -> Stencil {
        random_stencil_folded(rng, mask, 2.6)
    }

    #[test]
    fn derivatives_match_finite_differences() {
        for seed in 1..=6 {
            let mut rng = XorShift::new(seed);
            for mask in 0..8 {
                let rest = random_rest(&mut rng);
                let stencil = random_stencil(&mut rng, mask);
                let q = dofs_of(&stencil);
                let d = forms_with_derivatives(&rest, &stencil);
                let fd = fd_jacobian(|q| values(&rest, &stencil_at(q, &stencil)), &q);
                assert_all_close(&d.gradient, &fd, 1e-6);
                for (row, hessian) in d.hessian.iter().enumerate() {
                    let fd_hessian = fd_jacobian(
                        |q| {
                            let d = forms_with_derivatives(&rest, &stencil_at(q, &stencil));
                            d.gradient.row(row).transpose()
                        },
                        &q,
                    );
                    assert_all_close(hessian, &fd_hessian, 1e-6);
                }
            }
        }
    }

    #[test]
    fn derivative_and_gradient_paths_match_the_value_path() {
        let mut rng = XorShift::new(21);
        for mask in 0..8 {
            let rest = random_rest(&mut rng);
            let stencil = random_stencil(&mut rng, mask);
            let d = forms_with_derivatives(&rest, &stencil);
            let (first, second) = forms(&rest, &stencil);
            // The gradient path does the derivative path's arithmetic without the Hessians.
            let g = forms_with_gradient(&rest, &stencil);
            assert_eq!((g.first, g.second, g.gradient), (d.first, d.second, d.gradient));
            for k in 0..3 {
                assert_close(d.first[k], first[k], 1e-12);
                assert_close(d.second[k], second[k], 1e-12);
            }
            assert_close(d.area, current_area(&stencil.triangle), 1e-15);
            let f = deformation_gradient(&rest, &stencil.triangle);
            let first_from_f = f.transpose() * f;
            assert_close(first[0], first_from_f[(0, 0)], 1e-12);
            assert_close(first[1], first_from_f[(0, 1)], 1e-12);
            assert_close(first[2], first_from_f[(1, 1)], 1e-12);
        }
    }

    #[test]
    fn hessians_are_symmetric() {
        let mut rng = XorShift::new(4);
        for mask in 0..8 {
            let d = forms_with_derivatives(&random_rest(&mut rng), &random_stencil(&mut rng, mask));
            for hessian in &d.hessian {
                assert_eq!(*hessian, hessian.transpose());
            }
        }
    }

    #[test]
    fn missing_neighbours_have_zero_derivatives() {
        let mut rng = XorShift::new(8);
        let rest = random_rest(&mut rng);
        let stencil = random_stencil(&mut rng, 0b010);
        let d = forms_with_derivatives(&rest, &stencil);
        for slot in [3, 5] {
            assert!(d.gradient.fixed_columns::<3>(3 * slot).iter().all(|&g| g == 0.0));
            for hessian in &d.hessian {
                assert!(hessian.fixed_columns::<3>(3 * slot).iter().all(|&h| h == 0.0));
            }
        }
    }

    #[test]
    fn rigid_motion_leaves_forms_unchanged_and_rotates_derivatives() {
        let mut rng = XorShift::new(13);
        for mask in [0b111, 0b101] {
            let rest = random_rest(&mut rng);
            let stencil = random_stencil(&mut rng, mask);
            let rotation: Matrix3<f64> =
                Rotation3::from_axis_angle(&Unit::new_normalize(rng.vector()), rng.uniform(0.5, 3.0)).into();
            let shift = rng.vector() * 5.0;
            let moved = Stencil {
                triangle: stencil.triangle.map(|x| rotation * x + shift),
                neighbours: stencil.neighbours.map(|n| n.map(|x| rotation * x + shift)),
            };
            let (d, m) = (forms_with_derivatives(&rest, &stencil), forms_with_derivatives(&rest, &moved));
            for k in 0..3 {
                assert_close(m.first[k], d.first[k], 1e-12);
                assert_close(m.second[k], d.second[k], 1e-12);
            }
            let mut block_rotation = SMatrix::<f64, 18, 18>::zeros();
            for slot in 0..6 {
                block_rotation.fixed_view_mut::<3, 3>(3 * slot, 3 * slot).copy_from(&rotation);
            }
            assert_all_close(&m.gradient, &(d.gradient * block_rotation.transpose()), 1e-11);
            for (hm, hd) in m.hessian.iter().zip(&d.hessian) {
                assert_all_close(hm, &(block_rotation * hd * block_rotation.transpose()), 1e-11);
            }
        }
    }

    #[test]
    fn flat_configuration_has_zero_second_form() {
        let mut rng = XorShift::new(17);
        for mask in [0b111, 0b011] {
            let rest = random_rest(&mut rng);
            let stencil = random_stencil_folded(&mut rng, mask, 0.0);
            let (_, second) = forms(&rest, &stencil);
            assert!(second.iter().all(|s| s.abs() < 1e-13), "{second:?}");
        }
    }

    /// Every triangle of a regular grid on `[-half_x, half_x] × [-half_y, half_y]` (spacing `h`)
    /// that has three neighbours, as (rest, stencil, material centroid) with positions `embed`.
    fn interior_stencils(
        half_x: f64,
        half_y: f64,
        h: f64,
        embed: impl Fn(Vector2<f64>) -> Vec3,
    ) -> Vec<(RestTriangle, Stencil, Vector2<f64>)> {
        let grid = GridMesh::new(half_x, half_y, h);
        let far_vertex = grid.far_vertices();
        let position = |v: usize| embed(grid.material[v]);
        grid.triangles
            .iter()
            .filter_map(|t| {
                let far = [0, 1, 2].map(|i| far_vertex.get(&(t[(i + 1) % 3], t[(i + 2) % 3])).copied());
                far.iter().all(Option::is_some).then(|| {
                    let rest = RestTriangle::new(&t.map(|v| grid.material[v]));
                    let stencil =
                        Stencil { triangle: t.map(position), neighbours: far.map(|f| f.map(position)) };
                    let centroid = t.iter().map(|&v| grid.material[v]).sum::<Vector2<f64>>() / 3.0;
                    (rest, stencil, centroid)
                })
            })
            .collect()
    }

    fn assert_forms_near(
        stencils: &[(RestTriangle, Stencil, Vector2<f64>)],
        expected: impl Fn(Vector2<f64>) -> ([f64; 3], [f64; 3]),
        tolerance_first: f64,
        tolerance_second: f64,
    ) {
        assert!(stencils.len() > 100);
        for (rest, stencil, centroid) in stencils {
            let (first, second) = forms(rest, stencil);
            let (first_exact, second_exact) = expected(*centroid);
            for k in 0..3 {
                assert_close(first[k], first_exact[k], tolerance_first);
                assert_close(second[k], second_exact[k], tolerance_second);
            }
        }
    }

    /// `z = (c/2) x²` bends towards the CCW normal `+z`: `II11 = c/√(1 + c²x²) > 0`.
    #[test]
    fn parabola_second_form_is_positive_curvature() {
        let c = 1.5;
        let stencils = interior_stencils(0.25, 0.25, 0.01, |p| Vec3::new(p.x, p.y, 0.5 * c * p.x * p.x));
        assert_forms_near(
            &stencils,
            |p| {
                let slope = c * p.x;
                ([1.0 + slope * slope, 0.0, 1.0], [c / (1.0 + slope * slope).sqrt(), 0.0, 0.0])
            },
            0.01,
            0.01 * c,
        );
    }

    /// Material grid wrapped around a cylinder with axis along Y, bending towards (+) or away
    /// from (−) the normal: `II11 = ±1/R`, `I = Id`.
    #[test]
    fn cylinder_second_form_is_plus_minus_inverse_radius() {
        let radius = 0.5;
        for side in [1.0, -1.0] {
            let wrap = |p: Vector2<f64>| {
                let turn = p.x / radius;
                Vec3::new(radius * turn.sin(), p.y, side * radius * (1.0 - turn.cos()))
            };
            let stencils = interior_stencils(1.0, 0.1, 0.01, wrap);
            assert_forms_near(
                &stencils,
                |_| ([1.0, 0.0, 1.0], [side / radius, 0.0, 0.0]),
                1e-4,
                1e-3 / radius,
            );
        }
    }

    /// `z = (c/2)(x² + y²)`: `II ≈ c Id / √(1 + c² r²)`.
    #[test]
    fn paraboloid_second_form_is_isotropic() {
        let c = -2.0;
        let stencils = interior_stencils(0.2, 0.2, 0.01, |p| Vec3::new(p.x, p.y, 0.5 * c * p.norm_squared()));
        assert_forms_near(
            &stencils,
            |p| {
                let g = c * p;
                let scale = 1.0 / (1.0 + g.norm_squared()).sqrt();
                ([1.0 + g.x * g.x, g.x * g.y, 1.0 + g.y * g.y], [c * scale, 0.0, c * scale])
            },
            0.01,
            0.01 * c.abs(),
        );
    }
}
