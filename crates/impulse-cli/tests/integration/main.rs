//! The crate's integration tests, as one test binary: one binary links the crate once, where a
//! binary per file would link it once per file (the build's time and disk grow with each).
//! Run one file's tests with a filter on its module, e.g.
//! `cargo test -p impulse-cli --test integration bad_input::`.

mod bad_input;
mod checkpoint;
mod cli;
mod common;
mod edges;
mod export;
mod interrupt;
mod lcp_box;
mod mesh_files;
mod render;
mod variation;
