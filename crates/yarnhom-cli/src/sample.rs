//! `yarnhom rve sample`: the sampling sweep of App. A.3.1 written as a `grid` artifact, with a
//! progress bar, a checkpoint after every sweep line (so a killed run resumes where it stopped)
//! and shards (`--shard K/N`) that `yarnhom grid merge` joins bit-identically.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Context;
use clap::Args;
use yarnhom_artifacts::Spline;
use yarnhom_artifacts::grid::{AXIS_NAMES, GridShard};
use yarnhom_artifacts::open::{base_name, open_artifact, open_pattern_and_model};
use yarnhom_fit::sampled_ranges;
use yarnhom_rve::RveModel;
use yarnhom_rve::checkpoint::RunKey;
use yarnhom_rve::sample::{PlanRanges, PlaneRange, SampleOptions, SamplePlan};
use yarnhom_rve::sweep::{Sweep, Swept};
use yarnhom_trace::TraceMetadata;

use crate::Outcome;
use crate::args::{parse_axis, parse_interval, parse_shard};
use crate::output::{finish_trace, open_trace, print_summary, progress_bar, write_artifact, wrote};

#[derive(Debug, Args)]
pub struct SampleArgs {
    /// The pattern (with rest state; see `yarnhom rve relax`).
    pub pattern: PathBuf,
    /// Yarn model: a built-in `table4.1:<row>` or a `yarnmodel` file.
    #[arg(long)]
    pub model: String,
    /// Samples per 1D term (the thesis: 150).
    #[arg(long, default_value_t = 150)]
    pub n1d: usize,
    /// Samples per axis of each 2D term (the thesis: 50, i.e. 50 x 50).
    #[arg(long, default_value_t = 50)]
    pub n2d: usize,
    /// Sample over the ranges a fitted material was sampled over, recovered from its control
    /// points: an ARCSim-HYLC JSON (e.g. `../shared/data/hylc-materials/rib1.json`) or a
    /// `.spline.yh`. Default: the published stockinette's ranges (from `stock1.json`).
    #[arg(long, value_name = "MATERIAL")]
    pub ranges_from: Option<PathBuf>,
    /// Sample a 1D term over another range, e.g. `--range sx=-0.3:0.8` (repeatable; 0 must lie
    /// strictly inside; applied after `--ranges-from`).
    #[arg(long = "range", value_name = "AXIS=MIN:MAX", value_parser = parse_range)]
    pub ranges: Vec<(usize, [f64; 2])>,
    /// Sample a 2D term over other ranges, e.g. `--plane-range sa,ky=-0.6:0.6,-184:184`
    /// (repeatable; the thesis samples each plane over its own ranges, Alg. 6).
    #[arg(long = "plane-range", value_name = "A,B=MIN:MAX,MIN:MAX", value_parser = parse_plane_range)]
    pub plane_ranges: Vec<PlaneRange>,
    /// Compute this shard `K/N` of the sweep lines only (0 <= K < N); merge the shards with
    /// `yarnhom grid merge`.
    #[arg(long, value_name = "K/N")]
    pub shard: Option<String>,
    /// Store every sample's equilibrium geometry (for yarn detail, Ch. 5).
    #[arg(long)]
    pub geometry: bool,
    /// Skip the homogenized stress (3.23c).
    #[arg(long)]
    pub no_stress: bool,
    /// Newton iteration limit per solve.
    #[arg(long, default_value_t = 2000)]
    pub max_iterations: usize,
    /// Also record every sample as it is solved into an MCAP trace (`-`: stdout): one
    /// `/rve/sample` message each (frame = the sample's number in completion order), plus its
    /// yarns on `/yarn/frame` with `--geometry`. Samples resumed from a checkpoint are not
    /// recorded again.
    #[arg(long, value_name = "TRACE")]
    pub trace: Option<String>,
    /// Output file (default: PATTERN.grid.yh). The checkpoint is OUTPUT.checkpoint.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
}

/// `AXIS=MIN:MAX`.
fn parse_range(text: &str) -> Result<(usize, [f64; 2]), String> {
    let (name, range) = text.split_once('=').ok_or("expected AXIS=MIN:MAX, e.g. sx=-0.3:0.8")?;
    Ok((parse_axis(name)?, parse_interval(range)?))
}

/// `A,B=MIN:MAX,MIN:MAX`, the axes in either order.
fn parse_plane_range(text: &str) -> Result<PlaneRange, String> {
    let expected = "expected A,B=MIN:MAX,MIN:MAX, e.g. sa,ky=-0.6:0.6,-184:184";
    let (names, ranges) = text.split_once('=').ok_or(expected)?;
    let ((a, b), (ra, rb)) = names.split_once(',').zip(ranges.split_once(',')).ok_or(expected)?;
    let (a, b, ra, rb) = (parse_axis(a)?, parse_axis(b)?, parse_interval(ra)?, parse_interval(rb)?);
    match a.cmp(&b) {
        std::cmp::Ordering::Less => Ok(PlaneRange { axes: [a, b], ranges: [ra, rb] }),
        std::cmp::Ordering::Greater => Ok(PlaneRange { axes: [b, a], ranges: [rb, ra] }),
        std::cmp::Ordering::Equal => Err(format!("a 2D term needs two different axes, got '{names}'")),
    }
}

/// The published stockinette's ranges, or those of `--ranges-from`, with the command line's
/// `--range` and `--plane-range`.
fn plan_ranges(args: &SampleArgs) -> anyhow::Result<PlanRanges> {
    let mut ranges = match &args.ranges_from {
        Some(path) => ranges_of(path).with_context(|| format!("--ranges-from {}", path.display()))?,
        None => PlanRanges::default(),
    };
    for &(axis, [lower, upper]) in &args.ranges {
        (ranges.single.lower[axis], ranges.single.upper[axis]) = (lower, upper);
    }
    for plane in &args.plane_ranges {
        let [a, b] = plane.axes.map(|axis| AXIS_NAMES[axis]);
        let slot = ranges.plane_mut(plane.axes).with_context(|| {
            format!("--plane-range {a},{b}: not a sampled 2D term (kx and ky are never sampled together)")
        })?;
        *slot = *plane;
    }
    Ok(PlanRanges::new(ranges.single, ranges.planes)?)
}

/// The sampled ranges of a fitted material, as a plan's.
fn ranges_of(path: &Path) -> anyhow::Result<PlanRanges> {
    let recovered = sampled_ranges(&open_artifact::<Spline>(path)?.value)?;
    Ok(PlanRanges::from_bounds(recovered.single, &recovered.planes)?)
}

pub fn run(args: SampleArgs) -> anyhow::Result<Outcome> {
    let (pattern, model, inputs) = open_pattern_and_model(&args.pattern, &args.model)?;
    let tile = RveModel::new(&pattern, &model).with_context(|| format!("{}", args.pattern.display()))?;
    let plan = SamplePlan::thesis(&plan_ranges(&args)?, args.n1d, args.n2d)?;
    let shard =
        args.shard.as_deref().map(parse_shard).transpose().map_err(|e| anyhow::anyhow!("--shard {e}"))?;
    let shard = shard.map(|(index, count)| GridShard { index, count });
    let options = SampleOptions {
        max_iterations: args.max_iterations,
        stress: !args.no_stress,
        geometry: args.geometry,
    };
    let sizes = [args.n1d, args.n2d];
    let key = RunKey::new(
        &inputs[0].content_hash,
        &model.name,
        &plan,
        sizes,
        shard.map(|s| (s.index, s.count)),
        &options,
    );
    let output =
        args.output.clone().unwrap_or_else(|| format!("{}.grid.yh", base_name(&args.pattern)).into());
    let checkpoint_path = PathBuf::from(format!("{}.checkpoint", output.display()));
    let sweep = Sweep::resume(&plan, key, shard, &checkpoint_path)?;
    let (total, resumed) = (sweep.sample_count(), sweep.resumed_count());
    eprintln!(
        "sampling '{}' with '{}': {}",
        pattern.name,
        model.name,
        describe(&sweep, &plan, shard, &checkpoint_path)
    );
    let started = Instant::now();
    let trace = args.trace.as_deref().map(|path| open_trace(path, &trace_metadata(&args))).transpose()?;
    let bar = progress_bar(total as u64, "samples");
    bar.set_position(resumed as u64);
    let swept = sweep.run(&tile, &pattern, &options, trace, &|n| bar.inc(n as u64));
    bar.finish_and_clear();
    let Swept { grid, checkpoint, trace } = swept?;
    finish_trace(trace, args.trace.as_deref())?;
    write_artifact(&output, &grid, "rve sample", inputs)?;
    checkpoint.remove()?;
    let converged = grid.samples.iter().filter(|s| s.converged).count();
    let summary = format!(
        "sampled '{}': {converged} of {} samples converged, {:.1} s this run\n{}",
        pattern.name,
        grid.samples.len(),
        started.elapsed().as_secs_f64(),
        grid.summary()
    );
    print_summary(&summary, args.trace.as_deref());
    wrote(&output);
    Ok(Outcome::Success)
}

/// `N of M samples in L sweep lines (shard K/N), R resumed from CHECKPOINT`.
fn describe(sweep: &Sweep<'_>, plan: &SamplePlan, shard: Option<GridShard>, checkpoint: &Path) -> String {
    let (total, resumed) = (sweep.sample_count(), sweep.resumed_count());
    let mut text =
        format!("{total} of {} samples in {} sweep lines", plan.sample_count(), sweep.line_count());
    if let Some(s) = shard {
        text += &format!(" (shard {}/{})", s.index, s.count);
    }
    if resumed > 0 {
        text += &format!(", {resumed} resumed from {}", checkpoint.display());
    }
    text
}

fn trace_metadata(args: &SampleArgs) -> TraceMetadata {
    TraceMetadata::new("yarnhom rve sample", env!("CARGO_PKG_VERSION"))
        .with_entry("pattern", args.pattern.display().to_string())
        .with_entry("model", &args.model)
        .with_entry("n1d", args.n1d.to_string())
        .with_entry("n2d", args.n2d.to_string())
}
