//! The islands stage ([`crate::Stage::Islands`]): islands from the pairs (`island.rs`), and
//! every body's world inverse inertia tensor and centre of mass beside them.

use glam::{Mat3, Vec3};

use crate::World;
use crate::body::Bodies;
use crate::parallel::{BODIES_PER_TASK, both, map_into, spread};

impl World {
    /// Islands from the pairs first, so that assembly writes each island's constraints
    /// contiguously and nothing has to be moved afterwards. The union-find is serial; the
    /// world inertia tensors and centres of mass (from the poses alone) are computed beside
    /// it, once a body rather than once for each of its pairs.
    pub(super) fn islands_stage(&mut self, parallel: bool) {
        let joints = if self.joints.is_empty() {
            Vec::new()
        } else {
            self.active_joints()
        };
        let (islands, world_inverse_inertia, world_center_of_mass) = (
            &mut self.islands,
            &mut self.world_inverse_inertia,
            &mut self.world_center_of_mass,
        );
        let (bodies, pairs) = (&self.bodies, &self.narrow_phase.pairs);
        both(
            parallel,
            || {
                world_inverse_inertia_of(bodies, parallel, world_inverse_inertia);
                world_center_of_mass_of(bodies, parallel, world_center_of_mass);
            },
            || islands.build(bodies, pairs, &joints),
        );
    }
}

/// World-frame inverse inertia tensors I⁻¹ = R I_local⁻¹ Rᵀ (1/(kg·m²)) of every body at its
/// current pose, restricted to the free rotations of bodies with locked rotation axes
/// (`Bodies::world_inverse_inertia`); zero for bodies that do not rotate.
fn world_inverse_inertia_of(bodies: &Bodies, parallel: bool, out: &mut Vec<Mat3>) {
    map_into(
        spread(parallel, 1, 0),
        bodies.len(),
        BODIES_PER_TASK,
        |i| bodies.world_inverse_inertia(i),
        out,
    );
}

/// Every body's centre of mass in the world (m) at its current pose
/// (`Bodies::center_of_mass`).
fn world_center_of_mass_of(bodies: &Bodies, parallel: bool, out: &mut Vec<Vec3>) {
    map_into(
        spread(parallel, 1, 0),
        bodies.len(),
        BODIES_PER_TASK,
        |i| bodies.center_of_mass(i),
        out,
    );
}
