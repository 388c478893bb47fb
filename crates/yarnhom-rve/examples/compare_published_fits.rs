//! Our homogenized 1D in-plane responses against the published HYLC fits (issue 3, "Against the
//! published fits"): for each published pattern with its Table 4.1 yarn model, solve the tile
//! along each of sx, sa, sy (0.05 to 0.3; warm starts along the line), and compare the energy
//! added over the unstrained tile with the fit's 1D term. Prints the relative RMS difference
//! per term. Run: `cargo run --release -p yarnhom-rve --example compare_published_fits [MODE]`
//! with MODE `published` (the tiles as published, default), `periods` (their rest shape kept,
//! periods moved to the in-plane minimum: Algorithm 2's last stage) or `relaxed` (Algorithm 2
//! from the published geometry).

use yarnhom_artifacts::Spline;
use yarnhom_artifacts::open::open_artifact;
use yarnhom_artifacts::{Pattern, YarnModel, pyp::parse_pyp};
use yarnhom_fit::SplineMaterial;
use yarnhom_geom::MacroStrain;
use yarnhom_rve::homogenize::solve_at;
use yarnhom_rve::{RelaxOptions, RveModel, SolveOptions, relax};

const DATA: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data");
const SAMPLES: [f64; 6] = [0.05, 0.1, 0.15, 0.2, 0.25, 0.3];
const TERMS: [&str; 3] = ["sx", "sa", "sy"];

/// The tile to compare: the published pattern, or relaxed by `mode`.
fn pattern_for(mode: &str, pattern: Pattern, model: &YarnModel) -> Pattern {
    let options = match mode {
        "published" => return pattern,
        "periods" => RelaxOptions { keep_rest_shape: true, ..RelaxOptions::default() },
        "relaxed" => RelaxOptions { max_resets: 100, ..RelaxOptions::default() },
        other => panic!("unknown mode '{other}': published, periods or relaxed"),
    };
    let (relaxed, report) = relax(&pattern, model, &options, &mut |_| {}).expect("relaxes");
    eprintln!("{}: {report:?}", pattern.name);
    relaxed
}

fn main() {
    let mode = std::env::args().nth(1).unwrap_or_else(|| "published".into());
    println!("tiles: {mode}\n");
    println!("| pattern | term | ours at 0.3 (J/m²) | published at 0.3 | relative RMS over 0.05..0.3 |");
    println!("|---|---|---|---|---|");
    for name in ["stock", "rib", "honey", "basket", "satin"] {
        let text = std::fs::read_to_string(format!("{DATA}/hylc-patterns/{name}.pyp")).expect("pattern");
        let pattern = parse_pyp(&text, name, None).expect("imports");
        let path = format!("{DATA}/hylc-materials/{name}1.json");
        let fit = SplineMaterial::from(&open_artifact::<Spline>(&path).expect("published fit imports").value);
        let yarn = YarnModel::table_4_1(name).expect("row");
        let model = RveModel::new(&pattern_for(&mode, pattern, &yarn), &yarn).expect("tile");
        let zero: MacroStrain = "sx=0".parse().expect("strain");
        let (rest, _) = solve_at(&model, &zero, None, &SolveOptions::default());
        for (k, term) in TERMS.iter().enumerate() {
            let mut state = None;
            let (mut diff2, mut ref2) = (0.0, 0.0);
            let mut last = (f64::NAN, f64::NAN);
            for &x in &SAMPLES {
                let strain: MacroStrain = format!("{term}={x}").parse().expect("strain");
                let options =
                    if state.is_some() { SolveOptions::warm_started() } else { SolveOptions::default() };
                let (report, solved) = solve_at(&model, &strain, state.as_ref(), &options);
                if !report.converged {
                    println!("| {name} | {term} | not converged at {x} ({:?}) | | |", report.reason);
                    break;
                }
                state = Some(solved);
                let ours = report.energy_density_j_m2 - rest.energy_density_j_m2;
                let term = |x: f64| fit.term_1d(k, x).expect("the fit has the term");
                let published = term(x) - term(0.0);
                diff2 += (ours - published).powi(2);
                ref2 += published.powi(2);
                last = (ours, published);
            }
            println!(
                "| {name} | {term} | {:.4} | {:.4} | {:.1}% |",
                last.0,
                last.1,
                100.0 * (diff2 / ref2).sqrt()
            );
        }
    }
}
