//! [`BodyBuilder`], the description of a body to insert, and its checked conversion into the
//! state a world stores.

use glam::{Mat3, Quat, Vec3};
use parry3d::mass_properties::MassProperties;
use parry3d::math::Pose;
use parry3d::shape::SharedShape;

use super::rules::{self, ShapeClass};
use super::{BodyKind, Keyframe, LockedAxes};

/// A body to insert into a [`crate::World`]: shape, kind, pose, velocities, material and mass,
/// with glam types. Units SI; velocities are those of the body origin, angular velocity in
/// the world frame. Mass and inertia come from Parry's mass properties of the shape at
/// `density` (kg/m³), scaled to `mass` when given. Checked when inserted
/// ([`crate::World::insert`]): every number finite, friction ≥ 0, restitution in [0, 1],
/// density and mass > 0, damping ≥ 0, a particle a ball, a half-space static.
///
/// ```
/// use impulse::glam::Vec3;
/// use impulse::{BodyBuilder, SharedShape};
///
/// let crate_body = BodyBuilder::dynamic(SharedShape::cuboid(0.5, 0.5, 0.5))
///     .translation(Vec3::new(0.0, 3.0, 0.0))
///     .linear_velocity(Vec3::new(1.0, 0.0, 0.0))
///     .friction(0.4)
///     .name("crate");
/// # let _ = crate_body;
/// ```
#[derive(Clone)]
pub struct BodyBuilder {
    pub(crate) kind: BodyKind,
    pub(crate) shape: SharedShape,
    pub(crate) translation: Vec3,
    pub(crate) rotation: Quat,
    pub(crate) linear_velocity: Vec3,
    pub(crate) angular_velocity: Vec3,
    pub(crate) friction: f32,
    pub(crate) restitution: f32,
    pub(crate) roughness: f32,
    pub(crate) impact_perturbation: f32,
    pub(crate) roughness_draws: Vec<[f32; 2]>,
    pub(crate) density: f32,
    pub(crate) mass: Option<f32>,
    pub(crate) name: Option<String>,
    pub(crate) user_data: u128,
    pub(crate) linear_damping: f32,
    pub(crate) angular_damping: f32,
    pub(crate) locked_axes: LockedAxes,
    pub(crate) groups: u32,
    pub(crate) mask: u32,
    pub(crate) keyframes: Vec<Keyframe>,
    pub(crate) unit_mass_properties: Option<MassProperties>,
}

impl BodyBuilder {
    /// A body of `kind` and `shape` at the origin, at rest, with the default material
    /// (friction 0.6, restitution 0, density 1000 kg/m³).
    pub fn new(kind: BodyKind, shape: SharedShape) -> Self {
        Self {
            kind,
            shape,
            translation: Vec3::ZERO,
            rotation: Quat::IDENTITY,
            linear_velocity: Vec3::ZERO,
            angular_velocity: Vec3::ZERO,
            friction: 0.6,
            restitution: 0.0,
            roughness: 0.0,
            impact_perturbation: 0.0,
            roughness_draws: Vec::new(),
            density: 1000.0,
            mass: None,
            name: None,
            user_data: 0,
            linear_damping: 0.0,
            angular_damping: 0.0,
            locked_axes: LockedAxes::NONE,
            groups: u32::MAX,
            mask: u32::MAX,
            keyframes: Vec::new(),
            unit_mass_properties: None,
        }
    }

    /// A rigid body with mass and inertia.
    pub fn dynamic(shape: SharedShape) -> Self {
        Self::new(BodyKind::Dynamic, shape)
    }

    /// A body that never moves (ground, walls).
    pub fn fixed(shape: SharedShape) -> Self {
        Self::new(BodyKind::Static, shape)
    }

    /// A kinematic body ([`BodyKind::Kinematic`]): moved at its
    /// [`Self::linear_velocity`] and [`Self::angular_velocity`] (or along its
    /// [`Self::keyframes`]), pushing dynamic bodies without being pushed.
    pub fn kinematic(shape: SharedShape) -> Self {
        Self::new(BodyKind::Kinematic, shape)
    }

    /// A ball of `radius` (m) whose rotation is locked.
    pub fn particle(radius: f32) -> Self {
        Self::new(BodyKind::Particle, SharedShape::ball(radius))
    }

    /// Position of the body origin (m).
    pub fn translation(mut self, translation: Vec3) -> Self {
        self.translation = translation;
        self
    }

    /// Orientation (normalised when inserted; must not be zero).
    pub fn rotation(mut self, rotation: Quat) -> Self {
        self.rotation = rotation;
        self
    }

    /// Linear velocity of the body origin (m/s).
    pub fn linear_velocity(mut self, velocity: Vec3) -> Self {
        self.linear_velocity = velocity;
        self
    }

    /// Angular velocity, world frame (rad/s); ignored for particles, static bodies and
    /// dynamic bodies with locked rotation.
    pub fn angular_velocity(mut self, velocity: Vec3) -> Self {
        self.angular_velocity = velocity;
        self
    }

    /// Coulomb friction coefficient μ ≥ 0; a pair uses the geometric mean of its bodies'.
    pub fn friction(mut self, friction: f32) -> Self {
        self.friction = friction;
        self
    }

    /// Restitution coefficient in [0, 1]; a pair uses the larger of its bodies'.
    pub fn restitution(mut self, restitution: f32) -> Self {
        self.restitution = restitution;
        self
    }

    /// Surface roughness (degrees) in [0, [`super::MAX_ROUGHNESS_DEGREES`]]: each new
    /// contact's normal is tilted by a random angle up to the larger of its two bodies'
    /// roughness, drawn from the world's [`crate::World::seed`], the step and the pair
    /// (docs/scene-format.md, "Materials"). 0 (the default): smooth, nothing drawn.
    pub fn roughness(mut self, degrees: f32) -> Self {
        self.roughness = degrees;
        self
    }

    /// Explicit roughness draws: pairs [a, b] of standard-normal coordinates (unit-free,
    /// finite, at most [`super::MAX_ROUGHNESS_DRAWS`]) that replace the seeded draws of the
    /// body's rough contacts, one per new manifold in the order the manifolds appear. Pair k
    /// gives the k-th new manifold whose draw this body gives the tilt
    /// 1 − cos(tilt) = cap · (1 − cos(roughness)) with cap = 1 − exp(−(a² + b²)/2), in the
    /// direction azimuth = atan2(b, a) (in [0, 2π)) about the normal. For (a, b) drawn from
    /// N(0, I₂) the cap is uniform in [0, 1) and the azimuth uniform in [0, 2π), the
    /// distribution of the seeded draws, and the map is continuous, so a search can refine a
    /// take's draws (Chenney & Forsyth, "Sampling plausible solutions to multi-body constraint
    /// problems", SIGGRAPH 2000, perturb each collision's normal). A new manifold of a pair with
    /// a rough body takes its draw from the pair's first body (lower index) if that has a draw
    /// left, else from the second, else from the seed ([`crate::World::seed`]); the tilt's size
    /// still comes from the pair's roughness ([`Self::roughness`]), so draws on a smooth pair
    /// are not used. Default none.
    pub fn roughness_draws(mut self, draws: impl IntoIterator<Item = [f32; 2]>) -> Self {
        self.roughness_draws = draws.into_iter().collect();
        self
    }

    /// Impact perturbation (dimensionless) in [0, [`super::MAX_IMPACT_PERTURBATION`]]: at an
    /// impact (a contact closing faster than the restitution threshold) the pair's restitution
    /// is moved by a seeded draw uniform in ±(the larger of its two bodies' perturbation),
    /// kept in [0, 1], so the rebound speed moves in proportion to the approach speed. Drawn
    /// from the world's [`crate::World::seed`], the step and the pair (docs/scene-format.md,
    /// "Materials"). 0 (the default): no perturbation, nothing drawn.
    pub fn impact_perturbation(mut self, perturbation: f32) -> Self {
        self.impact_perturbation = perturbation;
        self
    }

    /// Density (kg/m³) > 0.
    pub fn density(mut self, density: f32) -> Self {
        self.density = density;
        self
    }

    /// Mass (kg) > 0, overriding the density; the inertia tensor is scaled to match.
    pub fn mass(mut self, mass: f32) -> Self {
        self.mass = Some(mass);
        self
    }

    /// Mass properties at density 1 kg/m³ (mass = volume, m³) to use instead of the shape's
    /// own, scaled by the density (or to [`Self::mass`]): for a shape that only approximates
    /// the body's solid, such as the overlapping convex parts of a decomposed mesh
    /// ([`crate::scene::DecomposedMesh::unit_mass_properties`]). A kinematic body takes its
    /// centre of mass from them. Checked when inserted: mass > 0, everything finite.
    pub fn unit_mass_properties(mut self, properties: MassProperties) -> Self {
        self.unit_mass_properties = Some(properties);
        self
    }

    /// A name, shown in error messages and exports.
    pub fn name(mut self, name: impl Into<String>) -> Self {
        self.name = Some(name.into());
        self
    }

    /// Any number the caller wants to find the body by; the engine never reads it.
    pub fn user_data(mut self, user_data: u128) -> Self {
        self.user_data = user_data;
        self
    }

    /// Linear damping c (1/s, finite, ≥ 0): each substep of h seconds scales the linear
    /// velocity by 1/(1 + h·c), after gravity and applied forces (Box2D's damping, implicit
    /// so that it is stable for any c). Default 0.
    pub fn linear_damping(mut self, damping: f32) -> Self {
        self.linear_damping = damping;
        self
    }

    /// Angular damping c (1/s, finite, ≥ 0): each substep scales the angular velocity by
    /// 1/(1 + h·c), as [`Self::linear_damping`]. Default 0.
    pub fn angular_damping(mut self, damping: f32) -> Self {
        self.angular_damping = damping;
        self
    }

    /// Locks all three rotation axes of a dynamic body (default unlocked), or unlocks them:
    /// [`Self::locked_axes`] with [`LockedAxes::ALL_ROTATIONS`] added or removed. Its world
    /// inverse inertia is then zero, so contacts, torques and impulses cannot turn it, and its
    /// angular velocity stays zero. It still translates.
    pub fn lock_rotation(mut self, locked: bool) -> Self {
        self.locked_axes = if locked {
            self.locked_axes | LockedAxes::ALL_ROTATIONS
        } else {
            self.locked_axes.difference(LockedAxes::ALL_ROTATIONS)
        };
        self
    }

    /// The world axes along which a dynamic body may not translate or about which it may not
    /// rotate (default none; [`LockedAxes`]). The locked components of the builder's
    /// velocities are dropped. Ignored for static and kinematic bodies (which contacts never
    /// move) and, for rotations, for particles (which never rotate).
    ///
    /// ```
    /// use impulse::{BodyBuilder, LockedAxes, SharedShape};
    ///
    /// // A door: turns only about the vertical axis and does not translate.
    /// let door = BodyBuilder::dynamic(SharedShape::cuboid(0.5, 1.0, 0.05))
    ///     .locked_axes(LockedAxes::ALL_TRANSLATIONS | LockedAxes::ROTATION_X | LockedAxes::ROTATION_Z);
    /// # let _ = door;
    /// ```
    pub fn locked_axes(mut self, locked_axes: LockedAxes) -> Self {
        self.locked_axes = locked_axes;
        self
    }

    /// Collision groups: `groups` are the groups the body belongs to and `mask` the groups it
    /// collides with, one bit each; bodies a and b collide when
    /// `(groups_a & mask_b) != 0 && (groups_b & mask_a) != 0` (Rapier's `InteractionGroups`).
    /// Default all bits of both: every body collides with every other.
    pub fn collision_groups(mut self, groups: u32, mask: u32) -> Self {
        self.groups = groups;
        self.mask = mask;
        self
    }

    /// Keyframes of a kinematic body (kinematic bodies only; default none): the body moves
    /// from its initial pose (its pose at time 0) through each keyframe's pose at its time,
    /// linearly in translation and by slerp in rotation, and stays at the last one. Each step
    /// takes the velocity that carries the body from its pose to the keyframed pose at the
    /// step's end (Rapier's position-based kinematic bodies), so contacts see the motion. The
    /// velocities given to the builder are then unused. Checked when inserted: times finite,
    /// > 0 and increasing; translations finite; rotations finite and non-zero.
    pub fn keyframes(mut self, keyframes: impl IntoIterator<Item = Keyframe>) -> Self {
        self.keyframes = keyframes.into_iter().collect();
        self
    }
}

/// A builder's body as the world stores it: checked, with mass properties and the velocities
/// of the centre of mass.
pub(crate) struct BuiltBody {
    pub(crate) keyframes: Vec<Keyframe>,
    pub(crate) pose: Pose,
    pub(crate) local_center_of_mass: Vec3,
    pub(crate) linear_velocity: Vec3,
    pub(crate) angular_velocity: Vec3,
    pub(crate) inverse_mass: f32,
    pub(crate) local_inverse_inertia: Mat3,
    pub(crate) shape: SharedShape,
    pub(crate) locked_axes: LockedAxes,
}

/// A builder's field that cannot be simulated: its path as in the scene format (`position`,
/// `material.friction`, `keyframes[2].t`, …) and what is wrong. The world adds the body's index
/// and name ([`crate::WorldError::InvalidBody`]).
#[derive(Debug)]
pub(crate) struct InvalidField {
    pub(crate) field: String,
    pub(crate) message: String,
}

/// An invalid field of a builder.
fn invalid_built(field: &str, message: String) -> InvalidField {
    InvalidField {
        field: field.to_string(),
        message,
    }
}

/// Turns a builder into state, rejecting every value that would make the simulation
/// meaningless (the library never panics on user input). Fields are named as in the scene
/// format (`position` for the translation, `material.friction`, …).
pub(crate) fn build(b: &BodyBuilder) -> Result<BuiltBody, InvalidField> {
    let check = |field: &str, rule: Result<(), String>| {
        rule.map_err(|message| invalid_built(field, message))
    };
    let bad = |field: &str, message: String| Err(invalid_built(field, message));
    check("position", rules::finite(&b.translation.to_array()))?;
    check("orientation", rules::orientation(b.rotation.to_array()))?;
    check(
        "linear_velocity",
        rules::finite(&b.linear_velocity.to_array()),
    )?;
    check(
        "angular_velocity",
        rules::finite(&b.angular_velocity.to_array()),
    )?;
    check("material.friction", rules::non_negative(b.friction))?;
    check("material.restitution", rules::unit_interval(b.restitution))?;
    check("material.roughness", rules::roughness(b.roughness))?;
    check(
        "material.impact_perturbation",
        rules::impact_perturbation(b.impact_perturbation),
    )?;
    rules::roughness_draws(&b.roughness_draws).map_err(|(at, message)| {
        let field = match at {
            Some((k, j)) => format!("roughness_draws[{k}][{j}]"),
            None => "roughness_draws".to_string(),
        };
        invalid_built(&field, message)
    })?;
    check("linear_damping", rules::non_negative(b.linear_damping))?;
    check("angular_damping", rules::non_negative(b.angular_damping))?;
    let shape = b.shape.clone();
    let type_name = format!("{:?}", shape.shape_type()).to_lowercase();
    check(
        "shape.type",
        rules::shape_for_kind(b.kind, ShapeClass::of(&shape), &type_name),
    )?;
    check("shape", rules::shape_extent(&shape))?;
    if !b.locked_axes.is_empty() {
        check("locked_axes", rules::locked_axes_for_kind(b.kind))?;
    }
    let keyframes = check_keyframes(b)?;
    let rotation = b.rotation.normalize();
    let pose = Pose::from_parts(b.translation, rotation);
    let (inverse_mass, local_center_of_mass, local_inverse_inertia) = match b.kind {
        BodyKind::Static => (0.0, Vec3::ZERO, Mat3::ZERO),
        BodyKind::Kinematic => {
            // No mass; the velocities are those of the shape's centroid, as for a dynamic
            // body of uniform density.
            let centroid = b
                .unit_mass_properties
                .unwrap_or_else(|| rules::mass_properties(shape.as_ref(), 1.0))
                .local_com;
            let centroid = if centroid.is_finite() {
                centroid
            } else {
                Vec3::ZERO
            };
            (0.0, centroid, Mat3::ZERO)
        }
        BodyKind::Dynamic | BodyKind::Particle => {
            check("material.density", rules::positive(b.density))?;
            if let Some(m) = b.mass {
                check("mass", rules::positive(m))?;
            }
            let particle = b.kind == BodyKind::Particle;
            let unit = b
                .unit_mass_properties
                .unwrap_or_else(|| rules::mass_properties(shape.as_ref(), 1.0));
            rules::derived_mass(&unit, b.density, b.mass, particle)
                .map_err(|(field, message)| invalid_built(field, message))?;
            let props = match b.unit_mass_properties {
                Some(mut unit) => {
                    // Inertia scales with the mass at a fixed distribution.
                    unit.set_mass(unit.mass() * b.density, true);
                    unit
                }
                None => rules::mass_properties(shape.as_ref(), b.density),
            };
            let computed_mass = props.mass();
            // Scaling mass and inertia together keeps the shape's mass distribution.
            let scale = b.mass.map_or(1.0, |m| m / computed_mass);
            let inverse_mass = props.inv_mass / scale;
            if !(inverse_mass.is_finite() && inverse_mass > 0.0) {
                return bad(
                    "mass",
                    format!("mass must be finite and > 0, got {}", 1.0 / inverse_mass),
                );
            }
            // A body with locked rotations keeps its inertia: the locks act on the world
            // tensor ([`Bodies::world_inverse_inertia`]), so they may be lifted later.
            let inertia = if b.kind == BodyKind::Particle {
                Mat3::ZERO
            } else {
                props.reconstruct_inverse_inertia_matrix() / scale
            };
            if !inertia.is_finite() || !props.local_com.is_finite() {
                return bad("shape", "mass properties are not finite".into());
            }
            (inverse_mass, props.local_com, inertia)
        }
    };
    // Locks act on dynamic bodies only; a particle never rotates.
    let locked_axes = match b.kind {
        BodyKind::Dynamic => b.locked_axes,
        BodyKind::Particle => b.locked_axes.difference(LockedAxes::ALL_ROTATIONS),
        BodyKind::Static | BodyKind::Kinematic => LockedAxes::NONE,
    };
    let angular_velocity = match b.kind {
        BodyKind::Kinematic => b.angular_velocity,
        BodyKind::Dynamic => locked_axes.lock_angular_velocity(b.angular_velocity),
        BodyKind::Static | BodyKind::Particle => Vec3::ZERO,
    };
    // The builder gives the velocity of the body origin; the solver works at the centre of
    // mass.
    let linear_velocity = if b.kind == BodyKind::Static {
        Vec3::ZERO
    } else {
        locked_axes.lock_linear_velocity(
            b.linear_velocity + angular_velocity.cross(rotation * local_center_of_mass),
        )
    };
    Ok(BuiltBody {
        keyframes,
        pose,
        local_center_of_mass,
        linear_velocity,
        angular_velocity,
        inverse_mass,
        local_inverse_inertia,
        shape,
        locked_axes,
    })
}

/// A builder's keyframes, checked by the rules of [`super::rules`] (kinematic bodies only, with no
/// velocities of their own; times finite, > 0 and increasing; translations finite; rotations
/// finite and non-zero) and with normalised rotations. Fields are named as in the scene format
/// (`keyframes[i].t`, `.position`, `.orientation`).
fn check_keyframes(b: &BodyBuilder) -> Result<Vec<Keyframe>, InvalidField> {
    if b.keyframes.is_empty() {
        return Ok(Vec::new());
    }
    let check = |field: String, rule: Result<(), String>| {
        rule.map_err(|message| invalid_built(&field, message))
    };
    check("keyframes".into(), rules::keyframes_for_kind(b.kind))?;
    for (field, velocity) in [
        ("linear_velocity", b.linear_velocity),
        ("angular_velocity", b.angular_velocity),
    ] {
        check(
            field.into(),
            rules::keyframed_velocity(field, velocity.to_array()),
        )?;
    }
    let mut previous = 0.0f32;
    let mut out = Vec::with_capacity(b.keyframes.len());
    for (k, key) in b.keyframes.iter().enumerate() {
        check(
            format!("keyframes[{k}].t"),
            rules::keyframe_time(k, key.time, previous),
        )?;
        previous = key.time;
        check(
            format!("keyframes[{k}].position"),
            rules::finite(&key.translation.to_array()),
        )?;
        check(
            format!("keyframes[{k}].orientation"),
            rules::orientation(key.rotation.to_array()),
        )?;
        out.push(Keyframe {
            rotation: key.rotation.normalize(),
            ..*key
        });
    }
    Ok(out)
}
