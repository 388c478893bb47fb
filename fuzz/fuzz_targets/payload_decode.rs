//! Any msgpack payload behind a valid frame (random bytes rarely pass the CRC, so the payload
//! decoder, the migrations and the validators get their own target): first byte picks the kind
//! and schema version.
#![no_main]

use libfuzzer_sys::fuzz_target;
use yarnhom_artifacts::container::{content_hash, Header, Producer, RawArtifact};
use yarnhom_artifacts::{AnyArtifact, KINDS};

fuzz_target!(|data: &[u8]| {
    let Some((&selector, payload)) = data.split_first() else { return };
    let kind = KINDS[usize::from(selector) % KINDS.len()];
    let header = Header {
        kind: kind.into(),
        schema_version: u32::from(selector >> 6),
        producer: Producer::default(),
        created_utc: String::new(),
        inputs: vec![],
        content_hash: content_hash(payload),
        payload_bytes: payload.len() as u64,
    };
    let _ = AnyArtifact::decode(&RawArtifact { header, payload: payload.to_vec() });
});
