//! Physics of the published patterns with their Table 4.1 parameters (issue 3, "Validation").
//! Heavy (rib alone takes about 16 s per solve): run with
//! `cargo test --release -p yarnhom-rve --test physics -- --ignored`.

use yarnhom_artifacts::{YarnModel, pyp::parse_pyp};
use yarnhom_geom::MacroStrain;
use yarnhom_rve::homogenize::solve_at;
use yarnhom_rve::{RveModel, SolveOptions};

fn tile(name: &str) -> RveModel {
    let path = format!("{}/../../../shared/data/hylc-patterns/{name}.pyp", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let pattern = parse_pyp(&text, name, None).expect("published pattern");
    RveModel::new(&pattern, &YarnModel::table_4_1(name).expect("Table 4.1 row")).expect("tile")
}

fn psi(model: &RveModel, strain: &str) -> f64 {
    let s: MacroStrain = strain.parse().expect("strain");
    let (report, _) = solve_at(model, &s, None, &SolveOptions::default());
    assert!(report.converged, "{strain}: {report:?}");
    println!("  psi({strain}) = {:.5e} J/m² ({} iterations)", report.energy_density_j_m2, report.iterations);
    report.energy_density_j_m2
}

#[test]
#[ignore = "heavy: about a minute in release"]
fn rib_is_strongly_anisotropic() {
    let rib = tile("rib");
    let (x, y) = (psi(&rib, "sx=0.3"), psi(&rib, "sy=0.3"));
    assert!(x < 0.25 * y, "rib: psi(sx=0.3) = {x}, psi(sy=0.3) = {y}");
}

#[test]
#[ignore = "heavy"]
fn honeycomb_contracts_sideways_when_stretched() {
    // Poisson effect: at sx = 0.3 the energy-minimizing sy is negative.
    let honey = tile("honey");
    let (minus, zero, plus) =
        (psi(&honey, "sx=0.3,sy=-0.05"), psi(&honey, "sx=0.3"), psi(&honey, "sx=0.3,sy=0.05"));
    assert!(minus < zero && zero < plus, "honey at sx=0.3: sy=-0.05 {minus}, 0 {zero}, +0.05 {plus}");
}

#[test]
#[ignore = "heavy"]
fn woven_fabrics_are_stiffer_in_stretch_than_knits() {
    let knits: Vec<f64> =
        ["stock", "honey"].iter().map(|n| psi(&tile(n), "sx=0.1") - psi(&tile(n), "sx=0")).collect();
    let wovens: Vec<f64> =
        ["basket", "satin"].iter().map(|n| psi(&tile(n), "sx=0.1") - psi(&tile(n), "sx=0")).collect();
    let softest_woven = wovens.iter().cloned().fold(f64::INFINITY, f64::min);
    let stiffest_knit = knits.iter().cloned().fold(0.0, f64::max);
    assert!(softest_woven > stiffest_knit, "stretch energy at sx=0.1: knits {knits:?}, wovens {wovens:?}");
}
