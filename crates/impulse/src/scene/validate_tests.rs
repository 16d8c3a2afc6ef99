//! Unit tests of the scene checks: every error collected, each naming its field.

use super::*;

#[test]
fn default_scene_is_valid_and_errors_are_collected() {
    assert!(validate(&Scene::default()).is_ok());
    let mut scene = Scene {
        dt: -1.0,
        ..Scene::default()
    };
    scene.solver.solve.iterations = 0;
    scene.bodies.push(BodyDesc::new(
        BodyKind::Particle,
        ShapeDesc::Cuboid {
            half_extents: [1.0, -1.0, 1.0],
        },
        [0.0; 3],
    ));
    let errors: Vec<String> = validate_all(&scene)
        .iter()
        .map(ToString::to_string)
        .collect();
    assert_eq!(
        errors,
        [
            "dt: must be finite and within [1e-6, 1] s, got -1",
            "solver.iterations: must be ≥ 1, got 0",
            "bodies[0].shape.type: a particle must have a sphere shape, got cuboid",
            "bodies[0].shape.half_extents[1]: must be ≥ 0, got -1",
        ]
    );
}
