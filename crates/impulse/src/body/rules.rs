//! The rules every body obeys, however it is made: the scene validator checks them on a scene
//! file's fields (and reports file, line, body and field), [`crate::World::insert`] on a
//! [`super::BodyBuilder`] (and reports the body and field). Each rule gives the message for
//! the one field it checks, so both paths say the same thing in the same words.

use parry3d::mass_properties::MassProperties;
use parry3d::shape::{Shape, SharedShape, TypedShape};

use super::BodyKind;

/// Smallest length of an orientation quaternion (or a direction) that can be normalised.
pub(crate) const MIN_NORM: f32 = 1e-6;

/// How far a shape may reach from its body's origin (m). An f32 keeps about seven digits, so a
/// shape of 1,000 km resolves to about 10 cm at its rim; larger shapes only overflow the
/// contact queries (a box 7e37 m long made Parry's EPA index out of bounds).
pub(crate) const MAX_SHAPE_EXTENT: f32 = 1.0e6;

/// Lightest mass (kg) of a moving body: 10⁻⁹ kg, a grain of sand 0.1 mm across. Lighter
/// bodies take velocity changes beyond f32 from the smallest contact impulse (a 10⁻²⁰ m ball
/// has an infinite inverse mass in f32).
pub(crate) const MIN_MASS: f32 = 1.0e-9;

/// Heaviest mass (kg) of a moving body: 10¹² kg, a cubic kilometre of water. The solver's f32
/// impulses (mass × speed change) are squared in the friction cone: at 10¹² kg and
/// 10⁵ m/s they reach 10³⁴ N²s², still within f32 (3·10³⁸); a 10²⁵ kg body overflows at once.
pub(crate) const MAX_MASS: f32 = 1.0e12;

/// A moving body's principal moments of inertia (kg·m²) lie within [10⁻²⁰, 10²⁴]: 10⁻²⁰ is a
/// [`MIN_MASS`] body 10 µm across (a smaller moment gives an infinite inverse in f32), 10²⁴ a
/// [`MAX_MASS`] body [`MAX_SHAPE_EXTENT`] across.
pub(crate) const INERTIA_RANGE: (f32, f32) = (1.0e-20, 1.0e24);

/// The body's mass and inertia, derived from its shape, density (or given `mass`), must lie
/// within [`MIN_MASS`]..[`MAX_MASS`] and [`INERTIA_RANGE`]: the checks the step's f32 arithmetic
/// needs, made where the values come from. Returns the field to blame (`mass` when given,
/// else `material.density` when the density is outside 10⁻³..10⁶ kg/m³, else `shape`) and
/// a message naming the fields that produced the value. `unit`: the shape's mass properties
/// at density 1 (its volume as mass). `particle`: no inertia (a particle never rotates).
pub(crate) fn derived_mass(
    unit: &MassProperties,
    density: f32,
    mass: Option<f32>,
    particle: bool,
) -> Result<(), (&'static str, String)> {
    let volume = unit.mass();
    let derived = volume * density;
    let (value, field, origin) = match mass {
        Some(m) => (m, "mass", format!("mass {m} kg")),
        None => {
            let field = if (1.0e-3..=1.0e6).contains(&density) {
                "shape"
            } else {
                "material.density"
            };
            let origin = format!(
                "the shape's volume {volume:e} m³ × material.density {density} kg/m³ = {derived:e} kg"
            );
            (derived, field, origin)
        }
    };
    if !(value.is_finite() && (MIN_MASS..=MAX_MASS).contains(&value)) {
        return Err((
            field,
            format!(
                "a moving body's mass must be within [{MIN_MASS:e}, {MAX_MASS:e}] kg (the range \
                 the solver's f32 impulses hold), got {origin}"
            ),
        ));
    }
    if particle {
        return Ok(());
    }
    let scale = value / derived;
    let moments = unit.principal_inertia() * density * scale;
    let (low, high) = INERTIA_RANGE;
    let smallest = moments.min_element();
    let largest = moments.max_element();
    if moments.is_finite() && smallest >= low && largest <= high {
        Ok(())
    } else {
        Err((
            if mass.is_some() { "mass" } else { "shape" },
            format!(
                "a moving body's principal moments of inertia must be within [{low:e}, \
                 {high:e}] kg·m², got {smallest:e} to {largest:e} kg·m² from the shape and \
                 {origin}"
            ),
        ))
    }
}

/// Bounding radius (m) above which [`mass_properties`] works at a scaled density.
const LARGE_SHAPE_RADIUS: f32 = 1.0e3;

/// The mass properties of `shape` at `density` (kg/m³), as Parry's `Shape::mass_properties`
/// gives them for a shape up to [`LARGE_SHAPE_RADIUS`] across. Parry finds a convex
/// polyhedron's principal axes from its inertia tensor in f32, whose squared entries overflow
/// once they pass about 10¹⁹ kg·m² (a hull some 10 km across at density 1 kg/m³ read as
/// infinite moments, reported as 0): a larger shape's properties are found at the density
/// ρ' = r⁻⁵ (r its bounding radius), which brings the tensor near 1, and scaled to `density`
/// (inertia scales with the mass at a fixed distribution).
pub(crate) fn mass_properties(shape: &dyn Shape, density: f32) -> MassProperties {
    let radius = shape.compute_local_bounding_sphere().radius();
    if !(radius.is_finite() && radius > LARGE_SHAPE_RADIUS) {
        return shape.mass_properties(density);
    }
    let scaled = radius.recip().powi(5);
    let mut properties = shape.mass_properties(scaled);
    properties.set_mass(properties.mass() * (density / scaled), true);
    properties
}

/// Strongest gravity (m/s²): 10⁴ m/s², about 1,000 g. Beyond it a second of fall reaches the
/// default `max_linear_speed` within seconds; 10³⁰ m/s² overflows the energy at once.
pub(crate) const MAX_GRAVITY: f32 = 1.0e4;

/// The time step (s): finite and within [10⁻⁶, 1] s. A step of a second already lets a body
/// fall 5 m between contact searches; 10¹⁰ s or 10⁻⁴⁵ s overflow or vanish in f32 (NaN energy).
pub(crate) fn time_step(dt: f32) -> Result<(), String> {
    if dt.is_finite() && (1.0e-6..=1.0).contains(&dt) {
        Ok(())
    } else {
        Err(format!("must be finite and within [1e-6, 1] s, got {dt}"))
    }
}

/// Gravity finite and no stronger than [`MAX_GRAVITY`].
pub(crate) fn gravity(g: [f32; 3]) -> Result<(), String> {
    finite(&g)?;
    let strength = glam::Vec3::from(g).length();
    if strength <= MAX_GRAVITY {
        Ok(())
    } else {
        Err(format!(
            "must be at most {MAX_GRAVITY:e} m/s² in magnitude, got {strength:e} m/s²"
        ))
    }
}

/// A moving body's start within the world's bounds ([`crate::SolverSettings`]): its position
/// within `max_distance` of the origin (m), its linear speed within `max_linear_speed` (m/s)
/// and its angular speed within `max_angular_speed` (rad/s); beyond them the first step would
/// take it out of the world or call it a blow-up. Returns the field and the message.
pub(crate) fn start_within_bounds(
    position: [f32; 3],
    linear_velocity: [f32; 3],
    angular_velocity: [f32; 3],
    settings: &crate::SolverSettings,
) -> Result<(), (&'static str, String)> {
    let length = |v: [f32; 3]| glam::Vec3::from(v).length();
    let checks = [
        (
            "position",
            length(position),
            "m from the origin",
            "max_distance",
            settings.limits.max_distance,
        ),
        (
            "linear_velocity",
            length(linear_velocity),
            "m/s",
            "max_linear_speed",
            settings.limits.max_linear_speed,
        ),
        (
            "angular_velocity",
            length(angular_velocity),
            "rad/s",
            "max_angular_speed",
            settings.limits.max_angular_speed,
        ),
    ];
    for (field, value, unit, setting, bound) in checks {
        if value > bound {
            return Err((
                field,
                format!(
                    "a moving body must start within solver.{setting} = {bound} {unit}, got {value} {unit}"
                ),
            ));
        }
    }
    Ok(())
}

/// A shape's reach from its body's origin: its local bounding box finite and within
/// [`MAX_SHAPE_EXTENT`] on every axis (a half-space, unbounded, is exempt), and a rounded
/// shape's border radius finite and ≥ 0 (Parry asserts it when it grows the box).
pub(crate) fn shape_extent(shape: &SharedShape) -> Result<(), String> {
    if shape.as_halfspace().is_some() {
        return Ok(());
    }
    let border_radius = rounded_parts(shape.as_ref()).map(|(_, radius)| radius);
    if let Some(radius) = border_radius.filter(|r| !(r.is_finite() && *r >= 0.0)) {
        return Err(format!(
            "border radius must be finite and ≥ 0, got {radius}"
        ));
    }
    let aabb = shape.compute_local_aabb();
    let reach = aabb.mins.abs().max(aabb.maxs.abs()).max_element();
    if reach.is_finite() && reach <= MAX_SHAPE_EXTENT {
        Ok(())
    } else {
        Err(format!(
            "the shape reaches {reach} m from the body's origin; at most {MAX_SHAPE_EXTENT} m"
        ))
    }
}

/// A rounded shape (Parry's `RoundShape`: every point within the border radius of its inner
/// shape) as its inner shape and border radius (m); `None` for any other shape.
pub(crate) fn rounded_parts(shape: &dyn Shape) -> Option<(&dyn Shape, f32)> {
    match shape.as_typed_shape() {
        TypedShape::RoundCuboid(s) => Some((&s.inner_shape, s.border_radius)),
        TypedShape::RoundTriangle(s) => Some((&s.inner_shape, s.border_radius)),
        TypedShape::RoundCylinder(s) => Some((&s.inner_shape, s.border_radius)),
        TypedShape::RoundCone(s) => Some((&s.inner_shape, s.border_radius)),
        TypedShape::RoundConvexPolyhedron(s) => Some((&s.inner_shape, s.border_radius)),
        _ => None,
    }
}

/// The scene format's name of a body kind.
pub(crate) fn kind_name(kind: BodyKind) -> &'static str {
    match kind {
        BodyKind::Dynamic => "dynamic",
        BodyKind::Static => "static",
        BodyKind::Particle => "particle",
        BodyKind::Kinematic => "kinematic",
    }
}

/// Every component finite.
pub(crate) fn finite(values: &[f32]) -> Result<(), String> {
    match values {
        [v] if !v.is_finite() => Err(format!("must be finite, got {v}")),
        _ if values.iter().any(|v| !v.is_finite()) => {
            Err(format!("must be finite, got {values:?}"))
        }
        _ => Ok(()),
    }
}

/// Finite and > 0 (sizes, density, mass).
pub(crate) fn positive(v: f32) -> Result<(), String> {
    finite(&[v])?;
    if v > 0.0 {
        Ok(())
    } else {
        Err(format!("must be > 0, got {v}"))
    }
}

/// Finite and ≥ 0 (friction, damping, capsule half heights).
pub(crate) fn non_negative(v: f32) -> Result<(), String> {
    finite(&[v])?;
    if v >= 0.0 {
        Ok(())
    } else {
        Err(format!("must be ≥ 0, got {v}"))
    }
}

/// The largest surface roughness (degrees, `Material::roughness`, [`BodyBuilder::roughness`]):
/// a tilt beyond it is no longer a small perturbation of the contact.
///
/// [`BodyBuilder::roughness`]: crate::BodyBuilder::roughness
pub const MAX_ROUGHNESS_DEGREES: f32 = 30.0;

/// A surface roughness (degrees): finite and in [0, [`MAX_ROUGHNESS_DEGREES`]].
pub(crate) fn roughness(v: f32) -> Result<(), String> {
    finite(&[v])?;
    let max = MAX_ROUGHNESS_DEGREES;
    if (0.0..=max).contains(&v) {
        Ok(())
    } else {
        Err(format!("must be in [0, {max}] degrees, got {v}"))
    }
}

/// The most explicit roughness draws a body may have ([`BodyBuilder::roughness_draws`],
/// `BodyDesc::roughness_draws`): 256 pairs, more new contacts than one body meets in a take
/// that is refined draw by draw; its later contacts draw from the seed.
///
/// [`BodyBuilder::roughness_draws`]: crate::BodyBuilder::roughness_draws
pub const MAX_ROUGHNESS_DRAWS: usize = 256;

/// A body's explicit roughness draws: at most [`MAX_ROUGHNESS_DRAWS`] pairs, every coordinate
/// finite. The error gives the pair and coordinate at fault (`None` for too many pairs).
pub(crate) fn roughness_draws(draws: &[[f32; 2]]) -> Result<(), (Option<(usize, usize)>, String)> {
    if draws.len() > MAX_ROUGHNESS_DRAWS {
        return Err((
            None,
            format!(
                "at most {MAX_ROUGHNESS_DRAWS} pairs [a, b], got {}",
                draws.len()
            ),
        ));
    }
    for (k, pair) in draws.iter().enumerate() {
        for (j, &v) in pair.iter().enumerate() {
            finite(&[v]).map_err(|message| (Some((k, j)), message))?;
        }
    }
    Ok(())
}

/// The largest impact perturbation (dimensionless, `Material::impact_perturbation`,
/// [`BodyBuilder::impact_perturbation`]): the whole range of a restitution coefficient.
///
/// [`BodyBuilder::impact_perturbation`]: crate::BodyBuilder::impact_perturbation
pub const MAX_IMPACT_PERTURBATION: f32 = 1.0;

/// An impact perturbation: finite and in [0, [`MAX_IMPACT_PERTURBATION`]].
pub(crate) fn impact_perturbation(v: f32) -> Result<(), String> {
    finite(&[v])?;
    let max = MAX_IMPACT_PERTURBATION;
    if (0.0..=max).contains(&v) {
        Ok(())
    } else {
        Err(format!("must be in [0, {max}], got {v}"))
    }
}

/// Finite and in [0, 1] (restitution).
pub(crate) fn unit_interval(v: f32) -> Result<(), String> {
    finite(&[v])?;
    if (0.0..=1.0).contains(&v) {
        Ok(())
    } else {
        Err(format!("must be in [0, 1], got {v}"))
    }
}

/// A body's or keyframe's orientation `[x, y, z, w]`: finite and not zero (it is normalised).
pub(crate) fn orientation(q: [f32; 4]) -> Result<(), String> {
    finite(&q)?;
    let norm = q
        .iter()
        .map(|&c| f64::from(c) * f64::from(c))
        .sum::<f64>()
        .sqrt();
    if norm < f64::from(MIN_NORM) {
        Err(format!(
            "quaternion must not be zero (it is normalised), got {q:?}"
        ))
    } else {
        Ok(())
    }
}

/// What a shape allows of the body that carries it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum ShapeClass {
    /// A sphere: any kind of body, the only shape of a particle.
    Sphere,
    /// A solid of finite volume other than a sphere.
    Solid,
    /// No volume to give a moving body mass (`what` names it): static bodies only.
    StaticOnly(&'static str),
}

impl ShapeClass {
    /// The class of a built shape.
    pub(crate) fn of(shape: &SharedShape) -> Self {
        match shape.as_typed_shape() {
            TypedShape::Ball(_) => Self::Sphere,
            TypedShape::HalfSpace(_) => Self::StaticOnly("a half_space"),
            TypedShape::TriMesh(_) => Self::StaticOnly("a trimesh"),
            TypedShape::HeightField(_) => Self::StaticOnly("a heightfield"),
            _ => Self::Solid,
        }
    }
}

/// Whether a body of `kind` may carry a shape of `class` (named `type_name` in messages).
pub(crate) fn shape_for_kind(
    kind: BodyKind,
    class: ShapeClass,
    type_name: &str,
) -> Result<(), String> {
    match class {
        ShapeClass::StaticOnly(what) if kind != BodyKind::Static => Err(format!(
            "{what} shape is only allowed on a static body, this body is {}",
            kind_name(kind)
        )),
        ShapeClass::Solid | ShapeClass::StaticOnly(_) if kind == BodyKind::Particle => Err(
            format!("a particle must have a sphere shape, got {type_name}"),
        ),
        _ => Ok(()),
    }
}

/// Whether a body of `kind` may have locked axes: contacts never move the others.
pub(crate) fn locked_axes_for_kind(kind: BodyKind) -> Result<(), String> {
    if kind.is_dynamic() {
        Ok(())
    } else {
        Err(format!(
            "only a dynamic body or a particle may have locked axes (contacts never move the \
             others), this body is {}",
            kind_name(kind)
        ))
    }
}

/// Whether a body of `kind` may have keyframes.
pub(crate) fn keyframes_for_kind(kind: BodyKind) -> Result<(), String> {
    if kind == BodyKind::Kinematic {
        Ok(())
    } else {
        Err(format!(
            "only a kinematic body may have keyframes, this body is {}",
            kind_name(kind)
        ))
    }
}

/// A body with keyframes takes its velocities from them: its own `field` velocity must be zero.
pub(crate) fn keyframed_velocity(field: &str, velocity: [f32; 3]) -> Result<(), String> {
    if velocity == [0.0; 3] {
        Ok(())
    } else {
        Err(format!(
            "a body with keyframes takes its velocity from them: leave {field} out, got \
             {velocity:?}"
        ))
    }
}

/// Keyframe `index`'s time `t` (s), after `previous` (the last keyframe's time, 0 for the
/// first: the body's own pose is its pose at t = 0).
pub(crate) fn keyframe_time(index: usize, t: f32, previous: f32) -> Result<(), String> {
    finite(&[t])?;
    if t > previous {
        Ok(())
    } else if index == 0 {
        Err(format!(
            "must be > 0 (the body's position and orientation are its pose at t = 0), got {t}"
        ))
    } else {
        Err(format!(
            "must be after the previous keyframe's t = {previous}, got {t}"
        ))
    }
}
