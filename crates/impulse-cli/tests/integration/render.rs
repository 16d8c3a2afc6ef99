//! `impulse render`, `impulse run --stats` and `impulse plot` end to end, on small scenes.

use std::path::{Path, PathBuf};

use image::AnimationDecoder;
use image::codecs::gif::GifDecoder;

use crate::common;
use crate::common::{assert_success, impulse};

/// A fresh directory for one test's files.
fn temp_dir(name: &str) -> PathBuf {
    common::fresh_dir("render", name)
}

/// A scene of a ground half-space and, if `ball`, a ball of radius 0.5 m dropped from 3 m.
fn scene(dir: &Path, ball: bool) -> PathBuf {
    let mut bodies = vec![
        r#"{"name": "ground", "kind": "static", "shape": {"type": "half_space", "normal": [0.0, 1.0, 0.0]}}"#,
    ];
    if ball {
        bodies.push(
            r#"{"name": "ball", "kind": "dynamic", "shape": {"type": "sphere", "radius": 0.5}, "position": [0.0, 3.0, 0.0]}"#,
        );
    }
    let text = format!(
        r#"{{"name": "drop", "gravity": [0.0, -9.81, 0.0], "dt": 0.016666668, "steps": 60, "bodies": [{}]}}"#,
        bodies.join(", ")
    );
    let path = dir.join("scene.json");
    std::fs::write(&path, text).unwrap();
    path
}

fn read_png(path: &Path) -> image::RgbImage {
    image::open(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .to_rgb8()
}

/// The variance of the pixels' brightness (sum of the channels).
fn variance(image: &image::RgbImage) -> f64 {
    let values: Vec<f64> = image
        .pixels()
        .map(|p| p.0.iter().map(|&c| c as f64).sum())
        .collect();
    let mean = values.iter().sum::<f64>() / values.len() as f64;
    values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / values.len() as f64
}

/// Pixels of row `y` darker than the row's median by more than 25 (of 765, the sum of the
/// channels): grid lines on the ground; none on the sky, whose rows are uniform.
fn dark_in_row(image: &image::RgbImage, y: u32) -> usize {
    let brightness: Vec<i32> = (0..image.width())
        .map(|x| image.get_pixel(x, y).0.iter().map(|&c| c as i32).sum())
        .collect();
    let mut sorted = brightness.clone();
    sorted.sort();
    let median = sorted[sorted.len() / 2];
    brightness.iter().filter(|&&b| b < median - 25).count()
}

#[test]
fn a_falling_ball_is_drawn_and_moves_between_frames() {
    let dir = temp_dir("falling");
    let scene = scene(&dir, true);
    let frames = dir.join("frames");
    let out = impulse()
        .args([
            "render",
            scene.to_str().unwrap(),
            "--steps",
            "20",
            "--every",
            "10",
        ])
        .args(["--size", "160x100", "--out", frames.to_str().unwrap()])
        .args(["--camera-eye", "0,2,10", "--camera-target", "0,2,0"])
        .output()
        .unwrap();
    assert_success(&out, "render: ");
    let names: Vec<String> = ["frame_00000.png", "frame_00010.png", "frame_00020.png"]
        .iter()
        .map(|n| n.to_string())
        .collect();
    for name in &names {
        assert!(frames.join(name).exists(), "{name} missing");
    }
    let first = read_png(&frames.join(&names[0]));
    let last = read_png(&frames.join(&names[2]));
    assert_eq!(first.dimensions(), (160, 100));
    assert!(variance(&first) > 100.0, "blank: {}", variance(&first));
    // The ball (at x = 0, in the middle column) fell: pixels changed there, and only there.
    let (mut changed, mut min_x, mut max_x) = (0, u32::MAX, 0);
    for (x, y, p) in first.enumerate_pixels() {
        let q = last.get_pixel(x, y);
        let difference: i32 = (0..3).map(|c| (p.0[c] as i32 - q.0[c] as i32).abs()).sum();
        if difference > 30 {
            changed += 1;
            min_x = min_x.min(x);
            max_x = max_x.max(x);
        }
    }
    assert!(changed > 20, "only {changed} pixels changed");
    assert!(
        min_x > 50 && max_x < 110,
        "changes from x = {min_x} to {max_x}"
    );
}

#[test]
fn the_ground_grid_lies_below_the_horizon() {
    let dir = temp_dir("ground");
    let scene = scene(&dir, false);
    let frames = dir.join("frames");
    // Eye 1 m above the ground looking level: the horizon is the middle row.
    let out = impulse()
        .args(["render", scene.to_str().unwrap(), "--steps", "0"])
        .args(["--size", "320x200", "--out", frames.to_str().unwrap()])
        .args(["--camera-eye", "0,1,0", "--camera-target", "0,1,-10"])
        .output()
        .unwrap();
    assert_success(&out, "render: ");
    let image = read_png(&frames.join("frame_00000.png"));
    let lines_in = |rows: std::ops::Range<u32>| rows.map(|y| dark_in_row(&image, y)).sum::<usize>();
    assert_eq!(lines_in(0..97), 0, "grid-line pixels above the horizon");
    assert!(
        lines_in(140..200) > 300,
        "too few grid-line pixels below it"
    );
}

/// The pixels drawn in the region outline's magenta (255, 0, 255): their count and box
/// (min x, min y, max x, max y).
fn magenta(image: &image::RgbImage) -> (usize, [u32; 4]) {
    let mut box_ = [u32::MAX, u32::MAX, 0, 0];
    let mut count = 0;
    for (x, y, p) in image.enumerate_pixels() {
        if p.0 == [255, 0, 255] {
            count += 1;
            box_ = [
                box_[0].min(x),
                box_[1].min(y),
                box_[2].max(x),
                box_[3].max(y),
            ];
        }
    }
    (count, box_)
}

#[test]
fn a_region_is_outlined_over_the_bodies_and_a_bad_one_is_refused_by_name() {
    let dir = temp_dir("region");
    let scene = scene(&dir, true);
    let draw = |name: &str, regions: &[&str]| {
        let frames = dir.join(name);
        let mut command = impulse();
        command
            .args(["render", scene.to_str().unwrap(), "--steps", "0"])
            .args(["--size", "160x100", "--out", frames.to_str().unwrap()])
            .args(["--camera-eye", "0,3,10", "--camera-target", "0,3,0"]);
        for region in regions {
            command.args(["--region", region]);
        }
        let out = command.output().unwrap();
        assert_success(&out, "render: ");
        read_png(&frames.join("frame_00000.png"))
    };
    assert_eq!(magenta(&draw("plain", &[])).0, 0, "magenta with no region");
    // A 2 m box about the ball (3 m up, in front of it too): its outline surrounds the image's
    // centre, where the ball is, and is drawn over the ball.
    let (count, [x0, y0, x1, y1]) = magenta(&draw("box", &["box:-1,2,-1,1,4,1"]));
    assert!(count > 100, "{count} outline pixels");
    assert!(
        x0 < 70 && x1 > 90 && y0 < 40 && y1 > 60,
        "outline box {x0},{y0} to {x1},{y1}"
    );
    let (count, [x0, _, x1, _]) = magenta(&draw("sphere", &["sphere:0,3,0,0.8"]));
    assert!(
        count > 50 && x0 < 75 && x1 > 85,
        "{count} pixels from x = {x0} to {x1}"
    );
    for bad in ["box:1,0,0,0,1,1", "sphere:0,0,0,0", "cone:0,0,0,1"] {
        let out = impulse()
            .args(["render", scene.to_str().unwrap(), "--steps", "0"])
            .args(["--out", dir.to_str().unwrap(), "--region", bad])
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(2), "{bad}");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(
            stderr.contains("--region") && stderr.contains(bad),
            "{stderr}"
        );
    }
}

#[test]
fn a_thin_ground_is_drawn_where_it_is() {
    // A flat box 0.6 m square (a Blender Plane: no thickness) under one die of two 2 m apart:
    // narrower than the dice's spread, so it is drawn as itself, not taken as the grid.
    let dir = temp_dir("thin_ground");
    let die = |x: f32| {
        format!(
            r#"{{"kind": "dynamic", "position": [{x}, 0.3, 0.0], "shape": {{"type": "cuboid", "half_extents": [0.05, 0.05, 0.05]}}}}"#
        )
    };
    let plane = r#"{"name": "plane", "kind": "static", "shape": {"type": "cuboid", "half_extents": [0.3, 0.0, 0.3]}}"#;
    // Without the plane, a 1 mm static ball as low as the plane's 2 mm slab keeps the grid at
    // the same height, so that only the plane can change the image.
    let speck =
        r#"{"name": "speck", "kind": "static", "shape": {"type": "sphere", "radius": 0.001}}"#;
    let draw = |name: &str, with_plane: bool| {
        let mut bodies = vec![die(0.0), die(2.0)];
        bodies.insert(0, if with_plane { plane } else { speck }.to_string());
        let path = dir.join(format!("{name}.json"));
        std::fs::write(
            &path,
            format!(r#"{{"name": "{name}", "bodies": [{}]}}"#, bodies.join(", ")),
        )
        .unwrap();
        let frames = dir.join(name);
        let out = impulse()
            .args(["render", path.to_str().unwrap(), "--steps", "0"])
            .args(["--size", "160x100", "--out", frames.to_str().unwrap()])
            .args(["--camera-eye", "0,2,2", "--camera-target", "0,0,0"])
            .output()
            .unwrap();
        assert_success(&out, "render: ");
        read_png(&frames.join("frame_00000.png"))
    };
    let (with, without) = (draw("with", true), draw("without", false));
    let changed = with
        .pixels()
        .zip(without.pixels())
        .filter(|(p, q)| {
            (0..3)
                .map(|c| (p.0[c] as i32 - q.0[c] as i32).abs())
                .sum::<i32>()
                > 30
        })
        .count();
    // The plane spans about 30 × 20 pixels from there, less the die on it.
    assert!(changed > 300, "the plane changed only {changed} pixels");
}

#[test]
fn the_gif_has_one_frame_per_drawn_step() {
    let dir = temp_dir("gif");
    let scene = scene(&dir, true);
    let gif = dir.join("drop.gif");
    let out = impulse()
        .args([
            "render",
            scene.to_str().unwrap(),
            "--steps",
            "6",
            "--every",
            "2",
        ])
        .args(["--size", "80x50", "--gif", gif.to_str().unwrap()])
        .output()
        .unwrap();
    assert_success(&out, "render: ");
    let file = std::io::BufReader::new(std::fs::File::open(&gif).unwrap());
    let frames = GifDecoder::new(file)
        .unwrap()
        .into_frames()
        .collect_frames()
        .unwrap();
    // Steps 0, 2, 4 and 6.
    assert_eq!(frames.len(), 4);
    assert_eq!(frames[0].buffer().dimensions(), (80, 50));
}

#[test]
fn render_rejects_bad_sizes_and_unwritable_outputs_by_name() {
    let dir = temp_dir("errors");
    let scene = scene(&dir, true);
    let out = impulse()
        .args(["render", scene.to_str().unwrap(), "--size", "big"])
        .args(["--out", dir.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("'big'"));
    let blocker = dir.join("file");
    std::fs::write(&blocker, "").unwrap();
    let inside = blocker.join("frames");
    let out = impulse()
        .args(["render", scene.to_str().unwrap(), "--steps", "1"])
        .args(["--out", inside.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains(inside.to_str().unwrap()), "{stderr}");
    let out = impulse()
        .args(["render", scene.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(!out.status.success(), "nothing to write must be an error");
    let out = impulse()
        .args([
            "render",
            scene.to_str().unwrap(),
            "--out",
            dir.to_str().unwrap(),
        ])
        .args(["--camera-eye", "1,2,3", "--camera-target", "1,2,3"])
        .output()
        .unwrap();
    assert!(!out.status.success(), "eye at the target must be an error");
    assert!(String::from_utf8_lossy(&out.stderr).contains("same point"));
}

#[test]
fn stats_have_one_finite_row_per_step_and_plot_as_svg_and_png() {
    let dir = temp_dir("stats");
    let scene = scene(&dir, true);
    let stats = dir.join("stats.csv");
    let out = impulse()
        .args(["run", scene.to_str().unwrap(), "--steps", "60", "--quiet"])
        .args(["--stats", stats.to_str().unwrap()])
        .output()
        .unwrap();
    assert_success(&out, "run: ");
    let text = std::fs::read_to_string(&stats).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(
        header[..8],
        [
            "step",
            "time",
            "contacts",
            "rows",
            "iterations",
            "natural_map_residual",
            "kinetic_energy",
            "max_depth"
        ]
    );
    for stage in [
        "broad_phase_ms",
        "narrow_phase_ms",
        "solve_ms",
        "end_step_ms",
        "total_ms",
    ] {
        assert!(header.contains(&stage), "no {stage} in {header:?}");
    }
    for phase in impulse::report::SolvePhase::ALL {
        let column = format!("phase_{}_ms", phase.name());
        assert!(
            header.contains(&column.as_str()),
            "no {column} in {header:?}"
        );
    }
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|c| c.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 60);
    for (k, row) in rows.iter().enumerate() {
        assert_eq!(row.len(), header.len());
        assert_eq!(row[0], (k + 1) as f64);
        assert!(row.iter().all(|v| v.is_finite()), "row {k}: {row:?}");
    }
    // The ball lands after 0.71 s (43 steps): some step has a contact.
    assert!(rows.iter().any(|r| r[2] > 0.0));

    let svg = dir.join("plot.svg");
    let out = impulse()
        .args([
            "plot",
            stats.to_str().unwrap(),
            "--out",
            svg.to_str().unwrap(),
        ])
        .args(["--columns", "contacts,kinetic_energy,solve_ms"])
        .output()
        .unwrap();
    assert_success(&out, "plot: ");
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.starts_with("<svg") && text.contains("polyline"));
    for column in ["contacts", "kinetic_energy", "solve_ms"] {
        assert!(text.contains(column), "{column} not in the plot");
    }
    let out = impulse()
        .args([
            "plot",
            stats.to_str().unwrap(),
            "--out",
            svg.to_str().unwrap(),
        ])
        .args(["--columns", "nope"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("no column 'nope'"));
    let png = dir.join("plot.png");
    let out = impulse()
        .args([
            "plot",
            stats.to_str().unwrap(),
            "--out",
            png.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert_success(&out, "plot --out plot.png: ");
    let image = read_png(&png);
    // Five default columns (contacts, iterations, natural_map_residual, kinetic_energy,
    // max_depth), 900 × 180 pixels each.
    assert_eq!(image.dimensions(), (900, 5 * 180));
    assert!(variance(&image) > 100.0, "the PNG plot is blank");
    let dark = |y0: u32, y1: u32| {
        (y0..y1)
            .flat_map(|y| (0..image.width()).map(move |x| (x, y)))
            .filter(|&(x, y)| {
                image
                    .get_pixel(x, y)
                    .0
                    .iter()
                    .map(|&c| c as u32)
                    .sum::<u32>()
                    < 150
            })
            .count()
    };
    // Text and axes are black: the first panel's caption ("contacts", in its top 30 rows) and
    // its axis, tick labels and x label.
    assert!(
        dark(0, 30) > 50,
        "no caption text: {} dark pixels",
        dark(0, 30)
    );
    assert!(dark(0, 180) > 400, "no axes: {} dark pixels", dark(0, 180));
    let blue = image.pixels().filter(|p| p.0 == [31, 100, 200]).count();
    assert!(blue > 100, "no data line: {blue} blue pixels");

    let jpg = dir.join("plot.jpg");
    let out = impulse()
        .args([
            "plot",
            stats.to_str().unwrap(),
            "--out",
            jpg.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains(".svg or .png"));
    assert!(!jpg.exists());
}

#[test]
fn a_glb_written_by_run_renders_one_frame_per_keyframe() {
    let dir = temp_dir("glb");
    let scene = scene(&dir, true);
    let glb = dir.join("drop.glb");
    let out = impulse()
        .args([
            "run",
            scene.to_str().unwrap(),
            "--steps",
            "20",
            "--every",
            "10",
        ])
        .args(["--quiet", "--out", glb.to_str().unwrap()])
        .output()
        .unwrap();
    assert_success(&out, "run: ");
    let frames = dir.join("frames");
    let out = impulse()
        .args(["render", glb.to_str().unwrap(), "--size", "160x100"])
        .args(["--out", frames.to_str().unwrap()])
        .args(["--camera-eye", "0,2,10", "--camera-target", "0,2,0"])
        .output()
        .unwrap();
    assert_success(&out, "render: ");
    // Keyframes of steps 0, 10 and 20, numbered by keyframe.
    let first = read_png(&frames.join("frame_00000.png"));
    let last = read_png(&frames.join("frame_00002.png"));
    assert!(!frames.join("frame_00003.png").exists());
    assert!(variance(&first) > 100.0);
    assert_ne!(first, last, "the ball did not move");
}

#[test]
fn lcp_convergence_writes_a_png_plot_and_refuses_other_formats() {
    let dir = temp_dir("convergence");
    let data = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../crates/impulse-lcp/tests/data/siconos/lcp_deudeu.dat");
    let png = dir.join("deudeu.png");
    let out = impulse()
        .args(["lcp", "convergence"])
        .arg(&data)
        .args(["--iterations", "50", "--out"])
        .arg(&png)
        .output()
        .unwrap();
    assert_success(&out, "lcp convergence --out deudeu.png: ");
    let image = read_png(&png);
    assert_eq!(image.dimensions(), (820, 600));
    assert!(variance(&image) > 100.0, "the PNG plot is blank");
    // The title, in black, in the top 30 rows.
    let dark = (0..30)
        .flat_map(|y| (0..image.width()).map(move |x| (x, y)))
        .filter(|&(x, y)| {
            image
                .get_pixel(x, y)
                .0
                .iter()
                .map(|&c| c as u32)
                .sum::<u32>()
                < 150
        })
        .count();
    assert!(dark > 50, "no title text: {dark} dark pixels");

    let pdf = dir.join("deudeu.pdf");
    let out = impulse()
        .args(["lcp", "convergence"])
        .arg(&data)
        .arg("--out")
        .arg(&pdf)
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains(".svg or .png"));
    assert!(!pdf.exists());
}
