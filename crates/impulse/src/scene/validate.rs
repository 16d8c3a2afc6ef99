//! Semantic checks of a [`Scene`]: everything that would make a simulation meaningless or
//! crash, rejected before any world is built. The rules of a body's own values (numbers, kind
//! and shape, locks, keyframes) are `body::rules`, the same functions `World::insert` checks a
//! builder with; this module adds what only a file has (materials by name, shape fields,
//! mesh data) and reports every problem with its path.
//!
//! The rules (also listed in `docs/scene-format.md`):
//!
//! - every number is finite (gravity, dt, solver settings, materials, positions, orientations,
//!   velocities, shape sizes, hull points, mass);
//! - `dt > 0`; the solver settings as [`crate::SolverSettings::problems`] checks them (the
//!   same check the library's `World` makes);
//! - materials: `friction ≥ 0`, `restitution` in [0, 1], `density > 0`, `roughness` in [0, 30]
//!   degrees, `impact_perturbation` in [0, 1];
//! - a body's `mass`, when given, is > 0; its `linear_damping` and `angular_damping` are ≥ 0;
//! - shapes: sphere, capsule, cylinder and cone `radius > 0`, capsule `half_height ≥ 0`,
//!   cylinder and cone `half_height > 0`, every cuboid half extent ≥ 0 with at most one 0 (a
//!   flat box), a convex hull has ≥ 4 points that span a volume or ≥ 3 coplanar ones (not all
//!   coincident or collinear), a `thickness` is > 0 and only on a flat cuboid or convex hull
//!   (flat shapes are thin shapes, `super::thin`), a half-space normal is not zero and belongs
//!   to a static body;
//! - a trimesh belongs to a static, dynamic or kinematic body (a moving body's is decomposed
//!   into convex parts; only it may have `decomposition`, with `resolution` in [8, 512],
//!   `concavity` in [0, 1] and `max_parts` ≥ 1) and has `file`, or `vertices` and `indices`,
//!   with at least one triangle, finite vertices, indices below the vertex count and no triangle
//!   without area; a heightfield belongs to a static body and has at least 2 × 2 finite
//!   heights in rows of one length and a scale > 0; a compound has at least one part, each a
//!   convex shape with a finite position and a non-zero orientation; a `border_radius` is
//!   > 0 and only on a cuboid, cylinder, cone or convex hull;
//! - a particle's shape is a sphere;
//! - `locked_axes` belong to a dynamic body or a particle;
//! - `roughness_draws` are at most 256 pairs `[a, b]` of finite numbers;
//! - `keyframes` belong to a kinematic body, are at least one, with times finite, > 0 and
//!   increasing, finite positions and non-zero orientations;
//! - the orientation quaternion is not zero (norm ≥ [`MIN_NORM`]); a nonzero non-unit
//!   quaternion is accepted and normalised when the world is built; the same holds for a
//!   half-space normal;
//! - a material name refers to an entry of `materials` or is `"default"` (always defined: when
//!   `materials` has no `"default"` entry it is [`Material::default()`]).

use std::collections::BTreeMap;

use std::sync::Arc;

use parry3d::shape::SharedShape;

use super::decomposition::{DecomposedMesh, DecompositionDesc};
pub(crate) use super::degeneracy::mesh_problem;
use super::degeneracy::{MeshProblem, hull_degeneracy};
use super::error::{BodyLocation, FieldPath, SceneError, SceneErrorKind};
use super::mesh_data::MeshData;
use super::shape::{decomposed_shape, shape_of};
use super::thin;
use super::{BodyDesc, BodyKind, KeyframeDesc, Material, MaterialRef, Scene, ShapeDesc};
use crate::body::BodyBuilder;
use crate::body::rules::{self, ShapeClass};

/// Smallest norm of an orientation quaternion or a half-space normal that is accepted;
/// below it the vector counts as zero (its direction is not defined in f32).
pub(crate) const MIN_NORM: f32 = rules::MIN_NORM;

/// Checks `scene` and returns the first problem, in this order: world settings (gravity,
/// dt, solver), the materials, then the bodies in scene order.
///
/// # Errors
/// A [`SceneError`] of kind [`SceneErrorKind::Invalid`] with `field` set to the path of the
/// offending value (e.g. `bodies[3].shape.radius`) and `body` set for body errors. It has no
/// origin or text position; [`parse_scene_str`](crate::scene::parse_scene_str) adds them.
pub fn validate(scene: &Scene) -> Result<(), SceneError> {
    match validate_all(scene).into_iter().next() {
        Some(error) => Err(error),
        None => Ok(()),
    }
}

/// Every problem of `scene`, in the order described at [`validate`]; empty if it is valid.
pub fn validate_all(scene: &Scene) -> Vec<SceneError> {
    let mut c = Checker {
        errors: Vec::new(),
        body: None,
    };
    let root = FieldPath::root();

    if c.finite_array(&root.key("gravity"), &scene.gravity) {
        c.rule(&root.key("gravity"), rules::gravity(scene.gravity));
    }
    c.rule(&root.key("dt"), rules::time_step(scene.dt));

    let solver = root.key("solver");
    for problem in scene.solver.problems() {
        let path = problem
            .field
            .split('.')
            .fold(solver.clone(), |path, key| path.key(key));
        c.fail(&path, problem.message);
    }

    for (name, material) in &scene.materials {
        c.material(&root.key("materials").key(name), material);
    }

    for (index, body) in scene.bodies.iter().enumerate() {
        c.body = Some(BodyLocation {
            index,
            name: body.name.clone(),
        });
        c.body(&FieldPath::body(index), body, &scene.materials);
        c.derived(index, body, scene);
    }
    let kinds: Vec<BodyKind> = scene.bodies.iter().map(|b| b.kind).collect();
    let names: Vec<Option<String>> = scene.bodies.iter().map(|b| b.name.clone()).collect();
    let positions: Vec<[f32; 3]> = scene.bodies.iter().map(|b| b.position).collect();
    c.errors.extend(super::joint_desc::joint_errors(
        &scene.joints,
        &kinds,
        &names,
        &positions,
    ));
    c.errors
}

/// The Parry shape of `shape` for a body of `kind`, after the checks of [`validate`] for
/// that shape. A triangle mesh whose file was not read with its scene
/// ([`super::load_scene_file`]) is read here, relative to the current directory. The same
/// shapes `World::from_scene` builds (the Rapier comparison uses it too).
///
/// # Errors
/// A [`SceneError`] of kind [`SceneErrorKind::Invalid`] whose field is the path from the
/// body (`shape.parts[1].shape.radius`): an invalid value, an unreadable or degenerate mesh
/// file, a hull Parry cannot build.
///
/// A trimesh on a dynamic or kinematic body is its convex decomposition's compound
/// ([`build_decomposed`]); give the body [`DecomposedMesh::unit_mass_properties`] for the
/// mass properties of the mesh's solid, or use [`body_builder`], which does.
pub fn build_shape(kind: BodyKind, shape: &ShapeDesc) -> Result<SharedShape, SceneError> {
    if is_decomposed(kind, shape) {
        return build_decomposed(kind, shape).map(|d| d.shape.clone());
    }
    if let Some(problem) = shape_problem(kind, shape) {
        return Err(shape_error(problem));
    }
    shape_of(shape).map_err(shape_error)
}

/// The convex decomposition of a trimesh `shape` on a body of `kind` (dynamic or
/// kinematic), after the checks of [`validate`] for that shape; cached by content
/// ([`super::decompose_mesh`]).
///
/// # Errors
/// As [`build_shape`]; also a shape that is not a trimesh, a static body (whose trimesh is
/// not decomposed), and a mesh that bounds no volume.
pub fn build_decomposed(
    kind: BodyKind,
    shape: &ShapeDesc,
) -> Result<Arc<DecomposedMesh>, SceneError> {
    if !is_decomposed(kind, shape) {
        return Err(shape_error((
            "shape.type".to_string(),
            format!(
                "only a trimesh on a dynamic or kinematic body is decomposed, got a {} on a {} \
                 body",
                shape.type_name(),
                rules::kind_name(kind)
            ),
        )));
    }
    if let Some(problem) = shape_problem(kind, shape) {
        return Err(shape_error(problem));
    }
    decomposed_shape(shape).map_err(shape_error)
}

/// A builder of a body of `kind` and `shape` ([`crate::BodyBuilder::new`]), its shape built by
/// [`build_shape`], with the mass properties of a decomposed mesh's solid.
///
/// # Errors
/// As [`build_shape`].
pub fn body_builder(kind: BodyKind, shape: &ShapeDesc) -> Result<BodyBuilder, SceneError> {
    if is_decomposed(kind, shape) {
        let decomposed = build_decomposed(kind, shape)?;
        return Ok(BodyBuilder::new(kind, decomposed.shape.clone())
            .unit_mass_properties(decomposed.unit_mass_properties));
    }
    build_shape(kind, shape).map(|shape| BodyBuilder::new(kind, shape))
}

/// What a valid scene's author should know before running it, one line each naming the body
/// (`bodies[3] ("mug").shape: the mesh is not closed ...`): every dynamic or kinematic body
/// whose trimesh's mass properties are not simply its solid's ([`DecomposedMesh::note`]: an
/// open mesh, overlapping shells), after the decomposition cache's warnings
/// ([`super::decomposition::take_decomposition_warnings`]). A mesh file not read yet is
/// skipped.
pub fn decomposition_notes(scene: &Scene) -> Vec<String> {
    let mut notes = super::decomposition::take_decomposition_warnings();
    for (index, body) in scene.bodies.iter().enumerate() {
        if !is_decomposed(body.kind, &body.shape) || body.shape.mesh_data().is_none() {
            continue;
        }
        let Ok(decomposed) = build_decomposed(body.kind, &body.shape) else {
            continue;
        };
        if let Some(note) = decomposed.note() {
            let name = body
                .name
                .as_ref()
                .map(|name| format!(" ({name:?})"))
                .unwrap_or_default();
            notes.push(format!("bodies[{index}]{name}.shape: {note}"));
        }
    }
    notes
}

/// Whether a body of `kind` carries `shape` as a convex decomposition: a trimesh on a
/// dynamic or kinematic body.
fn is_decomposed(kind: BodyKind, shape: &ShapeDesc) -> bool {
    matches!(shape, ShapeDesc::Trimesh { .. })
        && matches!(kind, BodyKind::Dynamic | BodyKind::Kinematic)
}

fn shape_error((field, message): (String, String)) -> SceneError {
    SceneError::new(SceneErrorKind::Invalid, FieldPath::parse(&field), message)
}

/// The first problem of `shape` on a body of `kind`, as (field path from the body, message),
/// e.g. `("shape.border_radius", "must be > 0, got -1")`; `None` if it is valid. Used when a
/// world is built from a scene that was not validated.
pub(crate) fn shape_problem(kind: BodyKind, shape: &ShapeDesc) -> Option<(String, String)> {
    let mut c = Checker {
        errors: Vec::new(),
        body: None,
    };
    c.shape(&FieldPath::root().key("shape"), kind, shape);
    c.errors.into_iter().next().map(|e| {
        let field = e.field.map(|f| f.to_string()).unwrap_or_default();
        (field, e.message)
    })
}

/// Collects errors; `body` is attached to each error raised while it is set.
struct Checker {
    errors: Vec<SceneError>,
    body: Option<BodyLocation>,
}

impl Checker {
    fn fail(&mut self, path: &FieldPath, message: String) {
        let mut error = SceneError::new(SceneErrorKind::Invalid, Some(path.clone()), message);
        error.body = self.body.clone();
        self.errors.push(error);
    }

    /// Records `rule`'s message at `path` if it failed; returns whether it held.
    fn rule(&mut self, path: &FieldPath, rule: Result<(), String>) -> bool {
        match rule {
            Ok(()) => true,
            Err(message) => {
                self.fail(path, message);
                false
            }
        }
    }

    fn finite(&mut self, path: &FieldPath, v: f32) -> bool {
        self.rule(path, rules::finite(&[v]))
    }

    fn finite_array(&mut self, path: &FieldPath, values: &[f32]) -> bool {
        let mut ok = true;
        for (i, &v) in values.iter().enumerate() {
            ok &= self.finite(&path.index(i), v);
        }
        ok
    }

    fn positive(&mut self, path: &FieldPath, v: f32) {
        self.rule(path, rules::positive(v));
    }

    fn non_negative(&mut self, path: &FieldPath, v: f32) {
        self.rule(path, rules::non_negative(v));
    }

    fn unit_interval(&mut self, path: &FieldPath, v: f32) {
        self.rule(path, rules::unit_interval(v));
    }

    /// An orientation quaternion at `path`: finite component by component, then not zero.
    fn orientation(&mut self, path: &FieldPath, q: [f32; 4]) {
        if self.finite_array(path, &q) {
            self.rule(path, rules::orientation(q));
        }
    }

    fn material(&mut self, path: &FieldPath, m: &Material) {
        self.non_negative(&path.key("friction"), m.friction);
        self.unit_interval(&path.key("restitution"), m.restitution);
        self.positive(&path.key("density"), m.density);
        self.rule(&path.key("roughness"), rules::roughness(m.roughness));
        self.rule(
            &path.key("impact_perturbation"),
            rules::impact_perturbation(m.impact_perturbation),
        );
    }

    fn body(&mut self, path: &FieldPath, b: &BodyDesc, materials: &BTreeMap<String, Material>) {
        self.finite_array(&path.key("position"), &b.position);
        self.orientation(&path.key("orientation"), b.orientation);
        self.finite_array(&path.key("linear_velocity"), &b.linear_velocity);
        self.finite_array(&path.key("angular_velocity"), &b.angular_velocity);
        if let Some(mass) = b.mass {
            self.positive(&path.key("mass"), mass);
        }
        self.non_negative(&path.key("linear_damping"), b.linear_damping);
        self.non_negative(&path.key("angular_damping"), b.angular_damping);
        match &b.material {
            MaterialRef::Named(name) => {
                if name != "default" && !materials.contains_key(name) {
                    let mut defined: Vec<&str> = materials.keys().map(String::as_str).collect();
                    if !materials.contains_key("default") {
                        defined.insert(0, "default");
                    }
                    self.fail(
                        &path.key("material"),
                        format!(
                            "material {name:?} is not defined (defined: {})",
                            defined.join(", ")
                        ),
                    );
                }
            }
            MaterialRef::Inline(m) => self.material(&path.key("material"), m),
        }
        self.shape(&path.key("shape"), b.kind, &b.shape);
        if !b.locked_axes.is_empty() {
            self.rule(
                &path.key("locked_axes"),
                rules::locked_axes_for_kind(b.kind),
            );
        }
        if let Some(keyframes) = &b.keyframes {
            self.keyframes(path, b, keyframes);
        }
        if let Err((at, message)) = rules::roughness_draws(&b.roughness_draws) {
            let mut at_path = path.key("roughness_draws");
            if let Some((k, j)) = at {
                at_path = at_path.index(k).index(j);
            }
            self.fail(&at_path, message);
        }
    }

    /// What a valid moving body derives from its fields: its mass and inertia
    /// ([`rules::derived_mass`]) and its start within the world's bounds
    /// ([`rules::start_within_bounds`]). Only once its own fields passed.
    fn derived(&mut self, index: usize, b: &BodyDesc, scene: &Scene) {
        let path = &FieldPath::body(index);
        let own_errors = self
            .errors
            .iter()
            .any(|e| e.body.as_ref().is_some_and(|l| l.index == index));
        if own_errors {
            return;
        }
        if !b.kind.is_moving() {
            // A static body's box is clamped to the broad phase's bound of 10⁶ m.
            let distance = norm(&b.position);
            if distance > f64::from(rules::MAX_SHAPE_EXTENT) {
                self.fail(
                    &path.key("position"),
                    format!(
                        "a static body must lie within {} m of the origin, got {distance} m",
                        rules::MAX_SHAPE_EXTENT
                    ),
                );
            }
            return;
        }
        let (density, density_path) = match &b.material {
            MaterialRef::Inline(m) => (m.density, path.key("material").key("density")),
            MaterialRef::Named(name) => match scene.materials.get(name) {
                Some(m) => (
                    m.density,
                    FieldPath::root().key("materials").key(name).key("density"),
                ),
                None => (Material::default().density, path.key("material")),
            },
        };
        if b.kind.is_dynamic()
            && let Ok(shape) = shape_of(&b.shape)
            && let Err((field, message)) = rules::derived_mass(
                &crate::body::rules::mass_properties(shape.as_ref(), 1.0),
                density,
                b.mass,
                b.kind == BodyKind::Particle,
            )
        {
            let at = if field == "material.density" {
                density_path
            } else {
                path.key(field)
            };
            self.fail(&at, message);
        }
        if let Err((field, message)) = rules::start_within_bounds(
            b.position,
            b.linear_velocity,
            b.angular_velocity,
            &scene.solver,
        ) {
            self.fail(&path.key(field), message);
        }
    }

    /// Keyframes of body `b` at `body` (its path).
    fn keyframes(&mut self, body: &FieldPath, b: &BodyDesc, keyframes: &[KeyframeDesc]) {
        let kind = b.kind;
        let path = &body.key("keyframes");
        if !self.rule(path, rules::keyframes_for_kind(kind)) {
            return;
        }
        if keyframes.is_empty() {
            self.fail(
                path,
                "needs at least one keyframe {\"t\": s, \"position\": [x, y, z]}".to_string(),
            );
        }
        for (field, velocity) in [
            ("linear_velocity", b.linear_velocity),
            ("angular_velocity", b.angular_velocity),
        ] {
            self.rule(&body.key(field), rules::keyframed_velocity(field, velocity));
        }
        let mut previous = 0.0f32;
        for (i, key) in keyframes.iter().enumerate() {
            let key_path = path.index(i);
            let t_path = key_path.key("t");
            if self.finite(&t_path, key.t) {
                self.rule(&t_path, rules::keyframe_time(i, key.t, previous));
                previous = key.t;
            }
            self.finite_array(&key_path.key("position"), &key.position);
            self.orientation(&key_path.key("orientation"), key.orientation);
        }
    }

    fn shape(&mut self, path: &FieldPath, kind: BodyKind, shape: &ShapeDesc) {
        let class = match shape {
            ShapeDesc::Sphere { .. } => ShapeClass::Sphere,
            ShapeDesc::HalfSpace { .. } => ShapeClass::StaticOnly("a half_space"),
            ShapeDesc::HeightField { .. } => ShapeClass::StaticOnly("a heightfield"),
            _ => ShapeClass::Solid,
        };
        let before = self.errors.len();
        self.rule(
            &path.key("type"),
            rules::shape_for_kind(kind, class, shape.type_name()),
        );
        self.shape_fields(path, shape);
        if let ShapeDesc::Trimesh {
            decomposition: Some(parameters),
            ..
        } = shape
        {
            self.decomposition(&path.key("decomposition"), kind, parameters);
        }
        if self.errors.len() == before
            && is_decomposed(kind, shape)
            && let Some(mesh) = shape.mesh_data()
            && let Some(problem) = super::recent::hull_check(&mesh.vertices, hull_degeneracy)
        {
            let field = match shape {
                ShapeDesc::Trimesh { file: Some(_), .. } => "file",
                _ => "vertices",
            };
            self.fail(
                &path.key(field),
                format!(
                    "a moving body's trimesh is decomposed into convex parts and must enclose \
                     a volume: {problem}"
                ),
            );
        }
        // Its fields valid, the shape built must lie within reach of the body's origin
        // (`rules::MAX_SHAPE_EXTENT`): each size may be, and their sum (a compound's offsets
        // plus its parts, a border around a shape) not.
        if self.errors.len() == before
            && let Ok(built) = shape_of(shape)
        {
            self.rule(path, rules::shape_extent(&built));
        }
    }

    /// Checks a trimesh's decomposition parameters at `path`: a moving body's, in range.
    fn decomposition(&mut self, path: &FieldPath, kind: BodyKind, parameters: &DecompositionDesc) {
        if kind == BodyKind::Static {
            self.fail(
                path,
                "only a dynamic or kinematic body's trimesh is decomposed; a static body's is \
                 used as it is (remove `decomposition`)"
                    .to_string(),
            );
            return;
        }
        for (field, message) in parameters.problems() {
            self.fail(&path.key(field), message);
        }
    }

    /// Checks the fields of `shape` at `path` (its own, not whether it suits the body).
    fn shape_fields(&mut self, path: &FieldPath, shape: &ShapeDesc) {
        match shape {
            ShapeDesc::Sphere { radius } => self.positive(&path.key("radius"), *radius),
            ShapeDesc::Cuboid { half_extents } => self.cuboid(path, half_extents),
            ShapeDesc::Capsule {
                half_height,
                radius,
            } => {
                self.non_negative(&path.key("half_height"), *half_height);
                self.positive(&path.key("radius"), *radius);
            }
            ShapeDesc::Cylinder {
                half_height,
                radius,
            }
            | ShapeDesc::Cone {
                half_height,
                radius,
            } => {
                self.positive(&path.key("half_height"), *half_height);
                self.positive(&path.key("radius"), *radius);
            }
            ShapeDesc::ConvexHull { points } => {
                let points_path = path.key("points");
                let mut finite = true;
                for (i, p) in points.iter().enumerate() {
                    finite &= self.finite_array(&points_path.index(i), p);
                }
                if points.len() < 3 {
                    self.fail(
                        &points_path,
                        format!(
                            "a convex hull needs at least 4 points (3 for a flat one), got {}",
                            points.len()
                        ),
                    );
                } else if finite
                    && !thin::is_flat(shape)
                    && let Some(problem) = hull_degeneracy(points)
                {
                    self.fail(&points_path, problem.to_string());
                }
            }
            ShapeDesc::HalfSpace { normal } => {
                let normal_path = path.key("normal");
                if self.finite_array(&normal_path, normal) && norm(normal) < f64::from(MIN_NORM) {
                    self.fail(
                        &normal_path,
                        format!("must not be zero (it is normalised), got {normal:?}"),
                    );
                }
            }
            ShapeDesc::Trimesh {
                file,
                vertices,
                indices,
                ..
            } => match (file, vertices, indices) {
                (Some(_), None, None) => {
                    if let Some(mesh) = shape.mesh_data() {
                        self.mesh(&path.key("file"), &path.key("file"), &mesh);
                    }
                }
                (None, Some(_), Some(_)) => {
                    if let Some(mesh) = shape.mesh_data() {
                        self.mesh(&path.key("vertices"), &path.key("indices"), &mesh);
                    }
                }
                (Some(_), _, _) => self.fail(
                    &path.key("file"),
                    "give either `file` or `vertices` and `indices`, not both".to_string(),
                ),
                (None, None, _) => self.fail(
                    &path.key("vertices"),
                    "a trimesh needs `file`, or `vertices` and `indices`".to_string(),
                ),
                (None, Some(_), None) => self.fail(
                    &path.key("indices"),
                    "a trimesh with `vertices` needs `indices` (triangles as three vertex \
                         indices each)"
                        .to_string(),
                ),
            },
            ShapeDesc::HeightField { heights, scale } => {
                let heights_path = path.key("heights");
                let columns = heights.first().map_or(0, Vec::len);
                if heights.len() < 2 || columns < 2 {
                    self.fail(
                        &heights_path,
                        format!(
                            "a height field needs at least 2 rows of at least 2 heights, got {} \
                             rows of {columns}",
                            heights.len()
                        ),
                    );
                }
                for (i, row) in heights.iter().enumerate() {
                    if row.len() != columns {
                        self.fail(
                            &heights_path.index(i),
                            format!(
                                "every row needs the same number of heights as the first \
                                 ({columns}), got {}",
                                row.len()
                            ),
                        );
                    }
                    self.finite_array(&heights_path.index(i), row);
                }
                for (i, &v) in scale.iter().enumerate() {
                    self.positive(&path.key("scale").index(i), v);
                }
            }
            ShapeDesc::Compound { parts } => {
                let parts_path = path.key("parts");
                if parts.is_empty() {
                    self.fail(
                        &parts_path,
                        "a compound needs at least one part".to_string(),
                    );
                }
                for (i, part) in parts.iter().enumerate() {
                    let part_path = parts_path.index(i);
                    self.finite_array(&part_path.key("position"), &part.position);
                    self.orientation(&part_path.key("orientation"), part.orientation);
                    let shape_path = part_path.key("shape");
                    let inner = match &part.shape {
                        ShapeDesc::Round { shape, .. } => shape.as_ref(),
                        other => other,
                    };
                    if matches!(
                        inner,
                        ShapeDesc::HalfSpace { .. }
                            | ShapeDesc::Trimesh { .. }
                            | ShapeDesc::HeightField { .. }
                            | ShapeDesc::Compound { .. }
                    ) {
                        self.fail(
                            &shape_path.key("type"),
                            format!(
                                "a compound part must be a sphere, cuboid, capsule, cylinder, \
                                 cone or convex_hull, got {}",
                                inner.type_name()
                            ),
                        );
                    } else {
                        self.shape_fields(&shape_path, &part.shape);
                    }
                }
            }
            ShapeDesc::Thickened { shape, thickness } => self.thickened(path, shape, *thickness),
            ShapeDesc::Round {
                shape,
                border_radius,
            } => {
                self.positive(&path.key("border_radius"), *border_radius);
                if matches!(
                    shape.as_ref(),
                    ShapeDesc::Cuboid { .. }
                        | ShapeDesc::Cylinder { .. }
                        | ShapeDesc::Cone { .. }
                        | ShapeDesc::ConvexHull { .. }
                        | ShapeDesc::Thickened { .. }
                ) {
                    self.shape_fields(path, shape);
                } else {
                    self.fail(
                        &path.key("border_radius"),
                        format!(
                            "border_radius is allowed on a cuboid, cylinder, cone or \
                             convex_hull, not on a {}",
                            shape.type_name()
                        ),
                    );
                }
            }
        }
    }

    /// A cuboid's half extents at `path`: each ≥ 0, at most one of them 0 (a flat box is a
    /// thin shape; a line or a point is no shape).
    fn cuboid(&mut self, path: &FieldPath, half_extents: &[f32; 3]) {
        let before = self.errors.len();
        for (i, &h) in half_extents.iter().enumerate() {
            self.non_negative(&path.key("half_extents").index(i), h);
        }
        if self.errors.len() == before
            && !thin::is_flat(&ShapeDesc::Cuboid {
                half_extents: *half_extents,
            })
            && half_extents.contains(&0.0)
        {
            self.fail(
                &path.key("half_extents"),
                format!(
                    "a cuboid needs at least two half extents > 0 (one 0 makes a flat box),                      got {half_extents:?}"
                ),
            );
        }
    }

    /// A flat `shape` given `thickness` at `path`: a cuboid or convex hull, valid and flat,
    /// and a thickness > 0.
    fn thickened(&mut self, path: &FieldPath, shape: &ShapeDesc, thickness: f32) {
        let thickness_path = path.key("thickness");
        self.positive(&thickness_path, thickness);
        if !matches!(
            shape,
            ShapeDesc::Cuboid { .. } | ShapeDesc::ConvexHull { .. }
        ) {
            self.fail(
                &thickness_path,
                format!(
                    "thickness is allowed on a cuboid or convex_hull, not on a {}",
                    shape.type_name()
                ),
            );
            return;
        }
        let before = self.errors.len();
        self.shape_fields(path, shape);
        if self.errors.len() == before && !thin::is_flat(shape) {
            let what = match shape {
                ShapeDesc::Cuboid { .. } => "this cuboid has no zero half extent",
                _ => "these convex hull points span a volume",
            };
            self.fail(
                &thickness_path,
                format!(
                    "thickness is for a flat shape (a cuboid with a zero half extent, or                      coplanar convex hull points); {what}"
                ),
            );
        }
    }

    /// Checks a triangle mesh: at least one triangle, finite vertices, indices within the
    /// vertices, and no triangle without area. Vertex problems are reported at
    /// `vertices_path`, triangle problems at `indices_path` (both the `file` field for a
    /// mesh read from a file).
    fn mesh(&mut self, vertices_path: &FieldPath, indices_path: &FieldPath, mesh: &MeshData) {
        let from_file = vertices_path == indices_path;
        let vertex_path = |i: usize| {
            if from_file {
                vertices_path.clone()
            } else {
                vertices_path.index(i)
            }
        };
        let triangle_path = |t: usize| {
            if from_file {
                indices_path.clone()
            } else {
                indices_path.index(t)
            }
        };
        match mesh_problem(mesh) {
            None => {}
            Some(MeshProblem::NoTriangles(message)) => self.fail(indices_path, message),
            Some(MeshProblem::Vertex(i, message)) => self.fail(&vertex_path(i), message),
            Some(MeshProblem::Triangle(t, message)) => self.fail(&triangle_path(t), message),
        }
    }
}

fn norm(v: &[f32]) -> f64 {
    v.iter()
        .map(|&x| f64::from(x) * f64::from(x))
        .sum::<f64>()
        .sqrt()
}

#[cfg(test)]
#[path = "validate_tests.rs"]
mod tests;
