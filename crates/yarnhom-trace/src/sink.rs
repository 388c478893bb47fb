//! Where a producer or a filter writes its trace: a file (written atomically) or standard
//! output (`-`), behind one type.

use std::io::{BufWriter, IsTerminal, Read, Stdout};
use std::path::Path;

use mcap::write::NoSeek;
use yarnhom_artifacts::AtomicFile;

use crate::filter::{self, FilterStats, Selection};
use crate::{RecordReader, TraceError, TraceMetadata, TraceWriter, messages::Topic};

/// The name that means standard output (or input).
pub const STDIO: &str = "-";

/// Whether `path` names standard output (or input).
pub fn is_stdio(path: &str) -> bool {
    path == STDIO
}

/// An open trace output.
pub enum TraceSink {
    /// A file, moved into place by [`TraceSink::finish`].
    File(TraceWriter<AtomicFile>),
    /// Standard output.
    Stdout(TraceWriter<NoSeek<BufWriter<Stdout>>>),
}

/// Runs `$body` with the writer `$w`, whatever the output.
macro_rules! dispatch {
    ($sink:expr, $w:ident => $body:expr) => {
        match $sink {
            TraceSink::File($w) => $body,
            TraceSink::Stdout($w) => $body,
        }
    };
}

impl TraceSink {
    /// Opens `path` (`-`: standard output, refused when it is a terminal) and writes the
    /// `yarnhom` metadata record.
    pub fn open(path: &str, metadata: &TraceMetadata) -> Result<Self, TraceError> {
        let mut sink = if is_stdio(path) {
            if std::io::stdout().is_terminal() {
                return Err(TraceError::Terminal);
            }
            Self::Stdout(TraceWriter::to_stdout()?)
        } else {
            Self::File(TraceWriter::create(path)?)
        };
        sink.write_metadata(metadata)?;
        Ok(sink)
    }

    /// Writes a message on its topic.
    pub fn write<T: Topic>(&mut self, message: &T) -> Result<(), TraceError> {
        dispatch!(self, w => w.write(message))
    }

    /// Ends a frame: closes the current chunk and flushes it, so that a reader at the other end
    /// of a pipe sees the frame now, and a trace cut short keeps every ended frame.
    pub fn end_frame(&mut self) -> Result<(), TraceError> {
        dispatch!(self, w => w.flush())
    }

    /// Writes a metadata record.
    pub fn write_metadata(&mut self, metadata: &TraceMetadata) -> Result<(), TraceError> {
        dispatch!(self, w => w.write_metadata(metadata))
    }

    /// Copies the records of `input` that `selection` keeps ([`filter::filter`]).
    pub fn filter<R: Read>(
        &mut self,
        input: RecordReader<R>,
        selection: &Selection,
    ) -> Result<FilterStats, TraceError> {
        dispatch!(self, w => filter::filter(input, w, selection))
    }

    /// Interleaves `inputs` by time ([`filter::merge`]).
    pub fn merge<R: Read>(&mut self, inputs: Vec<RecordReader<R>>) -> Result<FilterStats, TraceError> {
        dispatch!(self, w => filter::merge(inputs, w))
    }

    /// Completes the trace; a file is moved into place.
    pub fn finish(self) -> Result<(), TraceError> {
        dispatch!(self, w => w.finish().map(drop))
    }
}

/// Opens the bytes of a trace: a file, or standard input for `-`.
pub fn open_source(path: &str) -> Result<Box<dyn Read>, TraceError> {
    Ok(if is_stdio(path) {
        Box::new(std::io::stdin().lock())
    } else {
        let file = std::fs::File::open(Path::new(path))
            .map_err(|source| TraceError::Open { path: path.into(), source })?;
        Box::new(std::io::BufReader::new(file))
    })
}

/// Opens a trace input's records: a file, or standard input for `-`.
pub fn open_records(path: &str) -> Result<RecordReader<Box<dyn Read>>, TraceError> {
    Ok(RecordReader::new(open_source(path)?))
}
