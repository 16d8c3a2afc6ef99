//! Seams: a body sliding or rolling across a level joint keeps its speed and stays on the
//! surface (issue 23, item 6): across the joint of two static boxes with level tops, across
//! the triangle edges of a flat triangle mesh and across the cells of a flat height field.
//!
//! On a level frictionless floor a sliding body keeps its velocity, and a body rolling
//! without slipping keeps it too (no rolling resistance): the speed after the crossing must be
//! within 1 % of the speed before it, and the body must not rise more than 1 mm above the
//! height at which it rested before the crossing.

use impulse::glam::{Quat, Vec3};
use impulse::parry3d::shape::{HeightField, HeightFieldFlags, TriMeshFlags};
use impulse::{BodyBuilder, BodyHandle, SharedShape, SolverSettings, World};

const DT: f32 = 1.0 / 60.0;

/// The moving body of a seam test.
#[derive(Clone, Copy, Debug)]
enum Mover {
    /// A unit cube sliding without friction.
    Box,
    /// A ball of radius 0.5 m rolling without slipping (friction 0.5).
    Sphere,
    /// A capsule (radius 0.3 m, half height 0.4 m) lying along z, rolling along x.
    Capsule,
}

/// The static floor under the mover: its top is the plane y = 0 from x = −4 to 4 and from
/// z = −4 to 4, and x = 0 is a seam of each kind.
#[derive(Clone, Copy, Debug)]
enum Floor {
    /// Two boxes side by side, joined at x = 0.
    TwoBoxes,
    /// A flat triangle mesh: 8 × 8 squares of 1 m, each split along a diagonal.
    Mesh,
    /// A flat height field of 8 × 8 cells of 1 m.
    HeightField,
}

fn insert_floor(world: &mut World, floor: Floor, friction: f32) {
    match floor {
        Floor::TwoBoxes => {
            for x in [-2.0, 2.0] {
                world
                    .insert(
                        BodyBuilder::fixed(SharedShape::cuboid(2.0, 0.5, 4.0))
                            .translation(Vec3::new(x, -0.5, 0.0))
                            .friction(friction),
                    )
                    .unwrap();
            }
        }
        Floor::Mesh => {
            let n = 8;
            let mut vertices = Vec::new();
            for k in 0..=n {
                for i in 0..=n {
                    vertices.push(Vec3::new(i as f32 - 4.0, 0.0, k as f32 - 4.0));
                }
            }
            let mut indices = Vec::new();
            let at = |i: u32, k: u32| k * (n + 1) + i;
            for k in 0..n {
                for i in 0..n {
                    // Counter-clockwise seen from above: normals point up.
                    indices.push([at(i, k), at(i, k + 1), at(i + 1, k + 1)]);
                    indices.push([at(i, k), at(i + 1, k + 1), at(i + 1, k)]);
                }
            }
            let mesh = SharedShape::trimesh_with_flags(
                vertices,
                indices,
                TriMeshFlags::FIX_INTERNAL_EDGES,
            )
            .unwrap();
            world
                .insert(BodyBuilder::fixed(mesh).friction(friction))
                .unwrap();
        }
        Floor::HeightField => {
            let heights = impulse::parry3d::utils::Array2::new(9, 9, vec![0.0; 81]);
            let field = HeightField::with_flags(
                heights,
                Vec3::new(8.0, 1.0, 8.0),
                HeightFieldFlags::FIX_INTERNAL_EDGES,
            );
            world
                .insert(BodyBuilder::fixed(SharedShape::new(field)).friction(friction))
                .unwrap();
        }
    }
}

/// The mover's shape, resting height of its centre and orientation.
fn mover_shape(mover: Mover) -> (SharedShape, f32, Quat) {
    match mover {
        Mover::Box => (SharedShape::cuboid(0.5, 0.5, 0.5), 0.5, Quat::IDENTITY),
        Mover::Sphere => (SharedShape::ball(0.5), 0.5, Quat::IDENTITY),
        Mover::Capsule => (
            SharedShape::capsule_y(0.4, 0.3),
            0.3,
            Quat::from_rotation_x(std::f32::consts::FRAC_PI_2),
        ),
    }
}

/// Speed before and after the seam at x = 0 and the largest rise (m) above the height before
/// it, for `mover` started at x = −2.5 with `speed` (m/s) along +x on `floor`.
struct Crossing {
    speed_before: f32,
    speed_after: f32,
    rise: f32,
}

fn cross(mover: Mover, floor: Floor, speed: f32) -> Crossing {
    let settings = SolverSettings {
        sleep: None,
        ..SolverSettings::default()
    };
    let mut world = World::new(Vec3::new(0.0, -9.81, 0.0), DT, settings).unwrap();
    let friction = match mover {
        Mover::Box => 0.0,
        Mover::Sphere | Mover::Capsule => 0.5,
    };
    insert_floor(&mut world, floor, friction);
    let (shape, height, rotation) = mover_shape(mover);
    let radius = height;
    let angular = match mover {
        Mover::Box => Vec3::ZERO,
        // Rolling without slipping along +x: ω = v/r about −z.
        Mover::Sphere | Mover::Capsule => Vec3::new(0.0, 0.0, -speed / radius),
    };
    let body: BodyHandle = world
        .insert(
            BodyBuilder::dynamic(shape)
                .translation(Vec3::new(-2.5, height, 0.3))
                .rotation(rotation)
                .linear_velocity(Vec3::new(speed, 0.0, 0.0))
                .angular_velocity(angular)
                .friction(friction),
        )
        .unwrap();
    let position = |w: &World| w.body(body).unwrap().translation();
    let velocity = |w: &World| w.body(body).unwrap().linear_velocity();
    // Settle on the floor for 0.2 s away from any seam, then record the state 0.6 m before x = 0.
    let mut before = None;
    let mut rest_height = f32::NAN;
    let mut rise = 0.0f32;
    let mut steps = 0;
    while position(&world).x < 1.5 {
        world.step().unwrap();
        steps += 1;
        assert!(
            steps < 2000,
            "{mover:?} on {floor:?} at {speed} m/s stopped"
        );
        let p = position(&world);
        if before.is_none() && p.x > -0.6 {
            before = Some(velocity(&world).length());
            rest_height = p.y;
        }
        if before.is_some() {
            rise = rise.max(p.y - rest_height);
        }
    }
    Crossing {
        speed_before: before.unwrap(),
        speed_after: velocity(&world).length(),
        rise,
    }
}

fn check(mover: Mover, floor: Floor) {
    let mut report = Vec::new();
    let mut failed = false;
    for speed in [1.0, 2.0, 3.0, 4.0, 5.0] {
        let c = cross(mover, floor, speed);
        let change = (c.speed_after - c.speed_before).abs() / c.speed_before;
        report.push(format!(
            "{speed} m/s: {:.4} → {:.4} m/s ({:.3} %), rise {:.3} mm",
            c.speed_before,
            c.speed_after,
            100.0 * change,
            1000.0 * c.rise
        ));
        failed |= change > 0.01 || c.rise > 1.0e-3;
    }
    println!("{mover:?} on {floor:?}:\n{}", report.join("\n"));
    assert!(!failed, "{mover:?} on {floor:?}:\n{}", report.join("\n"));
}

#[test]
fn box_slides_across_the_joint_of_two_boxes() {
    check(Mover::Box, Floor::TwoBoxes);
}

#[test]
fn sphere_rolls_across_the_joint_of_two_boxes() {
    check(Mover::Sphere, Floor::TwoBoxes);
}

#[test]
fn capsule_rolls_across_the_joint_of_two_boxes() {
    check(Mover::Capsule, Floor::TwoBoxes);
}

#[test]
fn box_slides_across_mesh_triangle_edges() {
    check(Mover::Box, Floor::Mesh);
}

#[test]
fn sphere_rolls_across_mesh_triangle_edges() {
    check(Mover::Sphere, Floor::Mesh);
}

#[test]
fn capsule_rolls_across_mesh_triangle_edges() {
    check(Mover::Capsule, Floor::Mesh);
}

#[test]
fn box_slides_across_height_field_cells() {
    check(Mover::Box, Floor::HeightField);
}

#[test]
fn sphere_rolls_across_height_field_cells() {
    check(Mover::Sphere, Floor::HeightField);
}

#[test]
fn capsule_rolls_across_height_field_cells() {
    check(Mover::Capsule, Floor::HeightField);
}

/// The seam rule must keep the contacts of a concave corner: a cube pushed into the corner of
/// a floor and a wall (two static boxes) with a horizontal force of twice its weight stays
/// out of both, upright, for 3 s.
#[test]
fn cube_pushed_into_a_concave_corner_stays_out_of_both_walls() {
    let settings = SolverSettings {
        sleep: None,
        ..SolverSettings::default()
    };
    let mut world = World::new(Vec3::new(0.0, -9.81, 0.0), DT, settings).unwrap();
    // Floor: top at y = 0; wall: the face x = 0, standing on the floor.
    world
        .insert(
            BodyBuilder::fixed(SharedShape::cuboid(4.0, 0.5, 4.0))
                .translation(Vec3::new(0.0, -0.5, 0.0)),
        )
        .unwrap();
    world
        .insert(
            BodyBuilder::fixed(SharedShape::cuboid(0.5, 2.0, 4.0))
                .translation(Vec3::new(0.5, 2.0, 0.0)),
        )
        .unwrap();
    let cube = world
        .insert(
            BodyBuilder::dynamic(SharedShape::cuboid(0.5, 0.5, 0.5))
                .translation(Vec3::new(-0.5, 0.5, 0.0))
                .friction(0.5),
        )
        .unwrap();
    let weight = world.body(cube).unwrap().mass() * 9.81;
    let (mut worst_floor, mut worst_wall, mut worst_tilt) = (0.0f32, 0.0f32, 0.0f32);
    for _ in 0..180 {
        world
            .apply_force(cube, Vec3::new(2.0 * weight, 0.0, 0.0))
            .unwrap();
        world.step().unwrap();
        let body = world.body(cube).unwrap();
        let p = body.translation();
        worst_floor = worst_floor.max(0.5 - p.y);
        worst_wall = worst_wall.max(p.x + 0.5);
        worst_tilt = worst_tilt.max(body.rotation().angle_between(Quat::IDENTITY));
    }
    assert!(
        worst_floor < 1.0e-3,
        "sank into the floor by {worst_floor} m"
    );
    assert!(worst_wall < 1.0e-3, "went into the wall by {worst_wall} m");
    assert!(worst_tilt < 1.0e-3, "tilted by {worst_tilt} rad");
}
