//! Determinism: the same scene stepped the same number of times ends in the same state, to the
//! bit, on 1, 2 and 4 threads and from one run to the next (same binary, same CPU features).
//! The state is hashed (FNV-1a over every body's pose and velocities and every contact point's
//! impulses and separation, as f32 bits). `tests/snapshot.rs` checks that a world restored
//! from a snapshot continues to the same state.

use impulse::scene::builtin::builtin_scene;
use impulse::scene::json::load_scene_file;
use impulse::{Scene, World};

fn hash_state(world: &World) -> u64 {
    let mut hash = 0xcbf2_9ce4_8422_2325u64;
    let mut add = |x: f32| {
        for byte in x.to_bits().to_le_bytes() {
            hash ^= u64::from(byte);
            hash = hash.wrapping_mul(0x0100_0000_01b3);
        }
    };
    let b = &world.bodies;
    for i in 0..b.len() {
        let (t, q) = (b.pose[i].translation, b.pose[i].rotation);
        for x in [t.x, t.y, t.z, q.x, q.y, q.z, q.w] {
            add(x);
        }
        for v in [b.linear_velocity[i], b.angular_velocity[i]] {
            for x in v.to_array() {
                add(x);
            }
        }
    }
    for pair in world.contact_pairs() {
        for point in pair.points() {
            add(point.normal_impulse);
            for x in point.friction_impulse.to_array() {
                add(x);
            }
            add(point.separation);
        }
    }
    hash
}

/// `steps` steps of `scene` (sleeping off) on a pool of `threads` threads; the final state's
/// hash.
fn run(scene: &Scene, steps: u32, threads: usize) -> u64 {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| {
        let mut scene = scene.clone();
        scene.solver.sleep = false;
        let mut world = World::from_scene(&scene).unwrap();
        for _ in 0..steps {
            world.step().unwrap();
        }
        hash_state(&world)
    })
}

fn same_everywhere(scene: &Scene, steps: u32) {
    let reference = run(scene, steps, 1);
    for threads in [1, 2, 4] {
        assert_eq!(
            run(scene, steps, threads),
            reference,
            "{}: {threads} threads differ from one",
            scene.name
        );
    }
}

#[test]
fn pyramid20_is_the_same_on_any_thread_count_and_run() {
    same_everywhere(&builtin_scene("pyramid20").unwrap(), 120);
}

#[test]
fn balls4096_is_the_same_on_any_thread_count_and_run() {
    same_everywhere(&builtin_scene("balls4096").unwrap(), 90);
}

#[test]
fn a_scene_of_every_shape_is_the_same_on_any_thread_count_and_run() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/shapes.json");
    let scene = load_scene_file(std::path::Path::new(path)).unwrap();
    same_everywhere(&scene, 180);
}
