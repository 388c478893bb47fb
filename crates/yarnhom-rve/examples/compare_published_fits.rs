//! Our homogenized 1D in-plane responses against the published HYLC fits (issue 3, "Against the
//! published fits"): for each published pattern with its Table 4.1 yarn model, solve the tile
//! along each of sx, sa, sy (0.05 to 0.3; warm starts along the line), and compare the energy
//! added over the unstrained tile with the fit's 1D term. Prints the relative RMS difference
//! per term. Run: `cargo run --release -p yarnhom-rve --example compare_published_fits`.

use yarnhom_artifacts::{YarnModel, pyp::parse_pyp};
use yarnhom_geom::MacroStrain;
use yarnhom_rve::homogenize::solve_at;
use yarnhom_rve::{RveModel, SolveOptions};

const DATA: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data");
const SAMPLES: [f64; 6] = [0.05, 0.1, 0.15, 0.2, 0.25, 0.3];
const TERMS: [&str; 3] = ["sx", "sa", "sy"];

/// The published fit's 1D term `k` at strain `x` (cubic Hermite over strain / scale, linear
/// extrapolation; see ../shared/data/hylc-materials/FORMAT.md).
fn published_term(fit: &serde_json::Value, k: usize, x: f64) -> f64 {
    let scale = fit["strain scale"][k].as_f64().expect("scale");
    let term = fit["coeffs"]["1D"].as_array().expect("1D").iter().find(|t| t["k"] == k).expect("term");
    let v = |key: &str| -> Vec<f64> {
        term[key].as_array().expect(key).iter().map(|x| x.as_f64().expect("num")).collect()
    };
    let (t, p, m) = (v("t"), v("p"), v("m"));
    let (u, last) = (x / scale, t.len() - 1);
    if u <= t[0] {
        return p[0] + m[0] * (u - t[0]);
    }
    if u >= t[last] {
        return p[last] + m[last] * (u - t[last]);
    }
    let i = t.iter().position(|&ti| ti > u).expect("inside") - 1;
    let h = t[i + 1] - t[i];
    let s = (u - t[i]) / h;
    let (s2, s3) = (s * s, s * s * s);
    (2.0 * s3 - 3.0 * s2 + 1.0) * p[i]
        + (s3 - 2.0 * s2 + s) * h * m[i]
        + (-2.0 * s3 + 3.0 * s2) * p[i + 1]
        + (s3 - s2) * h * m[i + 1]
}

fn main() {
    println!("| pattern | term | ours at 0.3 (J/m²) | published at 0.3 | relative RMS over 0.05..0.3 |");
    println!("|---|---|---|---|---|");
    for name in ["stock", "rib", "honey", "basket", "satin"] {
        let text = std::fs::read_to_string(format!("{DATA}/hylc-patterns/{name}.pyp")).expect("pattern");
        let pattern = parse_pyp(&text, name, None).expect("imports");
        let fit: serde_json::Value = serde_json::from_str(
            &std::fs::read_to_string(format!("{DATA}/hylc-materials/{name}1.json")).expect("fit"),
        )
        .expect("json");
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
                let published = published_term(&fit, k, x) - published_term(&fit, k, 0.0);
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
