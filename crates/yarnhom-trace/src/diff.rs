//! The difference of two traces (`yarnhom diff A.mcap B.mcap`), generic over topics and fields.
//!
//! Both traces are streamed together, merged by log time (the latest read so far in each), and
//! never loaded whole. Each message
//! is decoded without its Rust type (a msgpack payload into a JSON-like value; another encoding,
//! or an undecodable payload, is kept as bytes) and matched with the other trace's by its key:
//! the topic, its name (the first string field among `mesh`, `name`, `yarns`) and its `frame`
//! field; messages with the same key (no `frame` field, or several messages per frame) are
//! matched in the order they come, so that without a frame the key is the message's ordinal
//! among those of its topic and name. Only messages whose match has not come yet are buffered
//! (about [`DEFAULT_PENDING_LIMIT_BYTES`] of encoded payload per trace at most; beyond that the
//! oldest are given up and count as unmatched).
//!
//! Matched messages are compared recursively: numbers with the [`Tolerance`], summarized per
//! topic and field path (object keys joined by `.`, array indices left out, e.g. `positions_m`
//! or `values.kinetic_energy_j`) as a [`FieldDiff`] whose `worst_index` is the frame (or the
//! ordinal) of the largest difference and whose `worst_at` says where it is, e.g.
//! `frame 3, mesh cloth, positions_m[12][2]`; strings, booleans, nulls, array lengths and key
//! sets must be equal (structural). Fields whose name starts with `wall_` (wall-clock times,
//! which differ between runs of the same computation) are summarized apart and do not count.
//! Messages in one trace only, topics in one trace only, channels with other schemas or
//! encodings, and a trace that is truncated or damaged are differences too.

use std::collections::{BTreeMap, HashMap, VecDeque};
use std::io::Read;

use serde::Serialize;
use serde_json::Value;
use yarnhom_artifacts::diff::{FieldDiff, FieldDiffBuilder, Tolerance};

use crate::messages::MESSAGE_ENCODING;
use crate::records::{RecordReader, TraceRecord};

/// Encoded payload bytes buffered per trace while waiting for the matching message of the other
/// trace (256 MiB); see [`diff_traces_with_limit`].
pub const DEFAULT_PENDING_LIMIT_BYTES: usize = 256 << 20;

/// Examples kept per kind of finding.
const EXAMPLES: usize = 5;

/// The string fields that name a message, in order of preference.
const NAME_FIELDS: [&str; 3] = ["mesh", "name", "yarns"];

/// The two traces, as indices.
const FIRST: usize = 0;
/// See [`FIRST`].
const SECOND: usize = 1;
/// The traces named in reports.
const ORDINALS: [&str; 2] = ["first", "second"];

/// Messages of a topic found in one trace only.
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct Unmatched {
    /// How many.
    pub count: usize,
    /// The first few, by key (e.g. `frame 3, mesh cloth`).
    pub examples: Vec<String>,
}

impl Unmatched {
    fn add(&mut self, example: String) {
        self.count += 1;
        if self.examples.len() < EXAMPLES {
            self.examples.push(example);
        }
    }
}

/// The comparison of one topic.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TopicDiff {
    /// The topic, e.g. `/mesh/frame`.
    pub topic: String,
    /// Messages found in both traces and compared.
    pub matched: usize,
    /// Messages found in the first trace only.
    pub only_in_first: Unmatched,
    /// Messages found in the second trace only.
    pub only_in_second: Unmatched,
    /// The first few structural differences of matched messages (strings, booleans, array
    /// lengths, key sets, value types) and of the channels (schema, encoding).
    pub structural: Vec<String>,
    /// All structural differences, counted.
    pub structural_count: usize,
    /// Numeric fields: `worst_index` is the frame (or, without one, the ordinal) of the message
    /// with the largest difference, `worst_at` the message and element.
    pub fields: Vec<FieldDiff>,
    /// Wall-clock fields (named `wall_*`), compared like `fields` but not deciding equality.
    pub wall_clock: Vec<FieldDiff>,
}

impl TopicDiff {
    /// Whether the topic is equal within the tolerance in both traces.
    pub fn equal(&self) -> bool {
        self.only_in_first.count == 0
            && self.only_in_second.count == 0
            && self.structural_count == 0
            && self.fields.iter().all(|f| f.outside == 0)
    }

    /// The topic's lines of a human report.
    fn report_lines(&self) -> Vec<String> {
        let only = |u: &Unmatched| format!("{} messages, e.g. {}", u.count, u.examples.join("; "));
        if self.matched == 0 && (self.only_in_first.count == 0) != (self.only_in_second.count == 0) {
            let (ordinal, u) = if self.only_in_first.count > 0 {
                ("first", &self.only_in_first)
            } else {
                ("second", &self.only_in_second)
            };
            return vec![format!("  {}: only in the {ordinal} trace: {}", self.topic, only(u))];
        }
        let mut lines = vec![format!("  {}: {} messages matched", self.topic, self.matched)];
        lines.extend(self.structural.iter().map(|s| format!("    structure: {s}")));
        if self.structural_count > self.structural.len() {
            let more = self.structural_count - self.structural.len();
            lines.push(format!("    structure: ... and {more} more"));
        }
        for (ordinal, u) in [("first", &self.only_in_first), ("second", &self.only_in_second)] {
            if u.count > 0 {
                lines.push(format!("    only in the {ordinal} trace: {}", only(u)));
            }
        }
        lines.extend(self.fields.iter().map(|f| format!("    {}", f.report_line())));
        lines.extend(
            self.wall_clock.iter().map(|f| format!("    (wall clock, not compared) {}", f.report_line())),
        );
        lines
    }
}

/// The difference between two traces.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TraceDiff {
    /// Always `trace`.
    pub kind: String,
    /// Differences of the traces as wholes: a trace truncated or damaged.
    pub structural: Vec<String>,
    /// Per topic, in name order.
    pub topics: Vec<TopicDiff>,
    /// Remarks that do not count by themselves.
    pub notes: Vec<String>,
}

impl TraceDiff {
    /// Whether the two traces are equal within the tolerance.
    pub fn equal(&self) -> bool {
        self.structural.is_empty() && self.topics.iter().all(TopicDiff::equal)
    }

    /// A human report, one line per finding.
    pub fn report(&self) -> String {
        let verdict = if self.equal() { "equal within tolerance" } else { "DIFFERENT" };
        let mut lines = vec![format!("{} {verdict}", self.kind)];
        lines.extend(self.structural.iter().map(|s| format!("  structure: {s}")));
        for topic in &self.topics {
            lines.extend(topic.report_lines());
        }
        lines.extend(self.notes.iter().map(|s| format!("  note: {s}")));
        lines.join("\n")
    }

    /// The topic named `topic`, if either trace has it.
    pub fn topic(&self, topic: &str) -> Option<&TopicDiff> {
        self.topics.iter().find(|t| t.topic == topic)
    }
}

/// Compare two traces read from `first` and `second` (see the module documentation), buffering
/// at most [`DEFAULT_PENDING_LIMIT_BYTES`] per trace.
pub fn diff_traces<A: Read, B: Read>(first: A, second: B, tol: Tolerance) -> TraceDiff {
    diff_traces_with_limit(first, second, tol, DEFAULT_PENDING_LIMIT_BYTES)
}

/// [`diff_traces`] buffering at most `pending_limit_bytes` of encoded payload per trace (and at
/// least the latest message): when more messages wait for their match, the oldest are given up
/// and count as unmatched. Traces of the same producer keep the buffer nearly empty, as their
/// messages come in the same order.
pub fn diff_traces_with_limit<A: Read, B: Read>(
    first: A,
    second: B,
    tol: Tolerance,
    pending_limit_bytes: usize,
) -> TraceDiff {
    let mut state = State::new(tol, pending_limit_bytes);
    let (mut a, mut b) = (Stream::new(first), Stream::new(second));
    loop {
        let side = match (a.peek_watermark(), b.peek_watermark()) {
            (None, None) => break,
            (Some(ta), Some(tb)) if ta == tb => state.side_at_equal_times([a.read, b.read]),
            (Some(ta), Some(tb)) if tb < ta => SECOND,
            (Some(_), _) => FIRST,
            (None, Some(_)) => SECOND,
        };
        let (message, other_done) = if side == FIRST {
            (a.take(), b.peek_watermark().is_none())
        } else {
            (b.take(), a.peek_watermark().is_none())
        };
        if let Some(message) = message {
            state.receive(side, &message, other_done);
        }
    }
    state.finish([a.end(), b.end()])
}

/// A trace read one message ahead.
struct Stream<R: Read> {
    reader: RecordReader<R>,
    next: Option<mcap::Message<'static>>,
    /// The latest log time read so far, the next message's included.
    watermark: u64,
    read: usize,
    error: Option<String>,
    done: bool,
}

impl<R: Read> Stream<R> {
    fn new(source: R) -> Self {
        let reader = RecordReader::new(source);
        Self { reader, next: None, watermark: 0, read: 0, error: None, done: false }
    }

    /// How far the trace has come: the latest log time up to its next message (a producer may
    /// stamp a message earlier than the one before it); `None` at the end or after an error.
    fn peek_watermark(&mut self) -> Option<u64> {
        while self.next.is_none() && !self.done {
            match self.reader.next() {
                Some(Ok(TraceRecord::Message(message))) => {
                    self.watermark = self.watermark.max(message.log_time);
                    self.next = Some(message);
                }
                Some(Ok(TraceRecord::Metadata(_))) => {}
                Some(Err(err)) => {
                    self.error = Some(err.to_string());
                    self.done = true;
                }
                None => self.done = true,
            }
        }
        self.next.as_ref().map(|_| self.watermark)
    }

    fn take(&mut self) -> Option<mcap::Message<'static>> {
        let message = self.next.take();
        self.read += usize::from(message.is_some());
        message
    }

    /// Why the trace ended early, if it did: the error after the messages read.
    fn end(self) -> Option<String> {
        let read = self.read;
        self.error.map(|err| format!("truncated or damaged after {read} messages: {err}"))
    }
}

/// The field that names a message (one of [`NAME_FIELDS`]) and its value.
type Name = Option<(&'static str, String)>;

/// How messages are matched across the traces.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
struct Key {
    topic: String,
    name: Name,
    frame: Option<u64>,
}

impl Key {
    /// The message for reports, e.g. `frame 3, mesh cloth`, `frame 3 (message 9)` (when the
    /// ordinal among the messages of its topic and name is not the frame) or `message 2`.
    fn describe(&self, ordinal: u64) -> String {
        let mut text = match self.frame {
            Some(frame) if frame == ordinal => format!("frame {frame}"),
            Some(frame) => format!("frame {frame} (message {ordinal})"),
            None => format!("message {ordinal}"),
        };
        if let Some((field, name)) = &self.name {
            text.push_str(&format!(", {field} {name}"));
        }
        text
    }
}

/// A message's content.
#[derive(Debug)]
enum Payload {
    /// A msgpack payload, decoded.
    Fields(Value),
    /// Any other payload, with its encoding (and why it was not decoded).
    Raw { encoding: String, bytes: Vec<u8> },
}

/// The content of a message and its key.
fn decode(message: &mcap::Message<'_>) -> (Key, Payload) {
    let topic = message.channel.topic.clone();
    let encoding = &message.channel.message_encoding;
    let decoded = (encoding == MESSAGE_ENCODING).then(|| rmp_serde::from_slice::<Value>(&message.data));
    let payload = match decoded {
        Some(Ok(value)) => Payload::Fields(value),
        Some(Err(err)) => Payload::Raw {
            encoding: format!("{encoding} (undecodable: {err})"),
            bytes: message.data.to_vec(),
        },
        None => Payload::Raw { encoding: encoding.clone(), bytes: message.data.to_vec() },
    };
    let Payload::Fields(Value::Object(fields)) = &payload else {
        return (Key { topic, name: None, frame: None }, payload);
    };
    let name = NAME_FIELDS.iter().find_map(|&f| Some((f, fields.get(f)?.as_str()?.to_string())));
    let frame = fields.get("frame").and_then(Value::as_u64);
    (Key { topic, name, frame }, payload)
}

/// A message waiting for its match.
#[derive(Debug)]
struct Buffered {
    id: u64,
    ordinal: u64,
    payload: Payload,
    size: usize,
}

/// The messages of one trace waiting for their match, by key in arrival order.
#[derive(Debug, Default)]
struct Pending {
    queues: HashMap<Key, VecDeque<Buffered>>,
    /// Arrival order of all waiting messages (ids increase), for giving up the oldest.
    order: BTreeMap<u64, Key>,
    next_id: u64,
    bytes: usize,
}

impl Pending {
    fn push(&mut self, key: Key, ordinal: u64, payload: Payload, size: usize) {
        let id = self.next_id;
        self.next_id += 1;
        self.bytes += size;
        self.order.insert(id, key.clone());
        self.queues.entry(key).or_default().push_back(Buffered { id, ordinal, payload, size });
    }

    /// The oldest waiting message of `key`.
    fn take(&mut self, key: &Key) -> Option<Buffered> {
        let queue = self.queues.get_mut(key)?;
        let buffered = queue.pop_front()?;
        if queue.is_empty() {
            self.queues.remove(key);
        }
        self.order.remove(&buffered.id);
        self.bytes -= buffered.size;
        Some(buffered)
    }

    /// The oldest waiting message of all.
    fn pop_oldest(&mut self) -> Option<(Key, Buffered)> {
        let (_, key) = self.order.first_key_value()?;
        let key = key.clone();
        let buffered = self.take(&key)?;
        Some((key, buffered))
    }
}

/// What is known of a topic so far.
#[derive(Debug, Default)]
struct TopicState {
    matched: usize,
    only: [Unmatched; 2],
    /// Schema name and message encoding of the topic's channel in each trace.
    channel: [Option<String>; 2],
    structural: Vec<String>,
    structural_count: usize,
    fields: BTreeMap<String, FieldDiffBuilder>,
    wall_clock: BTreeMap<String, FieldDiffBuilder>,
}

impl TopicState {
    fn structural(&mut self, finding: String) {
        self.structural_count += 1;
        if self.structural.len() < EXAMPLES {
            self.structural.push(finding);
        }
    }

    fn finish(mut self, topic: String) -> TopicDiff {
        if let [Some(a), Some(b)] = &self.channel
            && a != b
        {
            self.structural(format!("channel: {a} vs {b}"));
        }
        let [only_in_first, only_in_second] = self.only;
        TopicDiff {
            topic,
            matched: self.matched,
            only_in_first,
            only_in_second,
            structural: self.structural,
            structural_count: self.structural_count,
            fields: self.fields.into_values().map(FieldDiffBuilder::finish).collect(),
            wall_clock: self.wall_clock.into_values().map(FieldDiffBuilder::finish).collect(),
        }
    }
}

/// The comparison in progress.
struct State {
    tol: Tolerance,
    limit: usize,
    pending: [Pending; 2],
    /// Messages received per trace, per topic and name (the ordinal of the next one).
    ordinals: [HashMap<(String, Name), u64>; 2],
    topics: BTreeMap<String, TopicState>,
    given_up: usize,
}

impl State {
    fn new(tol: Tolerance, limit: usize) -> Self {
        Self {
            tol,
            limit,
            pending: Default::default(),
            ordinals: Default::default(),
            topics: BTreeMap::new(),
            given_up: 0,
        }
    }

    fn topic(&mut self, topic: &str) -> &mut TopicState {
        if !self.topics.contains_key(topic) {
            self.topics.insert(topic.to_string(), TopicState::default());
        }
        match self.topics.get_mut(topic) {
            Some(state) => state,
            None => unreachable!("inserted above"),
        }
    }

    /// Which trace to read from when both have come as far: the one that the other's waiting
    /// messages wait for, else the one that has read fewer messages (`read`), else the first.
    fn side_at_equal_times(&self, read: [usize; 2]) -> usize {
        let waiting = [FIRST, SECOND].map(|side| !self.pending[side].order.is_empty());
        match waiting {
            [true, false] => SECOND,
            [false, true] => FIRST,
            _ if read[SECOND] < read[FIRST] => SECOND,
            _ => FIRST,
        }
    }

    /// Take one message of trace `side`: compare it with its match from the other trace if that
    /// came already, else keep it for its match (unless the other trace has ended).
    fn receive(&mut self, side: usize, message: &mcap::Message<'_>, other_done: bool) {
        let (key, payload) = decode(message);
        let ordinal = self.next_ordinal(side, &key);
        let seen = &mut self.topic(&key.topic).channel[side];
        if seen.is_none() {
            let channel = &message.channel;
            let schema = channel.schema.as_ref().map_or("no schema", |s| s.name.as_str());
            *seen = Some(format!("schema {schema}, encoding {}", channel.message_encoding));
        }
        let other = 1 - side;
        if let Some(matched) = self.pending[other].take(&key) {
            let (first, second) =
                if side == FIRST { (payload, matched.payload) } else { (matched.payload, payload) };
            let first_ordinal = if side == FIRST { ordinal } else { matched.ordinal };
            self.compare(&key, first_ordinal, &first, &second);
        } else if other_done {
            // Nothing waiting can be matched any more: report it in order, then this one.
            while let Some((key, buffered)) = self.pending[side].pop_oldest() {
                self.topic(&key.topic).only[side].add(key.describe(buffered.ordinal));
            }
            self.topic(&key.topic).only[side].add(key.describe(ordinal));
        } else {
            self.pending[side].push(key, ordinal, payload, message.data.len());
            // Keep at least the message just received: its match may be the next message read.
            while self.pending[side].bytes > self.limit && self.pending[side].order.len() > 1 {
                let Some((key, buffered)) = self.pending[side].pop_oldest() else { break };
                self.given_up += 1;
                self.topic(&key.topic).only[side].add(key.describe(buffered.ordinal));
            }
        }
    }

    fn next_ordinal(&mut self, side: usize, key: &Key) -> u64 {
        let counter = self.ordinals[side].entry((key.topic.clone(), key.name.clone())).or_insert(0);
        *counter += 1;
        *counter - 1
    }

    /// Compare two matched messages.
    fn compare(&mut self, key: &Key, ordinal: u64, first: &Payload, second: &Payload) {
        let tol = self.tol;
        let topic = self.topic(&key.topic);
        topic.matched += 1;
        let message = key.describe(ordinal);
        let index = usize::try_from(key.frame.unwrap_or(ordinal)).unwrap_or(usize::MAX);
        match (first, second) {
            (Payload::Fields(a), Payload::Fields(b)) => {
                let mut comparison = Comparison { topic, tol, message, index, path: Vec::new() };
                comparison.values("", a, b);
            }
            (Payload::Raw { encoding: ea, bytes: a }, Payload::Raw { encoding: eb, bytes: b }) => {
                if ea != eb || a != b {
                    topic.structural(format!("{message}: payloads ({ea}; {eb}) differ"));
                }
            }
            (Payload::Fields(_), Payload::Raw { encoding, .. }) => {
                topic.structural(format!("{message}: decoded in the first trace, {encoding} in the second"));
            }
            (Payload::Raw { encoding, .. }, Payload::Fields(_)) => {
                topic.structural(format!("{message}: {encoding} in the first trace, decoded in the second"));
            }
        }
    }

    /// The summary, once both traces have ended (`ends`: why each ended early, if it did).
    fn finish(mut self, ends: [Option<String>; 2]) -> TraceDiff {
        for side in [FIRST, SECOND] {
            let mut pending = std::mem::take(&mut self.pending[side]);
            while let Some((key, buffered)) = pending.pop_oldest() {
                self.topic(&key.topic).only[side].add(key.describe(buffered.ordinal));
            }
        }
        let structural = ends
            .iter()
            .zip(ORDINALS)
            .filter_map(|(end, ordinal)| Some(format!("the {ordinal} trace is {}", end.as_ref()?)))
            .collect();
        let mut notes = Vec::new();
        if self.given_up > 0 {
            notes.push(format!(
                "{} messages waited too long for their match (over {} bytes buffered) and count as unmatched",
                self.given_up, self.limit
            ));
        }
        let topics = self.topics.into_iter().map(|(topic, state)| state.finish(topic)).collect();
        TraceDiff { kind: "trace".into(), structural, topics, notes }
    }
}

/// One step of the path to a value: an object key or an array index.
#[derive(Debug, Clone)]
enum Step {
    Key(String),
    Index(usize),
}

/// The comparison of two matched messages.
struct Comparison<'a> {
    topic: &'a mut TopicState,
    tol: Tolerance,
    /// The message, e.g. `frame 3, mesh cloth`.
    message: String,
    /// Its frame (or ordinal), the `worst_index` of its fields.
    index: usize,
    path: Vec<Step>,
}

/// The element at `path`, e.g. `positions_m[12][2]`.
fn element(path: &[Step]) -> String {
    let mut text = String::new();
    for step in path {
        match step {
            Step::Key(key) if text.is_empty() => text.push_str(key),
            Step::Key(key) => text.push_str(&format!(".{key}")),
            Step::Index(i) => text.push_str(&format!("[{i}]")),
        }
    }
    text
}

impl Comparison<'_> {
    fn structural(&mut self, what: String) {
        let finding = format!("{}: {}: {what}", self.message, element(&self.path));
        self.topic.structural(finding);
    }

    /// Compare two values of the field `field`.
    fn values(&mut self, field: &str, a: &Value, b: &Value) {
        match (a, b) {
            (Value::Number(x), Value::Number(y)) => {
                self.number(field, x.as_f64().unwrap_or(f64::NAN), y.as_f64().unwrap_or(f64::NAN));
            }
            (Value::Array(x), Value::Array(y)) if x.len() != y.len() => {
                self.structural(format!("{} vs {} elements", x.len(), y.len()));
            }
            (Value::Array(x), Value::Array(y)) => {
                for (i, (u, v)) in x.iter().zip(y).enumerate() {
                    self.path.push(Step::Index(i));
                    self.values(field, u, v);
                    self.path.pop();
                }
            }
            (Value::Object(x), Value::Object(y)) => self.objects(field, x, y),
            (x, y) if x == y => {}
            (x, y) => {
                let what = format!("{} vs {}", describe_value(x), describe_value(y));
                self.structural(what);
            }
        }
    }

    /// Compare two objects: their key sets exactly, then the values of the common keys.
    fn objects(
        &mut self,
        field: &str,
        a: &serde_json::Map<String, Value>,
        b: &serde_json::Map<String, Value>,
    ) {
        for (ordinal, (x, y)) in ORDINALS.iter().zip([(a, b), (b, a)]) {
            let only: Vec<&str> = x.keys().filter(|k| !y.contains_key(*k)).map(String::as_str).collect();
            if !only.is_empty() {
                self.structural(format!("keys only in the {ordinal} trace: {}", only.join(", ")));
            }
        }
        for (key, x) in a {
            let Some(y) = b.get(key) else { continue };
            let child = if field.is_empty() { key.clone() } else { format!("{field}.{key}") };
            self.path.push(Step::Key(key.clone()));
            self.values(&child, x, y);
            self.path.pop();
        }
    }

    /// Compare two numbers of the field `field`.
    fn number(&mut self, field: &str, a: f64, b: f64) {
        let last = field.rsplit('.').next().unwrap_or(field);
        let fields =
            if last.starts_with("wall_") { &mut self.topic.wall_clock } else { &mut self.topic.fields };
        if !fields.contains_key(field) {
            fields.insert(field.to_string(), FieldDiffBuilder::new(field));
        }
        let Some(builder) = fields.get_mut(field) else { return };
        if builder.push(&[a], &[b], self.tol) {
            let at = format!("{}, {}", self.message, element(&self.path));
            builder.locate_worst(self.index, at);
        }
    }
}

/// A value for structural findings: its type, and strings, booleans and numbers themselves.
fn describe_value(value: &Value) -> String {
    match value {
        Value::Null => "null".into(),
        Value::Bool(b) => b.to_string(),
        Value::Number(n) => n.to_string(),
        Value::String(s) if s.chars().count() > 40 => {
            format!("{:?}...", s.chars().take(40).collect::<String>())
        }
        Value::String(s) => format!("{s:?}"),
        Value::Array(a) => format!("an array of {}", a.len()),
        Value::Object(_) => "an object".into(),
    }
}

#[cfg(test)]
mod tests {
    use std::collections::BTreeMap;
    use std::io::Cursor;

    use super::*;
    use crate::{MeshFrame, MeshTopology, Scalars, SolverStep, TraceWriter};

    const TIGHT: Tolerance = Tolerance { rtol: 1e-12, atol: 0.0 };

    /// What to change in a test trace.
    #[derive(Default)]
    struct Changes {
        /// Move vertex 1 of this frame by 1 mm in z.
        moved_frame: Option<u64>,
        /// Leave this frame out (mesh and metrics).
        missing_frame: Option<u64>,
        /// Leave the metrics out.
        no_metrics: bool,
        /// Another wall time in the solver steps.
        wall_time_s: f64,
        /// Give the mesh this name in frames.
        mesh: Option<&'static str>,
    }

    /// A trace of a 3-vertex mesh over 5 frames, with metrics and 2 solver steps per frame.
    fn trace(changes: &Changes) -> Vec<u8> {
        let mut writer = TraceWriter::new(Cursor::new(Vec::new())).expect("writer");
        let rest = vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        writer
            .write(&MeshTopology {
                triangles: vec![[0, 1, 2]],
                rest_positions_m: rest.clone(),
                name: "cloth".into(),
            })
            .expect("topology");
        for frame in 0..5u64 {
            let time_s = frame as f64 * 0.1;
            for step in 0..2u32 {
                let solver = SolverStep {
                    frame,
                    time_s: time_s + 0.05 * f64::from(step),
                    newton_iterations: 3 + step,
                    residual: 1e-9,
                    line_search_steps: 0,
                    converged: true,
                    wall_time_s: 0.01 + changes.wall_time_s,
                };
                writer.write(&solver).expect("solver");
            }
            if changes.missing_frame == Some(frame) {
                continue;
            }
            let mut positions = rest.clone();
            for p in &mut positions {
                p[2] = -0.01 * time_s;
            }
            if changes.moved_frame == Some(frame) {
                positions[1][2] += 1e-3;
            }
            let mesh = changes.mesh.unwrap_or("cloth").to_string();
            writer.write(&MeshFrame { mesh, frame, time_s, positions_m: positions }).expect("frame");
            if !changes.no_metrics {
                let values = BTreeMap::from([("kinetic_energy_j".to_string(), time_s * 2.0)]);
                writer.write(&Scalars { frame, time_s, values }).expect("metrics");
            }
        }
        writer.finish().expect("finish").into_inner()
    }

    fn diff(a: &[u8], b: &[u8]) -> TraceDiff {
        diff_traces(a, b, TIGHT)
    }

    #[test]
    fn a_trace_equals_itself() {
        let a = trace(&Changes::default());
        let d = diff(&a, &a);
        assert!(d.equal(), "{}", d.report());
        let topics: Vec<&str> = d.topics.iter().map(|t| t.topic.as_str()).collect();
        assert_eq!(topics, ["/mesh/frame", "/mesh/topology", "/metrics", "/solver"]);
        let frames = d.topic("/mesh/frame").expect("frames");
        assert_eq!(frames.matched, 5);
        let positions = frames.fields.iter().find(|f| f.field == "positions_m").expect("positions");
        assert_eq!(positions.count, 5 * 9);
        assert_eq!(d.topic("/solver").expect("solver").matched, 10);
        let metrics = d.topic("/metrics").expect("metrics");
        assert!(metrics.fields.iter().any(|f| f.field == "values.kinetic_energy_j"), "{}", d.report());
    }

    #[test]
    fn a_moved_vertex_is_found_with_its_topic_field_and_frame() {
        let (a, b) =
            (trace(&Changes::default()), trace(&Changes { moved_frame: Some(3), ..Changes::default() }));
        let d = diff(&a, &b);
        assert!(!d.equal());
        let frames = d.topic("/mesh/frame").expect("frames");
        let positions = frames.fields.iter().find(|f| f.field == "positions_m").expect("positions");
        assert_eq!((positions.outside, positions.worst_index), (1, 3));
        assert!((positions.max_abs - 1e-3).abs() < 1e-12, "{}", positions.max_abs);
        assert_eq!(positions.worst_at.as_deref(), Some("frame 3, mesh cloth, positions_m[1][2]"));
        let report = d.report();
        assert!(
            report.contains("/mesh/frame") && report.contains("frame 3, mesh cloth, positions_m[1][2]"),
            "{report}"
        );
        // Every other topic is equal, and a tolerance of 2 mm makes the traces equal.
        assert!(d.topics.iter().filter(|t| t.topic != "/mesh/frame").all(TopicDiff::equal), "{report}");
        assert!(diff_traces(&a[..], &b[..], Tolerance { rtol: 0.0, atol: 2e-3 }).equal());
    }

    #[test]
    fn a_missing_frame_and_a_missing_topic_are_reported() {
        let a = trace(&Changes::default());
        let b = trace(&Changes { missing_frame: Some(2), no_metrics: true, ..Changes::default() });
        let d = diff(&a, &b);
        assert!(!d.equal());
        let frames = d.topic("/mesh/frame").expect("frames");
        assert_eq!(frames.matched, 4);
        assert_eq!(
            frames.only_in_first,
            Unmatched { count: 1, examples: vec!["frame 2, mesh cloth".into()] }
        );
        assert_eq!(frames.only_in_second.count, 0);
        assert!(frames.fields.iter().all(|f| f.outside == 0), "the other frames are equal");
        let metrics = d.topic("/metrics").expect("metrics");
        assert_eq!((metrics.matched, metrics.only_in_first.count), (0, 5));
        let report = d.report();
        assert!(report.contains("/metrics: only in the first trace: 5 messages, e.g. frame 0"), "{report}");
        assert!(report.contains("only in the first trace: 1 messages, e.g. frame 2, mesh cloth"), "{report}");
        // The other way round, the same messages are only in the second trace.
        let d = diff(&b, &a);
        assert_eq!(d.topic("/metrics").expect("metrics").only_in_second.count, 5);
    }

    #[test]
    fn names_strings_and_wall_clock_times() {
        let a = trace(&Changes::default());
        // Another mesh name: the frames no longer match by key.
        let d = diff(&a, &trace(&Changes { mesh: Some("other"), ..Changes::default() }));
        let frames = d.topic("/mesh/frame").expect("frames");
        assert_eq!((frames.matched, frames.only_in_first.count, frames.only_in_second.count), (0, 5, 5));
        assert!(frames.only_in_second.examples[0].contains("mesh other"), "{}", d.report());
        // Wall-clock times are summarized but do not count.
        let d = diff(&a, &trace(&Changes { wall_time_s: 0.5, ..Changes::default() }));
        assert!(d.equal(), "{}", d.report());
        let solver = d.topic("/solver").expect("solver");
        assert!(
            solver.wall_clock.iter().any(|f| f.field == "wall_time_s" && f.outside == 10),
            "{}",
            d.report()
        );
    }

    #[test]
    fn yarn_nodes_are_matched_by_their_yarn_set() {
        let nodes = |handle: u8| {
            let mut writer = TraceWriter::new(Cursor::new(Vec::new())).expect("writer");
            for yarns in ["a", "b"] {
                let message = crate::YarnNodes {
                    yarns: yarns.into(),
                    rest_positions_m: vec![[0.0; 3]; 3],
                    node_type: vec![handle, 0, 0],
                    edges: vec![[0, 1], [1, 2]],
                };
                writer.write(&message).expect("nodes");
            }
            writer.finish().expect("finish").into_inner()
        };
        let d = diff(&nodes(3), &nodes(0));
        let topic = d.topic("/yarn/nodes").expect("nodes");
        assert_eq!(topic.matched, 2);
        let types = topic.fields.iter().find(|f| f.field == "node_type").expect("node_type");
        assert_eq!(types.outside, 2, "{}", d.report());
        assert_eq!(types.worst_at.as_deref(), Some("message 0, yarns a, node_type[0]"), "{}", d.report());
        assert!(diff(&nodes(3), &nodes(3)).equal());
    }

    #[test]
    fn a_truncated_trace_is_a_structural_difference() {
        let a = trace(&Changes::default());
        let truncated = &a[..a.len() / 2];
        let d = diff(&a, truncated);
        assert!(!d.equal());
        assert!(
            d.structural.iter().any(|s| s.starts_with("the second trace is truncated or damaged")),
            "{:?}",
            d.structural
        );
        let d = diff(b"not a trace at all", &a);
        assert!(
            d.structural
                .iter()
                .any(|s| s.starts_with("the first trace is truncated or damaged after 0 messages"))
        );
    }

    #[test]
    fn a_small_buffer_gives_up_the_oldest_unmatched_messages() {
        let a = trace(&Changes::default());
        let b = trace(&Changes { no_metrics: true, ..Changes::default() });
        // Room for one message: the unmatched metrics are given up as the next message comes,
        // and the messages that do match are still compared.
        let d = diff_traces_with_limit(&a[..], &b[..], TIGHT, 1);
        assert_eq!(d.topic("/metrics").expect("metrics").only_in_first.count, 5);
        assert_eq!(d.topic("/mesh/frame").expect("frames").matched, 5, "{}", d.report());
        assert!(d.notes.iter().any(|n| n.contains("waited too long")), "{:?}", d.notes);
        // Traces of the same producer are read in step: one buffered message is enough.
        let d = diff_traces_with_limit(&a[..], &a[..], TIGHT, 1);
        assert!(d.equal() && d.notes.is_empty(), "{}", d.report());
    }
}
