//! How a contact's friction and restitution are made from its two bodies' coefficients
//! (`solver.friction_combine`, `solver.restitution_combine`), against closed forms: a ball's
//! rebound speed is c_r times its impact speed, and a box sliding on level ground slows at μ·g.

use glam::Vec3;
use impulse::scene::parse_scene_str;
use impulse::settings::CombineRule;
use impulse::{BodyDesc, BodyKind, Material, ShapeDesc, SolverSettings, World};

const DT: f32 = 1.0 / 60.0;
const G: f32 = 9.81;

const RULES: [CombineRule; 5] = [
    CombineRule::GeometricMean,
    CombineRule::Average,
    CombineRule::Min,
    CombineRule::Max,
    CombineRule::Multiply,
];

fn material(friction: f32, restitution: f32) -> Material {
    Material {
        friction,
        restitution,
        density: 1000.0,
        roughness: 0.0,
        impact_perturbation: 0.0,
    }
}

/// A world with a static ground box (top face at y = 0) of `ground` material.
fn world_on_ground(settings: SolverSettings, ground: Material) -> World {
    let mut world = World::new(Vec3::new(0.0, -G, 0.0), DT, settings).unwrap();
    let desc = BodyDesc::new(
        BodyKind::Static,
        ShapeDesc::Cuboid {
            half_extents: [50.0, 0.5, 50.0],
        },
        [0.0, -0.5, 0.0],
    );
    world.add_body(&desc, &ground).unwrap();
    world
}

#[test]
fn the_rules_combine_as_named() {
    let (a, b) = (0.25f32, 0.64f32);
    let expected = [0.4, 0.445, 0.25, 0.64, 0.16];
    for (rule, want) in RULES.into_iter().zip(expected) {
        assert!((rule.combine(a, b) - want).abs() < 1e-6, "{}", rule.name());
        assert_eq!(rule.combine(a, b), rule.combine(b, a), "{}", rule.name());
    }
}

/// A ball of restitution 0.8 dropped on a floor of restitution 0.5 leaves the floor at c_r
/// times its impact speed, with c_r the rule's: 0.632, 0.65, 0.5, 0.8, 0.4.
#[test]
fn a_dropped_ball_rebounds_at_the_combined_restitution() {
    let (ball_restitution, floor_restitution) = (0.8f32, 0.5f32);
    for rule in RULES {
        let settings = SolverSettings {
            contact: impulse::settings::ContactSettings {
                restitution_combine: rule,
                restitution_threshold: 0.1,
                ..SolverSettings::default().contact
            },
            sleep: None,
            ..SolverSettings::default()
        };
        let mut world = world_on_ground(settings, material(0.5, floor_restitution));
        let desc = BodyDesc::new(
            BodyKind::Dynamic,
            ShapeDesc::Sphere { radius: 0.1 },
            [0.0, 1.0, 0.0],
        );
        let ball = world
            .add_body(&desc, &material(0.5, ball_restitution))
            .unwrap();
        // The fastest downward and then upward speed around the first bounce.
        let (mut impact, mut rebound) = (0.0f32, 0.0f32);
        for _ in 0..60 {
            world.step().unwrap();
            let vy = world.linear_velocities()[ball].y;
            if rebound == 0.0 {
                impact = impact.max(-vy);
            }
            if vy > 0.0 {
                rebound = rebound.max(vy);
            }
            if rebound > 0.0 && vy < rebound - 0.5 {
                break;
            }
        }
        let want = rule.combine(ball_restitution, floor_restitution);
        let got = rebound / impact;
        assert!(
            (got - want).abs() < 0.03,
            "{}: rebound {rebound} m/s from {impact} m/s is c_r {got}, expected {want}",
            rule.name()
        );
    }
}

/// A box sliding on level ground slows at μ·g, with μ the rule's from the box's 0.4 and the
/// ground's 0.9: 0.6, 0.65, 0.4, 0.9, 0.36.
#[test]
fn a_sliding_box_slows_at_the_combined_friction() {
    let (box_friction, ground_friction) = (0.4f32, 0.9f32);
    for rule in RULES {
        let settings = SolverSettings {
            contact: impulse::settings::ContactSettings {
                friction_combine: rule,
                ..SolverSettings::default().contact
            },
            sleep: None,
            ..SolverSettings::default()
        };
        let mut world = world_on_ground(settings, material(ground_friction, 0.0));
        let mut desc = BodyDesc::new(
            BodyKind::Dynamic,
            ShapeDesc::Cuboid {
                half_extents: [0.25, 0.25, 0.25],
            },
            [0.0, 0.25, 0.0],
        );
        desc.linear_velocity = [8.0, 0.0, 0.0];
        let block = world.add_body(&desc, &material(box_friction, 0.0)).unwrap();
        // Past the first steps' settling, over half a second (still sliding at every rule).
        for _ in 0..6 {
            world.step().unwrap();
        }
        let v0 = world.linear_velocities()[block].x;
        let steps = 30;
        for _ in 0..steps {
            world.step().unwrap();
        }
        let v1 = world.linear_velocities()[block].x;
        assert!(v1 > 0.5, "{}: stopped too soon ({v1} m/s)", rule.name());
        let deceleration = (v0 - v1) / (steps as f32 * DT);
        let want = rule.combine(box_friction, ground_friction) * G;
        assert!(
            (deceleration - want).abs() < 0.02 * want,
            "{}: slows at {deceleration} m/s², expected μ·g = {want}",
            rule.name()
        );
    }
}

/// The rules are read from a scene's solver settings by name; a preset keeps them (they are
/// physics, not solver effort); an unknown name is an error naming the field.
#[test]
fn scenes_name_the_rules_and_presets_keep_them() {
    let text = r#"{"solver": {"friction_combine": "multiply", "restitution_combine": "min"},
        "bodies": [{"kind": "static", "shape": {"type": "half_space", "normal": [0, 1, 0]}}]}"#;
    let scene = parse_scene_str(text, "combine.json").unwrap();
    assert_eq!(scene.solver.contact.friction_combine, CombineRule::Multiply);
    assert_eq!(scene.solver.contact.restitution_combine, CombineRule::Min);
    let fast = scene
        .solver
        .with_effort_of(&SolverSettings::preset("fast").unwrap());
    assert_eq!(fast.contact.friction_combine, CombineRule::Multiply);
    assert_eq!(fast.contact.restitution_combine, CombineRule::Min);
    let defaults = SolverSettings::default();
    assert_eq!(
        defaults.contact.friction_combine,
        CombineRule::GeometricMean
    );
    assert_eq!(defaults.contact.restitution_combine, CombineRule::Max);

    let bad = r#"{"solver": {"friction_combine": "product"}, "bodies": []}"#;
    let message = parse_scene_str(bad, "combine.json")
        .unwrap_err()
        .to_string();
    assert!(message.contains("friction_combine"), "{message}");
    assert!(message.contains("multiply"), "the allowed names: {message}");
}
