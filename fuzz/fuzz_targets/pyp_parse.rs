//! Any text given to the `.pyp` importer: an error naming a line, or a valid pattern that
//! exports and re-imports to itself.
#![no_main]

use libfuzzer_sys::fuzz_target;
use yarnhom_artifacts::pyp::{parse_pyp, write_pyp};

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    if let Ok(p) = parse_pyp(text, "fuzz", None) {
        let text = write_pyp(&p).expect("a valid single-radius pattern exports");
        let again = parse_pyp(&text, "fuzz", Some(p.fabric)).expect("an export re-imports");
        assert_eq!(again, p, "import of export must be the identity");
    }
});
