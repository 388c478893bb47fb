//! Any bytes given to the `.yh` reader: an error or an artifact, never a panic, hang or
//! unbounded allocation.
#![no_main]

use libfuzzer_sys::fuzz_target;
use yarnhom_artifacts::{AnyArtifact, container};

fuzz_target!(|data: &[u8]| {
    if let Ok(raw) = container::decode_raw(data) {
        let _ = AnyArtifact::decode(&raw);
    }
});
