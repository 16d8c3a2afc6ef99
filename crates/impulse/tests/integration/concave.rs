//! Concave moving bodies: trimesh shapes on dynamic bodies, decomposed into convex parts
//! (`scene/decomposition.rs`). The meshes are built here as modelling tools export them:
//! closed triangle meshes, quads split into triangles, wound outward.

use std::f32::consts::{PI, TAU};

use impulse::glam::{Mat3, Vec3};
use impulse::scene::{BodyDesc, BodyKind, MeshData, Scene, ShapeDesc};
use impulse::{World, WorldSnapshot};

/// `mesh` with every triangle reversed when its signed volume is negative, so that it winds
/// outward (as exporters write closed meshes).
fn wound_outward(mut mesh: MeshData) -> MeshData {
    let volume: f32 = mesh
        .indices
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| Vec3::from(mesh.vertices[i as usize]));
            a.dot(b.cross(c)) / 6.0
        })
        .sum();
    if volume < 0.0 {
        for t in &mut mesh.indices {
            t.swap(1, 2);
        }
    }
    mesh
}

/// The closed surface swept by turning `profile`, points (r, y) from the axis (r = 0) back to
/// the axis, about the y axis in `segments` steps: each band of quads split into two
/// triangles, the ends at the axis closed by fans.
pub(crate) fn revolve(profile: &[[f32; 2]], segments: u32) -> MeshData {
    let mut vertices = Vec::new();
    // Index of profile point p at segment s (an axis point has one vertex).
    let mut ids: Vec<Vec<u32>> = Vec::new();
    for &[r, y] in profile {
        if r == 0.0 {
            ids.push(vec![vertices.len() as u32; segments as usize]);
            vertices.push([0.0, y, 0.0]);
        } else {
            let row = (0..segments)
                .map(|s| {
                    let angle = s as f32 / segments as f32 * TAU;
                    vertices.push([r * angle.cos(), y, r * angle.sin()]);
                    vertices.len() as u32 - 1
                })
                .collect();
            ids.push(row);
        }
    }
    let mut indices = Vec::new();
    for p in 0..profile.len() - 1 {
        for s in 0..segments as usize {
            let t = (s + 1) % segments as usize;
            let (a, b, c, d) = (ids[p][s], ids[p][t], ids[p + 1][t], ids[p + 1][s]);
            for triangle in [[a, b, c], [a, c, d]] {
                if triangle[0] != triangle[1]
                    && triangle[1] != triangle[2]
                    && triangle[0] != triangle[2]
                {
                    indices.push(triangle);
                }
            }
        }
    }
    wound_outward(MeshData { vertices, indices })
}

/// A torus about the y axis: tube of radius `tube` around a circle of radius `ring`, `n`
/// quads around the ring and `m` around the tube (2·n·m triangles).
pub(crate) fn torus(ring: f32, tube: f32, n: u32, m: u32) -> MeshData {
    let mut vertices = Vec::new();
    for i in 0..n {
        let u = i as f32 / n as f32 * TAU;
        for j in 0..m {
            let w = j as f32 / m as f32 * TAU;
            let r = ring + tube * w.cos();
            vertices.push([r * u.cos(), tube * w.sin(), r * u.sin()]);
        }
    }
    let id = |i: u32, j: u32| (i % n) * m + j % m;
    let mut indices = Vec::new();
    for i in 0..n {
        for j in 0..m {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            indices.push([a, b, c]);
            indices.push([a, c, d]);
        }
    }
    wound_outward(MeshData { vertices, indices })
}

/// A mug standing on y = 0: a cup of outer radius `radius`, wall and floor `wall` thick and
/// `height` tall, open at the top (about 2,000 triangles with `segments` = 48), and a handle:
/// half a torus on the +x side whose ends sink into the wall. One mesh of two closed parts.
pub(crate) fn mug(radius: f32, height: f32, wall: f32, segments: u32) -> MeshData {
    let inner = radius - wall;
    let profile = [
        [0.0, 0.0],
        [radius, 0.0],
        [radius, height],
        [inner, height],
        [inner, wall],
        [0.0, wall],
    ];
    let mut cup = revolve(&profile, segments);
    // The handle: a half torus in the x–y plane, centred on the wall at mid height.
    let (ring, tube) = (0.3 * height, 0.12 * height);
    let (n, m) = (12u32, 10u32);
    let mut vertices = Vec::new();
    for i in 0..=n {
        let u = -PI / 2.0 + i as f32 / n as f32 * PI;
        for j in 0..m {
            let w = j as f32 / m as f32 * TAU;
            let r = ring + tube * w.cos();
            vertices.push([
                radius - 0.5 * wall + r * u.cos(),
                0.5 * height + r * u.sin(),
                tube * w.sin(),
            ]);
        }
    }
    let mut indices: Vec<[u32; 3]> = Vec::new();
    for i in 0..n {
        for j in 0..m {
            let id = |i: u32, j: u32| i * m + j % m;
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            indices.push([a, b, c]);
            indices.push([a, c, d]);
        }
    }
    // Caps at both ends: fans around the end rings' centres.
    for end in [0, n] {
        let centre = vertices.len() as u32;
        let u = -PI / 2.0 + end as f32 / n as f32 * PI;
        vertices.push([
            radius - 0.5 * wall + ring * u.cos(),
            0.5 * height + ring * u.sin(),
            0.0,
        ]);
        for j in 0..m {
            let (a, b) = (end * m + j, end * m + (j + 1) % m);
            indices.push(if end == 0 {
                [centre, b, a]
            } else {
                [centre, a, b]
            });
        }
    }
    let handle = wound_outward(MeshData { vertices, indices });
    let offset = cup.vertices.len() as u32;
    cup.vertices.extend(handle.vertices);
    cup.indices
        .extend(handle.indices.iter().map(|t| t.map(|i| i + offset)));
    cup
}

/// Axis-aligned boxes as one mesh (each closed, wound outward): `(centre, half extents)`.
pub(crate) fn boxes(parts: &[([f32; 3], [f32; 3])]) -> MeshData {
    let mut mesh = MeshData::default();
    for (centre, h) in parts {
        let first = mesh.vertices.len() as u32;
        for i in 0..8 {
            let sign = |bit: u32, k: usize| if i & bit == 0 { -h[k] } else { h[k] };
            mesh.vertices.push([
                centre[0] + sign(1, 0),
                centre[1] + sign(2, 1),
                centre[2] + sign(4, 2),
            ]);
        }
        for [a, b, c, d] in [
            [0, 2, 3, 1],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 4, 6, 2],
            [1, 3, 7, 5],
        ] {
            mesh.indices.push([first + a, first + b, first + c]);
            mesh.indices.push([first + a, first + c, first + d]);
        }
    }
    mesh
}

fn trimesh(mesh: &MeshData) -> ShapeDesc {
    ShapeDesc::trimesh(mesh.vertices.clone(), mesh.indices.clone())
}

/// A scene with a ground box whose top is at y = 0 and `bodies` after it (default preset).
fn scene_on_ground(bodies: Vec<BodyDesc>) -> Scene {
    let mut scene = Scene::default();
    scene.bodies.push(BodyDesc::new(
        BodyKind::Static,
        ShapeDesc::Cuboid {
            half_extents: [2.0, 0.5, 2.0],
        },
        [0.0, -0.5, 0.0],
    ));
    scene.bodies.extend(bodies);
    scene
}

fn run(world: &mut World, seconds: f32) {
    let steps = (seconds / world.dt()).round() as usize;
    for _ in 0..steps {
        world.step().unwrap();
    }
}

/// The body's up axis (its local y) in the world.
fn up(world: &World, body: usize) -> Vec3 {
    world.poses()[body].rotation * Vec3::Y
}

/// A torus lying flat, dropped over a peg, threads onto it and comes to rest on the ground
/// around it: its hole (inner radius 9 cm) around the peg (radius 2 cm), lying flat and at
/// rest. The ring's centre of mass lies in its hole, next to the peg: continuous collision's
/// core sphere of a body in contact must sit inside the ring's parts, not there, or the peg
/// would hold the tipping ring still in mid-air.
#[test]
fn a_torus_dropped_over_a_peg_threads_onto_it() {
    let (ring, tube) = (0.12, 0.03);
    let peg = BodyDesc::new(
        BodyKind::Static,
        ShapeDesc::Cylinder {
            half_height: 0.15,
            radius: 0.02,
        },
        [0.0, 0.15, 0.0],
    );
    let ring_body = BodyDesc::new(
        BodyKind::Dynamic,
        trimesh(&torus(ring, tube, 48, 16)),
        [0.01, 0.5, 0.0],
    );
    let mut world = World::from_scene(&scene_on_ground(vec![peg, ring_body])).unwrap();
    run(&mut world, 3.0);
    let centre = world.poses()[2].translation;
    let off_axis = Vec3::new(centre.x, 0.0, centre.z).length();
    assert!(
        off_axis < ring - tube - 0.02 + 0.005,
        "the ring's centre is {off_axis} m off the peg"
    );
    assert!(
        (centre.y - tube).abs() < 0.01,
        "the ring rests at y = {} (on the ground: {tube})",
        centre.y
    );
    assert!(
        world.linear_velocities()[2].length() < 0.05,
        "the ring still moves"
    );
    let tilt = up(&world, 2).angle_between(Vec3::Y).to_degrees();
    assert!(tilt < 2.0, "the ring rests tilted by {tilt}°");
}

/// A ball dropped into a mug standing on the ground stays inside it, and the mug stays upright.
#[test]
fn a_ball_dropped_into_a_mug_stays_inside_and_the_mug_does_not_tip() {
    let (radius, height, wall) = (0.045, 0.1, 0.006);
    let mug_body = BodyDesc::new(
        BodyKind::Dynamic,
        trimesh(&mug(radius, height, wall, 48)),
        [0.0, 0.0, 0.0],
    );
    let ball = BodyDesc::new(
        BodyKind::Dynamic,
        ShapeDesc::Sphere { radius: 0.015 },
        [0.005, 0.25, 0.0],
    );
    let mut world = World::from_scene(&scene_on_ground(vec![mug_body, ball])).unwrap();
    run(&mut world, 2.0);
    let mug_pose = world.poses()[1];
    let ball_in_mug = mug_pose.inverse_transform_point(world.poses()[2].translation);
    let off_axis = Vec3::new(ball_in_mug.x, 0.0, ball_in_mug.z).length();
    assert!(
        off_axis < radius - wall,
        "the ball is {off_axis} m off the mug's axis"
    );
    assert!(
        ball_in_mug.y > wall && ball_in_mug.y < height,
        "the ball is at height {} in the mug",
        ball_in_mug.y
    );
    assert!(
        up(&world, 1).y > 0.99,
        "the mug tipped: its up axis is {}",
        up(&world, 1)
    );
}

/// A bowl resting on the ground catches 20 balls dropped into it and holds them all.
#[test]
fn a_bowl_catches_and_holds_twenty_balls() {
    // A hemispherical shell of outer radius 0.2 m, 1.5 cm thick, with a flat foot, rim up.
    let (outer, thickness) = (0.2f32, 0.015f32);
    let mut profile = vec![[0.0, 0.0]];
    for k in 0..=12 {
        let angle = k as f32 / 12.0 * PI / 2.0;
        profile.push([outer * angle.sin().max(0.05), outer * (1.0 - angle.cos())]);
    }
    for k in (0..=12).rev() {
        let angle = k as f32 / 12.0 * PI / 2.0;
        let inner = outer - thickness;
        profile.push([
            inner * angle.sin().max(0.05),
            thickness + outer - inner * angle.cos(),
        ]);
    }
    profile.push([0.0, thickness + outer - (outer - thickness)]);
    profile.dedup();
    let bowl = BodyDesc::new(
        BodyKind::Dynamic,
        trimesh(&revolve(&profile, 48)),
        [0.0, 0.0, 0.0],
    );
    let mut bodies = vec![bowl];
    for k in 0..20 {
        let angle = k as f32 * 2.4;
        let r = 0.02 + 0.006 * k as f32;
        bodies.push(BodyDesc::new(
            BodyKind::Dynamic,
            ShapeDesc::Sphere { radius: 0.025 },
            [r * angle.cos(), 0.35 + 0.06 * k as f32, r * angle.sin()],
        ));
    }
    let mut world = World::from_scene(&scene_on_ground(bodies)).unwrap();
    run(&mut world, 4.0);
    let bowl_pose = world.poses()[1];
    for k in 0..20 {
        let p = bowl_pose.inverse_transform_point(world.poses()[2 + k].translation);
        let off_axis = Vec3::new(p.x, 0.0, p.z).length();
        assert!(
            off_axis < outer && p.y > thickness && p.y < outer + 0.1,
            "ball {k} is at {p} in the bowl's frame"
        );
    }
    assert!(
        up(&world, 1).y > 0.98,
        "the bowl tipped: its up axis is {}",
        up(&world, 1)
    );
}

/// A chair of one mesh (four legs and a seat) dropped flat lands and rests on its four legs:
/// the ground touches each leg, and the seat is level.
#[test]
fn a_chair_lands_and_rests_on_its_four_legs() {
    let (leg, seat_half, leg_length) = (0.02f32, 0.2f32, 0.4f32);
    let mut parts = vec![([0.0, leg_length + 0.02, 0.0], [seat_half, 0.02, seat_half])];
    for (x, z) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
        let at = seat_half - leg;
        parts.push((
            [x * at, leg_length / 2.0, z * at],
            [leg, leg_length / 2.0, leg],
        ));
    }
    let chair = BodyDesc::new(BodyKind::Dynamic, trimesh(&boxes(&parts)), [0.0, 0.1, 0.0]);
    let mut world = World::from_scene(&scene_on_ground(vec![chair])).unwrap();
    run(&mut world, 2.0);
    let pose = world.poses()[1];
    assert!(
        up(&world, 1).y > 0.9999,
        "the seat tilts: up axis {}",
        up(&world, 1)
    );
    assert!(
        pose.translation.y.abs() < 0.005,
        "the chair's feet are at y = {}",
        pose.translation.y
    );
    let (ground, chair) = (world.handle_of(0).unwrap(), world.handle_of(1).unwrap());
    let pair = world
        .contact_pair(ground, chair)
        .expect("the chair touches the ground");
    let mut legs_touching = [false; 4];
    for point in pair.points().filter(|p| p.normal_impulse > 0.0) {
        let local = pose.inverse_transform_point(point.position);
        for (k, (x, z)) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
            .iter()
            .enumerate()
        {
            let at = seat_half - leg;
            if (local.x - x * at).abs() <= leg + 1e-3 && (local.z - z * at).abs() <= leg + 1e-3 {
                legs_touching[k] = true;
            }
        }
    }
    assert_eq!(legs_touching, [true; 4], "legs pushing on the ground");
    // Each point names the part of the chair it is on (the ground is no compound): the named
    // convex part holds it, to within the contact's millimetre.
    let compound = world.shapes()[1]
        .as_compound()
        .expect("a moving mesh is a compound of its parts");
    for point in pair.points().filter(|p| p.normal_impulse > 0.0) {
        assert_eq!(point.part1, None);
        let k = point.part2.expect("the point names the chair's part") as usize;
        let (part_pose, part) = &compound.shapes()[k];
        let local = pose.inverse_transform_point(point.position);
        let distance = part.distance_to_point(part_pose, local, true);
        assert!(distance < 2e-3, "part {k} is {distance} m from its point");
    }
}

/// The island report names the part of a compound its deepest contact is on: a chair (one
/// mesh: a seat and four legs) resting on the ground, whose deepest point is on one of the four
/// legs (a part reaching down to the ground), never on the seat 40 cm above it.
#[test]
fn an_island_report_names_the_part_of_a_compound_its_deepest_contact_is_on() {
    let (leg, seat_half, leg_length) = (0.02f32, 0.2f32, 0.4f32);
    let mut parts = vec![([0.0, leg_length + 0.02, 0.0], [seat_half, 0.02, seat_half])];
    for (x, z) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
        let at = seat_half - leg;
        parts.push((
            [x * at, leg_length / 2.0, z * at],
            [leg, leg_length / 2.0, leg],
        ));
    }
    let chair = BodyDesc::new(BodyKind::Dynamic, trimesh(&boxes(&parts)), [0.0, 0.1, 0.0]);
    let mut world = World::from_scene(&scene_on_ground(vec![chair])).unwrap();
    run(&mut world, 0.5);
    let islands = &world.diagnostics().islands;
    assert_eq!(islands.len(), 1, "one island: the chair on the ground");
    let deepest = islands[0]
        .deepest_contact
        .expect("the island's report names its deepest contact");
    assert_eq!((deepest.body1, deepest.body2), (0, 1));
    assert_eq!(deepest.part1, None, "the ground is no compound");
    let k = deepest.part2.expect("the report names the chair's part") as usize;
    let compound = world.shapes()[1]
        .as_compound()
        .expect("a moving mesh is a compound of its parts");
    let lowest = |(part_pose, part): &(_, impulse::parry3d::shape::SharedShape)| {
        part.compute_aabb(&(world.poses()[1] * *part_pose)).mins.y
    };
    // The check can tell parts apart: the seat's parts end 40 cm above the ground.
    assert!(compound.shapes().iter().any(|part| lowest(part) > 0.3));
    let lowest = lowest(&compound.shapes()[k]);
    assert!(
        lowest.abs() < 5e-3,
        "part {k}, named by the report, reaches down to y = {lowest} m, not to the ground"
    );
}

/// A hollow closed box (outer surface wound outward, inner surface inward, walls 1 mm thick)
/// gets the mass, centre of mass and inertia of its walls, not of the solid its convex parts
/// fill: within 1 % of the closed form of a thin-walled box (six plates of surface density
/// ρ·t).
#[test]
fn a_hollow_closed_box_has_the_inertia_of_its_walls() {
    let (a, b, c) = (0.4f32, 0.3f32, 0.2f32);
    let t = 0.001f32;
    let centre = [0.05, 0.1, -0.02];
    let outer = boxes(&[(centre, [a / 2.0, b / 2.0, c / 2.0])]);
    let mut inner = boxes(&[(centre, [a / 2.0 - t, b / 2.0 - t, c / 2.0 - t])]);
    for triangle in &mut inner.indices {
        triangle.swap(1, 2);
    }
    let mut mesh = outer;
    let offset = mesh.vertices.len() as u32;
    mesh.vertices.extend(inner.vertices);
    mesh.indices
        .extend(inner.indices.iter().map(|t| t.map(|i| i + offset)));
    let density = 1000.0;
    let mut scene = Scene::default();
    scene
        .bodies
        .push(BodyDesc::new(BodyKind::Dynamic, trimesh(&mesh), [0.0; 3]));
    let world = World::from_scene(&scene).unwrap();
    let body = world.body(world.handle_of(0).unwrap()).unwrap();

    // Thin-walled closed form: plates of mass σ·area (σ = ρ·t) on the walls' mid-surface,
    // a box of sides a − t, b − t, c − t.
    let sigma = density * t;
    let (a, b, c) = (a - t, b - t, c - t);
    let (m_x, m_y, m_z) = (sigma * b * c, sigma * a * c, sigma * a * b);
    let mass = 2.0 * (m_x + m_y + m_z);
    // About x: the ±x plates turn about their own centre line, the ±y and ±z plates are
    // also offset by b/2 and c/2.
    let i_x = 2.0
        * (m_x * (b * b + c * c) / 12.0
            + m_y * (c * c / 12.0 + b * b / 4.0)
            + m_z * (b * b / 12.0 + c * c / 4.0));
    let i_y = 2.0
        * (m_y * (a * a + c * c) / 12.0
            + m_x * (c * c / 12.0 + a * a / 4.0)
            + m_z * (a * a / 12.0 + c * c / 4.0));
    let i_z = 2.0
        * (m_z * (a * a + b * b) / 12.0
            + m_x * (b * b / 12.0 + a * a / 4.0)
            + m_y * (a * a / 12.0 + b * b / 4.0));
    let within = |got: f32, want: f32| (got - want).abs() <= 0.01 * want;
    assert!(
        within(body.mass(), mass),
        "mass {} against {mass}",
        body.mass()
    );
    // The body frame is the world frame: the centre of mass in either is the same point.
    let com = body.center_of_mass();
    assert!(
        (com - Vec3::from(centre)).length() < 1e-4,
        "centre of mass {com}"
    );
    let inertia = body.local_inverse_inertia().inverse();
    let want = Mat3::from_diagonal(Vec3::new(i_x, i_y, i_z));
    for k in 0..3 {
        assert!(
            within(inertia.col(k)[k], want.col(k)[k]),
            "inertia {inertia} against {want}"
        );
        for l in 0..3 {
            if k != l {
                assert!(
                    inertia.col(k)[l].abs() < 1e-3 * want.col(k)[k],
                    "inertia {inertia}"
                );
            }
        }
    }
}

/// An open mesh (a box without its lid) still moves, with the parts' mass properties and a
/// note saying so; a static body's mesh is not decomposed and refuses `decomposition`.
#[test]
fn an_open_mesh_gets_a_note_and_a_static_mesh_refuses_decomposition() {
    let mut mesh = boxes(&[([0.0; 3], [0.1, 0.1, 0.1])]);
    mesh.indices.retain(|t| !t.iter().all(|&i| i & 2 != 0));
    let mut scene = scene_on_ground(vec![BodyDesc::new(
        BodyKind::Dynamic,
        trimesh(&mesh),
        [0.0, 0.2, 0.0],
    )]);
    let notes = impulse::scene::decomposition_notes(&scene);
    assert_eq!(notes.len(), 1, "{notes:?}");
    assert!(
        notes[0].contains("bodies[1]") && notes[0].contains("not closed"),
        "{}",
        notes[0]
    );
    World::from_scene(&scene).unwrap();
    scene.bodies[1].kind = BodyKind::Static;
    if let ShapeDesc::Trimesh { decomposition, .. } = &mut scene.bodies[1].shape {
        *decomposition = Some(Default::default());
    }
    let error = impulse::scene::validate(&scene).unwrap_err().to_string();
    assert!(error.contains("bodies[1].shape.decomposition"), "{error}");
}

/// A snapshot keeps a decomposed body's parts and mass properties: the restored world steps
/// on to the bit as the original.
#[test]
fn a_snapshot_keeps_the_parts_and_continues_to_the_bit() {
    let torus_body = BodyDesc::new(
        BodyKind::Dynamic,
        trimesh(&torus(0.1, 0.03, 24, 8)),
        [0.0, 0.3, 0.0],
    );
    let mut world = World::from_scene(&scene_on_ground(vec![torus_body])).unwrap();
    run(&mut world, 0.25);
    let bytes = world.snapshot().unwrap().to_bytes().unwrap();
    let mut restored = World::from_snapshot(WorldSnapshot::from_bytes(&bytes).unwrap()).unwrap();
    assert!(
        restored.shapes()[1].as_compound().is_some(),
        "the restored shape is the compound"
    );
    run(&mut world, 0.5);
    run(&mut restored, 0.5);
    assert_eq!(world.poses()[1], restored.poses()[1]);
}

/// The figures of docs/benchmarks.md, "Moving meshes" (timings: printed, not checked):
/// `cargo test -p impulse --release --test integration concave::decomposition_costs -- --ignored --nocapture`.
#[test]
#[ignore = "timings for docs/benchmarks.md; run explicitly in release"]
fn decomposition_costs() {
    use impulse::scene::{DecompositionDesc, decompose_mesh, load_mesh_file};
    use std::time::Instant;
    let scenes = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let mug_mesh = load_mesh_file(&scenes.join("mug.obj")).unwrap();
    let torus_mesh = torus(0.3, 0.08, 100, 50);
    for (name, mesh) in [("mug", &mug_mesh), ("torus", &torus_mesh)] {
        let start = Instant::now();
        let decomposed = decompose_mesh(mesh, &DecompositionDesc::default()).unwrap();
        let first = start.elapsed();
        let start = Instant::now();
        decompose_mesh(mesh, &DecompositionDesc::default()).unwrap();
        let again = start.elapsed();
        println!(
            "{name}: {} triangles, {} parts, decomposed in {:.3} s, again (cache) in {:.3} ms",
            mesh.indices.len(),
            decomposed.parts.len(),
            first.as_secs_f64(),
            again.as_secs_f64() * 1e3
        );
    }
    // Step cost per body: 64 mugs dropped in a grid, as decomposed meshes and as hulls.
    let hull = ShapeDesc::ConvexHull {
        points: mug_mesh.vertices.clone(),
    };
    for (name, shape) in [
        ("decomposed mug", trimesh(&mug_mesh)),
        ("mug's convex hull", hull),
    ] {
        let bodies = (0..64)
            .map(|k| {
                let (row, column) = (k / 8, k % 8);
                let position = [
                    (column as f32 - 3.5) * 0.2,
                    0.1 + 0.02 * k as f32,
                    (row as f32 - 3.5) * 0.2,
                ];
                BodyDesc::new(BodyKind::Dynamic, shape.clone(), position)
            })
            .collect();
        let mut world = World::from_scene(&scene_on_ground(bodies)).unwrap();
        let start = Instant::now();
        run(&mut world, 2.0);
        let per_step = start.elapsed().as_secs_f64() / 120.0;
        println!(
            "{name}: {:.1} µs per body per step (64 bodies, 120 steps, default preset)",
            per_step / 64.0 * 1e6
        );
    }
}
