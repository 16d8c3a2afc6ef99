//! Bytes → a world snapshot (`WorldSnapshot::from_bytes`, then `World::from_snapshot`) → at
//! most `MAX_STEPS` steps of the restored world on the calling thread, with the solver effort
//! capped (common.rs, `snapshot_input`). The first byte picks what the rest is: odd, a whole
//! snapshot file (so the header checks are fuzzed); even, the CBOR payload alone, which gets a
//! valid header (magic, format version, length and CRC-32) so that the fuzzer reaches the
//! decoder and the checks of the restored world past the checksum. Errors are fine; a panic,
//! abort, timeout or out-of-memory is a bug.

#![no_main]

use libfuzzer_sys::fuzz_target;

#[path = "common.rs"]
mod common;

fuzz_target!(|data: &[u8]| {
    let _ = common::snapshot_input(data);
});
