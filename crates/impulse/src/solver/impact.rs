//! Simultaneous impacts by generalized reflections (`solver.impact: "propagation"`;
//! docs/method.md, "Simultaneous impacts").
//!
//! The method's restitution ([`crate::settings::ImpactModel::Simultaneous`]) asks every point
//! that collided in a step for v⁺ = −c_r·v⁻ in one LCP. Touching bodies that were not
//! approaching keep the target 0, so a struck row of touching balls leaves together: the impact
//! does not travel through it, and Newton's cradle fails. Here the impact is resolved as
//! Smith, Kaufman, Vouga, Tamstorf and Grinspun's generalized reflections ("Reflections on
//! simultaneous impact", SIGGRAPH 2012), from the island's velocities u⁻ at the step's start:
//!
//! 1. the **active set** is the normal rows that approach, J_i·u < −ε, and are in contact: they
//!    pushed during the step, or their gap s closes within it at this speed (s + J_i·u·dt < 0);
//! 2. the active rows are **projected** to rest together: impulses λ ≥ 0 with J_i·u' ≥ 0 and
//!    λ_i·J_i·u' = 0, u' = u + M⁻¹Jᵀλ (the inelastic LCP of the active rows alone, solved by
//!    projected Gauss-Seidel to a tight tolerance);
//! 3. the projection is **reflected**: u ← u + M⁻¹Jᵀ((1 + e)·λ), with one e for the set: when
//!    some rows approach faster than `restitution_threshold` the set is those rows alone and e
//!    the smallest of their pairs' c_r, otherwise e = 0 (a set with mixed coefficients could
//!    gain energy);
//! 4. the rows of the bodies that changed are examined again, until no row is active.
//!
//! Rows that were touching but not approaching take no impulse in a round, so bodies may break
//! away; an impact passes down a chain of touching bodies one contact per round, and two
//! contacts reached at once (a ball striking the apex of a rack) are resolved together, so
//! symmetric impacts stay symmetric. With e = 1 every round keeps kinetic energy (the
//! projection onto the cone J_A·u ≥ 0 in the metric of M is orthogonal to the reflected part)
//! and momentum (internal impulses); with e < 1 a round loses (1 − e²) of the energy the
//! projection removes, the two-body closed form for a single contact.
//!
//! Inelastic collapse (ever shorter sequences of collisions when e < 1) and pathological
//! elastic sequences are cut off as Smith et al. propose: after [`ROUNDS_BASE`] +
//! [`ROUNDS_PER_ROW`]·rows rounds the remaining rounds are plastic (e = 0), which dissipate
//! and end; after twice as many the propagation stops and leaves what remains to the solve that
//! follows.
//!
//! The result enters the step through the restitution solve after the substeps: each row the
//! reflections pushed gets as its target the normal velocity the reflections left it, J_i·u⁺,
//! and the impulse the substeps gave it over the step is replaced by the reflections' total:
//! the difference is applied to the velocities and added to the row's accumulated impulse, as
//! the one-LCP restitution adds its bounce, so the friction disc allows μ times it. The solve
//! thus starts at the reflected velocities and only adds what the rest of the step asks
//! (support against gravity, friction, contacts the impact did not reach).
//! [`ImpactWorkspace::finish`] then takes each pushed row's accumulated impulse as the
//! reflections left it back out, keeping only what the restitution solve added beyond it: the
//! accumulated impulses are the next step's warm start, and an impact must not be given a
//! second time. That includes the substeps' own impulse on the row, which is the impact's
//! too: when the collision falls in a step's last substep, that substep's soft contact holds
//! half of it, and warm-started it pushed a row of four balls in apart again in the next step
//! (0.875 and 1.042 m/s instead of 1).

use glam::Vec3;

use super::rows::{Velocities, apply_impulses};
use crate::body::Bodies;
use crate::contact::ContactConstraint;
use crate::contact::cap_to_disc;
use crate::settings::SolverSettings;

/// Rounds of reflections per island and step before the remaining ones are made plastic:
/// this plus [`ROUNDS_PER_ROW`] per normal row. A chain of n bodies struck at one end takes
/// n − 1 rounds; a packed rack of 15 billiard balls a few tens.
pub(crate) const ROUNDS_BASE: usize = 64;

/// See [`ROUNDS_BASE`].
pub(crate) const ROUNDS_PER_ROW: usize = 4;

/// Most projected Gauss-Seidel sweeps of one round's projection. A round's active set is
/// usually one contact or a few around one body, solved in one or two sweeps.
const PROJECTION_SWEEPS: u32 = 256;

/// Sweeps (at least; early exit at `tolerance`) of the restitution solve. After a propagation
/// it starts at the reflected velocities, so it only has to add what the rest of the step
/// asks, but that can be a chain's support against gravity, which one sweep does not carry.
/// With `"simultaneous"` it is the impact's one LCP, which conserves kinetic energy at c_r = 1
/// only when solved: at the soft step's one sweep, a row of five touching balls struck at one
/// end kept a third of its energy (0.166 J of 0.5 J; solved, all of it).
pub(crate) const RESTITUTION_SWEEPS: u32 = 32;

/// Velocity tolerance of the propagation relative to the fastest approach that set it off: a
/// row approaching slower than this fraction of that speed (or `tolerance`, if larger) counts
/// as at rest. Single precision resolves velocities to about 1e-7 of their size.
const RELATIVE_TOLERANCE: f32 = 1e-5;

/// Sweeps of the restitution solve after the substeps for `settings`: the larger of the
/// solve and relax budgets, and at least [`RESTITUTION_SWEEPS`] (the solve stops early at
/// `tolerance`; it runs only in islands where some point bounces).
pub(crate) fn restitution_iterations(settings: &SolverSettings) -> u32 {
    settings
        .solve
        .iterations
        .max(settings.solve.relax_iterations)
        .max(RESTITUTION_SWEEPS)
}

/// Work space of one island's propagation, kept between steps.
#[derive(Default)]
pub(crate) struct ImpactWorkspace {
    /// Per slot, the propagation's linear velocities (m/s), from the step's start.
    linear: Vec<Vec3>,
    /// Per slot, angular velocities (rad/s).
    angular: Vec<Vec3>,
    /// Per row, the reflections' accumulated normal impulse Λ (N·s).
    impulse: Vec<f32>,
    /// Per row, the current round's projection impulse λ (N·s).
    projection: Vec<f32>,
    /// The current round's restitution coefficient e, one for the whole active set.
    coefficient: f32,
    /// Per row, the last round it was queued for, so each is examined once a round.
    queued: Vec<u32>,
    /// Rows to examine this round.
    candidates: Vec<u32>,
    /// Rows of the current round's active set, in constraint order.
    active: Vec<u32>,
    /// Rows by moving slot: those of slot k are `slot_rows[slot_starts[k]..slot_starts[k + 1]]`.
    slot_starts: Vec<u32>,
    /// See `slot_starts`.
    slot_rows: Vec<u32>,
    /// Per moving slot, the next free place of its rows while they are listed.
    cursor: Vec<u32>,
    /// Per row the reflections pushed, its accumulated normal impulse as [`Self::propagate`]
    /// left it (N·s), which [`Self::finish`] takes out again.
    added: Vec<f32>,
    /// Whether `added` is waiting for [`Self::finish`].
    pending: bool,
    /// Rounds of the last propagation (0 when none ran).
    pub rounds: u32,
}

/// A row's normal velocity J·u (m/s) in the slot velocities `linear`, `angular`.
#[inline]
fn normal_velocity(c: &ContactConstraint, linear: &[Vec3], angular: &[Vec3]) -> f32 {
    let (a, b) = (c.local_a as usize, c.local_b as usize);
    c.normal
        .velocity(linear[a], angular[a], linear[b], angular[b])
}

/// Adds the normal impulse `impulse` (N·s) of row `c` to the slot velocities.
#[inline]
fn push(c: &ContactConstraint, impulse: f32, linear: &mut [Vec3], angular: &mut [Vec3]) {
    apply_impulses(c, [impulse, 0.0, 0.0], &mut Velocities { linear, angular });
}

impl ImpactWorkspace {
    /// Runs the propagation on one island after its substeps and sets the restitution
    /// targets of the rows it pushed (see the module docs); returns whether any row bounces,
    /// i.e. whether the restitution solve is to run. Nothing changes when no point collided
    /// (restitution above zero, approach faster than `restitution_threshold`, a normal impulse
    /// received during the step), so resting contacts keep the trajectories of
    /// [`crate::settings::ImpactModel::Simultaneous`] to the bit.
    ///
    /// `island` is (the island's bodies, its guests, all bodies): the first two name the slots
    /// as [`super::substep::step_island`] laid them out (the immovable slot last); the bodies
    /// still hold the velocities of the step's
    /// start, the pre-impact u⁻. `velocities` are the island's after the substeps, which are
    /// shifted by the change of each pushed row's impulse; `dt` is the step (s).
    pub(crate) fn propagate(
        &mut self,
        constraints: &mut [ContactConstraint],
        (island_bodies, guests, bodies): (&[u32], &[u32], &Bodies),
        velocities: &mut Velocities<'_>,
        dt: f32,
        settings: &SolverSettings,
    ) -> bool {
        self.rounds = 0;
        let threshold = settings.contact.restitution_threshold;
        let speed = constraints
            .iter()
            .filter(|c| c.restitution > 0.0 && c.max_normal_impulse > 0.0)
            .map(|c| -c.normal.velocity_before)
            .filter(|&approach| approach > threshold)
            .fold(0.0f32, f32::max);
        if speed <= 0.0 {
            return false;
        }
        let tolerance = settings.solve.tolerance.max(RELATIVE_TOLERANCE * speed);
        self.gather(island_bodies, guests, bodies);
        let moving = island_bodies.len();
        self.index_rows(constraints, moving);

        let rows = constraints.len();
        self.impulse.clear();
        self.impulse.resize(rows, 0.0);
        self.projection.clear();
        self.projection.resize(rows, 0.0);
        self.queued.clear();
        self.queued.resize(rows, 0);
        self.candidates.clear();
        self.candidates.extend(0..rows as u32);
        let elastic_rounds = ROUNDS_BASE + ROUNDS_PER_ROW * rows;
        for round in 0..2 * elastic_rounds {
            self.select_active(
                constraints,
                tolerance,
                dt,
                threshold,
                round < elastic_rounds,
            );
            if self.active.is_empty() {
                break;
            }
            self.rounds += 1;
            self.project(constraints, 0.1 * tolerance);
            self.reflect(constraints);
            self.queue_neighbours(constraints, moving, round as u32 + 1);
        }

        // On the rows they pushed, the reflections' impulses replace what the substeps gave
        // over the step (each substep's warm start applies the last one's impulse, so the
        // velocities carry the step total). The difference is applied now and also added to the
        // row's accumulated impulse, as the restitution solve of `Simultaneous` adds its bounce
        // to it: the friction disc of the solve that follows then allows μ times the impulse
        // beyond the substeps', and that solve may take back what the reflections added, no
        // more. `finish` removes the addition again once the solve is done.
        let mut any = false;
        self.added.clear();
        self.added.resize(rows, 0.0);
        for ((c, &total), added) in constraints
            .iter_mut()
            .zip(&self.impulse)
            .zip(&mut self.added)
        {
            if total <= 0.0 {
                continue;
            }
            any = true;
            let change = total - c.step_impulses[0];
            push(c, change, velocities.linear, velocities.angular);
            let accumulated = (c.normal_impulse + change).max(0.0);
            // The whole accumulated impulse is taken out again by `finish`: the substeps'
            // impulse on a row the reflections pushed is the impact's too.
            *added = accumulated;
            c.normal_impulse = accumulated;
            // The restitution solve's bookkeeping subtracts the accumulated impulse before it
            // and adds it after: the step total becomes the reflections' plus its change.
            c.step_impulses[0] = total;
            c.target_normal_velocity = normal_velocity(c, &self.linear, &self.angular);
        }
        self.pending = any;
        any
    }

    /// After the restitution solve that followed [`Self::propagate`]: takes each pushed row's
    /// accumulated impulse as the propagation left it (the substeps' and the reflections')
    /// back out (at least zero), leaving what the restitution solve added, and keeps the
    /// friction impulse inside the disc of what remains. The accumulated impulses are the next
    /// step's warm start, which must not give the impact a second time (a struck row of balls
    /// left at rest would be pushed apart again). The step totals keep the impact.
    pub(crate) fn finish(&mut self, constraints: &mut [ContactConstraint]) {
        if !std::mem::take(&mut self.pending) {
            return;
        }
        for (c, &added) in constraints.iter_mut().zip(&self.added) {
            if added == 0.0 {
                continue;
            }
            c.normal_impulse = (c.normal_impulse - added).max(0.0);
            c.tangent_impulses = cap_to_disc(c.tangent_impulses, c.friction * c.normal_impulse);
        }
    }

    /// The velocities of the step's start per slot: the island's bodies, its guests, then the
    /// immovable slot (zero).
    fn gather(&mut self, island_bodies: &[u32], guests: &[u32], bodies: &Bodies) {
        bodies.gather_slot_velocities(island_bodies, guests, &mut self.linear, &mut self.angular);
    }

    /// Lists each moving slot's rows (counting sort by slot); guests and the immovable slot,
    /// whose velocities no impulse changes, get none.
    fn index_rows(&mut self, constraints: &[ContactConstraint], moving: usize) {
        self.slot_starts.clear();
        self.slot_starts.resize(moving + 1, 0);
        for c in constraints {
            for slot in [c.local_a as usize, c.local_b as usize] {
                if slot < moving {
                    self.slot_starts[slot + 1] += 1;
                }
            }
        }
        for k in 0..moving {
            self.slot_starts[k + 1] += self.slot_starts[k];
        }
        self.slot_rows.clear();
        self.slot_rows
            .resize(self.slot_starts[moving] as usize, u32::MAX);
        self.cursor.clear();
        self.cursor.extend_from_slice(&self.slot_starts[..moving]);
        for (row, c) in constraints.iter().enumerate() {
            for slot in [c.local_a as usize, c.local_b as usize] {
                if slot < moving {
                    self.slot_rows[self.cursor[slot] as usize] = row as u32;
                    self.cursor[slot] += 1;
                }
            }
        }
    }

    /// The active set among the candidates (module docs, step 1), in constraint order, and its
    /// restitution coefficient. One coefficient for the whole set: with e_i differing within a
    /// set the reflection can add energy (E⁺ = E' + |Jᵀ(e∘λ)|² in the metric of M⁻¹, which can
    /// exceed E⁻ = E' + |Jᵀλ|² when impulses on one body partly cancel). So when some rows
    /// approach faster than `threshold`, the set is those rows alone, with the smallest of their
    /// pairs' coefficients (0 when `elastic` is false); otherwise it is the slower rows, with
    /// e = 0. Every round then keeps or loses kinetic energy, never gains it.
    fn select_active(
        &mut self,
        constraints: &[ContactConstraint],
        tolerance: f32,
        dt: f32,
        threshold: f32,
        elastic: bool,
    ) {
        self.active.clear();
        let mut fast = false;
        for &row in &self.candidates {
            let c = &constraints[row as usize];
            if c.normal.effective_mass <= 0.0 {
                continue;
            }
            let v = normal_velocity(c, &self.linear, &self.angular);
            let gap = (-c.depth).max(0.0);
            let in_contact = c.max_normal_impulse > 0.0 || gap + v * dt < 0.0;
            if v < -tolerance && in_contact {
                if v < -threshold && !fast {
                    // The first fast row: the slower ones found so far wait.
                    fast = true;
                    self.active.clear();
                }
                if !fast || v < -threshold {
                    self.active.push(row);
                }
            }
        }
        self.active.sort_unstable();
        self.coefficient = if fast && elastic {
            self.active
                .iter()
                .map(|&row| constraints[row as usize].restitution)
                .fold(f32::INFINITY, f32::min)
        } else {
            0.0
        };
    }

    /// The active rows' inelastic projection by projected Gauss-Seidel from λ = 0, sweeps in
    /// alternating direction, until no row's velocity changes by more than `tolerance` (m/s).
    fn project(&mut self, constraints: &[ContactConstraint], tolerance: f32) {
        for &row in &self.active {
            self.projection[row as usize] = 0.0;
        }
        for sweep in 0..PROJECTION_SWEEPS {
            let mut largest = 0.0f32;
            let count = self.active.len();
            for k in 0..count {
                let k = if sweep % 2 == 0 { k } else { count - 1 - k };
                let row = self.active[k] as usize;
                let c = &constraints[row];
                let v = normal_velocity(c, &self.linear, &self.angular);
                let accumulated = self.projection[row];
                let updated = (accumulated - c.normal.effective_mass * v).max(0.0);
                let change = updated - accumulated;
                if change != 0.0 {
                    push(c, change, &mut self.linear, &mut self.angular);
                    self.projection[row] = updated;
                    largest = largest.max(change.abs() * c.normal.inverse_effective_mass);
                }
            }
            if largest <= tolerance {
                break;
            }
        }
    }

    /// Adds e·λ_i of each active row on top of its projection (module docs, step 3) and the
    /// round's (1 + e)·λ_i to the row's total.
    fn reflect(&mut self, constraints: &[ContactConstraint]) {
        for &row in &self.active {
            let row = row as usize;
            let projection = self.projection[row];
            let extra = self.coefficient * projection;
            if extra != 0.0 {
                push(
                    &constraints[row],
                    extra,
                    &mut self.linear,
                    &mut self.angular,
                );
            }
            self.impulse[row] += projection + extra;
        }
    }

    /// The next round's candidates: every row of a moving body of this round's active rows.
    fn queue_neighbours(&mut self, constraints: &[ContactConstraint], moving: usize, stamp: u32) {
        self.candidates.clear();
        for &row in &self.active {
            let c = &constraints[row as usize];
            for slot in [c.local_a as usize, c.local_b as usize] {
                if slot >= moving {
                    continue;
                }
                let range = self.slot_starts[slot] as usize..self.slot_starts[slot + 1] as usize;
                for &neighbour in &self.slot_rows[range] {
                    if self.queued[neighbour as usize] != stamp {
                        self.queued[neighbour as usize] = stamp;
                        self.candidates.push(neighbour);
                    }
                }
            }
        }
    }
}
