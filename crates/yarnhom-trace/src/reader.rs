//! Reading traces.

use std::io::Read;

use crate::TraceError;
use crate::messages::{
    MESSAGE_ENCODING, MeshFrame, MeshTopology, RveSample, Scalars, SolverIteration, SolverStep,
    TOPIC_VERSION_KEY, TetFrame, TetTopology, Topic, YarnFrame, YarnNodes, topics,
};
use crate::records::{ReadProgress, RecordReader, TraceRecord};

/// One decoded message of a trace.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum TraceMessage {
    /// A `/mesh/topology` message.
    Topology(MeshTopology),
    /// A `/mesh/frame` message.
    Frame(MeshFrame),
    /// A `/yarn/frame` message.
    Yarns(YarnFrame),
    /// A `/yarn/nodes` message.
    YarnNodes(YarnNodes),
    /// A `/tet/topology` message.
    TetTopology(TetTopology),
    /// A `/tet/frame` message.
    TetFrame(TetFrame),
    /// A `/metrics` message.
    Scalars(Scalars),
    /// A `/solver` message.
    Solver(SolverStep),
    /// A `/solver/iteration` message.
    SolverIteration(SolverIteration),
    /// A `/rve/sample` message.
    RveSample(RveSample),
    /// A message on a topic this crate does not know (e.g. from a newer format or another
    /// producer); its payload is skipped.
    Unknown {
        /// The message's topic.
        topic: String,
    },
}

/// Streams the decoded messages of a trace, in file order, from any [`Read`] source: a file,
/// standard input, a pipe or a byte slice. No seeking is needed and memory is bounded by the
/// largest chunk (or message), not by the trace. Metadata records are skipped (see
/// [`RecordReader`] for them).
///
/// Errors come in two kinds. An error in the MCAP container ([`TraceError::Mcap`],
/// [`TraceError::Io`], [`TraceError::Truncated`] after every message that could be read) ends
/// the iteration: it is the last item. An error decoding one message ([`TraceError::Decode`],
/// [`TraceError::UnsupportedTopicVersion`], [`TraceError::UnsupportedEncoding`]) concerns that
/// message only, and iteration may go on.
///
/// The source is read in pieces sized to the records, so wrapping it in a
/// [`BufReader`](std::io::BufReader) is not needed.
pub struct TraceReader<R: Read> {
    records: RecordReader<R>,
}

impl<R: Read> TraceReader<R> {
    /// Starts reading a trace from `source`.
    pub fn new(source: R) -> Self {
        Self { records: RecordReader::new(source) }
    }

    /// How far the reader got.
    pub fn progress(&self) -> ReadProgress {
        self.records.progress()
    }
}

impl<R: Read> Iterator for TraceReader<R> {
    type Item = Result<TraceMessage, TraceError>;

    fn next(&mut self) -> Option<Self::Item> {
        loop {
            return Some(match self.records.next()? {
                Ok(TraceRecord::Message(message)) => decode(&message),
                Ok(TraceRecord::Metadata(_)) => continue,
                Err(err) => Err(err),
            });
        }
    }
}

/// Decodes one MCAP message by its channel's topic.
pub fn decode(message: &mcap::Message<'_>) -> Result<TraceMessage, TraceError> {
    Ok(match message.channel.topic.as_str() {
        topics::MESH_TOPOLOGY => TraceMessage::Topology(decode_as(message)?),
        topics::MESH_FRAME => TraceMessage::Frame(decode_as(message)?),
        topics::YARN_FRAME => TraceMessage::Yarns(decode_as(message)?),
        topics::YARN_NODES => TraceMessage::YarnNodes(decode_as(message)?),
        topics::TET_TOPOLOGY => TraceMessage::TetTopology(decode_as(message)?),
        topics::TET_FRAME => TraceMessage::TetFrame(decode_as(message)?),
        topics::METRICS => TraceMessage::Scalars(decode_as(message)?),
        topics::SOLVER => TraceMessage::Solver(decode_as(message)?),
        topics::SOLVER_ITERATION => TraceMessage::SolverIteration(decode_as(message)?),
        topics::RVE_SAMPLE => TraceMessage::RveSample(decode_as(message)?),
        other => TraceMessage::Unknown { topic: other.to_owned() },
    })
}
/// Checks the channel's encoding and topic version, then decodes the payload as `T`.
fn decode_as<T: Topic>(message: &mcap::Message<'_>) -> Result<T, TraceError> {
    let channel = &message.channel;
    if channel.message_encoding != MESSAGE_ENCODING {
        return Err(TraceError::UnsupportedEncoding {
            topic: channel.topic.clone(),
            encoding: channel.message_encoding.clone(),
        });
    }
    let version = channel.metadata.get(TOPIC_VERSION_KEY);
    if version.map(String::as_str) != Some(T::VERSION.to_string().as_str()) {
        return Err(TraceError::UnsupportedTopicVersion {
            topic: channel.topic.clone(),
            found: version.cloned(),
            supported: T::VERSION,
        });
    }
    rmp_serde::from_slice(&message.data)
        .map_err(|source| TraceError::Decode { topic: channel.topic.clone(), source })
}
