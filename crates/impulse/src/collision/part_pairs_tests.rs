//! The reduction of a compound's part manifolds: a row of parts flat on a box keeps four points
//! spanning the whole row; a part a few millimetres off the patch keeps its own points.

use super::*;
use crate::collision::dispatch::ContactDispatcher;
use glam::Vec3;
use parry3d::query::{ContactManifoldsWorkspace, PersistentQueryDispatcher};
use parry3d::shape::SharedShape;

/// Parry's manifolds of `compound` at `pose` (in the box's frame) against a box of half extents
/// (2, 0.5, 2) whose top face is at y = 0, within 1 cm, then reduced when `reduced`.
fn on_ground(compound: &SharedShape, pose: Pose, reduced: bool) -> Vec<Manifold> {
    let ground = SharedShape::cuboid(2.0, 0.5, 2.0);
    let ground_pose = Pose::from_translation(Vec3::new(0.0, -0.5, 0.0));
    let pos12 = ground_pose.inv_mul(&pose);
    let mut manifolds: Vec<Manifold> = Vec::new();
    let mut workspace: Option<ContactManifoldsWorkspace> = None;
    ContactDispatcher::default()
        .contact_manifolds(
            &pos12,
            ground.as_ref(),
            compound.as_ref(),
            0.01,
            &mut manifolds,
            &mut workspace,
        )
        .unwrap();
    // The reduction itself, on a compound's manifolds against a box (the engine applies it
    // between two compounds only: `applies`).
    if reduced {
        reduce(&mut manifolds, &still);
    }
    manifolds
}

/// Points of `manifolds` in the ground's frame (its centre at y = -0.5).
fn points(manifolds: &[Manifold]) -> Vec<(Vec3, f32)> {
    manifolds
        .iter()
        .flat_map(|m| {
            let pose = *m.subshape_pos1().unwrap_or(&Pose::IDENTITY);
            m.points.iter().map(move |p| {
                (
                    pose.transform_point(p.local_p1) + Vec3::new(0.0, -0.5, 0.0),
                    p.dist,
                )
            })
        })
        .collect()
}

/// `n` unit-wide cubes of half extent 0.05 m in a row along x, centred at `y`.
fn row(n: usize, y: f32) -> Vec<(Pose, SharedShape)> {
    (0..n)
        .map(|k| {
            let x = 0.1 * k as f32 - 0.05 * (n as f32 - 1.0);
            (
                Pose::from_translation(Vec3::new(x, y, 0.0)),
                SharedShape::cuboid(0.05, 0.05, 0.05),
            )
        })
        .collect()
}

/// Six cubes in a row resting on the box: 24 points, one patch, reduced to four that reach
/// both ends of the row (x = ±0.3) and both sides (z = ±0.05), all on the top face.
#[test]
fn a_row_of_parts_on_a_face_keeps_four_points_spanning_it() {
    let compound = SharedShape::compound(row(6, 0.05));
    let pose = Pose::IDENTITY;
    assert_eq!(points(&on_ground(&compound, pose, false)).len(), 24);
    let kept = points(&on_ground(&compound, pose, true));
    assert_eq!(kept.len(), 4, "{kept:?}");
    let xs: Vec<f32> = kept.iter().map(|(p, _)| p.x).collect();
    let zs: Vec<f32> = kept.iter().map(|(p, _)| p.z).collect();
    let span = |v: &[f32]| {
        v.iter().copied().fold(f32::NEG_INFINITY, f32::max)
            - v.iter().copied().fold(f32::INFINITY, f32::min)
    };
    assert!((span(&xs) - 0.6).abs() < 1e-4, "{xs:?}");
    assert!((span(&zs) - 0.1).abs() < 1e-4, "{zs:?}");
    for (p, dist) in kept {
        assert!(p.y.abs() < 1e-4 && dist.abs() < 1e-4, "{p} {dist}");
    }
}

/// A row whose middle cube stands 5 mm higher than the rest: the raised cube's speculative
/// points lie in a layer of their own, not the resting one (where they would take the place
/// of points that hold the row), so it keeps its four and the resting cubes keep four.
#[test]
fn a_part_off_the_patch_keeps_its_own_points() {
    let mut parts = row(5, 0.05);
    parts[2].0.translation.y += 0.005;
    let compound = SharedShape::compound(parts);
    let kept = points(&on_ground(&compound, Pose::IDENTITY, true));
    let raised = kept
        .iter()
        .filter(|(_, d)| (d - 0.005).abs() < 1e-4)
        .count();
    let resting = kept.iter().filter(|(_, d)| d.abs() < 1e-4).count();
    assert_eq!((raised, resting, kept.len()), (4, 4, 8), "{kept:?}");
}

/// A single manifold, or a pair that is not two compounds, is left alone; a triangle mesh's
/// pairs are not reduced (the seam pass reads their manifolds per triangle).
#[test]
fn other_pairs_are_not_reduced() {
    let ball = SharedShape::ball(0.1);
    let cube = SharedShape::cuboid(0.1, 0.1, 0.1);
    assert!(!applies(ball.as_ref(), cube.as_ref()));
    let compound = SharedShape::compound(row(2, 0.0));
    let mesh = SharedShape::trimesh(vec![Vec3::ZERO, Vec3::X, Vec3::Z], vec![[0, 1, 2]]).unwrap();
    assert!(!applies(mesh.as_ref(), compound.as_ref()));
    assert!(applies(compound.as_ref(), compound.as_ref()));
    assert!(!applies(cube.as_ref(), compound.as_ref()));
    let single = SharedShape::compound(row(1, 0.05));
    assert_eq!(points(&on_ground(&single, Pose::IDENTITY, true)).len(), 4);
}

/// A row whose cubes stand 0, 2, 4, 6 and 8 mm above the box: the resting cube keeps its
/// four points, and the four raised ones, at whatever gap, share the second layer's four (the
/// nearest raised cube's deepest among them), not four each.
#[test]
fn speculative_parts_share_one_layer() {
    let mut parts = row(5, 0.05);
    for (k, part) in parts.iter_mut().enumerate() {
        part.0.translation.y += 0.002 * k as f32;
    }
    let compound = SharedShape::compound(parts);
    assert_eq!(
        points(&on_ground(&compound, Pose::IDENTITY, false)).len(),
        20
    );
    let kept = points(&on_ground(&compound, Pose::IDENTITY, true));
    let resting = kept.iter().filter(|(_, d)| d.abs() < 1e-4).count();
    let nearest_raised = kept
        .iter()
        .filter(|(_, d)| (d - 0.002).abs() < 1e-4)
        .count();
    assert_eq!(kept.len(), 8, "{kept:?}");
    assert_eq!(resting, 4, "{kept:?}");
    assert!(nearest_raised >= 1, "{kept:?}");
}

/// A row of five cubes over the box, apart: the first resting on it, the second, fourth and fifth
/// 2 mm up, the middle one 8 mm up but closing 12 mm in the step (a part of a spinning body
/// turning into the other). The middle cube's points are about to touch: they make a layer of
/// their own and keep four points, beside the resting four and four of the far ones. Without
/// its motion (`still`) the middle cube is only the farthest of the far layer, whose four
/// points go to the deepest and the row's ends, and it keeps none.
#[test]
fn a_part_closing_within_the_step_keeps_its_points() {
    // Cubes 0.1 m wide, 0.1 m apart, so that no cube's corner is another's.
    let parts: Vec<(Pose, SharedShape)> = [0.0, 0.002, 0.008, 0.002, 0.002]
        .into_iter()
        .enumerate()
        .map(|(k, raise)| {
            let at = Vec3::new(0.2 * k as f32 - 0.4, 0.05 + raise, 0.0);
            (
                Pose::from_translation(at),
                SharedShape::cuboid(0.05, 0.05, 0.05),
            )
        })
        .collect();
    let compound = SharedShape::compound(parts);
    // The box is body 1; the middle cube's points lie near x = 0 in its frame.
    let closing = |position: Vec3, _normal: Vec3| {
        if position.x.abs() < 0.06 { 0.012 } else { 0.0 }
    };
    let reduced = |closing: &dyn Fn(Vec3, Vec3) -> f32| {
        let mut manifolds = on_ground(&compound, Pose::IDENTITY, false);
        reduce(&mut manifolds, closing);
        points(&manifolds)
    };
    let middle = |kept: &[(Vec3, f32)]| {
        kept.iter()
            .filter(|(p, d)| p.x.abs() < 0.06 && (d - 0.008).abs() < 1e-4)
            .count()
    };
    let moving = reduced(&closing);
    let resting = moving.iter().filter(|(_, d)| d.abs() < 1e-4).count();
    assert_eq!(
        (middle(&moving), resting, moving.len()),
        (4, 4, 12),
        "{moving:?}"
    );
    let still_kept = reduced(&still);
    assert_eq!(
        (middle(&still_kept), still_kept.len()),
        (0, 8),
        "{still_kept:?}"
    );
}
