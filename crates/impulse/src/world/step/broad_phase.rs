//! The broad phase stage ([`crate::Stage::BroadPhase`]): speculative margins and candidate
//! pairs on the poses and velocities at the step's start (`collision/broad_phase.rs`).

use crate::World;
use crate::collision::margins::SpeculativeMargins;
use crate::settings::SolverSettings;

impl World {
    /// Each body's speculative margin (writes `margins`), then the candidate pairs of bodies
    /// whose loosened boxes overlap (writes `candidates`), both on rayon's threads with
    /// `parallel`.
    pub(super) fn broad_phase_stage(
        &mut self,
        settings: &SolverSettings,
        parallel: bool,
        margins: &mut SpeculativeMargins,
        candidates: &mut Vec<(u32, u32)>,
    ) {
        margins.set_substeps(settings.solve.substeps);
        margins.update(
            &self.bodies,
            settings.contact.prediction_distance,
            self.gravity,
            self.dt,
            parallel,
        );
        self.broad_phase
            .candidate_pairs(&self.bodies, margins.margins(), parallel, candidates);
        // Bodies joined by a joint do not collide unless the joint says so.
        if !self.joints.is_empty() {
            let joined = self.joined_pairs();
            if !joined.is_empty() {
                candidates.retain(|&(a, b)| joined.binary_search(&(a.min(b), a.max(b))).is_err());
            }
        }
    }
}
