//! The broad phase stage ([`crate::Stage::BroadPhase`]): speculative margins and candidate
//! pairs on the poses and velocities at the step's start (`collision/broad_phase.rs`).

use crate::World;
use crate::settings::SolverSettings;

impl World {
    /// Each body's speculative margin, then the candidate pairs of bodies whose loosened boxes
    /// overlap (both on rayon's threads with `parallel`).
    pub(super) fn broad_phase_stage(&mut self, settings: &SolverSettings, parallel: bool) {
        self.margins.set_substeps(settings.substeps);
        self.margins.update(
            &self.bodies,
            settings.prediction_distance,
            self.gravity,
            self.dt,
            parallel,
        );
        self.broad_phase.candidate_pairs(
            &self.bodies,
            self.margins.margins(),
            parallel,
            &mut self.candidates,
        );
        // Bodies joined by a joint do not collide unless the joint says so.
        if !self.joints.is_empty() {
            let joined = self.joined_pairs();
            if !joined.is_empty() {
                self.candidates
                    .retain(|&(a, b)| joined.binary_search(&(a.min(b), a.max(b))).is_err());
            }
        }
    }
}
