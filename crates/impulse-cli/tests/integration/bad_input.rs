//! Bad command lines and scenes get a clear message instead of an abort or silence.

use std::time::Duration;

use crate::common::impulse;

fn stderr_of(args: &[&str]) -> (bool, String) {
    let out = impulse().args(args).output().unwrap();
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn a_negative_time_step_is_refused_as_a_time_step() {
    let (ok, err) = stderr_of(&["run", "stack3", "--steps", "1", "--quiet", "--dt", "-0.01"]);
    assert!(!ok);
    assert!(
        err.contains("dt") && err.contains("within [1e-6, 1] s") && err.contains("-0.01"),
        "{err}"
    );
}

#[test]
fn every_zero_is_refused() {
    let (ok, err) = stderr_of(&["run", "stack3", "--steps", "1", "--quiet", "--every", "0"]);
    assert!(!ok);
    assert!(err.contains("--every") && err.contains('0'), "{err}");
}

#[test]
fn a_scene_without_moving_bodies_is_named_in_a_warning() {
    let path = crate::common::temp("bad", "empty.json");
    std::fs::write(&path, r#"{"name": "empty", "bodies": []}"#).unwrap();
    let (ok, err) = stderr_of(&["run", path.to_str().unwrap(), "--steps", "2", "--quiet"]);
    assert!(ok, "{err}");
    assert!(err.contains("no moving body"), "{err}");
}

#[test]
fn bodies_created_inside_each_other_are_named_with_the_depth() {
    let (ok, err) = stderr_of(&["run", "overlap_pyramid", "--steps", "1", "--quiet"]);
    assert!(ok, "{err}");
    assert!(
        err.contains("bodies 0 (\"ground\") and 1 start overlapping by 125.0 mm"),
        "{err}"
    );
    let (_, clean) = stderr_of(&["run", "pyramid20", "--steps", "1", "--quiet"]);
    assert!(!clean.contains("overlapping"), "{clean}");
}

/// The largest step count starts running (it once reserved memory for every step up front
/// and aborted at once); the test stops it after a second.
#[test]
fn the_largest_step_count_runs_without_reserving_for_every_step() {
    let mut child = impulse()
        .args(["run", "stack3", "--steps", "4294967295", "--quiet"])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_secs(1));
    let finished = child.try_wait().unwrap();
    let _ = child.kill();
    let _ = child.wait();
    assert!(finished.is_none(), "the run ended at once: {finished:?}");
}
