//! What the CLI's integration tests share: the `impulse` command under test, scratch paths
//! and the success check.

use std::path::PathBuf;
use std::process::{Command, Output};

/// The `impulse` binary cargo built for these tests.
pub fn impulse() -> Command {
    Command::new(env!("CARGO_BIN_EXE_impulse"))
}

/// A path for file `name` in this process's scratch directory for `suite`.
pub fn temp(suite: &str, name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("impulse-{suite}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// A fresh, empty directory `name` in this process's scratch directory for `suite`.
pub fn fresh_dir(suite: &str, name: &str) -> PathBuf {
    let dir = temp(suite, name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A path inside the repository.
pub fn repo(path: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(path)
}

/// Asserts that a run succeeded, showing its standard error (prefixed by `context`) if not.
pub fn assert_success(out: &Output, context: &str) {
    assert!(
        out.status.success(),
        "{context}{}",
        String::from_utf8_lossy(&out.stderr)
    );
}
