//! Reading and writing scenes as JSON (`docs/scene-format.md`), with errors that name the
//! file, line, column, body and field.
//!
//! Parse errors come from serde_json (line and column) and `serde_path_to_error` (field path).
//! Validation errors ([`validate`]) carry only a field path; [`locate`], a small tolerant JSON
//! scanner, finds the line where that value starts in the text.

use std::io;
use std::path::Path;

use serde::Serialize;

use super::error::{
    BodyLocation, FieldPath, PathSegment, SceneError, SceneErrorKind, TextPosition,
};
use super::validate::validate;
use super::{
    BodyDesc, BodyKind, KeyframeDesc, LockedAxesDesc, Material, MaterialRef, Scene, ShapeDesc,
};
use crate::settings::SolverSettings;

/// Largest scene file [`load_scene_file`] reads: 256 MiB (268,435,456 bytes). A scene of a
/// million bodies is about 200 MB of JSON; anything larger is not a scene, and reading it whole
/// would exhaust memory first.
pub const MAX_SCENE_FILE_BYTES: u64 = 256 << 20;

/// Reads, parses and validates the scene file at `path`. A UTF-8 byte order mark at the start
/// is skipped.
///
/// # Errors
/// - [`SceneErrorKind::Io`] if the file cannot be read, is not a regular file (a directory, a
///   device such as `/dev/zero`, a pipe) or is larger than [`MAX_SCENE_FILE_BYTES`]; the last
///   two are found from the file's metadata, before reading;
/// - otherwise as [`parse_scene_str`], with the file's path (as given) as the origin.
pub fn load_scene_file(path: &Path) -> Result<Scene, SceneError> {
    let origin = path.display().to_string();
    let io_error = |message: String| {
        let mut error = SceneError::new(SceneErrorKind::Io, None, message);
        error.origin = Some(origin.clone());
        error
    };
    let metadata = std::fs::metadata(path).map_err(|e| io_error(format!("cannot read: {e}")))?;
    if !metadata.is_file() {
        return Err(io_error(
            "cannot read: not a regular file (a scene is read from a file)".to_string(),
        ));
    }
    if metadata.len() > MAX_SCENE_FILE_BYTES {
        return Err(io_error(format!(
            "cannot read: the file has {} bytes, more than the {} bytes (256 MiB) a scene file \
             may have",
            metadata.len(),
            MAX_SCENE_FILE_BYTES
        )));
    }
    let text = std::fs::read_to_string(path).map_err(|e| io_error(format!("cannot read: {e}")))?;
    let directory = path.parent().unwrap_or(Path::new(""));
    parse_scene_str_in(&text, &origin, directory)
}

/// Parses the JSON scene `text` and validates it. `origin` names the text in error messages
/// (normally its file path). A UTF-8 byte order mark at the start is skipped.
///
/// # Errors
/// The first problem found, with `origin` and, when it can be found, the line and column:
/// - [`SceneErrorKind::Syntax`]: not JSON, or a number beyond the f64 range such as `1e999`
///   (position where the parser stopped; `field` is the path the parser was in);
/// - [`SceneErrorKind::Structure`]: unknown field, wrong type, missing field, bad enum value
///   (position where the parser stopped; `field` is the path the parser was in, down to the
///   unknown key for unknown fields);
/// - [`SceneErrorKind::Invalid`]: a [`validate`] failure (position where the offending value,
///   or else its closest enclosing value present in the text, starts).
///
/// For errors inside `bodies[i]`, `body` holds the index and the body's `name` if the text has one.
/// Inside a `shape` the path of a type error stops at `shape`, because serde reads a tagged
/// shape whole before choosing its type; errors inside an inline `material` are traced to the
/// material's field.
///
/// Mesh files of `trimesh` shapes are read relative to the current directory
/// ([`parse_scene_str_in`] names another).
pub fn parse_scene_str(text: &str, origin: &str) -> Result<Scene, SceneError> {
    parse_scene_str_in(text, origin, Path::new(""))
}

/// [`parse_scene_str`], reading the mesh files of `trimesh` shapes relative to `directory`
/// (the scene file's own directory when called by [`load_scene_file`]).
///
/// # Errors
/// As [`parse_scene_str`]; also [`SceneErrorKind::Invalid`] at `bodies[i].shape.file` for a
/// mesh file that cannot be read or is not a valid OBJ, glTF or GLB file.
pub fn parse_scene_str_in(text: &str, origin: &str, directory: &Path) -> Result<Scene, SceneError> {
    // A byte order mark is not JSON (RFC 8259 §8.1 lets a parser ignore it); editors on
    // Windows write one.
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let locate_error = |mut e: SceneError| {
        e.origin = Some(origin.to_string());
        if let Some(field) = &e.field {
            e.position = locate_closest(text, field);
        }
        e
    };
    let mut scene = parse_only(text).map_err(|mut e| {
        e.origin = Some(origin.to_string());
        e
    })?;
    load_meshes(&mut scene, directory).map_err(locate_error)?;
    validate(&scene).map_err(locate_error)?;
    Ok(scene)
}

/// Reads the file of every `trimesh` shape of `scene` (relative to `directory`) into its
/// `loaded` mesh, each file named once read once: the bodies naming it share its triangles.
/// Errors name the body and `shape.file` (the first body naming a file that fails) but have
/// no origin yet.
fn load_meshes(scene: &mut Scene, directory: &Path) -> Result<(), SceneError> {
    let mut read = std::collections::HashMap::new();
    for (index, body) in scene.bodies.iter_mut().enumerate() {
        if let ShapeDesc::Trimesh {
            file: Some(file),
            loaded,
            ..
        } = &mut body.shape
        {
            let mesh = match read.get(file.as_str()) {
                Some(mesh) => super::mesh_file::LoadedMesh::clone(mesh),
                None => {
                    let mesh = read_body_mesh(index, body.name.as_deref(), file, directory)?;
                    read.insert(file.clone(), mesh.clone());
                    mesh
                }
            };
            *loaded = Some(mesh);
        }
    }
    Ok(())
}

/// Reads body `index`'s mesh `file` relative to `directory`. Errors name the body and
/// `shape.file` but have no origin yet.
pub(crate) fn read_body_mesh(
    index: usize,
    name: Option<&str>,
    file: &str,
    directory: &Path,
) -> Result<super::mesh_file::LoadedMesh, SceneError> {
    let mesh = super::mesh_file::load_mesh_file(&directory.join(file)).map_err(|e| {
        let mut error = SceneError::new(
            SceneErrorKind::Invalid,
            Some(FieldPath::body(index).key("shape").key("file")),
            e.to_string(),
        );
        error.body = Some(BodyLocation {
            index,
            name: name.map(str::to_string),
        });
        error
    })?;
    Ok(super::mesh_file::LoadedMesh(std::sync::Arc::new(mesh)))
}

/// Parses without validating; errors have no origin yet.
pub(crate) fn parse_only(text: &str) -> Result<Scene, SceneError> {
    let mut de = serde_json::Deserializer::from_str(text);
    let scene: Scene = serde_path_to_error::deserialize(&mut de).map_err(|e| {
        let field = convert_path(e.path());
        json_error(text, field, e.inner())
    })?;
    de.end()
        .map_err(|e| json_error(text, FieldPath::root(), &e))?;
    Ok(scene)
}

/// Turns a serde_json error at `field` into a [`SceneError`].
fn json_error(text: &str, mut field: FieldPath, inner: &serde_json::Error) -> SceneError {
    let kind = match inner.classify() {
        serde_json::error::Category::Io => SceneErrorKind::Io,
        serde_json::error::Category::Syntax | serde_json::error::Category::Eof => {
            SceneErrorKind::Syntax
        }
        serde_json::error::Category::Data => SceneErrorKind::Structure,
    };
    let mut message = bare_message(inner);
    // The root as an array or a scalar: serde's `invalid length 6, expected struct Scene with 8
    // elements` speaks of the Rust type, not of the file.
    if field.0.is_empty() && message.contains("expected struct Scene") {
        message = "a scene is a JSON object with a `bodies` array (and optional `gravity`, \
                   `dt`, `solver`, `materials`, `joints`), e.g. {\"bodies\": []}"
            .to_string();
    }
    let mut position =
        (inner.line() > 0).then(|| TextPosition::new(inner.line(), inner.column().max(1)));
    if message.starts_with("data did not match any variant of untagged enum MaterialRef") {
        // serde tries both forms and forgets why each failed: find out again.
        match material_error(text, &field) {
            Some((path, refined, at)) => {
                field.0.extend(path.0);
                message = refined;
                position = at.or(position);
            }
            None => {
                message = "must be a material name (a string) or an inline material \
                           (an object with friction, restitution, density)"
                    .to_string();
                position = locate(text, &field).or(position);
            }
        }
    }
    let body = field.body_index().map(|index| BodyLocation {
        index,
        name: string_at(text, &FieldPath::body(index).key("name")),
    });
    let mut error = SceneError::new(kind, (!field.is_root()).then_some(field), message);
    error.position =
        position.or_else(|| error.field.as_ref().and_then(|f| locate_closest(text, f)));
    error.body = body;
    error
}

/// serde_json's message without the " at line L column C" it appends.
fn bare_message(error: &serde_json::Error) -> String {
    let full = error.to_string();
    let suffix = format!(" at line {} column {}", error.line(), error.column());
    full.strip_suffix(&suffix).unwrap_or(&full).to_string()
}

/// Why the object at `field` is not a [`Material`]: the path inside it, the message and the
/// position in `text`. `None` if the value there is not an object or is a valid material.
fn material_error(
    text: &str,
    field: &FieldPath,
) -> Option<(FieldPath, String, Option<TextPosition>)> {
    let mut scanner = Scanner::new(text);
    let start = scanner.seek(field.segments())?;
    if scanner.peek()? != b'{' {
        return None;
    }
    scanner.skip_value()?;
    let mut de = serde_json::Deserializer::from_str(&text[start..scanner.i]);
    let error = serde_path_to_error::deserialize::<_, Material>(&mut de).err()?;
    let inner = error.inner();
    let base = position_of(text, start);
    let position = (inner.line() > 0).then(|| {
        if inner.line() == 1 {
            TextPosition::new(
                base.line as usize,
                base.column as usize + inner.column().max(1) - 1,
            )
        } else {
            TextPosition::new(base.line as usize + inner.line() - 1, inner.column().max(1))
        }
    });
    Some((convert_path(error.path()), bare_message(inner), position))
}

fn convert_path(path: &serde_path_to_error::Path) -> FieldPath {
    use serde_path_to_error::Segment;
    let mut out = FieldPath::root();
    for segment in path {
        match segment {
            Segment::Seq { index } => out.0.push(PathSegment::Index(*index)),
            Segment::Map { key } => out.0.push(PathSegment::Key(key.clone())),
            Segment::Enum { variant } => out.0.push(PathSegment::Key(variant.clone())),
            Segment::Unknown => break,
        }
    }
    out
}

// ---------------------------------------------------------------------------------------------
// Locator: a minimal JSON scanner that follows a path to the start of a value.

/// Where the value at `path` starts in the JSON `text` (1-based line and column), or `None`
/// if the text has no such value (or is too malformed to follow). The root path gives the
/// start of the top-level value.
///
/// The scanner only follows object keys and array indices; it does not check scalars, so it
/// works on texts serde_json rejects (e.g. with `1e999`). With duplicate keys the first wins.
pub fn locate(text: &str, path: &FieldPath) -> Option<TextPosition> {
    let offset = Scanner::new(text).seek(path.segments())?;
    Some(position_of(text, offset))
}

/// [`locate`] for `path`, or else for its longest prefix present in the text (e.g. the body's
/// own start for `bodies[3].mass` when the body has no `mass`); `None` if nothing is found.
pub fn locate_closest(text: &str, path: &FieldPath) -> Option<TextPosition> {
    let segments = path.segments();
    (1..=segments.len()).rev().find_map(|n| {
        Scanner::new(text)
            .seek(&segments[..n])
            .map(|offset| position_of(text, offset))
    })
}

/// The string at `path` in `text`, if there is one (used to name bodies in parse errors).
fn string_at(text: &str, path: &FieldPath) -> Option<String> {
    let mut scanner = Scanner::new(text);
    let start = scanner.seek(path.segments())?;
    let (s, e) = scanner.string()?;
    debug_assert_eq!(s, start);
    serde_json::from_str(&text[s..e]).ok()
}

fn position_of(text: &str, offset: usize) -> TextPosition {
    let before = &text[..offset];
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    TextPosition::new(
        before.matches('\n').count() + 1,
        before[line_start..].chars().count() + 1,
    )
}

struct Scanner<'a> {
    text: &'a str,
    bytes: &'a [u8],
    i: usize,
}

impl<'a> Scanner<'a> {
    fn new(text: &'a str) -> Self {
        Self {
            text,
            bytes: text.as_bytes(),
            i: 0,
        }
    }

    fn ws(&mut self) {
        while self.i < self.bytes.len() && self.bytes[self.i].is_ascii_whitespace() {
            self.i += 1;
        }
    }

    fn peek(&self) -> Option<u8> {
        self.bytes.get(self.i).copied()
    }

    /// Consumes `byte` after whitespace.
    fn expect(&mut self, byte: u8) -> Option<()> {
        self.ws();
        (self.peek()? == byte).then(|| self.i += 1)
    }

    /// Consumes the string literal at the cursor; returns its byte span including quotes.
    fn string(&mut self) -> Option<(usize, usize)> {
        let start = self.i;
        if self.peek()? != b'"' {
            return None;
        }
        self.i += 1;
        loop {
            match *self.bytes.get(self.i)? {
                b'\\' => self.i += 2,
                b'"' => {
                    self.i += 1;
                    return Some((start, self.i));
                }
                _ => self.i += 1,
            }
        }
    }

    /// Skips the value at the cursor (after whitespace).
    fn skip_value(&mut self) -> Option<()> {
        self.ws();
        let mut depth = 0usize;
        loop {
            match self.peek()? {
                b'"' => {
                    self.string()?;
                }
                b'{' | b'[' => {
                    depth += 1;
                    self.i += 1;
                }
                b'}' | b']' => {
                    depth = depth.checked_sub(1)?;
                    self.i += 1;
                }
                b',' | b':' if depth > 0 => self.i += 1,
                b if b.is_ascii_whitespace() => self.i += 1,
                _ => {
                    // A scalar: number or literal, up to a delimiter.
                    let start = self.i;
                    while let Some(b) = self.peek() {
                        if b == b','
                            || b == b']'
                            || b == b'}'
                            || b == b':'
                            || b.is_ascii_whitespace()
                        {
                            break;
                        }
                        self.i += 1;
                    }
                    if self.i == start {
                        return None;
                    }
                }
            }
            if depth == 0 {
                return Some(());
            }
        }
    }

    /// Follows `path` from the value at the cursor; returns the byte offset where the target
    /// value starts.
    fn seek(&mut self, path: &[PathSegment]) -> Option<usize> {
        self.ws();
        let Some((first, rest)) = path.split_first() else {
            return (self.i < self.bytes.len()).then_some(self.i);
        };
        match (self.peek()?, first) {
            (b'{', PathSegment::Key(wanted)) => {
                self.i += 1;
                loop {
                    self.ws();
                    if self.peek()? == b'}' {
                        return None;
                    }
                    let (s, e) = self.string()?;
                    let raw = &self.text[s + 1..e - 1];
                    let matches = if raw.contains('\\') {
                        serde_json::from_str::<String>(&self.text[s..e]).ok()? == *wanted
                    } else {
                        raw == wanted
                    };
                    self.expect(b':')?;
                    if matches {
                        return self.seek(rest);
                    }
                    self.skip_value()?;
                    self.ws();
                    match self.peek()? {
                        b',' => self.i += 1,
                        _ => return None,
                    }
                }
            }
            (b'[', PathSegment::Index(wanted)) => {
                self.i += 1;
                for index in 0.. {
                    self.ws();
                    if self.peek()? == b']' {
                        return None;
                    }
                    if index == *wanted {
                        return self.seek(rest);
                    }
                    self.skip_value()?;
                    self.ws();
                    match self.peek()? {
                        b',' => self.i += 1,
                        _ => return None,
                    }
                }
                None
            }
            _ => None,
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Writer.

/// The scene as JSON that [`parse_scene_str`] reads back to an equal [`Scene`]: the top-level
/// object one member per line, each material and each body on a line of its own, so that
/// scenes of thousands of bodies stay readable and diff well.
///
/// `solver` is written only if it differs from [`SolverSettings::default()`], so that the
/// standard scene files follow the engine's default settings. Body fields equal to their
/// defaults are left out (identity `orientation`, zero velocities,
/// `"material": "default"`, no `name`, no `mass`); `position` is always written. Floats are
/// written in the shortest form that reads back to the same f32. Non-finite numbers (which
/// [`validate`] rejects) are written as `null` and do not load.
pub fn to_json_string(scene: &Scene) -> String {
    // Destructured so that a new field of `Scene` cannot be forgotten here.
    let Scene {
        name,
        gravity,
        dt,
        steps,
        solver,
        materials,
        bodies,
        joints,
        seed,
    } = scene;
    let mut out = String::from("{\n");
    let mut members = vec![
        ("name", one_line(name)),
        ("gravity", one_line(gravity)),
        ("dt", one_line(dt)),
        ("steps", one_line(steps)),
    ];
    if *seed != 0 {
        members.push(("seed", one_line(seed)));
    }
    if *solver != SolverSettings::default() {
        members.push(("solver", one_line(solver)));
    }
    for (key, value) in members {
        out.push_str(&format!("  \"{key}\": {value},\n"));
    }
    out.push_str("  \"materials\": ");
    list(
        &mut out,
        '{',
        '}',
        materials
            .iter()
            .map(|(k, m)| format!("{}: {}", one_line(k), one_line(&MaterialOut::from(m)))),
    );
    out.push_str(",\n  \"bodies\": ");
    list(
        &mut out,
        '[',
        ']',
        bodies.iter().map(|b| one_line(&BodyOut::from(b))),
    );
    if !joints.is_empty() {
        out.push_str(",\n  \"joints\": ");
        list(&mut out, '[', ']', joints.iter().map(one_line));
    }
    out.push_str("\n}\n");
    out
}

/// Writes `items` between `open` and `close`, one per line indented by 4, or `{}` / `[]`.
fn list(out: &mut String, open: char, close: char, items: impl Iterator<Item = String>) {
    out.push(open);
    let mut any = false;
    for item in items {
        out.push_str(if any { ",\n    " } else { "\n    " });
        out.push_str(&item);
        any = true;
    }
    if any {
        out.push_str("\n  ");
    }
    out.push(close);
}

/// A body as written: fields at their defaults are skipped.
#[derive(Serialize)]
struct BodyOut<'a> {
    #[serde(skip_serializing_if = "Option::is_none")]
    name: &'a Option<String>,
    kind: BodyKind,
    shape: &'a ShapeDesc,
    position: [f32; 3],
    #[serde(skip_serializing_if = "is_identity")]
    orientation: [f32; 4],
    #[serde(skip_serializing_if = "is_zero")]
    linear_velocity: [f32; 3],
    #[serde(skip_serializing_if = "is_zero")]
    angular_velocity: [f32; 3],
    #[serde(
        skip_serializing_if = "is_default_material",
        serialize_with = "material_ref_out"
    )]
    material: &'a MaterialRef,
    #[serde(skip_serializing_if = "Option::is_none")]
    mass: Option<f32>,
    #[serde(skip_serializing_if = "is_zero_scalar")]
    linear_damping: f32,
    #[serde(skip_serializing_if = "is_zero_scalar")]
    angular_damping: f32,
    #[serde(skip_serializing_if = "is_false")]
    lock_rotation: bool,
    #[serde(skip_serializing_if = "LockedAxesDesc::is_empty")]
    locked_axes: &'a LockedAxesDesc,
    #[serde(skip_serializing_if = "is_all")]
    groups: u32,
    #[serde(skip_serializing_if = "is_all")]
    mask: u32,
    #[serde(skip_serializing_if = "Option::is_none")]
    keyframes: &'a Option<Vec<KeyframeDesc>>,
    #[serde(skip_serializing_if = "<[_]>::is_empty")]
    roughness_draws: &'a [[f32; 2]],
}

impl<'a> From<&'a BodyDesc> for BodyOut<'a> {
    fn from(b: &'a BodyDesc) -> Self {
        // Destructured so that a new field of `BodyDesc` cannot be forgotten here.
        let BodyDesc {
            name,
            kind,
            shape,
            position,
            orientation,
            linear_velocity,
            angular_velocity,
            material,
            mass,
            linear_damping,
            angular_damping,
            lock_rotation,
            locked_axes,
            groups,
            mask,
            keyframes,
            roughness_draws,
        } = b;
        Self {
            name,
            kind: *kind,
            shape,
            position: *position,
            orientation: *orientation,
            linear_velocity: *linear_velocity,
            angular_velocity: *angular_velocity,
            material,
            mass: *mass,
            linear_damping: *linear_damping,
            angular_damping: *angular_damping,
            lock_rotation: *lock_rotation,
            locked_axes,
            groups: *groups,
            mask: *mask,
            keyframes,
            roughness_draws,
        }
    }
}

// Exact comparisons are intended: a field is skipped only if reading the default back
// gives an equal value (−0.0 == 0.0 under PartialEq).
#[allow(clippy::float_cmp)]
fn is_identity(q: &[f32; 4]) -> bool {
    *q == [0.0, 0.0, 0.0, 1.0]
}
#[allow(clippy::float_cmp)]
fn is_zero(v: &[f32; 3]) -> bool {
    *v == [0.0; 3]
}
#[allow(clippy::float_cmp)]
fn is_zero_scalar(v: &f32) -> bool {
    *v == 0.0
}
fn is_false(b: &bool) -> bool {
    !*b
}
fn is_all(bits: &u32) -> bool {
    *bits == u32::MAX
}
fn is_default_material(m: &&MaterialRef) -> bool {
    **m == MaterialRef::default()
}

/// A material as written: a smooth surface's `roughness` (0) and an unperturbed one's
/// `impact_perturbation` (0) are left out, as scene files written before they existed read.
#[derive(Serialize)]
struct MaterialOut {
    friction: f32,
    restitution: f32,
    density: f32,
    #[serde(skip_serializing_if = "is_zero_scalar")]
    roughness: f32,
    #[serde(skip_serializing_if = "is_zero_scalar")]
    impact_perturbation: f32,
}

impl From<&Material> for MaterialOut {
    fn from(m: &Material) -> Self {
        let Material {
            friction,
            restitution,
            density,
            roughness,
            impact_perturbation,
        } = *m;
        MaterialOut {
            friction,
            restitution,
            density,
            roughness,
            impact_perturbation,
        }
    }
}

fn material_ref_out<S: serde::Serializer>(m: &&MaterialRef, s: S) -> Result<S::Ok, S::Error> {
    match m {
        MaterialRef::Named(name) => s.serialize_str(name),
        MaterialRef::Inline(material) => MaterialOut::from(material).serialize(s),
    }
}

/// serde_json formatter for one line with a space after `,` and `:`.
struct OneLine;

impl serde_json::ser::Formatter for OneLine {
    fn begin_array_value<W: ?Sized + io::Write>(
        &mut self,
        w: &mut W,
        first: bool,
    ) -> io::Result<()> {
        if first { Ok(()) } else { w.write_all(b", ") }
    }
    fn begin_object_key<W: ?Sized + io::Write>(
        &mut self,
        w: &mut W,
        first: bool,
    ) -> io::Result<()> {
        if first { Ok(()) } else { w.write_all(b", ") }
    }
    fn begin_object_value<W: ?Sized + io::Write>(&mut self, w: &mut W) -> io::Result<()> {
        w.write_all(b": ")
    }
}

fn one_line<T: Serialize + ?Sized>(value: &T) -> String {
    let mut buf = Vec::new();
    let mut ser = serde_json::Serializer::with_formatter(&mut buf, OneLine);
    value
        .serialize(&mut ser)
        .expect("scene values serialise to JSON");
    String::from_utf8(buf).expect("serde_json writes UTF-8")
}

#[cfg(test)]
mod tests {
    use super::*;

    const TEXT: &str = r#"{
  "name": "t",
  "materials": {"a b": {"friction": 1}, "x\"y": {"friction": 2}},
  "bodies": [
    {"kind": "static", "shape": {"type": "half_space", "normal": [0, 1, 0]}},
    {
      "name": "lid",
      "kind": "dynamic",
      "shape": {"type": "convex_hull", "points": [[0, 0, 0], [1e999, 0, 0],
                                                  [0, 1, 0]]}
    }
  ]
}"#;

    fn at(path: &str) -> Option<(usize, usize)> {
        locate(TEXT, &FieldPath::parse(path).unwrap()).map(|p| (p.line as usize, p.column as usize))
    }

    #[test]
    fn locator_follows_keys_and_indices() {
        assert_eq!(at(""), Some((1, 1)));
        assert_eq!(at("name"), Some((2, 11)));
        assert_eq!(at("bodies[0]"), Some((5, 5)));
        assert_eq!(at("bodies[0].shape.normal[1]"), Some((5, 70)));
        assert_eq!(at("bodies[1]"), Some((6, 5)));
        assert_eq!(at("bodies[1].name"), Some((7, 15)));
        assert_eq!(at("bodies[1].shape.points[1][0]"), Some((9, 63)));
        assert_eq!(at("bodies[1].shape.points[2]"), Some((10, 51)));
        assert_eq!(at("materials[\"a b\"].friction"), Some((3, 37)));
        assert_eq!(at("materials[\"x\\\"y\"].friction"), Some((3, 62)));
        assert_eq!(at("bodies[2]"), None);
        assert_eq!(at("bodies[1].mass"), None);
        assert_eq!(at("name.x"), None);
        let closest = locate_closest(TEXT, &FieldPath::parse("bodies[1].mass").unwrap());
        assert_eq!(closest, Some(TextPosition::new(6, 5)));
        assert_eq!(
            string_at(TEXT, &FieldPath::parse("bodies[1].name").unwrap()).as_deref(),
            Some("lid")
        );
    }

    #[test]
    fn locator_gives_up_on_garbage() {
        for text in [
            "",
            "{",
            "{\"a\" 1}",
            "[1, 2",
            "{\"bodies\": [1 2]}",
            "\"abc",
        ] {
            assert_eq!(
                locate(text, &FieldPath::parse("bodies[1]").unwrap()),
                None,
                "{text}"
            );
        }
    }

    /// A scene's `solver` keys for options that are off (`auto`'s under `pgs`, sleep's with
    /// `sleep: false`) are written back as read.
    #[test]
    fn a_scenes_solver_keys_survive_read_and_write_whatever_the_method() {
        let text = r#"{"bodies": [], "solver": {"method": "pgs", "escalation_iterations": 9,
            "mass_ratio_threshold": 2.5, "escalation_tolerance": 0.001, "sleep": false,
            "time_to_sleep": 3}}"#;
        let scene = parse_scene_str(text, "t.json").unwrap();
        let written = to_json_string(&scene);
        let solver = &serde_json::from_str::<serde_json::Value>(&written).unwrap()["solver"];
        assert_eq!(solver["escalation_iterations"], 9, "{written}");
        assert_eq!(solver["mass_ratio_threshold"], 2.5, "{written}");
        assert_eq!(solver["escalation_tolerance"], 0.001, "{written}");
        assert_eq!(solver["time_to_sleep"], 3.0, "{written}");
        assert_eq!(parse_scene_str(&written, "t.json").unwrap(), scene);
    }
}
