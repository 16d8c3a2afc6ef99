//! `impulse run --checkpoint-every K --checkpoint-dir DIR` and `impulse resume`: a run resumed
//! from a checkpoint writes the same trajectory rows, to the last digit, as the run that was
//! never stopped, on one and two threads; a damaged snapshot is a clear error.

use std::path::Path;

use crate::common::{assert_success, fresh_dir, impulse, temp};

const SUITE: &str = "checkpoint";

/// Trajectory rows (`frame,time,body,x,y,z,qx,qy,qz,qw`) of `path`, without the header.
fn rows(path: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("frame,time,body,x,y,z,qx,qy,qz,qw"));
    lines.map(str::to_string).collect()
}

fn frame(row: &str) -> u64 {
    row.split(',').next().unwrap().parse().unwrap()
}

/// Runs `scene` for `steps` steps in one go and again with checkpoints every `k` steps, then
/// resumes from the first checkpoint on each thread count: the resumed rows must be the
/// uninterrupted run's rows after the checkpoint's step.
fn resumed_rows_match(scene: &str, steps: u32, k: u32, every: u32) {
    let dir = fresh_dir(SUITE, scene);
    let whole = dir.join("whole.csv");
    let steps_arg = steps.to_string();
    let every_arg = every.to_string();
    let out = impulse()
        .args(["run", scene, "--steps", &steps_arg, "--every", &every_arg])
        .args(["--quiet", "--threads", "1", "--out"])
        .arg(&whole)
        .output()
        .unwrap();
    assert_success(&out, "uninterrupted run: ");
    let checkpoints = dir.join("checkpoints");
    let out = impulse()
        .args(["run", scene, "--steps", &steps_arg, "--every", &every_arg])
        .args([
            "--quiet",
            "--threads",
            "2",
            "--checkpoint-every",
            &k.to_string(),
        ])
        .arg("--checkpoint-dir")
        .arg(&checkpoints)
        .output()
        .unwrap();
    assert_success(&out, "run with checkpoints: ");
    let mut names: Vec<String> = std::fs::read_dir(&checkpoints)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    names.sort();
    let mut expected: Vec<String> = (1..=steps / k)
        .map(|i| format!("step-{:06}.snapshot", i * k))
        .collect();
    if !steps.is_multiple_of(k) {
        expected.push(format!("step-{steps:06}.snapshot"));
    }
    assert_eq!(
        names, expected,
        "one checkpoint every {k} steps and the last"
    );

    let whole_rows = rows(&whole);
    let after: Vec<&String> = whole_rows
        .iter()
        .filter(|r| frame(r) > u64::from(k))
        .collect();
    assert!(!after.is_empty());
    for threads in ["1", "2"] {
        let resumed = dir.join(format!("resumed-{threads}.csv"));
        let out = impulse()
            .arg("resume")
            .arg(checkpoints.join(&expected[0]))
            .args(["--quiet", "--threads", threads, "--out"])
            .arg(&resumed)
            .output()
            .unwrap();
        assert_success(&out, "resume: ");
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert!(
            stdout.starts_with(&format!("{scene}: ")) && stdout.contains(&format!("{steps} steps")),
            "the summary names the scene and the run's last step: {stdout}"
        );
        let resumed_rows = rows(&resumed);
        assert!(
            resumed_rows.iter().collect::<Vec<_>>() == after,
            "{scene}: resumed on {threads} thread(s) from step {k}: the rows differ from the \
             uninterrupted run's ({} rows against {})",
            resumed_rows.len(),
            after.len()
        );
    }
}

#[test]
fn pyramid20_resumed_from_a_checkpoint_writes_the_uninterrupted_rows() {
    resumed_rows_match("pyramid20", 90, 40, 7);
}

#[test]
fn balls4096_resumed_from_a_checkpoint_writes_the_uninterrupted_rows() {
    resumed_rows_match("balls4096", 30, 20, 5);
}

/// `--steps` counts from the snapshot's step; frames continue to be numbered by step.
#[test]
fn resume_steps_count_from_the_snapshot() {
    let dir = fresh_dir(SUITE, "steps");
    let out = impulse()
        .args([
            "run",
            "stack3",
            "--steps",
            "10",
            "--quiet",
            "--checkpoint-dir",
        ])
        .arg(&dir)
        .output()
        .unwrap();
    assert_success(&out, "");
    let csv = dir.join("more.csv");
    let out = impulse()
        .arg("resume")
        .arg(dir.join("step-000010.snapshot"))
        .args(["--steps", "5", "--quiet", "--out"])
        .arg(&csv)
        .output()
        .unwrap();
    assert_success(&out, "");
    let frames: Vec<u64> = rows(&csv).iter().map(|r| frame(r)).collect();
    let mut distinct = frames.clone();
    distinct.dedup();
    assert_eq!(distinct, [11, 12, 13, 14, 15]);
}

#[test]
fn a_damaged_snapshot_is_a_clear_error() {
    let dir = fresh_dir(SUITE, "damaged");
    let out = impulse()
        .args([
            "run",
            "stack3",
            "--steps",
            "5",
            "--quiet",
            "--checkpoint-dir",
        ])
        .arg(&dir)
        .output()
        .unwrap();
    assert_success(&out, "");
    let good = std::fs::read(dir.join("step-000005.snapshot")).unwrap();
    let cases: [(&str, Vec<u8>, &str); 4] = [
        (
            "cut.snapshot",
            good[..good.len() / 2].to_vec(),
            "snapshot truncated",
        ),
        (
            "flipped.snapshot",
            {
                let mut b = good.clone();
                let last = b.len() - 1;
                b[last] ^= 1;
                b
            },
            "snapshot corrupt: payload checksum",
        ),
        (
            "scene.snapshot",
            b"{\"name\": \"x\", \"bodies\": []}".to_vec(),
            "not an impulse world snapshot",
        ),
        (
            "newer.snapshot",
            {
                let mut b = good.clone();
                b[16] = 9;
                b
            },
            "snapshot format version 9",
        ),
    ];
    for (name, bytes, message) in cases {
        let path = dir.join(name);
        std::fs::write(&path, bytes).unwrap();
        let out = impulse()
            .arg("resume")
            .arg(&path)
            .arg("--quiet")
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{name}: {stderr}");
        assert!(
            stderr.starts_with("error: ") && stderr.contains(message),
            "{name}: {stderr}"
        );
    }
    let missing = impulse()
        .arg("resume")
        .arg(temp(SUITE, "missing.snapshot"))
        .output()
        .unwrap();
    assert!(String::from_utf8_lossy(&missing.stderr).contains("missing.snapshot"));
}

#[test]
fn checkpoint_every_needs_a_directory() {
    let out = impulse()
        .args(["run", "stack3", "--steps", "5", "--checkpoint-every", "2"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--checkpoint-dir"));
}
