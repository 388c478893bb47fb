//! Round trips through files and pipes, and checks against the MCAP library's own readers.

use std::collections::BTreeMap;
use std::io::{self, Read, Seek, Write};
use std::path::PathBuf;

use yarnhom_trace::{
    MeshFrame, MeshTopology, Scalars, SolverStep, Topic, TraceError, TraceMessage, TraceMetadata,
    TraceReader, TraceWriter, TraceWriterOptions, read_metadata,
};

/// A fresh, empty directory under Cargo's per-target scratch directory.
fn scratch_dir(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("create scratch dir");
    dir
}

fn topology() -> MeshTopology {
    MeshTopology {
        triangles: vec![[0, 1, 2], [0, 2, 3]],
        rest_positions_m: vec![[0.0, 0.0, 0.0], [0.01, 0.0, 0.0], [0.01, 0.01, 0.0], [0.0, 0.01, 0.0]],
        name: "cloth".into(),
    }
}

fn frame(i: u64) -> MeshFrame {
    let t = i as f64 * 1e-3;
    MeshFrame {
        mesh: "cloth".into(),
        frame: i,
        time_s: t,
        positions_m: (0..4).map(|v| [v as f64 * 0.01, (v / 2) as f64 * 0.01, -0.5 * 9.81 * t * t]).collect(),
    }
}

fn scalars(i: u64) -> Scalars {
    Scalars {
        frame: i,
        time_s: i as f64 * 1e-3,
        values: BTreeMap::from([
            ("kinetic_energy_j".to_owned(), 0.5 * i as f64),
            ("stretch_energy_j".to_owned(), 1.0 / (1.0 + i as f64)),
        ]),
    }
}

fn solver(i: u64) -> SolverStep {
    SolverStep {
        frame: i,
        time_s: i as f64 * 1e-3,
        newton_iterations: 3 + (i % 4) as u32,
        residual: 1e-9 * (i + 1) as f64,
        line_search_steps: (i % 3) as u32,
        converged: i % 5 != 4,
        wall_time_s: 0.002,
    }
}

const FRAMES: u64 = 50;

/// Writes the standard test trace and returns the messages in write order.
fn write_trace<W: Write + Seek>(writer: &mut TraceWriter<W>) -> Vec<TraceMessage> {
    let mut written = Vec::new();
    writer
        .write_metadata(
            &TraceMetadata::new("roundtrip-test", "9.9.9")
                .with_entry("scene", "patch.toml")
                .with_entry("material_file", "cotton.json"),
        )
        .expect("metadata");
    writer.write(&topology()).expect("topology");
    written.push(TraceMessage::Topology(topology()));
    for i in 0..FRAMES {
        writer.write(&solver(i)).expect("solver");
        written.push(TraceMessage::Solver(solver(i)));
        writer.write(&frame(i)).expect("frame");
        written.push(TraceMessage::Frame(frame(i)));
        writer.write(&scalars(i)).expect("scalars");
        written.push(TraceMessage::Scalars(scalars(i)));
    }
    written
}

fn read_all(source: impl Read) -> Vec<TraceMessage> {
    TraceReader::new(source).collect::<Result<Vec<_>, _>>().expect("read trace")
}

#[test]
fn file_round_trip_is_atomic_and_identical() {
    let dir = scratch_dir("file_round_trip");
    let path = dir.join("trace.mcap");
    let mut writer = TraceWriter::create(&path).expect("create");
    let written = write_trace(&mut writer);
    assert!(!path.exists(), "the trace must not appear before finish()");
    assert_eq!(std::fs::read_dir(&dir).expect("ls").count(), 1, "one temp file");
    let file = writer.finish().expect("finish");
    assert!(file.is_committed());
    assert_eq!(file.destination(), path);
    assert_eq!(std::fs::read_dir(&dir).expect("ls").count(), 1, "the temp file was renamed, not copied");

    let read = read_all(std::fs::File::open(&path).expect("open"));
    assert_eq!(read, written);

    let bytes = std::fs::read(&path).expect("read");
    let metadata = read_metadata(&bytes).expect("metadata");
    assert_eq!(metadata.len(), 1);
    assert_eq!(metadata[0].producer_name, "roundtrip-test");
    assert_eq!(metadata[0].producer_version, "9.9.9");
    assert_eq!(metadata[0].entries["scene"], "patch.toml");
    assert_eq!(metadata[0].entries["material_file"], "cotton.json");
}

#[test]
fn dropping_an_unfinished_file_writer_leaves_nothing() {
    let dir = scratch_dir("abandoned");
    let path = dir.join("trace.mcap");
    std::fs::write(&path, b"previous contents").expect("seed");
    {
        let mut writer = TraceWriter::create(&path).expect("create");
        write_trace(&mut writer);
    }
    assert_eq!(std::fs::read(&path).expect("read"), b"previous contents");
    assert_eq!(std::fs::read_dir(&dir).expect("ls").count(), 1, "temp file removed");
}

/// A sink that is only `Write`: no `Seek`, like a pipe.
#[derive(Default)]
struct Pipe(Vec<u8>);

impl Write for Pipe {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.0.extend_from_slice(buf);
        Ok(buf.len())
    }

    fn flush(&mut self) -> io::Result<()> {
        Ok(())
    }
}

/// A source that is only `Read` and returns at most 7 bytes per call.
struct Trickle<'a>(&'a [u8]);

impl Read for Trickle<'_> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let n = buf.len().min(self.0.len()).min(7);
        buf[..n].copy_from_slice(&self.0[..n]);
        self.0 = &self.0[n..];
        Ok(n)
    }
}

/// Writes the standard trace through a non-seekable sink, with small chunks so there are many.
fn pipe_bytes() -> (Vec<u8>, Vec<TraceMessage>) {
    let mut writer =
        TraceWriterOptions::new().chunk_size(4 * 1024).non_seeking(Pipe::default()).expect("writer");
    let written = write_trace(&mut writer);
    let bytes = writer.finish().expect("finish").into_inner().0;
    (bytes, written)
}

#[test]
fn pipe_round_trip_is_identical() {
    let (bytes, written) = pipe_bytes();
    assert_eq!(read_all(bytes.as_slice()), written);
    assert_eq!(read_all(Trickle(&bytes)), written);
    assert_eq!(read_metadata(&bytes).expect("metadata").len(), 1);
}

#[test]
fn uncompressed_round_trip_is_identical() {
    let mut writer =
        TraceWriterOptions::new().compression(false).non_seeking(Pipe::default()).expect("writer");
    let written = write_trace(&mut writer);
    let bytes = writer.finish().expect("finish").into_inner().0;
    let summary = mcap::Summary::read(&bytes).expect("summary").expect("present");
    assert!(summary.chunk_indexes.iter().all(|c| c.compression.is_empty()));
    assert_eq!(read_all(bytes.as_slice()), written);
}

/// A non-seekable sink whose bytes stay readable after the writer is gone.
#[derive(Default, Clone)]
struct SharedPipe(std::rc::Rc<std::cell::RefCell<Vec<u8>>>);

impl Write for SharedPipe {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.0.borrow_mut().extend_from_slice(buf);
        Ok(buf.len())
    }

    fn flush(&mut self) -> io::Result<()> {
        Ok(())
    }
}

#[test]
fn abandoned_stream_is_reported_as_truncated() {
    let sink = SharedPipe::default();
    let mut writer = TraceWriter::non_seeking(sink.clone()).expect("writer");
    write_trace(&mut writer);
    writer.flush().expect("flush");
    writer.write(&frame(FRAMES)).expect("unflushed frame");
    drop(writer);
    let bytes = sink.0.borrow().clone();
    let items: Vec<_> = TraceReader::new(bytes.as_slice()).collect();
    let (last, rest) = items.split_last().expect("items");
    assert!(rest.iter().all(Result::is_ok));
    assert_eq!(rest.len(), 1 + 3 * FRAMES as usize, "every flushed message is readable");
    assert!(
        matches!(last, Err(TraceError::Truncated(_))),
        "a missing end must be reported as truncation, got {last:?}"
    );
}

#[test]
fn stored_schemas_are_the_schemars_output() {
    let (bytes, _) = pipe_bytes();
    let summary = mcap::Summary::read(&bytes).expect("summary").expect("present");
    let mut seen = BTreeMap::new();
    for channel in summary.channels.values() {
        let schema = channel.schema.as_ref().expect("every channel has a schema");
        assert_eq!(schema.encoding, "jsonschema");
        assert_eq!(channel.message_encoding, "msgpack");
        let stored: serde_json::Value = serde_json::from_slice(&schema.data).expect("schema parses as JSON");
        seen.insert(channel.topic.clone(), (schema.name.clone(), stored));
        assert_eq!(channel.metadata["yarnhom_topic_version"], "1");
    }
    fn expect<T: Topic>(seen: &BTreeMap<String, (String, serde_json::Value)>) {
        let (name, stored) = &seen[T::TOPIC];
        assert_eq!(name, T::SCHEMA_NAME);
        let generated = serde_json::to_value(schemars::schema_for!(T)).expect("json");
        assert_eq!(stored, &generated, "{}", T::TOPIC);
    }
    assert_eq!(seen.len(), 4);
    expect::<MeshTopology>(&seen);
    expect::<MeshFrame>(&seen);
    expect::<Scalars>(&seen);
    expect::<SolverStep>(&seen);
    assert_eq!(seen["/mesh/frame"].0, "yarnhom.MeshFrame.v1");
}

#[test]
fn file_passes_mcap_summary_and_indexed_reads() {
    let dir = scratch_dir("indexed");
    let path = dir.join("trace.mcap");
    let mut writer = TraceWriterOptions::new().chunk_size(8 * 1024).create(&path).expect("create");
    write_trace(&mut writer);
    writer.finish().expect("finish");
    let bytes = std::fs::read(&path).expect("read");

    let summary = mcap::Summary::read(&bytes).expect("summary").expect("present");
    let stats = summary.stats.as_ref().expect("statistics");
    assert_eq!(stats.message_count, 1 + 3 * FRAMES);
    assert_eq!(stats.channel_count, 4);
    assert_eq!(stats.schema_count, 4);
    assert_eq!(stats.metadata_count, 1);
    assert_eq!(stats.message_start_time, 0);
    assert_eq!(stats.message_end_time, (FRAMES - 1) * 1_000_000);
    assert!(stats.chunk_count > 1, "small chunks: {}", stats.chunk_count);
    let count_of = |topic: &str| {
        let id = summary.channels.values().find(|c| c.topic == topic).expect("channel").id;
        stats.channel_message_counts[&id]
    };
    assert_eq!(count_of("/mesh/topology"), 1);
    assert_eq!(count_of("/mesh/frame"), FRAMES);
    assert_eq!(count_of("/metrics"), FRAMES);
    assert_eq!(count_of("/solver"), FRAMES);
    assert!(summary.chunk_indexes.iter().all(|c| c.compression == "zstd"));

    // Metadata through the metadata index.
    assert_eq!(summary.metadata_indexes.len(), 1);
    let metadata = mcap::read::metadata(&bytes, &summary.metadata_indexes[0]).expect("indexed metadata");
    assert_eq!(metadata.name, "yarnhom");
    assert_eq!(metadata.metadata["producer_name"], "roundtrip-test");

    // Every chunk through the chunk indexes.
    let mut via_chunks = 0;
    for index in &summary.chunk_indexes {
        for message in summary.stream_chunk(&bytes, index).expect("chunk") {
            message.expect("message");
            via_chunks += 1;
        }
    }
    assert_eq!(via_chunks, 1 + 3 * FRAMES);

    // The sans-io indexed reader, seeking in the file, in log-time order.
    let mut file = std::fs::File::open(&path).expect("open");
    let mut reader = mcap::sans_io::IndexedReader::new(&summary).expect("indexed reader");
    let mut buffer = Vec::new();
    let mut frames = Vec::new();
    let mut total = 0;
    while let Some(event) = reader.next_event() {
        match event.expect("event") {
            mcap::sans_io::IndexedReadEvent::ReadChunkRequest { offset, length } => {
                file.seek(io::SeekFrom::Start(offset)).expect("seek");
                buffer.resize(length, 0);
                file.read_exact(&mut buffer).expect("read chunk");
                reader.insert_chunk_record_data(offset, &buffer).expect("insert chunk");
            }
            mcap::sans_io::IndexedReadEvent::Message { header, data } => {
                total += 1;
                let channel = &summary.channels[&header.channel_id];
                if channel.topic == "/mesh/frame" {
                    let decoded: MeshFrame = rmp_serde::from_slice(data).expect("msgpack");
                    assert_eq!(header.sequence as u64, decoded.frame);
                    assert_eq!(header.log_time, decoded.frame * 1_000_000);
                    assert_eq!(header.publish_time, header.log_time);
                    frames.push(decoded);
                }
            }
        }
    }
    assert_eq!(total, 1 + 3 * FRAMES);
    assert_eq!(frames, (0..FRAMES).map(frame).collect::<Vec<_>>());

    // And the slice-based linear reader of the MCAP library.
    let linear =
        mcap::MessageStream::new(&bytes).expect("stream").collect::<Result<Vec<_>, _>>().expect("messages");
    assert_eq!(linear.len() as u64, 1 + 3 * FRAMES);
}

#[test]
fn unknown_topics_are_reported_and_bad_messages_name_their_topic() {
    use std::collections::BTreeMap;
    let mut bytes = Vec::new();
    {
        let mut mcap = mcap::WriteOptions::new().create(io::Cursor::new(&mut bytes)).expect("mcap");
        let other = mcap.add_channel(0, "/camera", "raw", &BTreeMap::new()).expect("channel");
        let v1 = BTreeMap::from([("yarnhom_topic_version".to_owned(), "1".to_owned())]);
        let v2 = BTreeMap::from([("yarnhom_topic_version".to_owned(), "2".to_owned())]);
        let garbage = mcap.add_channel(0, "/mesh/frame", "msgpack", &v1).expect("ch");
        let future = mcap.add_channel(0, "/solver", "msgpack", &v2).expect("ch");
        let json = mcap.add_channel(0, "/metrics", "json", &v1).expect("ch");
        for (channel_id, data) in
            [(other, &b"\x01\x02"[..]), (garbage, &b"\xc1"[..]), (future, &b"\x80"[..]), (json, &b"{}"[..])]
        {
            let header =
                mcap::records::MessageHeader { channel_id, sequence: 0, log_time: 0, publish_time: 0 };
            mcap.write_to_known_channel(&header, data).expect("write");
        }
        mcap.finish().expect("finish");
    }
    let items: Vec<_> = TraceReader::new(bytes.as_slice()).collect();
    assert_eq!(items.len(), 4, "decode errors do not end the iteration");
    assert!(matches!(&items[0], Ok(TraceMessage::Unknown { topic }) if topic == "/camera"));
    let err = |i: usize| match &items[i] {
        Err(err) => err,
        Ok(message) => panic!("item {i} decoded: {message:?}"),
    };
    assert!(matches!(err(1), TraceError::Decode { topic, .. } if topic == "/mesh/frame"));
    assert!(err(1).to_string().contains("/mesh/frame"), "{}", err(1));
    assert!(matches!(
        err(2),
        TraceError::UnsupportedTopicVersion { topic, found: Some(v), supported: 1 }
            if topic == "/solver" && v == "2"
    ));
    assert!(matches!(err(3), TraceError::UnsupportedEncoding { encoding, .. } if encoding == "json"));
}

#[test]
fn garbage_input_is_an_mcap_error() {
    let items: Vec<_> = TraceReader::new(&b"not an mcap file at all"[..]).collect();
    assert_eq!(items.len(), 1);
    assert!(matches!(items[0], Err(TraceError::Mcap(_))), "{items:?}");
}

#[test]
fn invalid_times_are_refused() {
    let mut writer = TraceWriter::non_seeking(Pipe::default()).expect("writer");
    let err = writer
        .write(&MeshFrame { mesh: "cloth".into(), frame: 0, time_s: f64::NAN, positions_m: vec![] })
        .expect_err("NaN time");
    assert!(matches!(err, TraceError::InvalidTime { topic: "/mesh/frame", .. }), "{err}");
    writer.finish().expect("the writer is still usable");
}
