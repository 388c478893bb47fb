//! The per-element kernels of the thin-shell simulator, one interior triangle of a curved,
//! stretched and sheared cloth with the published honeycomb material (`honey1.json`):
//! - the discrete forms (4.4)-(4.7) with their gradient and Hessian over the 18 stencil DOFs,
//!   and with their gradient only (what a gradient or a handle force needs),
//! - the whole element: forms, the spline material's derivatives and the A.5 composition, with
//!   and without the element Hessian, and with the Gauss-Newton bending matrix instead,
//! - the eigenvalue clamp of its 18 x 18 Hessian (Sec. 4.2),
//! - the edge-hinge bending energy (6.4) with derivatives.
//!
//! Compared with: no published per-element figure; these are the parts of the per-step time
//! that stands beside Table 4.2 (`benches/shell.rs`).

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::{Vector2, Vector3};
use yarnhom_fit::SplineMaterial;
use yarnhom_shell::elastic::split_hessian_18;
use yarnhom_shell::forms::{RestTriangle, Stencil, forms_with_derivatives, forms_with_gradient};
use yarnhom_shell::hinge::{HingeRest, hinge_energy_with_derivatives};
use yarnhom_shell::{ElasticModel, ShellMaterial, ShellMesh};

/// A smooth deformation: stretched, sheared, doubly curved.
fn deform(m: &Vector2<f64>) -> Vector3<f64> {
    Vector3::new(1.1 * m.x + 0.05 * m.y, 0.95 * m.y, 15.0 * m.x * m.x - 10.0 * m.y * m.y + 5.0 * m.x * m.y)
}

fn bench_kernels(c: &mut Criterion) {
    let path = format!("{}/../../shared/data/hylc-materials/honey1.json", env!("CARGO_MANIFEST_DIR"));
    let spline = yarnhom_artifacts::open::open_artifact::<yarnhom_artifacts::Spline>(&path)
        .map(|o| o.value)
        .expect("published material");
    let mesh = ShellMesh::rectangle(0.02, 0.02, 5, 5).expect("mesh");
    let x: Vec<Vector3<f64>> = mesh.material.iter().map(deform).collect();
    let t = (0..mesh.triangles.len())
        .find(|&t| mesh.neighbours[t].iter().all(Option::is_some))
        .expect("interior");
    let rest = RestTriangle::new(&mesh.triangles[t].map(|v| mesh.material[v as usize]));
    let stencil = Stencil {
        triangle: mesh.triangles[t].map(|v| x[v as usize]),
        neighbours: mesh.neighbours[t].map(|n| n.map(|v| x[v as usize])),
    };
    let model = ElasticModel::new(mesh.clone(), ShellMaterial::spline(SplineMaterial::from(&spline)));
    let (_, _, hessian) = model.triangle_element_exact(t, &x, true);
    let hessian = hessian.expect("asked for");
    let hinge = mesh.hinges[0].vertices;
    let hinge_rest = HingeRest::new(&hinge.map(|v| mesh.material[v as usize]), 1e-5, 0.0);
    let hinge_x = hinge.map(|v| x[v as usize]);

    let mut g = c.benchmark_group("shell kernels");
    g.bench_function("forms (4.4)-(4.7) with gradient and Hessian, 18 DOFs", |b| {
        b.iter(|| forms_with_derivatives(&rest, std::hint::black_box(&stencil)))
    });
    g.bench_function("forms (4.4)-(4.7) with gradient only, 18 DOFs", |b| {
        b.iter(|| forms_with_gradient(&rest, std::hint::black_box(&stencil)))
    });
    g.bench_function("spline element: forms, material jet, A.5 composition", |b| {
        b.iter(|| model.triangle_element_exact(t, std::hint::black_box(&x), true))
    });
    g.bench_function("spline element, Gauss-Newton matrix (no forms' Hessians, PSD by construction)", |b| {
        b.iter(|| model.triangle_element_gauss_newton(t, std::hint::black_box(&x)))
    });
    let material = SplineMaterial::from(&spline);
    let (first, second) = model.triangle_forms(t, &x);
    g.bench_function("spline material jet: energy density with gradient and Hessian in the forms", |b| {
        b.iter(|| material.jet(std::hint::black_box(first), second))
    });
    g.bench_function("spline material energy density alone (line searches)", |b| {
        b.iter(|| material.energy_density(std::hint::black_box(first), second))
    });
    g.bench_function("spline element, energy and gradient only", |b| {
        b.iter(|| model.triangle_element_exact(t, std::hint::black_box(&x), false))
    });
    g.bench_function("eigenvalue clamp of an indefinite 18x18 element Hessian", |b| {
        b.iter(|| split_hessian_18(std::hint::black_box(hessian)).clamped())
    });
    g.bench_function("edge-hinge bending (6.4) with gradient and Hessian", |b| {
        b.iter(|| hinge_energy_with_derivatives(&hinge_rest, std::hint::black_box(&hinge_x)))
    });
    g.finish();
}

criterion_group!(benches, bench_kernels);
criterion_main!(benches);
