//! A step allocates nothing once the world's buffers have grown to the scene: every work array
//! (pairs, constraints, islands, bundles, island workspaces, solver work vectors, reports) is
//! kept and reused from step to step. Counted by a global allocator that, while counting, takes
//! a backtrace of every allocation on any thread.
//!
//! The one exception is Parry: when a box pair's relative pose has moved too far for
//! `ContactManifold::try_update_contacts`, its cuboid-cuboid manifold generator clones the old
//! points to match them with the new ones. Those allocations are counted apart and only
//! reported.

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, Ordering};

use impulse::scene::builtin_scene;
use impulse::{SolverSettings, World};

struct Counting;

static COUNTING: AtomicBool = AtomicBool::new(false);

/// (allocations inside Parry, allocations elsewhere, the first backtrace of one elsewhere).
static COUNTS: Mutex<(u64, u64, Option<String>)> = Mutex::new((0, 0, None));

thread_local! {
    /// Set while this thread takes a backtrace, whose own allocations are not counted.
    static INSIDE: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

fn note() {
    if !COUNTING.load(Ordering::Relaxed) {
        return;
    }
    let _ = INSIDE.try_with(|inside| {
        if inside.replace(true) {
            return;
        }
        let trace = std::backtrace::Backtrace::force_capture().to_string();
        if let Ok(mut counts) = COUNTS.lock() {
            if trace.contains("parry3d::") {
                counts.0 += 1;
            } else {
                counts.1 += 1;
                counts.2.get_or_insert(trace);
            }
        }
        inside.set(false);
    });
}

// SAFETY: forwards every call to the system allocator unchanged.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        note();
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        note();
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        note();
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// `scene` with the settings of `preset`, sleeping off, stepped to rest on `threads` threads;
/// then 30 more steps counted. Returns (allocations in Parry, elsewhere, a trace of one).
fn count(scene: &str, preset: &str, threads: usize) -> (u64, u64, Option<String>) {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("pool");
    pool.install(|| {
        let mut scene = builtin_scene(scene).expect("built-in scene");
        scene.solver = SolverSettings::preset(preset).expect("preset");
        scene.solver.sleep = None;
        let mut world = World::from_scene(&scene).expect("world");
        for _ in 0..120 {
            world.step().expect("step");
        }
        *COUNTS.lock().unwrap() = (0, 0, None);
        COUNTING.store(true, Ordering::SeqCst);
        for _ in 0..30 {
            world.step().expect("step");
        }
        COUNTING.store(false, Ordering::SeqCst);
        COUNTS.lock().unwrap().clone()
    })
}

#[test]
fn resting_piles_step_without_allocating() {
    for (scene, preset, threads) in [
        ("pyramid20", "default", 1),
        ("pyramid20", "reference", 1),
        ("stack30", "fast", 1),
        ("pyramid3d10", "default", 1),
        // One island of 8,651 points: its colours, packing and passes go on both threads.
        ("pyramid3d10", "default", 2),
        ("pyramid3d10", "reference", 2),
    ] {
        let (parry, ours, trace) = count(scene, preset, threads);
        assert_eq!(
            ours,
            0,
            "{scene}, {preset}, {threads} threads: {ours} allocations in 30 steps outside \
             Parry ({parry} inside it); the first:\n{}",
            trace.unwrap_or_default()
        );
    }
}
