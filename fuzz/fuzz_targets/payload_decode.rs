//! Any msgpack payload behind a valid frame (random bytes rarely pass the CRC, so the payload
//! decoder, the migrations and the validators get their own target). The first byte picks the
//! kind (low bits) and the schema version (bits 4-5: current, 0, or one newer than current).
#![no_main]

use libfuzzer_sys::fuzz_target;
use yarnhom_artifacts::container::{Header, Producer, RawArtifact, content_hash};
use yarnhom_artifacts::{AnyArtifact, KINDS};

fuzz_target!(|data: &[u8]| {
    let Some((&selector, payload)) = data.split_first() else { return };
    let kind = KINDS[usize::from(selector & 0x0f) % KINDS.len()];
    let current = yarnhom_artifacts::schema_version(kind).expect("a known kind");
    let schema_version = match (selector >> 4) & 3 {
        1 => 0,
        2 => current + 1,
        _ => current,
    };
    let header = Header {
        kind: kind.into(),
        schema_version,
        producer: Producer::default(),
        created_utc: String::new(),
        inputs: vec![],
        content_hash: content_hash(payload),
        payload_bytes: payload.len() as u64,
    };
    let _ = AnyArtifact::decode(&RawArtifact { header, payload: payload.to_vec() });
});
