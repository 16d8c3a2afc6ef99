//! Nonsmooth nonlinear conjugate gradient: PGS sweeps with Fletcher–Reeves momentum.

use super::interface::Sweep;
use super::interface::{
    ContactSolver, EscalationLevel, SolveOutcome, SolvePass, SolveReport, solve_scalar,
};
use super::pgs::{BACKWARD, FORWARD, FrictionFirstRows, sweep_points};
use super::rows::{Velocities, apply_impulses, impulses};
use crate::contact::ContactConstraint;
use crate::graph::COLOURS;
use crate::joint::{IslandJoints, sweep_joints};
use crate::parallel::{
    NORM_POINTS_PER_TASK, SWEEP_POINTS_PER_TASK, SharedVelocities, parts_in_order, spread,
};

/// NNCG as a [`ContactSolver`], with its work vectors.
#[derive(Default)]
pub(crate) struct Nncg {
    /// Work vectors, kept between solves.
    pub workspace: NncgWorkspace,
}

impl ContactSolver for Nncg {
    fn solve(
        &mut self,
        constraints: &mut [ContactConstraint],
        velocities: &mut Velocities<'_>,
        joints: &mut IslandJoints,
        pass: &SolvePass<'_>,
    ) -> SolveOutcome {
        solve_scalar(constraints, pass, EscalationLevel::Nncg, |rows| {
            solve_nncg_with_joints(
                rows,
                pass.sweep,
                pass.iterations,
                pass.tolerance,
                velocities,
                &mut self.workspace,
                joints,
            )
        })
    }
}

/// Work vectors of [`solve_nncg`], kept between calls to avoid reallocating.
#[derive(Default)]
pub struct NncgWorkspace {
    previous: Vec<[f32; 3]>,
    direction: Vec<[f32; 3]>,
}

/// Nonsmooth nonlinear conjugate gradient (Silcowitz, Niebe, Erleben 2010): each iteration is
/// one PGS sweep (in alternating direction) x_{k+1} = PGS(x_k), read as a step
/// along −∇f = x_{k+1} − x_k, and then pushed further along the previous direction,
/// x_{k+1} += β_k p_k with Fletcher–Reeves β_k = ‖∇f_{k+1}‖² / ‖∇f_k‖² and
/// p_{k+1} = β_k p_k − ∇f_{k+1}; β_k > 1 restarts (p = −∇f). On a chain of L contacts, such as a
/// stack, PGS needs O(L²) sweeps to carry the load down; the conjugate directions cut that to
/// about O(L). The last iteration is a plain sweep, so the result satisfies the bounds.
/// Matrix-free: the momentum step updates velocities through M⁻¹Jᵀ like any impulse.
#[cfg(any(test, feature = "internals"))]
pub fn solve_nncg(
    constraints: &mut [ContactConstraint],
    sweep: Sweep<'_>,
    iterations: u32,
    tolerance: f32,
    velocities: &mut Velocities<'_>,
    workspace: &mut NncgWorkspace,
) -> SolveReport {
    solve_nncg_with_joints(
        constraints,
        sweep,
        iterations,
        tolerance,
        velocities,
        workspace,
        &mut IslandJoints::default(),
    )
}

/// [`solve_nncg`] with an island's joints swept in every iteration's symmetric sweep (first
/// going forward, last coming back). The conjugate step moves the contact impulses only: the
/// joints' rows are solved by the sweeps, a block Gauss-Seidel between joints and contacts.
pub(crate) fn solve_nncg_with_joints(
    constraints: &mut [ContactConstraint],
    sweep: Sweep<'_>,
    iterations: u32,
    tolerance: f32,
    velocities: &mut Velocities<'_>,
    workspace: &mut NncgWorkspace,
    joints: &mut IslandJoints,
) -> SolveReport {
    let n = constraints.len();
    workspace.previous.clear();
    workspace.previous.extend(constraints.iter().map(impulses));
    workspace.direction.clear();
    workspace.direction.resize(n, [0.0; 3]);
    let mut report = SolveReport::default();
    let mut previous_norm = 0.0f64;
    for iteration in 0..iterations {
        // One fixed symmetric sweep (forward then backward) is the "PGS step": conjugate
        // directions need the same operator every iteration.
        let joint_forward = if joints.is_empty() {
            0.0
        } else {
            sweep_joints(joints, velocities, true, true)
        };
        let forward = sweep_points(constraints, sweep, FORWARD, velocities, FrictionFirstRows);
        let backward = sweep_points(constraints, sweep, BACKWARD, velocities, FrictionFirstRows);
        let mut largest_change = forward.max(backward);
        if !joints.is_empty() {
            let joint_backward = sweep_joints(joints, velocities, false, true);
            largest_change = largest_change.max(joint_forward).max(joint_backward);
        }
        report.iterations += 1;
        report.last_change = largest_change;
        if largest_change <= tolerance || iteration + 1 == iterations {
            break;
        }
        // −∇f = x_{k+1} − x_k.
        let coloured = sweep.coloured(n);
        let norm = gradient_norm(constraints, &workspace.previous, coloured, sweep.parallel);
        let beta = if iteration == 0 || previous_norm == 0.0 {
            0.0
        } else {
            norm / previous_norm
        };
        previous_norm = norm;
        let step = Momentum {
            beta: beta as f32,
            restart: beta > 1.0 || beta == 0.0,
        };
        step.apply(
            constraints,
            &mut workspace.previous,
            &mut workspace.direction,
            sweep,
            velocities,
        );
    }
    report
}

/// ‖x_{k+1} − x_k‖² over the points' three impulses. A coloured island sums fixed runs of
/// [`NORM_POINTS_PER_TASK`] points and adds the partial sums in order, on rayon's threads
/// with `parallel`, so its β does not depend on the thread count; an island in constraint
/// order sums in one run, as before colouring existed.
fn gradient_norm(
    constraints: &[ContactConstraint],
    previous: &[[f32; 3]],
    coloured: bool,
    parallel: bool,
) -> f64 {
    let run = |(constraints, previous): (&[ContactConstraint], &[[f32; 3]])| {
        let mut norm = 0.0f64;
        for (c, previous) in constraints.iter().zip(previous) {
            let x = impulses(c);
            for k in 0..3 {
                let g = (x[k] - previous[k]) as f64;
                norm += g * g;
            }
        }
        norm
    };
    if !coloured {
        return run((constraints, previous));
    }
    if spread(parallel, 1, 0) {
        let n = constraints.len();
        parts_in_order(
            n.div_ceil(NORM_POINTS_PER_TASK),
            |i| {
                let range = i * NORM_POINTS_PER_TASK..((i + 1) * NORM_POINTS_PER_TASK).min(n);
                run((&constraints[range.clone()], &previous[range]))
            },
            |parts| parts.iter().sum(),
        )
    } else {
        constraints
            .chunks(NORM_POINTS_PER_TASK)
            .zip(previous.chunks(NORM_POINTS_PER_TASK))
            .map(run)
            .sum()
    }
}

/// NNCG's momentum step x += β·p, p ← β·p − ∇f (or p ← −∇f on a restart).
#[derive(Clone, Copy)]
struct Momentum {
    beta: f32,
    restart: bool,
}

impl Momentum {
    /// Updates one point's impulses, `previous` and `direction`; returns the impulse it added
    /// (zero on a restart), which the caller applies to the velocities.
    #[inline(always)]
    fn point(
        self,
        c: &mut ContactConstraint,
        previous: &mut [f32; 3],
        direction: &mut [f32; 3],
    ) -> [f32; 3] {
        let x = impulses(c);
        let gradient_step = [x[0] - previous[0], x[1] - previous[1], x[2] - previous[2]];
        let mut push = [0.0; 3];
        if self.restart {
            *direction = gradient_step;
        } else {
            push = [
                self.beta * direction[0],
                self.beta * direction[1],
                self.beta * direction[2],
            ];
            if push != [0.0; 3] {
                c.normal_impulse += push[0];
                c.tangent_impulses[0] += push[1];
                c.tangent_impulses[1] += push[2];
            }
            for k in 0..3 {
                direction[k] = push[k] + gradient_step[k];
            }
        }
        *previous = impulses(c);
        push
    }

    /// The step over all points. On a coloured island with `parallel`, colour by colour in
    /// order, each colour's points on rayon's threads: a body is pushed by at most one point
    /// of a colour, so every body receives its pushes in constraint order, as on one thread.
    fn apply(
        self,
        constraints: &mut [ContactConstraint],
        previous: &mut [[f32; 3]],
        direction: &mut [[f32; 3]],
        sweep: Sweep<'_>,
        velocities: &mut Velocities<'_>,
    ) {
        let colours = sweep.starts.len().saturating_sub(1);
        let serial = |constraints: &mut [ContactConstraint],
                      previous: &mut [[f32; 3]],
                      direction: &mut [[f32; 3]],
                      velocities: &mut Velocities<'_>| {
            for (c, (previous, direction)) in constraints
                .iter_mut()
                .zip(previous.iter_mut().zip(direction))
            {
                let push = self.point(c, previous, direction);
                if push != [0.0; 3] {
                    apply_impulses(c, push, velocities);
                }
            }
        };
        if !sweep.coloured(constraints.len()) || !spread(sweep.parallel, 1, 0) {
            serial(constraints, previous, direction, velocities);
            return;
        }
        let shared = SharedVelocities::of(velocities);
        for k in 0..colours {
            let range = sweep.starts[k] as usize..sweep.starts[k + 1] as usize;
            let (part, part_previous, part_direction) = (
                &mut constraints[range.clone()],
                &mut previous[range.clone()],
                &mut direction[range],
            );
            if k >= COLOURS || part.len() < 2 * SWEEP_POINTS_PER_TASK {
                serial(part, part_previous, part_direction, velocities);
                continue;
            }
            use rayon::prelude::*;
            part.par_chunks_mut(SWEEP_POINTS_PER_TASK)
                .zip(part_previous.par_chunks_mut(SWEEP_POINTS_PER_TASK))
                .zip(part_direction.par_chunks_mut(SWEEP_POINTS_PER_TASK))
                .for_each(|((chunk, chunk_previous), chunk_direction)| {
                    // Capture the whole wrapper (Sync), not its raw-pointer fields (not Sync).
                    #[allow(clippy::redundant_locals)]
                    let shared = shared;
                    for (c, (previous, direction)) in chunk
                        .iter_mut()
                        .zip(chunk_previous.iter_mut().zip(chunk_direction))
                    {
                        let push = self.point(c, previous, direction);
                        if push != [0.0; 3] {
                            // SAFETY: as in `sweep_points`: slots are below `slots`, and
                            // within this colour only this point touches slots a and b
                            // (the immovable slot is never written).
                            unsafe { shared.apply(c, push) };
                        }
                    }
                });
        }
    }
}
