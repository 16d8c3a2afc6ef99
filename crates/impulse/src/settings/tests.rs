//! Unit tests of `settings`.

use super::*;

/// The one problem of `settings`, as "field: message".
fn problem(settings: SolverSettings) -> String {
    let problems = settings.problems();
    assert_eq!(problems.len(), 1, "{problems:?}");
    assert_eq!(settings.validate(), Err(problems[0].clone()));
    format!("{}: {}", problems[0].field, problems[0].message)
}

#[test]
fn presets_are_valid() {
    for settings in [
        SolverSettings::default(),
        SolverSettings::fast(),
        SolverSettings::precise(),
        SolverSettings::reference(),
        SolverSettings::soft_step(1),
    ] {
        assert_eq!(settings.problems(), Vec::new());
        assert_eq!(settings.validate(), Ok(()));
    }
}

#[test]
fn each_rule_names_its_field_and_what_is_allowed() {
    let base = SolverSettings::default;
    let cases = [
        (
            SolverSettings {
                solve: SolveSettings {
                    iterations: 0,
                    ..base().solve
                },
                ..base()
            },
            "iterations: must be ≥ 1, got 0",
        ),
        (
            SolverSettings {
                solve: SolveSettings {
                    substeps: 0,
                    ..base().solve
                },
                ..base()
            },
            "substeps: must be ≥ 1, got 0",
        ),
        (
            SolverSettings {
                solve: SolveSettings {
                    method: SolverMethod::Auto {
                        escalation_tolerance: 1e-3,
                        escalation_iterations: 0,
                        mass_ratio_threshold: 10.0,
                    },
                    ..base().solve
                },
                ..base()
            },
            "escalation_iterations: must be ≥ 1, got 0",
        ),
        (
            SolverSettings {
                contact: ContactSettings {
                    repair: ContactRepair::SplitImpulse {
                        rate: 10.0,
                        iterations: 0,
                    },
                    ..base().contact
                },
                ..base()
            },
            "repair.iterations: must be ≥ 1, got 0",
        ),
        (
            SolverSettings {
                contact: ContactSettings {
                    repair: ContactRepair::Soft {
                        hertz: 0.0,
                        damping_ratio: 1.0,
                    },
                    ..base().contact
                },
                ..base()
            },
            "repair.hertz: must be > 0, got 0",
        ),
        (
            SolverSettings {
                contact: ContactSettings {
                    repair: ContactRepair::Soft {
                        hertz: f32::NAN,
                        damping_ratio: 1.0,
                    },
                    ..base().contact
                },
                ..base()
            },
            "repair.hertz: must be finite, got NaN",
        ),
        (
            SolverSettings {
                contact: ContactSettings {
                    repair: ContactRepair::Soft {
                        hertz: 30.0,
                        damping_ratio: -1.0,
                    },
                    ..base().contact
                },
                ..base()
            },
            "repair.damping_ratio: must be ≥ 0, got -1",
        ),
        (
            SolverSettings {
                contact: ContactSettings {
                    repair: ContactRepair::Bias { rate: f32::NAN },
                    ..base().contact
                },
                ..base()
            },
            "repair.rate: must be finite, got NaN",
        ),
        (
            SolverSettings {
                solve: SolveSettings {
                    tolerance: -1.0,
                    ..base().solve
                },
                ..base()
            },
            "tolerance: must be ≥ 0, got -1",
        ),
        (
            SolverSettings {
                sleep: Some(SleepSettings {
                    time_to_sleep: f32::INFINITY,
                    ..SleepSettings::default()
                }),
                ..base()
            },
            "time_to_sleep: must be finite, got inf",
        ),
        (
            SolverSettings {
                contact: ContactSettings {
                    max_repair_speed: -0.5,
                    ..base().contact
                },
                ..base()
            },
            "max_repair_speed: must be ≥ 0, got -0.5",
        ),
        (
            SolverSettings {
                solve: SolveSettings {
                    warm_start: 1.5,
                    ..base().solve
                },
                ..base()
            },
            "warm_start: must be in [0, 1], got 1.5",
        ),
        (
            SolverSettings {
                solve: SolveSettings {
                    warm_start: f32::NAN,
                    ..base().solve
                },
                ..base()
            },
            "warm_start: must be finite, got NaN",
        ),
    ];
    for (settings, expected) in cases {
        assert_eq!(problem(settings), expected);
    }
}

#[test]
fn every_problem_is_listed_in_field_order() {
    let settings = SolverSettings {
        solve: SolveSettings {
            iterations: 0,
            tolerance: -1.0,
            warm_start: 2.0,
            ..SolverSettings::default().solve
        },
        ..SolverSettings::default()
    };
    let fields: Vec<_> = settings.problems().iter().map(|p| p.field).collect();
    assert_eq!(fields, ["iterations", "tolerance", "warm_start"]);
    assert_eq!(settings.validate().unwrap_err().field, "iterations");
}

/// The documented rule of `friction_in_main_solve`: only `pgs` with a relax solve and no
/// split impulse keeps friction out of the repairing solve, and only when asked to.
#[test]
fn friction_leaves_the_main_solve_only_for_pgs_with_a_relax_solve() {
    let base = SolverSettings::default;
    assert_eq!(base().solve.method, SolverMethod::Pgs);
    assert!(!base().main_solve_friction());
    assert!(
        SolverSettings {
            solve: SolveSettings {
                friction_in_main_solve: true,
                ..base().solve
            },
            ..base()
        }
        .main_solve_friction()
    );
    for method in [SolverMethod::Nncg, SolverMethod::Apgd, SolverMethod::AUTO] {
        assert!(
            SolverSettings {
                solve: SolveSettings {
                    method,
                    ..base().solve
                },
                ..base()
            }
            .main_solve_friction()
        );
    }
    assert!(
        SolverSettings {
            contact: ContactSettings {
                repair: ContactRepair::SplitImpulse {
                    rate: 10.0,
                    iterations: 1
                },
                ..base().contact
            },
            ..base()
        }
        .main_solve_friction()
    );
    assert!(
        SolverSettings {
            solve: SolveSettings {
                relax_iterations: 0,
                ..base().solve
            },
            ..base()
        }
        .main_solve_friction()
    );
}

/// The soft step is one PGS sweep and one relax sweep a substep, springs at a fifth of
/// the substep rate (12·S Hz at dt = 1/60 s), no slop, repair capped at 0.5 m/s; the
/// default is that step at 20 substeps, `fast` at 8 and `precise` at 48.
#[test]
fn the_presets_are_the_soft_step() {
    for substeps in [1, 8, 20, 48] {
        let s = SolverSettings::soft_step(substeps);
        assert_eq!(
            (
                s.solve.method,
                s.solve.substeps,
                s.solve.iterations,
                s.solve.relax_iterations
            ),
            (SolverMethod::Pgs, substeps, 1, 1)
        );
        assert_eq!(
            s.contact.repair,
            ContactRepair::Soft {
                hertz: 12.0 * substeps as f32,
                damping_ratio: 10.0
            }
        );
        assert_eq!(
            (s.contact.overlap_slop, s.contact.max_repair_speed),
            (0.0, 0.5)
        );
    }
    assert_eq!(SolverSettings::soft_step(0).solve.substeps, 1);
    assert_eq!(SolverSettings::default(), SolverSettings::soft_step(20));
    let fast = SolverSettings::fast();
    assert_eq!(fast.solve.impact_sweeps, 0);
    assert_eq!(
        fast.contact.recycle_distance,
        crate::settings::FAST_RECYCLE_DISTANCE
    );
    assert_eq!(
        SolverSettings {
            solve: crate::settings::SolveSettings {
                impact_sweeps: SolverSettings::default().solve.impact_sweeps,
                ..fast.solve
            },
            contact: crate::settings::ContactSettings {
                recycle_distance: crate::settings::DEFAULT_RECYCLE_DISTANCE,
                ..fast.contact
            },
            ..fast
        },
        SolverSettings::soft_step(8)
    );
    assert_eq!(SolverSettings::precise(), SolverSettings::soft_step(48));
    for (name, preset) in [
        ("fast", SolverSettings::fast()),
        ("q50", SolverSettings::fast()),
        ("default", SolverSettings::default()),
        ("q5", SolverSettings::default()),
        ("precise", SolverSettings::precise()),
        ("q1", SolverSettings::precise()),
        ("reference", SolverSettings::reference()),
    ] {
        assert_eq!(SolverSettings::preset(name), Some(preset), "{name}");
    }
    assert_eq!(SolverSettings::preset("fastest"), None);
}

/// `reference` as documented: the automatic policy, 4 substeps of at most 8 iterations,
/// split impulse at 12/s above a 2 mm slop, repair capped at 1 m/s.
#[test]
fn the_reference_preset_is_as_documented() {
    let r = SolverSettings::reference();
    assert_eq!(
        (r.solve.method, r.solve.substeps, r.solve.iterations),
        (SolverMethod::AUTO, 4, 8)
    );
    assert_eq!(
        r.contact.repair,
        ContactRepair::SplitImpulse {
            rate: 12.0,
            iterations: 16
        }
    );
    assert!(r.split_impulse() && !SolverSettings::default().split_impulse());
    assert_eq!(
        (r.contact.overlap_slop, r.contact.max_repair_speed),
        (0.002, 1.0)
    );
}

/// A preset applied to a scene's settings changes the solve and keeps the physics.
#[test]
fn a_preset_sets_effort_and_keeps_the_scenes_physics() {
    let scene = SolverSettings {
        contact: ContactSettings {
            restitution_threshold: 2.0,
            prediction_distance: 0.05,
            friction: false,
            ..SolverSettings::default().contact
        },
        gyroscopic: false,
        continuous: false,
        sleep: Some(SleepSettings {
            linear_speed: 0.1,
            angular_speed: 0.2,
            time_to_sleep: 3.0,
        }),
        ..SolverSettings::default()
    };
    for name in SolverSettings::PRESETS {
        let preset = SolverSettings::preset(name).unwrap();
        let s = scene.with_effort_of(&preset);
        // Effort from the preset.
        let effort = SolverSettings {
            contact: ContactSettings {
                restitution_threshold: preset.contact.restitution_threshold,
                prediction_distance: preset.contact.prediction_distance,
                friction: preset.contact.friction,
                ..s.clone().contact
            },
            gyroscopic: preset.gyroscopic,
            continuous: preset.continuous,
            sleep: preset.sleep,
            ..s.clone()
        };
        assert_eq!(effort, preset, "{name}");
        // Physics from the scene.
        assert_eq!(
            s.with_effort_of(&scene),
            scene,
            "{name}: only effort fields changed"
        );
    }
}

#[test]
fn counts_have_a_maximum() {
    let s = SolverSettings {
        solve: SolveSettings {
            substeps: u32::MAX,
            ..SolverSettings::default().solve
        },
        ..SolverSettings::default()
    };
    assert_eq!(problem(s), "substeps: must be ≤ 10000, got 4294967295");
    let s = SolverSettings {
        solve: SolveSettings {
            iterations: SolverSettings::MAX_COUNT,
            ..SolverSettings::default().solve
        },
        ..SolverSettings::default()
    };
    assert_eq!(s.validate(), Ok(()));
}

/// The names the CLI and reports print are the scene format's.
#[test]
fn names_are_the_scene_format_names() {
    for method in SolverMethod::ALL {
        let settings = SolverSettings {
            solve: SolveSettings {
                method,
                ..SolverSettings::default().solve
            },
            ..SolverSettings::default()
        };
        let json = serde_json::to_value(&settings).unwrap();
        assert_eq!(json["method"], method.name());
        assert_eq!(method.name().parse(), Ok(method));
    }
    assert!(
        "lemke"
            .parse::<SolverMethod>()
            .unwrap_err()
            .contains("apgd")
    );
    for repair in [
        ContactRepair::Bias { rate: 1.0 },
        ContactRepair::SplitImpulse {
            rate: 1.0,
            iterations: 1,
        },
        ContactRepair::Soft {
            hertz: 1.0,
            damping_ratio: 1.0,
        },
    ] {
        let json = serde_json::to_value(repair).unwrap();
        assert_eq!(json["type"], repair.name());
    }
}

/// `auto`'s parameters sit beside `method` in the `solver` object: read into
/// [`SolverMethod::Auto`] and written back from it; under another method they are kept in
/// [`SolverSettings::off`] (the step ignores them) and written back as read.
#[test]
fn autos_parameters_read_and_write_beside_the_method() {
    let json = r#"{"method": "auto", "escalation_tolerance": 0.002, "escalation_iterations": 7,
        "mass_ratio_threshold": 3.5, "exact_max_contacts": 12}"#;
    let settings: SolverSettings = serde_json::from_str(json).unwrap();
    assert_eq!(
        settings.solve.method,
        SolverMethod::Auto {
            escalation_tolerance: 0.002,
            escalation_iterations: 7,
            mass_ratio_threshold: 3.5,
        }
    );
    assert_eq!(settings.solve.exact_max_contacts, 12);
    let written = serde_json::to_value(&settings).unwrap();
    assert_eq!(written["escalation_iterations"], 7);
    assert_eq!(
        serde_json::from_value::<SolverSettings>(written).unwrap(),
        settings
    );
    let pgs: SolverSettings =
        serde_json::from_str(r#"{"method": "pgs", "escalation_iterations": 7}"#).unwrap();
    assert_eq!(pgs.solve.method, SolverMethod::Pgs);
    assert_eq!(pgs.off.auto.1, 7);
    assert_eq!(
        serde_json::to_value(&pgs).unwrap()["escalation_iterations"],
        7
    );
    let pgs_default: SolverSettings = serde_json::from_str(r#"{"method": "pgs"}"#).unwrap();
    assert_eq!(pgs_default, SolverSettings::default());
    let default = serde_json::to_value(SolverSettings::default()).unwrap();
    assert_eq!(default["escalation_iterations"], 4);
    assert!(serde_json::from_str::<SolverSettings>(r#"{"substep": 3}"#).is_err());
}

/// The `solver` object stays flat while the Rust type is grouped: each group's keys read into
/// their group, the file keeps the 34 keys it has always had, `"sleep":
/// false` is `sleep: None`, and every preset reads back as it was written.
#[test]
fn flat_keys_read_into_their_groups_and_write_back_flat() {
    let json = r#"{"substeps": 7, "warm_start": 0.5, "prediction_distance": 0.01,
        "impact": "propagation", "sleep_linear_speed": 0.2, "time_to_sleep": 2,
        "max_distance": 50, "max_angular_speed": 1000, "gyroscopic": false}"#;
    let s: SolverSettings = serde_json::from_str(json).unwrap();
    let default = SolverSettings::default();
    assert_eq!((s.solve.substeps, s.solve.warm_start), (7, 0.5));
    assert_eq!(s.contact.prediction_distance, 0.01);
    assert_eq!(s.contact.impact, ImpactModel::Propagation);
    assert_eq!(
        s.sleep,
        Some(SleepSettings {
            linear_speed: 0.2,
            angular_speed: SleepSettings::default().angular_speed,
            time_to_sleep: 2.0,
        })
    );
    assert_eq!(
        (s.limits.max_distance, s.limits.max_angular_speed),
        (50.0, 1000.0)
    );
    assert_eq!(s.limits.max_linear_speed, default.limits.max_linear_speed);
    assert!(!s.gyroscopic && s.continuous);
    let asleep_off: SolverSettings =
        serde_json::from_str(r#"{"sleep": false, "time_to_sleep": 2}"#).unwrap();
    assert_eq!(asleep_off.sleep, None);
    let written = serde_json::to_value(&asleep_off).unwrap();
    assert_eq!(
        (&written["sleep"], &written["time_to_sleep"]),
        (&false.into(), &2.0.into())
    );
    let keys: Vec<String> = match serde_json::to_value(&default).unwrap() {
        serde_json::Value::Object(map) => map.keys().cloned().collect(),
        other => panic!("not an object: {other}"),
    };
    let expected = "method substeps iterations relax_iterations impact_sweeps tolerance escalation_tolerance \
        escalation_iterations mass_ratio_threshold exact_max_contacts heavy_on_light_mass_ratio \
        restitution_threshold repair overlap_slop max_repair_speed warm_start prediction_distance split_overlap collision_steps recycle_distance \
        sleep sleep_linear_speed sleep_angular_speed time_to_sleep friction friction_in_main_solve \
        direct_joint_solve parallel_island_contacts simd_island_contacts fused_multiply_add \
        gyroscopic continuous impact friction_combine restitution_combine max_distance \
        max_linear_speed max_angular_speed";
    let mut sorted_expected: Vec<&str> = expected.split_whitespace().collect();
    let mut sorted_keys: Vec<&str> = keys.iter().map(String::as_str).collect();
    sorted_expected.sort_unstable();
    sorted_keys.sort_unstable();
    assert_eq!(sorted_keys, sorted_expected);
    for name in SolverSettings::PRESETS {
        let preset = SolverSettings::preset(name).unwrap();
        let text = serde_json::to_string(&preset).unwrap();
        assert_eq!(
            serde_json::from_str::<SolverSettings>(&text).unwrap(),
            preset,
            "{name}"
        );
    }
}

/// Every key of the `solver` object survives read → write under every method and with sleep
/// on and off: each key set to a valid value other than its default reads and writes back to
/// the same value, and the settings read back equal.
#[test]
fn every_key_round_trips_whatever_the_method() {
    use serde_json::Value;
    let default = match serde_json::to_value(SolverSettings::default()).unwrap() {
        Value::Object(map) => map,
        other => panic!("not an object: {other}"),
    };
    for method in SolverMethod::ALL {
        for sleep in [true, false] {
            let mut file = serde_json::Map::new();
            for (key, value) in &default {
                let changed: Value = match (key.as_str(), value) {
                    ("method", _) => method.name().into(),
                    ("sleep", _) => sleep.into(),
                    ("repair", _) => serde_json::json!({"type": "bias", "rate": 3.5}),
                    ("impact", _) => "propagation".into(),
                    ("friction_combine" | "restitution_combine", _) => "min".into(),
                    ("warm_start", _) => 0.25.into(),
                    (_, Value::Bool(b)) => (!b).into(),
                    (_, Value::Number(n)) if n.is_u64() => (n.as_u64().unwrap() + 3).into(),
                    (_, Value::Number(n)) => (n.as_f64().unwrap() as f32 * 1.5 + 0.25).into(),
                    (key, other) => panic!("{key}: no changed value for {other}"),
                };
                if !matches!(key.as_str(), "method" | "sleep") {
                    assert_ne!(&changed, value, "{key} is not changed");
                }
                file.insert(key.clone(), changed);
            }
            let read: SolverSettings = serde_json::from_value(Value::Object(file.clone()))
                .unwrap_or_else(|e| panic!("{} sleep {sleep}: {e}", method.name()));
            assert_eq!(read.validate(), Ok(()));
            let written = match serde_json::to_value(&read).unwrap() {
                Value::Object(map) => map,
                other => panic!("not an object: {other}"),
            };
            for (key, value) in &file {
                assert_eq!(
                    written.get(key),
                    Some(value),
                    "{key} under {} with sleep {sleep}",
                    method.name()
                );
            }
            assert_eq!(written.len(), file.len());
            let again: SolverSettings = serde_json::from_value(Value::Object(written)).unwrap();
            assert_eq!(again, read);
        }
    }
}
