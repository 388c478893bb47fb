//! Stream filters over traces: select, decimate, merge, and a summary (`info`).
//!
//! Every filter reads records one at a time from [`RecordReader`]s and copies the kept messages
//! undecoded (channels, schemas and metadata records included) to a [`TraceWriter`], so memory
//! stays bounded by a chunk whatever the trace's length, and topics this crate does not know
//! pass through untouched. A truncated input is not an error for a filter: everything that could
//! be read is written, and the [`Truncation`] is reported in the returned statistics.

use std::collections::BTreeMap;
use std::io::{Read, Seek, Write};
use std::ops::Range;

use serde::{Deserialize, Serialize};

use crate::error::Truncation;
use crate::messages::MESSAGE_ENCODING;
use crate::records::{RecordReader, TraceRecord};
use crate::{TraceError, TraceWriter};

/// Which messages [`filter`] keeps. The default keeps everything.
///
/// A message is kept when its topic is selected and, if it has a `frame` field (every yarnhom
/// message except topologies), its frame and time pass the frame range, the time range and the
/// decimation. Messages without a frame (mesh and tet topologies) are kept whenever their topic
/// is, so that the kept frames can still be drawn.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Selection {
    /// Topics kept: exact names, or prefixes ending in `*` (`/mesh/*`); empty keeps every topic.
    pub topics: Vec<String>,
    /// Frames kept, half-open.
    pub frames: Option<Range<u64>>,
    /// Simulated times kept (seconds, half-open), read from the message's log time.
    pub time_s: Option<Range<f64>>,
    /// Keep only frames that are multiples of this (`trace decimate --every N`).
    pub every: Option<u64>,
}

/// `A:B` as the half-open range `A..B` of [`Selection::frames`] or [`Selection::time_s`];
/// either end may be left out (`10:`, `:2.5`) for `lowest` or `highest`. An empty range is
/// refused.
pub fn parse_range<T>(text: &str, lowest: T, highest: T) -> Result<Range<T>, String>
where
    T: std::str::FromStr + PartialOrd + Copy,
{
    let (a, b) = text.split_once(':').ok_or("expected A:B (either may be left out, e.g. 10: or :2.5)")?;
    let parse = |part: &str, default: T| -> Result<T, String> {
        if part.trim().is_empty() {
            return Ok(default);
        }
        part.trim().parse().map_err(|_| format!("'{part}' is not a valid bound"))
    };
    let (start, end) = (parse(a, lowest)?, parse(b, highest)?);
    if start < end { Ok(start..end) } else { Err("the range is empty (A must be below B)".into()) }
}

impl Selection {
    /// Whether a message on `topic` passes the topic filter.
    pub fn keeps_topic(&self, topic: &str) -> bool {
        self.topics.is_empty()
            || self.topics.iter().any(|pattern| match pattern.strip_suffix('*') {
                Some(prefix) => topic.starts_with(prefix),
                None => topic == pattern,
            })
    }

    /// Whether `message` is kept.
    pub fn keeps(&self, message: &mcap::Message<'_>) -> bool {
        if !self.keeps_topic(&message.channel.topic) {
            return false;
        }
        let Some(frame) = message_frame(message) else {
            return true;
        };
        let time_s = message.log_time as f64 * 1e-9;
        self.frames.as_ref().is_none_or(|range| range.contains(&frame))
            && self.time_s.as_ref().is_none_or(|range| range.contains(&time_s))
            && self.every.is_none_or(|every| frame.is_multiple_of(every))
    }
}

/// The `frame` field of a msgpack message, if it has one (other fields are skipped unread).
pub fn message_frame(message: &mcap::Message<'_>) -> Option<u64> {
    #[derive(Deserialize)]
    struct FrameField {
        frame: Option<u64>,
    }
    if message.channel.message_encoding != MESSAGE_ENCODING {
        return None;
    }
    rmp_serde::from_slice::<FrameField>(&message.data).ok()?.frame
}

/// What a filter read and wrote.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct FilterStats {
    /// Messages read from the inputs.
    pub messages_read: u64,
    /// Messages written.
    pub messages_written: u64,
    /// Metadata records copied.
    pub metadata_records: u64,
    /// Inputs that ended early, by input index, with what was lost.
    pub truncated_inputs: Vec<(usize, Truncation)>,
}

/// Reads the next record of `input` (input number `source`), handing a truncation over to
/// `stats` as the end of that input.
fn next_record<R: Read>(
    input: &mut RecordReader<R>,
    source: usize,
    stats: &mut FilterStats,
) -> Result<Option<TraceRecord>, TraceError> {
    match input.next() {
        None => Ok(None),
        Some(Ok(record)) => Ok(Some(record)),
        Some(Err(TraceError::Truncated(truncation))) => {
            stats.truncated_inputs.push((source, truncation));
            Ok(None)
        }
        Some(Err(err)) => Err(err),
    }
}

/// Copies the records of `input` that `selection` keeps to `output` (`trace select`,
/// `trace decimate`). Metadata records are always copied.
pub fn filter<R: Read, W: Write + Seek>(
    mut input: RecordReader<R>,
    output: &mut TraceWriter<W>,
    selection: &Selection,
) -> Result<FilterStats, TraceError> {
    let mut stats = FilterStats::default();
    while let Some(message) = next_message(&mut input, 0, output, &mut stats)? {
        if selection.keeps(&message) {
            output.write_message(0, &message)?;
            stats.messages_written += 1;
        }
    }
    Ok(stats)
}

/// Merges traces into one, interleaving messages by log time (ties keep the order of the
/// inputs, then of each input), holding one message per input in memory (`trace merge`).
/// Metadata records are copied as they are met. Channels with identical content are shared,
/// so two traces of a mesh with the same name become one mesh's frames: give meshes distinct
/// names when merging different simulations.
pub fn merge<R: Read, W: Write + Seek>(
    inputs: Vec<RecordReader<R>>,
    output: &mut TraceWriter<W>,
) -> Result<FilterStats, TraceError> {
    let mut stats = FilterStats::default();
    let mut inputs = inputs;
    let mut heads = Vec::with_capacity(inputs.len());
    for (source, input) in inputs.iter_mut().enumerate() {
        heads.push(next_message(input, source, output, &mut stats)?);
    }
    while let Some(source) = earliest(&heads) {
        if let Some(message) = heads[source].take() {
            output.write_message(source, &message)?;
            stats.messages_written += 1;
        }
        heads[source] = next_message(&mut inputs[source], source, output, &mut stats)?;
    }
    Ok(stats)
}

/// The input whose pending message has the smallest log time (the first such input on ties).
fn earliest(heads: &[Option<mcap::Message<'static>>]) -> Option<usize> {
    heads
        .iter()
        .enumerate()
        .filter_map(|(source, head)| head.as_ref().map(|m| (m.log_time, source)))
        .min()
        .map(|(_, source)| source)
}

/// The next message of input number `source`, copying the metadata records met on the way.
fn next_message<R: Read, W: Write + Seek>(
    input: &mut RecordReader<R>,
    source: usize,
    output: &mut TraceWriter<W>,
    stats: &mut FilterStats,
) -> Result<Option<mcap::Message<'static>>, TraceError> {
    while let Some(record) = next_record(input, source, stats)? {
        match record {
            TraceRecord::Metadata(metadata) => {
                output.write_metadata_record(&metadata)?;
                stats.metadata_records += 1;
            }
            TraceRecord::Message(message) => {
                stats.messages_read += 1;
                return Ok(Some(message));
            }
        }
    }
    Ok(None)
}

/// A summary of one topic of a trace.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct TopicInfo {
    /// Schema name (`yarnhom.MeshFrame.v1`), empty for a schemaless channel.
    pub schema: String,
    /// Message encoding.
    pub encoding: String,
    /// Messages on the topic.
    pub messages: u64,
    /// Payload bytes (uncompressed) of those messages.
    pub payload_bytes: u64,
    /// Smallest and largest log time, in seconds.
    pub time_s: Option<[f64; 2]>,
    /// Smallest and largest `frame` field, for messages that have one.
    pub frames: Option<[u64; 2]>,
}

/// A summary of a whole trace (`trace info`).
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct TraceInfo {
    /// Per-topic summaries, by topic name.
    pub topics: BTreeMap<String, TopicInfo>,
    /// Metadata records, by record name, in file order.
    pub metadata: Vec<(String, BTreeMap<String, String>)>,
    /// Messages in the trace.
    pub messages: u64,
    /// Bytes read (the trace's size on disk or on the pipe).
    pub bytes: u64,
    /// Set if the trace ended early.
    pub truncation: Option<Truncation>,
}

/// Reads a whole trace and summarizes it, one record at a time.
pub fn info<R: Read>(mut input: RecordReader<R>) -> Result<TraceInfo, TraceError> {
    let mut summary = TraceInfo::default();
    let mut stats = FilterStats::default();
    while let Some(record) = next_record(&mut input, 0, &mut stats)? {
        match record {
            TraceRecord::Metadata(metadata) => summary.metadata.push((metadata.name, metadata.metadata)),
            TraceRecord::Message(message) => {
                summary.messages += 1;
                let topic = summary.topics.entry(message.channel.topic.clone()).or_default();
                if topic.messages == 0 {
                    topic.schema =
                        message.channel.schema.as_ref().map(|s| s.name.clone()).unwrap_or_default();
                    topic.encoding = message.channel.message_encoding.clone();
                }
                topic.messages += 1;
                topic.payload_bytes += message.data.len() as u64;
                let time_s = message.log_time as f64 * 1e-9;
                topic.time_s = Some(match topic.time_s {
                    Some([lo, hi]) => [lo.min(time_s), hi.max(time_s)],
                    None => [time_s, time_s],
                });
                if let Some(frame) = message_frame(&message) {
                    topic.frames = Some(match topic.frames {
                        Some([lo, hi]) => [lo.min(frame), hi.max(frame)],
                        None => [frame, frame],
                    });
                }
            }
        }
    }
    summary.bytes = input.progress().bytes_read;
    summary.truncation = stats.truncated_inputs.first().map(|(_, t)| *t);
    Ok(summary)
}

impl std::fmt::Display for TraceInfo {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(f, "{} messages on {} topics, {} bytes", self.messages, self.topics.len(), self.bytes)?;
        for (name, metadata) in &self.metadata {
            writeln!(f, "metadata '{name}':")?;
            for (key, value) in metadata {
                writeln!(f, "  {key}: {value}")?;
            }
        }
        for (topic, info) in &self.topics {
            write!(
                f,
                "{topic:<20} {:>8} msgs {:>12} B  {:<28}",
                info.messages, info.payload_bytes, info.schema
            )?;
            if let Some([lo, hi]) = info.frames {
                write!(f, " frames {lo}..={hi}")?;
            }
            if let Some([lo, hi]) = info.time_s {
                write!(f, " t {lo:.4}..={hi:.4} s")?;
            }
            writeln!(f)?;
        }
        if let Some(truncation) = &self.truncation {
            writeln!(f, "WARNING: {truncation}")?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use std::io::Cursor;

    use super::*;

    #[test]
    fn ranges_parse_with_open_ends_and_reject_empty_or_bad_ones() {
        assert_eq!(parse_range("2:5", 0, u64::MAX), Ok(2..5));
        assert_eq!(parse_range(":5", 0, u64::MAX), Ok(0..5));
        assert_eq!(parse_range("7:", 0, u64::MAX), Ok(7..u64::MAX));
        assert_eq!(parse_range("0.5:1.5", 0.0, f64::INFINITY), Ok(0.5..1.5));
        assert!(parse_range("5:5", 0, u64::MAX).is_err());
        assert!(parse_range("5", 0, u64::MAX).is_err());
        assert!(parse_range("a:3", 0, u64::MAX).is_err());
        assert!(parse_range("-1:3", 0, u64::MAX).is_err());
    }
    use crate::{
        MeshFrame, MeshTopology, Scalars, TraceMessage, TraceMetadata, TraceReader, TraceWriterOptions,
        YarnFrame, YarnNodes,
    };

    /// A trace of one mesh `name` with `frames` frames at `dt` seconds, plus metrics.
    fn trace(name: &str, frames: u64, dt: f64) -> Vec<u8> {
        let options = TraceWriterOptions::new().chunk_size(512);
        let mut writer = options.seekable(Cursor::new(Vec::new())).expect("writer");
        writer.write_metadata(&TraceMetadata::new("test", "1").with_entry("mesh", name)).expect("metadata");
        let topology = MeshTopology {
            triangles: vec![[0, 1, 2]],
            rest_positions_m: vec![[0.0; 3]; 3],
            name: name.into(),
        };
        writer.write(&topology).expect("topology");
        for frame in 0..frames {
            let time_s = frame as f64 * dt;
            let positions_m = vec![[time_s, 0.0, 0.0]; 3];
            writer.write(&MeshFrame { mesh: name.into(), frame, time_s, positions_m }).expect("frame");
            let values = BTreeMap::from([("energy_j".to_owned(), time_s)]);
            writer.write(&Scalars { frame, time_s, values }).expect("scalars");
        }
        writer.finish().expect("finish").into_inner()
    }

    fn run_filter(input: &[u8], selection: &Selection) -> (Vec<TraceMessage>, FilterStats) {
        let mut writer = TraceWriter::new(Cursor::new(Vec::new())).expect("writer");
        let stats = filter(RecordReader::new(input), &mut writer, selection).expect("filter");
        let bytes = writer.finish().expect("finish").into_inner();
        let messages = TraceReader::new(bytes.as_slice()).collect::<Result<Vec<_>, _>>().expect("read back");
        (messages, stats)
    }

    fn frames_of(messages: &[TraceMessage]) -> Vec<u64> {
        messages
            .iter()
            .filter_map(|m| match m {
                TraceMessage::Frame(f) => Some(f.frame),
                _ => None,
            })
            .collect()
    }

    #[test]
    fn decimation_keeps_every_nth_frame_and_the_topology() {
        let (messages, stats) =
            run_filter(&trace("cloth", 10, 0.1), &Selection { every: Some(4), ..Default::default() });
        assert_eq!(frames_of(&messages), [0, 4, 8]);
        assert!(matches!(messages[0], TraceMessage::Topology(_)));
        assert_eq!(stats.messages_read, 21);
        assert_eq!(stats.messages_written, 1 + 2 * 3);
        assert_eq!(stats.metadata_records, 1);
    }

    #[test]
    fn selection_by_topic_frames_and_time() {
        let input = trace("cloth", 10, 0.1);
        let by_topic = Selection { topics: vec!["/mesh/*".into()], ..Default::default() };
        let (messages, _) = run_filter(&input, &by_topic);
        assert!(messages.iter().all(|m| !matches!(m, TraceMessage::Scalars(_))));
        assert_eq!(frames_of(&messages).len(), 10);
        let (messages, _) = run_filter(&input, &Selection { frames: Some(2..5), ..Default::default() });
        assert_eq!(frames_of(&messages), [2, 3, 4]);
        let (messages, _) = run_filter(&input, &Selection { time_s: Some(0.25..0.55), ..Default::default() });
        assert_eq!(frames_of(&messages), [3, 4, 5]);
    }

    #[test]
    fn merge_interleaves_by_time_and_keeps_both_meshes() {
        let (a, b) = (trace("a", 5, 0.2), trace("b", 10, 0.1));
        let mut writer = TraceWriter::new(Cursor::new(Vec::new())).expect("writer");
        let stats =
            merge(vec![RecordReader::new(a.as_slice()), RecordReader::new(b.as_slice())], &mut writer)
                .expect("merge");
        assert_eq!(stats.messages_written, 11 + 21);
        assert_eq!(stats.metadata_records, 2);
        let bytes = writer.finish().expect("finish").into_inner();
        let mut last_time = 0.0;
        let mut meshes = BTreeMap::new();
        for message in TraceReader::new(bytes.as_slice()) {
            if let TraceMessage::Frame(frame) = message.expect("message") {
                assert!(frame.time_s >= last_time, "frames out of time order");
                last_time = frame.time_s;
                *meshes.entry(frame.mesh).or_insert(0) += 1;
            }
        }
        assert_eq!(meshes, BTreeMap::from([("a".to_owned(), 5), ("b".to_owned(), 10)]));
    }

    #[test]
    fn a_truncated_input_is_filtered_up_to_the_cut_and_reported() {
        let input = trace("cloth", 200, 0.01);
        let cut = &input[..input.len() / 2];
        let (messages, stats) = run_filter(cut, &Selection::default());
        assert_eq!(stats.truncated_inputs.len(), 1);
        assert_eq!(stats.truncated_inputs[0].1.messages_recovered, stats.messages_read);
        assert_eq!(messages.len() as u64, stats.messages_written);
        assert!(stats.messages_written > 0 && stats.messages_written < 401);
    }

    #[test]
    fn yarn_nodes_are_kept_like_topologies_and_counted_by_info() {
        let mut writer = TraceWriter::new(Cursor::new(Vec::new())).expect("writer");
        let nodes = YarnNodes {
            yarns: "swatch".into(),
            rest_positions_m: vec![[0.0; 3], [1e-3, 0.0, 0.0]],
            node_type: vec![YarnNodes::HANDLE, YarnNodes::NORMAL],
            edges: vec![[0, 1]],
        };
        writer.write(&nodes).expect("nodes");
        for frame in 0..6 {
            let positions_m = vec![[0.0, 0.0, frame as f64 * 1e-3], [1e-3, 0.0, 0.0]];
            let time_s = 0.1 * frame as f64;
            let yarns = YarnFrame {
                yarns: "swatch".into(),
                frame,
                time_s,
                positions_m,
                radii_m: vec![1e-4; 2],
                yarn_ranges: vec![[0, 2]],
                ..Default::default()
            };
            writer.write(&yarns).expect("frame");
        }
        let input = writer.finish().expect("finish").into_inner();
        for selection in [
            Selection { every: Some(4), ..Default::default() },
            Selection { frames: Some(3..5), ..Default::default() },
            Selection { time_s: Some(0.25..1.0), ..Default::default() },
            Selection { topics: vec!["/yarn/*".into()], ..Default::default() },
        ] {
            let (messages, _) = run_filter(&input, &selection);
            assert_eq!(messages[0], TraceMessage::YarnNodes(nodes.clone()), "{selection:?}");
        }
        let info = info(RecordReader::new(input.as_slice())).expect("info");
        let topic = &info.topics["/yarn/nodes"];
        assert_eq!((topic.messages, topic.frames, topic.schema.as_str()), (1, None, "yarnhom.YarnNodes.v1"));
    }

    #[test]
    fn info_counts_topics_frames_and_times() {
        let info = info(RecordReader::new(trace("cloth", 10, 0.1).as_slice())).expect("info");
        assert_eq!(info.messages, 21);
        let frames = &info.topics["/mesh/frame"];
        assert_eq!(frames.messages, 10);
        assert_eq!(frames.frames, Some([0, 9]));
        assert_eq!(frames.schema, "yarnhom.MeshFrame.v1");
        let [t0, t1] = frames.time_s.expect("times");
        assert!((t0 - 0.0).abs() < 1e-9 && (t1 - 0.9).abs() < 1e-9);
        assert_eq!(info.topics["/mesh/topology"].frames, None);
        assert_eq!(info.metadata.len(), 1);
        assert!(info.truncation.is_none());
        assert!(info.to_string().contains("/mesh/frame"));
    }
}
