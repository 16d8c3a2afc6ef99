//! Mesh files and decompositions users bring: OBJ errors with the file's line, a byte order
//! mark skipped, an OBJ of lines refused as faceless, paths that are not regular files refused
//! before reading, a damaged decomposition cache rebuilt with a warning, and SIGTERM ending a
//! decomposition under way.

use std::path::{Path, PathBuf};
use std::process::Output;

use crate::common::{assert_success, fresh_dir, impulse};

/// A scene of one dynamic body whose trimesh is `file` (beside the scene), over the ground.
fn mesh_scene(dir: &Path, file: &str, decomposition: &str) -> PathBuf {
    let path = dir.join(format!("{file}.json"));
    let text = format!(
        r#"{{"name": "mesh", "bodies": [
  {{"kind": "static", "shape": {{"type": "half_space", "normal": [0, 1, 0]}}}},
  {{"kind": "dynamic", "position": [0, 2, 0],
    "shape": {{"type": "trimesh", "file": "{file}"{decomposition}}}}}
]}}"#
    );
    std::fs::write(&path, text).unwrap();
    path
}

fn run(scene: &Path, extra: &[&str]) -> Output {
    impulse()
        .args(["run", scene.to_str().unwrap(), "--steps", "1", "--quiet"])
        .args(extra)
        .output()
        .unwrap()
}

fn stderr(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

/// A closed unit cube as OBJ text.
const CUBE_OBJ: &str = "v -0.5 -0.5 -0.5\nv 0.5 -0.5 -0.5\nv -0.5 0.5 -0.5\nv 0.5 0.5 -0.5\n\
v -0.5 -0.5 0.5\nv 0.5 -0.5 0.5\nv -0.5 0.5 0.5\nv 0.5 0.5 0.5\n\
f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n";

#[test]
fn obj_errors_name_the_line_and_a_byte_order_mark_is_skipped() {
    let dir = fresh_dir("mesh-files", "obj");
    std::fs::write(dir.join("bad.obj"), "# a cube\nv 0 0 0\nv 1 0 x\nf 1 2 3\n").unwrap();
    let out = run(&mesh_scene(&dir, "bad.obj", ""), &[]);
    let err = stderr(&out);
    assert!(!out.status.success());
    assert!(
        err.contains("position parse error at line 3 (\"v 1 0 x\")"),
        "{err}"
    );
    std::fs::write(
        dir.join("beyond.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 9\n",
    )
    .unwrap();
    let err = stderr(&run(&mesh_scene(&dir, "beyond.obj", ""), &[]));
    assert!(
        err.contains("out of bounds at line 5 (\"f 1 2 9\")"),
        "{err}"
    );

    std::fs::write(dir.join("bom.obj"), format!("\u{feff}{CUBE_OBJ}")).unwrap();
    let out = run(&mesh_scene(&dir, "bom.obj", ""), &[]);
    assert_success(&out, "a cube with a byte order mark: ");

    std::fs::write(
        dir.join("lines.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2\nl 2 3\n",
    )
    .unwrap();
    let err = stderr(&run(&mesh_scene(&dir, "lines.obj", ""), &[]));
    assert!(err.contains("lines.obj: the file has no faces"), "{err}");
}

#[cfg(unix)]
#[test]
fn paths_that_are_not_regular_files_are_refused_before_reading() {
    let dir = fresh_dir("mesh-files", "special");
    let status = std::process::Command::new("mkfifo")
        .arg(dir.join("fifo.obj"))
        .status()
        .unwrap();
    assert!(status.success());
    std::os::unix::fs::symlink("/dev/zero", dir.join("zero.obj")).unwrap();
    for file in ["fifo.obj", "zero.obj"] {
        let out = run(&mesh_scene(&dir, file, ""), &[]);
        let err = stderr(&out);
        assert!(!out.status.success(), "{file}");
        assert!(err.contains("not a regular file"), "{file}: {err}");
    }
}

/// A decomposition cache file damaged on disk is found out, decomposed again with a warning,
/// and rewritten; the next run takes it without a warning.
#[test]
fn a_damaged_decomposition_cache_file_is_rebuilt_with_a_warning() {
    let dir = fresh_dir("mesh-files", "cache");
    std::fs::write(dir.join("cube.obj"), CUBE_OBJ).unwrap();
    let scene = mesh_scene(&dir, "cube.obj", r#", "decomposition": {"resolution": 16}"#);
    let cache = dir.join("cache");
    let with_cache = ["--decomposition-cache", cache.to_str().unwrap()];
    assert_success(&run(&scene, &with_cache), "first run: ");
    let files: Vec<PathBuf> = std::fs::read_dir(&cache)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    assert_eq!(files.len(), 1, "{files:?}");
    let mut bytes = std::fs::read(&files[0]).unwrap();
    let last = bytes.len() - 1;
    bytes[last] ^= 0x40;
    std::fs::write(&files[0], &bytes).unwrap();
    let out = run(&scene, &with_cache);
    assert_success(&out, "damaged cache: ");
    let err = stderr(&out);
    assert!(
        err.contains("warning: decomposition cache file")
            && err.contains("(damaged); decomposed again"),
        "{err}"
    );
    let out = run(&scene, &with_cache);
    assert_success(&out, "rewritten cache: ");
    assert!(
        !stderr(&out).contains("decomposition cache"),
        "{}",
        stderr(&out)
    );
}

/// A torus (ring radius 1 m, tube 0.3 m) of `n` × `m` quads as OBJ text.
fn torus_obj(n: u32, m: u32) -> String {
    let mut text = String::new();
    for i in 0..n {
        let u = i as f32 / n as f32 * std::f32::consts::TAU;
        for j in 0..m {
            let v = j as f32 / m as f32 * std::f32::consts::TAU;
            let r = 1.0 + 0.3 * v.cos();
            text.push_str(&format!(
                "v {} {} {}\n",
                r * u.cos(),
                0.3 * v.sin(),
                r * u.sin()
            ));
        }
    }
    let id = |i: u32, j: u32| (i % n) * m + (j % m) + 1;
    for i in 0..n {
        for j in 0..m {
            text.push_str(&format!(
                "f {} {} {} {}\n",
                id(i, j),
                id(i, j + 1),
                id(i + 1, j + 1),
                id(i + 1, j)
            ));
        }
    }
    text
}

/// SIGTERM while a scene's mesh is being decomposed ends `impulse` with status 130 before the
/// decomposition finishes (no step is taken); the time from the signal to the exit is printed
/// (docs/testing.md).
#[cfg(unix)]
#[test]
fn sigterm_ends_a_decomposition_under_way() {
    use std::time::{Duration, Instant};
    let dir = fresh_dir("mesh-files", "sigterm");
    std::fs::write(dir.join("torus.obj"), torus_obj(96, 48)).unwrap();
    let scene = mesh_scene(
        &dir,
        "torus.obj",
        r#", "decomposition": {"resolution": 300, "concavity": 0.0001}"#,
    );
    let child = impulse()
        .args(["run", scene.to_str().unwrap(), "--steps", "1", "--quiet"])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(1000));
    let signalled = Instant::now();
    let status = std::process::Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
    let out = child.wait_with_output().unwrap();
    let elapsed = signalled.elapsed();
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(130), "{err}");
    assert!(err.contains("impulse: interrupted"), "{err}");
    assert!(!err.contains("after step"), "{err}");
    eprintln!(
        "SIGTERM to exit during a decomposition: {:.0} ms",
        elapsed.as_secs_f64() * 1e3
    );
}
