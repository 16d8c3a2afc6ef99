//! Ctrl-C (SIGINT) stops a run after the step under way and leaves a valid trajectory: every
//! frame complete, the last one the step it stopped at, and exit status 130.
#![cfg(unix)]

use std::process::{Command, Stdio};
use std::time::Duration;

#[test]
fn sigint_stops_after_a_step_and_keeps_a_valid_file() {
    let csv = crate::common::temp("int", "run.csv");
    let child = Command::new(env!("CARGO_BIN_EXE_impulse"))
        .args([
            "run",
            "pyramid20",
            "--steps",
            "1000000",
            "--quiet",
            "--every",
            "7",
            "--out",
        ])
        .arg(&csv)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(1500));
    let status = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(130), "{stderr}");
    assert!(stderr.contains("interrupted after step"), "{stderr}");
    let stopped: u64 = stderr
        .rsplit("interrupted after step ")
        .next()
        .and_then(|t| t.trim().parse().ok())
        .expect("the step it stopped at");
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut frames: Vec<(u64, usize)> = Vec::new();
    for line in text.lines().skip(1) {
        let fields: Vec<&str> = line.split(',').collect();
        assert_eq!(fields.len(), 10, "a cut line: {line}");
        let frame: u64 = fields[0].parse().unwrap();
        match frames.last_mut() {
            Some((f, n)) if *f == frame => *n += 1,
            _ => frames.push((frame, 1)),
        }
    }
    assert!(
        frames.iter().all(|&(_, n)| n == 211),
        "a frame misses bodies"
    );
    assert_eq!(frames.first().map(|f| f.0), Some(0));
    assert_eq!(frames.last().map(|f| f.0), Some(stopped));
    assert!(stopped > 0 && stopped < 1_000_000);
}

/// With --checkpoint-dir, Ctrl-C also leaves a snapshot of the step the run stopped at, and
/// `impulse resume` continues from it.
#[test]
fn sigint_writes_a_final_checkpoint_that_resumes() {
    let dir = crate::common::temp("int", "checkpoints");
    let child = Command::new(env!("CARGO_BIN_EXE_impulse"))
        .args([
            "run",
            "pyramid20",
            "--steps",
            "1000000",
            "--quiet",
            "--checkpoint-every",
            "100000",
            "--checkpoint-dir",
        ])
        .arg(&dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(1500));
    let status = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(130), "{stderr}");
    let stopped: u64 = stderr
        .rsplit("interrupted after step ")
        .next()
        .and_then(|t| t.trim().parse().ok())
        .expect("the step it stopped at");
    let names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    let last = format!("step-{stopped:06}.snapshot");
    assert_eq!(
        names,
        std::slice::from_ref(&last),
        "only the final checkpoint"
    );
    let resumed = Command::new(env!("CARGO_BIN_EXE_impulse"))
        .arg("resume")
        .arg(dir.join(&last))
        .args(["--steps", "3", "--quiet"])
        .output()
        .unwrap();
    assert!(
        resumed.status.success(),
        "{}",
        String::from_utf8_lossy(&resumed.stderr)
    );
    let summary = String::from_utf8_lossy(&resumed.stdout);
    assert!(
        summary.contains(&format!("{} steps", stopped + 3)),
        "{summary}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
