//! The solve stage's restitution solve ([`crate::Stage::Solve`]), once per island after its
//! substeps: the bounce targets of the points that collided (Newton's hypothesis, or
//! generalized reflections), then one solve of contacts and joints together when any point
//! bounces (docs/method.md, "Targets: restitution, gaps and repair").

use super::bounce_energy::BounceIsland;
use super::impact;
use super::interface::{SolvePass, Sweep};
use super::island_workspace::IslandWorkspace;
use super::rows::{self, Velocities};
use super::substep::{IslandContext, JOINT_SWEEPS};
use crate::contact::{self, ContactConstraint};
use crate::parallel::RESTITUTION_POINTS_PER_TASK;
use crate::settings::{ImpactModel, SolverSettings};

impl IslandWorkspace {
    /// Restitution after the substeps (Newton's v⁺ = −c_r·v⁻, v⁻ from the start of the step),
    /// for the points that collided: their targets (or `impact: propagation`'s reflections),
    /// then one solve when any point bounces.
    pub(super) fn restitution(
        &mut self,
        island_bodies: &[u32],
        guests: &[u32],
        constraints: &mut [ContactConstraint],
        settings: &SolverSettings,
        context: &IslandContext<'_>,
        spread: bool,
    ) {
        let w = self;
        let threshold = settings.contact.restitution_threshold;
        let bounces = if !context.restitution {
            // No body bounces, so no pair does (a pair's coefficient is the larger of its
            // bodies').
            false
        } else if settings.contact.impact == ImpactModel::Propagation {
            let mut velocities = Velocities {
                linear: &mut w.linear,
                angular: &mut w.angular,
            };
            let island = (island_bodies, guests, context.bodies);
            w.impact
                .propagate(constraints, island, &mut velocities, context.dt, settings)
        } else if spread {
            // Per point: any split gives the same targets.
            use rayon::prelude::*;
            constraints
                .par_chunks_mut(RESTITUTION_POINTS_PER_TASK)
                .map(|part| contact::restitution_targets(part, threshold, &w.rotation))
                .reduce(|| false, |x, y| x || y)
        } else {
            contact::restitution_targets(constraints, threshold, &w.rotation)
        };
        if !bounces {
            return;
        }
        w.bounce_energy.start(
            (&w.linear, &w.angular),
            constraints,
            island_bodies.len(),
            (!w.joints.is_empty(), context.forces),
        );
        // With joints the bounce is a coupled problem: one sweep (the soft step's) takes the
        // joints first and the contacts after them, so the bounce would be that of bodies the
        // joints do not hold (a hinged door struck by a ball spun 37 % faster than the closed
        // form), and the joints would answer only in the next step. It sweeps to the tolerance,
        // like an impact's substeps (`JOINT_SWEEPS`).
        let sweeps = impact::restitution_iterations(settings);
        let pass = SolvePass {
            iterations: if w.joints.is_empty() {
                sweeps
            } else {
                sweeps.max(JOINT_SWEEPS)
            },
            tolerance: settings.solve.tolerance,
            friction: true,
            half_turn: false,
            warm_start_follows: false,
            escalate: false,
            targets: None,
            sweep: Sweep {
                starts: &w.colour_starts,
                parallel: w.parallel,
            },
        };
        // The step totals gain what the restitution solve adds to each impulse.
        for c in constraints.iter_mut() {
            let before = rows::impulses(c);
            for (total, before) in c.step_impulses.iter_mut().zip(before) {
                *total -= before;
            }
        }
        // The joints hold through the bounce with the relax solve's targets, set after the
        // last substep's positions.
        for joint in &mut w.joints {
            joint.start_bounce();
        }
        let outcome = w.solvers.scalar(settings.solve.method).solve(
            constraints,
            &mut Velocities {
                linear: &mut w.linear,
                angular: &mut w.angular,
            },
            &mut w.joints,
            &pass,
        );
        // An impact of passive bodies gains no kinetic energy (`bounce_energy`).
        let island = BounceIsland {
            island_bodies,
            bodies: context.bodies,
            gravity: context.gravity,
            displacement: &w.displacement,
            orientation: &w.orientation,
        };
        let velocities = (&mut w.linear[..], &mut w.angular[..]);
        w.bounce_energy.bound(&island, velocities, constraints);
        for c in constraints.iter_mut() {
            rows::add_step_impulses(c);
        }
        for joint in &mut w.joints {
            joint.finish_bounce();
        }
        w.record(&outcome, false);
        w.impact.finish(constraints);
    }
}
