//! `yarnhom diff A B`: two artifacts of the same kind (splines by evaluation, see
//! `yarnhom_fit::difference`), or two MCAP traces (`yarnhom_trace::diff`).

use std::io::{BufReader, Read, Write};
use std::path::{Path, PathBuf};

use anyhow::Context;
use clap::Args;
use yarnhom_artifacts::AnyArtifact;
use yarnhom_artifacts::diff::{Tolerance, diff};
use yarnhom_fit::diff_spline_materials;
use yarnhom_trace::diff_traces;

use crate::Outcome;
use crate::inputs;

#[derive(Debug, Args)]
pub struct DiffArgs {
    /// First artifact (any readable format, an ARCSim-HYLC material JSON, or an MCAP trace).
    pub a: PathBuf,
    /// Second artifact, of the same kind as the first.
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

/// The first bytes of an MCAP file.
const MCAP_MAGIC: &[u8] = b"\x89MCAP0\r\n";

pub fn run(args: DiffArgs) -> anyhow::Result<Outcome> {
    anyhow::ensure!(
        args.rtol >= 0.0 && args.atol >= 0.0,
        "tolerances must be non-negative numbers (got rtol {}, atol {})",
        args.rtol,
        args.atol
    );
    let tol = Tolerance { rtol: args.rtol, atol: args.atol };
    let (a_trace, b_trace) = (is_trace(&args.a)?, is_trace(&args.b)?);
    let (json, report, equal) = match (a_trace, b_trace) {
        (true, true) => {
            let d = diff_traces(open(&args.a)?, open(&args.b)?, tol);
            (serde_json::to_string_pretty(&d)?, d.report(), d.equal())
        }
        (false, false) => {
            let (a, b) = (load(&args.a)?, load(&args.b)?);
            anyhow::ensure!(
                a.kind() == b.kind(),
                "cannot compare a '{}' ({}) with a '{}' ({})",
                a.kind(),
                args.a.display(),
                b.kind(),
                args.b.display()
            );
            let d = match (&a, &b) {
                (AnyArtifact::Spline(a), AnyArtifact::Spline(b)) => diff_spline_materials(a, b, tol),
                _ => diff(&a, &b, tol),
            };
            (serde_json::to_string_pretty(&d)?, d.report(), d.equal())
        }
        (true, false) => anyhow::bail!("cannot compare a trace ({}) with an artifact", args.a.display()),
        (false, true) => anyhow::bail!("cannot compare an artifact with a trace ({})", args.b.display()),
    };
    // A reader that stopped early (`| head`) does not change the verdict the exit status gives.
    match writeln!(std::io::stdout().lock(), "{}", if args.json { json } else { report }) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => return Err(e.into()),
        _ => {}
    }
    Ok(if equal { Outcome::Success } else { Outcome::Different })
}

/// Whether `path` is an MCAP trace: it starts with the MCAP magic, or is named `*.mcap` (then it
/// must start with the magic).
fn is_trace(path: &Path) -> anyhow::Result<bool> {
    let mut start = Vec::with_capacity(MCAP_MAGIC.len());
    open(path)?
        .take(MCAP_MAGIC.len() as u64)
        .read_to_end(&mut start)
        .with_context(|| format!("cannot read {}", path.display()))?;
    let magic = start == MCAP_MAGIC;
    let named = path.extension().is_some_and(|e| e.eq_ignore_ascii_case("mcap"));
    anyhow::ensure!(magic || !named, "{}: not an MCAP trace (no MCAP magic at its start)", path.display());
    Ok(magic)
}

fn open(path: &Path) -> anyhow::Result<BufReader<std::fs::File>> {
    let file = std::fs::File::open(path).with_context(|| format!("cannot read {}", path.display()))?;
    Ok(BufReader::new(file))
}

/// An artifact in any readable format, or a spline from an ARCSim-HYLC material JSON.
fn load(path: &Path) -> anyhow::Result<AnyArtifact> {
    let bytes = std::fs::read(path).with_context(|| format!("cannot read {}", path.display()))?;
    if bytes.windows(14).any(|w| w == b"\"strain scale\"") {
        return Ok(AnyArtifact::Spline(crate::fit::load_spline(path)?));
    }
    Ok(inputs::load(path, None)?.artifact)
}
