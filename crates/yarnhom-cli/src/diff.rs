//! `yarnhom diff A B`: two artifacts of the same kind (splines by evaluation, see
//! `yarnhom_fit::difference`), or two MCAP traces (`yarnhom_trace::diff`).

use std::io::Write;
use std::path::{Path, PathBuf};

use clap::Args;
use yarnhom_artifacts::AnyArtifact;
use yarnhom_artifacts::diff::{Tolerance, diff};
use yarnhom_artifacts::open::{Contents, open};
use yarnhom_calib::report::CalibrationReport;
use yarnhom_fit::diff_spline_materials;
use yarnhom_trace::{diff_traces, open_source};

use crate::Outcome;

#[derive(Debug, Args)]
pub struct DiffArgs {
    /// First file: an artifact (any readable form, an ARCSim-HYLC material JSON), a calibration
    /// report (`shell-fit.json`, `yarn-fit.json`, `report.json`) or an MCAP trace.
    pub a: PathBuf,
    /// Second file, of the same kind as the first.
    pub b: PathBuf,
    /// Relative tolerance: values are equal if |a - b| <= atol + rtol * |b|.
    #[arg(long, default_value_t = 1e-9, allow_negative_numbers = true)]
    pub rtol: f64,
    /// Absolute tolerance, in each field's SI unit.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub atol: f64,
    /// Print the comparison as JSON.
    #[arg(long)]
    pub json: bool,
}

pub fn run(args: DiffArgs) -> anyhow::Result<Outcome> {
    anyhow::ensure!(
        args.rtol >= 0.0 && args.atol >= 0.0,
        "tolerances must be non-negative numbers (got rtol {}, atol {})",
        args.rtol,
        args.atol
    );
    let tol = Tolerance { rtol: args.rtol, atol: args.atol };
    let (a, b) = (open(&args.a)?, open(&args.b)?);
    let (json, report, equal) = match (a.contents, b.contents) {
        (Contents::Trace, Contents::Trace) => {
            let d = diff_traces(open_source(&path_text(&a.path))?, open_source(&path_text(&b.path))?, tol);
            (serde_json::to_string_pretty(&d)?, d.report(), d.equal())
        }
        (Contents::Artifact { artifact: x, .. }, Contents::Artifact { artifact: y, .. }) => {
            anyhow::ensure!(
                x.kind() == y.kind(),
                "cannot compare a '{}' ({}) with a '{}' ({})",
                x.kind(),
                a.path.display(),
                y.kind(),
                b.path.display()
            );
            let d = match (&x, &y) {
                (AnyArtifact::Spline(x), AnyArtifact::Spline(y)) => diff_spline_materials(x, y, tol),
                _ => diff(&x, &y, tol),
            };
            (serde_json::to_string_pretty(&d)?, d.report(), d.equal())
        }
        (Contents::Report(x), Contents::Report(y)) if x.format == y.format => {
            let d =
                CalibrationReport::decode(x.document)?.diff(&CalibrationReport::decode(y.document)?, tol)?;
            (serde_json::to_string_pretty(&d)?, d.report(), d.equal())
        }
        (x, y) => anyhow::bail!(
            "cannot compare a {} ({}) with a {} ({})",
            x.describe(),
            a.path.display(),
            y.describe(),
            b.path.display()
        ),
    };
    // A reader that stopped early (`| head`) does not change the verdict the exit status gives.
    match writeln!(std::io::stdout().lock(), "{}", if args.json { json } else { report }) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => return Err(e.into()),
        _ => {}
    }
    Ok(if equal { Outcome::Success } else { Outcome::Different })
}

fn path_text(path: &Path) -> String {
    path.display().to_string()
}
