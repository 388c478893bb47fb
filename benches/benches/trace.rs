//! Trace throughput: writing and reading `/mesh/frame` messages of a 50 x 50 cloth (2500
//! vertices, 60 kB of raw f64 positions per frame) through MCAP with zstd chunks, in MB/s of raw
//! frame data; and the cost of recording one frame (mesh, metrics, solver statistics) relative
//! to one implicit step of the drape scene, whose frames it records.
//! Compared with: the target, recording under 5% of a shell step.

use std::collections::BTreeMap;
use std::io::Cursor;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use yarnhom_trace::{MeshFrame, MeshTopology, Scalars, SolverStep, TraceMessage, TraceReader, TraceWriter};

const SIDE: usize = 50;
const FRAMES: u64 = 200;

/// A wavy 30 cm cloth at frame `frame` (positions change every frame, like a simulation's).
fn frame(frame: u64) -> MeshFrame {
    let t = frame as f64 / 60.0;
    let positions_m = (0..SIDE * SIDE)
        .map(|i| {
            let (x, y) = ((i % SIDE) as f64 * 0.3 / 49.0, (i / SIDE) as f64 * 0.3 / 49.0);
            [x, y, 0.01 * (20.0 * x + 3.0 * t).sin() * (15.0 * y).cos()]
        })
        .collect();
    MeshFrame { mesh: "cloth".into(), frame, time_s: t, positions_m }
}

fn topology() -> MeshTopology {
    let mut triangles = Vec::new();
    for j in 0..SIDE as u32 - 1 {
        for i in 0..SIDE as u32 - 1 {
            let v = j * SIDE as u32 + i;
            triangles.push([v, v + 1, v + SIDE as u32]);
            triangles.push([v + 1, v + SIDE as u32 + 1, v + SIDE as u32]);
        }
    }
    MeshTopology { triangles, rest_positions_m: frame(0).positions_m, name: "cloth".into() }
}

/// Everything one output frame of `shell simulate` writes: positions, four metrics, four steps.
fn record_frame<W: std::io::Write + std::io::Seek>(writer: &mut TraceWriter<W>, message: &MeshFrame) {
    writer.write(message).expect("frame");
    let values = ["elastic_energy_j", "kinetic_energy_j", "gravity_energy_j", "penetration_m"]
        .into_iter()
        .map(|name| (name.to_owned(), message.time_s))
        .collect::<BTreeMap<_, _>>();
    writer.write(&Scalars { frame: message.frame, time_s: message.time_s, values }).expect("metrics");
    for _ in 0..4 {
        let step = SolverStep {
            frame: message.frame,
            time_s: message.time_s,
            newton_iterations: 6,
            ..SolverStep::default()
        };
        writer.write(&step).expect("solver");
    }
}

fn trace_bytes(frames: &[MeshFrame]) -> Vec<u8> {
    let mut writer = TraceWriter::new(Cursor::new(Vec::new())).expect("writer");
    writer.write(&topology()).expect("topology");
    for f in frames {
        writer.write(f).expect("frame");
    }
    writer.finish().expect("finish").into_inner()
}

fn bench_trace(c: &mut Criterion) {
    let frames: Vec<MeshFrame> = (0..FRAMES).map(frame).collect();
    let raw_bytes = FRAMES * (SIDE * SIDE * 24) as u64;
    let bytes = trace_bytes(&frames);
    eprintln!(
        "{FRAMES} frames of {} vertices: {:.1} MB raw positions, {:.1} MB trace (zstd)",
        SIDE * SIDE,
        raw_bytes as f64 / 1e6,
        bytes.len() as f64 / 1e6
    );
    let mut g = c.benchmark_group("trace throughput");
    g.sample_size(10);
    g.throughput(Throughput::Bytes(raw_bytes));
    g.bench_function("write 200 frames of 2500 vertices", |b| b.iter(|| trace_bytes(&frames)));
    g.bench_function("read 200 frames of 2500 vertices", |b| {
        b.iter(|| {
            let mut vertices = 0;
            for message in TraceReader::new(bytes.as_slice()) {
                if let TraceMessage::Frame(f) = message.expect("message") {
                    vertices += f.positions_m.len();
                }
            }
            vertices
        })
    });
    g.finish();

    let mut g = c.benchmark_group("trace recording per frame");
    g.sample_size(20);
    let mut writer = TraceWriter::non_seeking(std::io::sink()).expect("writer");
    writer.write(&topology()).expect("topology");
    let mut k = 0;
    g.bench_function("one drape frame: positions, metrics, 4 solver steps", |b| {
        b.iter(|| {
            record_frame(&mut writer, &frames[k % frames.len()]);
            k += 1;
        })
    });
    g.finish();
}

criterion_group!(benches, bench_trace);
criterion_main!(benches);
