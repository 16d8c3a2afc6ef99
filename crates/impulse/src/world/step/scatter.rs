//! The scatter stage ([`crate::Stage::Scatter`]): every awake island's velocities and poses
//! back into the bodies, then the moving kinematic bodies moved (`kinematic.rs`).

use glam::Vec3;
use parry3d::math::Pose;

use crate::World;
use crate::body::Bodies;
use crate::island::Islands;
use crate::parallel::{BODIES_PER_TASK, for_each_of_three, spread};
use crate::solver::substep::IslandWorkspace;

impl World {
    /// Island results (the solve's `workspaces` of the islands it woke, `island_awake`) into
    /// the bodies, then the `moving_kinematic` bodies to their step's end poses.
    pub(super) fn scatter_stage(
        &mut self,
        islands: &Islands,
        island_awake: &[bool],
        workspaces: &[IslandWorkspace],
        moving_kinematic: &[u32],
    ) {
        self.scatter_islands(islands, island_awake, workspaces);
        self.move_kinematic_bodies(moving_kinematic);
    }

    /// Writes every awake island's velocities and poses back into the bodies. In parallel,
    /// runs of bodies each look up their island and local index (islands can be many and
    /// small, or one and large; body runs split either evenly).
    fn scatter_islands(
        &mut self,
        islands: &Islands,
        awake: &[bool],
        workspaces: &[IslandWorkspace],
    ) {
        if !spread(self.parallel, self.bodies.len(), BODIES_PER_TASK) {
            for k in 0..islands.len() {
                if awake[k] {
                    scatter(islands.bodies(k), &workspaces[k], &mut self.bodies);
                }
            }
            return;
        }
        let Bodies {
            pose,
            linear_velocity,
            angular_velocity,
            local_center_of_mass,
            ..
        } = &mut self.bodies;
        for_each_of_three(
            true,
            (pose, linear_velocity, angular_velocity),
            BODIES_PER_TASK,
            |i, pose, linear, angular| {
                let Some(&k) = islands.island_of_body.get(i) else {
                    return;
                };
                if k == u32::MAX || !awake[k as usize] {
                    return;
                }
                scatter_body(
                    &workspaces[k as usize],
                    islands.local_index(i),
                    local_center_of_mass[i],
                    pose,
                    linear,
                    angular,
                );
            },
        );
    }
}

/// Writes an island's velocities and poses back into the bodies.
fn scatter(island_bodies: &[u32], workspace: &IslandWorkspace, bodies: &mut Bodies) {
    for (k, &i) in island_bodies.iter().enumerate() {
        let i = i as usize;
        scatter_body(
            workspace,
            k,
            bodies.local_center_of_mass[i],
            &mut bodies.pose[i],
            &mut bodies.linear_velocity[i],
            &mut bodies.angular_velocity[i],
        );
    }
}

/// Writes the body at local index `k` of `workspace`'s island back: its velocities and its
/// pose (the centre of mass moved by the island's displacement, at its new orientation).
#[inline]
fn scatter_body(
    workspace: &IslandWorkspace,
    k: usize,
    local_center_of_mass: Vec3,
    pose: &mut Pose,
    linear: &mut Vec3,
    angular: &mut Vec3,
) {
    let com = pose.transform_point(local_center_of_mass) + workspace.displacement[k];
    let rotation = workspace.orientation[k];
    *linear = workspace.linear[k];
    *angular = workspace.angular[k];
    pose.rotation = rotation;
    pose.translation = com - rotation * local_center_of_mass;
}
