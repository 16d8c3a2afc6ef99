//! The rows' record as the step ends: each row's J·v* (`velocity_before`, the velocity its
//! rows had before this step's impulses, which the next step's restitution and the exported
//! LCP read), the natural-map residual ([`crate::StepDiagnostics::natural_map_residual`]) and
//! the count of rows with friction. One home for the three paths that take it:
//!
//! - an awake island solved in SIMD lanes took it from its bundles as its last substep ended
//!   (`IslandWorkspace::rows`, the lanes' `Bundles::record`), and its rows' J·v* and impulses
//!   stay there (`IslandWorkspace::impulses_in_lanes`) unless a pass over every row needs them;
//! - any other awake island takes it in one pass over its rows as its job ends, while they are
//!   still in cache ([`crate::diagnostics::record_velocity_before_and_residual`]);
//! - a sleeping island's rows take v* from the bodies' velocities, in one pass over every row
//!   at the finish ([`record_sleeping_rows`]); rows of awake islands (those in lanes have their
//!   impulses written back first) come out of that pass as their own record, to the last bits.
//!
//! The three give the same bits for the same rows on any thread count (tests in
//! `diagnostics/contact_lcp_tests.rs` and `solver/wide_tests.rs`).

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
    /// When any island slept through the step (`awake`), every row's v* from the bodies'
    /// velocities (one pass over all rows: the sleeping islands' rows get theirs, the awake
    /// islands' rows their own record again, to the bit).
    pub(super) fn record_sleeping_rows(
        &self,
        islands_of: &Islands,
        awake: &[bool],
        world_inverse_inertia: &[Mat3],
        constraints: &mut [ContactConstraint],
        workspaces: &mut [IslandWorkspace],
        scratch: &mut Vec<(Vec3, Vec3)>,
    ) {
        let islands = islands_of.len();
        if awake.iter().take(islands).any(|awake| !awake) {
            // The pass reads every row's impulses, which an awake island in lanes may have
            // kept in its lanes: they are written back first.
            for k in 0..islands {
                let w = &mut workspaces[k];
                if std::mem::take(&mut w.impulses_in_lanes) {
                    w.unpack_into(&mut constraints[islands_of.constraint_range(k)]);
                }
            }
            // The pass reads every row's I⁻¹(r × d), which the lanes keep in their bundles.
            contact::complete_products(constraints, world_inverse_inertia);
            contact::record_velocity_before(
                constraints,
                BodySlots::World,
                &self.bodies.linear_velocity,
                &self.bodies.angular_velocity,
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
