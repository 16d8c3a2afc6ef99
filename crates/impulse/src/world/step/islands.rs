//! The islands stage ([`crate::Stage::Islands`]): islands from the pairs (`island.rs`), and
//! every body's world inverse inertia tensor and centre of mass beside them.

use glam::{Mat3, Vec3};

use crate::World;
use crate::body::Bodies;
use crate::island::Islands;
use crate::parallel::{BODIES_PER_TASK, both, map_into, spread};
use crate::settings::SolverSettings;
use crate::solver::substep;

impl World {
    /// Islands from the pairs first (small components grouped under `settings`,
    /// [`substep::island_grouping`]), so that assembly writes each island's constraints
    /// contiguously and nothing has to be moved afterwards. The union-find is serial; the
    /// world inertia tensors and centres of mass (from the poses alone) are computed beside
    /// it, once a body rather than once for each of its pairs. Writes `islands`,
    /// `world_inverse_inertia` and `world_center_of_mass`.
    pub(super) fn islands_stage(
        &mut self,
        settings: &SolverSettings,
        parallel: bool,
        islands: &mut Islands,
        world_inverse_inertia: &mut Vec<Mat3>,
        world_center_of_mass: &mut Vec<Vec3>,
    ) {
        let joints = if self.joints.is_empty() {
            Vec::new()
        } else {
            self.active_joints()
        };
        let grouping = substep::island_grouping(settings, self.dt);
        let (bodies, pairs) = (&self.bodies, &self.narrow_phase.pairs);
        both(
            parallel,
            || {
                // R I_local⁻¹ Rᵀ (1/(kg·m²)), restricted to the free rotations of bodies with
                // locked rotation axes, zero for bodies that do not rotate; and each centre of
                // mass in the world (m).
                per_body(bodies, parallel, world_inverse_inertia, |i| {
                    bodies.world_inverse_inertia(i)
                });
                per_body(bodies, parallel, world_center_of_mass, |i| {
                    bodies.center_of_mass(i)
                });
            },
            || islands.build(bodies, pairs, &joints, grouping),
        );
    }
}

/// `of(i)` for every body `i` at its current pose, into `out` (in runs of bodies on rayon's
/// threads with `parallel`).
fn per_body<T: Send>(
    bodies: &Bodies,
    parallel: bool,
    out: &mut Vec<T>,
    of: impl Fn(usize) -> T + Sync + Send,
) {
    map_into(
        spread(parallel, 1, 0),
        bodies.len(),
        BODIES_PER_TASK,
        of,
        out,
    );
}
