//! Acceptance tests of the fit (thesis Sec. 4.1, App. A.3) on synthetic grids sampled from a
//! known, cloth-like energy with the thesis' plan shape: five 1D terms and the nine 2D terms of
//! Alg. 3, non-uniform sampling as in Alg. 6 / Fig. A.2 (dense towards compression for `sx`,
//! `sy`, dense around 0 for `sa`, `kx`, `ky`).

use yarnhom_artifacts::grid::{AXIS_NAMES, strain_from_values, strain_values};
use yarnhom_artifacts::{FitSettings, Grid, Spline, StrainSample};
use yarnhom_fit::mls::{symexp, symlog};
use yarnhom_fit::shape::unimodality_violation;
use yarnhom_fit::synthetic::{F0, KX_MIN, LOWER, UPPER, linspace, synthetic_grid};
use yarnhom_fit::{
    FitError, SplineMaterial, fit_errors, fit_grid, fit_grid_with_regularized_terms, regularized_term_shapes,
    term_shapes,
};

fn fit(grid: &Grid) -> (Spline, SplineMaterial) {
    let spline = fit_grid(grid, &FitSettings::default(), 0.3).expect("the synthetic grid fits");
    spline.validate().expect("the fitted spline is valid");
    let material = SplineMaterial::from(&spline);
    (spline, material)
}

fn strain_along(axes: &[u8], values: &[f64]) -> StrainSample {
    let mut v = [0.0; 5];
    for (&a, &x) in axes.iter().zip(values) {
        v[a as usize] = x;
    }
    strain_from_values(v)
}

/// Number of strict local minima of `ys`, a run of equal values counting as one point.
fn strict_local_minima(ys: &[f64]) -> usize {
    let mut runs: Vec<f64> = Vec::new();
    for &y in ys {
        if runs.last() != Some(&y) {
            runs.push(y);
        }
    }
    let n = runs.len();
    (0..n)
        .filter(|&i| (i == 0 || runs[i - 1] > runs[i]) && (i + 1 == n || runs[i + 1] > runs[i]) && n > 1)
        .filter(|&i| i != 0 && i + 1 != n)
        .count()
}

/// The knots of a 1D term in strain units.
fn knots_1d(spline: &Spline, axis: u8) -> Vec<f64> {
    let term = spline.terms_1d.iter().find(|t| t.axis == axis).expect("a 1D term per axis");
    term.knots.iter().map(|k| k * spline.strain_scale[axis as usize]).collect()
}

/// The widest knot spacing next to `x` (in strain units).
fn knot_spacing_near(knots: &[f64], x: f64) -> f64 {
    let k = (0..knots.len())
        .min_by(|&a, &b| (knots[a] - x).abs().total_cmp(&(knots[b] - x).abs()))
        .expect("knots");
    let left = k.checked_sub(1).map_or(0.0, |l| knots[k] - knots[l]);
    let right = knots.get(k + 1).map_or(0.0, |r| r - knots[k]);
    left.max(right)
}

/// Each fitted 1D term must have exactly one local minimum over 1.5 times its sampled range, at
/// 0 for in-plane and `ky` terms and near [`KX_MIN`] for `kx` (within a knot spacing); returns
/// the violations.
fn single_minimum_failures(grid: &Grid, spline: &Spline) -> Vec<String> {
    let material = SplineMaterial::from(spline);
    let mut failures = Vec::new();
    for term in grid.terms.iter().filter(|t| t.axes.len() == 1) {
        let axis = term.axes[0];
        let (lo, hi) = (term.values[0][0], term.values[0][term.values[0].len() - 1]);
        let xs = linspace(1.5 * lo, 1.5 * hi, 6001);
        let ys: Vec<f64> = xs.iter().map(|&x| material.term_1d(axis as usize, x).expect("1D term")).collect();
        let name = AXIS_NAMES[axis as usize];
        if let Some(i) = unimodality_violation(&ys, 1e-12 * value_range(&ys)) {
            failures.push(format!("f_{name} is not unimodal at {name} = {}", xs[i]));
        }
        let minima = strict_local_minima(&ys);
        if minima != 1 {
            failures.push(format!("f_{name} has {minima} strict interior local minima over 1.5x its range"));
        }
        let m = (0..ys.len()).min_by(|&a, &b| ys[a].total_cmp(&ys[b])).expect("samples");
        let expected = if axis == 3 { KX_MIN } else { 0.0 };
        let spacing = knot_spacing_near(&knots_1d(spline, axis), expected);
        if (xs[m] - expected).abs() > spacing {
            failures.push(format!(
                "f_{name} has its minimum at {} instead of {expected} (knot spacing {spacing})",
                xs[m]
            ));
        }
    }
    failures
}

fn value_range(ys: &[f64]) -> f64 {
    ys.iter().cloned().fold(f64::NEG_INFINITY, f64::max) - ys.iter().cloned().fold(f64::INFINITY, f64::min)
}

/// The material's energy on the plane of each marched 2D term (all but `f_{sx,sy}`, A.3.4),
/// `f0 + f_u + f_v + f_uv`, with at most one local minimum along every line through the term's
/// knots, halfway between them and along the edges, over 1.5 times the sampled range (plateaus
/// allowed, up to 1e-6 of the energy range); returns the violations ([`yarnhom_fit::shape`],
/// also printed by `yarnhom fit`).
fn quasiconvexity_failures(grid: &Grid, spline: &Spline) -> Vec<String> {
    term_shapes(grid, spline, 1e-6)
        .into_iter()
        .filter(|shape| shape.term.contains(','))
        .flat_map(|shape| shape.violations.into_iter().map(move |v| format!("{}: {v}", shape.term)))
        .collect()
}

/// `f_sa(x) = f_sa(-x)` and `Ψ(sa = x) = Ψ(sa = -x)` to 1e-9 relative, and the 2D terms with
/// `sa` even in it; returns the violations.
fn shear_asymmetries(spline: &Spline) -> Vec<String> {
    let material = SplineMaterial::from(spline);
    let mut failures = Vec::new();
    let limit = 1.5 * UPPER[1];
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-9 * a.abs().max(b.abs());
    for x in linspace(0.0, limit, 1001) {
        let (plus, minus) = (material.term_1d(1, x).expect("f_sa"), material.term_1d(1, -x).expect("f_sa"));
        if !close(plus, minus) {
            failures.push(format!("f_sa({x}) = {plus}, f_sa(-{x}) = {minus}"));
        }
        let total = |sa: f64| material.energy_at(&strain_along(&[1], &[sa]));
        let (plus, minus) = (total(x), total(-x));
        if !close(plus, minus) {
            failures.push(format!("Ψ(sa = ±{x}) = {plus}, {minus}"));
        }
    }
    for term in spline.terms_2d.iter().filter(|t| t.axes.contains(&1)) {
        let axes = [term.axes[0] as usize, term.axes[1] as usize];
        // the position of sa among the term's axes, and the other axis
        let k = if axes[0] == 1 { 0 } else { 1 };
        let other = axes[1 - k];
        for y in linspace(1.5 * LOWER[other], 1.5 * UPPER[other], 31) {
            for x in linspace(0.0, limit, 31) {
                let at = |sa: f64| {
                    let (u, v) = if k == 0 { (sa, y) } else { (y, sa) };
                    material.term_2d(axes, u, v).expect("2D term")
                };
                let (plus, minus) = (at(x), at(-x));
                if (plus - minus).abs() > 1e-9 * plus.abs().max(minus.abs()).max(1e-12) {
                    failures.push(format!(
                        "f_{axes:?} at sa = ±{x}, {} = {y}: {plus} vs {minus}",
                        AXIS_NAMES[other]
                    ));
                }
            }
        }
    }
    failures
}

/// Each 1D term increases strictly away from the minimum beyond its first and last knots, over
/// one knot range; returns the violations.
fn extrapolation_failures(spline: &Spline) -> Vec<String> {
    let material = SplineMaterial::from(spline);
    let mut failures = Vec::new();
    for term in &spline.terms_1d {
        let knots = knots_1d(spline, term.axis);
        let (first, last) = (knots[0], knots[knots.len() - 1]);
        let f = |x: f64| material.term_1d(term.axis as usize, x).expect("1D term");
        let name = AXIS_NAMES[term.axis as usize];
        for (end, outward) in [(last, 1.0), (first, -1.0)] {
            let mut previous = f(end);
            for d in linspace(0.0, last - first, 101).into_iter().skip(1) {
                let x = end + outward * d;
                let y = f(x);
                if y <= previous {
                    failures.push(format!("f_{name} does not increase outward at {x}: {y} after {previous}"));
                    break;
                }
                previous = y;
            }
        }
    }
    failures
}

#[test]
fn a_symmetrized_shear_fit_is_measured_against_the_mirror_averaged_data() {
    // A tile that is not mirror symmetric (the published stockinette) answers the two senses of
    // shear differently; the fit represents their mean in symlog space (A.35, Sec. 4.1), and
    // the modelled error measures it against that mean, while the raw error keeps the asymmetry.
    let mut grid = synthetic_grid();
    let widest_shear = grid.samples.iter().fold(0.0f64, |m, s| m.max(s.strain.sa.abs()));
    for s in grid.samples.iter_mut() {
        // Stiffer in one sense of shear, softer in the other (a factor odd in sa, so the
        // symlog-space mirror average is unchanged).
        let odd = 0.5 * s.strain.sa / widest_shear;
        let e = s.energy_density_j_m2.as_mut().expect("converged");
        *e = symexp(symlog(*e) * (1.0 + odd));
    }
    let (spline, material) = fit(&grid);
    let symmetrized = fit_errors(&grid, &material, spline.rest_energy_density_j_m2, true);
    let raw = fit_errors(&grid, &material, spline.rest_energy_density_j_m2, false);
    for ((e, r), term) in symmetrized.iter().zip(&raw).zip(&grid.terms) {
        eprintln!("{}: raw {:.4}, modelled {:?}", e.term, e.relative_rms, e.relative_rms_modelled);
        let modelled = e.relative_rms_modelled.expect("samples remain");
        if term.axes.contains(&1) {
            assert!(e.relative_rms > 0.05, "{}: the asymmetry shows in the raw error", e.term);
            assert!(modelled < 0.02, "{}: {modelled} against the mirror average", e.term);
            assert!(r.relative_rms_modelled.expect("samples") > 0.05, "{}: unsymmetrized", e.term);
        } else {
            assert_eq!(Some(modelled), r.relative_rms_modelled, "{}: no shear, no mirror", e.term);
        }
    }
}

#[test]
fn the_fit_reproduces_the_synthetic_energy() {
    let grid = synthetic_grid();
    let (spline, material) = fit(&grid);
    assert_eq!(spline.terms_1d.len(), 5);
    assert_eq!(spline.terms_2d.len(), 9);
    assert_eq!(spline.rest_energy_density_j_m2, F0);
    let errors = fit_errors(&grid, &material, spline.rest_energy_density_j_m2, true);
    eprintln!("{:<7} {:>7} {:>13} {:>25}", "term", "samples", "relative_rms", "relative_rms_deformation");
    for e in &errors {
        eprintln!(
            "{:<7} {:>7} {:>13.4e} {:>25.4e}",
            e.term, e.samples, e.relative_rms, e.relative_rms_deformation
        );
    }
    let mut failures = Vec::new();
    for (e, term) in errors.iter().zip(&grid.terms) {
        let bound = if term.axes.len() == 1 { 0.05 } else { 0.10 };
        if e.relative_rms.is_nan() || e.relative_rms >= bound {
            failures.push(format!("{}: relative RMS {:.4} >= {bound}", e.term, e.relative_rms));
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

#[test]
fn fitted_1d_terms_have_a_single_minimum_where_the_energy_has_it() {
    let grid = synthetic_grid();
    let (spline, _) = fit(&grid);
    let failures = single_minimum_failures(&grid, &spline);
    assert!(failures.is_empty(), "{failures:#?}");
}

#[test]
fn marched_2d_terms_have_at_most_one_minimum_per_grid_line() {
    let grid = synthetic_grid();
    let (spline, _) = fit(&grid);
    let failures = quasiconvexity_failures(&grid, &spline);
    assert!(failures.is_empty(), "{failures:#?}");
}

/// The published `stock.pyp` sampled with its Table 4.1 yarn on a reduced plan:
/// `yarnhom rve sample ../shared/data/hylc-patterns/stock.pyp --model table4.1:stock --n1d 40
/// --n2d 12` (all 1496 samples converged).
fn published_stockinette_grid() -> Grid {
    let path = format!("{}/tests/data/stock-40x12.grid.yh", env!("CARGO_MANIFEST_DIR"));
    yarnhom_artifacts::container::read::<Grid>(&path).expect("the stockinette grid fixture").1
}

/// The published rib (`rib.pyp`, Table 4.1 rib yarn) sampled over `rib1.json`'s ranges with the
/// normalized Kaldor contact: `rve sample rib.pyp --model table4.1:rib --ranges-from rib1.json
/// --n1d 40 --n2d 12`, all 1496 solves converged.
fn published_rib_grid() -> Grid {
    let path = format!("{}/tests/data/rib-40x12.grid.yh", env!("CARGO_MANIFEST_DIR"));
    yarnhom_artifacts::container::read::<Grid>(&path).expect("the rib grid fixture").1
}

/// Issue 4's bar: the fit reproduces its grid, as modelled, within 5% on the 1D terms and 10% on
/// the 2D terms.
fn assert_within_issue_4_bar(grid: &Grid, spline: &Spline, material: &SplineMaterial) {
    for e in fit_errors(grid, material, spline.rest_energy_density_j_m2, true) {
        let modelled = e.relative_rms_modelled.expect("samples remain");
        let bar = if e.term.contains(',') { 0.10 } else { 0.05 };
        println!("{}: {:.2}% as modelled", e.term, 100.0 * modelled);
        assert!(modelled < bar, "{}: {modelled}", e.term);
    }
}

#[test]
fn the_published_ribs_grid_is_reproduced_shear_terms_included() {
    // Issue 4's bar on the rib, whose shear response is nearly flat (sa term RMS 0.009 J/m²
    // against 7 J/m² for sy), a small difference of large energies: as modelled, 1D terms within
    // 5% (sa 4.70%) and 2D terms within 10% (sa,kx 8.46%, sa,ky 6.14%), every quasiconvexified
    // term with a single minimum.
    let grid = published_rib_grid();
    let (spline, material) = fit(&grid);
    assert_within_issue_4_bar(&grid, &spline, &material);
    let failures = regularized_term_failures(&grid);
    assert!(failures.is_empty(), "{failures:#?}");
}

#[test]
fn the_published_stockinettes_grid_is_reproduced_with_few_second_minima() {
    // Issue 4's bar on real data: as modelled, 1D terms within 5% and 2D terms within 10%.
    let grid = published_stockinette_grid();
    let (spline, material) = fit(&grid);
    assert_within_issue_4_bar(&grid, &spline, &material);
    // Each quasiconvexified term has a single minimum (`every_quasiconvexified_term_...`), but
    // the energy on each plane adds the 1D terms to the plane's residual, and the sum may have
    // more (Sec. 4.1.2). Marched on the plane's own fit, the sum had second minima on 17 of the
    // 162 lines through the control points (sa,kx on 8 of 18); marched with the 1D terms on its
    // axes, 6, and none on sa,kx. Checked also halfway between the control points and along the
    // edges (304 lines): 12, in the outermost interval of sa in sa,sy and sa,ky, where the
    // monotone step lowers the axis line's end slope below the 1D term's to keep the
    // extrapolation increasing (A.3.5).
    let failures = quasiconvexity_failures(&grid, &spline);
    assert!(failures.len() <= 12, "{failures:#?}");
    assert!(failures.iter().all(|f| f.starts_with("sa,sy") || f.starts_with("sa,ky")), "{failures:#?}");
}

/// The violations of a single minimum by the quasiconvexified terms of `grid`'s fit: the 1D
/// terms and the regularized 2D fits `f*_uv` (A.3.6) the marching (A.36) acts on.
fn regularized_term_failures(grid: &Grid) -> Vec<String> {
    let fit = fit_grid_with_regularized_terms(grid, &FitSettings::default(), 0.3).expect("fits");
    regularized_term_shapes(grid, &fit.spline, &fit.regularized_2d, 1e-6)
        .into_iter()
        .flat_map(|shape| shape.violations.into_iter().map(move |v| format!("{}: {v}", shape.term)))
        .collect()
}

#[test]
fn every_quasiconvexified_term_has_a_single_minimum() {
    // Issue 4: "no spurious interior minimum in any quasiconvexified term", the thesis' own
    // criterion (Sec. 4.1.2: individual terms have a single minimum, their sum may not).
    for (name, grid) in
        [("synthetic", synthetic_grid()), ("published stockinette", published_stockinette_grid())]
    {
        let failures = regularized_term_failures(&grid);
        assert!(failures.is_empty(), "{name}: {failures:#?}");
    }
    // The check sees a hole in a regularized fit off its axes, and a missing one.
    let grid = synthetic_grid();
    let mut fit = fit_grid_with_regularized_terms(&grid, &FitSettings::default(), 0.3).expect("fits");
    let t = fit.regularized_2d.iter().position(|t| t.axes == [0, 3]).expect("sx,kx");
    let nu = fit.regularized_2d[t].u_knots.len();
    fit.regularized_2d[t].values[nu + nu - 2] -= 20.0;
    let shapes = regularized_term_shapes(&grid, &fit.spline, &fit.regularized_2d, 1e-6);
    let failing: Vec<&str> =
        shapes.iter().filter(|s| !s.violations.is_empty()).map(|s| s.term.as_str()).collect();
    assert_eq!(failing, ["sx,kx"]);
    fit.regularized_2d.remove(t);
    let shapes = regularized_term_shapes(&grid, &fit.spline, &fit.regularized_2d, 1e-6);
    let sx_kx = shapes.iter().find(|s| s.term == "sx,kx").expect("checked");
    assert!(
        sx_kx.violations.iter().all(|v| v.starts_with("no finite energy")) && !sx_kx.violations.is_empty()
    );
}

#[test]
fn the_fit_is_symmetric_in_shear() {
    let (spline, _) = fit(&synthetic_grid());
    let failures = shear_asymmetries(&spline);
    assert!(failures.is_empty(), "{failures:#?}");
}

#[test]
fn extrapolation_increases_away_from_the_minimum() {
    let (spline, _) = fit(&synthetic_grid());
    let failures = extrapolation_failures(&spline);
    assert!(failures.is_empty(), "{failures:#?}");
}

/// The checks above fail on a spline with the defects they look for.
#[test]
fn the_checks_detect_defective_splines() {
    let grid = synthetic_grid();
    let (spline, _) = fit(&grid);
    let term_1d = |s: &mut Spline, axis: u8| -> usize {
        s.terms_1d.iter().position(|t| t.axis == axis).expect("1D term")
    };

    // A dip at the second-to-last knot of f_sx: a second minimum.
    let mut bad = spline.clone();
    let t = term_1d(&mut bad, 0);
    let n = bad.terms_1d[t].values.len();
    bad.terms_1d[t].values[n - 2] -= 20.0;
    assert!(!single_minimum_failures(&grid, &bad).is_empty());

    // f_kx with its minimum moved two knots left of 0.
    let mut bad = spline.clone();
    let t = term_1d(&mut bad, 3);
    let zero = bad.terms_1d[t].knots.iter().position(|&k| k == 0.0).expect("knot at 0");
    bad.terms_1d[t].values[zero - 2] -= 5.0;
    assert!(single_minimum_failures(&grid, &bad).iter().any(|f| f.contains("instead of 40")));

    // A hole in f_{sx,kx} off the axes: a second minimum along a grid line.
    let mut bad = spline.clone();
    let t = bad.terms_2d.iter().position(|t| t.axes == [0, 3]).expect("sx,kx");
    let nu = bad.terms_2d[t].u_knots.len();
    bad.terms_2d[t].values[nu + nu - 2] -= 20.0;
    assert!(!quasiconvexity_failures(&grid, &bad).is_empty());

    // An asymmetric f_sa and f_{sx,sa}.
    let mut bad = spline.clone();
    let t = term_1d(&mut bad, 1);
    bad.terms_1d[t].values[1] += 0.01;
    let t = bad.terms_2d.iter().position(|t| t.axes == [0, 1]).expect("sx,sa");
    let nu = bad.terms_2d[t].u_knots.len();
    bad.terms_2d[t].values[nu + nu - 2] += 0.01;
    let failures = shear_asymmetries(&bad);
    assert!(
        failures.iter().any(|f| f.starts_with("f_sa")) && failures.iter().any(|f| f.starts_with("f_[0, 1]"))
    );

    // f_ky extrapolated downhill beyond its last knot.
    let mut bad = spline.clone();
    let t = term_1d(&mut bad, 4);
    *bad.terms_1d[t].slopes.last_mut().expect("slopes") = -0.5;
    assert!(!extrapolation_failures(&bad).is_empty());
}

#[test]
fn too_few_samples_and_a_missing_rest_sample_are_errors() {
    let mut grid = synthetic_grid();
    // Keep 3 converged samples of the sy term.
    let sy = grid.terms.iter().position(|t| t.axes == [2]).expect("sy term") as u32;
    for s in grid.samples.iter_mut().filter(|s| s.term == sy).skip(3) {
        s.converged = false;
        s.stop_reason = "iteration_limit".into();
        s.energy_density_j_m2 = None;
    }
    grid.validate().expect("valid");
    assert_eq!(
        fit_grid(&grid, &FitSettings::default(), 0.3),
        Err(FitError::TooFewSamples { term: "sy".into(), converged: 3 })
    );

    let mut grid = synthetic_grid();
    for s in grid.samples.iter_mut().filter(|s| strain_values(&s.strain).iter().all(|&v| v == 0.0)) {
        s.converged = false;
        s.stop_reason = "line_search_failed".into();
        s.energy_density_j_m2 = None;
    }
    grid.validate().expect("valid");
    assert_eq!(fit_grid(&grid, &FitSettings::default(), 0.3), Err(FitError::NoRestSample));
}

/// Deterministic pseudo-random numbers in `[0, 1)` (xorshift64).
struct XorShift(u64);

impl XorShift {
    fn unit(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

#[test]
fn noise_in_compression_is_regularized_away() {
    let clean = synthetic_grid();
    let mut noisy = clean.clone();
    let mut rng = XorShift(0x9E37_79B9_7F4A_7C15);
    let amplitude = 0.04;
    for s in noisy.samples.iter_mut().filter(|s| s.strain.sx < 0.0 || s.strain.sy < 0.0) {
        let e = s.energy_density_j_m2.as_mut().expect("converged");
        *e *= 1.0 + amplitude * (2.0 * rng.unit() - 1.0);
    }
    noisy.validate().expect("valid");
    let (spline, material) = fit(&noisy);
    let failures = single_minimum_failures(&noisy, &spline);
    assert!(failures.is_empty(), "{failures:#?}");
    // Errors against the noiseless truth.
    let errors = fit_errors(&clean, &material, spline.rest_energy_density_j_m2, true);
    eprintln!("with {}% noise in compression, against the noiseless energy:", amplitude * 100.0);
    eprintln!("{:<7} {:>7} {:>13} {:>25}", "term", "samples", "relative_rms", "relative_rms_deformation");
    for e in &errors {
        eprintln!(
            "{:<7} {:>7} {:>13.4e} {:>25.4e}",
            e.term, e.samples, e.relative_rms, e.relative_rms_deformation
        );
    }
    for (e, term) in errors.iter().zip(&clean.terms) {
        if term.axes.len() == 1 {
            assert!(
                e.relative_rms < 0.05,
                "{}: relative RMS {:.4} against the truth",
                e.term,
                e.relative_rms
            );
        }
    }
}
