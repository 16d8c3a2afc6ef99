//! The grids of settings `impulse-bench front` runs each engine over: impulse's presets and
//! soft steps, Rapier's substeps × springs × friction, Box3D's substeps × contact hertz,
//! Jolt's collision steps × velocity iterations; the peers' grids for a scene with joints,
//! where contact springs do not matter and joint solving does; and the small grids of
//! `--quick`.

use impulse::SolverSettings;

use crate::peer_settings::{Box3dSetting, JoltSetting, RapierVariant};

/// A named impulse setting: None is the scene's own solver settings (`scene.solver`).
pub type ImpulseSetting = (String, Option<SolverSettings>);

/// impulse's settings measured by `front`: every preset (`default`, the scene's own settings,
/// which for the built-in scenes is `SolverSettings::default()`; `fast`, `precise`,
/// `reference`), the soft step at other substep counts, and the reference method at fewer
/// substeps and iterations.
///
/// - `soft S`: `SolverSettings::soft_step(S)`, S substeps of one PGS sweep and one relax sweep
///   on contacts of a fifth of the substep rate (12·S Hz at dt = 1/60 s).
/// - `soft S×I`: the same with I PGS sweeps in the main solve.
/// - `soft S, impact sweeps 0`: `soft S` without the sweeps an impact may add
///   (`SolveSettings::impact_sweeps` 0, as the preset `fast` at 8 substeps): cheaper wherever
///   bodies land, as in a pour, and a face landing at restitution 0 rises again at 7-9 % of
///   its impact speed.
/// - `soft S, impact sweeps 0, recycle 2 cm`: that, with contacts kept while a pair moves less
///   than 2 cm (`ContactSettings::recycle_distance`, as the preset `fast`): cheaper where
///   bodies move, as in a pour.
/// - `reference S×I`: `SolverSettings::reference()` (auto NNCG, split impulse, the exact
///   path) with S substeps of at most I iterations.
pub fn impulse_grid() -> Vec<ImpulseSetting> {
    let mut grid = vec![("default".to_string(), None)];
    for name in ["fast", "precise", "reference"] {
        grid.push((name.to_string(), SolverSettings::preset(name)));
    }
    for substeps in [1, 2, 3, 4, 5, 6, 10, 12, 16, 24, 28, 32, 40, 64] {
        grid.push(soft_step(substeps, 1));
    }
    for substeps in [4, 8, 16] {
        grid.push(soft_step(substeps, 2));
    }
    // At 8 substeps: the preset `fast`.
    for substeps in [3, 4, 6, 12] {
        grid.push(without_impact_sweeps(soft_step(substeps, 1)));
        grid.push(recycling_fast(without_impact_sweeps(soft_step(
            substeps, 1,
        ))));
    }
    for (substeps, iterations) in [(1, 4), (1, 8), (2, 4), (2, 8), (4, 4)] {
        grid.push(reference(substeps, iterations));
    }
    grid
}

/// impulse's settings for a scene with joints: the presets, and the soft step at substeps
/// {1, 2, 3, 4, 5, 6, 8 (with impact sweeps, unlike the preset `fast`), 10, 12, 16, 24, 32}
/// with the island's locked
/// joint rows solved together (`soft S`, `SolveSettings::direct_joint_solve`, the default)
/// and one joint after another (`soft S per-joint`), which costs less per sweep and holds
/// chains of similar masses nearly as well; and `soft S×2` at 4, 8 and 16 substeps. The substeps are what stiffens the
/// joints (each substep solves them with the positions it starts from), as the peers' joint
/// grids vary theirs.
pub fn impulse_joint_grid() -> Vec<ImpulseSetting> {
    let mut grid = vec![("default".to_string(), None)];
    for name in ["fast", "precise", "reference"] {
        grid.push((name.to_string(), SolverSettings::preset(name)));
    }
    for substeps in [1, 2, 3, 4, 5, 6, 8, 10, 12, 16, 24, 32] {
        let (name, settings) = soft_step(substeps, 1);
        grid.push((
            format!("{name} per-joint"),
            settings.clone().map(|settings| SolverSettings {
                solve: impulse::settings::SolveSettings {
                    direct_joint_solve: false,
                    ..settings.solve
                },
                ..settings
            }),
        ));
        grid.push((name, settings));
    }
    for substeps in [4, 8, 16] {
        grid.push(soft_step(substeps, 2));
    }
    grid
}

/// The small grid of `--quick` (for tests and checks): `default`, `fast` and two more.
pub fn impulse_quick_grid() -> Vec<ImpulseSetting> {
    vec![
        ("default".to_string(), None),
        ("fast".to_string(), Some(SolverSettings::fast())),
        soft_step(4, 1),
        reference(2, 4),
    ]
}

/// The soft step at `substeps` substeps with `iterations` sweeps in the main solve.
fn soft_step(substeps: u32, iterations: u32) -> ImpulseSetting {
    let name = if iterations == 1 {
        format!("soft {substeps}")
    } else {
        format!("soft {substeps}×{iterations}")
    };
    (
        name,
        Some(SolverSettings {
            solve: impulse::settings::SolveSettings {
                iterations,
                ..SolverSettings::soft_step(substeps).solve
            },
            ..SolverSettings::soft_step(substeps)
        }),
    )
}

/// `setting` with no impact sweeps (`SolveSettings::impact_sweeps` 0), named so.
fn without_impact_sweeps((name, settings): ImpulseSetting) -> ImpulseSetting {
    (
        format!("{name}, impact sweeps 0"),
        settings.map(|settings| SolverSettings {
            solve: impulse::settings::SolveSettings {
                impact_sweeps: 0,
                ..settings.solve
            },
            ..settings
        }),
    )
}

/// `setting` with contacts recycled within the preset `fast`'s distance
/// (`impulse::settings::FAST_RECYCLE_DISTANCE`, 2 cm), named so.
fn recycling_fast((name, settings): ImpulseSetting) -> ImpulseSetting {
    (
        format!(
            "{name}, recycle {} cm",
            impulse::settings::FAST_RECYCLE_DISTANCE * 100.0
        ),
        settings.map(|settings| SolverSettings {
            contact: impulse::settings::ContactSettings {
                recycle_distance: impulse::settings::FAST_RECYCLE_DISTANCE,
                ..settings.contact
            },
            ..settings
        }),
    )
}

/// `SolverSettings::reference()` with other substeps and iterations.
fn reference(substeps: u32, iterations: u32) -> ImpulseSetting {
    (
        format!("reference {substeps}×{iterations}"),
        Some(SolverSettings {
            solve: impulse::settings::SolveSettings {
                substeps,
                iterations,
                ..SolverSettings::reference().solve
            },
            ..SolverSettings::reference()
        }),
    )
}

/// Rapier's settings measured by `front`: substeps {4, 8, 16, 32} × contact spring
/// {30, 60, 120, 240, 480} Hz × friction {simplified (Rapier's default), Coulomb}. Rapier's
/// defaults are `4×30Hz`.
pub fn rapier_grid() -> Vec<RapierVariant> {
    let mut grid = Vec::new();
    for substeps in [4, 8, 16, 32] {
        for contact_hz in [30.0, 60.0, 120.0, 240.0, 480.0] {
            for coulomb_friction in [false, true] {
                grid.push(RapierVariant {
                    substeps,
                    contact_hz,
                    coulomb_friction,
                });
            }
        }
    }
    grid
}

/// The small grid of `--quick`: Rapier's defaults and two more.
pub fn rapier_quick_grid() -> Vec<RapierVariant> {
    vec![
        RapierVariant {
            substeps: 4,
            contact_hz: 30.0,
            coulomb_friction: false,
        },
        RapierVariant {
            substeps: 8,
            contact_hz: 120.0,
            coulomb_friction: false,
        },
        RapierVariant {
            substeps: 8,
            contact_hz: 120.0,
            coulomb_friction: true,
        },
    ]
}

/// Box3D's settings measured by `front`: substeps S {1, 2, 3, 4, 6, 8, 12, 16, 24, 32, 48, 64}
/// × contact hertz {30, 60, 120, 240, 480}, keeping at each S the hertz Box3D runs as asked
/// at dt = 1/60 s and that are at least a quarter of its clamp (from 7.5·S / 4 to 7.5·S Hz,
/// [`Box3dSetting::effective_contact_hz`]: Box3D's stiffest contacts at S and two octaves
/// softer), and Box3D's default 30 Hz at 1, 2 and 3 substeps, where Box3D clamps it to 7.5·S
/// Hz: 22 settings. Box3D's defaults are `4×30Hz`.
pub fn box3d_grid() -> Vec<Box3dSetting> {
    let dt = 1.0 / 60.0;
    let mut grid = Vec::new();
    for substeps in [1, 2, 3, 4, 6, 8, 12, 16, 24, 32, 48, 64] {
        let clamp = Box3dSetting {
            substeps,
            contact_hz: f32::INFINITY,
        }
        .effective_contact_hz(dt);
        for contact_hz in [30.0, 60.0, 120.0, 240.0, 480.0] {
            // Run as asked, up to rounding of the f32 substep rate.
            let as_asked = contact_hz <= 1.0001 * clamp && contact_hz >= 0.2499 * clamp;
            let clamped_default = contact_hz == 30.0 && substeps < 4;
            if as_asked || clamped_default {
                grid.push(Box3dSetting {
                    substeps,
                    contact_hz,
                });
            }
        }
    }
    grid
}

/// The small grid of `--quick`: Box3D's defaults and two more.
pub fn box3d_quick_grid() -> Vec<Box3dSetting> {
    vec![
        Box3dSetting::default(),
        Box3dSetting {
            substeps: 8,
            contact_hz: 60.0,
        },
        Box3dSetting {
            substeps: 16,
            contact_hz: 120.0,
        },
    ]
}

/// Jolt's settings measured by `front`: collision steps {1, 2, 4, 8, 16} × velocity
/// iterations {4, 10, 20, 40}, at Jolt's default 2 position iterations: 20 settings. Position
/// iterations correct only the penetration beyond Jolt's 2 cm slop, which a resting pile does
/// not reach, so they leave E as it is (docs/benchmarks.md, "How the peers are set up").
/// Jolt's defaults are `c1 v10 p2`.
pub fn jolt_grid() -> Vec<JoltSetting> {
    let mut grid = Vec::new();
    for collision_steps in [1, 2, 4, 8, 16] {
        for velocity_steps in [4, 10, 20, 40] {
            grid.push(JoltSetting {
                collision_steps,
                velocity_steps,
                ..JoltSetting::default()
            });
        }
    }
    grid
}

/// The small grid of `--quick`: Jolt's defaults and two more.
pub fn jolt_quick_grid() -> Vec<JoltSetting> {
    vec![
        JoltSetting::default(),
        JoltSetting {
            collision_steps: 2,
            velocity_steps: 20,
            position_steps: 2,
        },
        JoltSetting {
            collision_steps: 4,
            velocity_steps: 20,
            position_steps: 2,
        },
    ]
}

/// Rapier's settings for a scene with joints: substeps {1, 2, 4, 8, 16, 32, 64} at Rapier's
/// default springs and friction. Rapier's impulse joints are solved once per substep with the
/// joint spring of `IntegrationParameters` (its defaults), so the substeps are the setting that
/// makes them stiffer; contact springs and friction act on contacts only.
pub fn rapier_joint_grid() -> Vec<RapierVariant> {
    [1, 2, 4, 8, 16, 32, 64]
        .into_iter()
        .map(|substeps| RapierVariant {
            substeps,
            ..RapierVariant::default()
        })
        .collect()
}

/// Box3D's settings for a scene with joints: substeps {1, 2, 3, 4, 6, 8, 12, 16, 24, 32, 48,
/// 64} at Box3D's default 30 Hz contacts (Box3D's joints are solved in every substep with
/// their own `jointHertz` and `jointDampingRatio`, left at Box3D's defaults).
pub fn box3d_joint_grid() -> Vec<Box3dSetting> {
    [1, 2, 3, 4, 6, 8, 12, 16, 24, 32, 48, 64]
        .into_iter()
        .map(|substeps| Box3dSetting {
            substeps,
            ..Box3dSetting::default()
        })
        .collect()
}

/// Jolt's settings for a scene with joints: collision steps {1, 2, 4, 8} × velocity iterations
/// {10, 20, 40} × position iterations {2, 10}: Jolt's position iterations solve the joints'
/// position error (its Baumgarte-free position pass), so they matter here as they do not on
/// resting piles.
pub fn jolt_joint_grid() -> Vec<JoltSetting> {
    let mut grid = Vec::new();
    for collision_steps in [1, 2, 4, 8] {
        for velocity_steps in [10, 20, 40] {
            for position_steps in [2, 10] {
                grid.push(JoltSetting {
                    collision_steps,
                    velocity_steps,
                    position_steps,
                });
            }
        }
    }
    grid
}
