//! The checkpoint of a sampling run, so that a killed `yarnhom rve sample` resumes where it
//! stopped: a file of msgpack records, first the [`RunKey`] of the run, then one
//! [`CheckpointLine`] per finished sweep line, each flushed and synced as it is appended.
//!
//! A checkpoint is resumed only by the same run (same pattern content, yarn model, plan and
//! options); one of another run is an error rather than silently discarded work. A record cut
//! short by a kill is dropped. On resuming, the checkpoint is first rewritten (atomically) with
//! the lines it holds, so a half-written record never stays in the middle of the file.

use std::fs::{File, OpenOptions};
use std::io::{self, BufReader, BufWriter, Write};
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use yarnhom_artifacts::{AtomicFile, GridSample};

use crate::sample::{SampleOptions, SamplePlan};

/// What identifies a run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunKey {
    /// Content hash of the pattern.
    pub pattern_hash: String,
    /// Name of the yarn model.
    pub model: String,
    /// Values per 1D term.
    pub n1d: usize,
    /// Values per axis of the 2D terms.
    pub n2d: usize,
    /// `[lower, upper]` of each axis of each term, in plan order.
    pub ranges: Vec<[f64; 2]>,
    /// `(K, N)` of `--shard K/N`.
    pub shard: Option<(u32, u32)>,
    /// Whether samples keep their geometry.
    pub geometry: bool,
    /// Whether samples have their stress.
    pub stress: bool,
    /// Newton iteration limit.
    pub max_iterations: usize,
}

impl RunKey {
    /// The key of sampling `plan` (made with `n1d`, `n2d` values) on the pattern of content
    /// hash `pattern_hash` with the model `model`.
    pub fn new(
        pattern_hash: &str,
        model: &str,
        plan: &SamplePlan,
        [n1d, n2d]: [usize; 2],
        shard: Option<(u32, u32)>,
        options: &SampleOptions,
    ) -> Self {
        RunKey {
            pattern_hash: pattern_hash.into(),
            model: model.into(),
            n1d,
            n2d,
            ranges: plan.terms.iter().flat_map(|t| t.values.iter().map(|v| [v[0], v[v.len() - 1]])).collect(),
            shard,
            geometry: options.geometry,
            stress: options.stress,
            max_iterations: options.max_iterations,
        }
    }
}

/// One finished sweep line.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CheckpointLine {
    /// [`crate::sample::SweepLine::index`].
    pub line: usize,
    /// Its samples, in the line's order.
    pub samples: Vec<GridSample>,
}

/// Why a checkpoint cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum CheckpointError {
    /// Reading or writing it failed.
    #[error("{}: {source}", path.display())]
    Io {
        /// The checkpoint.
        path: PathBuf,
        /// What failed.
        source: io::Error,
    },
    /// The file does not start with a run key.
    #[error("{}: not a yarnhom sampling checkpoint", path.display())]
    NotACheckpoint {
        /// The file.
        path: PathBuf,
    },
    /// The checkpoint belongs to another run.
    #[error(
        "{}: a checkpoint of another run (pattern, model, plan or options differ); delete it to start over",
        path.display()
    )]
    OtherRun {
        /// The checkpoint.
        path: PathBuf,
    },
}

/// An open checkpoint, appending finished lines.
#[derive(Debug)]
pub struct Checkpoint {
    path: PathBuf,
    writer: BufWriter<File>,
}

impl Checkpoint {
    /// Opens the checkpoint of the run `key` at `path` for appending, and returns the lines it
    /// already holds (none when there is no file yet).
    pub fn resume(path: &Path, key: &RunKey) -> Result<(Self, Vec<CheckpointLine>), CheckpointError> {
        let io_error = |source| CheckpointError::Io { path: path.to_path_buf(), source };
        let done = read_lines(path, key)?;
        rewrite(path, key, &done).map_err(io_error)?;
        let file = OpenOptions::new().append(true).open(path).map_err(io_error)?;
        Ok((Checkpoint { path: path.to_path_buf(), writer: BufWriter::new(file) }, done))
    }

    /// Appends a finished line and syncs it to disk.
    pub fn append(&mut self, line: &CheckpointLine) -> Result<(), CheckpointError> {
        append_record(&mut self.writer, line)
            .and_then(|()| self.writer.get_ref().sync_data())
            .map_err(|source| CheckpointError::Io { path: self.path.clone(), source })
    }

    /// Deletes the checkpoint (the run is complete and its grid written).
    pub fn remove(self) -> Result<(), CheckpointError> {
        drop(self.writer);
        std::fs::remove_file(&self.path).map_err(|source| CheckpointError::Io { path: self.path, source })
    }
}

/// The lines of the checkpoint of `key` at `path`, if there is one.
fn read_lines(path: &Path, key: &RunKey) -> Result<Vec<CheckpointLine>, CheckpointError> {
    let file = match File::open(path) {
        Ok(f) => f,
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(Vec::new()),
        Err(source) => return Err(CheckpointError::Io { path: path.to_path_buf(), source }),
    };
    let mut reader = BufReader::new(file);
    let stored: RunKey = rmp_serde::from_read(&mut reader)
        .map_err(|_| CheckpointError::NotACheckpoint { path: path.to_path_buf() })?;
    if &stored != key {
        return Err(CheckpointError::OtherRun { path: path.to_path_buf() });
    }
    let mut lines = Vec::new();
    while let Ok(line) = rmp_serde::from_read::<_, CheckpointLine>(&mut reader) {
        lines.push(line);
    }
    Ok(lines)
}

/// Writes the checkpoint anew, atomically: the key, then `done`.
fn rewrite(path: &Path, key: &RunKey, done: &[CheckpointLine]) -> io::Result<()> {
    let mut file = AtomicFile::create(path)?;
    append_record(&mut file, key)?;
    for line in done {
        append_record(&mut file, line)?;
    }
    file.commit()
}

/// Appends one msgpack record and flushes it.
fn append_record<W: Write, T: Serialize>(writer: &mut W, value: &T) -> io::Result<()> {
    rmp_serde::encode::write_named(writer, value).map_err(io::Error::other)?;
    writer.flush()
}
