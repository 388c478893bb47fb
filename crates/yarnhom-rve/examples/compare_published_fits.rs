//! Our homogenized 1D in-plane responses against the published HYLC fits (issue 3, "Against the
//! published fits"): for each published pattern with its Table 4.1 yarn model, solve the tile
//! along each of sx, sa, sy (0.05 to 0.3; warm starts along the line), and compare the energy
//! added over the unstrained tile with the fit's 1D term. Prints the relative RMS difference
//! per term. Run: `cargo run --release -p yarnhom-rve --example compare_published_fits`.

use yarnhom_artifacts::arcsim::HylcFit;
use yarnhom_artifacts::{YarnModel, pyp::parse_pyp};
use yarnhom_geom::MacroStrain;
use yarnhom_rve::homogenize::solve_at;
use yarnhom_rve::{RveModel, SolveOptions};

const DATA: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data");
const SAMPLES: [f64; 6] = [0.05, 0.1, 0.15, 0.2, 0.25, 0.3];
const TERMS: [&str; 3] = ["sx", "sa", "sy"];

fn main() {
    println!("| pattern | term | ours at 0.3 (J/m²) | published at 0.3 | relative RMS over 0.05..0.3 |");
    println!("|---|---|---|---|---|");
    for name in ["stock", "rib", "honey", "basket", "satin"] {
        let text = std::fs::read_to_string(format!("{DATA}/hylc-patterns/{name}.pyp")).expect("pattern");
        let pattern = parse_pyp(&text, name, None).expect("imports");
        let fit = HylcFit::parse(
            &std::fs::read_to_string(format!("{DATA}/hylc-materials/{name}1.json")).expect("fit"),
        )
        .expect("published fit parses");
        let model = RveModel::new(&pattern, &YarnModel::table_4_1(name).expect("row")).expect("tile");
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
