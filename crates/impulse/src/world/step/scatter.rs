//! The scatter stage ([`crate::Stage::Scatter`]): every awake island's velocities and poses
//! back into the bodies, then the moving kinematic bodies moved (`kinematic.rs`).

use crate::World;
use crate::body::Bodies;
use crate::island::Islands;
use crate::parallel::{BODIES_PER_TASK, for_each_of_three, spread};
use crate::solver::substep::{self, IslandWorkspace};

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
                    substep::scatter(islands.bodies(k), &workspaces[k], &mut self.bodies);
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
                substep::scatter_body(
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
