//! The kinematic stage ([`crate::Stage::Kinematic`]): kinematic bodies' velocities as a step
//! starts and their poses as it ends (the maths in `body/motion.rs`; the target-pose edit,
//! `World::set_kinematic_target`, in `world/bodies.rs`).
//!
//! A kinematic body is velocity-based (it keeps the velocities it is given and moves by them)
//! or position-based (keyframes, or a target pose for the next step): each step then takes
//! the velocity that reaches the target pose at the step's end, so that the contacts see the
//! body's motion, and ends the step exactly at the target.

use glam::Vec3;
use parry3d::math::Pose;

use crate::World;
use crate::body::BodyKind;
use crate::body::motion::{advance, keyframed_pose, velocity_between};
use crate::settings::SolverSettings;

impl World {
    /// The kinematic stage: the kinematic bodies' velocities for the step (writes
    /// `moving_kinematic`), and (with continuous collision on) every body's pose at the step's
    /// start (writes `start_poses`).
    pub(super) fn kinematic_stage(
        &mut self,
        settings: &SolverSettings,
        moving_kinematic: &mut Vec<u32>,
        start_poses: &mut Vec<Pose>,
    ) {
        self.kinematic_velocities(moving_kinematic);
        if settings.continuous {
            start_poses.clone_from(&self.bodies.pose);
        } else {
            start_poses.clear();
        }
    }

    /// As a step starts: each position-based kinematic body takes the velocity that carries it
    /// to its target (or keyframed) pose at the step's end, and every kinematic body counts as
    /// asleep exactly while it does not move (so that pairs of it and sleeping bodies are not
    /// recomputed, and a moving one wakes the islands it touches).
    fn kinematic_velocities(&mut self, moving_kinematic: &mut Vec<u32>) {
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
        moving_kinematic.clear();
        let b = &mut self.bodies;
        for i in 0..b.len() {
            if b.kind[i] == BodyKind::Kinematic {
                let still =
                    b.linear_velocity[i] == Vec3::ZERO && b.angular_velocity[i] == Vec3::ZERO;
                b.asleep[i] = still;
                b.sleep_time[i] = 0.0;
                if !still {
                    moving_kinematic.push(i as u32);
                }
            }
        }
    }

    /// As a step ends: every moving kinematic body (`moving_kinematic`) moves by its
    /// velocities over dt, or to its step's target pose exactly when it has one.
    pub(super) fn move_kinematic_bodies(&mut self, moving_kinematic: &[u32]) {
        let dt = self.dt;
        for &i in moving_kinematic {
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
