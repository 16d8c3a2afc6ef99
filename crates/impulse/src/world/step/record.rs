//! The rows' record as the step ends: each row's J·v* (`velocity_before`, the velocity its
//! rows had before this step's impulses, which the next step's restitution and the exported
//! LCP read), the natural-map residual ([`crate::StepDiagnostics::natural_map_residual`]) and
//! the count of rows with friction. One home for the three paths that take it:
//!
//! - an awake island solved in SIMD lanes took it from its bundles as its last substep ended
//!   (`IslandWorkspace::rows`, the lanes' `Bundles::record`), and its rows' J·v* and impulses
//!   stay there (`IslandWorkspace::impulses_in_lanes`) until a reader of the rows asks for them;
//! - any other awake island takes it in one pass over its rows as its job ends, while they are
//!   still in cache ([`crate::diagnostics::record_velocity_before_and_residual`]);
//! - a sleeping island's rows take v* from its bodies' velocities at the finish, in one pass
//!   over its own rows in island slots ([`World::record_sleeping_rows`]): the finish costs the
//!   sleeping rows, not every row.
//!
//! Each gives the same bits on any thread count (tests in `diagnostics/contact_lcp_tests.rs`
//! and `solver/wide_tests.rs`).

use glam::{Mat3, Vec3};

use crate::World;
use crate::contact::{self, BodySlots, ContactConstraint};
use crate::diagnostics;
use crate::island::Islands;
use crate::solver::substep::IslandWorkspace;

/// Ends an awake island's job: its rows' record, the lanes' if they took it, else one pass over
/// the rows; the residual goes into the island's report and its friction rows beside it.
pub(super) fn end_island(
    rows: &mut [ContactConstraint],
    workspace: &mut IslandWorkspace,
    parallel: bool,
) {
    let report = match workspace.rows.take() {
        Some(report) => report,
        None => diagnostics::record_velocity_before_and_residual(
            rows,
            BodySlots::Island,
            &workspace.linear,
            &workspace.angular,
            parallel,
            &mut workspace.record_scratch,
        ),
    };
    workspace.report.natural_map_residual = report.natural_map_residual;
    workspace.friction_rows = report.friction_rows;
}

impl World {
    /// The record of the rows of the islands that slept through the step (`awake` false):
    /// each such island's rows take v* from its bodies' velocities in one pass over its own
    /// rows, in island slots ([`BodySlots::Island`]) as an awake island's own pass does, so
    /// the cost follows the sleeping rows, not the world's. `velocities` holds one island's
    /// local (linear, angular) arrays at a time; `scratch` the pass's per-body deltas.
    pub(super) fn record_sleeping_rows(
        &self,
        islands_of: &Islands,
        awake: &[bool],
        world_inverse_inertia: &[Mat3],
        constraints: &mut [ContactConstraint],
        velocities: &mut (Vec<Vec3>, Vec<Vec3>),
        scratch: &mut Vec<(Vec3, Vec3)>,
    ) {
        let bodies = &self.bodies;
        for k in (0..islands_of.len()).filter(|&k| !awake[k]) {
            let rows = &mut constraints[islands_of.constraint_range(k)];
            if rows.is_empty() {
                continue;
            }
            // The pass reads every row's I⁻¹(r × d), which a row may have left pending.
            contact::complete_products(rows, world_inverse_inertia);
            let (linear, angular) = velocities;
            bodies.gather_slot_velocities(
                islands_of.bodies(k),
                islands_of.guests(k),
                linear,
                angular,
            );
            contact::record_velocity_before(
                rows,
                BodySlots::Island,
                linear,
                angular,
                self.parallel,
                scratch,
            );
        }
    }

    /// The step's natural-map residual (the islands' added as a 2-norm, in island order), its
    /// rows with friction, and the reports of the awake islands with contacts, from the
    /// islands' records; a sleeping island's rows are counted here.
    pub(super) fn rows_summary(
        &mut self,
        islands_of: &Islands,
        awake: &[bool],
        constraints: &[ContactConstraint],
        workspaces: &[IslandWorkspace],
    ) -> (f32, usize) {
        let islands = islands_of.len();
        // Only awake islands were solved this step; sleeping ones keep last step's state.
        let mut squared = 0.0f64;
        let mut friction_rows = 0;
        // Reuse last step's list: no allocation per step once it has grown.
        let mut island_reports = std::mem::take(&mut self.diagnostics.islands);
        island_reports.clear();
        for k in 0..islands {
            let range = islands_of.constraint_range(k);
            if awake[k] {
                let mut report = workspaces[k].report;
                report.deepest_contact = crate::world::contacts::deepest_contact(
                    &constraints[range.clone()],
                    &self.narrow_phase.pairs,
                    &self.bodies,
                );
                let part = report.natural_map_residual as f64;
                squared += part * part;
                friction_rows += workspaces[k].friction_rows;
                if !range.is_empty() {
                    island_reports.push(report);
                }
            } else {
                friction_rows += self::friction_rows(&constraints[range]);
            }
        }
        self.diagnostics.islands = island_reports;
        (squared.sqrt() as f32, friction_rows)
    }
}

/// Contact points with friction (μ > 0): each adds two tangent rows to the step's LCP.
fn friction_rows(constraints: &[ContactConstraint]) -> usize {
    constraints.iter().filter(|c| c.friction > 0.0).count()
}
