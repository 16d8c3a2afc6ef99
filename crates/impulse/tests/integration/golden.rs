//! Golden trajectories: behaviour never changes silently (docs/testing.md, "Golden
//! trajectories").
//!
//! The standard scenes and the scene files with every shape, kinematic bodies, meshes and
//! compounds are stepped a fixed number of steps on 1 and on 2 threads. Every body's position,
//! orientation, linear and angular velocity after every step (f32, little-endian bytes, scene
//! order) is hashed with 64-bit FNV-1a; the two thread counts must agree, and the hash must
//! equal the one stored in `tests/data/golden-trajectories.txt`. A change of the engine that
//! moves any body by one bit fails here until the stored file is rewritten on purpose:
//!
//! ```text
//! IMPULSE_BLESS=1 cargo test -p impulse --test integration golden::
//! ```
//!
//! and committed with the reason in the commit message.

use std::collections::BTreeMap;
use std::hash::Hasher;
use std::path::{Path, PathBuf};

use fnv::FnvHasher;
use impulse::scene::{builtin_scene, load_scene_file};
use impulse::{Scene, World};

/// The command that rewrites the stored hashes.
const BLESS: &str = "IMPULSE_BLESS=1 cargo test -p impulse --test integration golden::";

/// A scene of the golden set and the steps it is run.
struct Case {
    name: &'static str,
    steps: u32,
    /// A built-in name, or a file under `scenes/` when it ends in `.json`.
    source: &'static str,
}

/// The golden set. Steps are enough for each scene's bodies to fall, meet and pile (contacts,
/// friction, sleeping where the scene sleeps), within a few seconds for all on 1 and 2
/// threads in the test profile.
const CASES: &[Case] = &[
    Case {
        name: "pyramid20",
        steps: 240,
        source: "pyramid20",
    },
    Case {
        name: "stack30",
        steps: 240,
        source: "stack30",
    },
    Case {
        name: "massratio",
        steps: 240,
        source: "massratio",
    },
    Case {
        name: "pyramid3d10",
        steps: 240,
        source: "pyramid3d10",
    },
    Case {
        name: "balls1k",
        steps: 240,
        source: "balls1k",
    },
    Case {
        name: "ragdollpile",
        steps: 150,
        source: "ragdollpile",
    },
    Case {
        name: "shapes",
        steps: 300,
        source: "shapes.json",
    },
    Case {
        name: "kinematic",
        steps: 300,
        source: "kinematic.json",
    },
    Case {
        name: "mesh_terrain",
        steps: 300,
        source: "mesh_terrain.json",
    },
    Case {
        name: "compound",
        steps: 300,
        source: "compound.json",
    },
];

fn repository() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn stored_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/golden-trajectories.txt")
}

fn scene(case: &Case) -> Scene {
    if case.source.ends_with(".json") {
        let path = repository().join("scenes").join(case.source);
        load_scene_file(&path).unwrap_or_else(|e| panic!("{e}"))
    } else {
        builtin_scene(case.source).unwrap_or_else(|| panic!("no built-in {}", case.source))
    }
}

/// FNV-1a over every body's state after each of `steps` steps of `scene`, on a pool of
/// `threads` threads (the scene's own settings, sleeping included).
fn trajectory_hash(scene: &Scene, steps: u32, threads: usize) -> u64 {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| {
        let mut world = World::from_scene(scene).unwrap();
        let mut hasher = FnvHasher::default();
        for step in 1..=steps {
            world
                .step()
                .unwrap_or_else(|e| panic!("{}: step {step}: {e}", scene.name));
            let (poses, linear, angular) = (
                world.poses(),
                world.linear_velocities(),
                world.angular_velocities(),
            );
            for i in 0..world.body_count() {
                let (t, q) = (poses[i].translation, poses[i].rotation);
                let (v, w) = (linear[i], angular[i]);
                for x in [
                    t.x, t.y, t.z, q.x, q.y, q.z, q.w, v.x, v.y, v.z, w.x, w.y, w.z,
                ] {
                    hasher.write(&x.to_le_bytes());
                }
            }
        }
        hasher.finish()
    })
}

/// The stored file's text for `results` (name, steps, hash), one line per scene.
fn render(results: &[(String, u32, u64)]) -> String {
    let mut text = String::from(
        "# Golden trajectories (crates/impulse/tests/integration/golden.rs): scene, steps, 64-bit FNV-1a of\n\
         # every body's position, orientation, linear and angular velocity (f32, little-endian)\n\
         # after every step, the same on 1 and 2 threads. Rewritten only on purpose, by\n",
    );
    text.push_str(&format!(
        "# `{BLESS}`,\n# in a commit whose message gives the reason (docs/testing.md).\n"
    ));
    for (name, steps, hash) in results {
        text.push_str(&format!("{name} {steps} {hash:016x}\n"));
    }
    text
}

/// The stored (steps, hash) by scene name; lines starting with `#` and blank lines skipped.
fn parse(text: &str) -> Result<BTreeMap<String, (u32, u64)>, String> {
    let mut stored = BTreeMap::new();
    for (number, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let fields: Vec<&str> = line.split_whitespace().collect();
        let parsed = match fields.as_slice() {
            [name, steps, hash] => steps
                .parse::<u32>()
                .ok()
                .zip(u64::from_str_radix(hash, 16).ok())
                .map(|entry| (name.to_string(), entry)),
            _ => None,
        };
        let (name, entry) = parsed.ok_or_else(|| {
            format!(
                "line {}: expected `NAME STEPS HASH`, got {line:?}",
                number + 1
            )
        })?;
        stored.insert(name, entry);
    }
    Ok(stored)
}

#[test]
fn the_standard_scenes_follow_their_stored_trajectories() {
    let mut results = Vec::new();
    for case in CASES {
        let scene = scene(case);
        let one = trajectory_hash(&scene, case.steps, 1);
        let two = trajectory_hash(&scene, case.steps, 2);
        assert_eq!(
            one, two,
            "{}: 2 threads differ from 1 ({two:016x} vs {one:016x}); results must not depend on \
             the thread count (tests/determinism.rs), so this is a bug, not a change to bless",
            case.name
        );
        results.push((case.name.to_string(), case.steps, one));
    }

    let path = stored_path();
    if std::env::var("IMPULSE_BLESS").is_ok_and(|v| v == "1") {
        std::fs::write(&path, render(&results))
            .unwrap_or_else(|e| panic!("cannot write {}: {e}", path.display()));
        eprintln!(
            "wrote {}; commit it with the reason for the change",
            path.display()
        );
        return;
    }

    let how_to_update = format!(
        "If the change of behaviour is deliberate, rewrite the stored hashes with\n    \
         {BLESS}\nand commit {} in the same commit as the change, giving the reason in the \
         commit message (docs/testing.md, \"Golden trajectories\").",
        "crates/impulse/tests/data/golden-trajectories.txt"
    );
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}\n{how_to_update}", path.display()));
    let stored =
        parse(&text).unwrap_or_else(|e| panic!("{}: {e}\n{how_to_update}", path.display()));
    let mut problems = Vec::new();
    for (name, steps, hash) in &results {
        match stored.get(name) {
            Some(&(s, h)) if s == *steps && h == *hash => {}
            Some(&(s, h)) => problems.push(format!(
                "{name}: {steps} steps hash to {hash:016x}; stored: {s} steps, {h:016x}"
            )),
            None => problems.push(format!(
                "{name}: not stored (now {steps} steps, {hash:016x})"
            )),
        }
    }
    for name in stored.keys() {
        if !results.iter().any(|(n, _, _)| n == name) {
            problems.push(format!("{name}: stored but no longer in the golden set"));
        }
    }
    assert!(
        problems.is_empty(),
        "the trajectories changed:\n  {}\n{how_to_update}",
        problems.join("\n  ")
    );
}

#[test]
fn the_stored_file_reads_back_as_written() {
    let results = vec![
        ("a".to_string(), 10, 0x0123_4567_89ab_cdef),
        ("b".to_string(), 1, u64::MAX),
    ];
    let stored = parse(&render(&results)).unwrap();
    assert_eq!(stored.len(), 2);
    assert_eq!(stored["a"], (10, 0x0123_4567_89ab_cdef));
    assert_eq!(stored["b"], (1, u64::MAX));
    assert!(parse("a 10").is_err());
    assert!(parse("a ten 00").is_err());
}
