//! World snapshots: a world restored from a snapshot steps on to the bit as the world it was
//! taken from (pyramid20, balls4096, a scene of every shape, a sleeping pile woken by a
//! projectile, the `reference` preset, edits between steps, joints), on 1 and 2 threads either
//! side of the snapshot; a damaged or invalid snapshot gives a typed error, never a panic; a
//! snapshot of the format before joints still reads.
//!
//! "To the bit" is checked twice: the uninterrupted world's and the restored world's own
//! snapshots after the same steps are the same bytes (every stored field: poses, velocities,
//! sleep timers, manifolds with their points, feature ids and warm-start impulses, broad-phase
//! boxes, energy reference), and a hash of every body's pose and velocities and every contact
//! point's impulses read through the public API agrees.

use crate::common::hash_state;
use impulse::glam::Vec3;
use impulse::report::{OLDEST_SNAPSHOT_FORMAT_VERSION, SNAPSHOT_FORMAT_VERSION};
use impulse::scene::builtin_scene;
use impulse::scene::load_scene_file;
use impulse::{
    BodyBuilder, JointBuilder, Scene, SharedShape, SnapshotError, SolverSettings, World,
    WorldSnapshot,
};

/// Runs `f` on a pool of `threads` threads (1: everything on the calling thread).
fn on_threads<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(f)
}

fn steps(world: &mut World, n: u32, threads: usize) {
    world.set_parallel(threads > 1);
    on_threads(threads, || {
        for _ in 0..n {
            world.step().unwrap();
        }
    });
}

/// The state after `before + after` steps of `world` in one go, against `before` steps on
/// `threads_before` threads, a snapshot through its bytes, and `after` steps of the restored
/// world on `threads_after` threads: the restored world's snapshot bytes and hash must be the
/// uninterrupted ones.
fn resumes_bit_for_bit(
    name: &str,
    make: impl Fn() -> World,
    before: u32,
    after: u32,
    threads: &[(usize, usize)],
) {
    let mut whole = make();
    steps(&mut whole, before + after, 1);
    let expected_bytes = whole.snapshot().unwrap().to_bytes().unwrap();
    let expected_hash = hash_state(&whole);
    for &(threads_before, threads_after) in threads {
        let mut first = make();
        steps(&mut first, before, threads_before);
        let bytes = first.snapshot().unwrap().to_bytes().unwrap();
        let mut resumed = World::from_snapshot(WorldSnapshot::from_bytes(&bytes).unwrap()).unwrap();
        assert_eq!(resumed.step_count(), first.step_count());
        steps(&mut resumed, after, threads_after);
        assert_eq!(
            hash_state(&resumed),
            expected_hash,
            "{name}: {before} steps on {threads_before} thread(s), a snapshot, {after} on \
             {threads_after}: the bodies or contacts differ from {} steps in one go",
            before + after
        );
        // Parry's work spaces of composite shapes hold hash maps, whose serialised order is
        // not fixed: for those the stepped state (above) is what must agree.
        let composite = resumed
            .shapes()
            .iter()
            .any(|s| s.as_composite_shape().is_some());
        let resumed_bytes = resumed.snapshot().unwrap().to_bytes().unwrap();
        assert!(
            composite || resumed_bytes == expected_bytes,
            "{name}: {threads_before}/{threads_after} threads: the stored state differs"
        );
    }
}

fn world_of(scene: &Scene) -> World {
    World::from_scene(scene).unwrap()
}

fn file_scene(name: &str) -> Scene {
    let path = format!("{}/../../scenes/{name}.json", env!("CARGO_MANIFEST_DIR"));
    load_scene_file(std::path::Path::new(&path)).unwrap()
}

const BOTH_WAYS: [(usize, usize); 2] = [(1, 2), (2, 1)];

#[test]
fn pyramid20_resumes_bit_for_bit_on_one_and_two_threads() {
    let mut scene = builtin_scene("pyramid20").unwrap();
    scene.solver.sleep = None;
    resumes_bit_for_bit("pyramid20", || world_of(&scene), 60, 60, &BOTH_WAYS);
}

#[test]
fn balls4096_resumes_bit_for_bit_on_one_and_two_threads() {
    let mut scene = builtin_scene("balls4096").unwrap();
    scene.solver.sleep = None;
    resumes_bit_for_bit("balls4096", || world_of(&scene), 60, 30, &BOTH_WAYS);
}

#[test]
fn a_scene_of_every_shape_resumes_bit_for_bit() {
    let scene = file_scene("shapes");
    resumes_bit_for_bit("shapes", || world_of(&scene), 90, 60, &BOTH_WAYS);
}

/// Kinematic bodies: a paddle at a constant velocity and a keyframed lift, snapshotted in the
/// middle of the lift's keyframes, so the world's clock and the keyframes cross the snapshot.
#[test]
fn kinematic_bodies_resume_bit_for_bit() {
    let scene = file_scene("kinematic");
    resumes_bit_for_bit("kinematic", || world_of(&scene), 75, 90, &BOTH_WAYS);
}

/// Composite shapes: a pile on a triangle-mesh terrain and compounds on a height field, whose
/// pairs keep Parry's per-pair work spaces and several manifolds each.
#[test]
fn meshes_height_fields_and_compounds_resume_bit_for_bit() {
    for name in ["mesh_terrain", "compound"] {
        let mut scene = file_scene(name);
        scene.solver.sleep = None;
        resumes_bit_for_bit(name, || world_of(&scene), 60, 40, &BOTH_WAYS);
    }
}

/// Sleep on: pyramid20 falls asleep within 30 steps, a ball dropped from 9 m above its top
/// lands on it after the snapshot and wakes it, so sleep flags and timers and the manifolds
/// kept by sleeping pairs cross the snapshot.
#[test]
fn a_sleeping_pyramid_woken_by_a_falling_ball_resumes_bit_for_bit() {
    let make = || {
        let mut world = world_of(&builtin_scene("pyramid20").unwrap());
        let top = impulse::metrics::top_body(&world, world.poses()).unwrap();
        let top = world.poses()[top].translation;
        world
            .insert(
                BodyBuilder::dynamic(SharedShape::ball(0.4))
                    .translation(top + Vec3::new(0.1, 9.0, 0.0))
                    .density(3000.0),
            )
            .unwrap();
        world
    };
    let asleep = |world: &World| world.asleep().iter().filter(|&&a| a).count();
    let mut probe = make();
    steps(&mut probe, 50, 1);
    let sleeping = asleep(&probe);
    assert!(
        sleeping > 100,
        "the pyramid sleeps at the snapshot ({sleeping} bodies)"
    );
    let mut woken = false;
    for _ in 0..60 {
        steps(&mut probe, 1, 1);
        woken |= asleep(&probe) < sleeping;
    }
    assert!(woken, "the ball wakes the pyramid after the snapshot");
    resumes_bit_for_bit("pyramid20 and a ball", make, 50, 60, &BOTH_WAYS);
}

/// The `reference` preset (NNCG escalating to the exact path) and restitution.
#[test]
fn the_reference_preset_with_restitution_resumes_bit_for_bit() {
    let mut scene = builtin_scene("pyramid20").unwrap();
    scene.solver = SolverSettings::reference();
    for material in scene.materials.values_mut() {
        material.restitution = 0.3;
    }
    resumes_bit_for_bit(
        "pyramid20 reference",
        || world_of(&scene),
        40,
        40,
        &[(1, 1)],
    );
}

/// Edits between steps cross the snapshot: a removed body (its slot on the free list), a new
/// body reusing the slot (the next generation), a force waiting for the next step, a changed
/// velocity. Old handles stay refused and new ones valid after the restore.
#[test]
fn edits_between_steps_resume_bit_for_bit() {
    let edited = || {
        let mut world = World::from_scene(&builtin_scene("pyramid20").unwrap()).unwrap();
        steps(&mut world, 20, 1);
        let handles: Vec<_> = (0..world.body_count())
            .map(|i| world.handle_of(i).unwrap())
            .collect();
        world.remove(handles[5]).unwrap();
        let ball = world
            .insert(
                BodyBuilder::dynamic(SharedShape::ball(0.3))
                    .translation(Vec3::new(0.0, 8.0, 0.0))
                    .restitution(0.5)
                    .user_data(u128::MAX - 7)
                    .name("dropped"),
            )
            .unwrap();
        assert_eq!(ball.index(), handles[5].index());
        assert_eq!(ball.generation(), 1);
        steps(&mut world, 10, 1);
        world.apply_force(ball, Vec3::new(30.0, 0.0, 0.0)).unwrap();
        (world, handles[5], ball)
    };
    let (world, removed, ball) = edited();
    let restored = World::from_snapshot(
        WorldSnapshot::from_bytes(&world.snapshot().unwrap().to_bytes().unwrap()).unwrap(),
    )
    .unwrap();
    assert!(restored.body(removed).is_none());
    let body = restored.body(ball).unwrap();
    assert_eq!(body.name(), Some("dropped"));
    assert_eq!(body.user_data(), u128::MAX - 7);
    resumes_bit_for_bit("edited pyramid20", || edited().0, 0, 40, &BOTH_WAYS);
}

/// A snapshot taken before the first step (no broad-phase tree, no pairs) and one of an empty
/// world both resume.
#[test]
fn a_fresh_world_and_an_empty_world_resume() {
    let scene = builtin_scene("pyramid20").unwrap();
    resumes_bit_for_bit("fresh pyramid20", || world_of(&scene), 0, 20, &[(1, 2)]);
    let empty = || World::new(Vec3::new(0.0, -9.81, 0.0), 0.01, SolverSettings::default()).unwrap();
    resumes_bit_for_bit("empty", empty, 3, 3, &[(1, 1)]);
}

/// serde_json writes each f32 as its shortest decimal and reads it back to the same bits, so a
/// snapshot survives JSON too (the file format is CBOR; JSON is for a reader's eyes).
#[test]
fn a_snapshot_survives_json_to_the_bit() {
    let mut world = World::from_scene(&file_scene("shapes")).unwrap();
    steps(&mut world, 60, 1);
    let snapshot = world.snapshot().unwrap();
    let text = serde_json::to_string(&snapshot).unwrap();
    let back: WorldSnapshot = serde_json::from_str(&text).unwrap();
    assert!(back.to_bytes().unwrap() == snapshot.to_bytes().unwrap());
}

fn small_world() -> World {
    let mut world = World::from_scene(&builtin_scene("pyramid20").unwrap()).unwrap();
    world.remove(world.handle_of(200).unwrap()).unwrap();
    steps(&mut world, 5, 1);
    world
}

#[test]
fn damaged_files_give_typed_errors() {
    let bytes = small_world().snapshot().unwrap().to_bytes().unwrap();
    let read = |b: &[u8]| WorldSnapshot::from_bytes(b).err().expect("an error");
    assert!(matches!(read(b""), SnapshotError::NotASnapshot));
    assert!(matches!(
        read(b"{\"name\": \"a scene\"}"),
        SnapshotError::NotASnapshot
    ));
    let cut = read(&bytes[..bytes.len() / 2]);
    assert!(
        matches!(cut, SnapshotError::Truncated { expected, found }
            if expected == bytes.len() as u64 && found == (bytes.len() / 2) as u64),
        "{cut}"
    );
    assert!(matches!(
        read(&bytes[..10]),
        SnapshotError::Truncated { .. }
    ));
    let mut flipped = bytes.clone();
    flipped[bytes.len() - 100] ^= 0x10;
    assert!(matches!(
        read(&flipped),
        SnapshotError::ChecksumMismatch { .. }
    ));
    let mut newer = bytes.clone();
    newer[16] += 1;
    let message = read(&newer).to_string();
    assert!(
        message.contains("format version 6") && message.contains("reads versions 2 to 5"),
        "{message}"
    );
    let mut longer = bytes.clone();
    longer.push(0);
    assert!(matches!(read(&longer), SnapshotError::Decode(_)));
}

/// A valid header and checksum around a payload that is not a snapshot.
#[test]
fn a_payload_that_is_not_a_snapshot_is_a_decode_error() {
    let bytes = small_world().snapshot().unwrap().to_bytes().unwrap();
    let payload = [0x83u8, 1, 2, 3]; // the CBOR array [1, 2, 3]
    let mut forged = bytes[..32].to_vec();
    forged[20..28].copy_from_slice(&(payload.len() as u64).to_le_bytes());
    forged[28..32].copy_from_slice(&crc32fast::hash(&payload).to_le_bytes());
    forged.extend_from_slice(&payload);
    let error = WorldSnapshot::from_bytes(&forged).err().unwrap();
    assert!(matches!(error, SnapshotError::Decode(_)), "{error}");
}

/// Every cut and every single-bit flip of a snapshot's bytes is an error, never a panic.
#[test]
fn no_cut_or_bit_flip_panics() {
    let mut world =
        World::new(Vec3::new(0.0, -9.81, 0.0), 0.01, SolverSettings::default()).unwrap();
    world
        .insert(BodyBuilder::fixed(SharedShape::cuboid(2.0, 0.5, 2.0)))
        .unwrap();
    world
        .insert(BodyBuilder::dynamic(SharedShape::ball(0.5)).translation(Vec3::new(0.0, 0.99, 0.0)))
        .unwrap();
    steps(&mut world, 3, 1);
    let bytes = world.snapshot().unwrap().to_bytes().unwrap();
    assert!(WorldSnapshot::from_bytes(&bytes).is_ok());
    for length in 0..bytes.len() {
        assert!(WorldSnapshot::from_bytes(&bytes[..length]).is_err());
    }
    for position in 0..bytes.len() {
        for bit in 0..8 {
            let mut flipped = bytes.clone();
            flipped[position] ^= 1 << bit;
            assert!(
                WorldSnapshot::from_bytes(&flipped).is_err(),
                "a flip of bit {bit} of byte {position} went unnoticed"
            );
        }
    }
}

/// A snapshot that decodes but describes an unsteppable world is refused, naming the fault.
#[test]
fn an_inconsistent_snapshot_is_invalid() {
    let snapshot = small_world().snapshot().unwrap();
    let value = serde_json::to_value(&snapshot).unwrap();
    let refused = |edit: &dyn Fn(&mut serde_json::Value)| {
        let mut value = value.clone();
        edit(&mut value);
        let snapshot: WorldSnapshot = serde_json::from_value(value).unwrap();
        match World::from_snapshot(snapshot) {
            Err(SnapshotError::Invalid(message)) => message,
            Err(e) => panic!("another error: {e}"),
            Ok(_) => panic!("accepted"),
        }
    };
    let message = refused(&|v| v["narrow_phase"][0]["body2"] = 5000.into());
    assert!(message.contains("contact pair 0"), "{message}");
    let message = refused(&|v| {
        v["bodies"]["friction"].as_array_mut().unwrap().pop();
    });
    assert!(message.contains("bodies.friction"), "{message}");
    let message = refused(&|v| v["bodies"]["restitution"][3] = 2.0.into());
    assert!(message.contains("body 3"), "{message}");
    // Body 1 given a shape of its own in the table, a box with a negative half extent.
    let message = refused(&|v| {
        let table = &mut v["bodies"]["shape"];
        let own = table["shapes"].as_array().unwrap().len();
        let index = table["of_body"][1].as_u64().unwrap() as usize;
        let mut shape = table["shapes"][index].clone();
        shape["Cuboid"]["half_extents"][0] = (-1.0).into();
        table["shapes"].as_array_mut().unwrap().push(shape);
        table["of_body"][1] = own.into();
    });
    assert!(message.contains("body 1: shape"), "{message}");
    // An index past the table does not decode.
    let mut past = value.clone();
    past["bodies"]["shape"]["of_body"][2] = 1000.into();
    let message = serde_json::from_value::<WorldSnapshot>(past)
        .err()
        .unwrap()
        .to_string();
    assert!(message.contains("body 2: shape index 1000"), "{message}");
    let message = refused(&|v| v["handles"]["free"] = serde_json::json!([]));
    assert!(message.contains("handle"), "{message}");
    let message = refused(&|v| v["broad_phase"]["pairs"][0] = serde_json::json!([7, 3]));
    assert!(message.contains("broad phase"), "{message}");
    let message = refused(&|v| v["settings"]["iterations"] = 0.into());
    assert!(message.contains("solver.iterations"), "{message}");
    let mut version = value.clone();
    version["format_version"] = 99.into();
    let snapshot: WorldSnapshot = serde_json::from_value(version).unwrap();
    assert!(matches!(
        World::from_snapshot(snapshot),
        Err(SnapshotError::VersionMismatch {
            found: 99,
            supported: SNAPSHOT_FORMAT_VERSION,
            ..
        })
    ));
}

/// The file functions write atomically (no temporary file is left) and read back.
#[test]
fn files_round_trip_and_a_missing_file_is_an_io_error() {
    let dir = std::env::temp_dir().join(format!("impulse-snapshot-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("world.impulse");
    let world = small_world();
    world.write_snapshot(&path).unwrap();
    let names: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names, ["world.impulse"]);
    let restored = World::read_snapshot(&path).unwrap();
    assert_eq!(hash_state(&restored), hash_state(&world));
    let missing = World::read_snapshot(&dir.join("missing.impulse"))
        .err()
        .unwrap();
    assert!(matches!(missing, SnapshotError::Io { .. }), "{missing}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Joints cross the snapshot with their warm-start impulses: the chain of 20 links swinging
/// from its start, and a world of every joint kind with a limit reached, a motor, springs and
/// a joint broken before the snapshot (its flag and the pair it no longer joins).
#[test]
fn worlds_with_joints_resume_bit_for_bit() {
    let mut scene = builtin_scene("chain20").unwrap();
    scene.solver.sleep = None;
    resumes_bit_for_bit("chain20", || world_of(&scene), 45, 45, &BOTH_WAYS);
    let mut probe = joint_zoo();
    steps(&mut probe, 30, 1);
    assert!(
        probe.joints().any(|j| j.broken()),
        "the breakable joint breaks before the snapshot"
    );
    resumes_bit_for_bit("joint zoo", joint_zoo, 30, 40, &BOTH_WAYS);
}

/// Every joint kind on small bodies over a ground: a door on a hinge with a limit it reaches,
/// a motorised wheel, a slider on a spring, a rope, a spherical pendulum, a generic joint and
/// a breakable fixed joint loaded past its threshold.
fn joint_zoo() -> World {
    let mut world = World::new(
        Vec3::new(0.0, -9.81, 0.0),
        1.0 / 60.0,
        SolverSettings {
            sleep: None,
            ..SolverSettings::default()
        },
    )
    .unwrap();
    world
        .insert(
            BodyBuilder::fixed(SharedShape::cuboid(5.0, 0.5, 5.0))
                .translation(Vec3::new(0.0, -0.5, 0.0)),
        )
        .unwrap();
    let post = world
        .insert(
            BodyBuilder::fixed(SharedShape::cuboid(0.05, 1.0, 0.05))
                .translation(Vec3::new(0.0, 1.5, 0.0)),
        )
        .unwrap();
    let body = |world: &mut World, at: Vec3| {
        world
            .insert(BodyBuilder::dynamic(SharedShape::cuboid(0.2, 0.1, 0.1)).translation(at))
            .unwrap()
    };
    let door = body(&mut world, Vec3::new(0.3, 2.0, 0.0));
    world
        .insert_joint(
            JointBuilder::revolute(post, door)
                .world_anchor(Vec3::new(0.05, 2.0, 0.0))
                .world_axis(Vec3::Z)
                .limits(-0.3, 0.3),
        )
        .unwrap();
    let wheel = body(&mut world, Vec3::new(-0.3, 2.0, 0.0));
    world
        .insert_joint(
            JointBuilder::revolute(post, wheel)
                .world_anchor(Vec3::new(-0.3, 2.0, 0.0))
                .world_axis(Vec3::X)
                .motor_velocity(3.0, 2.0),
        )
        .unwrap();
    let slider = body(&mut world, Vec3::new(0.3, 1.2, 0.0));
    world
        .insert_joint(
            JointBuilder::prismatic(post, slider)
                .world_anchor(Vec3::new(0.3, 1.2, 0.0))
                .world_axis(Vec3::Y)
                .spring(2.0, 0.3, 0.0)
                .limits(-0.5, 0.5),
        )
        .unwrap();
    let bob = body(&mut world, Vec3::new(-0.6, 1.4, 0.2));
    world
        .insert_joint(
            JointBuilder::distance(post, bob, 0.0, 0.8)
                .world_anchors(Vec3::new(0.0, 2.2, 0.0), Vec3::new(-0.6, 1.4, 0.2)),
        )
        .unwrap();
    let ball = body(&mut world, Vec3::new(0.0, 2.7, 0.5));
    world
        .insert_joint(JointBuilder::spherical(post, ball).world_anchor(Vec3::new(0.0, 2.5, 0.0)))
        .unwrap();
    let free = body(&mut world, Vec3::new(0.6, 0.6, 0.0));
    world
        .insert_joint(
            JointBuilder::generic(post, free)
                .world_anchor(Vec3::new(0.6, 0.6, 0.0))
                .dof(
                    impulse::joints::JointDof::LinearY,
                    impulse::joints::AxisMode::Free,
                )
                .dof(
                    impulse::joints::JointDof::AngularX,
                    impulse::joints::AxisMode::Limited {
                        lower: -0.2,
                        upper: 0.2,
                    },
                ),
        )
        .unwrap();
    let weak = body(&mut world, Vec3::new(-0.6, 0.6, 0.0));
    world
        .insert_joint(
            JointBuilder::fixed(post, weak)
                .world_anchor(Vec3::new(-0.6, 0.6, 0.0))
                .breakable(5.0, f32::INFINITY),
        )
        .unwrap();
    world
}

/// A checkpoint written by the format before joints (version 2: the `snapshot_reader` fuzz
/// seed of two bodies, as `impulse run --checkpoint-every` wrote it) reads as a world without
/// joints and steps; the re-taken snapshot is of the current format. A version older than
/// that is refused by name.
#[test]
fn a_snapshot_of_the_format_before_joints_reads_as_a_world_without_joints() {
    let path = format!(
        "{}/../../fuzz/seeds/snapshot_reader/boxes-file.bin",
        env!("CARGO_MANIFEST_DIR")
    );
    let seed = std::fs::read(path).unwrap();
    let file = &seed[1..]; // the fuzz target's selector byte: odd, a whole file
    assert_eq!(u32::from_le_bytes(file[16..20].try_into().unwrap()), 2);
    let mut world = World::from_snapshot(WorldSnapshot::from_bytes(file).unwrap()).unwrap();
    assert_eq!(world.joint_count(), 0);
    assert!(world.body_count() > 0);
    steps(&mut world, 10, 1);
    let again = world.snapshot().unwrap().to_bytes().unwrap();
    assert_eq!(
        u32::from_le_bytes(again[16..20].try_into().unwrap()),
        SNAPSHOT_FORMAT_VERSION
    );
    let mut older = file.to_vec();
    older[16..20].copy_from_slice(&(OLDEST_SNAPSHOT_FORMAT_VERSION - 1).to_le_bytes());
    let message = WorldSnapshot::from_bytes(&older).err().unwrap().to_string();
    assert!(
        message.contains("format version 1") && message.contains("reads versions 2 to 5"),
        "{message}"
    );
}

/// A snapshot whose joints would make the world unsteppable is refused, naming the joint.
#[test]
fn a_snapshot_with_inconsistent_joints_is_invalid() {
    let mut world = joint_zoo();
    steps(&mut world, 3, 1);
    let value = serde_json::to_value(world.snapshot().unwrap()).unwrap();
    let refused = |edit: &dyn Fn(&mut serde_json::Value)| {
        let mut value = value.clone();
        edit(&mut value);
        let snapshot: WorldSnapshot = serde_json::from_value(value).unwrap();
        match World::from_snapshot(snapshot) {
            Err(SnapshotError::Invalid(message)) => message,
            Err(e) => panic!("another error: {e}"),
            Ok(_) => panic!("accepted"),
        }
    };
    let joint = |v: &mut serde_json::Value| v["joints"]["joints"][2].clone();
    let message = refused(&|v| {
        let mut j = joint(v);
        j["body_b"] = j["body_a"].clone();
        v["joints"]["joints"][2] = j;
    });
    assert!(
        message.contains("joint 2 joins a body to itself"),
        "{message}"
    );
    let message = refused(&|v| v["joints"]["joints"][1]["impulses"][3][0] = 1e39.into());
    assert!(message.contains("joint 1: an anchor, impulse"), "{message}");
    let message = refused(&|v| {
        v["joints"]["joints"][0]["rotation_a"] = serde_json::json!([0.0, 0.0, 0.0, 3.0])
    });
    assert!(message.contains("joint 0: a frame rotation"), "{message}");
    let message = refused(&|v| v["joints"]["joints"][6]["break_force"] = (-1.0).into());
    assert!(message.contains("joint 6: break_force"), "{message}");
    let message = refused(&|v| {
        v["joints"]["joints"][0]["dofs"][3]["mode"] =
            serde_json::json!({"limited": {"lower": 1.0, "upper": -1.0}})
    });
    assert!(message.contains("joint 0: limits"), "{message}");
    let message = refused(&|v| v["joints"]["handles"]["free"] = serde_json::json!([7]));
    assert!(message.contains("free joint handle slot 7"), "{message}");
}

/// Bodies of one shape store it once: 40 bodies of one compound (a mesh's convex parts) make a
/// snapshot hardly larger than one body does, and 40 equal boxes built apart are stored once.
/// The restored world steps on to the bit.
#[test]
fn bodies_of_one_shape_store_it_once() {
    use impulse::parry3d::math::Pose;
    let parts: Vec<(Pose, SharedShape)> = (0..12)
        .map(|k| {
            let points: Vec<Vec3> = (0..24)
                .map(|j| {
                    let a = (j as f32 * 0.7 + k as f32).sin();
                    let b = (j as f32 * 1.3 - k as f32).cos();
                    Vec3::new(a, b, (a * b + j as f32 * 0.1).sin()) * 0.1
                })
                .collect();
            let at = Pose::from_translation(Vec3::new(k as f32 * 0.2, 0.0, 0.0));
            (at, SharedShape::convex_hull(&points).unwrap())
        })
        .collect();
    let compound = SharedShape::compound(parts);
    let world_of = |bodies: usize| {
        let mut world = World::new(
            Vec3::new(0.0, -9.81, 0.0),
            1.0 / 60.0,
            SolverSettings::default(),
        )
        .unwrap();
        world
            .insert(BodyBuilder::fixed(SharedShape::cuboid(20.0, 0.5, 20.0)))
            .unwrap();
        for i in 0..bodies {
            let at = Vec3::new((i % 5) as f32 * 3.0, 1.0 + (i / 5) as f32 * 1.5, 0.0);
            world
                .insert(BodyBuilder::dynamic(compound.clone()).translation(at))
                .unwrap();
            world
                .insert(
                    BodyBuilder::dynamic(SharedShape::cuboid(0.2, 0.2, 0.2))
                        .translation(at + Vec3::new(0.0, 0.0, 4.0)),
                )
                .unwrap();
        }
        world
    };
    let size = |world: &World| world.snapshot().unwrap().to_bytes().unwrap().len();
    let (one, many) = (size(&world_of(1)), size(&world_of(40)));
    let compound_bytes = {
        let mut bytes = Vec::new();
        ciborium::into_writer(&compound, &mut bytes).unwrap();
        bytes.len()
    };
    assert!(
        many - one < compound_bytes,
        "39 more bodies of a {compound_bytes}-byte compound added {} bytes",
        many - one
    );
    let mut world = world_of(40);
    steps(&mut world, 30, 1);
    let mut restored = World::from_snapshot(
        WorldSnapshot::from_bytes(&world.snapshot().unwrap().to_bytes().unwrap()).unwrap(),
    )
    .unwrap();
    steps(&mut world, 30, 1);
    steps(&mut restored, 30, 1);
    assert_eq!(world.poses(), restored.poses());
}

/// A snapshot that stores a shape per body, as format versions 2 and 3 did, reads as the
/// table does: the restored world steps on to the bit.
#[test]
fn a_snapshot_with_a_shape_per_body_reads_as_before() {
    let mut world = small_world();
    steps(&mut world, 20, 1);
    let mut value = serde_json::to_value(world.snapshot().unwrap()).unwrap();
    let table = value["bodies"]["shape"].clone();
    let per_body: Vec<serde_json::Value> = table["of_body"]
        .as_array()
        .unwrap()
        .iter()
        .map(|index| table["shapes"][index.as_u64().unwrap() as usize].clone())
        .collect();
    value["bodies"]["shape"] = per_body.into();
    let snapshot: WorldSnapshot = serde_json::from_value(value).unwrap();
    let mut restored = World::from_snapshot(snapshot).unwrap();
    steps(&mut world, 20, 1);
    steps(&mut restored, 20, 1);
    assert_eq!(world.poses(), restored.poses());
}
