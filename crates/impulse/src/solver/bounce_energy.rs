//! The kinetic-energy bound on the restitution solve ([`crate::Stage::Solve`]): an impact of
//! passive bodies with restitution coefficients at most 1 cannot increase their kinetic
//! energy (energetic consistency: Stronge, "Impact Mechanics", 2000), so the bounce
//! the restitution solve adds is scaled back, when it must be, until the island's kinetic
//! energy is no more than it had as the step began plus the work gravity did on it over the
//! step.
//!
//! Why the solve can gain energy: Newton's targets v⁺ = −c_r·v⁻ take v⁻ at the step's start,
//! as if every point that collided in the step were struck at once. With a speculative margin
//! covering a fast body's whole step, the points may be struck one after the other within
//! the step: a ball at 254 m/s bounces off one height-field triangle and only then reaches the
//! speculative point of a neighbouring one, at a fraction of the approach the step's start
//! shows there. The bounce asked at that point (−c_r times an approach that never happened)
//! adds energy: such a ball left at 285 m/s (+2,177 J/kg, tests/integration/fast_impacts.rs).
//! The bound keeps the direction the solve chose and only shortens it; an impact that keeps
//! within its energy (a Newton's cradle at c_r = 1 keeps it to rounding) is left as it is.
//!
//! Not bounded (their energy is not the contacts' alone): islands with joints (motors and
//! springs do work, and their bounce impulses would have to be scaled with the contacts'),
//! with a moving kinematic body among their guests, or in a step with applied forces.

use glam::{Quat, Vec3};

use super::rows;
use crate::body::{Bodies, inertia_form};
use crate::contact::ContactConstraint;

/// Work space of the bound: the island's velocities and rows' impulses as the restitution
/// solve starts.
#[derive(Default)]
pub(crate) struct BounceEnergy {
    /// Per slot, linear velocity before the restitution solve (m/s).
    linear: Vec<Vec3>,
    /// Per slot, angular velocity (rad/s).
    angular: Vec<Vec3>,
    /// Per row, (normal, tangent 1, tangent 2) accumulated impulse (N·s).
    impulses: Vec<[f32; 3]>,
    /// Whether the bound applies to this step's restitution solve.
    armed: bool,
}

/// The island as the restitution solve leaves it, for [`BounceEnergy::bound`].
pub(crate) struct BounceIsland<'a> {
    /// The island's bodies (indices into `bodies`), the first slots.
    pub island_bodies: &'a [u32],
    /// All bodies, still holding the step's start velocities and poses.
    pub bodies: &'a Bodies,
    /// Gravity (m/s²).
    pub gravity: Vec3,
    /// Per slot, centre-of-mass displacement over the step (m).
    pub displacement: &'a [Vec3],
    /// Per slot, orientation at the end of the substeps.
    pub orientation: &'a [Quat],
}

impl BounceEnergy {
    /// Before the restitution solve: keeps the slot velocities `linear`, `angular` (m/s,
    /// rad/s; the island's `moving` bodies first, then its guests and the immovable slot) and
    /// the rows' impulses it starts from, when the bound applies: no `joints`, no applied
    /// `forces`, every guest at rest.
    pub(crate) fn start(
        &mut self,
        (linear, angular): (&[Vec3], &[Vec3]),
        constraints: &[ContactConstraint],
        moving: usize,
        (joints, forces): (bool, bool),
    ) {
        let guests_rest = linear[moving..]
            .iter()
            .chain(&angular[moving..])
            .all(|v| *v == Vec3::ZERO);
        self.armed = !joints && !forces && guests_rest;
        if !self.armed {
            return;
        }
        self.linear.clear();
        self.linear.extend_from_slice(linear);
        self.angular.clear();
        self.angular.extend_from_slice(angular);
        self.impulses.clear();
        self.impulses.extend(constraints.iter().map(rows::impulses));
    }

    /// After the restitution solve: with v₀ the velocities it started from and d what it
    /// changed (`linear`, `angular` hold v₀ + d), the island's kinetic energy along v₀ + s·d is
    /// K(s) = K₀ + B·s + A·s². When K(1) is above the reference R (the step start's kinetic
    /// energy plus gravity's work m·g·Δx over the step, or K₀ if the substeps already ended
    /// above it), the velocities and the rows' impulses are put back to the largest s in
    /// [0, 1] with K(s) ≤ R, the larger root of A·s² + B·s + K₀ − R. Rotational energy is
    /// taken at the orientations of the step's start and end, as the world's energy check
    /// takes it.
    pub(crate) fn bound(
        &mut self,
        island: &BounceIsland<'_>,
        (linear, angular): (&mut [Vec3], &mut [Vec3]),
        constraints: &mut [ContactConstraint],
    ) {
        if !std::mem::take(&mut self.armed) {
            return;
        }
        let bodies = island.bodies;
        let (mut reference, mut start, mut first, mut second) = (0.0f64, 0.0f64, 0.0, 0.0);
        for (k, &i) in island.island_bodies.iter().enumerate() {
            let i = i as usize;
            let inverse_mass = bodies.inverse_mass[i];
            if inverse_mass <= 0.0 {
                continue;
            }
            let (inertia, mass) = (&bodies.local_inverse_inertia[i], 1.0 / inverse_mass);
            // The kinetic energy's bilinear form, m·v·x + ωᵀ·I·y.
            let form = |v: Vec3, w: Vec3, x: Vec3, y: Vec3, rotation| {
                f64::from(mass * v.dot(x) + inertia_form(inertia, rotation, w, y))
            };
            let (v0, w0) = (self.linear[k], self.angular[k]);
            let (dv, dw) = (linear[k] - v0, angular[k] - w0);
            let (before, after) = (bodies.pose[i].rotation, island.orientation[k]);
            let (v, w) = (bodies.linear_velocity[i], bodies.angular_velocity[i]);
            reference += 0.5 * form(v, w, v, w, before)
                + f64::from(mass * island.gravity.dot(island.displacement[k]));
            start += 0.5 * form(v0, w0, v0, w0, after);
            first += form(v0, w0, dv, dw, after);
            second += 0.5 * form(dv, dw, dv, dw, after);
        }
        let reference = reference.max(start);
        // A non-finite energy is the blow-up check's to report.
        let end = start + first + second;
        if !end.is_finite() || !reference.is_finite() || end <= reference {
            return;
        }
        // K(0) ≤ R < K(1), so the larger root lies in [0, 1).
        let slack = reference - start;
        let s = if second > 0.0 {
            (-first + (first * first + 4.0 * second * slack).sqrt()) / (2.0 * second)
        } else {
            slack / first
        };
        let s = s.clamp(0.0, 1.0) as f32;
        for k in 0..island.island_bodies.len() {
            linear[k] = self.linear[k] + s * (linear[k] - self.linear[k]);
            angular[k] = self.angular[k] + s * (angular[k] - self.angular[k]);
        }
        for (c, before) in constraints.iter_mut().zip(&self.impulses) {
            let now = rows::impulses(c);
            let scaled = |j: usize| before[j] + s * (now[j] - before[j]);
            c.normal_impulse = scaled(0);
            c.tangent_impulses = [scaled(1), scaled(2)];
        }
    }
}
