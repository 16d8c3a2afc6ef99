//! Cylinders and cones (`ShapeDesc::Cylinder`, `ShapeDesc::Cone`, along local y): mass
//! properties against the closed forms, resting contact on the ground, and the shape pairs
//! Parry generates contacts for.

use impulse::glam::Vec3;
use impulse::scene::{BodyDesc, BodyKind, Scene, ShapeDesc};
use impulse::{SolverSettings, World};

const DENSITY: f32 = 1000.0;

fn world_of(bodies: Vec<BodyDesc>) -> World {
    let scene = Scene {
        solver: SolverSettings {
            sleep: None,
            ..SolverSettings::default()
        },
        bodies,
        ..Scene::default()
    };
    World::from_scene(&scene).unwrap()
}

fn ground() -> BodyDesc {
    BodyDesc::new(
        BodyKind::Static,
        ShapeDesc::HalfSpace {
            normal: [0.0, 1.0, 0.0],
        },
        [0.0; 3],
    )
}

fn dynamic(shape: ShapeDesc, position: [f32; 3]) -> BodyDesc {
    BodyDesc::new(BodyKind::Dynamic, shape, position)
}

/// Mass, centre of mass and principal moments (about the centre of mass) of body 0.
fn mass_properties(shape: ShapeDesc) -> (f64, Vec3, [f64; 3]) {
    let world = world_of(vec![dynamic(shape, [0.0; 3])]);
    let b = world.body_at(0).unwrap();
    let inverse = b.local_inverse_inertia();
    let moments =
        [inverse.x_axis.x, inverse.y_axis.y, inverse.z_axis.z].map(|x| 1.0 / f64::from(x));
    (
        1.0 / f64::from(b.inverse_mass()),
        world.local_centers_of_mass()[0],
        moments,
    )
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() < 1e-4 * b.abs()
}

#[test]
fn cylinder_inertia_matches_the_closed_form() {
    let (hh, r) = (0.6f64, 0.25f64);
    let (m, com, [ix, iy, iz]) = mass_properties(ShapeDesc::Cylinder {
        half_height: hh as f32,
        radius: r as f32,
    });
    let h = 2.0 * hh;
    let expected_m = f64::from(DENSITY) * std::f64::consts::PI * r * r * h;
    assert!(close(m, expected_m), "mass {m} against {expected_m}");
    assert!(com.length() < 1e-6, "centre of mass {com}");
    let diameter = m * (3.0 * r * r + h * h) / 12.0;
    let axis = m * r * r / 2.0;
    assert!(
        close(ix, diameter) && close(iz, diameter),
        "{ix}, {iz} against {diameter}"
    );
    assert!(close(iy, axis), "{iy} against {axis}");
}

#[test]
fn cone_inertia_matches_the_closed_form() {
    let (hh, r) = (0.5f64, 0.4f64);
    let (m, com, [ix, iy, iz]) = mass_properties(ShapeDesc::Cone {
        half_height: hh as f32,
        radius: r as f32,
    });
    let h = 2.0 * hh;
    let expected_m = f64::from(DENSITY) * std::f64::consts::PI * r * r * h / 3.0;
    assert!(close(m, expected_m), "mass {m} against {expected_m}");
    // A quarter of the height above the base, at y = −half_height.
    let expected_com = -hh + h / 4.0;
    assert!(
        (f64::from(com.y) - expected_com).abs() < 1e-6 && com.x == 0.0 && com.z == 0.0,
        "centre of mass {com} against y = {expected_com}"
    );
    let diameter = 3.0 * m * (r * r / 20.0 + h * h / 80.0);
    let axis = 3.0 * m * r * r / 10.0;
    assert!(
        close(ix, diameter) && close(iz, diameter),
        "{ix}, {iz} against {diameter}"
    );
    assert!(close(iy, axis), "{iy} against {axis}");
}

#[test]
fn sphere_box_and_capsule_inertia_match_the_closed_forms() {
    let pi = std::f64::consts::PI;
    let rho = f64::from(DENSITY);
    // Solid sphere: I = 2/5 m r².
    let r = 0.35f64;
    let (m, com, moments) = mass_properties(ShapeDesc::Sphere { radius: r as f32 });
    let expected_m = rho * 4.0 / 3.0 * pi * r.powi(3);
    assert!(close(m, expected_m), "sphere mass {m} against {expected_m}");
    assert!(com.length() < 1e-6);
    for i in moments {
        assert!(close(i, 0.4 * m * r * r), "sphere {i}");
    }
    // Box of sides a, b, c: I_x = m (b² + c²)/12 and so on.
    let h = [0.3f64, 0.5, 0.7];
    let (m, com, [ix, iy, iz]) = mass_properties(ShapeDesc::Cuboid {
        half_extents: h.map(|x| x as f32),
    });
    let [a, b, c] = h.map(|x| 2.0 * x);
    assert!(close(m, rho * a * b * c), "box mass {m}");
    assert!(com.length() < 1e-6);
    assert!(close(ix, m * (b * b + c * c) / 12.0), "box x {ix}");
    assert!(close(iy, m * (a * a + c * c) / 12.0), "box y {iy}");
    assert!(close(iz, m * (a * a + b * b) / 12.0), "box z {iz}");
    // Capsule along y: a cylinder (radius r, height 2h) and two hemispheres, each hemisphere
    // with its own centre of mass 3r/8 from its flat face (parallel-axis theorem).
    let (r, hh) = (0.25f64, 0.4f64);
    let (m, com, [ix, iy, iz]) = mass_properties(ShapeDesc::Capsule {
        half_height: hh as f32,
        radius: r as f32,
    });
    let cylinder_m = rho * pi * r * r * 2.0 * hh;
    let sphere_m = rho * 4.0 / 3.0 * pi * r.powi(3);
    assert!(close(m, cylinder_m + sphere_m), "capsule mass {m}");
    assert!(com.length() < 1e-6);
    let axis = cylinder_m * r * r / 2.0 + 0.4 * sphere_m * r * r;
    let hemisphere_own =
        0.4 * (sphere_m / 2.0) * r * r - (sphere_m / 2.0) * (3.0 * r / 8.0).powi(2);
    let hemisphere_offset = hh + 3.0 * r / 8.0;
    let across = cylinder_m * (3.0 * r * r + 4.0 * hh * hh) / 12.0
        + 2.0 * (hemisphere_own + sphere_m / 2.0 * hemisphere_offset * hemisphere_offset);
    assert!(close(iy, axis), "capsule axis {iy} against {axis}");
    assert!(
        close(ix, across) && close(iz, across),
        "capsule {ix}, {iz} against {across}"
    );
}

/// A compound of two boxes side by side (and a small one turned on top): its mass is the sum,
/// its centre of mass the mass-weighted mean, and its inertia tensor about that centre the
/// sum of each part's own tensor (turned into the body's frame) plus m·(|d|²I − d dᵀ) for each
/// part's offset d from it (the parallel-axis theorem), computed here by hand.
#[test]
fn compound_inertia_matches_the_parallel_axis_theorem() {
    use impulse::glam::{DMat3, DQuat, DVec3};
    use impulse::scene::CompoundPart;
    let rho = f64::from(DENSITY);
    let parts = [
        ([0.5f64, 0.2, 0.3], [-0.5f64, 0.0, 0.1], DQuat::IDENTITY),
        ([0.25, 0.4, 0.3], [0.75, 0.2, 0.0], DQuat::IDENTITY),
        (
            [0.1, 0.1, 0.3],
            [0.0, 0.5, -0.2],
            DQuat::from_rotation_y(0.7) * DQuat::from_rotation_x(0.3),
        ),
    ];
    let shape = ShapeDesc::Compound {
        parts: parts
            .iter()
            .map(|(h, p, q)| CompoundPart {
                shape: ShapeDesc::Cuboid {
                    half_extents: h.map(|x| x as f32),
                },
                position: p.map(|x| x as f32),
                orientation: q.as_quat().to_array(),
            })
            .collect(),
    };
    // By hand.
    let mut mass = 0.0;
    let mut moment = DVec3::ZERO;
    for (h, p, _) in &parts {
        let m = rho * 8.0 * h[0] * h[1] * h[2];
        mass += m;
        moment += m * DVec3::from(*p);
    }
    let centre = moment / mass;
    let mut tensor = DMat3::ZERO;
    for (h, p, q) in &parts {
        let m = rho * 8.0 * h[0] * h[1] * h[2];
        let [a, b, c] = h.map(|x| 2.0 * x);
        let own = DMat3::from_diagonal(DVec3::new(
            m * (b * b + c * c) / 12.0,
            m * (a * a + c * c) / 12.0,
            m * (a * a + b * b) / 12.0,
        ));
        let rotation = DMat3::from_quat(*q);
        let d = DVec3::from(*p) - centre;
        let shift = m
            * (DMat3::from_diagonal(DVec3::splat(d.length_squared()))
                - DMat3::from_cols(d * d.x, d * d.y, d * d.z));
        tensor += rotation * own * rotation.transpose() + shift;
    }
    // The engine's.
    let world = world_of(vec![dynamic(shape, [0.0; 3])]);
    let b = world.body_at(0).unwrap();
    let engine_mass = 1.0 / f64::from(b.inverse_mass());
    assert!(
        close(engine_mass, mass),
        "mass {engine_mass} against {mass}"
    );
    let engine_centre = world.local_centers_of_mass()[0].as_dvec3();
    assert!(
        (engine_centre - centre).length() < 1e-5,
        "centre of mass {engine_centre} against {centre}"
    );
    let engine_tensor = b.local_inverse_inertia().as_dmat3().inverse();
    let scale = tensor
        .to_cols_array()
        .iter()
        .fold(0.0f64, |s, x| s.max(x.abs()));
    for (e, t) in engine_tensor
        .to_cols_array()
        .iter()
        .zip(tensor.to_cols_array())
    {
        assert!(
            (e - t).abs() < 1e-4 * scale,
            "inertia tensor\n{engine_tensor}\nagainst\n{tensor}"
        );
    }
}

/// Steps `world` for 10 s and returns the largest distance (m) body `i` moved from where it
/// was after the first second (the contact settling).
fn drift_after_settling(world: &mut World, i: usize) -> f32 {
    for _ in 0..60 {
        world.step().unwrap();
    }
    let start = world.poses()[i].translation;
    let mut worst = 0.0f32;
    for _ in 0..540 {
        world.step().unwrap();
        worst = worst.max((world.poses()[i].translation - start).length());
    }
    worst
}

#[test]
fn a_cylinder_and_a_cone_rest_on_the_ground() {
    let cylinder = ShapeDesc::Cylinder {
        half_height: 0.5,
        radius: 0.3,
    };
    let cone = ShapeDesc::Cone {
        half_height: 0.4,
        radius: 0.5,
    };
    for (shape, half_height) in [(cylinder, 0.5), (cone, 0.4)] {
        // On a half-space and on a static box.
        let floors = [
            ground(),
            BodyDesc::new(
                BodyKind::Static,
                ShapeDesc::Cuboid {
                    half_extents: [5.0, 0.5, 5.0],
                },
                [0.0, -0.5, 0.0],
            ),
        ];
        for floor in floors {
            let mut world = world_of(vec![floor, dynamic(shape.clone(), [0.0, half_height, 0.0])]);
            let drift = drift_after_settling(&mut world, 1);
            let y = world.poses()[1].translation.y;
            assert!(drift < 0.001, "{shape:?} drifts {drift} m");
            assert!(
                (y - half_height).abs() < 0.005,
                "{shape:?} rests at y = {y}, not {half_height}"
            );
        }
    }
}

#[test]
fn parry_makes_contacts_for_cylinders_and_cones_against_the_other_shapes() {
    let cylinder = ShapeDesc::Cylinder {
        half_height: 0.5,
        radius: 0.5,
    };
    let cone = ShapeDesc::Cone {
        half_height: 0.5,
        radius: 0.5,
    };
    let ball = ShapeDesc::Sphere { radius: 0.3 };
    let cuboid = ShapeDesc::Cuboid {
        half_extents: [0.3, 0.3, 0.3],
    };
    let capsule = ShapeDesc::Capsule {
        half_height: 0.3,
        radius: 0.2,
    };
    let hull = ShapeDesc::ConvexHull {
        points: vec![
            [-0.3, -0.3, -0.3],
            [0.3, -0.3, -0.3],
            [-0.3, -0.3, 0.3],
            [0.3, -0.3, 0.3],
            [0.0, 0.3, 0.0],
        ],
    };
    // Each top shape dropped flat-side down onto an upright cylinder (top face at y = 1),
    // and each shape under a cuboid landing on it; the top body must come to rest above.
    for (top, bottom_of_top) in [
        (ball.clone(), 0.3),
        (cuboid.clone(), 0.3),
        (capsule, 0.5),
        (hull, 0.3),
        (cylinder.clone(), 0.5),
        (cone.clone(), 0.5),
    ] {
        for base in [cylinder.clone(), cone.clone()] {
            if matches!(base, ShapeDesc::Cone { .. }) && !matches!(top, ShapeDesc::Cuboid { .. }) {
                continue;
            }
            let mut world = world_of(vec![
                ground(),
                dynamic(base.clone(), [0.0, 0.5, 0.0]),
                dynamic(top.clone(), [0.0, 1.1 + bottom_of_top, 0.0]),
            ]);
            for _ in 0..60 {
                world
                    .step()
                    .unwrap_or_else(|e| panic!("{top:?} on {base:?}: {e}"));
            }
            let y = world.body_at(2).unwrap().center_of_mass().y;
            assert!(
                y > 0.9,
                "{top:?} on {base:?} fell through: centre of mass at y = {y}"
            );
            assert!(
                world
                    .contact_pairs()
                    .any(|pair| pair.points().next().is_some()),
                "{top:?} on {base:?}: no contact"
            );
        }
    }
}
