//! A resumable sampling run, as `yarnhom rve sample` runs the plan of App. A.3.1: the sweep
//! lines of one shard, those a [`Checkpoint`] already holds, the rest solved in parallel
//! ([`sample_lines`]), each finished line appended to the checkpoint and recorded on an
//! optional trace, and the grid assembled in sample order, whatever the thread count, the
//! sharding or the number of times the run was interrupted.

use std::path::Path;
use std::sync::{Mutex, MutexGuard, PoisonError};

use yarnhom_artifacts::{Grid, GridSample, GridShard, Pattern};
use yarnhom_trace::{TraceError, TraceSink};

use crate::RveModel;
use crate::checkpoint::{Checkpoint, CheckpointError, CheckpointLine, RunKey};
use crate::messages::{sample_message, yarns_in_order};
use crate::sample::{
    LineResult, SampleOptions, SampleOutcome, SamplePlan, SweepLine, sample_lines, shard_lines,
};

/// Why a sampling run stopped.
#[derive(Debug, thiserror::Error)]
pub enum SweepError {
    /// The checkpoint could not be read, resumed or appended to.
    #[error(transparent)]
    Checkpoint(#[from] CheckpointError),
    /// The trace could not be written.
    #[error("cannot write the trace: {0}")]
    Trace(#[from] TraceError),
}

/// A sampling run of `plan` (or of one shard of it), resumed from its checkpoint.
#[derive(Debug)]
pub struct Sweep<'a> {
    plan: &'a SamplePlan,
    key: RunKey,
    shard: Option<GridShard>,
    /// The lines of this run (the shard's, or all).
    lines: Vec<SweepLine>,
    /// The lines the checkpoint already holds.
    done: Vec<CheckpointLine>,
    checkpoint: Checkpoint,
}

/// A finished run: the grid, and the checkpoint to remove once the grid is written.
pub struct Swept {
    /// Every sample of the run's lines, resumed or solved, in [`GridSample::key`] order.
    pub grid: Grid,
    /// The run's checkpoint ([`Checkpoint::remove`] it after writing the grid).
    pub checkpoint: Checkpoint,
    /// The trace, back for finishing.
    pub trace: Option<TraceSink>,
}

impl<'a> Sweep<'a> {
    /// The run `key` of `plan` (shard `shard`, if any), resuming the checkpoint at
    /// `checkpoint_path` (see [`Checkpoint::resume`]).
    pub fn resume(
        plan: &'a SamplePlan,
        key: RunKey,
        shard: Option<GridShard>,
        checkpoint_path: &Path,
    ) -> Result<Self, CheckpointError> {
        let (checkpoint, done) = Checkpoint::resume(checkpoint_path, &key)?;
        let lines = match shard {
            Some(s) => shard_lines(&plan.lines(), s.index as usize, s.count as usize),
            None => plan.lines(),
        };
        Ok(Sweep { plan, key, shard, lines, done, checkpoint })
    }

    /// The number of sweep lines of this run.
    pub fn line_count(&self) -> usize {
        self.lines.len()
    }

    /// The number of samples of this run.
    pub fn sample_count(&self) -> usize {
        self.lines.iter().map(|l| l.points.len()).sum()
    }

    /// The number of samples resumed from the checkpoint.
    pub fn resumed_count(&self) -> usize {
        self.done.iter().map(|d| d.samples.len()).sum()
    }

    /// Solve the lines the checkpoint does not hold on `tile` (of `pattern`), appending each
    /// to the checkpoint and, with a `trace`, recording its samples (numbered in completion
    /// order, with their yarns when they kept their geometry). `progress` is told the number of
    /// samples of each finished line, from the thread that finished it. The first error met is
    /// returned when the sweep is done.
    pub fn run(
        self,
        tile: &RveModel,
        pattern: &Pattern,
        options: &SampleOptions,
        trace: Option<TraceSink>,
        progress: &(dyn Fn(usize) + Sync),
    ) -> Result<Swept, SweepError> {
        let todo: Vec<SweepLine> =
            self.lines.iter().filter(|l| !self.done.iter().any(|d| d.line == l.index)).cloned().collect();
        let recorder = Recorder {
            checkpoint: Mutex::new(self.checkpoint),
            trace: Mutex::new((trace, 0)),
            error: Mutex::new(None),
        };
        let results = sample_lines(tile, self.plan, &todo, options, &|line| {
            recorder.record(self.plan, pattern, tile, line);
            progress(line.samples.len());
        });
        if let Some(e) = into_inner(recorder.error) {
            return Err(e);
        }
        let mut samples: Vec<GridSample> = self.done.into_iter().flat_map(|d| d.samples).collect();
        samples.extend(results.iter().flat_map(|l| l.samples.iter().map(SampleOutcome::to_grid_sample)));
        samples.sort_by_key(GridSample::key);
        let grid = Grid {
            pattern: pattern.name.clone(),
            model: self.key.model,
            terms: self.plan.grid_terms(),
            shard: self.shard,
            samples,
        };
        Ok(Swept { grid, checkpoint: into_inner(recorder.checkpoint), trace: into_inner(recorder.trace).0 })
    }
}

/// What the sweep does with each finished line, from whichever thread finished it: record its
/// samples on the trace, append it to the checkpoint. The first error is kept.
struct Recorder {
    checkpoint: Mutex<Checkpoint>,
    /// The trace and the number of samples recorded on it so far.
    trace: Mutex<(Option<TraceSink>, u64)>,
    error: Mutex<Option<SweepError>>,
}

impl Recorder {
    fn record(&self, plan: &SamplePlan, pattern: &Pattern, tile: &RveModel, line: &LineResult) {
        let mut trace = lock(&self.trace);
        let (sink, written) = &mut *trace;
        if let Some(sink) = sink.as_mut()
            && let Err(e) = record_line(sink, written, plan, pattern, tile, line)
        {
            lock(&self.error).get_or_insert(e.into());
        }
        drop(trace);
        let record = CheckpointLine {
            line: line.line,
            samples: line.samples.iter().map(SampleOutcome::to_grid_sample).collect(),
        };
        if let Err(e) = lock(&self.checkpoint).append(&record) {
            lock(&self.error).get_or_insert(e.into());
        }
    }
}

/// A mutex's value, whether or not a thread panicked holding it.
fn lock<T>(mutex: &Mutex<T>) -> MutexGuard<'_, T> {
    mutex.lock().unwrap_or_else(PoisonError::into_inner)
}

fn into_inner<T>(mutex: Mutex<T>) -> T {
    mutex.into_inner().unwrap_or_else(PoisonError::into_inner)
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
        sink.write(&sample_message(plan, s, frame))?;
        if let (Some(positions), Some(twists)) = (&s.positions_m, &s.edge_twist_rad) {
            sink.write(&yarns_in_order(pattern, tile, positions, twists, frame))?;
        }
    }
    sink.end_frame()
}
