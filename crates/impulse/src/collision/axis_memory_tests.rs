//! The face-axis memory gives the full search's contacts: two of the mug's V-HACD parts (thin
//! curved slabs, where the search runs) at seeded random poses, overlapping up to 8 mm, each
//! moved a little step after step as bodies in a pile move, get the same manifold to the bit
//! with the memory as from a full search; and a compound pair's memory goes with its part
//! pair's manifold when the parts part.

use glam::{Quat, Vec3};
use parry3d::math::Pose;
use parry3d::query::{ContactManifoldsWorkspace, PersistentQueryDispatcher};
use parry3d::shape::SharedShape;
use rand::rngs::ChaCha20Rng;
use rand::{RngExt, SeedableRng};
use rand_distr::{Distribution, UnitSphere};

use crate::collision::dispatch::ContactDispatcher;
use crate::collision::hull_pairs_tests::{PREDICTION, case, mug_parts, part_shape};
use crate::collision::manifold::Manifold;

/// Whether two manifolds hold the same contacts to the bit: normals, and every point's
/// positions, separation and features (the memory itself aside).
fn same_contacts(a: &Manifold, b: &Manifold) -> bool {
    let bits = |v: Vec3| v.to_array().map(f32::to_bits);
    bits(a.local_n1) == bits(b.local_n1)
        && bits(a.local_n2) == bits(b.local_n2)
        && a.points.len() == b.points.len()
        && a.points.iter().zip(&b.points).all(|(p, q)| {
            bits(p.local_p1) == bits(q.local_p1)
                && bits(p.local_p2) == bits(q.local_p2)
                && p.dist.to_bits() == q.dist.to_bits()
                && p.fid1 == q.fid1
                && p.fid2 == q.fid2
        })
}

/// A small random motion: a turn of up to `angle` (rad) and a shift of up to `shift` (m).
fn nudge(rng: &mut ChaCha20Rng, angle: f32, shift: f32) -> Pose {
    let axis = Vec3::from(UnitSphere.sample(rng) as [f32; 3]);
    let dir = Vec3::from(UnitSphere.sample(rng) as [f32; 3]);
    let turn = Quat::from_axis_angle(axis, rng.random_range(0.0..angle));
    Pose::from_parts(dir * rng.random_range(0.0..shift), turn)
}

/// 300 pairs of mug parts from touching to 8 mm in, each stepped 12 times with turns up to
/// 0.01 rad and shifts up to 0.3 mm a step (a mug at 0.07 m/s and 2.4 rad/s, at the pour's
/// 1/240 s): at every step the manifold updated with the memory is, to the bit, the one a full
/// search gives from the same manifold without it. The memory answers a share of the searches
/// (otherwise this would test nothing).
#[test]
fn a_remembered_face_axis_gives_the_full_searchs_manifold() {
    let parts = mug_parts();
    let mut rng = ChaCha20Rng::seed_from_u64(74);
    let (mut searches, mut reused) = (0, 0);
    for index in 0..300 {
        let start = case(74, index, 0.0..0.008);
        let (g1, g2) = (part_shape(&parts[start.i]), part_shape(&parts[start.j]));
        let mut pose2 = start.pose2;
        let mut kept = Manifold::new();
        for step in 0..12 {
            let pos12 = start.pose1.inv_mul(&pose2);
            let mut full = kept.clone();
            full.data.face_axes = None;
            let remembered = kept.data.face_axes;
            for manifold in [&mut kept, &mut full] {
                ContactDispatcher::default()
                    .contact_manifold_convex_convex(
                        &pos12,
                        g1.as_ref(),
                        g2.as_ref(),
                        None,
                        None,
                        PREDICTION,
                        manifold,
                    )
                    .unwrap();
            }
            assert!(
                same_contacts(&kept, &full),
                "case {index} (parts {} and {}), step {step}: {:?} {:?} / {:?} {:?}",
                start.i,
                start.j,
                kept.local_n1,
                kept.points,
                full.local_n1,
                full.points
            );
            if full.data.face_axes.is_some() {
                searches += 1;
                // The memory stood (not replaced by a new search's) where the full search ran.
                if remembered.is_some() && kept.data.face_axes == remembered {
                    reused += 1;
                }
            }
            pose2 = nudge(&mut rng, 0.01, 3.0e-4) * pose2;
        }
    }
    println!("{searches} face searches, {reused} answered from the memory");
    assert!(searches > 100, "{searches} searches");
    assert!(
        reused > searches / 10,
        "{reused} of {searches} searches reused"
    );
}

/// Two compounds of two mug parts each, overlapping: their part pairs' manifolds remember the
/// search; moved apart beyond the parts' reach the part manifolds go and their memories with
/// them; brought back, the memories are new (found at the new pose), not the old ones.
#[test]
fn a_part_pairs_memory_goes_when_the_parts_part() {
    let parts = mug_parts();
    let start = case(75, 3, 0.004..0.006);
    let (g1, g2) = (part_shape(&parts[start.i]), part_shape(&parts[start.j]));
    let compound = |shape: &SharedShape| {
        SharedShape::compound(vec![
            (Pose::IDENTITY, shape.clone()),
            (
                Pose::from_translation(Vec3::new(0.0, 1.0, 0.0)),
                shape.clone(),
            ),
        ])
    };
    let (c1, c2) = (compound(&g1), compound(&g2));
    let mut manifolds: Vec<Manifold> = Vec::new();
    let mut workspace: Option<ContactManifoldsWorkspace> = None;
    let mut update = |pos12: &Pose, manifolds: &mut Vec<Manifold>| {
        ContactDispatcher::default()
            .contact_manifolds(
                pos12,
                c1.as_ref(),
                c2.as_ref(),
                PREDICTION,
                manifolds,
                &mut workspace,
            )
            .unwrap();
    };
    let near = start.pose1.inv_mul(&start.pose2);
    update(&near, &mut manifolds);
    let memories = |manifolds: &[Manifold]| {
        manifolds
            .iter()
            .filter_map(|m| m.data.face_axes)
            .collect::<Vec<_>>()
    };
    let before = memories(&manifolds);
    // The case must exercise the search (a deep Parry point on thin parts).
    assert!(
        !before.is_empty(),
        "no search ran for parts {} and {}",
        start.i,
        start.j
    );
    let far = Pose::from_translation(Vec3::new(0.0, 0.0, 5.0)) * near;
    update(&far, &mut manifolds);
    assert!(manifolds.is_empty(), "{} manifolds apart", manifolds.len());
    let back = Pose::from_translation(Vec3::new(0.0, 0.0, 1.0e-4)) * near;
    update(&back, &mut manifolds);
    // A memory's pose is its parts' (part 2 in part 1's frame, which Parry composes from the
    // compounds' pose, rounding in the last bits): the new one's within a micrometre, 0.1 mm
    // from the old one's.
    let mut remembered = 0;
    for manifold in &manifolds {
        let Some(memory) = manifold.data.face_axes else {
            continue;
        };
        let identity = Pose::IDENTITY;
        let part1 = manifold.subshape_pos1().unwrap_or(&identity);
        let part2 = manifold.subshape_pos2().unwrap_or(&identity);
        let parts_now = part1.inv_mul(&(back * *part2));
        let moved = (memory.pose.translation - parts_now.translation).length();
        assert!(moved < 1.0e-6, "a memory of before the parting: {memory:?}");
        remembered += 1;
    }
    assert!(remembered > 0);
}
