//! The `impulse` binary end to end: trajectories, summaries, scene errors and LCP commands.

use std::path::{Path, PathBuf};

use crate::common;
use crate::common::{assert_success, impulse, repo};

fn temp(name: &str) -> PathBuf {
    common::temp("cli", name)
}

/// The JSON file at `path`.
fn read_json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

#[test]
fn run_writes_csv_trajectory_and_summary_json() {
    let csv = temp("stack.csv");
    let summary = temp("stack.json");
    let out = impulse()
        .args([
            "run", "stack30", "--steps", "20", "--every", "10", "--quiet",
        ])
        .arg("--out")
        .arg(&csv)
        .arg("--summary-json")
        .arg(&summary)
        .output()
        .unwrap();
    assert_success(&out, "");
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("frame,time,body,x,y,z,qx,qy,qz,qw"));
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    // Frames 0, 10 and 20, each with 31 bodies (ground + 30 cubes) in scene order.
    assert_eq!(rows.len(), 3 * 31);
    assert_eq!(rows[0][0], 0.0);
    assert_eq!(rows[31][0], 10.0);
    assert_eq!(rows[62][0], 20.0);
    for (k, row) in rows.iter().take(31).enumerate() {
        assert_eq!(row[2], k as f64);
        assert_eq!(row[9], 1.0, "identity orientation, scalar last");
    }
    // Body 30 starts at y = 29.5.
    assert!((rows[30][4] - 29.5).abs() < 1e-6);
    let json = read_json(&summary);
    for key in [
        "scene",
        "bodies",
        "steps",
        "dt",
        "ms_per_step",
        "max_overlap_m",
        "top_sink_m",
        "kinetic_energy_j",
        "mean_contacts",
        "stage_ms",
    ] {
        assert!(json.get(key).is_some(), "summary lacks {key}");
    }
    for stage in [
        "broad_phase",
        "narrow_phase",
        "islands",
        "assembly",
        "solve",
        "scatter",
        "store_impulses",
        "finish",
        "end_step",
        "total",
    ] {
        let ms = &json["stage_ms"][stage];
        assert!(ms.is_number(), "stage_ms.{stage}: {ms:?}");
    }
    for phase in impulse::report::SolvePhase::ALL {
        let ms = &json["stage_ms"]["solve_phases"][phase.name()];
        assert!(
            ms.is_number(),
            "stage_ms.solve_phases.{}: {ms:?}",
            phase.name()
        );
    }
    assert_eq!(json["bodies"], 31);
    assert_eq!(json["steps"], 20);
    assert!(String::from_utf8_lossy(&out.stdout).starts_with("stack30: 31 bodies, 20 steps"));
}

#[test]
fn profile_prints_the_median_of_every_stage() {
    let out = impulse()
        .args(["run", "stack3", "--steps", "5", "--quiet", "--profile"])
        .env_remove(impulse::simd::INSTRUCTION_SET_VARIABLE)
        .output()
        .unwrap();
    assert!(out.status.success());
    let stdout = String::from_utf8_lossy(&out.stdout);
    let line = stdout.lines().nth(1).unwrap_or_default();
    let stages: Vec<&str> = line
        .strip_prefix("stages (median ms): ")
        .unwrap_or_else(|| panic!("no stage line in {stdout}"))
        .split(", ")
        .collect();
    assert_eq!(stages.len(), impulse::report::Stage::ALL.len(), "{line}");
    // Then the solve's phases, by their names, timed: some island solved.
    let line = stdout.lines().nth(2).unwrap_or_default();
    let phases: Vec<(&str, f64)> = line
        .strip_prefix("solve phases (median CPU ms summed over islands): ")
        .unwrap_or_else(|| panic!("no phase line in {stdout}"))
        .split(", ")
        .map(|phase| {
            let (name, ms) = phase.rsplit_once(' ').unwrap();
            (name, ms.parse::<f64>().unwrap())
        })
        .collect();
    let names: Vec<&str> = impulse::report::SolvePhase::ALL
        .iter()
        .map(|p| p.name())
        .collect();
    assert_eq!(phases.iter().map(|(n, _)| *n).collect::<Vec<_>>(), names);
    assert!(phases.iter().all(|(_, ms)| *ms >= 0.0), "{line}");
    assert!(phases.iter().any(|(_, ms)| *ms > 0.0), "{line}");
    // Then which build of the SIMD kernels ran: the widest this CPU runs.
    let kernels = stdout.lines().nth(3).unwrap_or_default();
    let name = impulse::simd::InstructionSet::supported_widest().name();
    assert!(
        kernels.starts_with(&format!("SIMD kernels: {name} (")),
        "{kernels}"
    );
    for stage in stages {
        let (_, ms) = stage.rsplit_once(' ').unwrap();
        assert!(ms.parse::<f64>().unwrap() >= 0.0, "{stage}");
    }
}

#[test]
fn jsonl_has_one_object_per_frame() {
    let path = temp("example.jsonl");
    let out = impulse()
        .arg("run")
        .arg(repo("scenes/example-three-spheres.json"))
        .args(["--steps", "5", "--quiet", "--out"])
        .arg(&path)
        .output()
        .unwrap();
    assert_success(&out, "");
    let text = std::fs::read_to_string(&path).unwrap();
    let frames: Vec<serde_json::Value> = text
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(frames.len(), 6);
    assert_eq!(frames[5]["frame"], 5);
    assert_eq!(
        frames[0]["bodies"].as_array().unwrap()[0]
            .as_array()
            .unwrap()
            .len(),
        7
    );
}

#[test]
fn a_malformed_scene_names_file_line_body_and_field() {
    let path = temp("bad.json");
    std::fs::write(
        &path,
        "{\n  \"bodies\": [\n    {\"kind\": \"dynamic\", \"shape\": {\"type\": \"sphere\", \"radius\": -1}}\n  ]\n}\n",
    )
    .unwrap();
    let out = impulse().arg("run").arg(&path).output().unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("bad.json:3:"), "{err}");
    assert!(err.contains("bodies[0]"), "{err}");
    assert!(err.contains("shape.radius"), "{err}");
}

#[test]
fn unknown_scene_lists_the_builtins() {
    let out = impulse().args(["run", "no-such-scene"]).output().unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("pyramid20") && err.contains("stack30"),
        "{err}"
    );
}

#[test]
fn lcp_solve_reports_success_and_failure_through_the_exit_code() {
    let data = repo("crates/impulse-lcp/tests/data/siconos");
    let json = temp("deudeu.json");
    let ok = impulse()
        .args(["lcp", "solve"])
        .arg(data.join("lcp_deudeu.dat"))
        .args(["--solver", "lemke", "--json"])
        .arg(&json)
        .output()
        .unwrap();
    assert_success(&ok, "");
    let result = read_json(&json);
    let z = result["z"].as_array().unwrap();
    assert!((z[0].as_f64().unwrap() - 4.0 / 3.0).abs() < 1e-9);
    assert!((z[1].as_f64().unwrap() - 7.0 / 3.0).abs() < 1e-9);
    // Too few PGS sweeps for mmc: not converged, so the command fails.
    let fail = impulse()
        .args(["lcp", "solve"])
        .arg(data.join("lcp_mmc.dat"))
        .args(["--solver", "pgs", "--iterations", "3"])
        .output()
        .unwrap();
    assert!(!fail.status.success());
}

#[test]
fn lcp_dump_writes_a_step_problem_that_solve_reads() {
    let path = temp("stack-lcp.json");
    let out = impulse()
        .args([
            "lcp",
            "dump",
            "stack30",
            "--step",
            "20",
            "--no-friction",
            "--out",
        ])
        .arg(&path)
        .output()
        .unwrap();
    assert_success(&out, "");
    let solved = impulse()
        .args(["lcp", "solve"])
        .arg(&path)
        .args(["--solver", "pgs", "--iterations", "20000", "--tol", "1e-5"])
        .output()
        .unwrap();
    assert!(
        solved.status.success(),
        "{}",
        String::from_utf8_lossy(&solved.stdout)
    );
}

/// A scene with joints and no contacts (chain20 swinging in the air): the dump has the
/// joints' rows, free (bilateral) rows as a mixed LCP, and Lemke solves it.
#[test]
fn lcp_dump_of_a_chain_has_its_joint_rows_and_lemke_solves_it() {
    let path = temp("chain-lcp.json");
    let out = impulse()
        .args(["lcp", "dump", "chain20", "--step", "5", "--out"])
        .arg(&path)
        .output()
        .unwrap();
    assert_success(&out, "");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("0 contact points") && stdout.contains("joint rows of 20 joints"),
        "{stdout}"
    );
    let solved = impulse()
        .args(["lcp", "solve"])
        .arg(&path)
        .args(["--solver", "lemke"])
        .output()
        .unwrap();
    assert!(
        solved.status.success(),
        "{}{}",
        String::from_utf8_lossy(&solved.stdout),
        String::from_utf8_lossy(&solved.stderr)
    );
}

#[test]
fn a_blow_up_stops_with_the_step_and_keeps_the_frames_written() {
    // A runaway body: a sideways "gravity" of 5970 m/s² adds 99.5 m/s per step, so its speed
    // passes the scene's bound `solver.max_linear_speed` = 10⁴ m/s during step 101 (9950 m/s
    // after step 100). A body merely far away leaves the world instead (tests/far_bodies in
    // the engine).
    let scene = temp("runaway.json");
    std::fs::write(
        &scene,
        r#"{"gravity": [5970, 0, 0], "solver": {"max_linear_speed": 10000, "max_distance": 1e9}, "bodies": [
  {"kind": "dynamic", "shape": {"type": "sphere", "radius": 0.5}, "position": [0, 0, 0]}
]}"#,
    )
    .unwrap();
    let csv = temp("runaway.csv");
    let out = impulse()
        .arg("run")
        .arg(&scene)
        .args(["--steps", "200", "--quiet", "--out"])
        .arg(&csv)
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("blew up at step 101"), "{err}");
    assert!(
        err.contains("linear speed") && err.contains("solver.max_linear_speed = 10000 m/s"),
        "{err}"
    );
    let text = std::fs::read_to_string(&csv).unwrap();
    let last = text.lines().last().unwrap();
    assert!(last.starts_with("100,"), "last frame written: {last}");
}

/// `--preset` takes the presets by name and by bar, and the summary's E is the largest of
/// |sink|, overlap and drift; a preset that does not exist is an error naming the presets.
#[test]
fn presets_by_name_and_bar_and_the_quality_error() {
    let mut errors = Vec::new();
    for preset in ["fast", "q50", "default", "q5", "precise", "q1", "reference"] {
        let summary = temp(&format!("preset-{preset}.json"));
        let out = impulse()
            .args([
                "run", "stack3", "--steps", "30", "--quiet", "--preset", preset,
            ])
            .arg("--summary-json")
            .arg(&summary)
            .output()
            .unwrap();
        assert_success(&out, &format!("{preset}: "));
        let json = read_json(&summary);
        let field = |key: &str| json[key].as_f64().unwrap_or_else(|| panic!("{key}"));
        let e = field("quality_error_m");
        let parts = field("top_sink_m")
            .abs()
            .max(field("max_overlap_m"))
            .max(field("max_drift_m"));
        assert_eq!(e, parts, "{preset}");
        assert!(e < 0.05, "{preset}: a three-cube stack's E is {e} m");
        errors.push((preset, e, json["method"].as_str().unwrap().to_string()));
    }
    // The aliases are the same settings, so the same trajectory.
    for (a, b) in [(0, 1), (2, 3), (4, 5)] {
        assert_eq!(
            errors[a].1, errors[b].1,
            "{} and {}",
            errors[a].0, errors[b].0
        );
    }
    assert_eq!(errors[2].2, "pgs");
    assert_eq!(errors[6].2, "auto");
    let out = impulse()
        .args(["run", "stack3", "--steps", "1", "--quiet", "--preset", "q2"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("invalid value 'q2'") && stderr.contains("precise"),
        "{stderr}"
    );
}

/// The kinematic example runs: its paddle (body 1) moves at its 1.5 m/s along x from
/// x = −4 m, so it is at −2.5 m after 60 steps of 1/60 s.
#[test]
fn a_scene_with_kinematic_bodies_runs() {
    let path = temp("kinematic.jsonl");
    let out = impulse()
        .arg("run")
        .arg(repo("scenes/kinematic.json"))
        .args(["--steps", "60", "--quiet", "--out"])
        .arg(&path)
        .output()
        .unwrap();
    assert_success(&out, "");
    let text = std::fs::read_to_string(&path).unwrap();
    let last: serde_json::Value = serde_json::from_str(text.lines().last().unwrap()).unwrap();
    assert_eq!(last["frame"], 60);
    let paddle_x = last["bodies"][1][0].as_f64().unwrap();
    assert!((paddle_x + 2.5).abs() < 1e-3, "paddle at x = {paddle_x}");
}

#[test]
fn keyframes_out_of_order_name_file_line_body_and_field() {
    let path = temp("keyframes.json");
    std::fs::write(
        &path,
        "{\n  \"bodies\": [\n    {\"name\": \"lift\", \"kind\": \"kinematic\", \"shape\": {\"type\": \"sphere\", \"radius\": 1},\n     \"keyframes\": [{\"t\": 2, \"position\": [0, 1, 0]},\n                   {\"t\": 1, \"position\": [0, 2, 0]}]}\n  ]\n}\n",
    )
    .unwrap();
    let out = impulse().arg("run").arg(&path).output().unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("keyframes.json:5:"), "{err}");
    assert!(err.contains("lift"), "{err}");
    assert!(err.contains("keyframes[1].t"), "{err}");
}

/// The widest build of the SIMD kernels this CPU runs (x86-64-v4 where it has AVX-512,
/// x86-64-v3 where it has AVX2) gives the trajectories of the baseline build to the byte: the one island of pyramid3d10 on two
/// threads (the parallel pack, sweeps and record), pyramid20 on one, and bouncing spheres
/// (restitution, so assembly computes the lever-arm products itself). On a CPU without
/// either both runs take the baseline and the comparison says nothing; the test says so.
#[test]
fn instruction_sets_give_the_same_trajectories_to_the_byte() {
    let widest = impulse::simd::InstructionSet::supported_widest();
    if widest == impulse::simd::InstructionSet::Baseline {
        eprintln!(
            "this CPU has neither x86-64-v3 nor x86-64-v4: both runs take the baseline kernels"
        );
    }
    let runs: [&[&str]; 3] = [
        &["pyramid3d10", "--steps", "20", "--threads", "2"],
        &["pyramid20", "--steps", "60", "--threads", "1"],
        &[
            "scenes/example-three-spheres.json",
            "--steps",
            "90",
            "--threads",
            "1",
        ],
    ];
    for (k, args) in runs.into_iter().enumerate() {
        let trajectory = |set: Option<&str>| {
            let path = temp(&format!("isa-{k}-{}.jsonl", set.unwrap_or("detected")));
            let mut command = impulse();
            command.current_dir(repo("")).arg("run").args(args);
            command.args(["--no-sleep", "--quiet", "--out"]).arg(&path);
            command.env_remove(impulse::simd::INSTRUCTION_SET_VARIABLE);
            if let Some(set) = set {
                command.env(impulse::simd::INSTRUCTION_SET_VARIABLE, set);
            }
            let out = command.output().unwrap();
            assert_success(&out, &format!("{args:?}: "));
            std::fs::read(&path).unwrap()
        };
        let (baseline, detected) = (trajectory(Some("baseline")), trajectory(None));
        assert!(!baseline.is_empty());
        assert!(baseline == detected, "{args:?}: the trajectories differ");
    }
}
