//! Where producers and filters write traces: a file (atomic) or standard output (`-`).

use std::io::{BufWriter, IsTerminal, Stdout};

use anyhow::Context;
use yarnhom_artifacts::Pattern;
use yarnhom_rve::assembly::{RveState, world_positions};
use yarnhom_rve::{Placement, RveModel};
use yarnhom_trace::{AtomicFile, NoSeek, Topic, TraceError, TraceMetadata, TraceWriter, YarnFrame};

/// An open trace output.
pub enum TraceSink {
    /// A file, moved into place by [`TraceSink::finish`].
    File(TraceWriter<AtomicFile>, String),
    /// Standard output.
    Stdout(TraceWriter<NoSeek<BufWriter<Stdout>>>),
}

/// Whether `path` names standard output.
pub fn is_stdout(path: &str) -> bool {
    path == "-"
}

impl TraceSink {
    /// Opens `path` (`-`: standard output, refused when it is a terminal) and writes the
    /// `yarnhom` metadata record.
    pub fn open(path: &str, metadata: &TraceMetadata) -> anyhow::Result<Self> {
        let mut sink = if is_stdout(path) {
            anyhow::ensure!(
                !std::io::stdout().is_terminal(),
                "refusing to write a binary trace to the terminal: pipe it (`| yarnhom trace info`) or give a file"
            );
            Self::Stdout(TraceWriter::to_stdout()?)
        } else {
            let writer =
                TraceWriter::create(path).with_context(|| format!("cannot create the trace {path}"))?;
            Self::File(writer, path.to_owned())
        };
        sink.write_metadata(metadata)?;
        Ok(sink)
    }

    /// Writes a message on its topic.
    pub fn write<T: Topic>(&mut self, message: &T) -> Result<(), TraceError> {
        match self {
            Self::File(w, _) => w.write(message),
            Self::Stdout(w) => w.write(message),
        }
    }

    /// Ends a frame: closes the current chunk and flushes it, so that a reader at the other end
    /// of a pipe sees the frame now, and a trace cut short keeps every ended frame.
    pub fn end_frame(&mut self) -> Result<(), TraceError> {
        match self {
            Self::File(w, _) => w.flush(),
            Self::Stdout(w) => w.flush(),
        }
    }

    /// Writes a metadata record.
    pub fn write_metadata(&mut self, metadata: &TraceMetadata) -> Result<(), TraceError> {
        match self {
            Self::File(w, _) => w.write_metadata(metadata),
            Self::Stdout(w) => w.write_metadata(metadata),
        }
    }

    /// Completes the trace; a file is moved into place and named on stderr.
    pub fn finish(self) -> anyhow::Result<()> {
        match self {
            Self::File(w, path) => {
                w.finish().with_context(|| format!("cannot complete the trace {path}"))?;
                eprintln!("wrote {path}");
            }
            Self::Stdout(w) => {
                w.finish().context("cannot complete the trace on stdout")?;
            }
        }
        Ok(())
    }
}

/// Runs `f` with the underlying writer, whatever the output (for the stream filters, which are
/// generic over it).
macro_rules! with_writer {
    ($sink:expr, $w:ident => $body:expr) => {
        match $sink {
            $crate::trace_out::TraceSink::File($w, _) => $body,
            $crate::trace_out::TraceSink::Stdout($w) => $body,
        }
    };
}
pub(crate) use with_writer;

/// The tile's yarns at an iterate, yarn after yarn, for `/yarn/frame`.
pub fn yarn_frame(
    pattern: &Pattern,
    tile: &RveModel,
    placement: &Placement,
    state: &RveState,
    frame: u64,
) -> YarnFrame {
    let twists: Vec<f64> = (0..tile.vertices as u32).map(|v| state.g[tile.twist_dof(v)]).collect();
    yarns_in_order(pattern, tile, &world_positions(tile, placement, state), &twists, frame)
}

/// Per-vertex positions and edge twists of the tile (in the tile's vertex order) as a
/// `/yarn/frame` message, yarn after yarn.
pub fn yarns_in_order(
    pattern: &Pattern,
    tile: &RveModel,
    positions_m: &[[f64; 3]],
    edge_twist_rad: &[f64],
    frame: u64,
) -> YarnFrame {
    let mut message = YarnFrame { yarns: pattern.name.clone(), frame, ..YarnFrame::default() };
    for (yarn, info) in pattern.yarns.iter().zip(&tile.yarns) {
        message.yarn_ranges.push([message.positions_m.len() as u32, info.vertices.len() as u32]);
        for &v in &info.vertices {
            message.positions_m.push(positions_m[v as usize]);
            message.edge_twist_rad.push(edge_twist_rad[v as usize]);
            message.radii_m.push(yarn.radius_m);
        }
    }
    message
}
