//! Triangle meshes read from files for `trimesh` shapes: Wavefront OBJ (with `tobj`) and
//! glTF 2.0, `.gltf` or `.glb` (with `gltf`).
//!
//! Every triangle of the file is kept, in the file's own units and axes (impulse works in
//! metres with y up, as glTF does): for OBJ every object and group, polygons split into
//! triangles; for glTF every triangle primitive (`TRIANGLES`, `TRIANGLE_STRIP`,
//! `TRIANGLE_FAN`) of every mesh reached from the default scene's nodes (or from every scene
//! when there is no default), with the nodes' transforms applied.

use std::path::Path;
use std::sync::Arc;

use glam::{Mat4, Vec3};
use thiserror::Error;

use super::degeneracy::{MeshProblem, mesh_problem};
pub use super::mesh_data::MeshData;

/// A mesh read from a `trimesh` shape's `file`, kept with the scene description so that
/// the world is built from what was read (not serialised: the scene keeps the file's name).
#[derive(Clone, PartialEq)]
pub struct LoadedMesh(pub Arc<MeshData>);

impl std::fmt::Debug for LoadedMesh {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "LoadedMesh({} vertices, {} triangles)",
            self.0.vertices.len(),
            self.0.indices.len()
        )
    }
}

/// Why a mesh file could not be used.
#[derive(Debug, Error)]
pub enum MeshFileError {
    /// The file (or a glTF buffer it refers to) cannot be read.
    #[error("cannot read {path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// The system's reason.
        source: std::io::Error,
    },
    /// The extension is none of `.obj`, `.gltf`, `.glb`.
    #[error(
        "{path}: unknown mesh file type; allowed: .obj (Wavefront OBJ), .gltf or .glb (glTF 2.0)"
    )]
    UnknownType {
        /// The file.
        path: String,
    },
    /// The file is not a valid OBJ or glTF file, or uses what is not supported.
    #[error("{path}: {message}")]
    Format {
        /// The file.
        path: String,
        /// What is wrong.
        message: String,
    },
    /// The file has no triangle (an OBJ file of only `l` lines or points has none).
    #[error("{path}: the file has no faces (triangles or polygons; lines and points have no area)")]
    Empty {
        /// The file.
        path: String,
    },
}

/// The format of a mesh file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MeshFormat {
    /// Wavefront OBJ (text).
    Obj,
    /// glTF 2.0: JSON (`.gltf`) or binary (`.glb`), told apart by the GLB magic.
    Gltf,
}

impl MeshFormat {
    /// The format of a file by its extension, any case: `.obj`, `.gltf` or `.glb`; `None`
    /// for any other.
    pub fn of_path(path: &Path) -> Option<Self> {
        let extension = path.extension()?.to_str()?.to_ascii_lowercase();
        match extension.as_str() {
            "obj" => Some(Self::Obj),
            "gltf" | "glb" => Some(Self::Gltf),
            _ => None,
        }
    }
}

/// Largest mesh file (or glTF buffer file) [`load_mesh_file`] reads: 256 MiB (268,435,456
/// bytes), as [`super::MAX_SCENE_FILE_BYTES`] for scenes. A 5-million-triangle OBJ is about
/// 200 MB; anything larger would exhaust memory in the decomposition first.
pub const MAX_MESH_FILE_BYTES: u64 = 256 << 20;

/// Reads the triangles of the OBJ, glTF or GLB file at `path` (by extension, any case). A glTF
/// file's buffers may be in its GLB chunk, in data URIs or in files beside it. A UTF-8 byte
/// order mark at the start of an OBJ or `.gltf` file is skipped.
///
/// # Errors
/// [`MeshFileError`]: unreadable file, not a regular file (a directory, a pipe, a device such
/// as `/dev/zero`) or larger than [`MAX_MESH_FILE_BYTES`] (both found from the file's
/// metadata, before reading), unknown extension, a malformed file (an OBJ error with the
/// file's line), or no triangle.
pub fn load_mesh_file(path: &Path) -> Result<MeshData, MeshFileError> {
    let name = path.display().to_string();
    let format =
        MeshFormat::of_path(path).ok_or(MeshFileError::UnknownType { path: name.clone() })?;
    let bytes = read(path, &name)?;
    let directory = path.parent().unwrap_or(Path::new("."));
    read_mesh_bytes(&bytes, format, &name, Some(directory))
}

/// Reads the triangles of a mesh file's contents `bytes` in `format`; `name` names the file in
/// errors. A glTF file's buffers in other files (relative URIs) are read from `directory`;
/// with `None` they are refused, so that only self-contained files (a GLB chunk, data URIs)
/// are read and no other file is touched.
///
/// # Errors
/// [`MeshFileError`]: a malformed file, a buffer that cannot be read, or no triangle.
pub fn read_mesh_bytes(
    bytes: &[u8],
    format: MeshFormat,
    name: &str,
    directory: Option<&Path>,
) -> Result<MeshData, MeshFileError> {
    let mesh = match format {
        MeshFormat::Obj => read_obj(without_bom(bytes), name)?,
        MeshFormat::Gltf => read_gltf(without_bom(bytes), name, directory)?,
    };
    if mesh.indices.is_empty() {
        return Err(MeshFileError::Empty {
            path: name.to_string(),
        });
    }
    Ok(mesh)
}

/// The bytes of the regular file at `path`, refused before reading when it is not a regular
/// file or is larger than [`MAX_MESH_FILE_BYTES`] (and read at most that far, should it grow).
fn read(path: &Path, name: &str) -> Result<Vec<u8>, MeshFileError> {
    use std::io::Read as _;
    let io = |source| MeshFileError::Io {
        path: name.to_string(),
        source,
    };
    let metadata = std::fs::metadata(path).map_err(io)?;
    if !metadata.is_file() {
        return Err(format_error(
            name,
            "not a regular file (a mesh is read from a file, not a directory, pipe or device)",
        ));
    }
    let too_large = |bytes: u64| {
        format_error(
            name,
            format!(
                "the file has {bytes} bytes, more than the {MAX_MESH_FILE_BYTES} bytes \
                 (256 MiB) a mesh file may have"
            ),
        )
    };
    if metadata.len() > MAX_MESH_FILE_BYTES {
        return Err(too_large(metadata.len()));
    }
    let mut bytes = Vec::with_capacity(metadata.len() as usize);
    std::fs::File::open(path)
        .and_then(|file| file.take(MAX_MESH_FILE_BYTES + 1).read_to_end(&mut bytes))
        .map_err(io)?;
    if bytes.len() as u64 > MAX_MESH_FILE_BYTES {
        return Err(too_large(bytes.len() as u64));
    }
    Ok(bytes)
}

/// `bytes` without a leading UTF-8 byte order mark.
fn without_bom(bytes: &[u8]) -> &[u8] {
    bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes)
}

fn format_error(name: &str, message: impl Into<String>) -> MeshFileError {
    MeshFileError::Format {
        path: name.to_string(),
        message: message.into(),
    }
}

fn read_obj(bytes: &[u8], name: &str) -> Result<MeshData, MeshFileError> {
    // Lines and points have no area: a file of only `l` lines has no faces.
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ignore_lines: true,
        ignore_points: true,
    };
    // Materials are not needed: a missing .mtl file must not fail the load.
    let (models, _) = tobj::load_obj_buf(&mut &bytes[..], &options, |_| Ok(Default::default()))
        .map_err(|e| {
            let at = match obj_error_line(bytes, e) {
                Some((line, text)) => format!(" at line {line} ({text:?})"),
                None => String::new(),
            };
            format_error(name, format!("not a valid OBJ file: {e}{at}"))
        })?;
    let mut mesh = MeshData::default();
    for model in models {
        let m = &model.mesh;
        let base = u32::try_from(mesh.vertices.len())
            .map_err(|_| format_error(name, "more than 2³² vertices"))?;
        let count = m.positions.len() / 3;
        mesh.vertices
            .extend(m.positions.chunks_exact(3).map(|p| [p[0], p[1], p[2]]));
        for t in m.indices.chunks_exact(3) {
            if t.iter().any(|&i| i as usize >= count) {
                return Err(format_error(
                    name,
                    format!(
                        "object {:?}: a face refers to a vertex beyond the {count} it has",
                        model.name
                    ),
                ));
            }
            mesh.indices.push([base + t[0], base + t[1], base + t[2]]);
        }
    }
    // A vertex or triangle the scene format refuses is named by the file's line too.
    let (at, message) = match mesh_problem(&mesh) {
        Some(MeshProblem::Vertex(_, message)) => (obj_line(bytes, ObjFault::Vertex), message),
        Some(MeshProblem::Triangle(triangle, message)) => {
            let corners = mesh.indices[triangle].map(|i| mesh.vertices[i as usize]);
            (obj_line(bytes, ObjFault::Face(corners)), message)
        }
        _ => return Ok(mesh),
    };
    let at = match at {
        Some((line, text)) => format!("line {line} ({text:?}): "),
        None => String::new(),
    };
    Err(format_error(name, format!("{at}{message}")))
}

/// What [`obj_line`] looks for.
enum ObjFault {
    /// A `v` line whose position is not finite.
    Vertex,
    /// An `f` line one of whose triangles (a fan from its first vertex, as the reader splits
    /// polygons) has these corners: the face a triangle of the mesh as read came from, found
    /// by its corners because the reader renumbers vertices and regroups faces by object.
    Face([[f32; 3]; 3]),
}

/// The first line of the OBJ text `bytes` with `fault` (1-based, with its text, at most 80
/// characters); `None` when no line has it.
fn obj_line(bytes: &[u8], fault: ObjFault) -> Option<(usize, String)> {
    let text = String::from_utf8_lossy(bytes);
    let mut positions: Vec<[f32; 3]> = Vec::new();
    for (number, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        let found = match (words.next(), &fault) {
            (Some("v"), _) => {
                let mut position = [0.0f32; 3];
                for x in &mut position {
                    *x = words.next().and_then(|w| w.parse().ok()).unwrap_or(0.0);
                }
                positions.push(position);
                matches!(fault, ObjFault::Vertex) && !position.iter().all(|x| x.is_finite())
            }
            (Some("f"), ObjFault::Face(corners)) => {
                // A face's vertex is the first number of each word, 1-based or negative
                // (counted back from the vertices read so far).
                let face: Option<Vec<[f32; 3]>> = words
                    .map(|word| {
                        let index: i64 = word.split('/').next()?.parse().ok()?;
                        let at = if index < 0 {
                            positions.len() as i64 + index
                        } else {
                            index - 1
                        };
                        positions.get(usize::try_from(at).ok()?).copied()
                    })
                    .collect();
                face.is_some_and(|face| {
                    (1..face.len().saturating_sub(1))
                        .any(|k| [face[0], face[k], face[k + 1]] == *corners)
                })
            }
            _ => false,
        };
        if found {
            return Some((number + 1, line.trim().chars().take(80).collect()));
        }
    }
    None
}

/// The first line of the OBJ text `bytes` (1-based, with its text, at most 80 characters)
/// that gives `error`, found by a scan that follows tobj's reading of each statement: tobj's
/// errors name no line. `None` when the error is not about one line.
fn obj_error_line(bytes: &[u8], error: tobj::LoadError) -> Option<(usize, String)> {
    use tobj::LoadError as E;
    let text = String::from_utf8_lossy(bytes);
    let floats = |words: &[&str], n: usize| {
        words.len() >= n && words[..n].iter().all(|w| w.parse::<f32>().is_ok())
    };
    // Totals of positions, texture coordinates and normals: faces may refer forward.
    let mut totals = [0usize; 3];
    for line in text.lines() {
        match line.split_whitespace().next() {
            Some("v") => totals[0] += 1,
            Some("vt") => totals[1] += 1,
            Some("vn") => totals[2] += 1,
            _ => {}
        }
    }
    let mut seen = [0usize; 3];
    for (number, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        let keyword = words.next();
        let words: Vec<&str> = words.collect();
        let bad = match keyword {
            Some("v") => {
                seen[0] += 1;
                let rest = words.get(3..).unwrap_or(&[]);
                match error {
                    E::PositionParseError => {
                        !floats(&words, 3) || (rest.len() == 1 && rest[0].parse::<f32>().is_err())
                    }
                    E::ScalingByZeroError => rest.len() == 1 && rest[0].parse() == Ok(0.0f32),
                    E::ColorParseError => rest.len() == 2 || rest.len() > 3,
                    _ => false,
                }
            }
            Some("vt") => {
                seen[1] += 1;
                error == E::TexcoordParseError && !floats(&words, 2)
            }
            Some("vn") => {
                seen[2] += 1;
                error == E::NormalParseError && !floats(&words, 3)
            }
            Some(keyword @ ("f" | "l")) => words.iter().any(|word| {
                word.split('/').enumerate().any(|(k, part)| {
                    if part.is_empty() {
                        return false;
                    }
                    let Ok(index) = part.parse::<isize>() else {
                        return error == E::FaceParseError;
                    };
                    if k > 2 {
                        return error == E::FaceParseError;
                    }
                    let kind = [
                        E::FaceVertexOutOfBounds,
                        E::FaceTexCoordOutOfBounds,
                        E::FaceNormalOutOfBounds,
                    ][k];
                    // As tobj resolves them: relative (negative) indices count back from
                    // what has been read so far; 0 is no element.
                    let resolved = if index < 0 {
                        seen[k] as isize + index
                    } else {
                        index - 1
                    };
                    keyword == "f"
                        && error == kind
                        && (resolved < 0 || resolved as usize >= totals[k])
                })
            }),
            _ => false,
        };
        if bad {
            return Some((number + 1, line.trim().chars().take(80).collect()));
        }
    }
    None
}

fn read_gltf(
    bytes: &[u8],
    name: &str,
    directory: Option<&Path>,
) -> Result<MeshData, MeshFileError> {
    let not_valid = |e: gltf::Error| format_error(name, format!("not a valid glTF file: {e}"));
    let document = gltf::Gltf::from_slice_without_validation(bytes).map_err(not_valid)?;
    validate_gltf(document.as_json()).map_err(not_valid)?;
    let mut buffers: Vec<Vec<u8>> = Vec::new();
    for buffer in document.buffers() {
        let data = match buffer.source() {
            gltf::buffer::Source::Bin => document
                .blob
                .clone()
                .ok_or_else(|| format_error(name, "buffer refers to a missing GLB binary chunk"))?,
            gltf::buffer::Source::Uri(uri) => {
                if let Some(rest) = uri.strip_prefix("data:") {
                    let (_, encoded) = rest.split_once(";base64,").ok_or_else(|| {
                        format_error(name, "a data URI buffer must be base64-encoded")
                    })?;
                    use base64::Engine as _;
                    base64::engine::general_purpose::STANDARD
                        .decode(encoded)
                        .map_err(|e| format_error(name, format!("bad base64 buffer: {e}")))?
                } else if uri.contains("://") {
                    return Err(format_error(
                        name,
                        format!(
                            "buffer {uri:?}: only files beside the glTF file and data URIs are read"
                        ),
                    ));
                } else if let Some(directory) = directory {
                    let buffer_path = directory.join(uri);
                    read(&buffer_path, &buffer_path.display().to_string())?
                } else {
                    return Err(format_error(
                        name,
                        format!("buffer {uri:?}: buffers in other files are not read here"),
                    ));
                }
            }
        };
        if data.len() < buffer.length() {
            return Err(format_error(
                name,
                format!(
                    "buffer {} holds {} bytes, the file says {}",
                    buffer.index(),
                    data.len(),
                    buffer.length()
                ),
            ));
        }
        buffers.push(data);
    }
    let mut mesh = MeshData::default();
    let mut origins = Vec::new();
    let scenes: Vec<gltf::Scene> = match document.default_scene() {
        Some(scene) => vec![scene],
        None => document.scenes().collect(),
    };
    for scene in scenes {
        for node in scene.nodes() {
            let mut into = (&mut mesh, &mut origins);
            add_node(&node, Mat4::IDENTITY, &buffers, &mut into, name, 0)?;
        }
    }
    // A vertex or triangle that the scene format refuses is named by the accessor and element
    // it came from, which is what a modelling tool's export can be searched for.
    match mesh_problem(&mesh) {
        Some(MeshProblem::Vertex(vertex, message)) => {
            let origin = PrimitiveOrigin::of(&origins, |o| o.first_vertex <= vertex);
            Err(format_error(
                name,
                format!(
                    "{}, POSITION accessor {} element {} (after the nodes' transforms): {message}",
                    origin.primitive_name(),
                    origin.positions,
                    vertex - origin.first_vertex
                ),
            ))
        }
        Some(MeshProblem::Triangle(triangle, message)) => {
            let origin = PrimitiveOrigin::of(&origins, |o| o.first_triangle <= triangle);
            let within = triangle - origin.first_triangle;
            let indices = match origin.indices {
                Some(accessor) => format!("indices accessor {accessor}"),
                None => "the implicit indices".to_string(),
            };
            Err(format_error(
                name,
                format!(
                    "{}, triangle {within} of the primitive ({indices}, POSITION accessor {}): \
                     {message}",
                    origin.primitive_name(),
                    origin.positions
                ),
            ))
        }
        _ => Ok(mesh),
    }
}

/// Where a glTF primitive's vertices and triangles went in the mesh read: the mesh and
/// primitive, their accessors, and the first vertex and triangle of the primitive in
/// [`MeshData`].
struct PrimitiveOrigin {
    mesh: usize,
    mesh_name: String,
    primitive: usize,
    positions: usize,
    indices: Option<usize>,
    first_vertex: usize,
    first_triangle: usize,
}

impl PrimitiveOrigin {
    /// The last of `origins` (in the order read) that `starts_at_or_before` the element, the
    /// one holding it. `origins` is not empty when the mesh has a vertex or triangle.
    fn of(origins: &[Self], starts_at_or_before: impl Fn(&Self) -> bool) -> &Self {
        let after = origins.partition_point(starts_at_or_before);
        &origins[after.saturating_sub(1)]
    }

    /// `mesh 2 ("Handle") primitive 0`.
    fn primitive_name(&self) -> String {
        format!(
            "mesh {} ({:?}) primitive {}",
            self.mesh, self.mesh_name, self.primitive
        )
    }
}

/// The glTF crate's own validation of a parsed document (what `Gltf::from_slice` runs), after
/// the one check it leaves too late: gltf-json 1.4's validation reads each primitive's
/// `POSITION` accessor before it checks that the accessor exists, and panics on an index out
/// of range (found by fuzzing), so that index is checked first.
fn validate_gltf(root: &gltf::json::Root) -> Result<(), gltf::Error> {
    use gltf::json::mesh::Semantic;
    use gltf::json::validation::{Checked, Error, Validate};
    let mut errors = Vec::new();
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            let position = primitive
                .attributes
                .get(&Checked::Valid(Semantic::Positions));
            if position.is_some_and(|index| index.value() >= root.accessors.len()) {
                let path = gltf::json::Path::new()
                    .field("meshes")
                    .index(m)
                    .field("primitives")
                    .index(p)
                    .field("attributes")
                    .key("POSITION");
                errors.push((path, Error::IndexOutOfBounds));
            }
        }
    }
    if errors.is_empty() {
        root.validate(root, gltf::json::Path::new, &mut |path, error| {
            errors.push((path(), error))
        });
    }
    if errors.is_empty() {
        Ok(())
    } else {
        Err(gltf::Error::Validation(errors))
    }
}

/// The accessor types the glTF specification requires of what is read: positions three
/// floats, indices unsigned integers. The glTF crate's readers assume them (an index accessor
/// of floats reaches an `unreachable!`, found by fuzzing) and its validation does not check
/// them.
fn check_accessor_types(primitive: &gltf::Primitive, name: &str) -> Result<(), MeshFileError> {
    use gltf::accessor::{DataType, Dimensions};
    if let Some(positions) = primitive.get(&gltf::Semantic::Positions)
        && (positions.data_type() != DataType::F32 || positions.dimensions() != Dimensions::Vec3)
    {
        return Err(format_error(
            name,
            format!(
                "accessor {}: POSITION must be VEC3 of FLOAT, got {:?} of {:?}",
                positions.index(),
                positions.dimensions(),
                positions.data_type()
            ),
        ));
    }
    if let Some(indices) = primitive.indices()
        && (!matches!(
            indices.data_type(),
            DataType::U8 | DataType::U16 | DataType::U32
        ) || indices.dimensions() != Dimensions::Scalar)
    {
        return Err(format_error(
            name,
            format!(
                "accessor {}: indices must be SCALAR of UNSIGNED_BYTE, UNSIGNED_SHORT or \
                 UNSIGNED_INT, got {:?} of {:?}",
                indices.index(),
                indices.dimensions(),
                indices.data_type()
            ),
        ));
    }
    Ok(())
}

/// Adds the triangles of `node` and its children, with `parent` the transform above it, to
/// `into`'s mesh, and where each primitive's went to its origins.
fn add_node(
    node: &gltf::Node,
    parent: Mat4,
    buffers: &[Vec<u8>],
    into: &mut (&mut MeshData, &mut Vec<PrimitiveOrigin>),
    name: &str,
    depth: usize,
) -> Result<(), MeshFileError> {
    // A valid glTF node tree is acyclic; the depth bound only guards against a malformed one.
    if depth > 1000 {
        return Err(format_error(
            name,
            "the node tree is deeper than 1000 levels",
        ));
    }
    let transform = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
    if let Some(node_mesh) = node.mesh() {
        for primitive in node_mesh.primitives() {
            check_accessor_types(&primitive, name)?;
            let reader = primitive.reader(|b| buffers.get(b.index()).map(Vec::as_slice));
            let Some(positions) = reader.read_positions() else {
                continue;
            };
            let positions: Vec<Vec3> = positions
                .map(|p| transform.transform_point3(Vec3::from(p)))
                .collect();
            let count = positions.len();
            let order: Vec<u32> = match reader.read_indices() {
                Some(indices) => indices.into_u32().collect(),
                None => (0..count as u32).collect(),
            };
            let triangles: Vec<[u32; 3]> = match primitive.mode() {
                gltf::mesh::Mode::Triangles => {
                    order.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect()
                }
                gltf::mesh::Mode::TriangleStrip => order
                    .windows(3)
                    .enumerate()
                    .map(|(k, t)| {
                        if k % 2 == 0 {
                            [t[0], t[1], t[2]]
                        } else {
                            [t[1], t[0], t[2]]
                        }
                    })
                    .collect(),
                gltf::mesh::Mode::TriangleFan => order
                    .windows(2)
                    .skip(1)
                    .map(|t| [order[0], t[0], t[1]])
                    .collect(),
                // Points and lines have no area to touch.
                _ => continue,
            };
            let (mesh, origins) = (&mut *into.0, &mut *into.1);
            let base = u32::try_from(mesh.vertices.len())
                .map_err(|_| format_error(name, "more than 2³² vertices"))?;
            for t in &triangles {
                if let Some(&index) = t.iter().find(|&&i| i as usize >= count) {
                    let accessor = match primitive.indices() {
                        Some(indices) => format!("accessor {}", indices.index()),
                        None => "the implicit indices".to_string(),
                    };
                    return Err(format_error(
                        name,
                        format!(
                            "mesh {} ({:?}) primitive {}: {accessor} has index {index}, beyond \
                             the {count} vertices of POSITION accessor {}",
                            node_mesh.index(),
                            node_mesh.name().unwrap_or(""),
                            primitive.index(),
                            primitive
                                .get(&gltf::Semantic::Positions)
                                .map_or(0, |a| a.index())
                        ),
                    ));
                }
            }
            origins.push(PrimitiveOrigin {
                mesh: node_mesh.index(),
                mesh_name: node_mesh.name().unwrap_or("").to_string(),
                primitive: primitive.index(),
                positions: primitive
                    .get(&gltf::Semantic::Positions)
                    .map_or(0, |a| a.index()),
                indices: primitive.indices().map(|a| a.index()),
                first_vertex: mesh.vertices.len(),
                first_triangle: mesh.indices.len(),
            });
            mesh.vertices.extend(positions.iter().map(|p| p.to_array()));
            mesh.indices
                .extend(triangles.iter().map(|t| t.map(|i| base + i)));
        }
    }
    for child in node.children() {
        add_node(&child, transform, buffers, into, name, depth + 1)?;
    }
    Ok(())
}
