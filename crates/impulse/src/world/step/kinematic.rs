//! The kinematic stage ([`crate::Stage::Kinematic`]) and everything about kinematic bodies'
//! prescribed motion: the keyframed pose at a time, the velocity that carries a body from one
//! pose to another in one step, the pose a constant velocity reaches, the target-pose edit, the
//! velocities as a step starts and the poses as it ends.
//!
//! A kinematic body is velocity-based (it keeps the velocities it is given and moves by them)
//! or position-based (keyframes, or a target pose for the next step): each step then takes
//! the velocity that reaches the target pose at the step's end, so that the contacts see the
//! body's motion, and ends the step exactly at the target. Rapier's kinematic bodies work the
//! same way (`RigidBodyType::KinematicPositionBased`, whose velocity Rapier interpolates from
//! the current and the next pose, `RigidBodyPosition::interpolate_velocity`; rapier.rs user
//! guide, "Rigid-body type").

use glam::{Quat, Vec3};
use parry3d::math::Pose;

use super::kinematic_script::Script;
use crate::World;
use crate::body::{BodyHandle, BodyKind, Keyframe};
use crate::error::WorldError;
use crate::settings::SolverSettings;

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

impl World {
    /// Sets the pose a kinematic body reaches at the end of the next step (Rapier's
    /// `set_next_kinematic_position`): that step moves it at the constant velocity that gets
    /// it there, so the bodies it touches are pushed and carried, and it then stays (velocity
    /// zero) until given a new target, unless it has keyframes, which resume. Errors for a
    /// removed or non-kinematic body, a non-finite translation or a zero rotation.
    pub fn set_kinematic_target(
        &mut self,
        handle: BodyHandle,
        translation: Vec3,
        rotation: Quat,
    ) -> Result<(), WorldError> {
        let i = self
            .handles
            .body(handle)
            .ok_or(WorldError::UnknownBody(handle))?;
        let refuse = |field: &str, message: String| {
            Err(WorldError::InvalidBody {
                body: i,
                name: self.bodies.name[i].clone(),
                field: field.to_string(),
                message,
            })
        };
        if self.bodies.kind[i] != BodyKind::Kinematic {
            return refuse(
                "kind",
                "only a kinematic body has a target pose".to_string(),
            );
        }
        let target = match crate::world::bodies::checked_pose(translation, rotation) {
            Ok(pose) => pose,
            Err((field, message)) => return refuse(field, message),
        };
        match self.scripts.iter_mut().find(|s| s.handle == handle) {
            Some(script) => script.target = Some(target),
            None => self.scripts.push(Script {
                handle,
                initial: self.bodies.pose[i],
                keyframes: Vec::new(),
                target: Some(target),
                step_target: None,
            }),
        }
        Ok(())
    }

    /// The kinematic stage: the kinematic bodies' velocities for the step, and (with continuous
    /// collision on) every body's pose at the step's start.
    pub(super) fn kinematic_stage(&mut self, settings: &SolverSettings) {
        self.kinematic_velocities();
        self.record_start_poses(settings);
    }

    /// As a step starts: each position-based kinematic body takes the velocity that carries it
    /// to its target (or keyframed) pose at the step's end, and every kinematic body counts as
    /// asleep exactly while it does not move (so that pairs of it and sleeping bodies are not
    /// recomputed, and a moving one wakes the islands it touches).
    fn kinematic_velocities(&mut self) {
        let dt = self.dt;
        let end_time = self.time + f64::from(dt);
        let handles = &self.handles;
        self.scripts.retain(|s| handles.body(s.handle).is_some());
        for script in &mut self.scripts {
            let Some(i) = self.handles.body(script.handle) else {
                continue;
            };
            script.step_target = script.target.take().or_else(|| {
                (!script.keyframes.is_empty())
                    .then(|| keyframed_pose(&script.initial, &script.keyframes, end_time))
            });
            let b = &mut self.bodies;
            (b.linear_velocity[i], b.angular_velocity[i]) = match &script.step_target {
                Some(target) => velocity_between(&b.pose[i], target, b.local_center_of_mass[i], dt),
                None => (Vec3::ZERO, Vec3::ZERO),
            };
        }
        // A target reached and no keyframes to follow: nothing left to script.
        self.scripts
            .retain(|s| s.step_target.is_some() || !s.keyframes.is_empty());
        self.moving_kinematic.clear();
        let b = &mut self.bodies;
        for i in 0..b.len() {
            if b.kind[i] == BodyKind::Kinematic {
                let still =
                    b.linear_velocity[i] == Vec3::ZERO && b.angular_velocity[i] == Vec3::ZERO;
                b.asleep[i] = still;
                b.sleep_time[i] = 0.0;
                if !still {
                    self.moving_kinematic.push(i as u32);
                }
            }
        }
    }

    /// As a step ends: every moving kinematic body moves by its velocities over dt, or to its
    /// step's target pose exactly when it has one.
    pub(super) fn move_kinematic_bodies(&mut self) {
        let dt = self.dt;
        for &i in &self.moving_kinematic {
            let i = i as usize;
            let b = &mut self.bodies;
            b.pose[i] = advance(
                &b.pose[i],
                b.local_center_of_mass[i],
                b.linear_velocity[i],
                b.angular_velocity[i],
                dt,
            );
        }
        for script in &mut self.scripts {
            if let (Some(target), Some(i)) = (script.step_target, self.handles.body(script.handle))
            {
                self.bodies.pose[i] = target;
            }
        }
    }
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
