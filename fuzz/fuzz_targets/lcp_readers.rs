//! Bytes → each LCP file reader of impulse-lcp: Siconos `.dat` text and the JSON format. A
//! problem that reads is written back as JSON and read again. Errors are fine; a panic, abort,
//! timeout or out-of-memory is a bug.

#![no_main]

use impulse_lcp::{parse_json, parse_siconos, to_json_string};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    for lcp in [
        parse_siconos(text, "fuzz.dat"),
        parse_json(text, "fuzz.json"),
    ]
    .into_iter()
    .flatten()
    {
        if let Ok(json) = to_json_string(&lcp) {
            let _ = parse_json(&json, "round-trip.json");
        }
    }
});
