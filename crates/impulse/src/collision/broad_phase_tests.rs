//! The broad phase keeps its tree between steps and stores each box fattened by
//! `CHANGE_DETECTION_SKIN`, rewriting a leaf only when its body leaves it or it has grown too
//! large. Whatever the history of moves, it must find every pair whose boxes overlap, and only
//! pairs whose boxes are within a few skins of each other.

use crate::test_support as common;

use crate::collision::broad_phase::{BroadPhase, CHANGE_DETECTION_SKIN};
use crate::{BodyDesc, BodyKind, ShapeDesc, SolverSettings, World};
use glam::Vec3;
use parry3d::bounding_volume::{Aabb, BoundingVolume};

const RADIUS: f32 = 0.5;

/// Balls on a 4 × 3 × 4 lattice 1.2 m apart (0.2 m gaps, as in the standard ball scenes).
fn lattice() -> World {
    lattice_of(4, 3, 4)
}

/// Balls on an nx × ny × nz lattice 1.2 m apart.
fn lattice_of(nx: usize, ny: usize, nz: usize) -> World {
    let mut w = World::new(Vec3::ZERO, 1.0 / 60.0, SolverSettings::default()).unwrap();
    let m = common::material(0.3);
    for i in 0..nx {
        for j in 0..ny {
            for k in 0..nz {
                let position = [1.2 * i as f32, 1.2 * j as f32, 1.2 * k as f32];
                let desc = BodyDesc::new(
                    BodyKind::Dynamic,
                    ShapeDesc::Sphere { radius: RADIUS },
                    position,
                );
                w.add_body(&desc, &m).unwrap();
            }
        }
    }
    w
}

fn boxes(w: &World, margins: &[f32]) -> Vec<Aabb> {
    (0..w.bodies.len())
        .map(|i| {
            w.bodies.shape[i]
                .compute_aabb(&w.bodies.pose[i])
                .loosened(margins[i])
        })
        .collect()
}

/// Largest per-axis gap between two boxes (m); 0 when they overlap.
fn gap(a: &Aabb, b: &Aabb) -> f32 {
    (b.mins - a.maxs)
        .max(a.mins - b.maxs)
        .max(Vec3::ZERO)
        .max_element()
}

/// A deterministic sequence in [0, 1).
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }
}

/// Over 200 steps of jitter, drift, teleports and speculative margins that grow (a fast
/// body) and shrink again (it comes to rest), the kept tree's pairs are exactly checked
/// against the boxes: every pair of overlapping boxes is found, and no pair is further apart
/// than the stored boxes allow (each at most two skins larger than its body's box).
#[test]
fn kept_tree_finds_every_overlap_and_nothing_far() {
    check_history(lattice(), 7, 1.0);
}

/// The same with a few bodies moving at a time in a larger lattice, so that most steps update
/// the pairs by querying the changed leaves alone (at most a quarter of them changed) rather
/// than traversing the whole tree.
#[test]
fn few_changed_leaves_find_every_overlap_and_nothing_far() {
    check_history(lattice_of(8, 3, 8), 5, 0.06);
}

/// Moves a `moving` share of `w`'s bodies (jitter, drift, teleports; margins that grow and
/// shrink) over 200 steps and checks the kept tree's pairs against the boxes at every step.
fn check_history(mut w: World, seed: u64, moving: f32) {
    let n = w.bodies.len();
    let mut rng = Lcg(seed);
    let mut broad_phase = BroadPhase::default();
    let mut pairs = Vec::new();
    let mut margins = vec![0.01; n];
    for step in 0..200 {
        for (pose, margin) in w.bodies.pose.iter_mut().zip(&mut margins) {
            if rng.next() >= moving {
                continue;
            }
            let r = rng.next();
            let t = &mut pose.translation;
            if r < 0.02 {
                // Teleport anywhere in the lattice's volume.
                *t = Vec3::new(rng.next(), rng.next(), rng.next()) * 4.0;
            } else if r < 0.3 {
                *t += (Vec3::new(rng.next(), rng.next(), rng.next()) - 0.5) * 0.05;
            } else {
                *t += (Vec3::new(rng.next(), rng.next(), rng.next()) - 0.5) * 1e-6;
            }
            *margin = if rng.next() < 0.05 { 0.3 } else { 0.01 };
        }
        broad_phase.candidate_pairs(&w.bodies, &margins, false, &mut pairs);
        if step % 3 == 0 {
            broad_phase.optimize();
        }
        let boxes = boxes(&w, &margins);
        assert!(
            pairs.windows(2).all(|p| p[0] < p[1]),
            "step {step}: not sorted"
        );
        for a in 0..n {
            for b in a + 1..n {
                let found = pairs.binary_search(&(a as u32, b as u32)).is_ok();
                let g = gap(&boxes[a], &boxes[b]);
                if g == 0.0 {
                    assert!(
                        found,
                        "step {step}: overlapping boxes of {a} and {b} missed"
                    );
                }
                if found {
                    assert!(
                        g <= 4.0 * CHANGE_DETECTION_SKIN + 1e-5,
                        "step {step}: pair ({a}, {b}) {g} m apart"
                    );
                }
            }
        }
    }
}

/// Through steps of motion, steps where a few bodies move (the changed leaves are queried
/// alone) and steps at rest (where the pairs are last step's), the pairs on one and on two
/// threads are the same. The world has more bodies than go on threads
/// ([`crate::parallel::PARALLEL_BROAD_PHASE_BODIES`]).
#[test]
fn pairs_are_the_same_on_one_and_two_threads() {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap();
    let mut w = lattice_of(17, 16, 16);
    let n = w.bodies.len();
    assert!(n > crate::parallel::PARALLEL_BROAD_PHASE_BODIES);
    let mut rng = Lcg(11);
    let (mut serial, mut parallel) = (BroadPhase::default(), BroadPhase::default());
    let (mut serial_pairs, mut parallel_pairs) = (Vec::new(), Vec::new());
    // Neighbours 0.2 m apart are found with 0.1 m margins.
    let margins = vec![0.1; n];
    for step in 0..60 {
        // Every body moves, then about three a step, then none.
        let share = match step % 10 {
            0..5 => 1.0,
            5..8 => 3.0 / n as f32,
            _ => 0.0,
        };
        for i in 0..n {
            if rng.next() < share {
                w.bodies.pose[i].translation +=
                    (Vec3::new(rng.next(), rng.next(), rng.next()) - 0.5) * 0.04;
            }
        }
        serial.candidate_pairs(&w.bodies, &margins, false, &mut serial_pairs);
        pool.install(|| parallel.candidate_pairs(&w.bodies, &margins, true, &mut parallel_pairs));
        assert_eq!(serial_pairs, parallel_pairs, "step {step}");
        assert!(!serial_pairs.is_empty());
    }
}
