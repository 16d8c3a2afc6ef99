//! The bodies' mass properties against closed forms.

use glam::{Mat3, Quat, Vec3};
use parry3d::math::Pose;
use parry3d::shape::{Ball, SharedShape};

use super::locked_axes::rotate_tensor;
use super::{Bodies, BodyKind, LockedAxes};

/// ½ωᵀIω computed in the body frame equals the world-frame formula ½ωᵀ(R·I⁻¹·Rᵀ)⁻¹ω, for
/// a diagonal tensor and a full one, at a rotation that mixes all three axes.
#[test]
fn rotational_energy_in_the_body_frame_matches_the_world_tensor() {
    let rotation = Quat::from_euler(glam::EulerRot::XYZ, 0.7, -1.1, 2.3);
    let full = Mat3::from_cols_array(&[0.5, 0.1, -0.05, 0.1, 0.8, 0.2, -0.05, 0.2, 1.3]);
    for inverse_inertia in [Mat3::from_diagonal(Vec3::new(0.5, 2.0, 4.0)), full] {
        let mut bodies = Bodies::default();
        bodies.kind.push(BodyKind::Dynamic);
        bodies
            .pose
            .push(Pose::from_parts(Vec3::new(1.0, 2.0, 3.0), rotation));
        bodies.local_center_of_mass.push(Vec3::ZERO);
        bodies.linear_velocity.push(Vec3::new(1.0, -2.0, 0.5));
        let omega = Vec3::new(3.0, -1.0, 2.0);
        bodies.angular_velocity.push(omega);
        bodies.inverse_mass.push(0.25);
        bodies.local_inverse_inertia.push(inverse_inertia);
        bodies.shape.push(SharedShape::new(Ball::new(0.5)));
        bodies.friction.push(0.5);
        bodies.restitution.push(0.0);
        bodies.asleep.push(false);
        bodies.sleep_time.push(0.0);
        let world = rotate_tensor(rotation, &inverse_inertia);
        let expected = 0.5 * 4.0 * Vec3::new(1.0, -2.0, 0.5).length_squared()
            + 0.5 * omega.dot(world.inverse() * omega);
        let energy = bodies.kinetic_energy(0);
        assert!(
            (energy - expected).abs() < 1e-4 * expected,
            "{energy} J against {expected} J"
        );
    }
}

/// P·(Pᵀ·I_w·P)⁻¹·Pᵀ by inverting I_w and its free block in f64, for the locks of `locked`
/// (one or two rotations).
fn free_block_inverse(rotation: Quat, local: &Mat3, locked: LockedAxes) -> glam::DMat3 {
    let r = glam::DMat3::from_quat(rotation.as_dquat().normalize());
    let tensor = r * local.as_dmat3().inverse() * r.transpose();
    let free: Vec<usize> = (0..3)
        .filter(|&k| locked.rotation_factor()[k] != 0.0)
        .collect();
    let mut out = glam::DMat3::ZERO;
    match free[..] {
        [a] => {
            out.col_mut(a)[a] = 1.0 / tensor.col(a)[a];
        }
        [a, b] => {
            let (paa, pab, pbb) = (tensor.col(a)[a], tensor.col(b)[a], tensor.col(b)[b]);
            let det = paa * pbb - pab * pab;
            out.col_mut(a)[a] = pbb / det;
            out.col_mut(b)[b] = paa / det;
            out.col_mut(b)[a] = -pab / det;
            out.col_mut(a)[b] = -pab / det;
        }
        _ => unreachable!(),
    }
    out
}

const ONE_OR_TWO: [LockedAxes; 6] = [
    LockedAxes::ROTATION_X,
    LockedAxes::ROTATION_Y,
    LockedAxes::ROTATION_Z,
    LockedAxes::ROTATION_X.union(LockedAxes::ROTATION_Y),
    LockedAxes::ROTATION_X.union(LockedAxes::ROTATION_Z),
    LockedAxes::ROTATION_Y.union(LockedAxes::ROTATION_Z),
];

/// The locked world inverse inertia is the inverse of I_w's free block, P·(Pᵀ·I_w·P)⁻¹·Pᵀ,
/// for one and two locked rotations, at a rotation mixing all three axes, for a box's
/// diagonal tensor, a needle's (moments 1 : 2000 : 2000) and a full one; its locked rows
/// and columns are zero to the bit. Zeroing the rows and columns of I_w⁻¹ instead is off by
/// far more for the same bodies.
#[test]
fn locked_inverse_inertia_inverts_the_free_block_of_the_world_tensor() {
    let rotation = Quat::from_euler(glam::EulerRot::XYZ, 0.7, -1.1, 2.3);
    let full = Mat3::from_cols_array(&[0.5, 0.1, -0.05, 0.1, 0.8, 0.2, -0.05, 0.2, 1.3]);
    let tensors = [
        Mat3::from_diagonal(Vec3::new(1.0 / 13.6, 1.0 / 4.0, 1.0 / 10.4)),
        Mat3::from_diagonal(Vec3::new(1.0, 5e-4, 5e-4)),
        full,
    ];
    for local in tensors {
        for locked in ONE_OR_TWO {
            let got = locked.world_inverse_inertia(rotation, &local);
            let expected = free_block_inverse(rotation, &local, locked);
            let scale = expected
                .to_cols_array()
                .iter()
                .fold(0.0f64, |m, x| m.max(x.abs()));
            let error = (got.as_dmat3() - expected)
                .to_cols_array()
                .iter()
                .fold(0.0f64, |m, x| m.max(x.abs()));
            assert!(error < 1e-6 * scale, "{locked:?}: {got} against {expected}");
            let f = locked.rotation_factor();
            for k in (0..3).filter(|&k| f[k] == 0.0) {
                assert_eq!(got.col(k), Vec3::ZERO, "{locked:?}");
                assert_eq!(got.row(k), Vec3::ZERO, "{locked:?}");
            }
            let zeroed = rotate_tensor(rotation, &local).as_dmat3()
                * glam::DMat3::from_diagonal(f.as_dvec3());
            let zeroed = glam::DMat3::from_diagonal(f.as_dvec3()) * zeroed;
            let old = (zeroed - expected)
                .to_cols_array()
                .iter()
                .fold(0.0f64, |m, x| m.max(x.abs()));
            assert!(old > 1e-3 * scale, "{locked:?}: zeroing would do");
        }
    }
}

/// When every locked axis is a principal axis of I_w (the box turned about the locked axis
/// only, or not at all), the free block's inverse is the zeroed I⁻¹ of old; with nothing
/// locked the tensor is R·I⁻¹·Rᵀ to the bit; with all three rotations locked it is zero; a
/// singular or zero tensor gives a finite result.
#[test]
fn locked_inverse_inertia_in_the_cases_with_a_known_answer() {
    let local = Mat3::from_diagonal(Vec3::new(1.0 / 13.6, 1.0 / 4.0, 1.0 / 10.4));
    let zeroed = |rotation: Quat, locked: LockedAxes| {
        let f = locked.rotation_factor();
        let t = rotate_tensor(rotation, &local);
        Mat3::from_cols(
            t.x_axis * (f * f.x),
            t.y_axis * (f * f.y),
            t.z_axis * (f * f.z),
        )
    };
    for locked in ONE_OR_TWO {
        assert_eq!(
            locked.world_inverse_inertia(Quat::IDENTITY, &local),
            zeroed(Quat::IDENTITY, locked),
            "{locked:?}"
        );
    }
    for (axis, locked) in [
        (Vec3::X, LockedAxes::ROTATION_X),
        (Vec3::Y, LockedAxes::ROTATION_Y),
        (Vec3::Z, LockedAxes::ROTATION_Z),
    ] {
        let rotation = Quat::from_axis_angle(axis, 0.8);
        let got = locked.world_inverse_inertia(rotation, &local);
        let old = zeroed(rotation, locked);
        assert!(
            got.abs_diff_eq(old, 1e-7),
            "{locked:?}: {got} against {old}"
        );
    }
    let rotation = Quat::from_euler(glam::EulerRot::XYZ, 0.7, -1.1, 2.3);
    assert_eq!(
        LockedAxes::NONE.world_inverse_inertia(rotation, &local),
        rotate_tensor(rotation, &local)
    );
    assert_eq!(
        LockedAxes::ALL_ROTATIONS.world_inverse_inertia(rotation, &local),
        Mat3::ZERO
    );
    for singular in [Mat3::ZERO, Mat3::from_diagonal(Vec3::new(0.0, 2.0, 3.0))] {
        for locked in ONE_OR_TWO {
            for rotation in [Quat::IDENTITY, rotation] {
                let got = locked.world_inverse_inertia(rotation, &singular);
                assert!(got.is_finite(), "{locked:?}: {got}");
            }
        }
    }
}

/// A convex hull of a box's corners from 1 m to 600 km across, given a mass of 1 kg, gets the
/// box's moments m·(b² + c²)/3 (half extents a, b, c): Parry's f32 principal axes would
/// overflow for the large ones, which `rules::mass_properties` scales out.
#[test]
fn large_hulls_get_their_moments() {
    for half in [0.5f32, 5.0e3, 3.0e5] {
        let h = Vec3::new(half, 0.5 * half, 0.25 * half);
        let hull = SharedShape::convex_hull(&crate::test_support::box_corners(h)).unwrap();
        let properties = super::rules::mass_properties(hull.as_ref(), 1.0);
        let mut found = properties.principal_inertia().to_array();
        found.sort_by(f32::total_cmp);
        let volume = 8.0 * h.x * h.y * h.z;
        let mut expected = [
            volume * (h.y * h.y + h.z * h.z) / 3.0,
            volume * (h.x * h.x + h.z * h.z) / 3.0,
            volume * (h.x * h.x + h.y * h.y) / 3.0,
        ];
        expected.sort_by(f32::total_cmp);
        for (f, e) in found.iter().zip(expected) {
            assert!(
                (f - e).abs() <= 1e-3 * e,
                "half extent {half}: {found:?} against {expected:?}"
            );
        }
        let mut world =
            crate::World::new(Vec3::ZERO, 1.0 / 60.0, crate::SolverSettings::default()).unwrap();
        world
            .insert(super::BodyBuilder::dynamic(hull).mass(1.0))
            .expect("a large hull of 1 kg is a body");
    }
}
