//! The bodies' state as parallel arrays (structure of arrays), so the stages of the step touch
//! only the fields they need.

use glam::{Mat3, Vec3};
use parry3d::math::Pose;
use parry3d::shape::SharedShape;
use serde::{Deserialize, Serialize};

#[cfg(doc)]
use super::BodyBuilder;
use super::{BodyKind, LockedAxes};

/// All bodies of a world. Index `i` of every array is body `i` in scene order. Private to the
/// engine (the stages read and write the arrays directly); users read them through
/// [`crate::World::poses`] and the other read views.
///
/// Velocities are those of the centre of mass; `pose` is the body frame the scene gave
/// (trajectories report it), and `local_center_of_mass` locates the centre of mass in it.
#[derive(Clone, Default, Serialize, Deserialize)]
#[cfg_attr(not(feature = "internals"), allow(unreachable_pub))]
pub struct Bodies {
    /// Dynamic, static, particle or kinematic.
    pub(crate) kind: Vec<BodyKind>,
    /// Body frame in world coordinates.
    pub(crate) pose: Vec<Pose>,
    /// Centre of mass in the body frame (m).
    pub(crate) local_center_of_mass: Vec<Vec3>,
    /// Linear velocity of the centre of mass (m/s).
    pub(crate) linear_velocity: Vec<Vec3>,
    /// Angular velocity, world frame (rad/s). Always zero for particles and static bodies;
    /// a kinematic body's is its prescribed one.
    pub(crate) angular_velocity: Vec<Vec3>,
    /// 1/m (1/kg); 0 for static and kinematic bodies.
    pub(crate) inverse_mass: Vec<f32>,
    /// Inverse inertia tensor about the centre of mass, body frame (1/(kg·m²)); zero for
    /// static and kinematic bodies and particles (rotation locked).
    pub(crate) local_inverse_inertia: Vec<Mat3>,
    /// Collision shape in the body frame. Stored as a table of distinct shapes
    /// (`shape_table.rs`), so bodies of one mesh store its parts once.
    #[serde(with = "super::shape_table")]
    pub(crate) shape: Vec<SharedShape>,
    /// Coulomb friction coefficient μ.
    pub(crate) friction: Vec<f32>,
    /// Restitution coefficient c_r.
    pub(crate) restitution: Vec<f32>,
    /// Surface roughness (rad): the largest tilt of a new contact's normal (0: smooth).
    /// Absent from snapshots written before it existed: read as every body smooth.
    #[serde(default)]
    pub(crate) roughness: Vec<f32>,
    /// Impact perturbation (dimensionless, in [0, 1]): the largest change of an impact's
    /// restitution (0: none). Absent from snapshots written before it existed: read as 0.
    #[serde(default)]
    pub(crate) impact_perturbation: Vec<f32>,
    /// Explicit roughness draws ([`BodyBuilder::roughness_draws`]): standard-normal pairs
    /// (a, b), given in turn to the new rough manifolds whose draw the body gives. Absent
    /// from snapshots written before they existed: none.
    #[serde(default)]
    pub(crate) roughness_draws: Vec<Vec<[f32; 2]>>,
    /// How many of its `roughness_draws` the body has given so far: world state, so a
    /// restored world gives the next one. Absent from older snapshots: none given.
    #[serde(default)]
    pub(crate) roughness_draws_given: Vec<u32>,
    /// Asleep: skipped by the step until something awake touches its island. A kinematic
    /// body counts as asleep exactly while it does not move (zero velocities).
    pub(crate) asleep: Vec<bool>,
    /// How long (s) the body has been below the sleep thresholds.
    pub(crate) sleep_time: Vec<f32>,
    /// Force (N) applied at the centre of mass during the next step, then cleared.
    pub(crate) force: Vec<Vec3>,
    /// Torque (N·m, world frame) applied during the next step, then cleared.
    pub(crate) torque: Vec<Vec3>,
    /// Name given when the body was made.
    pub(crate) name: Vec<Option<String>>,
    /// The caller's number for the body ([`BodyBuilder::user_data`]).
    pub(crate) user_data: Vec<u128>,
    /// Linear damping c (1/s): v ← v/(1 + h·c) per substep ([`BodyBuilder::linear_damping`]).
    pub(crate) linear_damping: Vec<f32>,
    /// Angular damping c (1/s): ω ← ω/(1 + h·c) per substep.
    pub(crate) angular_damping: Vec<f32>,
    /// Collision groups the body belongs to, one bit each ([`BodyBuilder::collision_groups`]).
    pub(crate) groups: Vec<u32>,
    /// Collision groups the body collides with.
    pub(crate) mask: Vec<u32>,
    /// The world axes the body may not translate along or rotate about
    /// ([`BodyBuilder::locked_axes`]); always [`LockedAxes::NONE`] for static and kinematic
    /// bodies.
    pub(crate) locked_axes: Vec<LockedAxes>,
}

impl Bodies {
    /// The velocities of an island's slots into `linear` and `angular` (m/s, rad/s; cleared
    /// first): its bodies', its guests' (`island_bodies` and `guests`, body indices), then the
    /// immovable slot's, zero.
    pub(crate) fn gather_slot_velocities(
        &self,
        island_bodies: &[u32],
        guests: &[u32],
        linear: &mut Vec<Vec3>,
        angular: &mut Vec<Vec3>,
    ) {
        linear.clear();
        angular.clear();
        for &i in island_bodies.iter().chain(guests) {
            linear.push(self.linear_velocity[i as usize]);
            angular.push(self.angular_velocity[i as usize]);
        }
        linear.push(Vec3::ZERO);
        angular.push(Vec3::ZERO);
    }

    /// Removes body `i`, moving the last body into its place; returns its name.
    pub(crate) fn swap_remove(&mut self, i: usize) -> Option<String> {
        self.kind.swap_remove(i);
        self.pose.swap_remove(i);
        self.local_center_of_mass.swap_remove(i);
        self.linear_velocity.swap_remove(i);
        self.angular_velocity.swap_remove(i);
        self.inverse_mass.swap_remove(i);
        self.local_inverse_inertia.swap_remove(i);
        self.shape.swap_remove(i);
        self.friction.swap_remove(i);
        self.restitution.swap_remove(i);
        self.roughness.swap_remove(i);
        self.impact_perturbation.swap_remove(i);
        self.roughness_draws.swap_remove(i);
        self.roughness_draws_given.swap_remove(i);
        self.asleep.swap_remove(i);
        self.sleep_time.swap_remove(i);
        self.force.swap_remove(i);
        self.torque.swap_remove(i);
        self.user_data.swap_remove(i);
        self.linear_damping.swap_remove(i);
        self.angular_damping.swap_remove(i);
        self.groups.swap_remove(i);
        self.mask.swap_remove(i);
        self.locked_axes.swap_remove(i);
        self.name.swap_remove(i)
    }

    /// Checks that every array has one entry per body (a snapshot's bodies before they are
    /// trusted). Lists the same fields as [`Self::swap_remove`].
    pub(crate) fn check_lengths(&self) -> Result<(), String> {
        let n = self.kind.len();
        let lengths = [
            ("pose", self.pose.len()),
            ("local_center_of_mass", self.local_center_of_mass.len()),
            ("linear_velocity", self.linear_velocity.len()),
            ("angular_velocity", self.angular_velocity.len()),
            ("inverse_mass", self.inverse_mass.len()),
            ("local_inverse_inertia", self.local_inverse_inertia.len()),
            ("shape", self.shape.len()),
            ("friction", self.friction.len()),
            ("restitution", self.restitution.len()),
            ("roughness", self.roughness.len()),
            ("impact_perturbation", self.impact_perturbation.len()),
            ("roughness_draws", self.roughness_draws.len()),
            ("roughness_draws_given", self.roughness_draws_given.len()),
            ("asleep", self.asleep.len()),
            ("sleep_time", self.sleep_time.len()),
            ("force", self.force.len()),
            ("torque", self.torque.len()),
            ("user_data", self.user_data.len()),
            ("linear_damping", self.linear_damping.len()),
            ("angular_damping", self.angular_damping.len()),
            ("groups", self.groups.len()),
            ("mask", self.mask.len()),
            ("locked_axes", self.locked_axes.len()),
            ("name", self.name.len()),
        ];
        match lengths.iter().find(|(_, len)| *len != n) {
            Some((field, len)) => Err(format!("bodies.{field} has {len} entries for {n} bodies")),
            None => Ok(()),
        }
    }

    /// Number of bodies.
    pub(crate) fn len(&self) -> usize {
        self.kind.len()
    }

    /// True when there are no bodies.
    pub(crate) fn is_empty(&self) -> bool {
        self.kind.is_empty()
    }

    /// True for moving bodies that are awake: the dynamic bodies the step simulates, and
    /// kinematic bodies in motion.
    pub(crate) fn is_awake(&self, i: usize) -> bool {
        self.kind[i] != BodyKind::Static && !self.asleep[i]
    }

    /// True for bodies that may move: dynamic rigid bodies, particles and kinematic bodies.
    pub(crate) fn is_moving(&self, i: usize) -> bool {
        self.kind[i] != BodyKind::Static
    }

    /// True for bodies moved by forces and contacts (dynamic rigid bodies and particles): the
    /// bodies of islands. Static and kinematic bodies take no impulse.
    pub(crate) fn is_dynamic(&self, i: usize) -> bool {
        self.kind[i].is_dynamic()
    }

    /// Whether bodies `a` and `b` may collide by their collision groups:
    /// `(groups_a & mask_b) != 0 && (groups_b & mask_a) != 0`.
    #[inline]
    pub(crate) fn groups_interact(&self, a: usize, b: usize) -> bool {
        (self.groups[a] & self.mask[b]) != 0 && (self.groups[b] & self.mask[a]) != 0
    }

    /// World position of body `i`'s centre of mass (m).
    pub(crate) fn center_of_mass(&self, i: usize) -> Vec3 {
        self.pose[i].transform_point(self.local_center_of_mass[i])
    }

    /// World-frame inverse inertia R·I⁻¹·Rᵀ of body `i` (1/(kg·m²)), restricted to the
    /// rotations its locked axes leave free ([`LockedAxes::world_inverse_inertia`]); zero for a
    /// body that does not rotate.
    pub(crate) fn world_inverse_inertia(&self, i: usize) -> Mat3 {
        let local = &self.local_inverse_inertia[i];
        if *local == Mat3::ZERO {
            return Mat3::ZERO;
        }
        self.locked_axes[i].world_inverse_inertia(self.pose[i].rotation, local)
    }

    /// Whether body `i`, at its angular velocity (rad/s), turns by more than `spin` (rad) in a
    /// step of `dt` seconds and its contact points turn with it
    /// ([`Self::contact_points_turn_with_body`]): its rows may have to follow the turn.
    pub(crate) fn turns_in_step(&self, i: usize, dt: f32, spin: f32) -> bool {
        self.angular_velocity[i].length() * dt > spin && self.contact_points_turn_with_body(i)
    }

    /// Whether body `i`'s contact points are points of the body that turn with it: a
    /// polyhedron's vertices, edges and faces, a mesh's, a height field's and compounds of
    /// these. A round shape's (ball, capsule, cylinder, cone, rounded shapes) slide over its
    /// surface as it turns: a ball's stays below its centre however it rolls.
    pub(crate) fn contact_points_turn_with_body(&self, i: usize) -> bool {
        fn polyhedral(shape: &dyn parry3d::shape::Shape) -> bool {
            use parry3d::shape::ShapeType;
            match shape.shape_type() {
                ShapeType::Cuboid
                | ShapeType::ConvexPolyhedron
                | ShapeType::Triangle
                | ShapeType::TriMesh
                | ShapeType::Polyline
                | ShapeType::HeightField
                | ShapeType::HalfSpace
                | ShapeType::Voxels => true,
                ShapeType::Compound => shape
                    .as_compound()
                    .is_some_and(|c| c.shapes().iter().all(|(_, part)| polyhedral(part.as_ref()))),
                _ => false,
            }
        }
        polyhedral(self.shape[i].as_ref())
    }

    /// Per-axis inverse mass of body `i` (1/kg per world axis): 1/m on each free translation
    /// axis, 0 on each locked one (Rapier's `effective_inv_mass`); zero for static and
    /// kinematic bodies. A linear impulse p changes the velocity of the centre of mass by
    /// `effective_inverse_mass * p`, component by component.
    #[inline]
    pub(crate) fn effective_inverse_mass(&self, i: usize) -> Vec3 {
        let inverse_mass = Vec3::splat(self.inverse_mass[i]);
        let locked = self.locked_axes[i];
        if locked.locks_translation() {
            inverse_mass * locked.translation_factor()
        } else {
            inverse_mass
        }
    }

    /// Mass (kg) of body `i`; infinity for static and kinematic bodies.
    pub(crate) fn mass(&self, i: usize) -> f32 {
        if self.inverse_mass[i] > 0.0 {
            1.0 / self.inverse_mass[i]
        } else {
            f32::INFINITY
        }
    }

    /// Kinetic energy ½mv² + ½ωᵀIω of body `i` (J); 0 for static and kinematic bodies
    /// (infinite mass: their motion is prescribed, not part of the system's energy).
    pub(crate) fn kinetic_energy(&self, i: usize) -> f32 {
        if self.inverse_mass[i] == 0.0 {
            return 0.0;
        }
        let v = self.linear_velocity[i];
        let mut energy = 0.5 * v.length_squared() / self.inverse_mass[i];
        let w = self.angular_velocity[i];
        if w != Vec3::ZERO {
            energy +=
                0.5 * inertia_form(&self.local_inverse_inertia[i], self.pose[i].rotation, w, w);
        }
        energy
    }
}

/// The inertia tensor's bilinear form xᵀ·I_world·y (kg·m²/s² for angular velocities in rad/s)
/// of a body with local inverse inertia `local_inverse_inertia` (1/(kg·m²)) turned by
/// `rotation`, computed as x_lᵀ·I_local·y_l with x_l = Rᵀx: no world tensor to build, and
/// I_local = (I⁻¹_local)⁻¹ is a division per axis for the usual diagonal tensor. Zero when
/// the inverse is singular (every rotation locked). ½·ωᵀ·I·ω is the rotational kinetic energy.
pub(crate) fn inertia_form(
    local_inverse_inertia: &Mat3,
    rotation: glam::Quat,
    x: Vec3,
    y: Vec3,
) -> f32 {
    let inverse_rotation = rotation.inverse();
    let (x, y) = (inverse_rotation * x, inverse_rotation * y);
    let inv = local_inverse_inertia;
    let diagonal = Vec3::new(inv.x_axis.x, inv.y_axis.y, inv.z_axis.z);
    let off_diagonal = inv.x_axis.y != 0.0
        || inv.x_axis.z != 0.0
        || inv.y_axis.x != 0.0
        || inv.y_axis.z != 0.0
        || inv.z_axis.x != 0.0
        || inv.z_axis.y != 0.0;
    if !off_diagonal && diagonal.cmpgt(Vec3::ZERO).all() {
        x.dot(y / diagonal)
    } else if inv.determinant().abs() > f32::MIN_POSITIVE {
        x.dot(inv.inverse() * y)
    } else {
        0.0
    }
}
