//! The spline material: the energy density of a [`Spline`] artifact with exact first and second
//! derivatives in the discrete fundamental forms (thesis (4.1)-(4.3), (A.34), App. A.5).
//!
//! Evaluation follows the split of App. A.5: `I` gives the in-plane strains `s = (sx, sa, sy)`
//! (4.1); the splines give `Ψ` and its derivatives in `y = (sx, sa, sy, II11, II12, II22)`, the
//! bending terms through the curvature split (4.3), (A.39)-(A.41) in the form of
//! [`crate::curvature`], which stays smooth at umbilic points; the chain rule returns derivatives
//! in `(I11, I12, I22, II11, II12, II22)`. The shell simulator composes those with the
//! derivatives of the forms in the vertex positions.

use nalgebra::{Matrix3, Matrix4, Matrix6, Vector3, Vector4, Vector6};
use yarnhom_artifacts::{Spline, StrainSample};

use crate::curvature::{BendingAxis, CurvatureSplit, TermJet, blend, blend_value};
use crate::hermite::{Bicubic, Cubic};

/// Index of `II11` in `y`; `II12`, `II22` follow.
const II: usize = 3;

/// An energy density with its gradient and Hessian in some 6 strain coordinates.
#[derive(Debug, Clone, Copy)]
pub struct EnergyJet {
    /// Energy density (J/m²).
    pub value: f64,
    /// Gradient.
    pub gradient: Vector6<f64>,
    /// Hessian.
    pub hessian: Matrix6<f64>,
}

impl EnergyJet {
    fn zero() -> Self {
        Self { value: 0.0, gradient: Vector6::zeros(), hessian: Matrix6::zeros() }
    }
}

/// A 1D term: its axis and spline over normalized strain.
#[derive(Debug, Clone)]
struct Term1d {
    axis: usize,
    scale: f64,
    spline: Cubic,
}

/// A 2D term: its axes and patch over normalized strains.
#[derive(Debug, Clone)]
struct Term2d {
    axes: [usize; 2],
    scales: [f64; 2],
    patch: Bicubic,
}

/// A [`Spline`] artifact ready to evaluate.
#[derive(Debug, Clone)]
pub struct SplineMaterial {
    rest_energy_density: f64,
    areal_density: f64,
    terms_1d: Vec<Term1d>,
    terms_2d: Vec<Term2d>,
}

impl From<&Spline> for SplineMaterial {
    fn from(spline: &Spline) -> Self {
        let scale = |axis: u8| spline.strain_scale[axis as usize];
        Self {
            rest_energy_density: spline.rest_energy_density_j_m2,
            areal_density: spline.areal_density_kg_m2,
            terms_1d: spline
                .terms_1d
                .iter()
                .map(|t| Term1d { axis: t.axis as usize, scale: scale(t.axis), spline: Cubic::from(t) })
                .collect(),
            terms_2d: spline
                .terms_2d
                .iter()
                .map(|t| Term2d {
                    axes: [t.axes[0] as usize, t.axes[1] as usize],
                    scales: [scale(t.axes[0]), scale(t.axes[1])],
                    patch: Bicubic::from(t),
                })
                .collect(),
        }
    }
}

/// The principal curvature a bending axis (3 kx, 4 ky) weighs by `c²` in (4.3).
fn bending_axis(axis: usize) -> BendingAxis {
    if axis == 3 { BendingAxis::X } else { BendingAxis::Y }
}

impl SplineMaterial {
    /// Areal mass density (kg/m²).
    pub fn areal_density_kg_m2(&self) -> f64 {
        self.areal_density
    }

    /// The 1D term of `axis` (0 sx, 1 sa, 2 sy, 3 kx, 4 ky) at strain `x` (not normalized);
    /// `None` without such a term.
    pub fn term_1d(&self, axis: usize, x: f64) -> Option<f64> {
        let term = self.terms_1d.iter().find(|t| t.axis == axis)?;
        Some(term.spline.value(x / term.scale))
    }

    /// The 2D term of `axes` at strains `(x, y)` (not normalized); `None` without such a term.
    pub fn term_2d(&self, axes: [usize; 2], x: f64, y: f64) -> Option<f64> {
        let term = self.terms_2d.iter().find(|t| t.axes == axes)?;
        Some(term.patch.value(x / term.scales[0], y / term.scales[1]))
    }

    /// `Ψ` (A.34) with derivatives in `y = (sx, sa, sy, II11, II12, II22)`.
    fn jet_in_strains(&self, s: &Vector3<f64>, second: [f64; 3]) -> EnergyJet {
        let split = CurvatureSplit::new(second);
        let mut jet = EnergyJet::zero();
        jet.value = self.rest_energy_density;
        for term in &self.terms_1d {
            add_term_1d(&mut jet, term, s, &split);
        }
        for term in &self.terms_2d {
            add_term_2d(&mut jet, term, s, &split);
        }
        jet
    }

    /// `Ψ` (A.34) alone: [`SplineMaterial::jet_in_strains`]'s value, to the last bit.
    fn value_in_strains(&self, s: &Vector3<f64>, second: [f64; 3]) -> f64 {
        let split = CurvatureSplit::new(second);
        let [l1, l2] = split.principal_curvatures();
        let mut value = self.rest_energy_density;
        for term in &self.terms_1d {
            let inv = 1.0 / term.scale;
            value += match term.axis {
                axis if axis < 3 => term.spline.value(s[axis] * inv),
                axis => {
                    let at = |l: f64| term.spline.value(l * inv);
                    blend_value(&split, bending_axis(axis), at(l1), at(l2))
                }
            };
        }
        for term in &self.terms_2d {
            let [a, b] = term.axes;
            let [ia, ib] = [1.0 / term.scales[0], 1.0 / term.scales[1]];
            value += if b < 3 {
                term.patch.value(s[a] * ia, s[b] * ib)
            } else {
                let at = |l: f64| term.patch.value(s[a] * ia, l * ib);
                blend_value(&split, bending_axis(b), at(l1), at(l2))
            };
        }
        value
    }

    /// The energy density (J/m²) of the forms `I = (I11, I12, I22)`, `II = (II11, II12, II22)`:
    /// [`SplineMaterial::jet`]'s value, to the last bit, without the derivatives.
    pub fn energy_density(&self, first: [f64; 3], second: [f64; 3]) -> f64 {
        self.value_in_strains(&planar_strain_values(first), second)
    }

    /// The energy density with gradient and Hessian in `(I11, I12, I22, II11, II12, II22)`
    /// (App. A.5's strain part).
    pub fn jet(&self, first: [f64; 3], second: [f64; 3]) -> EnergyJet {
        let (s, ds, dds) = planar_strains(first);
        let inner = self.jet_in_strains(&s, second);
        // y depends on I through (4.1) and is II itself otherwise.
        let mut dy = Matrix6::identity();
        dy.fixed_view_mut::<3, 3>(0, 0).copy_from(&ds);
        let mut hessian = dy.transpose() * inner.hessian * dy;
        for (k, d2s) in dds.iter().enumerate() {
            let mut block = hessian.fixed_view_mut::<3, 3>(0, 0);
            block += inner.gradient[k] * d2s;
        }
        EnergyJet { value: inner.value, gradient: dy.transpose() * inner.gradient, hessian }
    }

    /// The energy density at a sampled strain of the RVE (`kx`, `ky` the normal curvatures
    /// along X1 and X2, no twist), the point the fit is compared with its grid at.
    pub fn energy_at(&self, strain: &StrainSample) -> f64 {
        let (a, b) = (1.0 + strain.sx, 1.0 + strain.sy);
        self.energy_density([a * a, strain.sa * a * b, b * b], [strain.kx, 0.0, strain.ky])
    }
}

/// Add a 1D term (A.34a, A.34b) to a jet in `y`.
fn add_term_1d(jet: &mut EnergyJet, term: &Term1d, s: &Vector3<f64>, split: &CurvatureSplit) {
    let inv = 1.0 / term.scale;
    if term.axis < 3 {
        let f = term.spline.jet(s[term.axis] * inv);
        jet.value += f.value;
        jet.gradient[term.axis] += f.d1 * inv;
        jet.hessian[(term.axis, term.axis)] += f.d2 * inv * inv;
        return;
    }
    let at = |l: f64| {
        let f = term.spline.jet(l * inv);
        TermJet { value: f.value, l: f.d1 * inv, ll: f.d2 * inv * inv, ..TermJet::default() }
    };
    add_blend(jet, None, term.axis, split, at, term.scale);
}

/// Add a 2D term (A.34a, A.34c) to a jet in `y`.
fn add_term_2d(jet: &mut EnergyJet, term: &Term2d, s: &Vector3<f64>, split: &CurvatureSplit) {
    let [a, b] = term.axes;
    let [ia, ib] = [1.0 / term.scales[0], 1.0 / term.scales[1]];
    if b < 3 {
        let f = term.patch.jet(s[a] * ia, s[b] * ib);
        jet.value += f.value;
        jet.gradient[a] += f.d1[0] * ia;
        jet.gradient[b] += f.d1[1] * ib;
        jet.hessian[(a, a)] += f.d2[0] * ia * ia;
        add_symmetric(&mut jet.hessian, a, b, f.d2[1] * ia * ib);
        jet.hessian[(b, b)] += f.d2[2] * ib * ib;
        return;
    }
    let x = s[a] * ia;
    let at = |l: f64| {
        let f = term.patch.jet(x, l * ib);
        TermJet {
            value: f.value,
            x: f.d1[0] * ia,
            l: f.d1[1] * ib,
            xx: f.d2[0] * ia * ia,
            xl: f.d2[1] * ia * ib,
            ll: f.d2[2] * ib * ib,
        }
    };
    add_blend(jet, Some(a), b, split, at, term.scales[1]);
}

/// Add a bending term `φ(x, λ)` (`at` evaluates it at a curvature; `x` the in-plane strain
/// `in_plane`, if any) blended over the principal curvatures (4.3), (A.41).
fn add_blend(
    jet: &mut EnergyJet,
    in_plane: Option<usize>,
    bending: usize,
    split: &CurvatureSplit,
    at: impl Fn(f64) -> TermJet,
    scale: f64,
) {
    let [l1, l2] = split.principal_curvatures();
    let (value, gradient, hessian): (f64, Vector4<f64>, Matrix4<f64>) =
        blend(split, bending_axis(bending), &at(l1), &at(l2), scale);
    jet.value += value;
    // The blend's variables (x, II11, II12, II22) in y; without an in-plane strain x is absent.
    let index = |k: usize| if k == 0 { in_plane } else { Some(II + k - 1) };
    for i in 0..4 {
        let Some(yi) = index(i) else { continue };
        jet.gradient[yi] += gradient[i];
        for j in 0..4 {
            if let Some(yj) = index(j) {
                jet.hessian[(yi, yj)] += hessian[(i, j)];
            }
        }
    }
}

/// Add `value` at `(i, j)` and `(j, i)`.
fn add_symmetric(m: &mut Matrix6<f64>, i: usize, j: usize, value: f64) {
    m[(i, j)] += value;
    m[(j, i)] += value;
}

/// The in-plane strains (4.1) `sx = √I11 - 1`, `sa = I12 / √(I11 I22)`, `sy = √I22 - 1` of
/// `I = (I11, I12, I22)`, with their Jacobian and the Hessian of each.
pub fn planar_strains(first: [f64; 3]) -> (Vector3<f64>, Matrix3<f64>, [Matrix3<f64>; 3]) {
    let [a, _, c] = first;
    let (ra, rc) = (a.sqrt(), c.sqrt());
    let strains = planar_strain_values(first);
    let sa = strains[1];
    let ds = Matrix3::new(
        0.5 / ra,
        0.0,
        0.0, //
        -0.5 * sa / a,
        1.0 / (ra * rc),
        -0.5 * sa / c, //
        0.0,
        0.0,
        0.5 / rc,
    );
    let dd_sx = Matrix3::new(-0.25 / (a * ra), 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    let dd_sy = Matrix3::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -0.25 / (c * rc));
    // sa = b a^{-1/2} c^{-1/2}
    let (ab, ac, bc) = (-0.5 / (a * ra * rc), 0.25 * sa / (a * c), -0.5 / (ra * c * rc));
    let dd_sa = Matrix3::new(
        0.75 * sa / (a * a),
        ab,
        ac, //
        ab,
        0.0,
        bc, //
        ac,
        bc,
        0.75 * sa / (c * c),
    );
    (strains, ds, [dd_sx, dd_sa, dd_sy])
}

/// The in-plane strains (4.1) alone.
fn planar_strain_values(first: [f64; 3]) -> Vector3<f64> {
    let [a, b, c] = first;
    let (ra, rc) = (a.sqrt(), c.sqrt());
    Vector3::new(ra - 1.0, b / (ra * rc), rc - 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn published(name: &str) -> SplineMaterial {
        let path = format!("{}/../../../shared/data/hylc-materials/{name}.json", env!("CARGO_MANIFEST_DIR"));
        SplineMaterial::from(
            &yarnhom_artifacts::open::open_artifact::<yarnhom_artifacts::Spline>(&path)
                .map(|o| o.value)
                .expect("published material"),
        )
    }

    #[test]
    fn planar_strain_derivatives_match_finite_differences() {
        let first = [1.3, 0.2, 0.8];
        let (_, ds, dds) = planar_strains(first);
        let h = 1e-6;
        for j in 0..3 {
            let (mut p, mut m) = (first, first);
            p[j] += h;
            m[j] -= h;
            let ((sp, dp, _), (sm, dm, _)) = (planar_strains(p), planar_strains(m));
            for k in 0..3 {
                assert!((ds[(k, j)] - (sp[k] - sm[k]) / (2.0 * h)).abs() < 1e-8, "ds[{k}][{j}]");
                for i in 0..3 {
                    assert!(
                        (dds[k][(i, j)] - (dp[(k, i)] - dm[(k, i)]) / (2.0 * h)).abs() < 1e-7,
                        "dds[{k}][{i}{j}]"
                    );
                }
            }
        }
    }

    #[test]
    fn published_material_derivatives_match_finite_differences() {
        let material = published("honey1");
        // In-plane stretch with shear and a doubly curved bend, inside and outside the knots.
        for (first, second) in [
            ([1.2, 0.05, 0.95], [20.0, 5.0, -10.0]),
            ([0.8, -0.1, 1.3], [-40.0, 15.0, 30.0]),
            ([2.5, 0.3, 0.5], [150.0, -60.0, 10.0]),
        ] {
            let jet = material.jet(first, second);
            let x: [f64; 6] = [first[0], first[1], first[2], second[0], second[1], second[2]];
            let at = |y: [f64; 6]| material.jet([y[0], y[1], y[2]], [y[3], y[4], y[5]]);
            for j in 0..6 {
                let h = if j < 3 { 1e-6 } else { 1e-4 };
                let (mut p, mut m) = (x, x);
                p[j] += h;
                m[j] -= h;
                let (jp, jm) = (at(p), at(m));
                let fd = (jp.value - jm.value) / (2.0 * h);
                assert!(
                    (jet.gradient[j] - fd).abs() < 1e-5 * (1.0 + fd.abs()),
                    "{x:?}: dΨ/d{j} {} vs {fd}",
                    jet.gradient[j]
                );
                for i in 0..6 {
                    let fd2 = (jp.gradient[i] - jm.gradient[i]) / (2.0 * h);
                    let scale = 1.0 + jet.hessian.column(j).amax();
                    assert!(
                        (jet.hessian[(i, j)] - fd2).abs() < 1e-4 * scale,
                        "{x:?}: d²Ψ/d{i}d{j} {} vs {fd2}",
                        jet.hessian[(i, j)]
                    );
                }
            }
        }
    }

    #[test]
    fn the_value_path_is_the_jets_value_to_the_last_bit() {
        // The line search compares energies from both paths, so they must agree exactly:
        // every published material over stretch, compression, shear, bending and twist, inside
        // and outside the knots.
        for name in ["stock1", "rib1", "honey1", "basket1", "satin1"] {
            let material = published(name);
            for k in 0..200 {
                let t = k as f64;
                let first = [
                    0.5 + 2.0 * (0.37 * t).sin().powi(2),
                    0.4 * (0.91 * t).cos(),
                    0.5 + 2.0 * (0.53 * t).cos().powi(2),
                ];
                let second = [150.0 * (0.7 * t).sin(), 60.0 * (1.3 * t).sin(), 150.0 * (0.29 * t).cos()];
                let jet = material.jet(first, second);
                assert_eq!(
                    material.energy_density(first, second),
                    jet.value,
                    "{name} at {first:?}, {second:?}"
                );
            }
            let flat = material.jet([1.0, 0.0, 1.0], [0.0; 3]);
            assert_eq!(material.energy_density([1.0, 0.0, 1.0], [0.0; 3]), flat.value, "{name} at rest");
        }
    }

    #[test]
    fn published_materials_rest_without_in_plane_stress() {
        // The in-plane minimum of each term is at s = 0 (A.36): the stress at rest is small
        // against the stress of a 10% stretch.
        for name in ["stock1", "rib1", "honey1", "satin1", "basket1"] {
            let material = published(name);
            let rest = material.jet([1.0, 0.0, 1.0], [0.0; 3]).gradient;
            let stretched = material.jet([1.1 * 1.1, 0.0, 1.1 * 1.1], [0.0; 3]).gradient;
            for k in [0, 2] {
                assert!(
                    rest[k].abs() < 0.05 * stretched[k].abs(),
                    "{name}: dΨ/dI[{k}] {} at rest vs {} at 10%",
                    rest[k],
                    stretched[k]
                );
            }
        }
    }

    #[test]
    fn the_hessian_of_a_flat_state_is_the_limit_of_nearby_ones() {
        // A flat cloth is an umbilic point of II. Written with λ1,2 and c² (A.40), the Hessian
        // there was dominated by rounding of terms growing like 1/√ε (element Hessians of the
        // published stockinette with eigenvalues of ±1.7e10 N/m); the split keeps it bounded.
        for name in ["stock1", "rib1", "honey1", "basket1"] {
            let material = published(name);
            let first = [1.05, 0.02, 0.98];
            let flat = material.jet(first, [0.0; 3]);
            for second in [[1e-3, -2e-3, 1.5e-3], [-1e-4, 0.0, 0.0], [0.0, 1e-4, 0.0]] {
                let near = material.jet(first, second);
                let scale = near.hessian.amax();
                assert!((flat.hessian - near.hessian).amax() < 1e-2 * scale, "{name} at {second:?}");
                assert!((flat.gradient - near.gradient).amax() < 1e-2 * (1.0 + near.gradient.amax()));
            }
        }
    }

    /// The sum (A.34) written out for a strain with only one curvature, term by term.
    fn sum_of_terms(material: &SplineMaterial, kx: f64, ky: f64) -> f64 {
        let zero = |axes: [usize; 2], y: f64| material.term_2d(axes, 0.0, y).unwrap_or(0.0);
        material.rest_energy_density
            + (0..3).map(|k| material.term_1d(k, 0.0).expect("in-plane term")).sum::<f64>()
            + material.term_1d(3, kx).expect("kx term")
            + material.term_1d(4, ky).expect("ky term")
            + [[0, 1], [0, 2], [1, 2]].iter().map(|&axes| zero(axes, 0.0)).sum::<f64>()
            + (0..3).map(|k| zero([k, 3], kx) + zero([k, 4], ky)).sum::<f64>()
    }

    #[test]
    fn bending_about_x_or_y_picks_the_matching_terms() {
        let material = published("rib1");
        let k = 30.0;
        let along_x = material.energy_density([1.0, 0.0, 1.0], [k, 0.0, 0.0]);
        let along_y = material.energy_density([1.0, 0.0, 1.0], [0.0, 0.0, k]);
        assert!((along_x - sum_of_terms(&material, k, 0.0)).abs() < 1e-9);
        assert!((along_y - sum_of_terms(&material, 0.0, k)).abs() < 1e-9);
        assert!((along_x - along_y).abs() > 1e-4, "rib bends anisotropically");
    }
}
