//! The command line's edges: bounds on threads, counts and input sizes, outputs that would
//! overwrite each other, write errors, termination signals, zero steps, progress options, the
//! summary line of moving scenes, and presets that keep a scene's physics.

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

use crate::common::{assert_success, fresh_dir, impulse, repo, temp};

const SUITE: &str = "edges";

/// Runs `command` and returns its output, failing the test if it has not ended within
/// `seconds` (a hang or a read of an endless file is the defect these tests guard against).
fn output_within(command: &mut Command, seconds: u64) -> Output {
    let mut child = command
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let deadline = Instant::now() + Duration::from_secs(seconds);
    while child.try_wait().unwrap().is_none() {
        if Instant::now() > deadline {
            let _ = child.kill();
            let _ = child.wait();
            panic!("still running after {seconds} s: {command:?}");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    child.wait_with_output().unwrap()
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

fn stdout(out: &Output) -> String {
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// Asserts that `out` failed with a message containing each of `parts`.
fn assert_refused(out: &Output, parts: &[&str]) {
    let err = stderr(out);
    assert!(!out.status.success(), "accepted: {err}");
    for part in parts {
        assert!(err.contains(part), "missing {part:?} in: {err}");
    }
}

fn logical_cpus() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

#[test]
fn threads_are_bounded_by_four_per_cpu_and_zero_is_all_cpus() {
    let too_many = (4 * logical_cpus() + 1).to_string();
    for threads in ["1000000", too_many.as_str()] {
        let out = output_within(
            impulse().args([
                "run",
                "stack3",
                "--steps",
                "1",
                "--quiet",
                "--threads",
                threads,
            ]),
            60,
        );
        assert_refused(&out, &[&format!("--threads {threads}"), "logical CPUs"]);
    }
    let most = (4 * logical_cpus()).to_string();
    for threads in ["0", most.as_str()] {
        let out = output_within(
            impulse().args([
                "run",
                "stack3",
                "--steps",
                "2",
                "--quiet",
                "--threads",
                threads,
            ]),
            120,
        );
        assert_success(&out, &format!("--threads {threads}: "));
    }
    let out = output_within(
        impulse().args(["bench", "stack3", "--steps", "1", "--threads", "1000000"]),
        60,
    );
    assert_refused(&out, &["--threads 1000000"]);
}

/// A count far beyond any use is a field error at once, not a run that never ends.
#[test]
fn a_huge_substep_count_is_a_field_error() {
    let path = temp(SUITE, "substeps.json");
    let scene = r#"{"name": "s", "solver": {"substeps": 4294967295},
        "bodies": [{"kind": "dynamic", "shape": {"type": "sphere", "radius": 0.5}}]}"#;
    std::fs::write(&path, scene).unwrap();
    let out = output_within(impulse().arg("run").arg(&path).arg("--quiet"), 60);
    assert_refused(&out, &["solver.substeps", "≤ 10000", "4294967295"]);
    for option in ["--substeps", "--iterations", "--relax", "--impact-sweeps"] {
        let out = output_within(
            impulse().args(["run", "stack3", "--quiet", option, "4294967295"]),
            60,
        );
        assert_refused(&out, &["≤ 10000", "4294967295"]);
    }
}

/// 3,000 coincident spheres: refused with where they pile up and exit 1, before any pair is
/// listed (they once took 17 GB in the overlap measure and aborted).
#[test]
fn a_pile_of_coincident_spheres_is_refused_with_where_it_is() {
    let path = temp(SUITE, "pile.json");
    let ball =
        r#"{"kind": "dynamic", "shape": {"type": "sphere", "radius": 0.5}, "position": [0, 0, 0]}"#;
    let bodies = vec![ball; 3_000].join(",\n");
    std::fs::write(&path, format!("{{\"bodies\": [{bodies}]}}")).unwrap();
    let out = output_within(impulse().arg("run").arg(&path).arg("--quiet"), 60);
    assert_refused(
        &out,
        &["3000 bodies overlap at (0, 0, 0)", "spread the bodies out"],
    );
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
}

/// Values derived from a scene are checked where they come from: a 1e-20 m ball's mass
/// (named by the shape, with the density it was made from), a 1e25 kg/m³ density, a 1e30 Hz
/// joint spring and 1e30 m/s² gravity are refused with file, line and field; a scene that is
/// not an object says what a scene is; a capsule spinning at a rifle bullet's 18,850 rad/s
/// runs.
#[test]
fn derived_and_extreme_values_are_refused_at_the_door() {
    let cases = [
        (
            r#"{"bodies": [{"kind": "dynamic", "shape": {"type": "sphere", "radius": 1e-20}}]}"#,
            vec![
                "tiny.json:1:",
                "bodies[0].shape",
                "mass must be within",
                "material.density 1000",
            ],
        ),
        (
            r#"{"bodies": [{"kind": "dynamic", "shape": {"type": "sphere", "radius": 1},
                "material": {"friction": 0.5, "restitution": 0, "density": 1e25}}]}"#,
            vec!["tiny.json:2:", "bodies[0].material.density", "1e12"],
        ),
        (
            r#"{"gravity": [0, -1e30, 0], "bodies": []}"#,
            vec!["tiny.json:1:", "gravity", "1e4"],
        ),
        (
            "[]",
            vec!["tiny.json:1:", "a scene is a JSON object", "`bodies`"],
        ),
    ];
    for (scene, parts) in cases {
        let path = temp(SUITE, "tiny.json");
        std::fs::write(&path, scene).unwrap();
        let out = output_within(impulse().arg("run").arg(&path).arg("--quiet"), 60);
        assert_refused(&out, &parts);
    }
    let path = temp(SUITE, "bullet.json");
    std::fs::write(
        &path,
        r#"{"bodies": [
  {"kind": "static", "shape": {"type": "half_space", "normal": [0, 1, 0]}},
  {"kind": "dynamic", "shape": {"type": "capsule", "half_height": 0.01, "radius": 0.004},
   "position": [0, 1, 0], "linear_velocity": [800, -5, 0], "angular_velocity": [18850, 0, 0]}
]}"#,
    )
    .unwrap();
    let out = output_within(
        impulse()
            .arg("run")
            .arg(&path)
            .args(["--quiet", "--steps", "30"]),
        60,
    );
    assert!(out.status.success(), "{}", stderr(&out));
}

#[test]
fn a_scene_that_is_not_a_regular_file_or_too_large_is_refused_before_reading() {
    let out = output_within(impulse().args(["run", "/dev/zero", "--quiet"]), 30);
    assert_refused(&out, &["/dev/zero", "not a regular file"]);
    let dir = fresh_dir(SUITE, "a_directory.json");
    let out = output_within(impulse().arg("run").arg(&dir).arg("--quiet"), 30);
    assert_refused(&out, &["not a regular file"]);
    // A sparse file one byte over the limit: refused from its size, not read.
    let big = temp(SUITE, "big.json");
    let file = std::fs::File::create(&big).unwrap();
    file.set_len(256 * 1024 * 1024 + 1).unwrap();
    drop(file);
    let out = output_within(impulse().arg("run").arg(&big).arg("--quiet"), 30);
    assert_refused(&out, &["268435457 bytes", "268435456 bytes (256 MiB)"]);
    std::fs::remove_file(&big).unwrap();
}

#[test]
fn a_byte_order_mark_is_skipped_in_scene_and_lcp_files() {
    let exported = impulse().args(["export", "stack3"]).output().unwrap();
    assert_success(&exported, "export: ");
    let scene = temp(SUITE, "bom_scene.json");
    let mut text = "\u{feff}".as_bytes().to_vec();
    text.extend_from_slice(&exported.stdout);
    std::fs::write(&scene, &text).unwrap();
    let out = output_within(
        impulse()
            .arg("run")
            .arg(&scene)
            .args(["--steps", "2", "--quiet"]),
        60,
    );
    assert_success(&out, "a scene with a BOM: ");

    let lcp = temp(SUITE, "bom_lcp.json");
    std::fs::write(
        &lcp,
        "\u{feff}{\"n\": 2, \"a\": [[2.0, 1.0], [1.0, 2.0]], \"b\": [3.0, 3.0]}",
    )
    .unwrap();
    let out = output_within(impulse().args(["lcp", "solve"]).arg(&lcp), 30);
    assert_success(&out, "an LCP with a BOM: ");
    // The exact solution γ = (1, 1): A γ = b with both rows active.
    assert!(stdout(&out).contains("converged"), "{}", stdout(&out));
}

/// n = 50,000 would need 80 GB of dense storage: Lemke refuses, naming the size, at once.
#[test]
fn lemke_refuses_a_problem_above_its_dense_limit() {
    let n = 50_000;
    let indptr: Vec<usize> = (0..=n).collect();
    let indices: Vec<usize> = (0..n).collect();
    let lcp = serde_json::json!({
        "n": n,
        "a": {"csr": {"indptr": indptr, "indices": indices, "values": vec![1.0; n]}},
        "b": vec![1.0; n],
    });
    let path = temp(SUITE, "identity50000.json");
    std::fs::write(&path, lcp.to_string()).unwrap();
    let out = output_within(
        impulse()
            .args(["lcp", "solve"])
            .arg(&path)
            .args(["--solver", "lemke"]),
        60,
    );
    assert_refused(&out, &["n = 50000", "80.0 GB", "n ≤ 8000"]);
    // PGS solves it: γ = b on the identity.
    let out = output_within(
        impulse()
            .args(["lcp", "solve"])
            .arg(&path)
            .args(["--solver", "pgs"]),
        60,
    );
    assert_success(&out, "pgs: ");
}

#[test]
fn two_outputs_to_one_path_are_refused_before_anything_runs() {
    let dir = fresh_dir(SUITE, "same_path");
    let a = dir.join("a.csv");
    let same = dir.join(".").join("a.csv");
    let cases: [(&str, &Path); 3] = [
        ("--stats", &a),
        ("--summary-json", &same),
        ("--island-report", &a),
    ];
    for (option, path) in cases {
        let out = output_within(
            impulse()
                .args(["run", "stack3", "--steps", "2", "--quiet", "--out"])
                .arg(&a)
                .arg(option)
                .arg(path),
            30,
        );
        assert_refused(&out, &["--out and ", option, "a.csv"]);
        assert!(!a.exists(), "{option}: something ran");
    }
    // An output among the checkpoint files, or the scene file read.
    let checkpoints = dir.join("checkpoints");
    let out = output_within(
        impulse()
            .args([
                "run",
                "stack3",
                "--steps",
                "2",
                "--quiet",
                "--checkpoint-dir",
            ])
            .arg(&checkpoints)
            .arg("--summary-json")
            .arg(checkpoints.join("step-000002.snapshot")),
        30,
    );
    assert_refused(&out, &["--summary-json", "--checkpoint-dir"]);
    let scene = dir.join("scene.json");
    std::fs::copy(repo("scenes/stack30.json"), &scene).unwrap();
    let out = output_within(
        impulse()
            .arg("run")
            .arg(&scene)
            .args(["--steps", "2", "--quiet", "--summary-json"])
            .arg(&scene),
        30,
    );
    assert_refused(&out, &["scene file"]);
    let kept = std::fs::read(repo("scenes/stack30.json")).unwrap();
    assert_eq!(
        std::fs::read(&scene).unwrap(),
        kept,
        "the scene was overwritten"
    );
}

/// A checkpoint of stack3 after 3 steps, in a fresh directory `name`.
fn checkpoint(name: &str) -> PathBuf {
    let dir = fresh_dir(SUITE, name);
    let out = output_within(
        impulse()
            .args([
                "run",
                "stack3",
                "--steps",
                "3",
                "--quiet",
                "--checkpoint-dir",
            ])
            .arg(&dir),
        60,
    );
    assert_success(&out, "checkpoint: ");
    dir.join("step-000003.snapshot")
}

#[cfg(target_os = "linux")]
#[test]
fn every_write_error_names_its_file_and_fails() {
    let snapshot = checkpoint("write_errors");
    let out = output_within(
        impulse().arg("resume").arg(&snapshot).args([
            "--steps",
            "2",
            "--quiet",
            "--out",
            "/dev/full",
        ]),
        30,
    );
    assert_refused(&out, &["/dev/full"]);
    // A file name the writers accept, on a device that is always full.
    let dir = fresh_dir(SUITE, "full");
    for (option, name) in [
        ("--out", "full.csv"),
        ("--out", "full.jsonl"),
        ("--stats", "full.csv"),
        ("--island-report", "full.jsonl"),
        ("--summary-json", "full.json"),
    ] {
        let link = dir.join(name);
        let _ = std::fs::remove_file(&link);
        std::os::unix::fs::symlink("/dev/full", &link).unwrap();
        for command in ["run", "resume"] {
            let mut cmd = impulse();
            match command {
                "run" => cmd.args(["run", "stack3"]),
                _ => cmd.arg("resume").arg(&snapshot),
            };
            let out = output_within(cmd.args(["--steps", "2", "--quiet", option]).arg(&link), 60);
            assert_refused(&out, &[name, "No space left on device"]);
        }
    }
    let link = dir.join("full.gif");
    let _ = std::fs::remove_file(&link);
    std::os::unix::fs::symlink("/dev/full", &link).unwrap();
    let out = output_within(
        impulse()
            .args([
                "render", "stack3", "--steps", "2", "--size", "32x32", "--quiet", "--gif",
            ])
            .arg(&link),
        60,
    );
    assert_refused(&out, &["full.gif", "No space left on device"]);
}

/// SIGTERM and SIGHUP stop a run as Ctrl-C does: after the step under way, every frame whole,
/// a checkpoint of that step, status 130.
#[cfg(unix)]
#[test]
fn sigterm_and_sighup_finish_the_frame_and_write_the_checkpoint() {
    for signal in ["TERM", "HUP"] {
        let dir = fresh_dir(SUITE, &format!("signal_{signal}"));
        let csv = dir.join("run.csv");
        let checkpoints = dir.join("checkpoints");
        let child = impulse()
            .args([
                "run",
                "pyramid20",
                "--steps",
                "1000000",
                "--quiet",
                "--every",
                "7",
            ])
            .arg("--out")
            .arg(&csv)
            .args(["--checkpoint-every", "100000", "--checkpoint-dir"])
            .arg(&checkpoints)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        // Until the first frames are on disk: the handler is installed before stepping.
        let deadline = Instant::now() + Duration::from_secs(60);
        while std::fs::read_to_string(&csv).map_or(0, |t| t.lines().count()) < 2 * 211 {
            assert!(Instant::now() < deadline, "{signal}: no frames written");
            std::thread::sleep(Duration::from_millis(50));
        }
        let status = Command::new("kill")
            .args([&format!("-{signal}"), &child.id().to_string()])
            .status()
            .unwrap();
        assert!(status.success());
        let out = child.wait_with_output().unwrap();
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(130), "{signal}: {err}");
        let stopped: u64 = err
            .rsplit("interrupted after step ")
            .next()
            .and_then(|t| t.trim().parse().ok())
            .unwrap_or_else(|| panic!("{signal}: the step it stopped at: {err}"));
        let text = std::fs::read_to_string(&csv).unwrap();
        let mut last_frame = None;
        let mut rows = 0;
        for line in text.lines().skip(1) {
            let fields: Vec<&str> = line.split(',').collect();
            assert_eq!(fields.len(), 10, "{signal}: a torn row: {line}");
            last_frame = Some(fields[0].parse::<u64>().unwrap());
            rows += 1;
        }
        assert_eq!(rows % 211, 0, "{signal}: a frame misses bodies");
        assert_eq!(last_frame, Some(stopped), "{signal}");
        let snapshot = checkpoints.join(format!("step-{stopped:06}.snapshot"));
        assert!(
            snapshot.is_file(),
            "{signal}: no checkpoint of step {stopped}"
        );
    }
}

#[test]
fn zero_steps_of_run_and_resume_are_refused_with_a_clear_message() {
    // (`render --steps 0` draws the initial state: tests/render.rs.)
    let out = output_within(impulse().args(["run", "stack3", "--steps", "0"]), 30);
    assert_refused(&out, &["--steps", "0 is not in 1.."]);
    let snapshot = checkpoint("zero_steps");
    let out = output_within(
        impulse()
            .arg("resume")
            .arg(&snapshot)
            .args(["--steps", "0"]),
        30,
    );
    assert_refused(&out, &["--steps", "0 is not in 1.."]);
    // The snapshot is the run's last step: nothing to resume without --steps.
    let out = output_within(impulse().arg("resume").arg(&snapshot), 30);
    assert_refused(&out, &["step 3, the last of its run", "--steps"]);
    let path = temp(SUITE, "zero_steps.json");
    std::fs::write(
        &path,
        r#"{"name": "zero", "steps": 0,
        "bodies": [{"kind": "dynamic", "shape": {"type": "sphere", "radius": 0.5}}]}"#,
    )
    .unwrap();
    let out = output_within(impulse().arg("run").arg(&path).arg("--quiet"), 30);
    assert_refused(&out, &["\"zero\" asks for 0 steps", "--steps"]);
}

#[test]
fn render_and_bench_take_quiet() {
    let gif = temp(SUITE, "quiet.gif");
    let out = output_within(
        impulse()
            .args([
                "render", "stack3", "--steps", "3", "--size", "32x32", "--quiet", "--gif",
            ])
            .arg(&gif),
        120,
    );
    assert_success(&out, "render --quiet: ");
    assert!(stderr(&out).is_empty(), "{}", stderr(&out));
    let out = output_within(
        impulse().args(["bench", "stack3", "--steps", "2", "--quiet"]),
        120,
    );
    assert_success(&out, "bench --quiet: ");
    assert!(!stderr(&out).contains("measured"), "{}", stderr(&out));
}

/// Top sink, drift and E are errors only for a scene that starts at rest; a thrown body's
/// travel is labelled as motion.
#[test]
fn the_summary_labels_sink_and_drift_of_a_moving_scene() {
    let out = output_within(
        impulse().args(["run", "stack3", "--steps", "3", "--quiet"]),
        60,
    );
    assert_success(&out, "stack3: ");
    let line = stdout(&out);
    assert!(line.contains("top sink") && line.contains("(E "), "{line}");
    assert!(!line.contains("moving scene"), "{line}");
    let out = output_within(
        impulse()
            .arg("run")
            .arg(repo("scenes/pyramid20_projectile.json"))
            .args(["--steps", "3", "--quiet", "--summary-json"])
            .arg(temp(SUITE, "moving.json")),
        120,
    );
    assert_success(&out, "pyramid20_projectile: ");
    let line = stdout(&out);
    assert!(
        line.contains("moving scene, not errors: top sink"),
        "{line}"
    );
    assert!(!line.contains("(E "), "{line}");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(temp(SUITE, "moving.json")).unwrap())
            .unwrap();
    assert_eq!(summary["starts_at_rest"], false);
}

/// The highest point a ball dropped from 0.15 m above a ground (impact at 1.7 m/s, restitution
/// 0.9) reaches after its first impact, with the scene's `solver` object and `args`.
fn rebound_height(solver: &str, args: &[&str]) -> f64 {
    let scene = format!(
        r#"{{"name": "drop", "dt": 0.016666668, "steps": 60, "solver": {solver},
        "bodies": [
          {{"kind": "static", "shape": {{"type": "half_space", "normal": [0, 1, 0]}}}},
          {{"kind": "dynamic", "shape": {{"type": "sphere", "radius": 0.1}},
            "position": [0, 0.25, 0],
            "material": {{"friction": 0.5, "restitution": 0.9, "density": 1000}}}}
        ]}}"#
    );
    let path = temp(SUITE, "drop.json");
    std::fs::write(&path, scene).unwrap();
    let csv = temp(SUITE, "drop.csv");
    let out = output_within(
        impulse()
            .arg("run")
            .arg(&path)
            .args(["--quiet", "--out"])
            .arg(&csv)
            .args(args),
        60,
    );
    assert_success(&out, "drop: ");
    // Body 1's height (m) per frame; the impact is near t = 0.175 s, frame 10.
    let heights: Vec<f64> = std::fs::read_to_string(&csv)
        .unwrap()
        .lines()
        .skip(1)
        .filter(|l| l.split(',').nth(2) == Some("1"))
        .map(|l| l.split(',').nth(4).unwrap().parse().unwrap())
        .collect();
    let landed = heights
        .iter()
        .position(|&y| y < 0.105)
        .expect("the ball reaches the ground");
    heights[landed..].iter().fold(f64::MIN, |a, &b| a.max(b)) - 0.1
}

/// A preset sets solver effort only: the scene's restitution threshold (2 m/s, above the
/// 1.7 m/s impact) keeps the ball from bouncing under `--preset fast` as without it.
#[test]
fn a_preset_keeps_the_scenes_restitution_threshold() {
    let no_bounce = r#"{"restitution_threshold": 2.0}"#;
    for args in [
        &[][..],
        &["--preset", "fast"],
        &["--quality", "q1"],
        &["--preset", "reference"],
    ] {
        let rebound = rebound_height(no_bounce, args);
        assert!(rebound < 0.005, "{args:?}: bounced {rebound:.3} m");
    }
    // The same drop at the default threshold (0.5 m/s) bounces: the check can fail.
    let rebound = rebound_height("{}", &["--preset", "fast"]);
    assert!(rebound > 0.05, "bounced only {rebound:.3} m");
}

/// The commands of the README and of docs/cli.md write only files outside the repository's
/// tracked tree: absolute paths under /tmp, or bare names in the working directory that
/// `.gitignore` ignores.
#[test]
fn the_documented_examples_write_outside_tracked_files() {
    let gitignore = std::fs::read_to_string(repo(".gitignore")).unwrap();
    let ignored = |name: &str| {
        gitignore.lines().any(|pattern| {
            let pattern = pattern.trim().trim_start_matches('/');
            pattern
                .strip_prefix('*')
                .is_some_and(|extension| !pattern.contains('/') && name.ends_with(extension))
                || pattern.trim_end_matches('/') == name
        })
    };
    for doc in ["README.md", "docs/cli.md"] {
        let text = std::fs::read_to_string(repo(doc)).unwrap();
        let checked = outputs_outside_tracked_files(doc, &text, &ignored);
        assert!(checked >= 3, "only {checked} outputs found in {doc}");
    }
}

/// How many outputs the commands of `doc` (text `text`) write, each checked to be under /tmp
/// or a bare name that `ignored` says `.gitignore` ignores.
fn outputs_outside_tracked_files(doc: &str, text: &str, ignored: &dyn Fn(&str) -> bool) -> usize {
    let mut checked = 0;
    // Commands continued over lines with a trailing backslash, joined.
    let joined = text.replace("\\\n", " ");
    for line in joined.lines() {
        let line = line.trim();
        if !(line.starts_with("impulse ") || line.starts_with("cargo run")) {
            continue;
        }
        let words: Vec<&str> = line.split_whitespace().collect();
        for pair in words.windows(2) {
            if [
                "--out",
                "--gif",
                "--stats",
                "--summary-json",
                "--island-report",
            ]
            .contains(&pair[0])
            {
                let path = pair[1];
                checked += 1;
                let outside = path.starts_with("/tmp/");
                let bare_and_ignored = !path.contains('/') && ignored(path);
                assert!(
                    outside || bare_and_ignored,
                    "{doc} example writes {path} inside the repository: {line}"
                );
            }
        }
    }
    checked
}

/// `lcp engine-convergence` replays a run once per iteration count: it takes --quiet too.
#[test]
fn engine_convergence_takes_quiet() {
    let svg = temp(SUITE, "engine.svg");
    let out = output_within(
        impulse()
            .args(["lcp", "engine-convergence", "stack3", "--step", "3"])
            .args(["--iterations", "2", "--quiet", "--out"])
            .arg(&svg),
        120,
    );
    assert_success(&out, "engine-convergence --quiet: ");
    assert!(stderr(&out).is_empty(), "{}", stderr(&out));
    assert!(
        stdout(&out).contains("pgs   residual after 2 iterations"),
        "{}",
        stdout(&out)
    );
}
