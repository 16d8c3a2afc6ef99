//! Kinematic bodies' prescribed motion as maths: the keyframed pose at a time, the velocity
//! that carries a body from one pose to another in one step, the rotation vector between two
//! orientations, and the pose a constant velocity reaches. The kinematic stage
//! (`world/step/kinematic.rs`) drives kinematic bodies with them; continuous collision's sweeps
//! (`collision/continuous.rs`) turn bodies by [`rotation_vector`].
//!
//! A position-based kinematic body takes, each step, the velocity that reaches its target pose
//! at the step's end, as Rapier's kinematic bodies do (`RigidBodyType::KinematicPositionBased`,
//! whose velocity Rapier interpolates from the current and the next pose,
//! `RigidBodyPosition::interpolate_velocity`; rapier.rs user guide, "Rigid-body type").

use glam::{Quat, Vec3};
use parry3d::math::Pose;

use super::Keyframe;

/// The keyframed pose at `time` (s): the initial pose at time 0, each keyframe's pose at its
/// time, linear interpolation of the translation and slerp of the rotation in between (the
/// shorter way round), the last pose held after the last keyframe. `keyframes` must be sorted
/// by time with times > 0; an empty list holds the initial pose.
pub(crate) fn keyframed_pose(initial: &Pose, keyframes: &[Keyframe], time: f64) -> Pose {
    let mut before = (0.0f64, initial.translation, initial.rotation);
    for k in keyframes {
        let t = f64::from(k.time);
        if time < t {
            let span = t - before.0;
            let s = if span > 0.0 {
                ((time - before.0) / span).clamp(0.0, 1.0) as f32
            } else {
                1.0
            };
            let translation = before.1.lerp(k.translation, s);
            let rotation = before.2.slerp(k.rotation, s).normalize();
            return Pose::from_parts(translation, rotation);
        }
        before = (t, k.translation, k.rotation);
    }
    Pose::from_parts(before.1, before.2)
}

/// The constant linear velocity of the centre of mass (m/s) and angular velocity (rad/s,
/// world frame) that carry a body from pose `from` to pose `to` in `dt` seconds, its centre of
/// mass at `local_center_of_mass` in the body frame: Δc/dt and the rotation vector of
/// `to.rotation · from.rotation⁻¹` (the shorter way round) over dt.
pub(crate) fn velocity_between(
    from: &Pose,
    to: &Pose,
    local_center_of_mass: Vec3,
    dt: f32,
) -> (Vec3, Vec3) {
    let linear = (to.transform_point(local_center_of_mass)
        - from.transform_point(local_center_of_mass))
        / dt;
    (linear, rotation_vector(from.rotation, to.rotation) / dt)
}

/// The rotation vector (axis × angle, rad, angle in [0, π]) of `to · from⁻¹`.
pub(crate) fn rotation_vector(from: Quat, to: Quat) -> Vec3 {
    let mut delta = to * from.inverse();
    if delta.w < 0.0 {
        delta = -delta;
    }
    let scaled = delta.normalize().to_scaled_axis();
    if scaled.is_finite() {
        scaled
    } else {
        Vec3::ZERO
    }
}

/// The pose a body reaches from `pose` in `dt` seconds at constant velocities: its centre of
/// mass (at `local_center_of_mass` in the body frame) moves by `linear`·dt and the body turns
/// by the rotation vector `angular`·dt about it (exact for a constant ω, unlike the island's
/// first-order orientation update).
pub(crate) fn advance(
    pose: &Pose,
    local_center_of_mass: Vec3,
    linear: Vec3,
    angular: Vec3,
    dt: f32,
) -> Pose {
    let center = pose.transform_point(local_center_of_mass) + linear * dt;
    let rotation = (Quat::from_scaled_axis(angular * dt) * pose.rotation).normalize();
    Pose::from_parts(center - rotation * local_center_of_mass, rotation)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn key(time: f32, x: f32, angle: f32) -> Keyframe {
        Keyframe {
            time,
            translation: Vec3::new(x, 0.0, 0.0),
            rotation: Quat::from_rotation_y(angle),
        }
    }

    /// Interpolation between keyframes, from the initial pose before the first, held after the
    /// last; the velocity between two poses reaches the second one in one step.
    #[test]
    fn keyframes_interpolate_and_hold() {
        let initial = Pose::from_parts(Vec3::ZERO, Quat::IDENTITY);
        let keys = [key(1.0, 2.0, 1.0), key(3.0, 6.0, 1.5)];
        let at = |t| keyframed_pose(&initial, &keys, t);
        assert!((at(0.5).translation.x - 1.0).abs() < 1e-6);
        assert!(at(0.5).rotation.angle_between(Quat::from_rotation_y(0.5)) < 1e-5);
        assert!((at(2.0).translation.x - 4.0).abs() < 1e-6);
        assert!(at(2.0).rotation.angle_between(Quat::from_rotation_y(1.25)) < 1e-5);
        assert!((at(10.0).translation.x - 6.0).abs() < 1e-6);
        let from = at(0.5);
        let to = at(0.6);
        let com = Vec3::new(0.1, 0.2, 0.0);
        let (v, w) = velocity_between(&from, &to, com, 0.1);
        let reached = advance(&from, com, v, w, 0.1);
        assert!((reached.translation - to.translation).length() < 1e-5);
        assert!(reached.rotation.angle_between(to.rotation) < 1e-5);
        assert!((w - Vec3::new(0.0, 1.0, 0.0)).length() < 1e-3, "{w}");
    }
}
