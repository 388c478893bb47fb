//! Writing traces.

use std::collections::{BTreeMap, HashMap};
use std::io::{self, BufWriter, Seek, Stdout, Write};
use std::path::Path;

use mcap::records::MessageHeader;
use mcap::write::NoSeek;

use crate::messages::{MESSAGE_ENCODING, SCHEMA_ENCODING, TOPIC_VERSION_KEY, Topic};
use yarnhom_artifacts::AtomicFile;

use crate::{TraceError, TraceMetadata};

/// Default target size of an uncompressed chunk, in bytes (1 MiB, the MCAP library's default).
///
/// Readers hold one chunk in memory at a time, so this bounds their memory use, except that a
/// single message larger than the target gets a chunk of its own.
pub const DEFAULT_CHUNK_SIZE: u64 = 1024 * 1024;

/// Options for [`TraceWriter`]; the constructors of [`TraceWriter`] use the defaults.
#[derive(Debug, Clone)]
pub struct TraceWriterOptions {
    chunk_size: u64,
    compress: bool,
}

impl Default for TraceWriterOptions {
    fn default() -> Self {
        Self { chunk_size: DEFAULT_CHUNK_SIZE, compress: true }
    }
}

impl TraceWriterOptions {
    /// The defaults: zstd compression, chunks of [`DEFAULT_CHUNK_SIZE`] bytes.
    pub fn new() -> Self {
        Self::default()
    }

    /// Sets the target uncompressed chunk size in bytes. A chunk is closed once it grows past
    /// this size. When writing to a non-seekable stream, the current chunk is buffered in
    /// memory, so this also bounds the writer's memory.
    #[must_use]
    pub fn chunk_size(mut self, bytes: u64) -> Self {
        self.chunk_size = bytes;
        self
    }

    /// Enables (the default) or disables zstd compression of chunks.
    #[must_use]
    pub fn compression(mut self, zstd: bool) -> Self {
        self.compress = zstd;
        self
    }

    fn mcap_options(&self, seeking: bool) -> mcap::WriteOptions {
        mcap::WriteOptions::new()
            .compression(self.compress.then_some(mcap::Compression::Zstd))
            .chunk_size(Some(self.chunk_size))
            .library(format!("yarnhom-trace/{}; {}", env!("CARGO_PKG_VERSION"), mcap::LIBRARY_IDENTIFIER))
            .disable_seeking(!seeking)
    }

    /// Starts a trace file at `path`, written atomically: the data goes to a temporary file in
    /// the same directory, which [`TraceWriter::finish`] renames to `path`. If the writer is
    /// dropped without `finish`, the temporary file is deleted and `path` is left untouched.
    pub fn create(&self, path: impl AsRef<Path>) -> Result<TraceWriter<AtomicFile>, TraceError> {
        let file = AtomicFile::create(path.as_ref())?;
        let mut writer = self.seekable(file)?;
        writer.on_finish = Some(AtomicFile::commit);
        Ok(writer)
    }

    /// Starts a trace on any seekable output (a [`std::fs::File`], an [`io::Cursor`], ...).
    pub fn seekable<W: Write + Seek>(&self, out: W) -> Result<TraceWriter<W>, TraceError> {
        TraceWriter::from_mcap_options(out, self.mcap_options(true))
    }

    /// Starts a trace on a non-seekable output such as a pipe or socket. Each chunk is buffered
    /// in memory and written whole; wrap unbuffered outputs in a [`BufWriter`] so the few small
    /// records outside chunks are not written one syscall each.
    pub fn non_seeking<O: Write>(&self, out: O) -> Result<TraceWriter<NoSeek<O>>, TraceError> {
        TraceWriter::from_mcap_options(NoSeek::new(out), self.mcap_options(false))
    }

    /// Starts a trace on standard output. Nothing else may write to standard output while the
    /// trace is being written.
    pub fn to_stdout(&self) -> Result<TraceWriter<NoSeek<BufWriter<Stdout>>>, TraceError> {
        self.non_seeking(BufWriter::new(io::stdout()))
    }
}

/// Per-topic state of a registered channel.
#[derive(Debug, Clone, Copy)]
struct ChannelState {
    id: u16,
    /// Messages written on the channel so far (the sequence of frameless messages).
    count: u32,
}

/// Writes a yarnhom trace as MCAP.
///
/// Schemas and channels are registered lazily, on the first message of each topic. Call
/// [`finish`](Self::finish) to complete the trace: it writes the summary section and reports any
/// error. Dropping the writer without `finish` abandons the trace: a file started with
/// [`create`](Self::create) is deleted, and a stream is left truncated, so that a reader reports
/// an error at its end rather than mistaking it for a complete trace.
pub struct TraceWriter<W: Write + Seek> {
    /// `Some` until `finish` or `drop` takes it; both consume the writer.
    mcap: Option<mcap::Writer<W>>,
    channels: BTreeMap<&'static str, ChannelState>,
    /// Output channel of each copied input channel, by (source, input channel id).
    copied_channels: HashMap<(usize, u16), u16>,
    /// Reused MessagePack buffer.
    buf: Vec<u8>,
    /// Runs on the flushed output once the MCAP is complete (the atomic rename of `create`).
    on_finish: Option<fn(&mut W) -> io::Result<()>>,
}

impl TraceWriter<AtomicFile> {
    /// Starts a trace file at `path` with default options, written atomically; see
    /// [`TraceWriterOptions::create`].
    pub fn create(path: impl AsRef<Path>) -> Result<Self, TraceError> {
        TraceWriterOptions::default().create(path)
    }
}

impl TraceWriter<NoSeek<BufWriter<Stdout>>> {
    /// Starts a trace on standard output with default options; see
    /// [`TraceWriterOptions::to_stdout`].
    pub fn to_stdout() -> Result<Self, TraceError> {
        TraceWriterOptions::default().to_stdout()
    }
}

impl<O: Write> TraceWriter<NoSeek<O>> {
    /// Starts a trace on a non-seekable output with default options; see
    /// [`TraceWriterOptions::non_seeking`].
    pub fn non_seeking(out: O) -> Result<Self, TraceError> {
        TraceWriterOptions::default().non_seeking(out)
    }
}

impl<W: Write + Seek> TraceWriter<W> {
    /// Starts a trace on a seekable output with default options; see
    /// [`TraceWriterOptions::seekable`].
    pub fn new(out: W) -> Result<Self, TraceError> {
        TraceWriterOptions::default().seekable(out)
    }

    fn from_mcap_options(out: W, options: mcap::WriteOptions) -> Result<Self, TraceError> {
        Ok(Self {
            mcap: Some(options.create(out)?),
            channels: BTreeMap::new(),
            copied_channels: HashMap::new(),
            buf: Vec::new(),
            on_finish: None,
        })
    }

    fn mcap(&mut self) -> &mut mcap::Writer<W> {
        match self.mcap.as_mut() {
            Some(mcap) => mcap,
            None => unreachable!("the MCAP writer is only taken by finish() and drop()"),
        }
    }

    /// Writes the `yarnhom` metadata record (producer and free key/values). Usually written
    /// once, first; MCAP closes the current chunk before a metadata record.
    pub fn write_metadata(&mut self, metadata: &TraceMetadata) -> Result<(), TraceError> {
        let record = metadata.to_record()?;
        self.write_metadata_record(&record)
    }

    /// Copies a metadata record read from another trace (a filter's input).
    pub fn write_metadata_record(&mut self, record: &mcap::records::Metadata) -> Result<(), TraceError> {
        self.mcap().write_metadata(record)?;
        Ok(())
    }

    /// Copies a message read from another trace (a filter's input) without decoding it, with
    /// its channel and schema. `source` tells inputs apart when several are copied into one
    /// trace (`trace merge`), since their channel ids may collide; channels with identical
    /// content (topic, encoding, metadata, schema) share one output channel.
    pub fn write_message(&mut self, source: usize, message: &mcap::Message<'_>) -> Result<(), TraceError> {
        let input = &message.channel;
        let channel_id = match self.copied_channels.get(&(source, input.id)) {
            Some(&id) => id,
            None => {
                let mcap = self.mcap();
                let schema_id = match &input.schema {
                    Some(schema) => mcap.add_schema(&schema.name, &schema.encoding, &schema.data)?,
                    None => 0,
                };
                let id =
                    mcap.add_channel(schema_id, &input.topic, &input.message_encoding, &input.metadata)?;
                self.copied_channels.insert((source, input.id), id);
                id
            }
        };
        let header = MessageHeader {
            channel_id,
            sequence: message.sequence,
            log_time: message.log_time,
            publish_time: message.publish_time,
        };
        self.mcap().write_to_known_channel(&header, &message.data)?;
        Ok(())
    }

    /// Closes the current chunk and flushes the output, so that a reader at the other end of a
    /// pipe sees every message written so far. Frequent flushes make chunks smaller and
    /// compression worse.
    pub fn flush(&mut self) -> Result<(), TraceError> {
        self.mcap().flush()?;
        Ok(())
    }

    /// Completes the trace (last chunk, summary section, footer), flushes the output and, for
    /// [`create`](Self::create), moves the file into place. Returns the output.
    pub fn finish(mut self) -> Result<W, TraceError> {
        let Some(mut mcap) = self.mcap.take() else {
            unreachable!("the MCAP writer is only taken by finish() and drop()")
        };
        if let Err(err) = mcap.finish() {
            // Skip the MCAP writer's own finish-on-drop: the trace is abandoned.
            drop(mcap.into_inner());
            return Err(err.into());
        }
        let mut out = mcap.into_inner();
        out.flush()?;
        if let Some(on_finish) = self.on_finish {
            on_finish(&mut out)?;
        }
        Ok(out)
    }

    fn channel<T: Topic>(&mut self) -> Result<&mut ChannelState, TraceError> {
        if !self.channels.contains_key(T::TOPIC) {
            let schema = serde_json::to_vec(&T::root_schema())
                .map_err(|source| TraceError::Schema { topic: T::TOPIC, source })?;
            let metadata = BTreeMap::from([(TOPIC_VERSION_KEY.to_owned(), T::VERSION.to_string())]);
            let mcap = self.mcap();
            let schema_id = mcap.add_schema(T::SCHEMA_NAME, SCHEMA_ENCODING, &schema)?;
            let id = mcap.add_channel(schema_id, T::TOPIC, MESSAGE_ENCODING, &metadata)?;
            self.channels.insert(T::TOPIC, ChannelState { id, count: 0 });
        }
        match self.channels.get_mut(T::TOPIC) {
            Some(state) => Ok(state),
            None => unreachable!("the channel was registered above"),
        }
    }

    /// Writes a message on its topic (a mesh topology before the mesh's frames, frames,
    /// metrics, ...; see the crate documentation for the topics).
    pub fn write<T: Topic>(&mut self, message: &T) -> Result<(), TraceError> {
        let log_time = match message.time_s() {
            Some(time_s) => seconds_to_ns(T::TOPIC, time_s)?,
            None => 0,
        };
        self.buf.clear();
        rmp_serde::encode::write_named(&mut self.buf, message)
            .map_err(|source| TraceError::Encode { topic: T::TOPIC, source })?;
        let channel = self.channel::<T>()?;
        // MCAP sequences are 32-bit: the frame number wraps (the message keeps all 64 bits).
        let sequence = match message.frame() {
            Some(frame) => frame as u32,
            None => channel.count,
        };
        channel.count = channel.count.wrapping_add(1);
        let header = MessageHeader { channel_id: channel.id, sequence, log_time, publish_time: log_time };
        let Some(mcap) = self.mcap.as_mut() else {
            unreachable!("the MCAP writer is only taken by finish() and drop()")
        };
        mcap.write_to_known_channel(&header, &self.buf)?;
        Ok(())
    }
}

impl<W: Write + Seek> Drop for TraceWriter<W> {
    /// Abandons an unfinished trace without writing its summary (see [`TraceWriter`]).
    fn drop(&mut self) {
        if let Some(mcap) = self.mcap.take() {
            drop(mcap.into_inner());
        }
    }
}

/// Converts simulated seconds to MCAP nanoseconds, rounding to the nearest nanosecond.
fn seconds_to_ns(topic: &'static str, time_s: f64) -> Result<u64, TraceError> {
    /// 2⁶⁴, the first value that no longer fits a `u64`.
    const LIMIT: f64 = 18_446_744_073_709_551_616.0;
    let ns = (time_s * 1e9).round();
    if time_s.is_finite() && time_s >= 0.0 && ns < LIMIT {
        // In range by the check above, so the cast is exact for the rounded value.
        Ok(ns as u64)
    } else {
        Err(TraceError::InvalidTime { topic, time_s })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn seconds_convert_to_rounded_nanoseconds() {
        let ns = |t| seconds_to_ns("/t", t).ok();
        assert_eq!(ns(0.0), Some(0));
        assert_eq!(ns(-0.0), Some(0));
        assert_eq!(ns(1.5), Some(1_500_000_000));
        assert_eq!(ns(0.1), Some(100_000_000));
        assert_eq!(ns(1e-10), Some(0));
        assert_eq!(ns(18_000_000_000.0), Some(18_000_000_000_000_000_000));
        assert_eq!(ns(-1e-12), None);
        assert_eq!(ns(f64::NAN), None);
        assert_eq!(ns(f64::INFINITY), None);
        assert_eq!(ns(18_446_744_074.0), None);
        let err = seconds_to_ns("/mesh/frame", -1.0).expect_err("negative time");
        assert!(err.to_string().contains("/mesh/frame"), "{err}");
    }
}
