//! The semantic difference of two spline materials (`yarnhom diff` on splines): both materials
//! evaluated on a dense strain plan shaped like the sampling plan (thesis App. A.3.1), so two
//! fits are compared by the energies and stresses they give, not by their coefficients (which
//! differ with the knots even for the same energy).
//!
//! The plan has one line per strain axis `(sx, sa, sy, kx, ky)` ([`LINE_POINTS`] points, the
//! other axes 0) and one plane per pair of axes ([`PLANE_POINTS`]² points, the others 0), each
//! axis over the union of the two splines' knot ranges in real strain units (knots times
//! [`Spline::strain_scale`]). For each line or plane the [`Diff`] holds two fields:
//! - `<axes>.energy_density_j_m2`: the energy density `Ψ` (J/m²);
//! - `<axes>.stress`: the stress `dΨ/d(sx, sa, sy, kx, ky)` compared as 5-vectors: the
//!   difference of a point is the Euclidean norm of the component differences (mixed units:
//!   J/m² per unit strain for `sx, sa, sy`, J/m per unit curvature for `kx, ky`), and a point
//!   is outside tolerance if any component is.
//!
//! `<axes>` is the term's name as in grids (`sx`, `sx,kx`), and each field's
//! [`worst_at`](FieldDiff::worst_at) is the strain of its largest difference, e.g.
//! `sx=0.312 kx=-50`. The areal density and `f0` are compared as fields too; the
//! coefficient-level comparison of `yarnhom-artifacts` ([`diff_splines`]) and differing strain
//! scales or term sets are only notes: the evaluated fields decide equality.

use yarnhom_artifacts::Spline;
use yarnhom_artifacts::diff::{Diff, FieldDiff, FieldDiffBuilder, Tolerance, describe_strain, diff_splines};
use yarnhom_artifacts::grid::AXIS_NAMES;

use crate::material::SplineMaterial;

/// Points of each line of the evaluation plan.
pub const LINE_POINTS: usize = 201;

/// Points along each axis of each plane of the evaluation plan.
pub const PLANE_POINTS: usize = 41;

/// A line or plane of the evaluation plan.
#[derive(Debug, Clone, PartialEq)]
pub struct Section {
    /// The axes that vary (indices into [`AXIS_NAMES`]): one for a line, two for a plane.
    pub axes: Vec<usize>,
    /// The strains `(sx, sa, sy, kx, ky)` of its points (the other axes 0); a plane's are
    /// row-major with the second axis outer.
    pub strains: Vec<[f64; 5]>,
}

impl Section {
    /// The section's name: its axes' names joined by commas, e.g. `sx,kx`.
    pub fn name(&self) -> String {
        let names: Vec<&str> = self.axes.iter().map(|&a| AXIS_NAMES.get(a).copied().unwrap_or("?")).collect();
        names.join(",")
    }
}

/// The strain range `[lo, hi]` of `axis` (0 sx, 1 sa, 2 sy, 3 kx, 4 ky) that a spline's terms
/// have knots over, in real strain units; `None` when no term has that axis.
pub fn knot_range(spline: &Spline, axis: usize) -> Option<[f64; 2]> {
    let scale = *spline.strain_scale.get(axis)?;
    let terms_1d = spline.terms_1d.iter().filter(|t| t.axis as usize == axis).map(|t| &t.knots);
    let u = spline.terms_2d.iter().filter(|t| t.axes[0] as usize == axis).map(|t| &t.u_knots);
    let v = spline.terms_2d.iter().filter(|t| t.axes[1] as usize == axis).map(|t| &t.v_knots);
    let knots = terms_1d.chain(u).chain(v).flat_map(|k| k.iter().map(|x| x * scale));
    knots.fold(None, |range, x| Some(widen(range, [x, x])))
}

/// The smallest range holding `range` (if any) and `other`.
fn widen(range: Option<[f64; 2]>, other: [f64; 2]) -> [f64; 2] {
    match range {
        Some([lo, hi]) => [lo.min(other[0]), hi.max(other[1])],
        None => other,
    }
}

/// Per axis, the union of the two splines' knot ranges (`None` when neither has a term on it).
pub fn union_ranges(a: &Spline, b: &Spline) -> [Option<[f64; 2]>; 5] {
    std::array::from_fn(|axis| match (knot_range(a, axis), knot_range(b, axis)) {
        (Some(x), y) => Some(y.map_or(x, |y| widen(Some(x), y))),
        (None, y) => y,
    })
}

/// `n` evenly spaced values from `lo` to `hi`.
fn linspace([lo, hi]: [f64; 2], n: usize) -> Vec<f64> {
    let last = (n.max(2) - 1) as f64;
    (0..n).map(|k| lo + (hi - lo) * k as f64 / last).collect()
}

/// The evaluation plan over `ranges`: a line per axis with a range, then a plane per pair of
/// such axes (in the order `sx,sa`, `sx,sy`, ..., `kx,ky`).
pub fn evaluation_plan(ranges: &[Option<[f64; 2]>; 5]) -> Vec<Section> {
    let axes: Vec<(usize, [f64; 2])> =
        ranges.iter().enumerate().filter_map(|(a, r)| Some((a, (*r)?))).collect();
    let mut plan: Vec<Section> = axes.iter().map(|&(axis, range)| line(axis, range)).collect();
    for (k, &first) in axes.iter().enumerate() {
        for &second in &axes[k + 1..] {
            plan.push(plane(first, second));
        }
    }
    plan
}

/// The line of `axis` over `range`.
fn line(axis: usize, range: [f64; 2]) -> Section {
    let strains = linspace(range, LINE_POINTS)
        .into_iter()
        .map(|x| {
            let mut s = [0.0; 5];
            s[axis] = x;
            s
        })
        .collect();
    Section { axes: vec![axis], strains }
}

/// The plane of two `(axis, range)`s.
fn plane((u, u_range): (usize, [f64; 2]), (v, v_range): (usize, [f64; 2])) -> Section {
    let us = linspace(u_range, PLANE_POINTS);
    let mut strains = Vec::with_capacity(PLANE_POINTS * PLANE_POINTS);
    for y in linspace(v_range, PLANE_POINTS) {
        for &x in &us {
            let mut s = [0.0; 5];
            s[u] = x;
            s[v] = y;
            strains.push(s);
        }
    }
    Section { axes: vec![u, v], strains }
}

/// The energy density (J/m²) of `material` at the strain `(sx, sa, sy, kx, ky)` (as
/// [`SplineMaterial::energy_at`]: normal curvatures `kx`, `ky`, no twist) and its stress
/// `dΨ/d(sx, sa, sy, kx, ky)`: the gradient of [`SplineMaterial::jet`] in the fundamental forms
/// composed with the derivative of `I = ((1+sx)², sa (1+sx)(1+sy), (1+sy)²)`,
/// `II = (kx, 0, ky)` in the strain.
pub fn energy_and_stress(material: &SplineMaterial, strain: &[f64; 5]) -> (f64, [f64; 5]) {
    let [sx, sa, sy, kx, ky] = *strain;
    let (a, b) = (1.0 + sx, 1.0 + sy);
    let jet = material.jet([a * a, sa * a * b, b * b], [kx, 0.0, ky]);
    let g = jet.gradient;
    let stress = [g[0] * 2.0 * a + g[1] * sa * b, g[1] * a * b, g[1] * sa * a + g[2] * 2.0 * b, g[3], g[5]];
    (jet.value, stress)
}

/// The energy and stress fields of one section: both materials at each of its points.
fn section_fields(
    section: &Section,
    a: &SplineMaterial,
    b: &SplineMaterial,
    tol: Tolerance,
) -> [FieldDiff; 2] {
    let name = section.name();
    let mut energy = FieldDiffBuilder::new(format!("{name}.energy_density_j_m2"));
    let mut stress = FieldDiffBuilder::new(format!("{name}.stress"));
    for (index, strain) in section.strains.iter().enumerate() {
        let ((ea, sa), (eb, sb)) = (energy_and_stress(a, strain), energy_and_stress(b, strain));
        if energy.push(&[ea], &[eb], tol) {
            energy.locate_worst(index, describe_strain(strain, &section.axes));
        }
        if stress.push(&sa, &sb, tol) {
            stress.locate_worst(index, describe_strain(strain, &section.axes));
        }
    }
    [energy.finish(), stress.finish()]
}

/// A scalar parameter as a field.
fn scalar_field(field: &str, a: f64, b: f64, tol: Tolerance) -> FieldDiff {
    let mut builder = FieldDiffBuilder::new(field);
    builder.push(&[a], &[b], tol);
    builder.finish()
}

/// Compare two spline materials by evaluation (see the module documentation): the areal
/// density and `f0`, then the energy and stress on each line and plane of the plan over the
/// union of their knot ranges. Names, strain scales, term sets and coefficients are notes.
pub fn diff_spline_materials(a: &Spline, b: &Spline, tol: Tolerance) -> Diff {
    let mut d = Diff::new("spline");
    if a.name != b.name {
        d.notes.push(format!("names differ: '{}' vs '{}'", a.name, b.name));
    }
    d.fields.push(scalar_field("areal_density_kg_m2", a.areal_density_kg_m2, b.areal_density_kg_m2, tol));
    d.fields.push(scalar_field(
        "rest_energy_density_j_m2",
        a.rest_energy_density_j_m2,
        b.rest_energy_density_j_m2,
        tol,
    ));
    let ranges = union_ranges(a, b);
    let (ma, mb) = (SplineMaterial::from(a), SplineMaterial::from(b));
    for section in evaluation_plan(&ranges) {
        d.fields.extend(section_fields(&section, &ma, &mb, tol));
    }
    let unevaluated: Vec<&str> =
        ranges.iter().zip(AXIS_NAMES).filter(|(r, _)| r.is_none()).map(|(_, name)| name).collect();
    if !unevaluated.is_empty() {
        d.notes.push(format!("no term of either material on {}: not evaluated", unevaluated.join(", ")));
    }
    d.notes.extend(coefficient_notes(a, b, tol));
    d
}

/// The coefficient-level comparison as notes: differing strain scales, terms in one material
/// only or with other knots, and the coefficient arrays outside tolerance.
fn coefficient_notes(a: &Spline, b: &Spline, tol: Tolerance) -> Vec<String> {
    let coefficients = diff_splines(a, b, tol);
    let mut notes: Vec<String> =
        coefficients.structural.iter().map(|s| format!("coefficients: {s}")).collect();
    let outside: Vec<&str> = coefficients
        .fields
        .iter()
        .filter(|f| {
            f.outside > 0 && !matches!(f.field.as_str(), "areal_density_kg_m2" | "rest_energy_density_j_m2")
        })
        .map(|f| f.field.as_str())
        .collect();
    if !outside.is_empty() {
        notes.push(format!("coefficients outside tolerance: {}", outside.join(", ")));
    }
    notes
}

#[cfg(test)]
mod tests {
    use std::collections::BTreeSet;

    use super::*;

    fn published(name: &str) -> Spline {
        let path = format!("{}/../../../shared/data/hylc-materials/{name}.json", env!("CARGO_MANIFEST_DIR"));
        yarnhom_artifacts::open::open_artifact::<yarnhom_artifacts::Spline>(&path)
            .map(|o| o.value)
            .expect("published material")
    }

    const EXACT: Tolerance = Tolerance { rtol: 0.0, atol: 0.0 };
    /// Beyond rounding: a curvature section's stress in the other bending axis is a sum over
    /// both principal curvatures that cancels to rounding level (about 1e-18), not to 0.
    const TIGHT: Tolerance = Tolerance { rtol: 1e-9, atol: 1e-12 };

    /// The fields outside tolerance.
    fn outside(d: &Diff) -> BTreeSet<String> {
        d.fields.iter().filter(|f| f.outside > 0).map(|f| f.field.clone()).collect()
    }

    /// Whether a field's section (the part before the first '.') has `axis` among its axes.
    fn involves(field: &str, axis: &str) -> bool {
        field.split('.').next().is_some_and(|section| section.split(',').any(|a| a == axis))
    }

    #[test]
    fn a_material_equals_itself_exactly() {
        let stock = published("stock1");
        let d = diff_spline_materials(&stock, &stock, EXACT);
        assert!(d.equal(), "{}", d.report());
        // 2 scalars, then energy and stress on 5 lines and 10 planes.
        assert_eq!(d.fields.len(), 2 + 2 * 15, "{}", d.report());
        let line = d.fields.iter().find(|f| f.field == "sx.energy_density_j_m2").expect("sx line");
        assert_eq!(line.count, LINE_POINTS);
        let plane = d.fields.iter().find(|f| f.field == "sx,kx.stress").expect("sx,kx plane");
        assert_eq!(plane.count, PLANE_POINTS * PLANE_POINTS);
    }

    #[test]
    fn different_published_materials_differ_and_say_where() {
        let (stock, honey) = (published("stock1"), published("honey1"));
        let d = diff_spline_materials(&stock, &honey, TIGHT);
        assert!(!d.equal());
        let worst = d
            .fields
            .iter()
            .filter(|f| f.field.ends_with("energy_density_j_m2") && f.count > 1)
            .max_by(|x, y| x.max_abs.total_cmp(&y.max_abs))
            .expect("energy fields");
        assert!(worst.outside > 0 && worst.max_abs > 0.0, "{}", d.report());
        let at = worst.worst_at.as_deref().expect("the worst strain is reported");
        // The strain names the section's axes with values, e.g. `sx=0.312 kx=-50`.
        let section = worst.field.split('.').next().expect("section");
        for axis in section.split(',') {
            assert!(at.contains(&format!("{axis}=")), "{at} for {}", worst.field);
        }
        assert!(d.report().contains(&format!("worst at {at}")), "{}", d.report());
        // The strain reported is where the largest difference is.
        let strain = worst_strain(&stock, &honey, worst);
        assert_eq!(describe_strain(&strain, &section_axes(section)), at);
        let (ma, mb) = (SplineMaterial::from(&stock), SplineMaterial::from(&honey));
        let (ea, eb) = (energy_and_stress(&ma, &strain).0, energy_and_stress(&mb, &strain).0);
        assert_eq!((ea - eb).abs(), worst.max_abs, "{at}");
    }

    /// The axes of a section named e.g. `sx,kx`.
    fn section_axes(section: &str) -> Vec<usize> {
        let axis = |name: &str| AXIS_NAMES.iter().position(|&a| a == name).expect("axis name");
        section.split(',').map(axis).collect()
    }

    /// The strain of the plan point where `field` has its largest difference.
    fn worst_strain(a: &Spline, b: &Spline, field: &FieldDiff) -> [f64; 5] {
        let name = field.field.split('.').next().expect("section");
        let plan = evaluation_plan(&union_ranges(a, b));
        let section = plan.iter().find(|s| s.name() == name).expect("section in the plan");
        section.strains[field.worst_index]
    }

    #[test]
    fn an_edited_1d_coefficient_changes_only_the_sections_of_its_axis() {
        let stock = published("stock1");
        let mut edited = stock.clone();
        let term = edited.terms_1d.iter_mut().find(|t| t.axis == 3).expect("kx term");
        // The last knot's value: the term away from 0, so at kx = 0 nothing changes.
        let last = term.values.len() - 1;
        term.values[last] += 0.1 * term.values[last].abs() + 1e-3;
        let d = diff_spline_materials(&stock, &edited, TIGHT);
        let changed = outside(&d);
        assert!(changed.contains("kx.energy_density_j_m2") && changed.contains("kx.stress"), "{changed:?}");
        assert!(changed.contains("sx,kx.energy_density_j_m2"), "{changed:?}");
        for field in &changed {
            assert!(involves(field, "kx"), "{field} changed by an edit of f_kx: {changed:?}");
        }
        for axis in ["sx", "sa", "sy", "ky"] {
            assert!(!changed.iter().any(|f| f.split('.').next() == Some(axis)), "{axis}: {changed:?}");
        }
        assert!(d.notes.iter().any(|n| n.contains("f_kx.values")), "{:?}", d.notes);
    }

    #[test]
    fn an_edited_2d_coefficient_changes_only_its_plane() {
        let stock = published("stock1");
        let mut edited = stock.clone();
        let term = edited.terms_2d.iter_mut().find(|t| t.axes == [0, 3]).expect("sx,kx term");
        // A node off both axes, so that the lines (and other planes) keep their values.
        let i = term.u_knots.iter().rposition(|&u| u != 0.0).expect("u knot");
        let j = term.v_knots.iter().rposition(|&v| v != 0.0).expect("v knot");
        let node = j * term.u_knots.len() + i;
        term.values[node] += 0.1 * term.values[node].abs() + 1e-3;
        let d = diff_spline_materials(&stock, &edited, TIGHT);
        let expected: BTreeSet<String> =
            ["sx,kx.energy_density_j_m2", "sx,kx.stress"].iter().map(|s| s.to_string()).collect();
        assert_eq!(outside(&d), expected, "{}", d.report());
    }

    /// Central difference of `f` along each strain axis (steps suited to strains and
    /// curvatures).
    fn finite_difference(f: impl Fn(&[f64; 5]) -> f64, strain: &[f64; 5]) -> [f64; 5] {
        std::array::from_fn(|k| {
            let h = if k < 3 { 1e-6 } else { 1e-4 };
            let (mut p, mut m) = (*strain, *strain);
            p[k] += h;
            m[k] -= h;
            (f(&p) - f(&m)) / (2.0 * h)
        })
    }

    #[test]
    fn stress_differences_are_derivatives_of_the_energy_difference() {
        let (stock, honey) = (published("stock1"), published("honey1"));
        let (ma, mb) = (SplineMaterial::from(&stock), SplineMaterial::from(&honey));
        // The energy difference through `energy_at`, independent of `energy_and_stress`.
        let energy_difference = |s: &[f64; 5]| {
            let strain = yarnhom_artifacts::grid::strain_from_values(*s);
            ma.energy_at(&strain) - mb.energy_at(&strain)
        };
        let stress_difference = |s: &[f64; 5]| {
            let (sa, sb) = (energy_and_stress(&ma, s).1, energy_and_stress(&mb, s).1);
            std::array::from_fn::<f64, 5, _>(|k| sa[k] - sb[k])
        };
        for strain in [
            [0.1, 0.05, -0.03, 20.0, -7.0],
            [-0.05, -0.1, 0.2, -15.0, 3.0],
            [0.3, 0.0, 0.0, 40.0, 0.0],
            [0.0, 0.2, 0.1, 0.0, -30.0],
        ] {
            let (exact, fd) = (stress_difference(&strain), finite_difference(energy_difference, &strain));
            for k in 0..5 {
                assert!(
                    (exact[k] - fd[k]).abs() <= 1e-5 * (1.0 + fd[k].abs()),
                    "{strain:?}: d(ΔΨ)/d{} {} vs {}",
                    AXIS_NAMES[k],
                    exact[k],
                    fd[k]
                );
            }
        }
        // The reported largest stress difference of a line is that of the finite differences.
        let d = diff_spline_materials(&stock, &honey, TIGHT);
        let field = d.fields.iter().find(|f| f.field == "sy.stress").expect("sy line");
        let strain = worst_strain(&stock, &honey, field);
        let fd = finite_difference(energy_difference, &strain);
        let norm = fd.iter().map(|x| x * x).sum::<f64>().sqrt();
        assert!((norm - field.max_abs).abs() <= 1e-4 * (1.0 + norm), "{norm} vs {}", field.max_abs);
    }
}
