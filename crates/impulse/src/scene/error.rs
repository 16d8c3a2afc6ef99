//! Errors of reading and checking scene descriptions, with the place they refer to: the
//! file, the line and column in it, the body and the field path.

use std::fmt;

use thiserror::Error;

/// One step of a [`FieldPath`]: an object key or an array index.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub enum PathSegment {
    /// Member of a JSON object (a struct field, a map key such as a material name).
    Key(String),
    /// Element of a JSON array (0-based).
    Index(usize),
}

/// Path from the root of a scene to one value, written like `bodies[3].shape.radius` or
/// `materials.heavy.density`. Keys that are not plain identifiers are written quoted in
/// brackets: `materials["my steel"].friction`.
#[derive(Clone, Debug, Default, PartialEq, Eq, Hash)]
pub struct FieldPath(pub Vec<PathSegment>);

impl FieldPath {
    /// The empty path: the scene itself.
    pub fn root() -> Self {
        Self(Vec::new())
    }

    /// This path followed by object key `key`.
    pub fn key(&self, key: &str) -> Self {
        let mut segments = self.0.clone();
        segments.push(PathSegment::Key(key.to_string()));
        Self(segments)
    }

    /// This path followed by array index `index`.
    pub fn index(&self, index: usize) -> Self {
        let mut segments = self.0.clone();
        segments.push(PathSegment::Index(index));
        Self(segments)
    }

    /// The path `bodies[index]`.
    pub fn body(index: usize) -> Self {
        Self::root().key("bodies").index(index)
    }

    /// The segments, root first.
    pub fn segments(&self) -> &[PathSegment] {
        &self.0
    }

    /// True for the empty path.
    pub fn is_root(&self) -> bool {
        self.0.is_empty()
    }

    /// The body index if the path starts with `bodies[i]`.
    pub fn body_index(&self) -> Option<usize> {
        match self.0.as_slice() {
            [PathSegment::Key(k), PathSegment::Index(i), ..] if k == "bodies" => Some(*i),
            _ => None,
        }
    }

    /// Parses the written form (`bodies[3].shape.half_extents[1]`, `materials["a b"].friction`).
    /// Returns `None` for malformed text. The empty string is the root path.
    pub fn parse(text: &str) -> Option<Self> {
        let mut segments = Vec::new();
        let mut rest = text;
        let mut first = true;
        while !rest.is_empty() {
            if let Some(after) = rest.strip_prefix('[') {
                let close = after.find(']')?;
                let inside = &after[..close];
                if inside.starts_with('"') {
                    // A quoted key: find the closing quote that is followed by `]`.
                    let end = quoted_end(after)?;
                    let key: String = serde_json::from_str(&after[..end]).ok()?;
                    segments.push(PathSegment::Key(key));
                    rest = after[end..].strip_prefix(']')?;
                } else {
                    segments.push(PathSegment::Index(inside.parse().ok()?));
                    rest = &after[close + 1..];
                }
            } else {
                let body = if first { rest } else { rest.strip_prefix('.')? };
                let end = body.find(['.', '[']).unwrap_or(body.len());
                if end == 0 {
                    return None;
                }
                segments.push(PathSegment::Key(body[..end].to_string()));
                rest = &body[end..];
            }
            first = false;
        }
        Some(Self(segments))
    }
}

/// Byte length of the JSON string literal at the start of `text` (which starts with `"`).
fn quoted_end(text: &str) -> Option<usize> {
    let bytes = text.as_bytes();
    let mut i = 1;
    while i < bytes.len() {
        match bytes[i] {
            b'\\' => i += 2,
            b'"' => return Some(i + 1),
            _ => i += 1,
        }
    }
    None
}

fn is_plain_key(key: &str) -> bool {
    !key.is_empty()
        && key
            .bytes()
            .all(|b| b.is_ascii_alphanumeric() || b == b'_' || b == b'-')
}

fn write_segment(f: &mut fmt::Formatter<'_>, segment: &PathSegment, first: bool) -> fmt::Result {
    match segment {
        PathSegment::Index(i) => write!(f, "[{i}]"),
        PathSegment::Key(k) if is_plain_key(k) => {
            if first {
                write!(f, "{k}")
            } else {
                write!(f, ".{k}")
            }
        }
        PathSegment::Key(k) => {
            let quoted = serde_json::to_string(k).map_err(|_| fmt::Error)?;
            write!(f, "[{quoted}]")
        }
    }
}

impl fmt::Display for FieldPath {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (n, segment) in self.0.iter().enumerate() {
            write_segment(f, segment, n == 0)?;
        }
        Ok(())
    }
}

/// The body a scene error is about: its index in scene order and its name (the scene file's
/// place of a body, not a view of a world's body, which is [`crate::BodyRef`]).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BodyLocation {
    /// Index of the body in scene order (`bodies[index]`).
    pub index: usize,
    /// The body's `name`, if it has one (and, for parse errors, if it could be read).
    pub name: Option<String>,
}

/// A place in a text: 1-based line and 1-based column (counted in characters).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub struct TextPosition {
    /// Line, from 1.
    pub line: u32,
    /// Column, from 1, in characters.
    pub column: u32,
}

impl TextPosition {
    /// A position from `usize` line and column (saturating at `u32::MAX`).
    pub fn new(line: usize, column: usize) -> Self {
        let clamp = |v: usize| u32::try_from(v).unwrap_or(u32::MAX);
        Self {
            line: clamp(line),
            column: clamp(column),
        }
    }
}

/// What went wrong, broadly.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SceneErrorKind {
    /// The file could not be read.
    Io,
    /// The text is not well-formed JSON, has trailing characters, or has a number beyond
    /// the f64 range (`1e999`).
    Syntax,
    /// Well-formed JSON that does not fit the scene format: unknown field, wrong type,
    /// missing field, unknown enum value.
    Structure,
    /// A value has the right type but cannot be simulated: found by
    /// [`validate`](crate::scene::validate).
    Invalid,
}

/// An error of loading, parsing or validating a scene.
///
/// Every part of the location is optional; what is known is shown, in the form
/// `origin:line:column: bodies[3] ("lid").shape.radius: must be > 0, got -0.5`.
/// Scenes built in code have no origin and no position; validating them gives
/// `bodies[3].shape.radius: must be > 0, got -0.5`.
#[derive(Clone, Debug, PartialEq, Eq, Error)]
#[error("{}", self.render())]
pub struct SceneError {
    /// Kind of error.
    pub kind: SceneErrorKind,
    /// What is wrong, without the location (e.g. `must be > 0, got -0.5`).
    pub message: String,
    /// The file (or other origin name given to the parser) the scene came from.
    pub origin: Option<String>,
    /// Line and column in the text: where the parser stopped for parse errors, where the
    /// offending value (or the closest enclosing value present in the text) starts for
    /// validation errors.
    pub position: Option<TextPosition>,
    /// The body concerned, if the error is inside `bodies[i]`.
    pub body: Option<BodyLocation>,
    /// Path of the offending value from the root of the scene (e.g. `bodies[3].shape.radius`,
    /// `dt`, `solver.iterations`). `None` when unknown (e.g. an unreadable file).
    pub field: Option<FieldPath>,
}

impl SceneError {
    /// An error without location, other than `field`.
    pub fn new(kind: SceneErrorKind, field: Option<FieldPath>, message: impl Into<String>) -> Self {
        Self {
            kind,
            message: message.into(),
            origin: None,
            position: None,
            body: None,
            field,
        }
    }

    /// The line (1-based), if known.
    pub fn line(&self) -> Option<usize> {
        self.position.map(|p| p.line as usize)
    }

    /// The column (1-based), if known.
    pub fn column(&self) -> Option<usize> {
        self.position.map(|p| p.column as usize)
    }

    /// Writes the field path with the body name after `bodies[i]`, e.g. `bodies[3] ("lid").shape`.
    fn write_field(&self, f: &mut fmt::Formatter<'_>, field: &FieldPath) -> fmt::Result {
        let name = self.body.as_ref().and_then(|b| b.name.as_ref());
        match (field.body_index(), name) {
            (Some(index), Some(name)) => {
                write!(f, "bodies[{index}] ({name:?})")?;
                for segment in &field.0[2..] {
                    write_segment(f, segment, false)?;
                }
                Ok(())
            }
            _ => write!(f, "{field}"),
        }
    }

    fn render(&self) -> Rendered<'_> {
        Rendered(self)
    }
}

/// Display helper for [`SceneError`].
struct Rendered<'a>(&'a SceneError);

impl fmt::Display for Rendered<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let e = self.0;
        let mut located = false;
        if let Some(origin) = &e.origin {
            write!(f, "{origin}")?;
            located = true;
        }
        if let Some(p) = e.position {
            if located {
                write!(f, ":")?;
            } else {
                write!(f, "line ")?;
            }
            write!(f, "{}:{}", p.line, p.column)?;
            located = true;
        }
        if located {
            write!(f, ": ")?;
        }
        match (&e.field, &e.body) {
            (Some(field), _) if !field.is_root() => {
                e.write_field(f, field)?;
                write!(f, ": ")?;
            }
            (_, Some(body)) => {
                write!(f, "bodies[{}]", body.index)?;
                if let Some(name) = &body.name {
                    write!(f, " ({name:?})")?;
                }
                write!(f, ": ")?;
            }
            _ => {}
        }
        write!(f, "{}", e.message)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn path_display_and_parse_round_trip() {
        for text in [
            "",
            "dt",
            "solver.iterations",
            "bodies[3].shape.radius",
            "bodies[12].shape.points[2][1]",
            "materials.heavy.density",
            "materials[\"my steel\"].friction",
        ] {
            let path = FieldPath::parse(text).unwrap();
            assert_eq!(path.to_string(), text);
        }
        assert_eq!(
            FieldPath::parse("bodies[3].shape.radius").unwrap(),
            FieldPath::body(3).key("shape").key("radius")
        );
        assert!(FieldPath::parse("bodies[x]").is_none());
        assert!(FieldPath::parse("a..b").is_none());
    }

    #[test]
    fn message_format() {
        let mut e = SceneError::new(
            SceneErrorKind::Invalid,
            Some(FieldPath::body(3).key("shape").key("radius")),
            "must be > 0, got -0.5",
        );
        assert_eq!(
            e.to_string(),
            "bodies[3].shape.radius: must be > 0, got -0.5"
        );
        e.body = Some(BodyLocation {
            index: 3,
            name: Some("lid".into()),
        });
        e.origin = Some("scenes/bad.json".into());
        e.position = Some(TextPosition::new(14, 23));
        assert_eq!(
            e.to_string(),
            "scenes/bad.json:14:23: bodies[3] (\"lid\").shape.radius: must be > 0, got -0.5"
        );
    }
}
