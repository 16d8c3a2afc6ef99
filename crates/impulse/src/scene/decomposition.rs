//! Convex decomposition of triangle meshes, so that a concave mesh can move: a `trimesh`
//! shape on a dynamic or kinematic body is simulated as the compound of convex parts that
//! Parry's V-HACD finds (voxelise the solid, split it by planes until each piece is nearly
//! convex, then take the convex hull of the mesh's triangles in each piece).
//!
//! Mass, centre of mass and inertia come from the mesh's own solid when the mesh is closed
//! (Parry's `MassProperties::from_trimesh`: the divergence theorem over the triangles), since
//! the parts overlap and fill what the voxels could not resolve; an open mesh (a hole, a
//! dangling triangle) bounds no solid and gets the parts' mass properties instead.
//!
//! V-HACD runs on one thread with no hashing or random choices, so a mesh and its parameters
//! give the same parts everywhere. Results are cached by content (the mesh's vertices and
//! triangles and the parameters, compared in full): in memory for the life of the process,
//! so 500 bodies of one mesh decompose once, and in a directory when one is set
//! ([`set_decomposition_cache_dir`]).

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

use super::mesh_file::MeshData;

/// Largest voxel resolution accepted: the work and memory grow with its cube.
pub const MAX_DECOMPOSITION_RESOLUTION: u32 = 512;

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
    /// Most convex parts, ≥ 1. Default 1024.
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
    /// Edges of the mesh (vertices welded by position) not shared by exactly two triangles
    /// of opposite winding; 0 for a closed mesh.
    pub open_edges: usize,
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

    /// What a user should know about this mesh as a moving body, if anything: that an open
    /// mesh takes the parts' mass properties ([`open_mesh_note`]).
    pub fn note(&self) -> Option<String> {
        (!self.is_closed()).then(|| open_mesh_note(self.open_edges))
    }
}

/// The note for a moving body's mesh with `open_edges` open edges ([`open_edges`]).
pub fn open_mesh_note(open_edges: usize) -> String {
    format!(
        "the mesh is not closed ({open_edges} edges without exactly one opposite neighbour): \
         its mass, centre of mass and inertia are those of its convex parts, which may \
         overlap or fill its openings"
    )
}

/// The edges of `mesh` (vertices welded by exact position) that are not shared by exactly
/// two triangles of opposite winding: 0 for a closed, consistently wound mesh.
pub fn open_edges(mesh: &MeshData) -> usize {
    let mut welded: HashMap<[u32; 3], u32> = HashMap::new();
    let ids: Vec<u32> = mesh
        .vertices
        .iter()
        .map(|v| {
            let next = welded.len() as u32;
            *welded.entry(v.map(f32::to_bits)).or_insert(next)
        })
        .collect();
    // Count of each directed edge.
    let mut directed: HashMap<(u32, u32), u32> = HashMap::new();
    for triangle in &mesh.indices {
        let [a, b, c] = triangle.map(|i| ids.get(i as usize).copied().unwrap_or(u32::MAX));
        for edge in [(a, b), (b, c), (c, a)] {
            *directed.entry(edge).or_default() += 1;
        }
    }
    directed
        .iter()
        .filter(|&(&(a, b), &count)| count != 1 || directed.get(&(b, a)) != Some(&1))
        .count()
}

/// The convex decomposition of `mesh` with `parameters`, from the cache when this mesh was
/// decomposed with these parameters before (in this process, or in the cache directory).
///
/// # Errors
/// A message when the parameters are invalid ([`DecompositionDesc::problems`]) or the mesh
/// bounds no volume V-HACD can split into parts (flat, or no triangle).
pub fn decompose_mesh(
    mesh: &MeshData,
    parameters: &DecompositionDesc,
) -> Result<Arc<DecomposedMesh>, String> {
    if let Some((field, message)) = parameters.problems().into_iter().next() {
        return Err(format!("decomposition.{field}: {message}"));
    }
    let key = CacheKey {
        vertices: mesh.vertices.clone(),
        indices: mesh.indices.clone(),
        parameters: parameters.clone(),
    };
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
    let open_edges = open_edges(mesh);
    let unit_mass_properties = if open_edges == 0 {
        let vertices: Vec<Vec3> = mesh.vertices.iter().map(|v| Vec3::from(*v)).collect();
        let solid = MassProperties::from_trimesh(1.0, &vertices, &mesh.indices);
        // A closed mesh whose solid is degenerate (zero volume, e.g. two coincident sheets)
        // falls back to the parts.
        if solid.mass() > 0.0 && solid.mass().is_finite() && solid.local_com.is_finite() {
            solid
        } else {
            parts_properties
        }
    } else {
        parts_properties
    };
    Ok(DecomposedMesh {
        parts,
        shape: SharedShape::compound(shapes),
        unit_mass_properties,
        open_edges,
    })
}

/// What a decomposition depends on, compared in full on every cache hit.
#[derive(Clone, PartialEq, Serialize, Deserialize)]
struct CacheKey {
    vertices: Vec<[f32; 3]>,
    indices: Vec<[u32; 3]>,
    parameters: DecompositionDesc,
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

/// Version of the cache files' layout; files of another version are ignored.
const CACHE_FILE_VERSION: u32 = 1;

/// One file of the cache directory: the key it was made from and the parts.
#[derive(Serialize, Deserialize)]
struct CacheFile {
    version: u32,
    key: CacheKey,
    parts: Vec<ConvexPart>,
}

fn cache_file(directory: &Path, hash: u64) -> PathBuf {
    directory.join(format!("{hash:016x}.vhacd"))
}

/// The parts stored for `key`, if its file exists, reads and holds this very key.
fn disk_lookup(directory: &Path, hash: u64, key: &CacheKey) -> Option<Vec<ConvexPart>> {
    let bytes = std::fs::read(cache_file(directory, hash)).ok()?;
    let file: CacheFile = ciborium::from_reader(bytes.as_slice()).ok()?;
    (file.version == CACHE_FILE_VERSION && file.key == *key).then_some(file.parts)
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
    let file = CacheFile {
        version: CACHE_FILE_VERSION,
        key: key.clone(),
        parts: parts.to_vec(),
    };
    let mut bytes = Vec::new();
    ciborium::into_writer(&file, &mut bytes).map_err(std::io::Error::other)?;
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
}
