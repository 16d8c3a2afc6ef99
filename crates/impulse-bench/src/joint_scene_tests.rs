//! Every engine on `chain20heavy` (a chain of 20 links with a ball of 100 links' mass at its
//! end, released horizontally): at its finest setting of the front's grid the chain holds
//! together, and the ball swings at the chain's length from the pivot.

use glam::Vec3;

use crate::peer::EngineRun;
use crate::peer_settings::PeerSetting;
use crate::{BenchRow, scene_by_name};

/// Steps of each run: 2 s at dt = 1/60 s, through the bottom of the first swing, where the
/// chain pulls hardest.
const STEPS: u32 = 120;

/// The pivot: the post's face the first link hangs from (m).
const PIVOT: Vec3 = Vec3::new(0.1, 6.0, 0.0);

/// The rest distance from the pivot to the ball's centre (m): 20 links of 0.25 m and the
/// ball's radius.
const REACH: f32 = 20.0 * 0.25 + 0.2;

/// Runs `run` for [`STEPS`] and checks the joint gap and the ball's distance from the pivot:
/// the gap below `gap_bound` (m; the bound 0.1 m, 2 % of the links' 5 m, is a sanity bound, the
/// front measures the gap), the ball no farther than the rest distance plus the gap, and the
/// chain nearly straight (the heavy end pulls it taut).
fn check(name: &str, mut run: Box<dyn EngineRun>, gap_bound: f64) -> BenchRow {
    run.advance(STEPS).unwrap();
    let poses = run.poses();
    let row = run.finish();
    let gap = row
        .max_joint_gap_m
        .expect("a scene with joints has a joint gap");
    assert!(gap < gap_bound, "{name}: joint gap {gap} m");
    let ball = poses.last().unwrap().translation;
    let reach = (ball - PIVOT).length();
    assert!(
        reach <= REACH + gap as f32 + 1e-3 && reach > 0.97 * REACH,
        "{name}: ball at {reach} m from the pivot, rest distance {REACH} m"
    );
    // Through the bottom of the swing, on the other side of the pivot, and below it.
    assert!(
        ball.x < PIVOT.x && ball.y < PIVOT.y,
        "{name}: ball at {ball}"
    );
    println!(
        "{name}: joint gap {:.2} mm, ball at {reach:.4} m",
        gap * 1e3
    );
    row
}

#[test]
fn impulse_holds_the_heavy_chain_at_its_default_setting() {
    let scene = scene_by_name("chain20heavy").unwrap();
    let run = crate::impulse_engine::ImpulseRun::new(&scene, STEPS, 1, None).unwrap();
    check("impulse default", Box::new(run), 0.1);
}

/// Each peer compiled in, at the last (finest) setting of its joint grid.
#[test]
fn every_peer_holds_the_heavy_chain_at_its_finest_setting() {
    let scene = scene_by_name("chain20heavy").unwrap();
    let config = crate::front::FrontConfig {
        scenes: vec![scene.name.clone()],
        ..Default::default()
    };
    for grid in config.peer_settings(&scene).unwrap() {
        let setting: PeerSetting = *grid.last().unwrap();
        let name = format!("{} {}", setting.engine(), setting.setting_name());
        let run = crate::engines::start_peer(&scene, STEPS, &setting, &name).unwrap();
        // Box3D solves its joints as springs of `constraintHertz` (its default 60 Hz, damping
        // ratio 2, which the front keeps): the heavy ball stretches them by tens of
        // centimetres whatever the substeps.
        let bound = if setting.engine() == crate::peer_settings::BOX3D {
            1.5
        } else {
            0.1
        };
        check(&name, run, bound);
    }
}

/// A bar of 0.9 m (0.1 × 0.1 m section, 9 kg) held at one end, at the origin, by `joint` (the
/// JSON of a joint between the static block `0` there and the bar `1`), the bar's centre at
/// `centre` (m, on the x or z axis).
fn bar_scene(joint: &str, centre: [f32; 3]) -> impulse::Scene {
    let bar_half = if centre[0] != 0.0 {
        [0.45, 0.05, 0.05]
    } else {
        [0.05, 0.05, 0.45]
    };
    let text = format!(
        r#"{{
  "name": "bar",
  "gravity": [0.0, -9.81, 0.0],
  "dt": 0.016666668,
  "bodies": [
    {{"kind": "static", "shape": {{"type": "cuboid", "half_extents": [0.05, 0.05, 0.05]}}, "position": [0.0, 0.0, 0.0]}},
    {{"kind": "dynamic", "shape": {{"type": "cuboid", "half_extents": {bar_half:?}}}, "position": {centre:?}}}
  ],
  "joints": [{joint}]
}}"#
    );
    impulse::scene::parse_scene_str(&text, "bar.json").unwrap()
}

/// A run of `scene` by impulse at its defaults and by each peer compiled in at its defaults,
/// each with its engine's name.
fn every_engine(scene: &impulse::Scene) -> Vec<(String, Box<dyn EngineRun>)> {
    let mut runs: Vec<(String, Box<dyn EngineRun>)> = vec![(
        "impulse default".to_string(),
        Box::new(crate::impulse_engine::ImpulseRun::new(scene, STEPS, 1, None).unwrap()),
    )];
    let defaults = [
        PeerSetting::Rapier(Default::default()),
        PeerSetting::Box3d(Default::default()),
        PeerSetting::Jolt(Default::default()),
    ];
    for setting in defaults
        .into_iter()
        .filter(|setting| crate::peer_settings::peer_compiled(setting.engine()))
    {
        let name = setting.engine().to_string();
        let run = crate::engines::start_peer(scene, STEPS, &setting, &name).unwrap();
        runs.push((name, run));
    }
    runs
}

/// Each engine (impulse at its defaults, each peer compiled in at its default) holds a hinge
/// at the limit gravity drives it to, with the angle's sign and axis as impulse defines them
/// (B's rotation relative to A about the axis, counter-clockwise positive): a bar out along
/// +z on a hinge about x falls to the upper limit 0.3 rad (not to the lower −1.0), and a bar
/// out along +x on a hinge about z falls to the lower limit −0.3 rad (not to the upper 1.0).
#[test]
fn every_engine_stops_a_hinge_at_the_limit_of_impulses_sign() {
    let cases = [
        ([1.0, 0.0, 0.0], [0.0, 0.0, 0.5], [-1.0, 0.3], 0.3f32),
        ([0.0, 0.0, 1.0], [0.5, 0.0, 0.0], [-0.3, 1.0], -0.3),
    ];
    for (axis, centre, limits, expected) in cases {
        let joint = format!(
            r#"{{"type": "revolute", "body_a": 0, "body_b": 1, "anchor": [0.0, 0.0, 0.0], "axis": {axis:?}, "limits": {limits:?}}}"#
        );
        let scene = bar_scene(&joint, centre);
        let axis = Vec3::from(axis);
        for (name, mut run) in every_engine(&scene) {
            run.advance(STEPS).unwrap();
            let rotation = run.poses()[1].rotation;
            // The bar turned about the hinge axis only: its rotation's angle about the axis.
            let along = Vec3::new(rotation.x, rotation.y, rotation.z).dot(axis);
            let angle = 2.0 * along.atan2(rotation.w);
            println!("{name}: hinge about {axis} at {angle:.4} rad (limit {expected})");
            assert!(
                (angle - expected).abs() < 0.05,
                "{name}: hinge about {axis} came to {angle} rad, the limit it falls to is \
                 {expected} rad"
            );
        }
    }
}

/// Steps of the joint friction test: 0.5 s, in which a frictionless bar falls from level
/// through 1.7 rad.
const FRICTION_STEPS: u32 = 30;

/// Each engine carries impulse's joint friction over (a velocity motor of target 0 whose
/// bound is the friction torque, N·m): a bar held out level by a hinge about x or by a
/// spherical joint, whose weight pulls with 9 kg · 9.81 m/s² · 0.5 m = 44.1 N·m about the
/// joint. Under 100 N·m of friction it stays level for 0.5 s (impulse, Box3D, Jolt within
/// 0.01 rad; Rapier's motor lets it creep, 0.085 rad in 0.5 s, so within 0.1 rad);
/// under 20 N·m it turns as far as impulse's bar does, within 0.1 rad (about 1 rad, where a
/// frictionless bar turns 1.7): the same torque in every engine.
#[test]
fn every_engine_brakes_a_falling_bar_with_impulses_joint_friction() {
    let friction = |torque: f32| {
        format!(
            r#"{{"velocity": 0.0, "hertz": 5.0, "damping_ratio": 1.0, "max_force": {torque:?}}}"#
        )
    };
    for torque in [100.0f32, 20.0] {
        let motor = friction(torque);
        let joints = [
            format!(
                r#"{{"type": "revolute", "body_a": 0, "body_b": 1, "anchor": [0.0, 0.0, 0.0], "axis": [1.0, 0.0, 0.0], "motor": {motor}}}"#
            ),
            format!(
                r#"{{"type": "spherical", "body_a": 0, "body_b": 1, "anchor": [0.0, 0.0, 0.0], "dofs": {{"angular_x": {{"motor": {motor}}}, "angular_y": {{"motor": {motor}}}, "angular_z": {{"motor": {motor}}}}}}}"#
            ),
        ];
        for joint in &joints {
            let scene = bar_scene(joint, [0.0, 0.0, 0.5]);
            let kind = scene.joints[0].kind;
            let mut impulse_angle = None;
            for (name, mut run) in every_engine(&scene) {
                run.advance(FRICTION_STEPS).unwrap();
                let angle = run.poses()[1].rotation.angle_between(glam::Quat::IDENTITY);
                println!("{name}, {kind:?} joint, friction {torque} N·m: turned {angle:.4} rad");
                let reference = *impulse_angle.get_or_insert(angle);
                if torque > 44.1 {
                    let bound = if name == crate::peer_settings::RAPIER {
                        0.1
                    } else {
                        0.01
                    };
                    assert!(angle < bound, "{name}, {kind:?}: turned {angle} rad");
                } else {
                    assert!(
                        (0.5..1.5).contains(&angle) && (angle - reference).abs() < 0.1,
                        "{name}, {kind:?}: turned {angle} rad, impulse's bar {reference} rad"
                    );
                }
            }
        }
    }
}
