//! Streaming the records of a trace: messages (undecoded) and metadata, from any [`Read`]
//! source, with truncation reported as such.

use std::collections::HashMap;
use std::io::{self, Read};
use std::sync::Arc;

use mcap::records::{Metadata, Record};
use mcap::sans_io::{LinearReadEvent, LinearReader};

use crate::TraceError;
use crate::error::Truncation;

/// One record of a trace, in file order.
#[derive(Debug, Clone, PartialEq)]
pub enum TraceRecord {
    /// A message, linked to its channel and schema, payload not decoded.
    Message(mcap::Message<'static>),
    /// An MCAP metadata record (the `yarnhom` record or any other producer's).
    Metadata(Metadata),
}

/// How far a [`RecordReader`] got.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ReadProgress {
    /// Bytes read from the source so far.
    pub bytes_read: u64,
    /// Bytes read when the last record was yielded.
    pub bytes_at_last_record: u64,
    /// Messages yielded so far.
    pub messages: u64,
}

/// Streams the messages and metadata records of a trace from a file, standard input or a
/// pipe, without seeking. Memory is bounded by the largest record and the decompression window,
/// independently of the trace's length.
///
/// A trace that ends early (a killed producer, a partial copy) yields every message that could
/// be read in full, then [`TraceError::Truncated`] saying how many bytes were lost; any other
/// error in the container ends the iteration too. The summary section is read through without
/// being checked against the data.
pub struct RecordReader<R: Read> {
    source: R,
    reader: LinearReader,
    schemas: HashMap<u16, Arc<mcap::Schema<'static>>>,
    channels: HashMap<u16, Arc<mcap::Channel<'static>>>,
    progress: ReadProgress,
    past_data_end: bool,
    done: bool,
}

impl<R: Read> RecordReader<R> {
    /// Starts reading a trace from `source`.
    pub fn new(source: R) -> Self {
        Self {
            source,
            reader: LinearReader::new(),
            schemas: HashMap::new(),
            channels: HashMap::new(),
            progress: ReadProgress::default(),
            past_data_end: false,
            done: false,
        }
    }

    /// How far the reader got.
    pub fn progress(&self) -> ReadProgress {
        self.progress
    }

    /// Fills the linear reader with up to `need` bytes; returns the number read (0 at the end).
    fn fill(&mut self, need: usize) -> io::Result<usize> {
        let buffer = self.reader.insert(need);
        let read = loop {
            match self.source.read(buffer) {
                Ok(n) => break n,
                Err(err) if err.kind() == io::ErrorKind::Interrupted => continue,
                Err(err) => return Err(err),
            }
        };
        self.reader.notify_read(read);
        self.progress.bytes_read += read as u64;
        Ok(read)
    }

    /// The next record, `Ok(None)` at a clean end.
    fn next_record(&mut self) -> Result<Option<TraceRecord>, TraceError> {
        loop {
            let (opcode, data) = match self.reader.next_event() {
                None => return Ok(None),
                Some(Err(mcap::McapError::UnexpectedEof)) => return Err(self.truncated()),
                Some(Err(err)) => return Err(err.into()),
                Some(Ok(LinearReadEvent::ReadRequest(need))) => {
                    self.fill(need)?;
                    continue;
                }
                Some(Ok(LinearReadEvent::Record { opcode, data })) => (opcode, data),
            };
            // Records after the data end (the summary) repeat schemas and channels: skip them.
            if self.past_data_end {
                continue;
            }
            match mcap::parse_record(opcode, data)? {
                Record::DataEnd(_) => self.past_data_end = true,
                Record::Schema { header, data } => {
                    let schema = mcap::Schema {
                        id: header.id,
                        name: header.name,
                        encoding: header.encoding,
                        data: data.into_owned().into(),
                    };
                    self.schemas.insert(header.id, Arc::new(schema));
                }
                Record::Channel(channel) => {
                    let schema = match channel.schema_id {
                        0 => None,
                        id => Some(
                            self.schemas
                                .get(&id)
                                .cloned()
                                .ok_or_else(|| mcap::McapError::UnknownSchema(channel.topic.clone(), id))?,
                        ),
                    };
                    let linked = mcap::Channel {
                        id: channel.id,
                        topic: channel.topic,
                        schema,
                        message_encoding: channel.message_encoding,
                        metadata: channel.metadata,
                    };
                    self.channels.insert(channel.id, Arc::new(linked));
                }
                Record::Message { header, data } => {
                    let channel = self
                        .channels
                        .get(&header.channel_id)
                        .cloned()
                        .ok_or(mcap::McapError::UnknownChannel(header.sequence, header.channel_id))?;
                    self.progress.messages += 1;
                    self.progress.bytes_at_last_record = self.progress.bytes_read;
                    return Ok(Some(TraceRecord::Message(mcap::Message {
                        channel,
                        sequence: header.sequence,
                        log_time: header.log_time,
                        publish_time: header.publish_time,
                        data: data.into_owned().into(),
                    })));
                }
                Record::Metadata(metadata) => {
                    self.progress.bytes_at_last_record = self.progress.bytes_read;
                    return Ok(Some(TraceRecord::Metadata(metadata)));
                }
                _ => {}
            }
        }
    }

    fn truncated(&self) -> TraceError {
        TraceError::Truncated(Truncation {
            messages_recovered: self.progress.messages,
            bytes_read: self.progress.bytes_read,
            bytes_lost: self.progress.bytes_read - self.progress.bytes_at_last_record,
        })
    }
}

impl<R: Read> Iterator for RecordReader<R> {
    type Item = Result<TraceRecord, TraceError>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.done {
            return None;
        }
        let record = self.next_record().transpose();
        if !matches!(record, Some(Ok(_))) {
            self.done = true;
        }
        record
    }
}

#[cfg(test)]
mod tests {
    use std::io::Cursor;

    use super::*;
    use crate::{MeshFrame, MeshTopology, TraceMetadata, TraceWriterOptions};

    fn trace(frames: u64, chunk_size: u64) -> Vec<u8> {
        let options = TraceWriterOptions::new().chunk_size(chunk_size);
        let mut writer = options.seekable(Cursor::new(Vec::new())).expect("writer");
        writer.write_metadata(&TraceMetadata::new("test", "1")).expect("metadata");
        writer
            .write(&MeshTopology {
                triangles: vec![[0, 1, 2]],
                rest_positions_m: vec![[0.0; 3]; 3],
                name: "m".into(),
            })
            .expect("topology");
        for frame in 0..frames {
            let positions_m = vec![[frame as f64, 0.0, 0.0]; 3];
            writer
                .write(&MeshFrame { mesh: "m".into(), frame, time_s: frame as f64, positions_m })
                .expect("frame");
        }
        writer.finish().expect("finish").into_inner()
    }

    fn read_all(bytes: &[u8]) -> (usize, usize, Option<TraceError>) {
        let (mut messages, mut metadata, mut error) = (0, 0, None);
        for record in RecordReader::new(bytes) {
            match record {
                Ok(TraceRecord::Message(_)) => messages += 1,
                Ok(TraceRecord::Metadata(_)) => metadata += 1,
                Err(err) => error = Some(err),
            }
        }
        (messages, metadata, error)
    }

    #[test]
    fn a_complete_trace_yields_every_message_and_metadata_once() {
        let (messages, metadata, error) = read_all(&trace(20, 200));
        assert_eq!((messages, metadata), (21, 1));
        assert!(error.is_none(), "{error:?}");
    }

    #[test]
    fn a_truncated_trace_yields_the_messages_before_the_cut_and_says_what_was_lost() {
        let full = trace(50, 300);
        let mut last = usize::MAX;
        for cut in [full.len() - 1, full.len() * 3 / 4, full.len() / 2, full.len() / 4] {
            let (messages, _, error) = read_all(&full[..cut]);
            assert!(messages <= last, "fewer bytes cannot give more messages");
            last = messages;
            match error {
                Some(TraceError::Truncated(Truncation { messages_recovered, bytes_read, bytes_lost })) => {
                    assert_eq!(messages_recovered as usize, messages);
                    assert_eq!(bytes_read as usize, cut);
                    assert!(bytes_lost as usize <= cut);
                }
                other => panic!("cut at {cut} of {}: expected Truncated, got {other:?}", full.len()),
            }
        }
        // Only the end magic is missing: every message is there.
        assert_eq!(read_all(&full[..full.len() - 1]).0, 51);
    }
}
