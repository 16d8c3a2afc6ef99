//! A joint's frames at given poses: lever arms, the anchor separation, A's frame axes in the
//! world, and the six coordinates of B's frame relative to A's.
//!
//! Angular coordinates come from the relative rotation q = q_A⁻¹·q_B of the two frames (in A's
//! frame, with q.w ≥ 0): with every rotation locked, 2·vec(q) (the rotation vector to first
//! order); with exactly one rotation free or limited (a hinge), the twist–swing decomposition
//! about that axis, q = swing·twist: the twist's angle is the hinge angle (exact at any angle)
//! and 2·vec(swing) the error of the two locked rotations; with two or three, the components
//! of the rotation vector log(q) (exact for one axis at a time, first order for combined
//! rotations, as the per-axis limits of PhysX's D6 joint are).

use glam::{Mat3, Quat, Vec3};

use super::forms::{AnchorGeometry, JointForm};
use super::types::{AxisMode, JointAxis};

/// The frames of a joint in its bodies, relative to their centres of mass.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct LocalFrames {
    /// A's anchor from A's centre of mass, in A's body frame (m).
    pub anchor_a: Vec3,
    /// B's anchor from B's centre of mass, in B's body frame (m).
    pub anchor_b: Vec3,
    /// A's joint frame in A's body frame.
    pub rotation_a: Quat,
    /// B's joint frame in B's body frame.
    pub rotation_b: Quat,
}

/// A joint's geometry at given poses.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct FrameState {
    /// The lever arms, the anchor separation and A's frame axes in the world.
    pub geometry: AnchorGeometry,
    /// The six coordinates of B's frame relative to A's (m, rad): linear as the joint's form
    /// measures them ([`JointForm::translation_coordinates`]; along A's axes but for a
    /// distance joint's first, the anchor distance), angular as the module says.
    pub coordinates: [f32; 6],
}

/// The geometry of a joint of form `form` with A's centre of mass at `center_a` and
/// orientation `orientation_a`, and B's likewise.
pub(crate) fn frame_state(
    frames: &LocalFrames,
    dofs: &[JointAxis; 6],
    form: &dyn JointForm,
    (center_a, orientation_a): (Vec3, Quat),
    (center_b, orientation_b): (Vec3, Quat),
) -> FrameState {
    let r_a = orientation_a * frames.anchor_a;
    let r_b = orientation_b * frames.anchor_b;
    let separation = (center_b + r_b) - (center_a + r_a);
    let frame_a = (orientation_a * frames.rotation_a).normalize();
    let frame_b = (orientation_b * frames.rotation_b).normalize();
    let geometry = AnchorGeometry {
        r_a,
        r_b,
        separation,
        axes: Mat3::from_quat(frame_a),
    };
    let mut coordinates = [0.0f32; 6];
    coordinates[..3].copy_from_slice(&form.translation_coordinates(&geometry));
    let angular = angular_coordinates(frame_a.conjugate() * frame_b, dofs);
    coordinates[3..].copy_from_slice(&angular);
    FrameState {
        geometry,
        coordinates,
    }
}

/// The angular coordinates of the relative rotation `relative` (see the module).
fn angular_coordinates(relative: Quat, dofs: &[JointAxis; 6]) -> [f32; 3] {
    let q = if relative.w < 0.0 {
        -relative
    } else {
        relative
    };
    let v = Vec3::new(q.x, q.y, q.z);
    let mut open = [0usize; 3];
    let mut count = 0;
    for k in 0..3 {
        if dofs[3 + k].mode != AxisMode::Locked {
            open[count] = k;
            count += 1;
        }
    }
    match count {
        0 => (2.0 * v).to_array(),
        1 => {
            let k = open[0];
            let twist_sine = v[k];
            let angle = 2.0 * twist_sine.atan2(q.w);
            let norm = (twist_sine * twist_sine + q.w * q.w).sqrt();
            let swing = if norm > 1e-9 {
                let mut axis = Vec3::ZERO;
                axis[k] = twist_sine / norm;
                let twist = Quat::from_xyzw(axis.x, axis.y, axis.z, q.w / norm);
                let swing = q * twist.conjugate();
                if swing.w < 0.0 { -swing } else { swing }
            } else {
                // Swung by half a turn: no twist can be told apart.
                q
            };
            let mut out = (2.0 * Vec3::new(swing.x, swing.y, swing.z)).to_array();
            out[k] = angle;
            out
        }
        _ => {
            let sine = v.length();
            if sine < 1e-9 {
                (2.0 * v).to_array()
            } else {
                (v * (2.0 * sine.atan2(q.w) / sine)).to_array()
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hinge() -> [JointAxis; 6] {
        let mut dofs = [JointAxis::LOCKED; 6];
        dofs[3] = JointAxis::FREE;
        dofs
    }

    #[test]
    fn a_hinge_angle_is_exact_at_any_angle_and_the_swing_is_apart() {
        for angle in [-3.0f32, -1.2, 0.0, 0.4, 2.5, 3.1] {
            let swing = Quat::from_rotation_y(0.01);
            let q = swing * Quat::from_rotation_x(angle);
            let c = angular_coordinates(q, &hinge());
            assert!((c[0] - angle).abs() < 1e-4, "{angle}: {c:?}");
            assert!(
                (c[1] - 0.01).abs() < 1e-4 && c[2].abs() < 1e-4,
                "{angle}: {c:?}"
            );
        }
    }

    #[test]
    fn free_rotations_read_the_rotation_vector() {
        let dofs = [JointAxis::FREE; 6];
        let c = angular_coordinates(Quat::from_rotation_z(1.0), &dofs);
        assert!((c[2] - 1.0).abs() < 1e-5 && c[0].abs() < 1e-6 && c[1].abs() < 1e-6);
    }
}
