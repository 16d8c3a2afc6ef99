//! Kinematic bodies in the world: their velocities as a step starts (from keyframes or a
//! target pose), their poses as it ends, and the target-pose edit.

use glam::{Quat, Vec3};

use super::World;
use crate::body::{BodyHandle, BodyKind};
use crate::error::WorldError;
use crate::kinematic::{self, Script};

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
        let target = match super::bodies::checked_pose(translation, rotation) {
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

    /// As a step starts: each position-based kinematic body takes the velocity that carries it
    /// to its target (or keyframed) pose at the step's end, and every kinematic body counts as
    /// asleep exactly while it does not move (so that pairs of it and sleeping bodies are not
    /// recomputed, and a moving one wakes the islands it touches).
    pub(super) fn kinematic_velocities(&mut self) {
        let dt = self.dt;
        let end_time = self.time + f64::from(dt);
        let handles = &self.handles;
        self.scripts.retain(|s| handles.body(s.handle).is_some());
        for script in &mut self.scripts {
            let Some(i) = self.handles.body(script.handle) else {
                continue;
            };
            script.step_target = script.target.take().or_else(|| {
                (!script.keyframes.is_empty()).then(|| {
                    kinematic::keyframed_pose(&script.initial, &script.keyframes, end_time)
                })
            });
            let b = &mut self.bodies;
            (b.linear_velocity[i], b.angular_velocity[i]) = match &script.step_target {
                Some(target) => {
                    kinematic::velocity_between(&b.pose[i], target, b.local_center_of_mass[i], dt)
                }
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
            b.pose[i] = kinematic::advance(
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
