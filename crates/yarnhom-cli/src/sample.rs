//! `yarnhom rve sample`: the sampling sweep of App. A.3.1 written as a `grid` artifact, with a
//! progress bar, a checkpoint after every sweep line (so a killed run resumes where it stopped)
//! and shards (`--shard K/N`) that `yarnhom grid merge` joins bit-identically.

use std::fs::File;
use std::io::{BufReader, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::Instant;

use anyhow::Context;
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use serde::{Deserialize, Serialize};
use yarnhom_artifacts::Pattern;
use yarnhom_artifacts::container;
use yarnhom_artifacts::grid::{AXIS_NAMES, Grid, GridSample, GridShard, GridTerm, strain_from_values};
use yarnhom_fit::sampled_ranges;
use yarnhom_rve::RveModel;
use yarnhom_rve::sample::{
    LineResult, PlanRanges, PlaneRange, SampleOptions, SampleOutcome, SamplePlan, SampleRanges, SweepLine,
    plane_axes, sample_lines, shard_lines,
};
use yarnhom_trace::{RveSample, TraceError, TraceMetadata};

use crate::Outcome;
use crate::fit::{load_spline, parse_axis, parse_interval};
use crate::inputs::{base_name, provenance};
use crate::rve::{load_pattern_and_model, stop_reason};
use crate::trace_out::{TraceSink, is_stdout, yarns_in_order};

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

/// What identifies a run: a checkpoint is resumed only by the same run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
struct RunKey {
    pattern_hash: String,
    model: String,
    n1d: usize,
    n2d: usize,
    /// `[lower, upper]` of each axis of each term, in plan order.
    ranges: Vec<[f64; 2]>,
    shard: Option<(u32, u32)>,
    geometry: bool,
    stress: bool,
    max_iterations: usize,
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
    let recovered = sampled_ranges(&load_spline(path)?)?;
    let single = SampleRanges {
        lower: recovered.single.map(|[lower, _]| lower),
        upper: recovered.single.map(|[_, upper]| upper),
    };
    let planes = plane_axes()
        .into_iter()
        .map(|axes| {
            let [a, b] = axes.map(|axis| AXIS_NAMES[axis]);
            recovered
                .planes
                .iter()
                .find(|(p, _)| p.map(usize::from) == axes)
                .map(|&(_, ranges)| PlaneRange { axes, ranges })
                .with_context(|| format!("the material has no 2D term {a},{b}"))
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    Ok(PlanRanges::new(single, planes)?)
}

/// One finished sweep line in the checkpoint.
#[derive(Debug, Clone, Serialize, Deserialize)]
struct CheckpointLine {
    line: usize,
    samples: Vec<GridSample>,
}

pub fn run(args: SampleArgs) -> anyhow::Result<Outcome> {
    let (pattern, model, inputs) = load_pattern_and_model(&args.pattern, &args.model)?;
    let tile = RveModel::new(&pattern, &model).with_context(|| format!("{}", args.pattern.display()))?;
    let plan = SamplePlan::thesis(&plan_ranges(&args)?, args.n1d, args.n2d)?;
    let shard = args.shard.as_deref().map(parse_shard).transpose()?;
    let key = RunKey {
        pattern_hash: inputs[0].content_hash.clone(),
        model: model.name.clone(),
        n1d: args.n1d,
        n2d: args.n2d,
        ranges: plan.terms.iter().flat_map(|t| t.values.iter().map(|v| [v[0], v[v.len() - 1]])).collect(),
        shard: shard.map(|s| (s.index, s.count)),
        geometry: args.geometry,
        stress: !args.no_stress,
        max_iterations: args.max_iterations,
    };
    let output =
        args.output.clone().unwrap_or_else(|| format!("{}.grid.yh", base_name(&args.pattern)).into());
    let checkpoint = PathBuf::from(format!("{}.checkpoint", output.display()));
    let done = read_checkpoint(&checkpoint, &key)?;
    let all_lines = plan.lines();
    let mine = match shard {
        Some(s) => shard_lines(&all_lines, s.index as usize, s.count as usize),
        None => all_lines,
    };
    let todo: Vec<SweepLine> =
        mine.iter().filter(|l| !done.iter().any(|d| d.line == l.index)).cloned().collect();
    let total: usize = mine.iter().map(|l| l.points.len()).sum();
    let resumed: usize = done.iter().map(|d| d.samples.len()).sum();
    eprintln!(
        "sampling '{}' with '{}': {} of {} samples in {} sweep lines{}{}",
        pattern.name,
        model.name,
        total,
        plan.sample_count(),
        mine.len(),
        shard.map(|s| format!(" (shard {}/{})", s.index, s.count)).unwrap_or_default(),
        if resumed > 0 {
            format!(", {resumed} resumed from {}", checkpoint.display())
        } else {
            String::new()
        }
    );
    let bar = progress_bar(total as u64, resumed as u64);
    let writer = Mutex::new(open_checkpoint(&checkpoint, &key, &done)?);
    let options = SampleOptions {
        max_iterations: args.max_iterations,
        stress: !args.no_stress,
        geometry: args.geometry,
    };
    let started = Instant::now();
    let failed_write = Mutex::new(None);
    let trace = match &args.trace {
        Some(path) => {
            let metadata = TraceMetadata::new("yarnhom rve sample", env!("CARGO_PKG_VERSION"))
                .with_entry("pattern", args.pattern.display().to_string())
                .with_entry("model", &args.model)
                .with_entry("n1d", args.n1d.to_string())
                .with_entry("n2d", args.n2d.to_string());
            Some(TraceSink::open(path, &metadata)?)
        }
        None => None,
    };
    let trace = Mutex::new((trace, 0u64));
    let failed_trace = Mutex::new(None);
    let results = sample_lines(&tile, &plan, &todo, &options, &|line: &LineResult| {
        let mut guard = trace.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
        let (sink, written) = &mut *guard;
        if let Some(sink) = sink.as_mut()
            && let Err(e) = record_line(sink, written, &plan, &pattern, &tile, line)
        {
            failed_trace.lock().unwrap_or_else(std::sync::PoisonError::into_inner).get_or_insert(e);
        }
        drop(guard);
        let record =
            CheckpointLine { line: line.line, samples: line.samples.iter().map(grid_sample).collect() };
        let mut w = writer.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
        if let Err(e) = append(&mut w, &record) {
            failed_write.lock().unwrap_or_else(std::sync::PoisonError::into_inner).get_or_insert(e);
        }
        bar.inc(line.samples.len() as u64);
    });
    bar.finish_and_clear();
    if let Some(e) = failed_write.into_inner().unwrap_or_else(std::sync::PoisonError::into_inner) {
        return Err(e.context(format!("cannot write the checkpoint {}", checkpoint.display())));
    }
    if let Some(e) = failed_trace.into_inner().unwrap_or_else(std::sync::PoisonError::into_inner) {
        return Err(anyhow::Error::new(e).context("cannot write the trace"));
    }
    if let (Some(sink), _) = trace.into_inner().unwrap_or_else(std::sync::PoisonError::into_inner) {
        sink.finish()?;
    }
    let mut samples: Vec<GridSample> = done.into_iter().flat_map(|d| d.samples).collect();
    samples.extend(results.iter().flat_map(|l| l.samples.iter().map(grid_sample)));
    samples.sort_by_key(GridSample::key);
    let grid = Grid {
        pattern: pattern.name.clone(),
        model: model.name.clone(),
        terms: grid_terms(&plan),
        shard,
        samples,
    };
    container::write(&output, &grid, &provenance("rve sample", inputs))?;
    std::fs::remove_file(&checkpoint).with_context(|| format!("cannot remove {}", checkpoint.display()))?;
    let converged = grid.samples.iter().filter(|s| s.converged).count();
    let summary = format!(
        "sampled '{}': {converged} of {} samples converged, {:.1} s this run\n{}",
        pattern.name,
        grid.samples.len(),
        started.elapsed().as_secs_f64(),
        grid.summary()
    );
    if args.trace.as_deref().is_some_and(is_stdout) {
        eprintln!("{summary}");
    } else {
        println!("{summary}");
    }
    eprintln!("wrote {}", output.display());
    Ok(Outcome::Success)
}

/// Writes the samples of a finished line to the trace, numbering them on from `written`.
fn record_line(
    sink: &mut TraceSink,
    written: &mut u64,
    plan: &SamplePlan,
    pattern: &Pattern,
    tile: &RveModel,
    line: &LineResult,
) -> Result<(), TraceError> {
    for s in &line.samples {
        let frame = *written;
        *written += 1;
        sink.write(&RveSample {
            frame,
            time_s: 0.0,
            term: plan.terms[s.term].axes.iter().map(|&a| AXIS_NAMES[a]).collect::<Vec<_>>().join(","),
            grid_index: s.index,
            strain: s.strain,
            converged: s.converged,
            energy_density_j_m2: s.energy_density_j_m2,
            stress: s.stress,
            iterations: s.iterations as u32,
        })?;
        if let (Some(positions), Some(twists)) = (&s.positions_m, &s.edge_twist_rad) {
            sink.write(&yarns_in_order(pattern, tile, positions, twists, frame))?;
        }
    }
    sink.end_frame()
}

/// `K/N` with `0 <= K < N`.
fn parse_shard(text: &str) -> anyhow::Result<GridShard> {
    let parse = || -> Option<GridShard> {
        let (k, n) = text.split_once('/')?;
        let (index, count) = (k.trim().parse().ok()?, n.trim().parse().ok()?);
        (index < count).then_some(GridShard { index, count })
    };
    parse().ok_or_else(|| anyhow::anyhow!("--shard {text}: expected K/N with 0 <= K < N, e.g. 3/16"))
}

fn progress_bar(total: u64, done: u64) -> ProgressBar {
    let bar = ProgressBar::new(total);
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} samples, {elapsed} elapsed, ETA {eta}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    bar.set_position(done);
    bar
}

fn grid_terms(plan: &SamplePlan) -> Vec<GridTerm> {
    plan.terms
        .iter()
        .map(|t| GridTerm { axes: t.axes.iter().map(|&a| a as u8).collect(), values: t.values.clone() })
        .collect()
}

fn grid_sample(s: &SampleOutcome) -> GridSample {
    GridSample {
        term: s.term as u32,
        index: s.index,
        strain: strain_from_values(s.strain),
        converged: s.converged,
        stop_reason: stop_reason(s.stop_reason).into(),
        energy_density_j_m2: s.energy_density_j_m2,
        stress: s.stress,
        iterations: s.iterations as u32,
        positions_m: s.positions_m.clone(),
        edge_twist_rad: s.edge_twist_rad.clone(),
    }
}

/// The lines a checkpoint of this run already holds (none if there is no checkpoint). A
/// checkpoint of another run is an error rather than silently discarded work; a record cut
/// short by a kill is dropped.
fn read_checkpoint(path: &Path, key: &RunKey) -> anyhow::Result<Vec<CheckpointLine>> {
    let file = match File::open(path) {
        Ok(f) => f,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Vec::new()),
        Err(e) => return Err(e).with_context(|| format!("cannot read {}", path.display())),
    };
    let mut reader = BufReader::new(file);
    let stored: RunKey = rmp_serde::from_read(&mut reader)
        .with_context(|| format!("{}: not a yarnhom sampling checkpoint", path.display()))?;
    if &stored != key {
        anyhow::bail!(
            "{}: a checkpoint of another run (pattern, model, plan or options differ); delete it to start over",
            path.display()
        );
    }
    let mut lines = Vec::new();
    while let Ok(line) = rmp_serde::from_read::<_, CheckpointLine>(&mut reader) {
        lines.push(line);
    }
    Ok(lines)
}

/// The checkpoint, written anew with the run's key and the lines already done (a record cut
/// short by a kill is not carried over), open for appending the next lines.
fn open_checkpoint(path: &Path, key: &RunKey, done: &[CheckpointLine]) -> anyhow::Result<BufWriter<File>> {
    let file =
        File::create(path).with_context(|| format!("cannot write the checkpoint {}", path.display()))?;
    let mut writer = BufWriter::new(file);
    append(&mut writer, key)?;
    for line in done {
        append(&mut writer, line)?;
    }
    Ok(writer)
}

/// Append one msgpack record and flush it to the file.
fn append<T: Serialize>(writer: &mut BufWriter<File>, value: &T) -> anyhow::Result<()> {
    rmp_serde::encode::write_named(writer, value)?;
    writer.flush()?;
    writer.get_ref().sync_data()?;
    Ok(())
}
