//! Physics of the published patterns with their Table 4.1 parameters (issue 3, "Validation").
//! About 20 s in all (the rib tile's solves take 3 s each).

use yarnhom_artifacts::{Pattern, YarnModel, pyp::parse_pyp};
use yarnhom_fit::SplineMaterial;
use yarnhom_geom::MacroStrain;
use yarnhom_pattern::{MirrorAxis, find_mirror, mirrored};
use yarnhom_rve::assembly::RveState;
use yarnhom_rve::homogenize::{placement, solve_at};
use yarnhom_rve::{RveModel, SolveOptions};

/// The published tile `name` with its own Table 4.1 row.
fn tile(name: &str) -> RveModel {
    tile_with(name, &YarnModel::table_4_1(name).expect("Table 4.1 row"))
}

/// The published tile `name` with the yarn `yarn`.
fn tile_with(name: &str, yarn: &YarnModel) -> RveModel {
    RveModel::new(&published_pattern(name), yarn).expect("tile")
}

/// The published pattern `name`.
fn published_pattern(name: &str) -> Pattern {
    let path = format!("{}/../../../shared/data/hylc-patterns/{name}.pyp", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    parse_pyp(&text, name, None).expect("published pattern")
}

fn psi(model: &RveModel, strain: &str) -> f64 {
    let s: MacroStrain = strain.parse().expect("strain");
    let (report, _) = solve_at(model, &s, None, &SolveOptions::default());
    assert!(report.converged, "{strain}: {report:?}");
    println!("  psi({strain}) = {:.5e} J/m² ({} iterations)", report.energy_density_j_m2, report.iterations);
    report.energy_density_j_m2
}

#[test]
fn rib_is_strongly_anisotropic() {
    let rib = tile("rib");
    let (x, y) = (psi(&rib, "sx=0.3"), psi(&rib, "sy=0.3"));
    assert!(x < 0.25 * y, "rib: psi(sx=0.3) = {x}, psi(sy=0.3) = {y}");
}

#[test]
fn honeycomb_contracts_sideways_when_stretched() {
    // Poisson effect: at sx = 0.3 the energy-minimizing sy is negative.
    let honey = tile("honey");
    let (minus, zero, plus) =
        (psi(&honey, "sx=0.3,sy=-0.05"), psi(&honey, "sx=0.3"), psi(&honey, "sx=0.3,sy=0.05"));
    assert!(minus < zero && zero < plus, "honey at sx=0.3: sy=-0.05 {minus}, 0 {zero}, +0.05 {plus}");
}

/// Energy added by stretching 30% along X1 and along X2 (J/m²).
fn stretch_energies(model: &RveModel) -> [f64; 2] {
    let rest = psi(model, "sx=0");
    [psi(model, "sx=0.3") - rest, psi(model, "sy=0.3") - rest]
}

#[test]
fn wovens_are_stiffer_in_stretch_than_knits_of_the_same_yarn() {
    // Issue 3: "woven basket/satin are stiffer in stretch than the knits". Knitted loops
    // straighten before their yarn stretches; woven yarns are nearly straight from the start.
    // Table 4.1 gives the knits (stock, rib, honey) one yarn (E = 0.5 MPa) and the wovens one
    // five times softer (E = 0.1 MPa), so the claim is about the same yarn: every pattern with
    // the stockinette's row. (With their own rows the stockinette stores more than either woven
    // at 30%, and so do the published fits: stock1.json 2.26 J/m² along X1 against basket1.json
    // 1.17 and satin1.json 1.62; rib and honeycomb store less than either woven both ways.)
    let yarn = YarnModel::table_4_1("stock").expect("Table 4.1 row");
    let stretch = |name: &str| {
        let energies = stretch_energies(&tile_with(name, &yarn));
        println!("{name} with the stockinette's yarn: sx {:.4}, sy {:.4} J/m²", energies[0], energies[1]);
        energies
    };
    let knits = [stretch("stock"), stretch("rib"), stretch("honey")];
    for woven in ["basket", "satin"] {
        let w = stretch(woven);
        for k in &knits {
            assert!(w[0] > k[0] && w[1] > k[1], "{woven} {w:?} vs a knit {k:?}");
        }
    }
    let published = |name: &str, k: usize| published_term(name, k, 0.3) - published_term(name, k, 0.0);
    for (woven, knit, k) in ["basket", "satin"]
        .into_iter()
        .flat_map(|w| ["rib", "honey"].into_iter().flat_map(move |n| [(w, n, 0), (w, n, 2)]))
    {
        assert!(published(woven, k) > published(knit, k), "published {woven} vs {knit}, term {k}");
    }
    assert!(published("stock", 0) > published("satin", 0), "the published stockinette is the stiffest fit");
}

/// The published HYLC fit's 1D term `k` (0 = sx) at strain `x`.
fn published_term(name: &str, k: usize, x: f64) -> f64 {
    let path = format!("{}/../../../shared/data/hylc-materials/{name}1.json", env!("CARGO_MANIFEST_DIR"));
    let fit = SplineMaterial::from(
        &yarnhom_artifacts::open::open_artifact::<yarnhom_artifacts::Spline>(&path)
            .map(|o| o.value)
            .expect("published fit imports"),
    );
    fit.term_1d(k, x).expect("the fit has the term")
}

#[test]
fn stretch_response_matches_the_published_fits() {
    // Energy added by stretching 30% along X1 and along X2, ours (solve at 0.3 minus 0)
    // against the published fit's 1D sx and sy terms: each within the 25% of issue 3, and the
    // same ranking across patterns along X1. (Measured: stock +0.0% / +1.3%, satin +0.5% /
    // +0.5%, basket -19.2% / -17.8%, honey +1.8% / +3.7%, rib -5.3% / -3.2%; over 0.05..0.3,
    // `examples/compare_published_fits.rs`.)
    let names = ["stock", "satin", "basket", "honey", "rib"];
    let mut along_x1 = Vec::new();
    for name in names {
        let t = tile(name);
        let rest = psi(&t, "sx=0");
        for (k, axis) in [(0, "sx"), (2, "sy")] {
            let added = psi(&t, &format!("{axis}=0.3")) - rest;
            let published = published_term(name, k, 0.3) - published_term(name, k, 0.0);
            println!(
                "{name} {axis}: ours {added:.4}, published {published:.4} J/m², {:+.1}%",
                100.0 * (added / published - 1.0)
            );
            assert!(
                (added / published - 1.0).abs() < 0.25,
                "{name} {axis}: ours {added}, published {published}"
            );
            if k == 0 {
                along_x1.push((added, published));
            }
        }
    }
    for w in along_x1.windows(2) {
        assert!(w[0].0 > w[1].0 && w[0].1 > w[1].1, "ranking differs: {along_x1:?}");
    }
}

#[test]
fn a_tile_bent_round_onto_itself_has_no_contact_wall() {
    // The published stockinette (period 15.1 mm along X1, contact images two periods out) bent
    // past kx = 2π/(3 P_1) = 139 1/m brings an image round onto the tile itself; that is the
    // same fabric again, not a second layer, so the energy must continue smoothly (before the
    // material-proximity rule of `RveModel::can_touch` it jumped from 1.26 to 7.6 J/m² between
    // kx = 130 and 140, the yarns 0.32 radii apart).
    let stock = tile("stock");
    let mut state = None;
    let mut energies = Vec::new();
    for kx in [120.0, 130.0, 140.0, 150.0, 160.0] {
        let strain: MacroStrain = format!("kx={kx}").parse().expect("strain");
        let options = if state.is_some() { SolveOptions::warm_started() } else { SolveOptions::default() };
        let (report, solved) = solve_at(&stock, &strain, state.as_ref(), &options);
        assert!(report.converged, "kx = {kx}: {report:?}");
        let separation = yarnhom_rve::assembly::min_separation(&stock, &placement(&stock, &strain), &solved)
            .expect("yarns in contact");
        println!(
            "  kx = {kx}: psi {:.4} J/m², yarns {:.3} radii apart",
            report.energy_density_j_m2,
            separation / stock.radius_m
        );
        assert!(separation > 1.5 * stock.radius_m, "kx = {kx}: yarns {separation} m apart");
        energies.push(report.energy_density_j_m2);
        state = Some(solved);
    }
    let steps: Vec<f64> = energies.windows(2).map(|w| w[1] - w[0]).collect();
    for pair in steps.windows(2) {
        assert!(pair[1] > 0.0 && pair[1] < 1.5 * pair[0], "energy steps {steps:?}");
    }
}

#[test]
fn the_published_rest_states_balance_the_normalized_kaldor_contact() {
    // The published patterns are rest states of the thesis' code at their Table 4.1 rows. In
    // this model their stretching, bending and contact forces should cancel; pooled over the
    // four whose yarns touch, the best contact scale is within 10% of 1 (the normalization
    // `KALDOR_TABLE_4_1_NORMALIZATION` is that estimate), and the normalization takes the
    // stock, rib and honeycomb residuals below half of what Table 4.1's stiffness as our
    // integral's leaves (measured: 0.095 / 0.24 / 0.12 of the stretching force against
    // 0.67 / 0.74 / 0.82).
    use yarnhom_rod::contact::KALDOR_TABLE_4_1_NORMALIZATION as NORMALIZATION;
    use yarnhom_rve::residual::{equilibrium_residual, pooled_contact_scale};
    let residuals: Vec<_> = ["stock", "rib", "honey", "satin"]
        .into_iter()
        .map(|name| {
            let path =
                format!("{}/../../../shared/data/hylc-patterns/{name}.pyp", env!("CARGO_MANIFEST_DIR"));
            let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
            let pattern = parse_pyp(&text, name, None).expect("published pattern");
            let residual =
                equilibrium_residual(&pattern, &YarnModel::table_4_1(name).expect("row")).expect("tile");
            let (ours, printed) = (residual.relative_at(1.0), residual.relative_at(1.0 / NORMALIZATION));
            println!("{name}: {residual:?}; relative residual {ours:.3}, unnormalized {printed:.3}");
            if name != "satin" {
                assert!(ours < 0.5 * printed, "{name}: {ours} against {printed}");
            }
            residual
        })
        .collect();
    let pooled = pooled_contact_scale(&residuals).expect("the yarns touch");
    println!("pooled contact scale {pooled:.3}");
    assert!((pooled - 1.0).abs() < 0.1, "pooled contact scale {pooled}");
}

/// Energies added over the unstrained tile by shearing `model` from 0 to `sign · 0.01 · steps` in
/// steps of 0.01, each solve warm-started from the one before as the sampler walks a line, and
/// the equilibrium at the last step.
fn shear_sweep(model: &RveModel, sign: f64, steps: usize) -> (Vec<f64>, RveState) {
    let zero: MacroStrain = "sx=0".parse().expect("strain");
    let (rest, mut state) = solve_at(model, &zero, None, &SolveOptions::default());
    let energies = (1..=steps)
        .map(|i| {
            let strain = MacroStrain::new(0.0, sign * 0.01 * i as f64, 0.0, 0.0, 0.0).expect("strain");
            let (report, solved) = solve_at(model, &strain, Some(&state), &SolveOptions::warm_started());
            assert!(report.converged, "{strain:?}: {report:?}");
            state = solved;
            report.energy_density_j_m2 - rest.energy_density_j_m2
        })
        .collect();
    (energies, state)
}

#[test]
fn the_published_stockinette_rests_unsheared_and_shears_nearly_symmetrically() {
    // Issue 3: "shear response is symmetric in sa for the published stock pattern". What the
    // thesis observed of its own yarn-level runs is "symmetric rest shapes with zero shear", and
    // it still symmetrized its sampled data in sa (Sec. 4.3.1, App. A.3.2): the published tile is
    // the mirror image of itself as curves (about its X1 axis, which turns sa into -sa) only to 0.10 yarn
    // radii RMS, 0.16 at most, and its contacts are grazing (centrelines 1.9-2 radii apart), so
    // they close at different |sa| on the two sides. Measured: the rest is the shear minimum
    // (Ψ(0.01) - Ψ(0) = 6.8e-5, Ψ(-0.01) - Ψ(0) = 1.1e-5 J/m²); the two sides differ by 6.3% RMS
    // over 0.01..0.25, most (51%) at |sa| = 0.1, between the two sides' snaps at +0.045 and
    // -0.115, and by 0.9% and 1.1% at |sa| = 0.2 and 0.25.
    let stock = tile("stock");
    let (plus, minus) = (shear_sweep(&stock, 1.0, 25).0, shear_sweep(&stock, -1.0, 25).0);
    assert!(
        plus[0] > 0.0 && minus[0] > 0.0,
        "the unsheared tile is the shear minimum: {} {}",
        plus[0],
        minus[0]
    );
    let (difference2, mean2) = plus
        .iter()
        .zip(&minus)
        .fold((0.0, 0.0), |(d, m), (p, n)| (d + (p - n).powi(2), m + (0.5 * (p + n)).powi(2)));
    let rms = (difference2 / mean2).sqrt();
    println!("shear sides: {:.1}% RMS; at ±0.1 {:.2e} vs {:.2e} J/m²", 100.0 * rms, plus[9], minus[9]);
    assert!(rms < 0.1, "the two shear sides differ by {:.1}% RMS", 100.0 * rms);
    for i in [19, 24] {
        let relative = (plus[i] / minus[i] - 1.0).abs();
        assert!(relative < 0.02, "sa = ±{:.2}: {} vs {}", 0.01 * (i + 1) as f64, plus[i], minus[i]);
    }
}

#[test]
fn the_stockinettes_shear_asymmetry_is_its_tiles_and_not_the_sweeps() {
    // Is the gap between Ψ(0.1) and Ψ(-0.1) of the published stockinette (previous test) a
    // lower state the sweep to -0.1 missed? The tile's mirror image Q (`X2 -> -X2`, same
    // vertices and yarns, 0.10 radii from the tile as curves) holds at -0.1 exactly the tile's
    // equilibrium at +0.1, mirrored. Started from those positions (the tile's own twists and
    // rest shape), the tile at -0.1 does not keep that low energy: it relaxes back to its own
    // -0.1 branch. Measured: Ψ - Ψ(0) is 2.68e-3 J/m² for Q, 4.05e-3 swept and 4.11e-3 from Q's
    // positions (the same contact state; at every |sa| from 0.005 to 0.15 the start from Q's
    // positions ends on the swept branch or another, never as low as Q's where the two sides
    // differ). So the asymmetry is the tile's.
    let pattern = published_pattern("stock");
    let yarn = YarnModel::table_4_1("stock").expect("Table 4.1 row");
    let image = mirrored(&pattern, &find_mirror(&pattern, MirrorAxis::X2).expect("a mirror")).expect("image");
    let (tile, image_tile) =
        (RveModel::new(&pattern, &yarn).expect("tile"), RveModel::new(&image, &yarn).expect("image"));
    let (swept, _) = shear_sweep(&tile, -1.0, 10);
    let (mirror_of_plus, image_state) = shear_sweep(&image_tile, -1.0, 10);
    let strain = MacroStrain::new(0.0, -0.1, 0.0, 0.0, 0.0).expect("strain");
    let (rest, _) = solve_at(&tile, &"sx=0".parse().expect("strain"), None, &SolveOptions::default());
    let start = with_positions_of(&tile, &strain, &image_state);
    let (report, _) = solve_at(&tile, &strain, Some(&start), &SolveOptions::warm_started());
    assert!(report.converged, "{report:?}");
    let from_image = report.energy_density_j_m2 - rest.energy_density_j_m2;
    let (swept, mirror_of_plus) = (swept[9], mirror_of_plus[9]);
    println!(
        "sa = -0.1: swept {swept:.3e}, image {mirror_of_plus:.3e}, from the image {from_image:.3e} J/m²"
    );
    assert!(swept > 1.4 * mirror_of_plus, "the two sides differ: {swept} vs {mirror_of_plus}");
    assert!(
        (from_image / swept - 1.0).abs() < 0.05,
        "from the image's positions the tile returns to its branch: {from_image} vs {swept}"
    );
}

/// The tile's affine start at `strain` (its own twists and frames) with the fluctuations of
/// `other`'s vertices: `other` a state of a tile with the same vertices and yarns.
fn with_positions_of(model: &RveModel, strain: &MacroStrain, other: &RveState) -> RveState {
    let placement = placement(model, strain);
    let mut state = RveState::affine(model, &placement);
    for v in 0..model.material.len() as u32 {
        let d = model.position_dof(v);
        state.g.rows_mut(d, 3).copy_from(&other.g.rows(d, 3));
    }
    state.update_frames(model, &placement);
    state
}
