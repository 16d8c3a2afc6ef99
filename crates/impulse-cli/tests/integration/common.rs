//! What the CLI's integration tests share: the `impulse` command under test, scratch paths
//! and the success check.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::OnceLock;

/// The `impulse` binary cargo built for these tests.
pub fn impulse() -> Command {
    Command::new(env!("CARGO_BIN_EXE_impulse"))
}

/// This test process's scratch directory (`impulse-cli-tests-PID` in the system's temporary
/// directory), made at its first use and removed with everything in it when the process
/// exits, whether its tests passed or failed.
static SCRATCH: OnceLock<PathBuf> = OnceLock::new();

unsafe extern "C" {
    /// The C library's `atexit`: `callback` runs when the process exits normally (the test
    /// harness ends with `exit`, after the last test).
    fn atexit(callback: extern "C" fn()) -> std::os::raw::c_int;
}

extern "C" fn remove_scratch() {
    if let Some(dir) = SCRATCH.get() {
        let _ = std::fs::remove_dir_all(dir);
    }
}

fn scratch() -> &'static Path {
    SCRATCH.get_or_init(|| {
        let dir = std::env::temp_dir().join(format!("impulse-cli-tests-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        // SAFETY: `remove_scratch` is a plain function that only reads a set `OnceLock` and
        // removes files; registering it has no other effect.
        unsafe { atexit(remove_scratch) };
        dir
    })
}

/// A path for file `name` in this process's scratch directory for `suite` (removed when the
/// process exits).
pub fn temp(suite: &str, name: &str) -> PathBuf {
    let dir = scratch().join(suite);
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
