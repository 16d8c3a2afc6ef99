//! Speculative margins: how far ahead the broad and narrow phases look in one step, per body
//! and per pair, and the reach a pair's bodies can close in the step ([`SweptReach`]), past
//! which a speculative point is dropped.

use glam::Vec3;
use parry3d::math::Pose;
use parry3d::query::{QueryDispatcher, ShapeCastOptions};

use super::dispatch::ContactDispatcher;
use super::manifold::Manifold;
use crate::body::Bodies;
use crate::parallel::{BODIES_PER_TASK, spread};

/// Cap on a body's speculative margin (m), so a body thrown at absurd speed does not pair
/// with the whole scene.
pub(crate) const MAX_SPECULATIVE_MARGIN: f32 = 2.0;

/// How far ahead the broad and narrow phases look in one step (speculative contacts), from
/// the poses and velocities at the step's start.
///
/// - Per body ([`SpeculativeMargins::margins`], for the broad phase, which grows each body's
///   box by it): half the base prediction distance plus the distance the body can travel in
///   one step, dt·(|v| + |ω|·R + |g|·dt) with R its bounding radius. Pairs are then found
///   before fast bodies meet rather than after they have tunnelled into each other; a fixed
///   margin lets a ball falling at 19 m/s overlap its neighbours by a tenth of a metre.
/// - Per pair ([`SpeculativeMargins::pair_prediction`], for the narrow phase): contact points
///   are generated up to the base prediction distance plus how far the two bodies can close
///   in one step, dt·(|v_a − v_b| + |ω_a|·R_a + |ω_b|·R_b), plus |g|·dt² when only one of them
///   is dynamic (gravity moves both alike otherwise); never more than the two bodies' margins.
///   A kinematic body counts with its prescribed velocities and no gravity.
///   Balls falling side by side close at 0 m/s, so they get no speculative contact and do not
///   join one island; with the sum of the per-body margins every column of `balls16k` joined
///   one island of 16,000 balls while falling.
#[derive(Default)]
pub struct SpeculativeMargins {
    margins: Vec<f32>,
    /// Per body, |ω|·R (m/s): the fastest any of its points moves by rotation.
    spin_speeds: Vec<f32>,
    prediction_distance: f32,
    dt: f32,
    /// |g|·dt (m/s).
    gravity_speed: f32,
}

impl SpeculativeMargins {
    /// Recomputes the margins for a step of `dt` seconds (`prediction_distance` in m,
    /// `gravity` in m/s²). With `parallel`, in runs of [`BODIES_PER_TASK`] bodies on rayon's
    /// threads: each body's margin depends on that body alone, so the margins are the same on
    /// any thread count.
    pub fn update(
        &mut self,
        bodies: &Bodies,
        prediction_distance: f32,
        gravity: Vec3,
        dt: f32,
        parallel: bool,
    ) {
        self.prediction_distance = prediction_distance;
        self.dt = dt;
        self.gravity_speed = gravity.length() * dt;
        let gravity_speed = self.gravity_speed;
        // (margin, spin speed) of body i.
        let of = |i: usize| {
            if bodies.is_moving(i) {
                let radius = bodies.shape[i].compute_local_aabb().half_extents().length();
                let spin_speed = bodies.angular_velocity[i].length() * radius;
                let gravity_speed = if bodies.is_dynamic(i) {
                    gravity_speed
                } else {
                    0.0
                };
                let speed = bodies.linear_velocity[i].length() + spin_speed + gravity_speed;
                (
                    (0.5 * prediction_distance + speed * dt).min(MAX_SPECULATIVE_MARGIN),
                    spin_speed,
                )
            } else {
                (0.5 * prediction_distance, 0.0)
            }
        };
        self.margins.clear();
        self.spin_speeds.clear();
        if spread(parallel, bodies.len(), BODIES_PER_TASK) {
            use rayon::prelude::*;
            (0..bodies.len())
                .into_par_iter()
                .with_min_len(BODIES_PER_TASK)
                .map(of)
                .unzip_into_vecs(&mut self.margins, &mut self.spin_speeds);
        } else {
            for i in 0..bodies.len() {
                let (margin, spin_speed) = of(i);
                self.margins.push(margin);
                self.spin_speeds.push(spin_speed);
            }
        }
    }

    /// Per-body margins (m), indexed like the bodies.
    pub fn margins(&self) -> &[f32] {
        &self.margins
    }

    /// The separation (m) up to which pair (`a`, `b`) gets contact points this step.
    #[inline]
    pub fn pair_prediction(&self, bodies: &Bodies, a: usize, b: usize) -> f32 {
        let velocity = |i: usize| moving_velocity(bodies, i);
        let gravity = self.relative_gravity_speed(bodies, a, b);
        let closing = (velocity(a) - velocity(b)).length()
            + self.spin_speeds[a]
            + self.spin_speeds[b]
            + gravity;
        (self.prediction_distance + closing * self.dt).min(self.margins[a] + self.margins[b])
    }

    /// Pair (`a`, `b`)'s straight relative motion over the step and how near along it its
    /// shapes must come for its speculative points to stand ([`SweptReach`]).
    #[inline]
    pub(crate) fn pair_reach(&self, bodies: &Bodies, a: usize, b: usize) -> SweptReach {
        let velocity = |i: usize| moving_velocity(bodies, i);
        let gravity = self.relative_gravity_speed(bodies, a, b);
        SweptReach {
            displacement: (velocity(b) - velocity(a)) * self.dt,
            distance: self.prediction_distance
                + (self.spin_speeds[a] + self.spin_speeds[b] + gravity) * self.dt,
        }
    }

    /// The speed (m/s) gravity can add to pair (`a`, `b`)'s closing: it moves dynamic bodies
    /// alike, and kinematic and static ones not at all.
    #[inline]
    fn relative_gravity_speed(&self, bodies: &Bodies, a: usize, b: usize) -> f32 {
        if bodies.is_dynamic(a) != bodies.is_dynamic(b) {
            self.gravity_speed
        } else {
            0.0
        }
    }
}

/// Body `i`'s linear velocity (m/s) if it moves, else zero.
#[inline]
fn moving_velocity(bodies: &Bodies, i: usize) -> Vec3 {
    if bodies.is_moving(i) {
        bodies.linear_velocity[i]
    } else {
        Vec3::ZERO
    }
}

/// What the speculative points of a pair must meet to stand: the pair's shapes, moved apart
/// by the straight relative motion of the step (body 2 by `displacement` against body 1),
/// come within `distance` of each other at some time of the step.
///
/// A speculative point holds its pair's closing speed along the manifold's normal to the gap
/// over the step, v·n ≥ −gap/dt: it acts as a plane through the witness point, unbounded
/// across the normal. A path that passes beside the feature the point belongs to crosses
/// that plane outside the feature and is stopped there, on nothing (a 5 cm ball at 150 m/s
/// whose path passes 0.23 m below a wall's edge stopped on the plane of its face). The pair's own
/// shape cast tells a real approach from such a passage: where the shapes, moved by the
/// step's straight motion, never come within `distance`, no point of the pair can be
/// reached in the step and all its points beyond `distance` are dropped. `distance` is the
/// part of the pair's prediction ([`SpeculativeMargins::pair_prediction`]) that is not that
/// straight motion: the base prediction distance, which catches velocity changes within the
/// step (a body pushed by its neighbours), how far rotation can carry any point of either
/// body (|ω|·R·dt) and, for a dynamic body against a static or kinematic one, what gravity
/// adds (|g|·dt²). Points within `distance` (every resting contact) are never dropped.
///
/// Box2D v3 avoids the same phantoms by keeping its speculative distance small (4 linear
/// slops, `B2_SPECULATIVE_DISTANCE` in `constants.h`, the cut-off of every manifold function
/// in `manifold.c`) and leaving fast bodies to its continuous collision; here the margin
/// grows with the speed, so that fast bodies meet each other too, and the cast bounds it.
#[derive(Clone, Copy, Debug)]
pub(crate) struct SweptReach {
    /// Displacement of body 2 relative to body 1 over the step (m, world frame).
    pub displacement: Vec3,
    /// Distance (m) within which the shapes must come along it.
    pub distance: f32,
}

impl SweptReach {
    /// Drops every point of `manifolds` (of a pair whose body 2 sits at `pos12` in body 1's
    /// frame, body 1 at world rotation `rotation1`) beyond [`SweptReach::distance`] when the
    /// shapes, moved by the step's straight motion, stay farther apart than that distance;
    /// whether any point was dropped. Shape pairs Parry cannot cast keep their points.
    pub(crate) fn drop_unreachable(
        &self,
        pos12: &Pose,
        rotation1: glam::Quat,
        shape1: &dyn parry3d::shape::Shape,
        shape2: &dyn parry3d::shape::Shape,
        manifolds: &mut [Manifold],
    ) -> bool {
        let beyond = |manifolds: &[Manifold]| {
            manifolds
                .iter()
                .any(|m| m.points.iter().any(|p| p.dist > self.distance))
        };
        if !beyond(manifolds) {
            return false;
        }
        let options = ShapeCastOptions {
            max_time_of_impact: 1.0,
            target_distance: self.distance,
            stop_at_penetration: true,
            compute_impact_geometry_on_penetration: false,
        };
        let local_displacement = rotation1.inverse() * self.displacement;
        let cast =
            ContactDispatcher.cast_shapes(pos12, local_displacement, shape1, shape2, options);
        if !matches!(cast, Ok(None)) {
            return false;
        }
        for manifold in manifolds.iter_mut() {
            manifold.points.retain(|p| p.dist <= self.distance);
        }
        true
    }
}

#[cfg(test)]
#[path = "margins_tests.rs"]
mod tests;
