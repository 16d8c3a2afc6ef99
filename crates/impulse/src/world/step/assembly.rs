//! The assembly stage ([`crate::Stage::Assembly`]): one constraint per contact point, with its
//! Jacobian rows, effective masses and warm-start impulses (`contact/constraints.rs`).

use crate::World;
use crate::contact;
use crate::settings::SolverSettings;

impl World {
    /// The constraints of every island's points, each island's contiguous.
    pub(super) fn assembly_stage(&mut self, settings: &SolverSettings) {
        contact::assemble(
            &self.bodies,
            &self.narrow_phase,
            &self.islands,
            settings,
            &self.world_inverse_inertia,
            &self.world_center_of_mass,
            !self.any_restitution(),
            self.parallel,
            &mut self.constraints,
        );
        self.assemble_joints(settings.warm_start);
    }

    /// Whether any body has a restitution coefficient above zero (then islands end their step
    /// with a restitution solve).
    pub(super) fn any_restitution(&self) -> bool {
        self.bodies.restitution.iter().any(|&r| r > 0.0)
    }
}
