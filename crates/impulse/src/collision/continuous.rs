//! Continuous collision's geometry (motion clamping), for the continuous stage
//! ([`crate::Stage::Continuous`], `world/step/motion_clamp.rs`, which picks the bodies and the
//! targets and applies the clamps): a dynamic body that moved more than a fraction of
//! its own size in a step is swept from its pose at the step's start to its pose at the end
//! against the static and kinematic bodies in its swept box, with Parry's nonlinear shape
//! cast (translation and rotation); if it would pass one, its pose is put back to the first
//! time of impact, less a small gap, and its velocity is left as it is, so that the next
//! step's speculative contact stops it (docs/method.md, "Continuous collision").
//!
//! Half-spaces and height fields, which Parry's nonlinear cast does not take (neither is a
//! support map nor, in Parry, a composite shape for that cast), are swept through the parts
//! of them the body can reach in the step: for a half-space a box whose top face is the
//! half-space's plane and which holds every point of the half-space the body can reach
//! ([`half_space_slab`]), for a height field its triangles under the body's path
//! ([`height_field_triangles`]), each with the target's own motion.
//!
//! This is the method of Rapier's CCD, which sweeps every fast dynamic body against the fixed
//! colliders and clamps its motion to the first impact, leaving the velocities to the solver
//! (rapier.rs user guide, "Rigid-body CCD"), and of Box2D v3's continuous collision against
//! static shapes, including its fallback for a body that starts the step touching a shape:
//! the sweep of a small core sphere around the centre of mass, so that a body sliding along
//! a surface is not stopped by it but one pushed through it is (Box2D v3.1,
//! `b2ContinuousQueryCallback`).

use glam::{Quat, Vec3};
use parry3d::bounding_volume::{Aabb, BoundingVolume};
use parry3d::math::Pose;
use parry3d::query::{NonlinearRigidMotion, cast_shapes_nonlinear, contact, distance};
use parry3d::shape::{Ball, Compound, Cuboid, HalfSpace, HeightField, Shape, Triangle};

use crate::body::motion::rotation_vector;

/// A body is swept when it moved more than this fraction of its smallest half extent in a
/// step (Box2D v3's safety factor: a slower body cannot pass through anything the contacts
/// see, and needs no sweep).
pub(crate) const FAST_FRACTION: f32 = 0.5;

/// The gap (m) a clamped body is left short of the surface it would hit, at most (Box2D's
/// linear slop), and at most this fraction of its smallest half extent for small bodies.
pub(crate) const CLAMP_GAP: f32 = 0.005;

/// Radius of the core sphere of a body that starts the step touching a surface, as a fraction
/// of its smallest half extent (Box2D v3.1 uses a quarter of the shape's minimum extent).
pub(crate) const CORE_FRACTION: f32 = 0.25;

/// One body's motion over a step: from `start` to `end` (body frames), about its centre of
/// mass at `local_center_of_mass`, turning by the rotation vector `turn`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Sweep {
    /// Pose at the step's start.
    pub(crate) start: Pose,
    /// Pose at the step's end.
    pub(crate) end: Pose,
    /// Centre of mass in the body frame (m).
    pub(crate) local_center_of_mass: Vec3,
    /// Rotation vector of the turn from `start` to `end` (rad, world frame): see
    /// [`Sweep::new`].
    pub(crate) turn: Vec3,
}

impl Sweep {
    /// The sweep from `start` to `end` of a body whose angular velocity times the step is
    /// `spin` (rad, world frame). The turn is the rotation from the start orientation to the
    /// end one, about its own axis, by the angle of that rotation plus the whole number of
    /// turns that brings it closest to `spin`: the same end orientation, but a body spinning by
    /// more than half a turn a step (a dart that hit a wall at 200 m/s spins at over 1,000
    /// rad/s, 20 rad a step at 60 Hz) is swept round the way it turned, not the short way back.
    pub(crate) fn new(start: Pose, end: Pose, local_center_of_mass: Vec3, spin: Vec3) -> Self {
        let shortest = rotation_vector(start.rotation, end.rotation);
        let angle = shortest.length();
        let turn = if angle > 0.0 {
            let axis = shortest / angle;
            // The angle about `axis` nearest to `spin`'s component along it, among angle + 2πk.
            let along = spin.dot(axis);
            let tau = std::f32::consts::TAU;
            let windings = ((along - angle) / tau).round();
            axis * (angle + windings * tau)
        } else {
            shortest
        };
        Self {
            start,
            end,
            local_center_of_mass,
            turn,
        }
    }

    /// The motion as Parry's [`NonlinearRigidMotion`] over the time interval [0, 1]: the centre
    /// of mass moving at constant velocity and the body turning at constant angular velocity
    /// (`turn`) about it.
    pub(crate) fn motion(&self) -> NonlinearRigidMotion {
        let com = self.local_center_of_mass;
        NonlinearRigidMotion::new(
            self.start,
            com,
            self.end.transform_point(com) - self.start.transform_point(com),
            self.turn,
        )
    }

    /// The pose at fraction `t` ∈ [0, 1] of the step along [`Sweep::motion`].
    pub(crate) fn pose_at(&self, t: f32) -> Pose {
        self.motion().position_at_time(t)
    }

    /// A bound on how far (m) any point within `radius` of the centre of mass moves along the
    /// sweep: the centre's travel plus the turned angle times `radius`.
    pub(crate) fn travel(&self, radius: f32) -> f32 {
        let com = self.local_center_of_mass;
        (self.end.transform_point(com) - self.start.transform_point(com)).length()
            + self.turn.length() * radius
    }

    /// The sweep of a part fixed at `part` in this body's frame: the same motion about the
    /// same centre of mass.
    fn of_part(&self, part: &Pose) -> Self {
        Self {
            start: self.start * *part,
            end: self.end * *part,
            local_center_of_mass: part.inverse_transform_point(self.local_center_of_mass),
            turn: self.turn,
        }
    }

    /// The centre of mass's world position at the step's start and end.
    fn center_path(&self) -> (Vec3, Vec3) {
        let com = self.local_center_of_mass;
        (
            self.start.transform_point(com),
            self.end.transform_point(com),
        )
    }
}

/// A bound on [`Sweep::travel`] for the sweep of [`Sweep::new`] with the same arguments,
/// without its inverse trigonometry (the stage asks it of every moving body, and most turn by
/// micro-radians): `None` when it cannot tell cheaply, for a spin (`spin`, rad) above 1 rad or
/// a shortest turn from `start` to `end` above 60°, where the sweep may wind round.
///
/// With x = sin(θ/2) of the shortest turn θ, θ = 2·asin(x) ≤ π·x; below those limits the
/// sweep's turn is the shortest one (|spin·axis − θ| < π gives no whole turn), so the travel
/// is at most the centre's travel plus π·x·`radius`.
pub(crate) fn travel_bound(
    start: &Pose,
    end: &Pose,
    local_center_of_mass: Vec3,
    spin: Vec3,
    radius: f32,
) -> Option<f32> {
    let delta = end.rotation * start.rotation.inverse();
    let sine_squared = Vec3::new(delta.x, delta.y, delta.z).length_squared();
    let norm_squared = sine_squared + delta.w * delta.w;
    let sine = (sine_squared / norm_squared).sqrt();
    if sine.is_nan() || sine > 0.5 || spin.length_squared() > 1.0 {
        return None;
    }
    let com = local_center_of_mass;
    let center = (end.transform_point(com) - start.transform_point(com)).length();
    Some(center + std::f32::consts::PI * sine * radius)
}

/// What the sweep needs to know of the fast body's shape.
#[derive(Clone, Copy)]
pub(crate) struct FastBody<'a> {
    /// Its shape (body frame).
    pub(crate) shape: &'a dyn Shape,
    /// Its motion over the step.
    pub(crate) sweep: Sweep,
    /// Its smallest half extent (m): the core sphere's and the gap's scale.
    pub(crate) min_half_extent: f32,
    /// A bound on how far any of its points moves in the step (m), > 0.
    pub(crate) travel: f32,
    /// The farthest any of its points lies from its centre of mass (m).
    pub(crate) radius: f32,
    /// When the solver released its speculative rows as stale this step (it turned past the
    /// solver's limit, `contact::SPECULATIVE_TURN`, and is not a ball), that limit (rad): the
    /// turn up to which its rows held it. Set by the continuous stage; `None` here.
    pub(crate) released: Option<f32>,
}

impl<'a> FastBody<'a> {
    /// The motion of a body of `shape` from `start` to `end` over the step (its centre of mass
    /// at `local_center_of_mass` in the body frame, its angular velocity times the step `spin`,
    /// rad, world frame) as a body to sweep; `None` when it moved no more than
    /// [`FAST_FRACTION`] of its smallest half extent (or its travel is not finite): such a
    /// body cannot pass through anything the contacts see.
    pub(crate) fn moving_fast(
        shape: &'a dyn Shape,
        start: Pose,
        end: Pose,
        local_center_of_mass: Vec3,
        spin: Vec3,
    ) -> Option<Self> {
        let local = shape.compute_local_aabb();
        let half = local.half_extents();
        let min_half_extent = half.min_element();
        let radius = (local.center() - local_center_of_mass).length() + half.length();
        // Most bodies are slow: a cheap bound settles them before the sweep's trigonometry.
        let limit = FAST_FRACTION * min_half_extent;
        if travel_bound(&start, &end, local_center_of_mass, spin, radius)
            .is_some_and(|bound| bound <= limit)
        {
            return None;
        }
        let sweep = Sweep::new(start, end, local_center_of_mass, spin);
        let travel = sweep.travel(radius);
        if !travel.is_finite() || travel <= limit {
            return None;
        }
        Some(Self {
            shape,
            sweep,
            min_half_extent,
            travel,
            radius,
            released: None,
        })
    }
}

impl FastBody<'_> {
    /// A box in `target`'s frame at the step's start that holds every point of this body
    /// during the part of the step from fraction `from` to `to`, seen from `target`'s frame
    /// at any time of the step. The body stays within [`FastBody::radius`] of its centre's
    /// straight path; a point fixed in the world moves in a frame carried by `target` by at
    /// most `target`'s travel for points that far from its centre of mass.
    fn region_in(&self, target: &Sweep, from: f32, to: f32) -> Aabb {
        let (a, b) = self.sweep.center_path();
        let (a, b) = (a + (b - a) * from, a + (b - a) * to);
        let (target_center, _) = target.center_path();
        let far = (a - target_center)
            .length()
            .max((b - target_center).length())
            + self.radius;
        let slack = self.radius + target.travel(far);
        let (a, b) = (
            target.start.inverse_transform_point(a),
            target.start.inverse_transform_point(b),
        );
        Aabb::new(a.min(b), a.max(b)).loosened(slack)
    }
}

/// The fraction of the step, in [0, 1), to which `body`'s motion is clamped so that it does not
/// pass `target` (a static or kinematic body's shape moving along `target_sweep`), or `None`
/// when the motion needs no clamp ([`clamp_fraction_castable`]). A half-space is swept as the
/// box of it that the body can reach ([`half_space_slab`]), a height field as its triangles
/// under the body's path ([`height_field_triangles`]); every other shape as it is.
pub(crate) fn clamp_fraction(
    body: &FastBody<'_>,
    target: &dyn Shape,
    target_sweep: &Sweep,
    in_contact: bool,
) -> Option<f32> {
    if let Some(half_space) = target.as_shape::<HalfSpace>() {
        let region = body.region_in(target_sweep, 0.0, 1.0);
        let (slab, pose) = half_space_slab(half_space.normal, &region)?;
        let sweep = target_sweep.of_part(&pose);
        return clamp_fraction_castable(body, &slab, &sweep, in_contact);
    }
    if let Some(height_field) = target.as_heightfield() {
        // Contact with a height field is contact with some of its triangles: a fast body
        // held off one triangle by its contact points may still hit another under its path
        // (a ball skimming a rough terrain at 50–830 m/s sank up to 74 % of its radius into
        // the next slope, as far as the core sphere lets it). So each triangle gets the core
        // sphere only where the body starts the step touching it.
        return height_field_triangles(body, height_field, target_sweep)
            .iter()
            .filter_map(|triangle| clamp_fraction_castable(body, triangle, target_sweep, false))
            .min_by(f32::total_cmp);
    }
    clamp_fraction_castable(body, target, target_sweep, in_contact)
}

/// The box of the half-space below the plane through the origin with outward unit `normal`
/// (the half-space's frame) that holds every point of it within `region` (same frame): its top
/// face lies on the plane, across the projection of the ball around `region`, and it reaches
/// down to that ball's lowest point. Within `region` the box and the half-space are the same
/// set, so a body that stays in `region` meets the one where it meets the other. `None` when
/// the ball lies wholly above the plane (nothing there to meet). Returns the box and its pose
/// in the half-space's frame.
pub(crate) fn half_space_slab(normal: Vec3, region: &Aabb) -> Option<(Cuboid, Pose)> {
    let center = region.center();
    let reach = region.half_extents().length();
    let height = normal.dot(center);
    if height.is_nan() || height > reach {
        return None;
    }
    let half_depth = 0.5 * (reach - height).max(1.0e-3);
    let top = center - normal * height;
    let pose = Pose::from_parts(
        top - normal * half_depth,
        Quat::from_rotation_arc(Vec3::Y, normal),
    );
    Some((Cuboid::new(Vec3::new(reach, half_depth, reach)), pose))
}

/// Most slices of the body's path [`height_field_triangles`] gathers triangles over.
const MAX_PATH_SLICES: usize = 64;

/// The triangles of `height_field` (in its own frame) that `body` can reach in the step: those
/// in the boxes of [`FastBody::region_in`] over slices of the step short enough that each box
/// hugs the path (about the body's diameter of travel each, at most [`MAX_PATH_SLICES`]), each
/// triangle once.
pub(crate) fn height_field_triangles(
    body: &FastBody<'_>,
    height_field: &HeightField,
    target_sweep: &Sweep,
) -> Vec<Triangle> {
    let (a, b) = body.sweep.center_path();
    let slices = ((a - b).length() / (2.0 * body.radius).max(1.0e-3))
        .ceil()
        .clamp(1.0, MAX_PATH_SLICES as f32) as usize;
    let mut found: Vec<(u32, Triangle)> = Vec::new();
    for k in 0..slices {
        let (from, to) = (k as f32 / slices as f32, (k + 1) as f32 / slices as f32);
        let region = body.region_in(target_sweep, from, to);
        height_field.map_elements_in_local_aabb(&region, &mut |id, triangle| {
            found.push((id, *triangle));
        });
    }
    found.sort_unstable_by_key(|&(id, _)| id);
    found.dedup_by_key(|&mut (id, _)| id);
    found.into_iter().map(|(_, triangle)| triangle).collect()
}

/// Most casts [`confirmed_time_of_impact`] makes in a step.
const CONFIRM_CASTS: usize = 16;

/// The first time of impact (fraction of the step) of `body` on `target` moving along
/// `target_sweep`, by Parry's nonlinear cast, confirmed by the exact distance there: the cast
/// advances along one separating direction at a time and may stop where the shapes no longer
/// approach along it while still apart (a cube passing a wall's edge 0.2 mm away stopped
/// there, a false impact). A time where the shapes are farther apart than a thousandth of the
/// body's smallest half extent is no impact: the cast goes on from the earliest time they
/// could touch, that distance later at the speed its points move at most ([`Sweep::travel`]).
/// Only a pair that does not turn is confirmed so: Parry's answer that nothing comes after
/// (one separating plane at the end of the step) holds for a straight motion only, and a
/// turning body cast on from a later time could be let through (a plate spinning at 100 rad/s
/// into a wall was). A turning pair keeps the cast's first time, as does a cast that has not
/// settled in [`CONFIRM_CASTS`].
fn confirmed_time_of_impact(
    body: &FastBody<'_>,
    target: &dyn Shape,
    target_sweep: &Sweep,
) -> Option<f32> {
    let (motion, target_motion) = (body.sweep.motion(), target_sweep.motion());
    let tolerance = 1.0e-3 * body.min_half_extent;
    let turns = body.sweep.turn != Vec3::ZERO || target_sweep.turn != Vec3::ZERO;
    let (target_center, _) = target_sweep.center_path();
    let (mut from, mut first) = (0.0, None);
    for _ in 0..CONFIRM_CASTS {
        let cast = |from| {
            cast_shapes_nonlinear(&motion, body.shape, &target_motion, target, from, 1.0, true)
        };
        let hit = cast(from).ok()??;
        let t = hit.time_of_impact;
        first.get_or_insert(t);
        if t >= 1.0 || turns {
            return Some(t);
        }
        let (at, target_at) = (body.sweep.pose_at(t), target_sweep.pose_at(t));
        let apart = distance(&at, body.shape, &target_at, target).map_or(0.0, |d| d.distance);
        if apart <= tolerance {
            return Some(t);
        }
        // The target's points near the body move at most its travel at that reach.
        let reach = (at.transform_point(body.sweep.local_center_of_mass) - target_center).length()
            + body.radius;
        let closing = body.travel + target_sweep.travel(reach + body.travel);
        from = t + apart / closing;
        if from.is_nan() || from >= 1.0 {
            return None;
        }
    }
    first
}

/// [`clamp_fraction`] for a target Parry's nonlinear cast takes (support maps, meshes,
/// compounds). With the two apart by more than the gap at the start and no contact between
/// them this step (`in_contact` false): the first time of impact of Parry's nonlinear cast,
/// moved back by the gap along the motion. With the two touching at the start,
/// or in contact this step (the solver already held them apart at the points the narrow phase
/// found, speculative ones included): the time of impact of the body's core sphere, so that
/// only a body driven through the target is stopped, and a body sliding or spinning along it
/// is not held at its start pose step after step. Shape pairs Parry cannot cast are not
/// clamped.
pub(crate) fn clamp_fraction_castable(
    body: &FastBody<'_>,
    target: &dyn Shape,
    target_sweep: &Sweep,
    in_contact: bool,
) -> Option<f32> {
    let gap = CLAMP_GAP.min(0.1 * body.min_half_extent);
    let start_distance = if in_contact {
        0.0
    } else {
        distance(&body.sweep.start, body.shape, &target_sweep.start, target)
            .ok()?
            .distance
    };
    if start_distance > gap {
        let t = confirmed_time_of_impact(body, target, target_sweep)?;
        return (t < 1.0).then(|| (t - gap / body.travel).max(0.0));
    }
    let core = core_spheres(body, &mut |core, center| {
        clamp_core(body, core, center, target_sweep, target)
    });
    if let Some(limit) = body.released
        && driven_in(body, target, target_sweep)
    {
        // Its rows held it while it turned by less than the limit: it is put back to where it
        // had turned that far, and the next step's contacts, taken there, go on.
        let held = limit / body.sweep.turn.length();
        return Some(core.map_or(held, |t| t.min(held)));
    }
    core
}

/// Whether `body` ends the step inside `target` (moving along `target_sweep`) deeper than it
/// started by more than its smallest half extent: deeper than contacts that hold a body ever
/// let it sink. A thin body held at one corner and turning past the solver's limit swings
/// its other corners through the surface while its core sphere, at its centre, stays out (a
/// card spinning at 120 rad/s off its first corner's impact ended with its centre on a plane
/// and corners 34 mm under it).
fn driven_in(body: &FastBody<'_>, target: &dyn Shape, target_sweep: &Sweep) -> bool {
    let depth = |at: &Pose, target_at: &Pose| {
        contact(at, body.shape, target_at, target, 0.0)
            .ok()
            .flatten()
            .map_or(0.0, |c| (-c.dist).max(0.0))
    };
    let start = depth(&body.sweep.start, &target_sweep.start);
    let end = depth(&body.sweep.end, &target_sweep.end);
    end > start + body.min_half_extent
}

/// Calls `each` with every core sphere of `body` (in contact, [`clamp_fraction_castable`]):
/// a ball and its centre in the body frame, and returns the earliest fraction any of them
/// gives. A compound has one core sphere per part, at the mean of the part's vertices (inside
/// the convex part) with a [`CORE_FRACTION`] of the part's smallest half extent: the centre of
/// mass of a ring or a mug lies in its hole, where a core sphere of the whole body would meet a
/// peg through the hole that the ring itself never touches, and hold the ring still. Any other
/// shape has one, at its centre of mass, with a [`CORE_FRACTION`] of [`FastBody::min_half_extent`].
fn core_spheres(
    body: &FastBody<'_>,
    each: &mut dyn FnMut(Ball, Vec3) -> Option<f32>,
) -> Option<f32> {
    let Some(compound) = body.shape.as_shape::<Compound>() else {
        return each(
            Ball::new(CORE_FRACTION * body.min_half_extent),
            body.sweep.local_center_of_mass,
        );
    };
    compound
        .shapes()
        .iter()
        .filter_map(|(pose, part)| {
            let inside = match part.as_convex_polyhedron() {
                Some(hull) if !hull.points().is_empty() => {
                    hull.points().iter().copied().sum::<Vec3>() / hull.points().len() as f32
                }
                _ => part.compute_local_aabb().center(),
            };
            let half = part.compute_local_aabb().half_extents().min_element();
            each(
                Ball::new(CORE_FRACTION * half),
                pose.transform_point(inside),
            )
        })
        .min_by(f32::total_cmp)
}

/// The clamp from one core sphere `core` centred at `center` (body frame) of `body`: its first
/// time of impact with `target`, moved back by the gap along the centre's path; `None` when it
/// starts touching the target or does not meet it in the step.
fn clamp_core(
    body: &FastBody<'_>,
    core: Ball,
    center: Vec3,
    target_sweep: &Sweep,
    target: &dyn Shape,
) -> Option<f32> {
    let gap = CLAMP_GAP.min(0.1 * body.min_half_extent);
    let core_sweep = body.sweep.of_part(&Pose::from_translation(center));
    let target_motion = target_sweep.motion();
    let cast = |from: f32| {
        cast_shapes_nonlinear(
            &core_sweep.motion(),
            &core,
            &target_motion,
            target,
            from,
            1.0,
            true,
        )
    };
    let mut hit = cast(0.0).ok()??;
    // A ball about the centre of mass moves along the centre's straight path however the body
    // turns, so against a target that does not turn its cast is confirmed by the distance, as
    // a whole body's is ([`confirmed_time_of_impact`]): Parry's cast read a card's core sphere
    // 1 mm above a mesh triangle, and moving away from it, as touching it at the step's start,
    // and the card was held still, a corner in the mesh, step after step.
    let straight = center == body.sweep.local_center_of_mass || body.sweep.turn == Vec3::ZERO;
    if straight && target_sweep.turn == Vec3::ZERO {
        let tolerance = 1.0e-3 * body.min_half_extent;
        let (start, end) = core_sweep.center_path();
        let closing = (end - start).length()
            + (target_sweep.end.translation - target_sweep.start.translation).length();
        for _ in 0..CONFIRM_CASTS {
            let t = hit.time_of_impact;
            if !(t > 0.0 && t < 1.0) {
                break;
            }
            let (at, target_at) = (core_sweep.pose_at(t), target_sweep.pose_at(t));
            let apart = distance(&at, &core, &target_at, target).map_or(0.0, |d| d.distance);
            if apart <= tolerance {
                break;
            }
            let from = t + apart / closing;
            if from.is_nan() || from >= 1.0 {
                return None;
            }
            hit = cast(from).ok()??;
        }
    }
    let t = hit.time_of_impact;
    if !(t > 0.0 && t < 1.0) {
        return None;
    }
    // Moved back by the gap along the centre's path, as the whole body is above: a core sphere
    // left touching the target casts a time of impact of 0 the next step, and so would not be
    // clamped again however far the body then went through.
    let center_travel = (core_sweep.end.translation - core_sweep.start.translation).length();
    Some(if center_travel > gap {
        (t - gap / center_travel).max(0.0)
    } else {
        0.0
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Quat;

    /// The cheap bound is never below the sweep's travel where it answers (turns up to 60°,
    /// spins up to 1 rad, off-centre masses), follows a small turn to within its π/2 factor,
    /// and declines a fast spin or a large turn.
    #[test]
    fn the_travel_bound_holds_the_sweeps_travel() {
        let axes = [Vec3::X, Vec3::new(0.3, -0.8, 0.52).normalize(), Vec3::Z];
        let mut answered = 0;
        for (k, axis) in axes.into_iter().enumerate() {
            for angle in [0.0f32, 1e-6, 1e-3, 0.1, 0.5, 1.0, 1.04, 1.1, 2.0, 3.1] {
                for spin_scale in [0.0f32, 0.5, 1.0, 1.5] {
                    let start = Pose::from_parts(
                        Vec3::new(1.0, 2.0, -0.5),
                        Quat::from_rotation_x(0.4 * k as f32),
                    );
                    let turn = Quat::from_axis_angle(axis, angle);
                    let end = Pose::from_parts(
                        Vec3::new(1.01, 1.98, -0.5),
                        (turn * start.rotation).normalize(),
                    );
                    let com = Vec3::new(0.05, -0.02, 0.1);
                    let spin = axis * angle * spin_scale;
                    let radius = 0.7;
                    let travel = Sweep::new(start, end, com, spin).travel(radius);
                    match travel_bound(&start, &end, com, spin, radius) {
                        Some(bound) => {
                            answered += 1;
                            assert!(bound >= travel, "{angle} {spin}: {bound} < {travel}");
                            assert!(bound <= 1.6 * travel + 1e-6, "{angle}: {bound} ≫ {travel}");
                            assert!(angle <= 1.05 && spin.length() <= 1.0);
                        }
                        None => assert!(angle > 1.04 || spin.length() > 1.0, "{angle} {spin}"),
                    }
                }
            }
        }
        assert!(answered > 40);
    }

    /// Within the region it is built for, the half-space's box holds exactly the points of
    /// the half-space: points of a grid over the region (tilted planes, the region above,
    /// across and below the plane) are inside the box just when they are below the plane
    /// (to within 10 µm of it). A region wholly above the plane gets no box.
    #[test]
    fn the_half_space_box_is_the_half_space_within_the_region() {
        use parry3d::query::PointQuery;
        let normals = [
            Vec3::Y,
            Vec3::new(0.3, 0.9, -0.2).normalize(),
            Vec3::new(-0.7, 0.1, 0.7).normalize(),
        ];
        let mut checked = 0;
        for normal in normals {
            for height in [-3.0f32, -0.4, 0.0, 0.7, 1.9] {
                let center = normal * height + Vec3::new(5.0, -2.0, 1.0).cross(normal);
                let region = Aabb::new(
                    center - Vec3::new(1.0, 0.5, 2.0),
                    center + Vec3::new(1.0, 0.5, 2.0),
                );
                let Some((slab, pose)) = half_space_slab(normal, &region) else {
                    assert!(normal.dot(center) > region.half_extents().length());
                    continue;
                };
                for i in 0..=8 {
                    for j in 0..=8 {
                        for k in 0..=8 {
                            let f = Vec3::new(i as f32, j as f32, k as f32) / 8.0;
                            let p = region.mins + (region.maxs - region.mins) * f;
                            let below = normal.dot(p);
                            if below.abs() < 1.0e-5 {
                                continue;
                            }
                            let inside = slab.contains_point(&pose, p);
                            assert_eq!(inside, below < 0.0, "{normal} {height} {p}");
                            checked += 1;
                        }
                    }
                }
            }
        }
        assert!(checked > 5000, "{checked}");
        let above = Aabb::new(Vec3::new(-1.0, 5.0, -1.0), Vec3::new(1.0, 6.0, 1.0));
        assert!(half_space_slab(Vec3::Y, &above).is_none());
    }

    /// A body that spins 20 rad about z in a step is swept 20 rad about z, the turn that ends
    /// at its end orientation nearest to its spin, not the short way (20 − 6π ≈ 1.15 rad).
    /// Spinning backwards as far, it is swept backwards.
    #[test]
    fn a_fast_spin_is_swept_the_way_it_turns() {
        let start = Pose::IDENTITY;
        for spin in [20.0f32, -20.0] {
            let end = Pose::from_parts(Vec3::ZERO, Quat::from_rotation_z(spin));
            let sweep = Sweep::new(start, end, Vec3::ZERO, Vec3::new(0.0, 0.0, spin));
            assert!(
                (sweep.turn - Vec3::new(0.0, 0.0, spin)).length() < 1e-3,
                "{sweep:?}"
            );
            let end_rotation = sweep.pose_at(1.0).rotation;
            assert!(end_rotation.angle_between(end.rotation) < 1e-3);
            // Half a step in, it has turned 10 rad, not 0.57.
            let middle = sweep.pose_at(0.5).rotation;
            assert!(middle.angle_between(Quat::from_rotation_z(0.5 * spin)) < 1e-3);
        }
        // A slow turn is the short rotation itself.
        let end = Pose::from_parts(Vec3::X, Quat::from_rotation_y(0.3));
        let sweep = Sweep::new(start, end, Vec3::ZERO, Vec3::new(0.0, 0.31, 0.0));
        assert!(
            (sweep.turn - Vec3::new(0.0, 0.3, 0.0)).length() < 1e-5,
            "{sweep:?}"
        );
    }
}
