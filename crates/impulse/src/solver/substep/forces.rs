//! A substep's velocity changes before its contacts are solved (gravity, applied forces,
//! damping, locked axes, the gyroscopic term), on an island's gathered bodies.

use glam::Vec3;

use super::{IslandWorkspace, SolvePlan};
use crate::integrate;
use crate::parallel::BODIES_PER_TASK;

impl IslandWorkspace {
    /// A substep's velocity changes before the contacts are solved: gravity, applied forces,
    /// damping, locked axes and the gyroscopic term.
    pub(super) fn apply_forces(&mut self, gravity: Vec3, plan: &SolvePlan) {
        let (h, moving) = (plan.h, plan.moving);
        let w = self;
        integrate::prospective_velocities(&mut w.linear[..moving], gravity, h);
        for (k, &(linear, angular)) in w.acceleration.iter().enumerate() {
            w.linear[k] += linear * h;
            w.angular[k] += angular * h;
        }
        // Damping after gravity and forces, implicit: v ← v/(1 + h·c) (Box2D's damping).
        for (k, &(linear, angular)) in w.damping.iter().enumerate() {
            w.linear[k] *= linear;
            w.angular[k] *= angular;
        }
        // Locked components stay zero: gravity is the one velocity change above that does
        // not go through the inverse mass.
        for &(k, free) in &w.translation_locks {
            w.linear[k as usize] *= free;
        }
        // The gyroscopic term, per body at its current orientation, with the other velocity
        // updates before the contacts are solved (as Bullet applies it with the external forces).
        if !w.inertia.is_empty() {
            let angular = &mut w.angular[..moving];
            if plan.spread {
                use rayon::prelude::*;
                angular
                    .par_chunks_mut(BODIES_PER_TASK)
                    .zip(w.orientation.par_chunks(BODIES_PER_TASK))
                    .zip(w.inertia.par_chunks(BODIES_PER_TASK))
                    .for_each(|((a, o), t)| integrate::gyroscopic(a, o, t, h));
            } else {
                integrate::gyroscopic(angular, &w.orientation, &w.inertia, h);
            }
        }
        for (k, locked, tensor) in &w.rotation_locks {
            let k = *k as usize;
            integrate::gyroscopic_in_plane(
                &mut w.angular[k],
                w.orientation[k],
                tensor,
                usize::from(*locked),
                h,
            );
        }
    }
}
