//! A triangle mesh as plain data, as scene files, mesh files and the library hand it over.

/// A triangle mesh as plain data: vertex positions (m, the body's frame) and triangles as
/// three indices into `vertices`, counter-clockwise seen from the side bodies touch.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MeshData {
    /// Vertex positions (m).
    pub vertices: Vec<[f32; 3]>,
    /// Triangles: indices into `vertices`.
    pub indices: Vec<[u32; 3]>,
}
