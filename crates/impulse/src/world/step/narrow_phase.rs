//! The narrow phase stage ([`crate::Stage::NarrowPhase`]): contact manifolds of the candidate
//! pairs (Parry, `collision/narrow_phase.rs`), beside the broad phase tree's upkeep.

use crate::World;
use crate::collision::margins::SpeculativeMargins;
use crate::error::StepError;
use crate::parallel::both;
use crate::settings::SolverSettings;

impl World {
    /// The manifolds of the `candidates` (with their `margins`, recycled within `settings`'
    /// recycle distance), with the broad phase's tree optimised beside them (neither reads
    /// what the other writes).
    pub(super) fn narrow_phase_stage(
        &mut self,
        settings: &SolverSettings,
        parallel: bool,
        candidates: &[(u32, u32)],
        margins: &SpeculativeMargins,
    ) -> Result<(), StepError> {
        let (broad_phase, narrow_phase) = (&mut self.broad_phase, &mut self.narrow_phase);
        let bodies = &self.bodies;
        let recycle_distance = settings.contact.recycle_distance;
        let narrow =
            || narrow_phase.update(bodies, candidates, margins, recycle_distance, parallel);
        let of_body = &self.handles.of_body;
        both(parallel, || broad_phase.optimize(), narrow)
            .1
            .map_err(|pair| StepError::UnsupportedShapePair {
                body1: of_body[pair.0],
                body2: of_body[pair.1],
            })?;
        if self.bodies.roughness.iter().any(|&r| r > 0.0) {
            crate::contact::roughness::draw_new_manifolds(
                &mut self.narrow_phase.pairs,
                &mut self.bodies,
                self.seed,
                self.step_count,
            );
        }
        if self.bodies.impact_perturbation.iter().any(|&p| p > 0.0) {
            crate::contact::impact::draw_impacts(
                &mut self.narrow_phase.pairs,
                &self.bodies,
                self.seed,
                self.step_count,
            );
        }
        Ok(())
    }
}
