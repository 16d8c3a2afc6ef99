//! The assembly stage ([`crate::Stage::Assembly`]): one constraint per contact point, with its
//! Jacobian rows, effective masses and warm-start impulses (`contact/assembly.rs`).

use glam::{Mat3, Vec3};

use crate::World;
use crate::contact::{self, ContactConstraint};
use crate::island::Islands;
use crate::settings::SolverSettings;
use crate::solver::substep::IslandWorkspace;

impl World {
    /// The constraints of every island's points, each island's contiguous (writes
    /// `constraints`), and the joints' rows into their islands' `workspaces`, from the islands
    /// stage's `islands`, `world_inverse_inertia` and `world_center_of_mass`.
    pub(super) fn assembly_stage(
        &mut self,
        settings: &SolverSettings,
        islands: &Islands,
        world_inverse_inertia: &[Mat3],
        world_center_of_mass: &[Vec3],
        constraints: &mut Vec<ContactConstraint>,
        workspaces: &mut Vec<IslandWorkspace>,
    ) {
        contact::assemble(
            &self.bodies,
            &self.narrow_phase,
            islands,
            settings,
            world_inverse_inertia,
            world_center_of_mass,
            !self.any_restitution(),
            self.parallel,
            constraints,
        );
        self.assemble_joints(
            settings.solve.warm_start,
            islands,
            world_inverse_inertia,
            workspaces,
        );
    }

    /// Whether any body has a restitution coefficient or an impact perturbation above zero
    /// (then islands end their step with a restitution solve).
    pub(super) fn any_restitution(&self) -> bool {
        self.bodies.restitution.iter().any(|&r| r > 0.0)
            || self.bodies.impact_perturbation.iter().any(|&p| p > 0.0)
    }
}
