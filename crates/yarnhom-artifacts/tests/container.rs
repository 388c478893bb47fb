//! The `.yh` container: round trips and every failure mode named by DESIGN.md.

mod common;

use proptest::prelude::*;
use proptest::strategy::ValueTree;
use yarnhom_artifacts::container::{self, Provenance, decode, encode, frame, header_for, payload_of};
use yarnhom_artifacts::{Artifact, Error, Pattern, YarnModel};

fn sample_pattern() -> Pattern {
    let mut runner = proptest::test_runner::TestRunner::deterministic();
    common::pattern().new_tree(&mut runner).expect("strategy").current()
}

fn sample_bytes() -> Vec<u8> {
    encode(&sample_pattern(), &Provenance::default()).expect("encode")
}

#[test]
fn every_truncation_is_reported_as_truncation_or_bad_magic() {
    let bytes = sample_bytes();
    for len in 0..bytes.len() {
        match decode::<Pattern>(&bytes[..len]) {
            Err(Error::Truncated { .. }) => {}
            Err(Error::WrongMagic { .. }) if len < 8 => {}
            other => panic!("truncation to {len} bytes gave {other:?}"),
        }
    }
}

#[test]
fn every_single_bit_flip_is_detected() {
    let bytes = sample_bytes();
    for i in 0..bytes.len() {
        for bit in [0, 3, 7] {
            let mut bad = bytes.clone();
            bad[i] ^= 1 << bit;
            assert!(decode::<Pattern>(&bad).is_err(), "flip of bit {bit} in byte {i} went unnoticed");
        }
    }
}

#[test]
fn trailing_bytes_are_rejected() {
    let mut bytes = sample_bytes();
    bytes.push(0);
    assert!(matches!(decode::<Pattern>(&bytes), Err(Error::TrailingBytes { extra: 1 })));
}

#[test]
fn wrong_magic_is_named() {
    let mut bytes = sample_bytes();
    bytes[1] = b'X';
    let e = decode::<Pattern>(&bytes).unwrap_err();
    assert!(matches!(e, Error::WrongMagic { .. }), "{e:?}");
    assert!(e.to_string().contains("not a yarnhom artifact"));
}

#[test]
fn newer_container_version_is_refused_before_the_checksum() {
    let mut bytes = sample_bytes();
    bytes[8..10].copy_from_slice(&(container::CONTAINER_VERSION + 1).to_le_bytes());
    assert!(matches!(decode::<Pattern>(&bytes), Err(Error::NewerContainer { .. })));
}

fn reframed(pattern: &Pattern, edit: impl FnOnce(&mut container::Header)) -> Vec<u8> {
    let payload = payload_of(pattern).expect("payload");
    let mut header = header_for::<Pattern>(&payload, &Provenance::default());
    edit(&mut header);
    frame(&header, &payload).expect("frame")
}

#[test]
fn newer_schema_version_is_refused_with_both_versions() {
    let bytes = reframed(&sample_pattern(), |h| h.schema_version = Pattern::SCHEMA_VERSION + 1);
    let e = decode::<Pattern>(&bytes).unwrap_err();
    assert!(matches!(e, Error::NewerSchema { found: 2, supported: 1, .. }), "{e:?}");
}

#[test]
fn unknown_and_wrong_kinds_are_named() {
    let bytes = reframed(&sample_pattern(), |h| h.kind = "teapot".into());
    let raw = container::decode_raw(&bytes).expect("frame is fine");
    let e = yarnhom_artifacts::AnyArtifact::decode(&raw).unwrap_err();
    assert!(matches!(&e, Error::UnknownKind(k) if k == "teapot"), "{e:?}");
    let bytes = sample_bytes();
    assert!(matches!(decode::<YarnModel>(&bytes), Err(Error::WrongKind { expected: "yarnmodel", .. })));
}

#[test]
fn content_hash_mismatch_is_detected() {
    let bytes = reframed(&sample_pattern(), |h| h.content_hash = container::content_hash(b"other"));
    assert!(matches!(decode::<Pattern>(&bytes), Err(Error::ContentHashMismatch { .. })));
}

#[test]
fn payload_size_lies_are_detected() {
    let bytes = reframed(&sample_pattern(), |h| h.payload_bytes -= 1);
    assert!(matches!(decode::<Pattern>(&bytes), Err(Error::Decode { .. })));
}

#[test]
fn non_finite_numbers_are_invalid_on_write_and_on_read() {
    let mut p = sample_pattern();
    p.positions_m[0][1] = f64::NAN;
    let e = encode(&p, &Provenance::default()).unwrap_err();
    assert!(e.to_string().contains("positions_m[0]"), "{e}");
    let bytes = reframed(&p, |_| {});
    let e = decode::<Pattern>(&bytes).unwrap_err();
    assert!(matches!(e, Error::Invalid { kind: "pattern", .. }), "{e:?}");
}

#[test]
fn inconsistent_sizes_are_invalid() {
    let mut p = sample_pattern();
    p.edge_twist_rad.pop();
    let e = decode::<Pattern>(&reframed(&p, |_| {})).unwrap_err();
    assert!(e.to_string().contains("edge_twist_rad"), "{e}");
}

#[test]
fn errors_name_the_file_on_one_line() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("bad.pattern.yh");
    let mut bytes = sample_bytes();
    bytes.truncate(bytes.len() / 2);
    std::fs::write(&path, &bytes).expect("write");
    let message = container::read::<Pattern>(&path).unwrap_err().to_string();
    assert!(message.starts_with(&path.display().to_string()), "{message}");
    assert!(message.contains("truncated"), "{message}");
    assert!(!message.contains('\n'));
}

#[test]
fn writes_are_atomic_and_leave_no_temporary_files() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("x.pattern.yh");
    let p = sample_pattern();
    container::write(&path, &p, &Provenance::default()).expect("write");
    container::write(&path, &p, &Provenance::default()).expect("overwrite");
    let names: Vec<_> =
        std::fs::read_dir(dir.path()).expect("ls").map(|e| e.expect("entry").file_name()).collect();
    assert_eq!(names, vec![std::ffi::OsString::from("x.pattern.yh")]);
    assert_eq!(container::read::<Pattern>(&path).expect("read").1, p);
}

#[test]
fn a_failed_write_keeps_the_old_file() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("x.pattern.yh");
    let good = sample_pattern();
    container::write(&path, &good, &Provenance::default()).expect("write");
    let mut bad = good.clone();
    bad.period_m[0] = -1.0;
    assert!(container::write(&path, &bad, &Provenance::default()).is_err());
    assert_eq!(container::read::<Pattern>(&path).expect("read").1, good);
}

#[test]
fn the_content_hash_is_the_payload_identity_not_the_file_identity() {
    let p = sample_pattern();
    let (ha, _) =
        decode::<Pattern>(&reframed(&p, |h| h.created_utc = "2020-01-01T00:00:00Z".into())).expect("a");
    let (hb, _) =
        decode::<Pattern>(&reframed(&p, |h| h.created_utc = "2030-01-01T00:00:00Z".into())).expect("b");
    assert_eq!(ha.content_hash, hb.content_hash);
    let mut q = p.clone();
    q.positions_m[0][0] += 1e-9;
    let (hq, _) = decode::<Pattern>(&reframed(&q, |_| {})).expect("q");
    assert_ne!(ha.content_hash, hq.content_hash);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn pattern_round_trips_through_the_container(p in common::pattern()) {
        let bytes = encode(&p, &Provenance::default()).expect("encode");
        let (header, back) = decode::<Pattern>(&bytes).expect("decode");
        prop_assert_eq!(header.kind, "pattern");
        prop_assert_eq!(back, p);
    }

    #[test]
    fn yarn_model_round_trips_through_the_container(m in common::yarn_model()) {
        let bytes = encode(&m, &Provenance::default()).expect("encode");
        prop_assert_eq!(decode::<YarnModel>(&bytes).expect("decode").1, m);
    }

    #[test]
    fn rve_solve_round_trips_through_the_container(r in common::rve_solve()) {
        let bytes = encode(&r, &Provenance::default()).expect("encode");
        prop_assert_eq!(decode::<yarnhom_artifacts::RveSolve>(&bytes).expect("decode").1, r);
    }

    #[test]
    fn grid_round_trips_through_the_container(g in common::grid()) {
        let bytes = encode(&g, &Provenance::default()).expect("encode");
        prop_assert_eq!(decode::<yarnhom_artifacts::Grid>(&bytes).expect("decode").1, g);
    }

    #[test]
    fn every_kind_round_trips_through_json(
        p in common::pattern(),
        m in common::yarn_model(),
        r in common::rve_solve(),
        g in common::grid(),
    ) {
        for a in [
            yarnhom_artifacts::AnyArtifact::Pattern(p),
            yarnhom_artifacts::AnyArtifact::YarnModel(m),
            yarnhom_artifacts::AnyArtifact::RveSolve(r),
            yarnhom_artifacts::AnyArtifact::Grid(g),
        ] {
            let bytes = a.encode(&Provenance::default()).expect("encode");
            let raw = container::decode_raw(&bytes).expect("raw");
            let doc = yarnhom_artifacts::JsonDocument { header: raw.header, payload: a.to_json().expect("json") };
            let text = serde_json::to_string(&doc).expect("text");
            let doc: yarnhom_artifacts::JsonDocument = serde_json::from_str(&text).expect("parse");
            prop_assert_eq!(yarnhom_artifacts::AnyArtifact::from_json_document(&doc).expect("back"), a);
        }
    }

    #[test]
    fn pattern_round_trips_through_pyp_exactly(p in common::pattern()) {
        let text = yarnhom_artifacts::pyp::write_pyp(&p).expect("export");
        let back = yarnhom_artifacts::pyp::parse_pyp(&text, &p.name, Some(p.fabric)).expect("import");
        prop_assert_eq!(&back.positions_m, &p.positions_m);
        prop_assert_eq!(&back.edge_twist_rad, &p.edge_twist_rad);
        prop_assert_eq!(&back.rest, &p.rest);
        prop_assert_eq!(back.period_m, p.period_m);
        // Yarns are renumbered to start at their lowest vertex; the edge set is the same.
        let edges = |q: &Pattern| { let mut e: Vec<_> = q.edges().map(|e| (e.from, e.to, e.offset)).collect(); e.sort(); e };
        prop_assert_eq!(edges(&back), edges(&p));
    }

    #[test]
    fn arbitrary_bytes_never_panic(bytes in prop::collection::vec(any::<u8>(), 0..512)) {
        let _ = container::decode_raw(&bytes);
    }

    #[test]
    fn corrupting_a_valid_file_never_panics(i in any::<prop::sample::Index>(), v in any::<u8>()) {
        let mut bytes = sample_bytes();
        let k = i.index(bytes.len());
        bytes[k] = v;
        let _ = decode::<Pattern>(&bytes);
    }
}

#[cfg(unix)]
#[test]
fn written_files_are_world_readable_and_keep_the_permissions_they_replace() {
    use std::os::unix::fs::PermissionsExt;
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("x.pattern.yh");
    let mode = |p: &std::path::Path| std::fs::metadata(p).expect("stat").permissions().mode() & 0o777;
    container::write(&path, &sample_pattern(), &Provenance::default()).expect("write");
    assert_eq!(mode(&path), 0o644);
    std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o600)).expect("chmod");
    container::write(&path, &sample_pattern(), &Provenance::default()).expect("overwrite");
    assert_eq!(mode(&path), 0o600);
}
