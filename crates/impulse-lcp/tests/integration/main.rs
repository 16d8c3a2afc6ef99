//! The crate's integration tests, as one test binary: one binary links the crate once, where a
//! binary per file would link it once per file (the build's time and disk grow with each).
//! Run one file's tests with a filter on its module, e.g.
//! `cargo test -p impulse-lcp --test integration bounds::`.

mod bounds;
mod classic;
mod common;
mod errors;
mod fuzz_regressions;
mod io;
mod mixed;
mod mixed_random;
mod random_contacts;
mod siconos;
