//! Overrides and seeded variations of a scene: change fields by their JSON path, then jitter
//! the moving bodies by a seed (`docs/scene-format.md`, "Overrides and variations").
//!
//! An override edits the scene's JSON form (the [`Scene`] serialised to a
//! [`serde_json::Value`]) and the result is read back by the same deserialiser and the same
//! [`validate`] as a scene file, so a value that a file may not hold is refused with the
//! file's error for that field. The jitter draws from ChaCha20 (Bernstein, "ChaCha, a variant
//! of Salsa20", 2008), one stream per body keyed by (seed, body index): a body's draw depends
//! on nothing else, and the arithmetic (IEEE-754 f64 operations and `libm`'s sine and cosine)
//! gives the same bits on every machine.

use std::fmt;
use std::path::Path;

use rand::RngExt;
use rand::SeedableRng;
use rand::rngs::ChaCha20Rng;
use rand_distr::{Distribution, UnitBall, UnitSphere};
use serde::{Deserialize, Serialize};
use serde_json::Value;

use super::error::{BodyLocation, FieldPath, PathSegment, SceneError, SceneErrorKind};
use super::validate::validate;
use super::{BodyKind, Scene, ShapeDesc, WorldAxis};

/// One change of a scene's JSON by path: `materials.wood.friction=0.2`,
/// `bodies[3].linear_velocity=[0,0,-5]`, `solver.substeps=12`.
///
/// The path is written as scene errors write fields ([`FieldPath`]): object keys joined by
/// `.`, array indices in brackets, keys that are not plain identifiers quoted in brackets
/// (`materials["my steel"].friction`). The value replaces whatever is at the path.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Override {
    /// Path of the field from the root of the scene, e.g. `bodies[3].linear_velocity`.
    pub path: String,
    /// The new value, as it would be written in the scene file.
    pub value: Value,
}

impl Override {
    /// Parses `PATH=VALUE`: the text up to the first `=` outside brackets is the path; the
    /// rest is the value, read as JSON (`0.2`, `[0, 0, -5]`, `true`, `{"type": "sphere",
    /// "radius": 0.1}`) or, when it is not JSON, taken as a string (`material=steel`).
    /// Spaces around the path and the value are ignored.
    ///
    /// # Errors
    /// A [`SceneError`] of kind [`SceneErrorKind::Syntax`] whose origin names the text, when
    /// there is no `=`, the path is empty or it is not a well-formed path.
    pub fn parse(text: &str) -> Result<Override, SceneError> {
        let syntax = |message: &str| {
            let mut error = SceneError::new(SceneErrorKind::Syntax, None, message);
            error.origin = Some(format!("{ORIGIN_PREFIX} {text}"));
            error
        };
        let Some(equals) = split_point(text) else {
            return Err(syntax(
                "expected PATH=VALUE, e.g. materials.wood.friction=0.2 or \
                 bodies[3].linear_velocity=[0,0,-5]",
            ));
        };
        let path = text[..equals].trim();
        let value_text = text[equals + 1..].trim();
        match FieldPath::parse(path) {
            Some(parsed) if !parsed.is_root() => {}
            _ => {
                return Err(syntax(&format!(
                    "{path:?} is not a field path (keys joined by '.', indices in brackets, \
                     e.g. bodies[3].shape.radius)"
                )));
            }
        }
        let value = serde_json::from_str(value_text)
            .unwrap_or_else(|_| Value::String(value_text.to_string()));
        Ok(Override::new(path, value))
    }

    /// The override setting `path` to `value` (checked when applied).
    pub fn new(path: impl Into<String>, value: Value) -> Override {
        Override {
            path: path.into(),
            value,
        }
    }
}

impl fmt::Display for Override {
    /// `PATH=VALUE` as [`Override::parse`] reads it back: the value as compact JSON, except a
    /// string that is not JSON itself, which is written bare (`material=steel`).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.value {
            Value::String(text)
                if text.trim() == text
                    && !text.is_empty()
                    && serde_json::from_str::<Value>(text).is_err() =>
            {
                write!(f, "{}={text}", self.path)
            }
            value => write!(f, "{}={value}", self.path),
        }
    }
}

/// Start of the origin of errors caused by overrides: `override materials.wood.friction=-1`
/// (`overrides a=1, b=2` when several may be the cause).
pub const ORIGIN_PREFIX: &str = "override";

/// Byte offset of the `=` that ends the path of `text`: the first one outside brackets and
/// outside a quoted key.
fn split_point(text: &str) -> Option<usize> {
    let mut depth = 0usize;
    let mut quoted = false;
    let mut escaped = false;
    for (i, c) in text.char_indices() {
        if quoted {
            match (escaped, c) {
                (true, _) => escaped = false,
                (false, '\\') => escaped = true,
                (false, '"') => quoted = false,
                _ => {}
            }
            continue;
        }
        match c {
            '"' if depth > 0 => quoted = true,
            '[' => depth += 1,
            ']' => depth = depth.saturating_sub(1),
            '=' if depth == 0 => return Some(i),
            _ => {}
        }
    }
    None
}

/// Random variation of a scene's moving bodies by seed (all zero = none).
///
/// Each moving body (kind `dynamic` or `particle`; static and kinematic bodies are never
/// moved) draws, from its own stream of the seed:
/// - a position offset uniform in the ball of radius `position` (m) about its position;
/// - a rotation by an angle uniform in [0, `angle_degrees`] about an axis uniform on the unit
///   sphere, applied in the world frame about the body's origin (`dynamic` bodies without
///   locked rotation axes only);
/// - a linear velocity offset uniform in the ball of radius `velocity` (m/s).
///
/// Offsets along a body's locked translation axes are dropped. Bodies may overlap after the
/// jitter: whether that is acceptable (it is repaired by the solver's overlap repair in the
/// first steps) is the user's choice of radius.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Jitter {
    /// Radius of the ball of position offsets (m), finite and ≥ 0.
    pub position: f32,
    /// Largest rotation angle (degrees), in [0, 180].
    pub angle_degrees: f32,
    /// Radius of the ball of linear velocity offsets (m/s), finite and ≥ 0.
    pub velocity: f32,
}

impl Jitter {
    /// Whether the jitter changes nothing (every radius and the angle zero).
    pub fn is_none(&self) -> bool {
        self.position == 0.0 && self.angle_degrees == 0.0 && self.velocity == 0.0
    }

    /// The first out-of-range value, as (name, message).
    fn problem(&self) -> Option<(&'static str, String)> {
        let checks = [
            ("position", self.position, f32::INFINITY, "m"),
            ("angle_degrees", self.angle_degrees, 180.0, "degrees"),
            ("velocity", self.velocity, f32::INFINITY, "m/s"),
        ];
        checks.into_iter().find_map(|(name, value, max, unit)| {
            let ok = value.is_finite() && (0.0..=max).contains(&value);
            (!ok).then(|| {
                let range = if max.is_finite() {
                    format!("in [0, {max}]")
                } else {
                    "finite and ≥ 0".to_string()
                };
                (name, format!("must be {range} ({unit}), got {value}"))
            })
        })
    }
}

/// Overrides, then a seeded jitter, applied to a scene.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Variation {
    /// Field changes, applied in order (a later one wins where two set the same field).
    pub overrides: Vec<Override>,
    /// Seed of the jitter and, when not 0, the scene's [`Scene::seed`] (the draws of rough
    /// and impact-perturbed materials): run K of a sweep uses seed K.
    pub seed: u64,
    /// The jitter; all zero leaves the bodies where the overrides put them.
    pub jitter: Jitter,
}

impl Variation {
    /// The scene with the overrides applied (validated exactly as a scene file is, errors
    /// naming the override and the field) and then, where `jitter` is non-zero, each dynamic
    /// body jittered by a counter-based generator keyed by (seed, body index), so run K is the
    /// same on any machine, thread count or worker.
    ///
    /// The mesh files of `trimesh` shapes that an override adds or changes are read relative
    /// to the current directory ([`Variation::apply_in`] names another); meshes the scene
    /// already holds are kept.
    ///
    /// # Errors
    /// A [`SceneError`] whose origin is `override PATH=VALUE` (the override that set the
    /// field, or `overrides …` listing the candidates when it is not clear which):
    /// - [`SceneErrorKind::Syntax`]: a path that is not well-formed;
    /// - [`SceneErrorKind::Structure`]: a path through a value that has no such member (a
    ///   key of a number, an index past the end of an array, a field the scene format does
    ///   not have: the message names the closest existing one), or a value of the wrong type;
    /// - [`SceneErrorKind::Invalid`]: a value [`validate`] rejects, or a jitter out of range.
    pub fn apply(&self, scene: &Scene) -> Result<Scene, SceneError> {
        self.apply_in(scene, Path::new(""))
    }

    /// [`Variation::apply`], reading the mesh files that overrides add or change relative to
    /// `directory` (the scene file's own directory for a scene read from a file).
    ///
    /// # Errors
    /// As [`Variation::apply`]; also [`SceneErrorKind::Invalid`] at `bodies[i].shape.file`
    /// for a mesh file that cannot be read.
    pub fn apply_in(&self, scene: &Scene, directory: &Path) -> Result<Scene, SceneError> {
        let mut varied = if self.overrides.is_empty() {
            scene.clone()
        } else {
            self.overridden(scene, directory)?
        };
        if let Some((name, message)) = self.jitter.problem() {
            let mut error = SceneError::new(SceneErrorKind::Invalid, None, message);
            error.origin = Some(format!("jitter {name}"));
            return Err(error);
        }
        if !self.jitter.is_none() {
            for (index, body) in varied.bodies.iter_mut().enumerate() {
                jitter_body(self.seed, index, &self.jitter, body);
            }
        }
        // The seed also draws the rough surfaces' normals and the perturbed impacts: run K of
        // a sweep gets its own. A non-zero seed replaces the scene's whatever it draws, so
        // `--seed K`, `--set seed=K` and Python's `from_scene(seed=K)` give the same scene.
        if self.seed != 0 {
            varied.seed = self.seed;
        }
        validate(&varied).map_err(|e| self.blame(e))?;
        Ok(varied)
    }

    /// The overrides applied to `scene` and read back as a scene file is.
    fn overridden(&self, scene: &Scene, directory: &Path) -> Result<Scene, SceneError> {
        let mut json = serde_json::to_value(scene).map_err(|e| {
            self.blame(SceneError::new(
                SceneErrorKind::Structure,
                None,
                format!("the scene has no JSON form: {e}"),
            ))
        })?;
        for item in &self.overrides {
            let path = FieldPath::parse(item.path.trim())
                .filter(|path| !path.is_root())
                .ok_or_else(|| {
                    let mut error = SceneError::new(
                        SceneErrorKind::Syntax,
                        None,
                        format!(
                            "{:?} is not a field path (keys joined by '.', indices in \
                             brackets, e.g. bodies[3].shape.radius)",
                            item.path
                        ),
                    );
                    error.origin = Some(format!("{ORIGIN_PREFIX} {item}"));
                    error
                })?;
            set_path(&mut json, &path, item.value.clone()).map_err(|(at, message)| {
                let mut error = SceneError::new(SceneErrorKind::Structure, Some(at), message);
                error.origin = Some(format!("{ORIGIN_PREFIX} {item}"));
                with_body(error, &json)
            })?;
        }
        let text = json.to_string();
        let mut varied = super::json::parse_only(&text).map_err(|mut e| {
            // The position is in the generated text, which the user never sees.
            e.position = None;
            e.message = with_suggestion(&e.message);
            self.blame(e)
        })?;
        load_meshes(&mut varied, scene, directory).map_err(|e| self.blame(e))?;
        Ok(varied)
    }

    /// `error` with its origin naming the override(s) that caused it: the one whose path
    /// shares the longest start with the error's field (the last of them if several), or
    /// every override when none shares any.
    fn blame(&self, mut error: SceneError) -> SceneError {
        if error.origin.is_some() || self.overrides.is_empty() {
            return error;
        }
        let field = error.field.clone().unwrap_or_default();
        let shared = |o: &Override| {
            FieldPath::parse(o.path.trim()).map_or(0, |path| {
                path.segments()
                    .iter()
                    .zip(field.segments())
                    .take_while(|(a, b)| a == b)
                    .count()
            })
        };
        let best = self.overrides.iter().map(shared).max().unwrap_or(0);
        let origin = if best > 0 {
            let last = self
                .overrides
                .iter()
                .rev()
                .find(|o| shared(o) == best)
                .map(ToString::to_string)
                .unwrap_or_default();
            format!("{ORIGIN_PREFIX} {last}")
        } else if let [only] = self.overrides.as_slice() {
            format!("{ORIGIN_PREFIX} {only}")
        } else {
            let all: Vec<String> = self.overrides.iter().map(ToString::to_string).collect();
            format!("{ORIGIN_PREFIX}s {}", all.join(", "))
        };
        error.origin = Some(origin);
        error
    }
}

/// `error` with its body (index and name, read from `json`) set when its field is inside
/// `bodies[i]`.
fn with_body(mut error: SceneError, json: &Value) -> SceneError {
    if let Some(index) = error.field.as_ref().and_then(FieldPath::body_index) {
        let name = json
            .pointer(&format!("/bodies/{index}/name"))
            .and_then(Value::as_str)
            .map(str::to_string);
        error.body = Some(BodyLocation { index, name });
    }
    error
}

/// The JSON type of `value`, for messages.
fn type_name(value: &Value) -> &'static str {
    match value {
        Value::Null => "null",
        Value::Bool(_) => "a boolean",
        Value::Number(_) => "a number",
        Value::String(_) => "a string",
        Value::Array(_) => "an array",
        Value::Object(_) => "an object",
    }
}

/// Sets the value at `path` in `root` to `value`. A missing object key is added (the scene
/// format then decides whether it is a field: a map such as `materials` takes any key, a
/// struct only its own fields), with objects made for the keys after it; an index may address
/// an element or the one past the end (appending). Errors give the path reached and why it
/// cannot go on.
fn set_path(root: &mut Value, path: &FieldPath, value: Value) -> Result<(), (FieldPath, String)> {
    let segments = path.segments();
    let mut here = root;
    let mut reached = FieldPath::root();
    for (n, segment) in segments.iter().enumerate() {
        let last = n + 1 == segments.len();
        let shown = |reached: &FieldPath| {
            if reached.is_root() {
                "the scene".to_string()
            } else {
                reached.to_string()
            }
        };
        here = match (here, segment) {
            (Value::Object(map), PathSegment::Key(key)) => {
                if !map.contains_key(key) {
                    // Set whatever follows as a new object: the deserialiser judges the key.
                    let mut fresh = value;
                    for later in segments[n + 1..].iter().rev() {
                        match later {
                            PathSegment::Key(k) => {
                                let mut object = serde_json::Map::new();
                                object.insert(k.clone(), fresh);
                                fresh = Value::Object(object);
                            }
                            PathSegment::Index(i) => {
                                return Err((
                                    reached.key(key),
                                    format!(
                                        "has no element {i}: {} has no member {key:?}",
                                        shown(&reached)
                                    ),
                                ));
                            }
                        }
                    }
                    map.insert(key.clone(), fresh);
                    return Ok(());
                }
                reached = reached.key(key);
                map.get_mut(key).expect("key checked present")
            }
            (Value::Array(items), PathSegment::Index(i)) => {
                let len = items.len();
                if *i == len && last {
                    items.push(value);
                    return Ok(());
                }
                if *i >= len {
                    return Err((
                        reached.index(*i),
                        format!(
                            "index out of range: {} has {len} elements (an override may \
                             append one, at index {len})",
                            shown(&reached)
                        ),
                    ));
                }
                reached = reached.index(*i);
                &mut items[*i]
            }
            (other, segment) => {
                let wanted = match segment {
                    PathSegment::Key(k) => format!("no field {k:?}"),
                    PathSegment::Index(i) => format!("no element [{i}]"),
                };
                return Err((
                    reached.clone(),
                    format!("is {}, which has {wanted}", type_name(other)),
                ));
            }
        };
    }
    *here = value;
    Ok(())
}

/// serde's "unknown field `x`, expected one of `a`, `b`" (or "unknown variant …") with the
/// closest expected name added when there is a close one.
fn with_suggestion(message: &str) -> String {
    if !(message.starts_with("unknown field") || message.starts_with("unknown variant")) {
        return message.to_string();
    }
    let names: Vec<&str> = message.split('`').skip(1).step_by(2).collect();
    let Some((unknown, expected)) = names.split_first() else {
        return message.to_string();
    };
    let closest = expected
        .iter()
        .map(|name| (strsim::damerau_levenshtein(unknown, name), *name))
        .min();
    match closest {
        // Close: at most a third of the name's characters differ.
        Some((distance, name)) if distance * 3 <= unknown.chars().count().max(3) => {
            format!("{message} (did you mean `{name}`?)")
        }
        _ => message.to_string(),
    }
}

/// Reads the mesh file of every `trimesh` shape of `varied` that has a file but no mesh yet:
/// the mesh of the same body of `original` when its file is the same, else the file read
/// relative to `directory`.
fn load_meshes(varied: &mut Scene, original: &Scene, directory: &Path) -> Result<(), SceneError> {
    for (index, body) in varied.bodies.iter_mut().enumerate() {
        let ShapeDesc::Trimesh {
            file: Some(file),
            loaded,
            ..
        } = &mut body.shape
        else {
            continue;
        };
        let kept = original
            .bodies
            .get(index)
            .and_then(|before| match &before.shape {
                ShapeDesc::Trimesh {
                    file: Some(before_file),
                    loaded: Some(mesh),
                    ..
                } if before_file == file => Some(mesh.clone()),
                _ => None,
            });
        *loaded = match kept {
            Some(mesh) => Some(mesh),
            None => Some(super::json::read_body_mesh(
                index,
                body.name.as_deref(),
                file,
                directory,
            )?),
        };
    }
    Ok(())
}

/// The generator of body `index` for `seed`: ChaCha20 keyed by the seed (its 8 little-endian
/// bytes, then zeros), on stream `index`, from word 0.
pub(super) fn body_generator(seed: u64, index: usize) -> ChaCha20Rng {
    let mut key = [0u8; 32];
    key[..8].copy_from_slice(&seed.to_le_bytes());
    let mut generator = ChaCha20Rng::from_seed(key);
    generator.set_stream(index as u64);
    generator
}

/// Jitters `body` (the `index`-th of the scene) as [`Jitter`] documents. The draws are made in
/// a fixed order whatever the body's kind (position, axis, angle, velocity), so adding a
/// field to one kind cannot shift another's.
fn jitter_body(seed: u64, index: usize, jitter: &Jitter, body: &mut super::BodyDesc) {
    let moving = matches!(body.kind, BodyKind::Dynamic | BodyKind::Particle);
    if !moving {
        return;
    }
    let mut generator = body_generator(seed, index);
    let position: [f64; 3] = UnitBall.sample(&mut generator);
    let axis: [f64; 3] = UnitSphere.sample(&mut generator);
    let angle_fraction: f64 = generator.random();
    let velocity: [f64; 3] = UnitBall.sample(&mut generator);

    let mut locked = [false; 3];
    for axis in &body.locked_axes.translation {
        locked[match axis {
            WorldAxis::X => 0,
            WorldAxis::Y => 1,
            WorldAxis::Z => 2,
        }] = true;
    }
    let offset = |value: &mut [f32; 3], unit: [f64; 3], radius: f32| {
        for k in 0..3 {
            if !locked[k] {
                value[k] = (f64::from(value[k]) + unit[k] * f64::from(radius)) as f32;
            }
        }
    };
    offset(&mut body.position, position, jitter.position);
    offset(&mut body.linear_velocity, velocity, jitter.velocity);

    let may_turn = body.kind == BodyKind::Dynamic
        && !body.lock_rotation
        && body.locked_axes.rotation.is_empty();
    if may_turn && jitter.angle_degrees > 0.0 {
        let half = 0.5 * angle_fraction * f64::from(jitter.angle_degrees).to_radians();
        let (s, c) = (libm::sin(half), libm::cos(half));
        let turn = [axis[0] * s, axis[1] * s, axis[2] * s, c];
        let q = body.orientation.map(f64::from);
        body.orientation = quaternion_product(turn, q).map(|v| v as f32);
    }
}

/// The Hamilton product a·b of quaternions `[x, y, z, w]`: b, then a.
fn quaternion_product(a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
    let [ax, ay, az, aw] = a;
    let [bx, by, bz, bw] = b;
    [
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
        aw * bw - ax * bx - ay * by - az * bz,
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parse_splits_at_the_first_equals_outside_brackets() {
        let o = Override::parse("materials[\"a=b\"].friction = 0.25").unwrap();
        assert_eq!(o.path, "materials[\"a=b\"].friction");
        assert_eq!(o.value, serde_json::json!(0.25));
        let o = Override::parse("bodies[0].material=steel").unwrap();
        assert_eq!(o.value, Value::String("steel".into()));
        let o = Override::parse("bodies[1].linear_velocity=[0,0,-5]").unwrap();
        assert_eq!(o.value, serde_json::json!([0, 0, -5]));
        assert_eq!(o.to_string(), "bodies[1].linear_velocity=[0,0,-5]");
        for text in ["name=pyramid", "name=\"1\"", "name=\"\"", "dt=0.5"] {
            let o = Override::parse(text).unwrap();
            assert_eq!(o.to_string(), text);
            assert_eq!(Override::parse(&o.to_string()).unwrap(), o);
        }
        for bad in ["friction", "=1", "a..b=1", "bodies[x]=1"] {
            let error = Override::parse(bad).unwrap_err();
            assert_eq!(error.kind, SceneErrorKind::Syntax, "{bad}");
            assert!(error.to_string().starts_with("override "), "{error}");
        }
    }

    #[test]
    fn suggestion_names_the_closest_field() {
        assert_eq!(
            with_suggestion("unknown field `fricton`, expected one of `friction`, `density`"),
            "unknown field `fricton`, expected one of `friction`, `density` \
             (did you mean `friction`?)"
        );
        assert_eq!(
            with_suggestion("unknown field `zzz`, expected `friction`"),
            "unknown field `zzz`, expected `friction`"
        );
    }

    #[test]
    fn quaternion_product_composes_rotations() {
        let half = std::f64::consts::FRAC_PI_4; // 90° about z, twice: 180° about z.
        let quarter = [0.0, 0.0, libm::sin(half), libm::cos(half)];
        let q = quaternion_product(quarter, quarter);
        assert!(
            (q[2].abs() - 1.0).abs() < 1e-15 && q[3].abs() < 1e-15,
            "{q:?}"
        );
    }
}
