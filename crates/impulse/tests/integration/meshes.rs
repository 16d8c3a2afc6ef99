//! Triangle meshes, height fields, compounds and rounded shapes through the scene format:
//! files read (OBJ, glTF, GLB), piles coming to rest on a mesh terrain without falling
//! through, every shape resting on every ground and on the flat-topped shapes. Bad input is
//! in `malformed_meshes.rs`.

use std::path::{Path, PathBuf};

use impulse::glam::Vec3;
use impulse::parry3d::query;
use impulse::scene::{
    BodyDesc, BodyKind, CompoundPart, MeshFormat, Scene, ShapeDesc, load_mesh_file,
    load_scene_file, read_mesh_bytes,
};
use impulse::{SolverSettings, World};

fn scenes_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes")
}

/// A scratch directory of this test binary, emptied first.
pub(crate) fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("impulse-meshes-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Largest depth (m) by which any moving body of `world` overlaps static body `ground`.
fn deepest_into(world: &World, ground: usize) -> f32 {
    let (poses, shapes) = (world.poses(), world.shapes());
    let mut deepest = 0.0f32;
    for i in 0..world.body_count() {
        if i == ground || !world.body_kinds()[i].is_moving() {
            continue;
        }
        if let Ok(Some(contact)) = query::contact(
            &poses[ground],
            shapes[ground].as_ref(),
            &poses[i],
            shapes[i].as_ref(),
            0.0,
        ) {
            deepest = deepest.max(-contact.dist);
        }
    }
    deepest
}

/// The example pile (32 bodies of eight shapes dropped on `scenes/terrain.obj`) settles: within
/// 30 s every body is asleep (slower than the sleep thresholds for `time_to_sleep`), none sank
/// more than 1 cm into the terrain on the way, and none fell through it. Cones and rounded
/// cylinders standing on their flat caps across two or three triangles come to rest too
/// (`collision::caps`: with Parry's square cap they rocked on their rims for ever).
#[test]
fn pile_on_the_mesh_terrain_comes_to_rest_without_falling_through() {
    let scene = load_scene_file(&scenes_dir().join("mesh_terrain.json")).unwrap();
    let mut world = World::from_scene(&scene).unwrap();
    let mut deepest = 0.0f32;
    let mut steps = 0;
    let settled =
        |w: &World| (1..w.body_count()).all(|i| !w.body_kinds()[i].is_moving() || w.asleep()[i]);
    while !settled(&world) {
        assert!(steps < 1800, "the pile is not at rest after 30 s");
        world.step().unwrap();
        steps += 1;
        deepest = deepest.max(deepest_into(&world, 0));
    }
    for i in 1..world.body_count() {
        // The terrain's lowest point is at y = −0.4 m.
        let p = world.poses()[i].translation;
        assert!(p.y > -0.4, "body {i} fell through: {p}");
    }
    assert!(deepest < 0.01, "a body sank {deepest} m into the terrain");
    println!("at rest after {steps} steps, deepest overlap {deepest} m");
}

/// A cylinder, a rounded cylinder and a cone, without angular damping, set down upright 5 cm
/// above `scenes/terrain.obj` where their flat bottoms span several triangles meeting at a
/// saddle-shaped vertex (at 2–3° to each other), come to rest: asleep within 10 s. With
/// Parry's square approximation of the cap they rolled on their rims there for good, at
/// 0.1–0.5 rad/s (`collision::caps`); now each sleeps within 3.5 s.
#[test]
fn caps_set_down_across_terrain_triangles_come_to_rest() {
    let scene = load_scene_file(&scenes_dir().join("mesh_terrain.json")).unwrap();
    // The terrain's surface: y = 0.4 sin(0.6x) cos(0.5z) at its vertices.
    let height = |x: f32, z: f32| 0.4 * (0.6 * x).sin() * (0.5 * z).cos();
    let cylinder = ShapeDesc::Cylinder {
        half_height: 0.15,
        radius: 0.35,
    };
    // (name, shape, height of its flat bottom below its origin (m)).
    let shapes = [
        ("cylinder", cylinder.clone(), 0.15),
        (
            "rounded cylinder",
            ShapeDesc::Round {
                shape: Box::new(cylinder),
                border_radius: 0.04,
            },
            0.19,
        ),
        (
            "cone",
            ShapeDesc::Cone {
                half_height: 0.3,
                radius: 0.35,
            },
            0.3,
        ),
    ];
    let mut failures = Vec::new();
    for (name, shape, below) in &shapes {
        for (x, z) in [(-1.0f32, 2.0f32), (-0.98, 2.11), (-2.26, 2.08)] {
            let mut pile = scene.clone();
            pile.bodies.truncate(1);
            let position = [x, height(x, z) + below + 0.05, z];
            pile.bodies
                .push(BodyDesc::new(BodyKind::Dynamic, shape.clone(), position));
            let mut world = World::from_scene(&pile).unwrap();
            let steps = (0..600).take_while(|_| {
                world.step().unwrap();
                !world.asleep()[1]
            });
            if steps.count() == 600 {
                failures.push(format!(
                    "{name} at ({x}, {z}) awake after 10 s: {:.3} m/s, {:.3} rad/s",
                    world.linear_velocities()[1].length(),
                    world.angular_velocities()[1].length()
                ));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The OBJ file's triangles, and the same triangles written as glTF (a data-URI buffer) and
/// GLB under a node that moves them by (1, 2, 3): the glTF reader applies the node transform.
#[test]
fn obj_gltf_and_glb_give_the_same_triangles() {
    let obj = load_mesh_file(&scenes_dir().join("terrain.obj")).unwrap();
    assert_eq!(obj.vertices.len(), 169);
    assert_eq!(obj.indices.len(), 288);
    let offset = [1.0f32, 2.0, 3.0];
    let mut bin: Vec<u8> = Vec::new();
    for v in &obj.vertices {
        for x in v {
            bin.extend(x.to_le_bytes());
        }
    }
    let positions_length = bin.len();
    for t in &obj.indices {
        for i in t {
            bin.extend(i.to_le_bytes());
        }
    }
    let (mut low, mut high) = ([f32::MAX; 3], [f32::MIN; 3]);
    for v in &obj.vertices {
        for k in 0..3 {
            low[k] = low[k].min(v[k]);
            high[k] = high[k].max(v[k]);
        }
    }
    let document = |uri: Option<String>| {
        let mut buffer = serde_json::json!({"byteLength": bin.len()});
        if let Some(uri) = uri {
            buffer["uri"] = serde_json::Value::String(uri);
        }
        serde_json::json!({
            "asset": {"version": "2.0"},
            "scene": 0,
            "scenes": [{"nodes": [0]}],
            "nodes": [{"translation": offset, "children": [1]}, {"mesh": 0}],
            "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
            "buffers": [buffer],
            "bufferViews": [
                {"buffer": 0, "byteOffset": 0, "byteLength": positions_length},
                {"buffer": 0, "byteOffset": positions_length, "byteLength": bin.len() - positions_length}
            ],
            "accessors": [
                {"bufferView": 0, "componentType": 5126, "count": obj.vertices.len(), "type": "VEC3", "min": low, "max": high},
                {"bufferView": 1, "componentType": 5125, "count": 3 * obj.indices.len(), "type": "SCALAR"}
            ]
        })
    };
    let dir = scratch("gltf");
    use base64::Engine as _;
    let uri = format!(
        "data:application/octet-stream;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(&bin)
    );
    std::fs::write(dir.join("terrain.gltf"), document(Some(uri)).to_string()).unwrap();
    // GLB: 12-byte header, a JSON chunk and a BIN chunk, each padded to 4 bytes.
    let mut json = document(None).to_string().into_bytes();
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    let mut blob = bin.clone();
    while !blob.len().is_multiple_of(4) {
        blob.push(0);
    }
    let mut glb = Vec::new();
    glb.extend(b"glTF");
    glb.extend(2u32.to_le_bytes());
    glb.extend(((12 + 8 + json.len() + 8 + blob.len()) as u32).to_le_bytes());
    glb.extend((json.len() as u32).to_le_bytes());
    glb.extend(b"JSON");
    glb.extend(&json);
    glb.extend((blob.len() as u32).to_le_bytes());
    glb.extend(b"BIN\0");
    glb.extend(&blob);
    std::fs::write(dir.join("terrain.glb"), &glb).unwrap();
    // The buffer in a file beside the glTF file.
    std::fs::write(dir.join("terrain.bin"), &bin).unwrap();
    let external = document(Some("terrain.bin".into())).to_string();
    std::fs::write(dir.join("external.gltf"), &external).unwrap();
    for name in ["terrain.gltf", "terrain.glb", "external.gltf"] {
        let mesh = load_mesh_file(&dir.join(name)).unwrap();
        assert_eq!(mesh.indices, obj.indices, "{name}");
        for (a, b) in mesh.vertices.iter().zip(&obj.vertices) {
            let moved = [b[0] + offset[0], b[1] + offset[1], b[2] + offset[2]];
            assert_eq!(*a, moved, "{name}");
        }
    }
    // From bytes: the same triangles; a buffer in another file is read only from a directory.
    let from_glb = read_mesh_bytes(&glb, MeshFormat::Gltf, "terrain.glb", None).unwrap();
    assert_eq!(from_glb, load_mesh_file(&dir.join("terrain.glb")).unwrap());
    let beside = read_mesh_bytes(external.as_bytes(), MeshFormat::Gltf, "x.gltf", Some(&dir));
    assert_eq!(beside.unwrap(), from_glb);
    let refused = read_mesh_bytes(external.as_bytes(), MeshFormat::Gltf, "x.gltf", None)
        .expect_err("a buffer in another file without a directory must be refused")
        .to_string();
    assert!(
        refused.contains("x.gltf") && refused.contains("terrain.bin"),
        "{refused}"
    );
    let _ = std::fs::remove_dir_all(dir);
}

// ---------------------------------------------------------------------------------------------
// Every shape resting on every ground and on the flat-topped shapes for 10 s.

fn settings() -> SolverSettings {
    SolverSettings {
        sleep: None,
        ..SolverSettings::default()
    }
}

/// The moving shapes, each with the height of its lowest point below its origin when
/// upright (m): the body's origin is placed that high above the surface it rests on.
fn moving_shapes() -> Vec<(&'static str, ShapeDesc, f32)> {
    let round = |shape: ShapeDesc, border_radius: f32| ShapeDesc::Round {
        shape: Box::new(shape),
        border_radius,
    };
    vec![
        ("sphere", ShapeDesc::Sphere { radius: 0.3 }, 0.3),
        (
            "cuboid",
            ShapeDesc::Cuboid {
                half_extents: [0.3, 0.2, 0.25],
            },
            0.2,
        ),
        // Lying along z (see `placed`).
        (
            "capsule",
            ShapeDesc::Capsule {
                half_height: 0.2,
                radius: 0.2,
            },
            0.2,
        ),
        (
            "cylinder",
            ShapeDesc::Cylinder {
                half_height: 0.2,
                radius: 0.3,
            },
            0.2,
        ),
        (
            "cone",
            ShapeDesc::Cone {
                half_height: 0.25,
                radius: 0.3,
            },
            0.25,
        ),
        (
            "convex hull",
            ShapeDesc::ConvexHull {
                points: vec![
                    [-0.3, -0.2, -0.3],
                    [0.3, -0.2, -0.3],
                    [0.3, -0.2, 0.3],
                    [-0.3, -0.2, 0.3],
                    [0.0, 0.3, 0.0],
                ],
            },
            0.2,
        ),
        (
            "round cuboid",
            round(
                ShapeDesc::Cuboid {
                    half_extents: [0.25, 0.15, 0.2],
                },
                0.05,
            ),
            0.2,
        ),
        (
            "round cylinder",
            round(
                ShapeDesc::Cylinder {
                    half_height: 0.15,
                    radius: 0.25,
                },
                0.05,
            ),
            0.2,
        ),
        (
            "round cone",
            round(
                ShapeDesc::Cone {
                    half_height: 0.2,
                    radius: 0.25,
                },
                0.05,
            ),
            0.25,
        ),
        (
            "round convex hull",
            round(
                ShapeDesc::ConvexHull {
                    points: vec![
                        [-0.25, -0.15, -0.25],
                        [0.25, -0.15, -0.25],
                        [0.25, -0.15, 0.25],
                        [-0.25, -0.15, 0.25],
                        [0.0, 0.25, 0.0],
                    ],
                },
                0.05,
            ),
            0.2,
        ),
        ("compound", stool(), 0.2),
    ]
}

/// A stool: a seat on four legs; its feet at y = −0.2, its seat's top at y = 0.3.
fn stool() -> ShapeDesc {
    let cuboid = |h: [f32; 3], p: [f32; 3]| CompoundPart {
        shape: ShapeDesc::Cuboid { half_extents: h },
        position: p,
        orientation: [0.0, 0.0, 0.0, 1.0],
    };
    let mut parts = vec![cuboid([0.35, 0.05, 0.35], [0.0, 0.25, 0.0])];
    for (x, z) in [(-0.28, -0.28), (0.28, -0.28), (-0.28, 0.28), (0.28, 0.28)] {
        parts.push(cuboid([0.05, 0.2, 0.05], [x, 0.0, z]));
    }
    ShapeDesc::Compound { parts }
}

/// The static grounds, each with its top at y = 0 around the origin.
fn grounds() -> Vec<(&'static str, BodyDesc)> {
    let at = |shape: ShapeDesc, y: f32| BodyDesc::new(BodyKind::Static, shape, [0.0, y, 0.0]);
    let n = 6u32;
    let mut vertices = Vec::new();
    for k in 0..=n {
        for i in 0..=n {
            vertices.push([i as f32 - 3.0, 0.0, k as f32 - 3.0]);
        }
    }
    let mut indices = Vec::new();
    let index = |i: u32, k: u32| k * (n + 1) + i;
    for k in 0..n {
        for i in 0..n {
            indices.push([index(i, k), index(i, k + 1), index(i + 1, k + 1)]);
            indices.push([index(i, k), index(i + 1, k + 1), index(i + 1, k)]);
        }
    }
    vec![
        (
            "half-space",
            at(
                ShapeDesc::HalfSpace {
                    normal: [0.0, 1.0, 0.0],
                },
                0.0,
            ),
        ),
        (
            "box",
            at(
                ShapeDesc::Cuboid {
                    half_extents: [3.0, 0.5, 3.0],
                },
                -0.5,
            ),
        ),
        ("trimesh", at(ShapeDesc::trimesh(vertices, indices), 0.0)),
        (
            "heightfield",
            at(
                ShapeDesc::HeightField {
                    heights: vec![vec![0.0; 7]; 7],
                    scale: [6.0, 1.0, 6.0],
                },
                0.0,
            ),
        ),
    ]
}

/// A moving body of `shape` (named `name`) with its origin at `position`; a capsule lies
/// along z (standing on a hemisphere it would topple).
fn placed(name: &str, shape: ShapeDesc, position: [f32; 3]) -> BodyDesc {
    let mut body = BodyDesc::new(BodyKind::Dynamic, shape, position);
    if name == "capsule" {
        body.orientation = [
            std::f32::consts::FRAC_1_SQRT_2,
            0.0,
            0.0,
            std::f32::consts::FRAC_1_SQRT_2,
        ];
    }
    body
}

/// Runs `bodies` for 10 s and returns the largest displacement (m) of any moving body from
/// where it started. The bodies start touching, at rest.
fn drift(bodies: Vec<BodyDesc>) -> f32 {
    let scene = Scene {
        solver: settings(),
        bodies,
        ..Scene::default()
    };
    let mut world = World::from_scene(&scene).unwrap();
    let start: Vec<Vec3> = world.poses().iter().map(|p| p.translation).collect();
    for _ in 0..600 {
        world.step().unwrap();
    }
    (0..world.body_count())
        .filter(|&i| world.body_kinds()[i].is_moving())
        .map(|i| world.poses()[i].translation.distance(start[i]))
        .fold(0.0, f32::max)
}

#[test]
fn every_shape_rests_on_every_ground_for_10_s() {
    let mut failures = Vec::new();
    for (ground_name, ground) in grounds() {
        for (name, shape, below) in moving_shapes() {
            let body = placed(name, shape, [0.2, below, 0.1]);
            let d = drift(vec![ground.clone(), body]);
            if d >= 1.0e-3 {
                failures.push(format!("{name} on {ground_name}: drift {:.3} mm", 1e3 * d));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Every moving shape resting on each flat-topped shape (itself resting on a half-space)
/// moves less than 1 mm in 10 s. A ball rolls on any lean of its contact normal, so on the
/// rounded shapes this checks that the normal on a rounded shape's flat top is the face's
/// (`collision::dispatch`; Parry's own leans by 1e-5 rad and rolled the ball 13–65 mm).
#[test]
fn every_shape_rests_on_the_flat_topped_shapes_for_10_s() {
    // Lower shapes with a flat top: (name, shape, height of the origin above the ground,
    // height of the top above the origin).
    let lower: Vec<(&str, ShapeDesc, f32, f32)> = vec![
        (
            "cuboid",
            ShapeDesc::Cuboid {
                half_extents: [0.5, 0.2, 0.5],
            },
            0.2,
            0.2,
        ),
        (
            "cylinder",
            ShapeDesc::Cylinder {
                half_height: 0.2,
                radius: 0.55,
            },
            0.2,
            0.2,
        ),
        (
            "round cuboid",
            ShapeDesc::Round {
                shape: Box::new(ShapeDesc::Cuboid {
                    half_extents: [0.45, 0.15, 0.45],
                }),
                border_radius: 0.05,
            },
            0.2,
            0.2,
        ),
        (
            "round cylinder",
            ShapeDesc::Round {
                shape: Box::new(ShapeDesc::Cylinder {
                    half_height: 0.15,
                    radius: 0.5,
                }),
                border_radius: 0.05,
            },
            0.2,
            0.2,
        ),
        (
            "round convex hull",
            ShapeDesc::Round {
                shape: Box::new(ShapeDesc::ConvexHull {
                    points: vec![
                        [-0.45, -0.15, -0.45],
                        [0.45, -0.15, -0.45],
                        [0.45, -0.15, 0.45],
                        [-0.45, -0.15, 0.45],
                        [-0.4, 0.15, -0.4],
                        [0.4, 0.15, -0.4],
                        [0.4, 0.15, 0.4],
                        [-0.4, 0.15, 0.4],
                    ],
                }),
                border_radius: 0.05,
            },
            0.2,
            0.2,
        ),
        (
            "convex hull",
            ShapeDesc::ConvexHull {
                points: vec![
                    [-0.5, -0.2, -0.5],
                    [0.5, -0.2, -0.5],
                    [0.5, -0.2, 0.5],
                    [-0.5, -0.2, 0.5],
                    [-0.45, 0.2, -0.45],
                    [0.45, 0.2, -0.45],
                    [0.45, 0.2, 0.45],
                    [-0.45, 0.2, 0.45],
                ],
            },
            0.2,
            0.2,
        ),
        ("compound", stool(), 0.2, 0.3),
    ];
    let ground = BodyDesc::new(
        BodyKind::Static,
        ShapeDesc::HalfSpace {
            normal: [0.0, 1.0, 0.0],
        },
        [0.0; 3],
    );
    let mut failures = Vec::new();
    for (lower_name, lower_shape, lower_height, top) in &lower {
        for (name, shape, below) in moving_shapes() {
            let base = BodyDesc::new(
                BodyKind::Dynamic,
                lower_shape.clone(),
                [0.0, *lower_height, 0.0],
            );
            let upper = placed(name, shape, [0.05, lower_height + top + below, -0.03]);
            let d = drift(vec![ground.clone(), base, upper]);
            if d >= 1.0e-3 {
                failures.push(format!("{name} on {lower_name}: drift {:.3} mm", 1e3 * d));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
