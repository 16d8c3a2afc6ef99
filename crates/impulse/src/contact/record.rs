//! The diagnostics record: each row's J·v* (v* the velocities before the solve's impulses),
//! from which the step's contact LCP and its natural-map residual are checked.

use glam::Vec3;

use super::row::ContactConstraint;
use crate::parallel::{PAIRS_PER_TASK, spread};
use rayon::prelude::*;

/// Rewrites each row's `velocity_before` as J·v* for the solve that produced the current
/// impulses: v* = v − M⁻¹Jᵀγ, the velocities without this solve's impulses. With it,
/// (A, b = target − J·v*) is exactly the LCP whose solution the rows now hold, so it can be
/// exported and checked ([`crate::diagnostics::contact_lcp`]). O(rows); `scratch` holds per-body deltas.
///
/// The deltas are summed in up to [`RECORD_PARTS`] parts of consecutive rows, each into its
/// own per-body array, then added part after part; the parts depend only on the number of
/// rows, so the sums are the same on any thread count. With `parallel`, the parts and the
/// second pass (one row at a time, no shared writes) run on rayon's threads, so that a large
/// island does not leave the other threads idle.
/// An island's step ends with the same two passes, the second one fused with its residual
/// ([`crate::diagnostics::record_velocity_before_and_residual`]).
///
/// `slots` says how rows name their bodies, and so how `linear` and `angular` are indexed.
pub(crate) fn record_velocity_before(
    constraints: &mut [ContactConstraint],
    slots: BodySlots,
    linear: &[Vec3],
    angular: &[Vec3],
    parallel: bool,
    scratch: &mut Vec<(Vec3, Vec3)>,
) {
    let parallel = spread(parallel, 1, 0);
    let Some(changes) =
        impulse_velocity_changes(constraints, slots, linear.len(), parallel, scratch)
    else {
        return;
    };
    let bodies_of = slots.bodies_of();
    let record = |c: &mut ContactConstraint| {
        let (a, b) = bodies_of(c);
        record_row(c, a, b, linear, angular, changes);
    };
    if parallel && constraints.len() > PAIRS_PER_TASK {
        constraints
            .par_iter_mut()
            .with_min_len(PAIRS_PER_TASK)
            .for_each(record);
    } else {
        constraints.iter_mut().for_each(record);
    }
}

/// The first pass of [`record_velocity_before`]: per body slot (below `bodies`), the velocity
/// change M⁻¹Jᵀγ of the rows' current impulses, as (linear, angular), summed in parts as
/// described there. `None` when there are no bodies.
pub(crate) fn impulse_velocity_changes<'s>(
    constraints: &[ContactConstraint],
    slots: BodySlots,
    bodies: usize,
    parallel: bool,
    scratch: &'s mut Vec<(Vec3, Vec3)>,
) -> Option<&'s [(Vec3, Vec3)]> {
    if bodies == 0 {
        return None;
    }
    let bodies_of = slots.bodies_of();
    let parts = constraints
        .len()
        .div_ceil(RECORD_POINTS_PER_PART)
        .clamp(1, RECORD_PARTS);
    let per_part = constraints.len().div_ceil(parts).max(1);
    scratch.clear();
    scratch.resize(parts * bodies, (Vec3::ZERO, Vec3::ZERO));
    let add_part = |(rows, deltas): (&[ContactConstraint], &mut [(Vec3, Vec3)])| {
        for c in rows {
            let (a, b) = bodies_of(c);
            let rows = [
                (&c.normal, c.normal_impulse),
                (&c.tangents[0], c.tangent_impulses[0]),
                (&c.tangents[1], c.tangent_impulses[1]),
            ];
            for (row, impulse) in rows {
                deltas[a].0 += row.direction * (c.inverse_mass_a * impulse);
                deltas[a].1 += row.inverse_inertia_angular_a * impulse;
                deltas[b].0 -= row.direction * (c.inverse_mass_b * impulse);
                deltas[b].1 -= row.inverse_inertia_angular_b * impulse;
            }
        }
    };
    if parallel && parts > 1 {
        constraints
            .par_chunks(per_part)
            .zip(scratch.par_chunks_mut(bodies))
            .for_each(add_part);
    } else {
        constraints
            .chunks(per_part)
            .zip(scratch.chunks_mut(bodies))
            .for_each(add_part);
    }
    let (first, later) = scratch.split_at_mut(bodies);
    let later = &*later;
    let sum = |(i, delta): (usize, &mut (Vec3, Vec3))| {
        for part in 1..parts {
            let (l, a) = later[(part - 1) * bodies + i];
            delta.0 += l;
            delta.1 += a;
        }
    };
    if parts > 1 {
        if parallel {
            first.par_iter_mut().enumerate().for_each(sum);
        } else {
            first.iter_mut().enumerate().for_each(sum);
        }
    }
    Some(first)
}

/// The second pass of [`record_velocity_before`] on one row, whose bodies are at `a` and `b`:
/// its rows' J·v* from the velocities and the `changes` of [`impulse_velocity_changes`].
#[inline(always)]
pub(crate) fn record_row(
    c: &mut ContactConstraint,
    a: usize,
    b: usize,
    linear: &[Vec3],
    angular: &[Vec3],
    changes: &[(Vec3, Vec3)],
) {
    let (la, aa) = (linear[a] - changes[a].0, angular[a] - changes[a].1);
    let (lb, ab) = (linear[b] - changes[b].0, angular[b] - changes[b].1);
    c.normal.velocity_before = c.normal.velocity(la, aa, lb, ab);
    for t in &mut c.tangents {
        t.velocity_before = t.velocity(la, aa, lb, ab);
    }
}

/// Most parts of [`record_velocity_before`]'s first pass: each costs a per-body array.
pub(crate) const RECORD_PARTS: usize = 4;

/// Rows per part of [`record_velocity_before`]'s first pass below [`RECORD_PARTS`] parts:
/// smaller sets of rows are summed in one part, as before the parts existed.
const RECORD_POINTS_PER_PART: usize = 8192;

/// Which indices of a [`ContactConstraint`] name its bodies in a pass over velocity arrays.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum BodySlots {
    /// `body_a` / `body_b`: the world's body arrays (the tests' world-wide passes; the step
    /// records every row in its island's slots).
    #[cfg(test)]
    World,
    /// `local_a` / `local_b`: one island's local arrays (the immovable slot last, at rest).
    /// The island's step records its rows this way while its data is in cache, on whichever
    /// thread solved it; the result is the world-wide pass's once the velocities are
    /// scattered back.
    Island,
}

impl BodySlots {
    /// A row's two indices into the velocity arrays, (A, B).
    pub(crate) fn bodies_of(self) -> fn(&ContactConstraint) -> (usize, usize) {
        match self {
            #[cfg(test)]
            BodySlots::World => |c| (c.body_a as usize, c.body_b as usize),
            BodySlots::Island => |c| (c.local_a as usize, c.local_b as usize),
        }
    }
}
