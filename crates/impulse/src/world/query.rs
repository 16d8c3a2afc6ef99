//! Geometric queries against the world's bodies at their current poses, through Parry: ray
//! casts, shape casts, and point and shape overlaps.
//!
//! Each query tests every body's bounding box first and runs Parry's exact test only on the
//! boxes it meets: O(bodies) per query, which suits occasional queries (picking, line of
//! sight, spawning); a game casting thousands of rays a step wants them batched against the
//! broad phase's tree, which is not exposed yet.

use glam::Vec3;
use parry3d::bounding_volume::{Aabb, BoundingVolume};
use parry3d::math::Pose;
use parry3d::query::{Ray, RayCast, ShapeCastOptions};
use parry3d::shape::Shape;

use super::World;
use crate::body::BodyHandle;

/// Where a ray meets a body ([`World::cast_ray`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayHit {
    /// The body hit first.
    pub body: BodyHandle,
    /// Ray parameter of the hit: the hit is at origin + distance·direction (metres when the
    /// direction has unit length).
    pub distance: f32,
    /// The hit point (m).
    pub point: Vec3,
    /// The surface normal there, pointing out of the body (zero for a ray starting inside a
    /// solid cast).
    pub normal: Vec3,
}

/// Where a moving shape first touches a body ([`World::cast_shape`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShapeHit {
    /// The body touched first.
    pub body: BodyHandle,
    /// Time of impact (s at the given velocity; the shape has moved velocity·time).
    pub time: f32,
    /// The touching point on the moving shape, and on the body, at that time (m).
    pub witness_shape: Vec3,
    /// See `witness_shape`.
    pub witness_body: Vec3,
    /// Unit normal at the moving shape's touching point, pointing out of it.
    pub normal: Vec3,
}

impl World {
    /// The first body along the ray from `origin` in `direction`, within `max_distance`
    /// (in units of the direction's length). With `solid`, a ray starting inside a body hits
    /// it at distance 0; otherwise it hits the body's boundary from inside. `None` when
    /// nothing is hit or the inputs are not finite.
    pub fn cast_ray(
        &self,
        origin: Vec3,
        direction: Vec3,
        max_distance: f32,
        solid: bool,
    ) -> Option<RayHit> {
        if !(origin.is_finite() && direction.is_finite() && max_distance >= 0.0) {
            return None;
        }
        let ray = Ray::new(origin, direction);
        let mut best: Option<RayHit> = None;
        for (i, shape) in self.bodies.shape.iter().enumerate() {
            let pose = &self.bodies.pose[i];
            let limit = best.map_or(max_distance, |b| b.distance);
            if shape
                .compute_aabb(pose)
                .cast_ray(&Pose::IDENTITY, &ray, limit, true)
                .is_none()
            {
                continue;
            }
            if let Some(hit) = shape.cast_ray_and_get_normal(pose, &ray, limit, solid) {
                best = Some(RayHit {
                    body: self.handles.of_body[i],
                    distance: hit.time_of_impact,
                    point: ray.point_at(hit.time_of_impact),
                    normal: hit.normal,
                });
            }
        }
        best
    }

    /// The bodies whose shape contains world point `point` (m).
    pub fn bodies_containing_point(&self, point: Vec3) -> impl Iterator<Item = BodyHandle> + '_ {
        let box_of_point = Aabb::new(point, point);
        (0..self.bodies.len())
            .filter(move |&i| {
                let (shape, pose) = (&self.bodies.shape[i], &self.bodies.pose[i]);
                shape.compute_aabb(pose).intersects(&box_of_point)
                    && shape.contains_point(pose, point)
            })
            .map(|i| self.handles.of_body[i])
    }

    /// The bodies that overlap `shape` placed at `pose`. Pairs of shapes Parry cannot test
    /// are skipped.
    pub fn bodies_intersecting_shape<'a>(
        &'a self,
        pose: &'a Pose,
        shape: &'a dyn Shape,
    ) -> impl Iterator<Item = BodyHandle> + 'a {
        let bounds = shape.compute_aabb(pose);
        (0..self.bodies.len())
            .filter(move |&i| {
                let (body_shape, body_pose) = (&self.bodies.shape[i], &self.bodies.pose[i]);
                body_shape.compute_aabb(body_pose).intersects(&bounds)
                    && parry3d::query::intersection_test(pose, shape, body_pose, &**body_shape)
                        .is_ok_and(|test| test.intersecting)
            })
            .map(|i| self.handles.of_body[i])
    }

    /// The first body that `shape`, starting at `pose` and moving at `velocity` (m/s, no
    /// rotation), touches within `max_time` (s); bodies it already overlaps at time 0 are hit
    /// at time 0. `None` when nothing is touched or the inputs are not finite.
    pub fn cast_shape(
        &self,
        pose: &Pose,
        velocity: Vec3,
        shape: &dyn Shape,
        max_time: f32,
    ) -> Option<ShapeHit> {
        if !(velocity.is_finite() && max_time >= 0.0) {
            return None;
        }
        let start = shape.compute_aabb(pose);
        let swept = start.merged(&Aabb::new(
            start.mins + velocity * max_time,
            start.maxs + velocity * max_time,
        ));
        let mut best: Option<ShapeHit> = None;
        for (i, body_shape) in self.bodies.shape.iter().enumerate() {
            let body_pose = &self.bodies.pose[i];
            if !body_shape.compute_aabb(body_pose).intersects(&swept) {
                continue;
            }
            let limit = best.map_or(max_time, |b| b.time);
            let options = ShapeCastOptions::with_max_time_of_impact(limit);
            let Ok(Some(hit)) = parry3d::query::cast_shapes(
                pose,
                velocity,
                shape,
                body_pose,
                Vec3::ZERO,
                &**body_shape,
                options,
            ) else {
                continue;
            };
            // Parry gives the witnesses and normal in each shape's local frame.
            best = Some(ShapeHit {
                body: self.handles.of_body[i],
                time: hit.time_of_impact,
                witness_shape: pose.transform_point(hit.witness1) + velocity * hit.time_of_impact,
                witness_body: body_pose.transform_point(hit.witness2),
                normal: pose.rotation * hit.normal1,
            });
        }
        best
    }
}
