//! Unit tests of `front.rs`: the front's dominance, bars and tables on hand-made points.

use super::*;
use crate::BenchRow;
use crate::MachineInfo;
use crate::peer_settings::{Box3dSetting, JoltSetting, RapierVariant};

fn point(engine: &str, setting: &str, ms: f64, e_mm: f64) -> FrontPoint {
    FrontPoint {
        engine: engine.into(),
        setting: setting.into(),
        ms_per_step: ms,
        runs_ms: vec![ms],
        e_mm,
        sink_mm: e_mm,
        overlap_mm: 0.0,
        end_overlap_mm: None,
        drift_mm: 0.0,
        joint_gap_mm: None,
        steps: 10,
        details: String::new(),
        failed: None,
    }
}

fn names(points: &[&FrontPoint]) -> Vec<String> {
    points.iter().map(|p| p.setting.clone()).collect()
}

#[test]
fn pareto_front_drops_dominated_points_and_keeps_ties() {
    let mut failed = point(IMPULSE, "failed", 0.01, 0.0);
    failed.failed = Some("blew up".into());
    let points = vec![
        point(IMPULSE, "slow good", 4.0, 0.5),
        point(IMPULSE, "fast bad", 1.0, 40.0),
        point(IMPULSE, "mid", 2.0, 3.0),
        // Slower and worse than "mid".
        point(IMPULSE, "dominated", 3.0, 4.0),
        // As fast as "mid", worse: dominated.
        point(IMPULSE, "same time worse", 2.0, 3.5),
        // As good as "slow good", slower: dominated.
        point(IMPULSE, "same e slower", 5.0, 0.5),
        // The same time and E as "mid": neither dominates the other.
        point(IMPULSE, "mid twin", 2.0, 3.0),
        failed,
        point(IMPULSE, "nan", f64::NAN, 1.0),
        // Another engine's point would dominate everything.
        point(RAPIER, "other engine", 0.1, 0.1),
    ];
    let front = pareto_front(&points, IMPULSE);
    assert_eq!(names(&front), ["fast bad", "mid", "mid twin", "slow good"]);
    assert_eq!(names(&pareto_front(&points, RAPIER)), ["other engine"]);
    assert!(pareto_front(&points, "nobody").is_empty());
}

#[test]
fn cheapest_meeting_each_bar() {
    let mut failed = point(IMPULSE, "failed", 0.1, 0.0);
    failed.failed = Some("blew up".into());
    let points = vec![
        point(IMPULSE, "a", 1.0, 30.0),
        point(IMPULSE, "b", 2.0, 4.0),
        point(IMPULSE, "c", 3.0, 5.0),
        point(IMPULSE, "d", 2.0, 2.0),
        failed,
        point(RAPIER, "r", 0.5, 0.9),
    ];
    let at = |bar| cheapest_meeting(&points, IMPULSE, bar).map(|p| p.setting.as_str());
    assert_eq!(at(50.0), Some("a"));
    // At the same time the smaller E wins.
    assert_eq!(at(5.0), Some("d"));
    // E equal to the bar meets it.
    assert_eq!(at(30.0), Some("a"));
    assert_eq!(at(1.0), None);
    let rapier = cheapest_meeting(&points, RAPIER, 1.0).unwrap();
    assert_eq!(rapier.setting, "r");
}

#[test]
fn error_is_the_largest_of_sink_overlap_and_drift() {
    assert_eq!(error_mm(-7.0, 2.0, 3.0), 7.0);
    assert_eq!(error_mm(1.0, 2.0, 3.0), 3.0);
    assert_eq!(error_mm(0.0, 0.0, 0.0), 0.0);
    assert!(error_mm(f64::NAN, 0.0, 0.0).is_nan());
    assert_eq!(error_mm(f64::INFINITY, 0.0, 0.0), f64::INFINITY);
}

/// A run that blew up is a failed point, and so is one whose result is not finite.
#[test]
fn failed_runs_are_failed_points() {
    let mut row = BenchRow::new(
        "s",
        "impulse",
        2,
        10,
        &mut [1.0; 10],
        crate::QualityReport::default(),
        "settings".into(),
    );
    row.top_sink_m = -0.002;
    let ok = FrontPoint::from_row(IMPULSE, "fast", &row, None);
    assert!(ok.counts());
    assert_eq!((ok.e_mm, ok.sink_mm, ok.ms_per_step), (2.0, -2.0, 1.0));
    let error = Some("step 7: blew up".to_string());
    let blown = FrontPoint::from_row(IMPULSE, "fast", &row, error.clone());
    assert!(!blown.counts());
    assert_eq!(blown.failed, error);
    row.max_drift_m = f64::NAN;
    let nan = FrontPoint::from_row(IMPULSE, "fast", &row, None);
    assert_eq!(nan.failed.as_deref(), Some("non-finite result"));
    let points = [ok, blown, nan];
    assert_eq!(pareto_front(&points, IMPULSE).len(), 1);
    let json = serde_json::to_value(&points[2]).unwrap();
    assert!(json["e_mm"].is_null() && json["failed"].is_string());
}

#[test]
fn tables_mark_bars_no_setting_meets() {
    let front = SceneFront {
        scene: "s".into(),
        bodies: 4,
        steps: 20,
        repeats: 1,
        points: vec![
            point(IMPULSE, "fast", 1.0, 30.0),
            point(IMPULSE, "default", 4.0, 0.5),
            point(RAPIER, "4×30Hz", 2.0, 40.0),
            point(RAPIER, "32×480Hz", 8.0, 3.0),
        ],
    };
    let table = format_bar_table(&front);
    let lines: Vec<&str> = table.lines().collect();
    assert_eq!(lines.len(), 5, "{table}");
    assert!(lines[0].ends_with(
        "| Rapier: cheapest setting | ms/step | E (mm) | cheapest peer | time impulse/cheapest peer |"
    ));
    assert_eq!(
        lines[2],
        "| Q50 (E ≤ 50 mm) | fast | 1.00 | 30.0 | 4×30Hz | 2.00 | 40.0 | rapier | 0.50 |"
    );
    assert_eq!(
        lines[3],
        "| Q5 (E ≤ 5 mm) | default | 4.00 | 0.500 | 32×480Hz | 8.00 | 3.00 | rapier | 0.50 |"
    );
    assert_eq!(
        lines[4],
        "| Q1 (E ≤ 1 mm) | default | 4.00 | 0.500 | — | — | — | — | impulse only |"
    );
    let summary = format_summary_table(std::slice::from_ref(&front));
    assert!(
        summary.contains("| s | 4 | 20 | 0.50 (rapier) | 0.50 (rapier) | impulse only |"),
        "{summary}"
    );

    // Neither engine meets Q1; only Rapier meets Q5.
    let front = SceneFront {
        points: vec![
            point(IMPULSE, "fast", 1.0, 30.0),
            point(RAPIER, "32×480Hz", 8.0, 3.0),
        ],
        ..front
    };
    let table = format_bar_table(&front);
    let lines: Vec<&str> = table.lines().collect();
    assert!(lines[3].starts_with("| Q5 (E ≤ 5 mm) | — | — | — | 32×480Hz |"));
    assert!(
        lines[3].ends_with("| rapier | rapier only |"),
        "{}",
        lines[3]
    );
    assert_eq!(
        lines[4],
        "| Q1 (E ≤ 1 mm) | — | — | — | — | — | — | — | — |"
    );

    // Without a peer measured at all, impulse alone is not "impulse only".
    let front = SceneFront {
        points: vec![point(IMPULSE, "fast", 1.0, 0.5)],
        ..front
    };
    assert!(
        format_bar_table(&front)
            .lines()
            .all(|l| !l.contains("only"))
    );

    let fronts = format_front_table(&SceneFront {
        points: vec![
            point(IMPULSE, "fast", 1.0, 30.0),
            point(IMPULSE, "worse", 2.0, 31.0),
            point(RAPIER, "4×30Hz", 2.0, 40.0),
        ],
        ..front
    });
    assert_eq!(fronts.lines().count(), 4, "{fronts}");
    assert!(fronts.contains("| impulse | fast | 1.00 | 30.0 | 30.0 | 0.000 | 0.000 |"));
    assert!(!fronts.contains("worse"));
}

/// With several peers: a column group per peer measured, impulse's ratio to the cheapest peer
/// meeting the bar, and the peers named when impulse meets none.
#[test]
fn tables_compare_impulse_with_the_cheapest_peer() {
    let front = SceneFront {
        scene: "s".into(),
        bodies: 4,
        steps: 20,
        repeats: 1,
        points: vec![
            point(IMPULSE, "fast", 1.0, 30.0),
            point(RAPIER, "4×30Hz", 4.0, 40.0),
            point(BOX3D, "4×30Hz", 2.0, 20.0),
            point(BOX3D, "32×240Hz", 10.0, 2.0),
            point(JOLT, "c1 v10 p2", 3.0, 45.0),
            point(JOLT, "c4 v40 p8", 20.0, 3.0),
        ],
    };
    let table = format_bar_table(&front);
    let lines: Vec<&str> = table.lines().collect();
    assert!(
        lines[0].contains("| Rapier: cheapest setting |")
            && lines[0].contains("| Box3D: cheapest setting |")
            && lines[0].contains("| Jolt: cheapest setting |"),
        "{}",
        lines[0]
    );
    assert_eq!(
        lines[2],
        "| Q50 (E ≤ 50 mm) | fast | 1.00 | 30.0 | 4×30Hz | 4.00 | 40.0 | 4×30Hz | 2.00 | 20.0 \
         | c1 v10 p2 | 3.00 | 45.0 | box3d | 0.50 |"
    );
    assert!(
        lines[3].ends_with("| box3d | box3d, jolt only |"),
        "{}",
        lines[3]
    );
    let summary = format_summary_table(std::slice::from_ref(&front));
    assert!(
        summary.contains("| s | 4 | 20 | 0.50 (box3d) | box3d, jolt only | — |"),
        "{summary}"
    );
    let fronts = format_front_table(&front);
    for engine in ["| impulse |", "| rapier |", "| box3d |", "| jolt |"] {
        assert!(fronts.contains(engine), "{engine}: {fronts}");
    }
    // A peer measured on no scene gets no columns.
    let no_jolt = SceneFront {
        points: front.points[..4].to_vec(),
        ..front
    };
    assert!(!format_bar_table(&no_jolt).contains("Jolt"));
}

#[test]
fn grids_have_the_documented_sizes_and_names() {
    let grid = impulse_grid();
    assert_eq!(grid.len(), 4 + 14 + 3 + 4 * 2 + 5);
    assert!(
        grid.iter()
            .any(|(name, _)| name == "soft 6, impact sweeps 0, recycle 2 cm")
    );
    assert_eq!(grid[0], ("default".to_string(), None));
    assert_eq!(grid[1].1, Some(SolverSettings::fast()));
    // The presets are soft steps the grid does not repeat.
    let (name, settings) = grid.iter().find(|(name, _)| name == "soft 16").unwrap();
    assert_eq!(
        settings.as_ref(),
        Some(&SolverSettings::soft_step(16)),
        "{name}"
    );
    let settings: Vec<&SolverSettings> = grid.iter().filter_map(|(_, s)| s.as_ref()).collect();
    for preset in ["default", "fast", "precise", "reference"] {
        let preset = SolverSettings::preset(preset).unwrap();
        let copies = settings.iter().filter(|s| ***s == preset).count();
        assert!(copies <= 1, "{preset:?} measured {copies} times");
    }
    let names: std::collections::HashSet<&String> = grid.iter().map(|(n, _)| n).collect();
    assert_eq!(names.len(), grid.len(), "names are unique");
    let (_, split) = grid.iter().find(|(n, _)| n == "reference 2×4").unwrap();
    let split = split.as_ref().unwrap();
    assert!(split.split_impulse() && split.solve.method.is_auto());
    assert_eq!((split.solve.substeps, split.solve.iterations), (2, 4));
    let (_, lean) = grid
        .iter()
        .find(|(n, _)| n == "soft 6, impact sweeps 0")
        .unwrap();
    let lean = lean.as_ref().unwrap();
    assert_eq!(lean.solve.impact_sweeps, 0);
    assert_eq!(
        SolverSettings {
            solve: impulse::settings::SolveSettings {
                impact_sweeps: SolverSettings::default().solve.impact_sweeps,
                ..lean.solve
            },
            ..lean.clone()
        },
        SolverSettings::soft_step(6)
    );
    assert!(impulse_quick_grid().len() < 5);
    let joint_grid = impulse_joint_grid();
    assert_eq!(joint_grid.len(), 4 + 12 * 2 + 3);
    let (_, per_joint) = joint_grid
        .iter()
        .find(|(n, _)| n == "soft 4 per-joint")
        .unwrap();
    assert_eq!(
        per_joint.as_ref(),
        Some(&SolverSettings {
            solve: impulse::settings::SolveSettings {
                direct_joint_solve: false,
                ..SolverSettings::soft_step(4).solve
            },
            ..SolverSettings::soft_step(4)
        })
    );
    let joint_settings: Vec<&SolverSettings> =
        joint_grid.iter().filter_map(|(_, s)| s.as_ref()).collect();
    for (i, setting) in joint_settings.iter().enumerate() {
        assert!(
            !joint_settings[..i].contains(setting),
            "{setting:?} measured twice"
        );
    }
    let names = |names: Vec<String>| -> std::collections::HashSet<String> {
        let count = names.len();
        let set: std::collections::HashSet<String> = names.into_iter().collect();
        assert_eq!(set.len(), count, "names are unique");
        set
    };
    let rapier = names(rapier_grid().iter().map(|v| v.setting_name()).collect());
    assert_eq!(rapier.len(), 40);
    assert!(rapier.contains("4×30Hz") && rapier.contains("32×480Hz coulomb"));
    assert!(rapier_quick_grid().len() < 5);
    assert_eq!(rapier_quick_grid()[0], RapierVariant::default());

    // Box3D: hertz run as asked and within two octaves of the clamp, and the default 30 Hz
    // (clamped) below 4 substeps.
    let box3d = box3d_grid();
    let box3d_names = names(box3d.iter().map(|s| s.setting_name()).collect());
    assert_eq!(box3d.len(), 22, "{box3d_names:?}");
    for name in [
        "1×30Hz",
        "4×30Hz",
        "8×60Hz",
        "16×30Hz",
        "32×240Hz",
        "64×480Hz",
    ] {
        assert!(box3d_names.contains(name), "{name}");
    }
    for name in ["4×60Hz", "24×30Hz", "64×60Hz"] {
        assert!(!box3d_names.contains(name), "{name}");
    }
    for setting in &box3d {
        let run = setting.effective_contact_hz(1.0 / 60.0);
        assert!(
            setting.substeps < 4 || run >= 0.9999 * setting.contact_hz,
            "{setting:?}"
        );
    }
    assert_eq!(box3d_quick_grid()[0], Box3dSetting::default());

    let jolt = names(jolt_grid().iter().map(|s| s.setting_name()).collect());
    assert_eq!(jolt.len(), 20);
    assert!(jolt.contains("c1 v10 p2") && jolt.contains("c16 v40 p2"));
    assert_eq!(jolt_quick_grid()[0], JoltSetting::default());
}

#[test]
fn large_scenes_run_fewer_steps() {
    let config = FrontConfig {
        steps: 600,
        large_steps: 120,
        ..FrontConfig::default()
    };
    let small = scene_by_name("stack3").unwrap();
    let large = scene_by_name("pyramid100").unwrap();
    assert_eq!(config.steps_for(&small), 600);
    assert_eq!(config.steps_for(&large), 120);
    // A pour runs its own steps whatever its size (pour2000 has more than 2000 bodies), or
    // `pour_steps`.
    let pour = scene_by_name("pour2000").unwrap();
    assert!(pour.bodies.len() > LARGE_SCENE_BODIES);
    assert_eq!(config.steps_for(&pour), 300);
    let config = FrontConfig {
        pour_steps: Some(40),
        ..config
    };
    assert_eq!(config.steps_for(&pour), 40);
    assert_eq!(config.steps_for(&large), 120);
}

/// A pour's E is its end overlap or a thirtieth of its overlap during the run, whichever is
/// larger, whatever its sink and drift: it meets a bar of b mm exactly when the end overlap is
/// at most b and the overlap during the run at most 30·b.
#[test]
fn a_pours_error_is_made_of_its_two_overlaps() {
    let row = |scene: &str, end_m: f64, during_m: f64| {
        let mut row = BenchRow::new(
            scene,
            "impulse",
            505,
            300,
            &mut [1.0; 300],
            crate::QualityReport::default(),
            "settings".into(),
        );
        (row.top_sink_m, row.max_drift_m) = (12.0, 30.0);
        (row.end_overlap_m, row.max_overlap_m) = (end_m, during_m);
        row
    };
    // Q1 met: 0.25 mm at the end, 11 mm during the run.
    let good = FrontPoint::from_row(IMPULSE, "default", &row("pour500", 0.00025, 0.011), None);
    assert!(
        (good.end_overlap_mm.unwrap() - 0.25).abs() < 1e-9,
        "{good:?}"
    );
    assert!((good.e_mm - 11.0 / 30.0).abs() < 1e-9, "{good:?}");
    // 13.1 mm at the end and 181 mm during the run: Q50 only.
    let rapier = FrontPoint::from_row(RAPIER, "4×30Hz", &row("pour500", 0.0131, 0.181), None);
    assert!((rapier.e_mm - 13.1).abs() < 1e-9);
    // 0.5 mm at the end but 45 mm during the run: not Q1 (45 > 30), Q5 (45 ≤ 150).
    let transient = FrontPoint::from_row(IMPULSE, "fast", &row("mugs98", 0.0005, 0.045), None);
    assert!((transient.e_mm - 1.5).abs() < 1e-9);
    let points = [good, rapier, transient];
    let at = |engine, bar| cheapest_meeting(&points, engine, bar).map(|p| p.setting.as_str());
    assert_eq!(at(IMPULSE, 1.0), Some("default"));
    assert_eq!(at(IMPULSE, 5.0), Some("default"));
    assert_eq!((at(RAPIER, 5.0), at(RAPIER, 50.0)), (None, Some("4×30Hz")));
    // The same row under another scene's name is measured by sink, overlap and drift.
    let standard =
        FrontPoint::from_row(IMPULSE, "default", &row("pyramid20", 0.00025, 0.011), None);
    assert_eq!((standard.end_overlap_mm, standard.e_mm), (None, 30_000.0));
    assert!(pour_error_mm(f64::NAN, 1.0).is_nan());
    assert_eq!(pour_error_mm(2.0, 30.0), 2.0);
    // The front table shows the two overlaps of a pour.
    let front = SceneFront {
        scene: "pour500".into(),
        bodies: 505,
        steps: 300,
        repeats: 1,
        points: points.to_vec(),
    };
    let table = format_front_table(&front);
    assert!(
        table.contains("| end overlap (mm) | overlap during the run (mm) |"),
        "{table}"
    );
    assert!(
        table.contains("| impulse | default | 1.00 | 0.367 | 0.250 | 11.0 |"),
        "{table}"
    );
}

/// `front --quick` on a small scene, end to end: points of every engine compiled in, a table
/// row per bar, a plot per scene.
#[test]
fn quick_front_on_a_small_stack() {
    let config = FrontConfig {
        scenes: vec!["stack3".into()],
        steps: 20,
        large_steps: 20,
        quick: true,
        ..FrontConfig::default()
    };
    let mut progress = Vec::new();
    let mut again = Vec::new();
    let fronts = run_front(&config, &mut |p| {
        if p.round == 0 {
            progress.push((p.done, p.total, p.point.engine.clone()))
        } else {
            again.push((p.round, p.point.engine.clone(), p.point.setting.clone()))
        }
    })
    .unwrap();
    assert_eq!(fronts.len(), 1);
    let front = &fronts[0];
    assert_eq!((front.scene.as_str(), front.steps), ("stack3", 20));
    let stack3 = scene_by_name("stack3").unwrap();
    let peers = config.peer_settings(&stack3).unwrap();
    let expected =
        config.impulse_settings(&stack3).len() + peers.iter().map(Vec::len).sum::<usize>();
    assert_eq!(front.points.len(), expected);
    assert_eq!(progress.len(), expected);
    assert_eq!(progress.last().unwrap().0, progress.last().unwrap().1);
    // The engines take turns: impulse, then each peer compiled in.
    let compiled: Vec<&str> = PEERS
        .into_iter()
        .filter(|p| crate::peer_settings::peer_compiled(p))
        .collect();
    assert_eq!(front.points[0].engine, IMPULSE);
    for (k, peer) in compiled.iter().enumerate() {
        assert_eq!(front.points[1 + k].engine, *peer);
        assert!(front.measured(peer));
    }
    for p in &front.points {
        assert!(p.counts(), "{p:?}");
        assert_eq!(p.steps, 20);
        assert!(p.ms_per_step > 0.0);
        // A three-cube stack stands within a few centimetres for every setting.
        assert!(p.e_mm < 50.0, "{p:?}");
    }
    assert!(!pareto_front(&front.points, IMPULSE).is_empty());
    // The bars' contenders ran `repeats` times in all, the others once, and a re-timed
    // point's time is the median of its runs. Contenders are chosen from the grid pass's
    // times (each point's first run): the re-timed medians may pick another set.
    let grid_pass: Vec<_> = front
        .points
        .iter()
        .map(|p| {
            let mut first = p.clone();
            first.ms_per_step = p.runs_ms.first().copied().unwrap_or(p.ms_per_step);
            first
        })
        .collect();
    let contenders = crate::front_retime::contenders(&grid_pass, &BARS);
    assert!(!contenders.is_empty());
    assert_eq!(
        again.len(),
        contenders.len() * (DEFAULT_REPEATS as usize - 1)
    );
    for (round, engine, setting) in &again {
        assert!(*round < DEFAULT_REPEATS);
        assert!(
            contenders
                .iter()
                .any(|&k| front.points[k].engine == *engine && front.points[k].setting == *setting),
            "{engine} {setting} re-timed but no contender"
        );
    }
    for (k, p) in front.points.iter().enumerate() {
        let runs = if contenders.contains(&k) {
            DEFAULT_REPEATS as usize
        } else {
            1
        };
        assert_eq!(p.runs_ms.len(), runs, "{p:?}");
        assert_eq!(
            p.ms_per_step,
            crate::quality::median(&mut p.runs_ms.clone())
        );
    }

    let dir = std::env::temp_dir().join(format!("impulse-front-test-{}", std::process::id()));
    let paths = crate::plot::write_plots(&fronts, &dir).unwrap();
    assert_eq!(paths, [dir.join("front-stack3.svg")]);
    let svg = std::fs::read_to_string(&paths[0]).unwrap();
    assert!(svg.starts_with("<svg"), "{}", &svg[..svg.len().min(200)]);
    assert!(svg.contains("stack3") && svg.contains("Q50"));

    let tables = format_tables(&fronts, Plots::Path(&dir));
    assert!(tables.contains(&format!("Plot: `{}`", paths[0].display())));
    let markdown = format_markdown(
        &fronts,
        Plots::Image(Path::new("")),
        "impulse-bench front stack3",
        &MachineInfo::current(),
        &MachineInfo::current(),
    );
    assert!(markdown.contains("![front-stack3](front-stack3.svg)"));
    for bar in [
        "| Q50 (E ≤ 50 mm) |",
        "| Q5 (E ≤ 5 mm) |",
        "| Q1 (E ≤ 1 mm) |",
    ] {
        let rows = tables.lines().filter(|l| l.starts_with(bar)).count();
        assert_eq!(rows, 1, "{bar}: {tables}");
    }
    assert!(tables.contains("#### stack3 (4 bodies, 20 steps,"));
    let machine = MachineInfo::current();
    let json = front_json(&fronts, "impulse-bench front stack3", &machine, &machine);
    assert_eq!(
        json["scenes"][0]["points"].as_array().unwrap().len(),
        expected
    );
    assert_eq!(json["scenes"][0]["steps"], 20);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The contenders at a bar are each engine's settings meeting it within the span of its
/// cheapest there; failed points and settings too slow or too poor are not.
#[test]
fn the_contenders_are_each_engines_settings_near_its_cheapest_at_a_bar() {
    let mut failed = point(IMPULSE, "failed", 0.1, 0.0);
    failed.failed = Some("blew up".into());
    let points = vec![
        point(IMPULSE, "cheapest Q50", 1.0, 40.0),
        point(IMPULSE, "near Q50", 1.4, 30.0),
        point(IMPULSE, "too slow for Q50, cheapest Q5", 2.0, 4.0),
        point(IMPULSE, "too poor", 0.5, 80.0),
        point(RAPIER, "only Q50", 3.0, 20.0),
        point(RAPIER, "slow Q5", 9.0, 5.0),
        failed,
    ];
    let names: Vec<&str> = crate::front_retime::contenders(&points, &BARS)
        .into_iter()
        .map(|k| points[k].setting.as_str())
        .collect();
    assert_eq!(
        names,
        [
            "cheapest Q50",
            "near Q50",
            "too slow for Q50, cheapest Q5",
            "only Q50",
            "slow Q5"
        ]
    );
}

#[test]
fn a_retimed_point_takes_the_median_of_its_runs() {
    use crate::front_retime::add_run;
    let mut p = point(IMPULSE, "soft 4", 5.0, 1.0);
    add_run(&mut p, &point(IMPULSE, "soft 4", 1.0, 1.0));
    add_run(&mut p, &point(IMPULSE, "soft 4", 2.0, 1.0));
    let mut failed = point(IMPULSE, "soft 4", 0.1, 1.0);
    failed.failed = Some("blew up".into());
    add_run(&mut p, &failed);
    assert_eq!(
        (p.runs_ms.as_slice(), p.ms_per_step),
        ([5.0, 1.0, 2.0].as_slice(), 2.0)
    );
}

/// A pour's point is timed by its mean step, what its bake waits for: its landing steps cost
/// several times a settled one, which the median leaves out. Other scenes keep the median.
#[test]
fn a_pours_time_is_its_mean_step() {
    let row = |scene: &str| {
        // 290 settled steps of 1 ms and 10 landing steps of 31 ms: median 1, mean 2.
        let mut times: Vec<f64> = [1.0; 290].into_iter().chain([31.0; 10]).collect();
        BenchRow::new(
            scene,
            "impulse",
            505,
            300,
            &mut times,
            crate::QualityReport::default(),
            "settings".into(),
        )
    };
    let pour = FrontPoint::from_row(IMPULSE, "default", &row("pour500"), None);
    assert_eq!(
        (pour.ms_per_step, pour.runs_ms.as_slice()),
        (2.0, &[2.0][..])
    );
    let standard = FrontPoint::from_row(IMPULSE, "default", &row("pyramid20"), None);
    assert_eq!(standard.ms_per_step, 1.0);
}
