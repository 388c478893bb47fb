//! Reading traces.

use std::io::Read;

use crate::TraceError;
use crate::messages::{
    MESSAGE_ENCODING, MeshFrame, MeshTopology, Scalars, SolverStep, TOPIC_VERSION_KEY, Topic, topics,
};

/// One decoded message of a trace.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum TraceMessage {
    /// A `/mesh/topology` message.
    Topology(MeshTopology),
    /// A `/mesh/frame` message.
    Frame(MeshFrame),
    /// A `/metrics` message.
    Scalars(Scalars),
    /// A `/solver` message.
    Solver(SolverStep),
    /// A message on a topic this crate does not know (e.g. from a newer format slice or
    /// another producer); its payload is skipped.
    Unknown {
        /// The message's topic.
        topic: String,
    },
}

/// Streams the messages of a trace, in file order, from any [`Read`] source: a file, standard
/// input, a pipe or a byte slice. No seeking is needed and memory is bounded by the largest
/// chunk (or message), not by the trace.
///
/// Errors come in two kinds. An error in the MCAP container ([`TraceError::Mcap`],
/// [`TraceError::Io`]) ends the iteration: it is the last item. An error decoding one message
/// ([`TraceError::Decode`], [`TraceError::UnsupportedTopicVersion`],
/// [`TraceError::UnsupportedEncoding`]) concerns that message only, and iteration may go on.
///
/// The source is read in pieces sized to the records, so wrapping it in a
/// [`BufReader`](std::io::BufReader) is not needed. The summary section at the end is read
/// through without being checked against the data, and the MCAP metadata record is skipped; use
/// [`read_metadata`](crate::read_metadata) for it.
pub struct TraceReader<R: Read> {
    messages: mcap::io::MessageReader<R>,
}

impl<R: Read> TraceReader<R> {
    /// Starts reading a trace from `source`.
    pub fn new(source: R) -> Self {
        Self { messages: mcap::io::MessageReader::new(source) }
    }

    /// Returns the underlying source.
    pub fn into_inner(self) -> R {
        self.messages.into_inner()
    }
}

impl<R: Read> Iterator for TraceReader<R> {
    type Item = Result<TraceMessage, TraceError>;

    fn next(&mut self) -> Option<Self::Item> {
        Some(match self.messages.next()? {
            Ok(message) => decode(&message),
            Err(err) => Err(err.into()),
        })
    }
}

/// Decodes one MCAP message by its channel's topic.
fn decode(message: &mcap::Message<'_>) -> Result<TraceMessage, TraceError> {
    Ok(match message.channel.topic.as_str() {
        topics::MESH_TOPOLOGY => TraceMessage::Topology(decode_as(message)?),
        topics::MESH_FRAME => TraceMessage::Frame(decode_as(message)?),
        topics::METRICS => TraceMessage::Scalars(decode_as(message)?),
        topics::SOLVER => TraceMessage::Solver(decode_as(message)?),
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
