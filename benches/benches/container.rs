//! Reading and writing a pattern: the `.yh` container against the published `.pyp` text format,
//! on the published HYLC rib tile (356 vertices with rest state).
//! Compared with: parsing the same tile from its published `.pyp` text.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use yarnhom_artifacts::Pattern;
use yarnhom_artifacts::container::{Provenance, decode, encode};
use yarnhom_artifacts::pyp::{parse_pyp, write_pyp};

const RIB: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../shared/data/hylc-patterns/rib.pyp");

fn rib_pyp() -> String {
    std::fs::read_to_string(RIB).unwrap_or_else(|e| panic!("{RIB}: {e}"))
}

fn bench_container(c: &mut Criterion) {
    let text = rib_pyp();
    let pattern = parse_pyp(&text, "rib", None).expect("published rib imports");
    let bytes = encode(&pattern, &Provenance::default()).expect("encode");
    eprintln!("rib: .pyp {} bytes, .yh {} bytes", text.len(), bytes.len());

    let mut g = c.benchmark_group("rib pattern");
    g.throughput(Throughput::Elements(pattern.vertex_count() as u64));
    g.bench_function("yh decode (checksum, zstd, msgpack, validate)", |b| {
        b.iter(|| decode::<Pattern>(std::hint::black_box(&bytes)).expect("decode"))
    });
    g.bench_function("yh encode", |b| {
        b.iter(|| encode(std::hint::black_box(&pattern), &Provenance::default()).expect("encode"))
    });
    g.bench_function("pyp parse (published format)", |b| {
        b.iter(|| parse_pyp(std::hint::black_box(&text), "rib", None).expect("parse"))
    });
    g.bench_function("pyp write", |b| b.iter(|| write_pyp(std::hint::black_box(&pattern)).expect("write")));
    g.finish();
}

criterion_group!(benches, bench_container);
criterion_main!(benches);
