//! Convex decomposition of triangle meshes, so that a concave mesh can move: a `trimesh`
//! shape on a dynamic or kinematic body is simulated as the compound of convex parts that
//! Parry's V-HACD finds (voxelise the solid, split it by planes until each piece is nearly
//! convex, then take the convex hull of the mesh's triangles in each piece).
//!
//! Mass, centre of mass and inertia come from the mesh's own solid when the mesh is closed
//! ([`super::mesh_mass`]: shells wound outward whatever the file's winding, cavities
//! subtracted, in f64), since the parts overlap and fill what the voxels could not resolve; an
//! open mesh (a hole, a dangling triangle) bounds no solid and gets the parts' mass properties
//! instead, with a note giving their volume and the convex hull's.
//!
//! V-HACD runs on one thread with no hashing or random choices, so a mesh and its parameters
//! give the same parts everywhere. Results are cached by content (the mesh's vertices and
//! triangles, the parameters and the V-HACD settings they make, compared in full): in memory
//! for the life of the process, so 500 bodies of one mesh decompose once, and in a directory
//! when one is set ([`set_decomposition_cache_dir`]), each file checked (magic, version,
//! CRC-32, key, parts) before it is trusted.

use std::collections::HashMap;
use std::hash::Hasher;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use glam::Vec3;
use parry3d::mass_properties::MassProperties;
use parry3d::math::Pose;
use parry3d::shape::SharedShape;
use parry3d::transformation::vhacd::{VHACD, VHACDParameters};
use serde::{Deserialize, Serialize};

use super::mesh_data::MeshData;
use super::mesh_mass::{MeshSolid, convex_hull_volume, mesh_solid};

/// Largest voxel resolution accepted: the work and memory grow with its cube.
pub const MAX_DECOMPOSITION_RESOLUTION: u32 = 512;

/// Most convex parts a decomposition may ask for: 65,536. V-HACD splits the voxels in two,
/// level after level, until it has `max_parts` pieces, and finds the depth by doubling a
/// 32-bit count, which never reaches a value above 2³¹ (the doubling wraps to 0 and V-HACD
/// loops forever); 65,536 parts of a mesh at the largest resolution are a few voxels each.
pub const MAX_DECOMPOSITION_PARTS: u32 = 1 << 16;

/// Most memory a decomposition may need, as [`decomposition_memory`] estimates it: 2 GiB.
/// A resolution that would need more for the mesh's bounding box is refused before V-HACD
/// runs, with the memory it would need and the largest resolution that fits.
pub const MAX_DECOMPOSITION_BYTES: u64 = 2 << 30;

/// Bytes per voxel of the grid V-HACD fills, an upper bound: its record of a voxel (32 bytes:
/// integer coordinates, a surface flag and a range of triangles) and the voxelisation's
/// one-byte grid, plus what splitting copies (docs/testing.md, "Decomposition limits", for the
/// measurement).
const BYTES_PER_VOXEL: u64 = 36;

/// The grid V-HACD voxelises `mesh` into at `resolution` (Parry's voxelisation: `resolution`
/// cells along the longest side of the bounding box, 2 + resolution·side/longest along the
/// others) and an upper bound of the memory it needs (bytes): `BYTES_PER_VOXEL` per cell.
pub fn decomposition_memory(mesh: &MeshData, resolution: u32) -> ([u64; 3], u64) {
    let mut low = [f64::INFINITY; 3];
    let mut high = [f64::NEG_INFINITY; 3];
    for v in &mesh.vertices {
        for (k, &x) in v.iter().enumerate() {
            low[k] = low[k].min(x as f64);
            high[k] = high[k].max(x as f64);
        }
    }
    let sides: [f64; 3] = std::array::from_fn(|k| (high[k] - low[k]).max(0.0));
    let longest = sides.iter().copied().fold(0.0, f64::max);
    let flat = longest.is_nan() || longest <= 0.0;
    let cells: [u64; 3] = std::array::from_fn(|k| {
        if flat || sides[k] == longest {
            resolution as u64
        } else {
            2 + (resolution as f64 * sides[k] / longest) as u64
        }
    });
    let bytes = cells.iter().product::<u64>() * BYTES_PER_VOXEL;
    (cells, bytes)
}

/// The problem of decomposing `mesh` at `resolution`, if its grid would need more than
/// [`MAX_DECOMPOSITION_BYTES`]: the message gives the grid, the memory and the largest
/// resolution that fits.
fn memory_problem(mesh: &MeshData, resolution: u32) -> Option<String> {
    let (cells, bytes) = decomposition_memory(mesh, resolution);
    if bytes <= MAX_DECOMPOSITION_BYTES {
        return None;
    }
    let fits = (8..resolution)
        .rev()
        .find(|&r| decomposition_memory(mesh, r).1 <= MAX_DECOMPOSITION_BYTES)
        .unwrap_or(8);
    Some(format!(
        "decomposition.resolution: {resolution} gives this mesh a grid of {} × {} × {} voxels, \
         which would need about {:.1} GB, over the {:.1} GB (2 GiB) a decomposition may \
         use; at most {fits} for this mesh",
        cells[0],
        cells[1],
        cells[2],
        bytes as f64 / 1e9,
        MAX_DECOMPOSITION_BYTES as f64 / 1e9
    ))
}

/// Parameters of a mesh's convex decomposition (the `decomposition` object of a `trimesh`
/// shape in a scene file). The defaults keep the holes of the usual objects: a ring's hole
/// and a mug's inside stay open at 64 voxels along the mesh's longest side.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct DecompositionDesc {
    /// Voxels along the longest side of the mesh's bounding box, 8 to
    /// [`MAX_DECOMPOSITION_RESOLUTION`]: a hole or wall thinner than about one voxel is lost.
    /// Default 64.
    pub resolution: u32,
    /// Largest concavity a part may keep, as a fraction of the mesh's bounding-box diagonal,
    /// in [0, 1]: smaller gives more, tighter parts. Default 0.01.
    pub concavity: f32,
    /// V-HACD's limit on convex parts, 1 to [`MAX_DECOMPOSITION_PARTS`]. Default 1024. Parry's
    /// V-HACD turns it into a depth of halving splits and does not merge parts back, so a mesh
    /// gets at most [`most_parts`]`(max_parts)` parts: twice the power of two at or above it
    /// (4 for 1, 2,048 for 1,024).
    pub max_parts: u32,
}

impl Default for DecompositionDesc {
    fn default() -> Self {
        let parry = VHACDParameters::default();
        Self {
            resolution: parry.resolution,
            concavity: parry.concavity,
            max_parts: parry.max_convex_hulls,
        }
    }
}

impl DecompositionDesc {
    /// The problems of the parameters as (field, message), e.g. `("resolution", "must be in
    /// [8, 512], got 4")`; empty when they are valid.
    pub fn problems(&self) -> Vec<(&'static str, String)> {
        let mut problems = Vec::new();
        if !(8..=MAX_DECOMPOSITION_RESOLUTION).contains(&self.resolution) {
            problems.push((
                "resolution",
                format!(
                    "must be in [8, {MAX_DECOMPOSITION_RESOLUTION}], got {}",
                    self.resolution
                ),
            ));
        }
        if !(self.concavity.is_finite() && (0.0..=1.0).contains(&self.concavity)) {
            problems.push((
                "concavity",
                format!("must be in [0, 1], got {}", self.concavity),
            ));
        }
        if self.max_parts == 0 {
            problems.push(("max_parts", "must be ≥ 1, got 0".to_string()));
        } else if self.max_parts > MAX_DECOMPOSITION_PARTS {
            problems.push((
                "max_parts",
                format!(
                    "must be ≤ {MAX_DECOMPOSITION_PARTS}, got {}",
                    self.max_parts
                ),
            ));
        }
        problems
    }

    fn vhacd_parameters(&self) -> VHACDParameters {
        VHACDParameters {
            resolution: self.resolution,
            concavity: self.concavity,
            max_convex_hulls: self.max_parts,
            ..VHACDParameters::default()
        }
    }
}

/// One convex part of a decomposed mesh: a closed convex triangle mesh in the body's frame.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ConvexPart {
    /// Vertex positions (m).
    pub vertices: Vec<[f32; 3]>,
    /// Triangles as indices into `vertices`, counter-clockwise seen from outside.
    pub indices: Vec<[u32; 3]>,
}

/// A mesh's convex decomposition, ready to give a moving body: the parts, the compound built
/// of them and the mass properties at density 1 kg/m³.
#[derive(Clone)]
pub struct DecomposedMesh {
    /// The convex parts, in V-HACD's order.
    pub parts: Vec<ConvexPart>,
    /// The parts as one Parry compound (each a `ConvexPolyhedron` at the identity pose).
    pub shape: SharedShape,
    /// Mass properties at density 1 kg/m³ (mass = volume in m³): the mesh's solid's when
    /// [`Self::open_edges`] is 0, else the parts'.
    pub unit_mass_properties: MassProperties,
    /// Edges of the mesh (vertices welded by position) not shared by exactly two triangles,
    /// or in a winding conflict (a shell that cannot be wound consistently); 0 for a closed
    /// mesh.
    pub open_edges: usize,
    /// What a user should know about the mass properties, if anything: an open mesh's (the
    /// parts' volume used, the convex hull's as the closed alternative) or overlapping shells'
    /// (their sum used, the parts' volume beside it: the union, and what the parts fill).
    pub mass_note: Option<String>,
}

impl std::fmt::Debug for DecomposedMesh {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "DecomposedMesh({} parts, {} open edges)",
            self.parts.len(),
            self.open_edges
        )
    }
}

impl DecomposedMesh {
    /// Whether the mesh is closed, so that its mass properties are its solid's.
    pub fn is_closed(&self) -> bool {
        self.open_edges == 0
    }

    /// What a user should know about this mesh's mass as a moving body, if anything
    /// ([`Self::mass_note`]).
    pub fn note(&self) -> Option<String> {
        self.mass_note.clone()
    }
}

/// The note for a moving body's open mesh: `open_edges` open edges, the parts' volume
/// `parts_volume` (m³) used, the convex hull's `hull_volume` (m³) the closed alternative.
pub fn open_mesh_note(open_edges: usize, parts_volume: f64, hull_volume: f64) -> String {
    format!(
        "the mesh is not closed ({open_edges} edges not shared by exactly two triangles, or \
         wound in conflict): its mass, centre of mass and inertia are those of its convex \
         parts, volume {parts_volume:.4e} m³; its convex hull, closed, has {hull_volume:.4e} \
         m³ (close the mesh, or give the body's mass)"
    )
}

/// The edges of `mesh` (vertices welded by exact position) that are not shared by exactly
/// two triangles: 0 for a closed mesh, whatever its winding.
pub fn open_edges(mesh: &MeshData) -> usize {
    super::mesh_mass::open_edge_count(mesh)
}

/// The convex decomposition of `mesh` with `parameters`, from the cache when this mesh was
/// decomposed with these parameters before (in this process, or in the cache directory).
///
/// The most convex parts a decomposition with `max_parts` gives ([`DecompositionDesc::max_parts`]):
/// Parry's V-HACD splits to the depth d with 2^(d−1) the power of two at or above
/// max(`max_parts`, 2), and does not merge parts back, so up to 2^d.
pub fn most_parts(max_parts: u32) -> u64 {
    2 * u64::from(max_parts.max(2)).next_power_of_two()
}

/// # Errors
/// A message when the parameters are invalid ([`DecompositionDesc::problems`]), the
/// resolution would need more memory than [`MAX_DECOMPOSITION_BYTES`] for this mesh (the
/// message gives it), or the mesh bounds no volume V-HACD can split into parts (flat, or no
/// triangle).
pub fn decompose_mesh(
    mesh: &MeshData,
    parameters: &DecompositionDesc,
) -> Result<Arc<DecomposedMesh>, String> {
    if let Some((field, message)) = parameters.problems().into_iter().next() {
        return Err(format!("decomposition.{field}: {message}"));
    }
    if let Some(message) = memory_problem(mesh, parameters.resolution) {
        return Err(message);
    }
    let key = CacheKey::new(mesh, parameters);
    let hash = key.hash();
    if let Some(found) = memory_lookup(hash, &key) {
        return Ok(found);
    }
    let directory = cache_directory();
    let parts = match directory
        .as_deref()
        .and_then(|d| disk_lookup(d, hash, &key))
    {
        Some(parts) => parts,
        None => {
            let parts = decompose_parts(mesh, parameters);
            if let Some(directory) = &directory {
                // A cache that cannot be written costs time, not correctness.
                let _ = disk_store(directory, hash, &key, &parts);
            }
            parts
        }
    };
    let decomposed = Arc::new(assemble(mesh, parts)?);
    memory_store(hash, key, decomposed.clone());
    Ok(decomposed)
}

/// Sets (or with `None` clears) the directory where decompositions are also kept between
/// processes, one file per mesh and parameters (`<hash>.vhacd`, CBOR). The directory is
/// created when the first decomposition is written. Applies to the whole process.
pub fn set_decomposition_cache_dir(directory: Option<PathBuf>) {
    *CACHE_DIRECTORY.lock().unwrap_or_else(|e| e.into_inner()) = directory;
}

/// V-HACD's parts of `mesh`, as closed convex triangle meshes.
fn decompose_parts(mesh: &MeshData, parameters: &DecompositionDesc) -> Vec<ConvexPart> {
    let vertices: Vec<Vec3> = mesh.vertices.iter().map(|v| Vec3::from(*v)).collect();
    let decomposition = VHACD::decompose(
        &parameters.vhacd_parameters(),
        &vertices,
        &mesh.indices,
        true,
    );
    decomposition
        .compute_exact_convex_hulls(&vertices, &mesh.indices)
        .into_iter()
        .map(|(vertices, indices)| ConvexPart {
            vertices: vertices.iter().map(|v| v.to_array()).collect(),
            indices,
        })
        .collect()
}

/// The compound and mass properties of `parts`, the decomposition of `mesh`.
fn assemble(mesh: &MeshData, parts: Vec<ConvexPart>) -> Result<DecomposedMesh, String> {
    let shapes: Vec<(Pose, SharedShape)> = parts
        .iter()
        .filter_map(|part| {
            let points = part.vertices.iter().map(|v| Vec3::from(*v)).collect();
            SharedShape::convex_mesh(points, &part.indices).map(|shape| (Pose::IDENTITY, shape))
        })
        .filter(|(_, shape)| shape.mass_properties(1.0).mass() > 0.0)
        .collect();
    if shapes.is_empty() {
        return Err(
            "the mesh bounds no volume to split into convex parts (is it flat?)".to_string(),
        );
    }
    let parts_properties = MassProperties::from_compound(1.0, &shapes);
    let parts_volume = parts_properties.mass() as f64;
    let (unit_mass_properties, open_edges, mass_note) = match mesh_solid(mesh) {
        MeshSolid::Closed {
            moments,
            overlapping,
            ..
        } => match moments.to_mass_properties() {
            Some(solid) => {
                let note = overlapping.first().map(|&(a, b)| {
                    format!(
                        "shells {a} and {b} of the mesh overlap ({} overlapping pairs): its \
                         mass properties are the sum of its shells', volume {:.4e} m³, which \
                         counts the overlap twice; its convex parts, which hold the union \
                         but also fill what the voxels cannot resolve, have \
                         {parts_volume:.4e} m³",
                        overlapping.len(),
                        moments.volume
                    )
                });
                (solid, 0, note)
            }
            // A closed mesh whose solid is degenerate (zero volume, e.g. two coincident
            // sheets) falls back to the parts.
            None => (
                parts_properties,
                0,
                Some(format!(
                    "the closed mesh bounds a volume of {:.4e} m³: its mass properties are \
                     its convex parts', volume {parts_volume:.4e} m³",
                    moments.volume
                )),
            ),
        },
        MeshSolid::Open { open_edges } => (
            parts_properties,
            open_edges,
            Some(open_mesh_note(
                open_edges,
                parts_volume,
                convex_hull_volume(mesh),
            )),
        ),
    };
    Ok(DecomposedMesh {
        parts,
        shape: SharedShape::compound(shapes),
        unit_mass_properties,
        open_edges,
        mass_note,
    })
}

/// What a decomposition depends on, compared in full on every cache hit: the mesh, the
/// parameters, and the V-HACD settings they make with impulse's version (`algorithm`), so
/// that a file written by another version or with other fixed settings is never taken.
#[derive(Clone, PartialEq, Serialize, Deserialize)]
struct CacheKey {
    vertices: Vec<[f32; 3]>,
    indices: Vec<[u32; 3]>,
    parameters: DecompositionDesc,
    algorithm: String,
}

impl CacheKey {
    fn new(mesh: &MeshData, parameters: &DecompositionDesc) -> CacheKey {
        CacheKey {
            vertices: mesh.vertices.clone(),
            indices: mesh.indices.clone(),
            parameters: parameters.clone(),
            algorithm: format!(
                "impulse {} {:?}",
                env!("CARGO_PKG_VERSION"),
                parameters.vhacd_parameters()
            ),
        }
    }
}

impl CacheKey {
    /// FNV-1a over the bits of every value: the same on every machine and build, so that it
    /// can name a file of the cache directory.
    fn hash(&self) -> u64 {
        let mut hasher = fnv::FnvHasher::default();
        hasher.write_u64(self.vertices.len() as u64);
        for v in &self.vertices {
            for x in v {
                hasher.write_u32(x.to_bits());
            }
        }
        hasher.write_u64(self.indices.len() as u64);
        for t in &self.indices {
            for i in t {
                hasher.write_u32(*i);
            }
        }
        let p = &self.parameters;
        hasher.write_u32(p.resolution);
        hasher.write_u32(p.concavity.to_bits());
        hasher.write_u32(p.max_parts);
        hasher.write(self.algorithm.as_bytes());
        hasher.finish()
    }
}

/// The process's decompositions by key hash (entries of one hash told apart by their keys).
type MemoryCache = HashMap<u64, Vec<(CacheKey, Arc<DecomposedMesh>)>>;

static MEMORY_CACHE: Mutex<Option<MemoryCache>> = Mutex::new(None);
static CACHE_DIRECTORY: Mutex<Option<PathBuf>> = Mutex::new(None);

fn cache_directory() -> Option<PathBuf> {
    CACHE_DIRECTORY
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .clone()
}

fn memory_lookup(hash: u64, key: &CacheKey) -> Option<Arc<DecomposedMesh>> {
    let cache = MEMORY_CACHE.lock().unwrap_or_else(|e| e.into_inner());
    cache
        .as_ref()?
        .get(&hash)?
        .iter()
        .find(|(k, _)| k == key)
        .map(|(_, found)| found.clone())
}

fn memory_store(hash: u64, key: CacheKey, decomposed: Arc<DecomposedMesh>) {
    let mut cache = MEMORY_CACHE.lock().unwrap_or_else(|e| e.into_inner());
    let entries = cache
        .get_or_insert_with(HashMap::new)
        .entry(hash)
        .or_default();
    if !entries.iter().any(|(k, _)| *k == key) {
        entries.push((key, decomposed));
    }
}

/// Version of the cache files' layout: 2 has the header with the checksum. A file of another
/// version is rebuilt.
const CACHE_FILE_VERSION: u32 = 2;

/// The first bytes of a cache file.
const CACHE_MAGIC: &[u8; 16] = b"IMPULSE-VHACD\0\0\0";

/// Length of a cache file's header: magic, version (u32), payload length (u64), CRC-32 (u32).
const CACHE_HEADER_LEN: usize = 32;

/// One file of the cache directory: the key it was made from and the parts (the payload).
#[derive(Serialize, Deserialize)]
struct CacheFile {
    version: u32,
    key: CacheKey,
    parts: Vec<ConvexPart>,
}

fn cache_file(directory: &Path, hash: u64) -> PathBuf {
    directory.join(format!("{hash:016x}.vhacd"))
}

/// Warnings of the decomposition cache not yet taken ([`take_decomposition_warnings`]).
static CACHE_WARNINGS: Mutex<Vec<String>> = Mutex::new(Vec::new());

/// The warnings of the decomposition cache since the last call, oldest first: each cache file
/// that was found damaged, of another version or inconsistent, and so rebuilt (the command
/// line prints them as `warning:` lines, the Python package as warnings).
pub fn take_decomposition_warnings() -> Vec<String> {
    std::mem::take(&mut *CACHE_WARNINGS.lock().unwrap_or_else(|e| e.into_inner()))
}

/// The parts stored for `key`, if its file exists and passes every check of
/// [`read_cache_file`]; a file that exists but fails one is reported
/// ([`take_decomposition_warnings`]) and rebuilt by the caller.
fn disk_lookup(directory: &Path, hash: u64, key: &CacheKey) -> Option<Vec<ConvexPart>> {
    let path = cache_file(directory, hash);
    let bytes = std::fs::read(&path).ok()?;
    match read_cache_file(&bytes, key) {
        Ok(parts) => Some(parts),
        Err(problem) => {
            CACHE_WARNINGS
                .lock()
                .unwrap_or_else(|e| e.into_inner())
                .push(format!(
                    "decomposition cache file {}: {problem}; decomposed again",
                    path.display()
                ));
            None
        }
    }
}

/// The parts a cache file's `bytes` hold for `key`, trusted only after every check: the
/// magic, the version, the payload's length and CRC-32, the CBOR, the key (compared in
/// full) and the parts themselves (finite vertices, indices in range: what Parry's convex
/// polyhedron assumes). Never panics, whatever the bytes.
fn read_cache_file(bytes: &[u8], key: &CacheKey) -> Result<Vec<ConvexPart>, String> {
    if bytes.len() < CACHE_HEADER_LEN || &bytes[..16] != CACHE_MAGIC {
        return Err("not a decomposition cache file (no header)".to_string());
    }
    let word = |range: std::ops::Range<usize>| -> u64 {
        bytes[range]
            .iter()
            .rev()
            .fold(0u64, |value, &byte| (value << 8) | byte as u64)
    };
    let version = word(16..20);
    if version != CACHE_FILE_VERSION as u64 {
        return Err(format!(
            "format version {version}, this build reads {CACHE_FILE_VERSION}"
        ));
    }
    let length = word(20..28);
    let expected = word(28..32) as u32;
    let payload = &bytes[CACHE_HEADER_LEN..];
    if payload.len() as u64 != length {
        return Err(format!(
            "the header gives a payload of {length} bytes, the file has {}",
            payload.len()
        ));
    }
    let checksum = crc32fast::hash(payload);
    if checksum != expected {
        return Err(format!(
            "checksum {checksum:08x}, the header says {expected:08x} (damaged)"
        ));
    }
    let file: CacheFile =
        ciborium::from_reader(payload).map_err(|e| format!("cannot decode: {e}"))?;
    if file.version != CACHE_FILE_VERSION {
        return Err(format!("the payload says format version {}", file.version));
    }
    if file.key != *key {
        return Err("made from another mesh or other parameters".to_string());
    }
    for (k, part) in file.parts.iter().enumerate() {
        if let Some(problem) = part_problem(part) {
            return Err(format!("part {k}: {problem}"));
        }
    }
    Ok(file.parts)
}

/// What makes `part` unsafe to build a convex polyhedron from, if anything: a non-finite
/// vertex or an index out of range. (A part without volume, which V-HACD itself may give, is
/// left out when the compound is assembled.)
fn part_problem(part: &ConvexPart) -> Option<String> {
    if let Some(v) = part
        .vertices
        .iter()
        .position(|v| !v.iter().all(|x| x.is_finite()))
    {
        return Some(format!("vertex {v} is not finite: {:?}", part.vertices[v]));
    }
    let count = part.vertices.len();
    if let Some(t) = part
        .indices
        .iter()
        .position(|t| t.iter().any(|&i| i as usize >= count))
    {
        return Some(format!(
            "triangle {t} {:?} refers beyond the {count} vertices",
            part.indices[t]
        ));
    }
    None
}

/// The cache file's bytes for `parts` of `key`: the 16-byte magic `IMPULSE-VHACD\0\0\0`, the
/// format version (u32), the payload's length in bytes (u64) and its CRC-32 (u32, IEEE), all
/// little-endian, then the payload ([`CacheFile`] in CBOR).
fn cache_file_bytes(key: &CacheKey, parts: &[ConvexPart]) -> std::io::Result<Vec<u8>> {
    let file = CacheFile {
        version: CACHE_FILE_VERSION,
        key: key.clone(),
        parts: parts.to_vec(),
    };
    let mut payload = Vec::new();
    ciborium::into_writer(&file, &mut payload).map_err(std::io::Error::other)?;
    let mut bytes = Vec::with_capacity(CACHE_HEADER_LEN + payload.len());
    bytes.extend_from_slice(CACHE_MAGIC);
    bytes.extend_from_slice(&CACHE_FILE_VERSION.to_le_bytes());
    bytes.extend_from_slice(&(payload.len() as u64).to_le_bytes());
    bytes.extend_from_slice(&crc32fast::hash(&payload).to_le_bytes());
    bytes.extend_from_slice(&payload);
    Ok(bytes)
}

/// Writes `parts` for `key`, through a temporary file renamed into place so that a reader
/// never sees half a file.
fn disk_store(
    directory: &Path,
    hash: u64,
    key: &CacheKey,
    parts: &[ConvexPart],
) -> std::io::Result<()> {
    std::fs::create_dir_all(directory)?;
    let bytes = cache_file_bytes(key, parts)?;
    let path = cache_file(directory, hash);
    let temporary = path.with_extension(format!("tmp{}", std::process::id()));
    std::fs::write(&temporary, bytes)?;
    std::fs::rename(&temporary, &path)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A closed axis-aligned box of half extents `h`, outward winding.
    fn closed_box(h: [f32; 3]) -> MeshData {
        let vertices = (0..8)
            .map(|i| {
                [
                    if i & 1 == 0 { -h[0] } else { h[0] },
                    if i & 2 == 0 { -h[1] } else { h[1] },
                    if i & 4 == 0 { -h[2] } else { h[2] },
                ]
            })
            .collect();
        let quads = [
            [0, 2, 3, 1],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 4, 6, 2],
            [1, 3, 7, 5],
        ];
        let indices = quads
            .iter()
            .flat_map(|[a, b, c, d]| [[*a, *b, *c], [*a, *c, *d]])
            .collect();
        MeshData { vertices, indices }
    }

    #[test]
    fn a_closed_box_has_no_open_edges_and_its_solid_mass() {
        let mesh = closed_box([0.5, 0.25, 0.125]);
        assert_eq!(open_edges(&mesh), 0);
        let decomposed = decompose_mesh(&mesh, &DecompositionDesc::default()).unwrap();
        assert!(decomposed.is_closed());
        let volume = 1.0 * 0.5 * 0.25;
        assert!((decomposed.unit_mass_properties.mass() - volume).abs() < 1e-6);
        // The same mesh and parameters: the very same decomposition from the cache.
        let again = decompose_mesh(&mesh, &DecompositionDesc::default()).unwrap();
        assert!(Arc::ptr_eq(&decomposed, &again));
    }

    #[test]
    fn a_box_without_its_lid_has_open_edges_and_a_note() {
        let mut mesh = closed_box([0.5, 0.5, 0.5]);
        // Remove the two triangles of the top face (+y: vertices 2, 3, 6, 7).
        mesh.indices.retain(|t| !t.iter().all(|i| i & 2 != 0));
        assert_eq!(open_edges(&mesh), 4);
        let decomposed = decompose_mesh(&mesh, &DecompositionDesc::default()).unwrap();
        assert!(decomposed.note().is_some());
    }

    #[test]
    fn invalid_parameters_are_named() {
        let parameters = DecompositionDesc {
            resolution: 4,
            concavity: 2.0,
            max_parts: 0,
        };
        let fields: Vec<&str> = parameters.problems().iter().map(|(f, _)| *f).collect();
        assert_eq!(fields, ["resolution", "concavity", "max_parts"]);
    }

    /// An L-shaped prism (concave): its decomposition depends on every parameter.
    fn l_prism() -> MeshData {
        let outline = [
            [0.0, 0.0],
            [2.0, 0.0],
            [2.0, 1.0],
            [1.0, 1.0],
            [1.0, 2.0],
            [0.0, 2.0f32],
        ];
        let n = outline.len() as u32;
        let mut vertices: Vec<[f32; 3]> = outline.iter().map(|p| [p[0], p[1], 0.0]).collect();
        vertices.extend(outline.iter().map(|p| [p[0], p[1], 0.5]));
        let mut indices = Vec::new();
        let fan = 3;
        for k in 1..n - 1 {
            let (a, b) = ((fan + k) % n, (fan + k + 1) % n);
            indices.push([n + fan, n + a, n + b]);
            indices.push([fan, b, a]);
        }
        for k in 0..n {
            let next = (k + 1) % n;
            indices.push([k, next, n + next]);
            indices.push([k, n + next, n + k]);
        }
        MeshData { vertices, indices }
    }

    /// Each parameter is part of the cache key: changing any one changes the key and its
    /// hash (the file name), and every decomposition taken through the cache is the one its
    /// own parameters give (a key that ignored `max_parts` would hand back the parts of
    /// `max_parts` 1 for 8).
    #[test]
    fn the_cache_key_holds_every_parameter() {
        let mesh = l_prism();
        let base = DecompositionDesc {
            resolution: 32,
            concavity: 0.001,
            max_parts: 8,
        };
        let variants = [
            base.clone(),
            DecompositionDesc {
                max_parts: 1,
                ..base.clone()
            },
            DecompositionDesc {
                resolution: 16,
                ..base.clone()
            },
            DecompositionDesc {
                concavity: 0.5,
                ..base.clone()
            },
        ];
        let base_key = CacheKey::new(&mesh, &base);
        for variant in &variants[1..] {
            let key = CacheKey::new(&mesh, variant);
            assert!(key != base_key, "{variant:?}");
            assert_ne!(key.hash(), base_key.hash(), "{variant:?}");
        }
        for variant in &variants {
            let cached = decompose_mesh(&mesh, variant).unwrap();
            assert_eq!(cached.parts, decompose_parts(&mesh, variant), "{variant:?}");
        }
        let one = decompose_mesh(&mesh, &variants[1]).unwrap();
        let several = decompose_mesh(&mesh, &variants[0]).unwrap();
        // `max_parts` changes the parts, so a key without it would hand back the wrong ones.
        assert_ne!(one.parts, several.parts);
        // On disk too: a file is found under its own key only.
        let directory = std::env::temp_dir().join(format!("impulse-key-{}", std::process::id()));
        let key = CacheKey::new(&mesh, &variants[0]);
        disk_store(&directory, key.hash(), &key, &several.parts).unwrap();
        assert_eq!(
            disk_lookup(&directory, key.hash(), &key).as_deref(),
            Some(&several.parts[..])
        );
        let other = CacheKey::new(&mesh, &variants[1]);
        assert_eq!(disk_lookup(&directory, key.hash(), &other), None);
        let _ = std::fs::remove_dir_all(&directory);
    }

    /// `max_parts` above [`MAX_DECOMPOSITION_PARTS`] (where V-HACD's doubling would wrap at
    /// 2³¹ + 1) and a resolution whose grid would need more than [`MAX_DECOMPOSITION_BYTES`]
    /// are refused, naming the field; the memory message gives the grid and a resolution
    /// that fits.
    #[test]
    fn parameters_that_would_hang_or_exhaust_memory_are_refused() {
        let too_many = DecompositionDesc {
            max_parts: 2_147_483_649,
            ..DecompositionDesc::default()
        };
        assert_eq!(
            too_many.problems(),
            [("max_parts", "must be ≤ 65536, got 2147483649".to_string())]
        );
        let cube = closed_box([0.5, 0.5, 0.5]);
        let fine = DecompositionDesc {
            resolution: 512,
            ..DecompositionDesc::default()
        };
        let message = decompose_mesh(&cube, &fine).unwrap_err();
        assert!(
            message.starts_with(
                "decomposition.resolution: 512 gives this mesh a grid of 512 × 512 × 512 voxels"
            ),
            "{message}"
        );
        let (_, bytes) = decomposition_memory(&cube, 512);
        assert_eq!(bytes, 512 * 512 * 512 * BYTES_PER_VOXEL);
        let fits: u32 = message
            .rsplit("at most ")
            .next()
            .unwrap()
            .split(' ')
            .next()
            .unwrap()
            .parse()
            .unwrap();
        assert!(decomposition_memory(&cube, fits).1 <= MAX_DECOMPOSITION_BYTES);
        assert!(decomposition_memory(&cube, fits + 1).1 > MAX_DECOMPOSITION_BYTES);
        // A flat slab's grid is thin: 512 fits.
        let slab = closed_box([0.5, 0.01, 0.5]);
        assert!(decomposition_memory(&slab, 512).1 <= MAX_DECOMPOSITION_BYTES);
    }

    /// A valid cache file for the closed box at the default parameters, and its key.
    fn good_cache_file() -> (Vec<u8>, CacheKey) {
        let mesh = closed_box([0.5, 0.25, 0.125]);
        let parameters = DecompositionDesc::default();
        let parts = decompose_mesh(&mesh, &parameters).unwrap().parts.clone();
        let key = CacheKey::new(&mesh, &parameters);
        (cache_file_bytes(&key, &parts).unwrap(), key)
    }

    /// `count` seeded damaged copies of a good cache file, half with the CRC-32 rewritten to
    /// match (so that the decoder and the part checks see the damage): 1 to 3 bytes changed,
    /// or the file cut. None may panic; each either is refused or reads to parts that
    /// assemble into a compound.
    fn damaged_cache_files(count: u64) -> (usize, usize) {
        use rand::{RngExt, SeedableRng};
        let (good, key) = good_cache_file();
        let mesh = closed_box([0.5, 0.25, 0.125]);
        assert!(read_cache_file(&good, &key).is_ok());
        let (mut refused, mut read) = (0, 0);
        for seed in 0..count {
            let mut generator = rand::rngs::ChaCha20Rng::seed_from_u64(seed);
            let mut bytes = good.clone();
            if generator.random_range(0..8) == 0 {
                bytes.truncate(generator.random_range(0..good.len()));
            } else {
                for _ in 0..generator.random_range(1..=3) {
                    let at = generator.random_range(0..bytes.len());
                    bytes[at] = generator.random();
                }
            }
            if !seed.is_multiple_of(2) && bytes.len() >= CACHE_HEADER_LEN {
                let checksum = crc32fast::hash(&bytes[CACHE_HEADER_LEN..]);
                bytes[28..32].copy_from_slice(&checksum.to_le_bytes());
            }
            match read_cache_file(&bytes, &key) {
                Err(_) => refused += 1,
                Ok(parts) => {
                    read += 1;
                    // What the caller does with parts it trusts.
                    let _ = assemble(&mesh, parts);
                }
            }
        }
        (refused, read)
    }

    #[test]
    fn damaged_cache_files_are_refused_or_read_never_panic() {
        let (refused, read) = damaged_cache_files(300);
        assert_eq!(refused + read, 300);
        assert!(refused > 0);
    }

    /// The long sweep of docs/testing.md: 1,000 damaged cache files.
    #[test]
    #[ignore]
    fn damaged_cache_files_sweep() {
        let (refused, read) = damaged_cache_files(1000);
        println!("1000 damaged cache files: {refused} refused, {read} read, 0 panics");
    }

    /// A cache file holding a NaN vertex (with a matching checksum) is refused, naming it.
    #[test]
    fn a_nan_vertex_in_the_cache_is_refused() {
        let (good, key) = good_cache_file();
        let mut file: CacheFile = ciborium::from_reader(&good[CACHE_HEADER_LEN..]).unwrap();
        file.parts[0].vertices[0][1] = f32::NAN;
        let bytes = cache_file_bytes(&key, &file.parts).unwrap();
        let problem = read_cache_file(&bytes, &key).unwrap_err();
        assert!(
            problem.contains("part 0: vertex 0 is not finite"),
            "{problem}"
        );
    }

    /// A seeded draw of decomposition parameters as a user might write them: one in ten of
    /// each field out of range (0, past the limit, `u32::MAX`, NaN, ±∞, negative), the rest
    /// log-uniform (resolution 8 to 128 voxels, concavity 10⁻⁶ to 1 or uniform in [0, 1],
    /// max_parts 1 to 65,536).
    fn drawn_parameters(generator: &mut rand::rngs::ChaCha20Rng) -> DecompositionDesc {
        use rand::RngExt;
        let mut log_uniform =
            |low: f64, high: f64| (low.ln() + generator.random::<f64>() * (high / low).ln()).exp();
        let resolution = log_uniform(8.0, 129.0) as u32;
        let concavity = log_uniform(1e-6, 1.0) as f32;
        let max_parts = log_uniform(1.0, 65_537.0) as u32;
        let mut parameters = DecompositionDesc {
            resolution,
            concavity: if generator.random() {
                concavity
            } else {
                generator.random()
            },
            max_parts,
        };
        if generator.random_range(0..10) == 0 {
            parameters.resolution = [0, 7, 513, u32::MAX][generator.random_range(0..4)];
        }
        if generator.random_range(0..10) == 0 {
            parameters.concavity = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, -0.01, 1.5]
                [generator.random_range(0..5)];
        }
        if generator.random_range(0..10) == 0 {
            parameters.max_parts =
                [0, 65_537, 2_147_483_649, u32::MAX][generator.random_range(0..4)];
        }
        parameters
    }

    /// `count` seeded parameter sets on the L-shaped prism: each is refused naming its field
    /// (or the memory it would need), or decomposes into 1 to [`most_parts`] convex parts
    /// with a positive volume. Returns (refused, decomposed, most parts).
    fn parameter_sweep(count: u64) -> (usize, usize, usize) {
        use rand::SeedableRng;
        let mesh = l_prism();
        let (mut refused, mut decomposed, mut most) = (0, 0, 0);
        for seed in 0..count {
            let mut generator = rand::rngs::ChaCha20Rng::seed_from_u64(0xDEC0 ^ seed);
            let parameters = drawn_parameters(&mut generator);
            match decompose_mesh(&mesh, &parameters) {
                Err(message) => {
                    assert!(
                        message.starts_with("decomposition."),
                        "seed {seed}, {parameters:?}: {message}"
                    );
                    assert!(
                        !parameters.problems().is_empty(),
                        "seed {seed}, {parameters:?} refused: {message}"
                    );
                    refused += 1;
                }
                Ok(found) => {
                    assert!(
                        parameters.problems().is_empty(),
                        "seed {seed}: {parameters:?}"
                    );
                    let parts = found.parts.len();
                    assert!(
                        (1..=most_parts(parameters.max_parts)).contains(&(parts as u64)),
                        "seed {seed}, {parameters:?}: {parts} parts"
                    );
                    assert!(found.unit_mass_properties.mass() > 0.0);
                    decomposed += 1;
                    most = most.max(parts);
                }
            }
        }
        (refused, decomposed, most)
    }

    #[test]
    fn drawn_parameters_are_refused_by_name_or_decompose() {
        let (refused, decomposed, _) = parameter_sweep(24);
        assert_eq!(refused + decomposed, 24);
        assert!(refused > 0 && decomposed > 0);
    }

    /// The long sweep of docs/testing.md: 1,000 parameter sets, none hangs or panics.
    #[test]
    #[ignore]
    fn drawn_parameters_sweep() {
        let start = std::time::Instant::now();
        let (refused, decomposed, most) = parameter_sweep(1000);
        println!(
            "1000 parameter sets: {refused} refused, {decomposed} decomposed (at most {most} \
             parts), 0 panics, {:.1} s",
            start.elapsed().as_secs_f64()
        );
    }
}
