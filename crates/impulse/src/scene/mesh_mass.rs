//! The solid a closed triangle mesh bounds, and its mass properties, whatever the winding of
//! its triangles and shells (docs/scene-format.md, "Mass of a mesh").
//!
//! The mesh is welded by exact vertex position and split into shells (triangles connected
//! through shared edges). It is closed when every edge is shared by exactly two triangles and
//! each shell can be wound consistently (orientable). Each shell is then wound consistently
//! (a breadth-first walk over shared edges) and outward (positive signed volume); a shell
//! inside an odd number of others is a cavity and counts negatively, one inside an even number
//! a solid. Volume, centre of mass and inertia are the signed-tetrahedron sums (the divergence
//! theorem over the triangles: Mirtich 1996; Kallay 2006 for the second moments), in f64 about
//! the bounding box's centre, so that meshes hundreds of kilometres across do not overflow f32.
//!
//! Shells that overlap without nesting (two interpenetrating cubes) bound the union of their
//! solids, which the sums count twice where they overlap: `MeshSolid`'s overlapping figures name
//! them so that the caller can warn.

use std::collections::HashMap;

use glam::{DMat3, DVec3, Mat3, Vec3};
use parry3d::mass_properties::MassProperties;

use super::mesh_data::MeshData;

/// Volume, centre of mass and inertia of a solid at density 1 kg/m³, in f64.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolidMoments {
    /// Volume (m³), = mass at density 1.
    pub volume: f64,
    /// Centre of mass (m, the mesh's frame).
    pub center: DVec3,
    /// Inertia tensor about the centre of mass at density 1 (kg·m², per kg/m³).
    pub inertia: DMat3,
}

impl SolidMoments {
    /// As Parry's f32 mass properties at density 1; `None` when a value is not finite in f32
    /// or the volume is not positive. Parry finds the principal axes in f32, whose squared
    /// tensor entries overflow past about 10¹⁹ kg·m² (a mesh some 10 km across): the tensor and
    /// volume are divided by the tensor's largest entry for that, and the mass set back after
    /// (inertia scales with the mass at a fixed distribution).
    pub fn to_mass_properties(&self) -> Option<MassProperties> {
        let mass = self.volume as f32;
        let center = self.center.as_vec3();
        let inertia: Mat3 = self.inertia.as_mat3();
        let finite = mass.is_finite()
            && mass > 0.0
            && center.is_finite()
            && inertia.to_cols_array().iter().all(|x| x.is_finite());
        if !finite {
            return None;
        }
        let largest = self
            .inertia
            .to_cols_array()
            .iter()
            .fold(0.0f64, |m, x| m.max(x.abs()));
        if largest <= 1.0e15 {
            return Some(MassProperties::with_inertia_matrix(center, mass, inertia));
        }
        let (volume, tensor) = (self.volume / largest, self.inertia / largest);
        let mut properties =
            MassProperties::with_inertia_matrix(center, volume as f32, tensor.as_mat3());
        properties.set_mass(mass, true);
        Some(properties)
    }
}

/// What a mesh bounds: a closed mesh's solid, or the count of its open edges.
#[derive(Clone, Debug, PartialEq)]
pub enum MeshSolid {
    /// Every edge shared by exactly two triangles and every shell orientable.
    Closed {
        /// The solid's moments: shells wound outward, cavities (inside an odd number of
        /// shells) subtracted.
        moments: SolidMoments,
        /// Number of shells.
        shells: usize,
        /// Number of shells that are cavities.
        cavities: usize,
        /// Triangles whose winding was turned to agree with their shell's outward winding.
        reversed_triangles: usize,
        /// Pairs of shells (indices in shell order) that overlap without one holding the
        /// other: their solids' union is less than `moments.volume`.
        overlapping: Vec<(usize, usize)>,
    },
    /// Not closed: `open_edges` edges (welded) are not shared by exactly two triangles, or a
    /// shell cannot be wound consistently (then `open_edges` counts its edges in conflict).
    Open {
        /// Edges not shared by exactly two triangles (or in a winding conflict).
        open_edges: usize,
    },
}

/// Welded vertex ids (by exact position, −0 and +0 equal) and the triangles that are not
/// degenerate in them.
fn welded(mesh: &MeshData) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let mut ids: HashMap<[u32; 3], u32> = HashMap::new();
    let mut points = Vec::new();
    let map: Vec<u32> = mesh
        .vertices
        .iter()
        .map(|v| {
            let key = v.map(|x| (x + 0.0).to_bits());
            *ids.entry(key).or_insert_with(|| {
                points.push(DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64));
                (points.len() - 1) as u32
            })
        })
        .collect();
    let triangles = mesh
        .indices
        .iter()
        .filter_map(|t| {
            let [a, b, c] = t.map(|i| map.get(i as usize).copied().unwrap_or(u32::MAX));
            let valid = a != u32::MAX && b != u32::MAX && c != u32::MAX;
            (valid && a != b && b != c && c != a).then_some([a, b, c])
        })
        .collect();
    (points, triangles)
}

/// The edges of `mesh` (welded by exact position) not shared by exactly two triangles: 0 for
/// a closed mesh, whatever the winding.
pub fn open_edge_count(mesh: &MeshData) -> usize {
    let (_, triangles) = welded(mesh);
    edge_triangles(&triangles)
        .values()
        .filter(|list| list.len() != 2)
        .count()
}

/// Each undirected edge (lower id first) with the triangles that have it.
fn edge_triangles(triangles: &[[u32; 3]]) -> HashMap<(u32, u32), Vec<u32>> {
    let mut edges: HashMap<(u32, u32), Vec<u32>> = HashMap::new();
    for (t, &[a, b, c]) in triangles.iter().enumerate() {
        for (p, q) in [(a, b), (b, c), (c, a)] {
            edges
                .entry((p.min(q), p.max(q)))
                .or_default()
                .push(t as u32);
        }
    }
    edges
}

/// Whether triangle `t` has the directed edge p → q.
fn has_directed(t: [u32; 3], p: u32, q: u32) -> bool {
    (t[0] == p && t[1] == q) || (t[1] == p && t[2] == q) || (t[2] == p && t[0] == q)
}

/// The solid `mesh` bounds ([`MeshSolid`]).
pub fn mesh_solid(mesh: &MeshData) -> MeshSolid {
    let (points, mut triangles) = welded(mesh);
    let edges = edge_triangles(&triangles);
    let open = edges.values().filter(|list| list.len() != 2).count();
    if open > 0 || triangles.is_empty() {
        return MeshSolid::Open {
            open_edges: open.max(usize::from(triangles.is_empty())),
        };
    }
    // Shells, each wound consistently from its first triangle.
    let count = triangles.len();
    let mut shell_of = vec![u32::MAX; count];
    let mut reversed = vec![false; count];
    let mut shells: Vec<Vec<u32>> = Vec::new();
    let mut conflicts = 0usize;
    for start in 0..count {
        if shell_of[start] != u32::MAX {
            continue;
        }
        let shell = shells.len() as u32;
        shell_of[start] = shell;
        let mut members = vec![start as u32];
        let mut next = 0;
        while next < members.len() {
            let t = members[next] as usize;
            next += 1;
            let [a, b, c] = triangles[t];
            // The triangle's edges as wound after its reversal.
            let wound = if reversed[t] {
                [(b, a), (c, b), (a, c)]
            } else {
                [(a, b), (b, c), (c, a)]
            };
            for (p, q) in wound {
                for &u in &edges[&(p.min(q), p.max(q))] {
                    let u = u as usize;
                    if u == t {
                        continue;
                    }
                    // A consistent neighbour runs the shared edge q → p.
                    let runs_same_way = has_directed(triangles[u], p, q);
                    if shell_of[u] == u32::MAX {
                        shell_of[u] = shell;
                        reversed[u] = runs_same_way;
                        members.push(u as u32);
                    } else if runs_same_way != reversed[u] {
                        conflicts += 1;
                    }
                }
            }
        }
        shells.push(members);
    }
    if conflicts > 0 {
        // Each conflicting edge is seen from both of its triangles.
        return MeshSolid::Open {
            open_edges: conflicts.div_ceil(2),
        };
    }
    for (t, triangle) in triangles.iter_mut().enumerate() {
        if reversed[t] {
            triangle.swap(1, 2);
        }
    }
    // About the bounding box's centre: the sums' terms stay near the mesh's own size.
    let (low, high) = points.iter().fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(low, high), p| (low.min(*p), high.max(*p)),
    );
    let origin = (low + high) * 0.5;
    let mut sums: Vec<Sums> = shells
        .iter()
        .map(|members| {
            let mut sums = Sums::default();
            for &t in members {
                let [a, b, c] = triangles[t as usize].map(|i| points[i as usize] - origin);
                sums.add(a, b, c);
            }
            sums
        })
        .collect();
    // Outward: a shell of negative signed volume is wound inward throughout.
    for (k, members) in shells.iter().enumerate() {
        if sums[k].volume < 0.0 {
            sums[k] = sums[k].negated();
            for &t in members {
                triangles[t as usize].swap(1, 2);
                reversed[t as usize] = !reversed[t as usize];
            }
        }
    }
    let reversed_triangles = reversed.iter().filter(|&&r| r).count();
    let nesting = Nesting::of(&points, &triangles, &shells);
    let mut total = Sums::default();
    for (k, shell_sums) in sums.iter().enumerate() {
        if nesting.depth[k].is_multiple_of(2) {
            total = total.plus(shell_sums);
        } else {
            total = total.plus(&shell_sums.negated());
        }
    }
    MeshSolid::Closed {
        moments: total.moments(origin),
        shells: shells.len(),
        cavities: nesting
            .depth
            .iter()
            .filter(|&&d| !d.is_multiple_of(2))
            .count(),
        reversed_triangles,
        overlapping: nesting.overlapping,
    }
}

/// Signed volume, first moments and second moments (∫x xᵀ dV) of tetrahedra from the origin.
#[derive(Clone, Copy, Debug)]
struct Sums {
    volume: f64,
    first: DVec3,
    second: DMat3,
}

/// All zero (glam's own default matrix is the identity).
impl Default for Sums {
    fn default() -> Self {
        Sums {
            volume: 0.0,
            first: DVec3::ZERO,
            second: DMat3::ZERO,
        }
    }
}

impl Sums {
    /// Adds the tetrahedron (0, a, b, c): det = a·(b × c) = 6·volume; ∫x dV = det/24·(a+b+c);
    /// ∫x xᵀ dV = det/120·(a aᵀ + b bᵀ + c cᵀ + s sᵀ), s = a + b + c.
    fn add(&mut self, a: DVec3, b: DVec3, c: DVec3) {
        let det = a.dot(b.cross(c));
        let s = a + b + c;
        let outer = |u: DVec3| DMat3::from_cols(u * u.x, u * u.y, u * u.z);
        self.volume += det / 6.0;
        self.first += s * (det / 24.0);
        self.second += (outer(a) + outer(b) + outer(c) + outer(s)) * (det / 120.0);
    }

    fn negated(&self) -> Sums {
        Sums {
            volume: -self.volume,
            first: -self.first,
            second: self.second * -1.0,
        }
    }

    fn plus(&self, other: &Sums) -> Sums {
        Sums {
            volume: self.volume + other.volume,
            first: self.first + other.first,
            second: self.second + other.second,
        }
    }

    /// The moments, the sums taken about `origin`.
    fn moments(&self, origin: DVec3) -> SolidMoments {
        let volume = self.volume;
        let center_local = if volume != 0.0 {
            self.first / volume
        } else {
            DVec3::ZERO
        };
        let c = center_local;
        let about_center = self.second - DMat3::from_cols(c * c.x, c * c.y, c * c.z) * volume;
        let trace = about_center.x_axis.x + about_center.y_axis.y + about_center.z_axis.z;
        let inertia = DMat3::from_diagonal(DVec3::splat(trace)) - about_center;
        SolidMoments {
            volume,
            center: origin + center_local,
            inertia,
        }
    }
}

/// How the shells of a closed mesh nest: each shell's depth (the number of shells it is
/// inside) and the pairs that overlap.
struct Nesting {
    depth: Vec<usize>,
    overlapping: Vec<(usize, usize)>,
}

/// Vertices of a shell tested against another shell: evenly spread over its vertex list.
const SAMPLES_PER_SHELL: usize = 16;

impl Nesting {
    /// A shell is inside another when all its sampled vertices are (generalised winding
    /// number above ½); some but not all inside is an overlap. Shells whose bounding boxes are
    /// apart are not tested.
    fn of(points: &[DVec3], triangles: &[[u32; 3]], shells: &[Vec<u32>]) -> Nesting {
        let n = shells.len();
        let mut depth = vec![0; n];
        let mut overlapping = Vec::new();
        if n < 2 {
            return Nesting { depth, overlapping };
        }
        let boxes: Vec<(DVec3, DVec3)> = shells
            .iter()
            .map(|members| {
                members.iter().flat_map(|&t| triangles[t as usize]).fold(
                    (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
                    |(low, high), i| (low.min(points[i as usize]), high.max(points[i as usize])),
                )
            })
            .collect();
        let samples: Vec<Vec<DVec3>> = shells
            .iter()
            .map(|members| {
                let mut vertices: Vec<u32> = members
                    .iter()
                    .flat_map(|&t| triangles[t as usize])
                    .collect();
                vertices.sort_unstable();
                vertices.dedup();
                let stride = vertices.len().div_ceil(SAMPLES_PER_SHELL).max(1);
                vertices
                    .iter()
                    .step_by(stride)
                    .map(|&i| points[i as usize])
                    .collect()
            })
            .collect();
        // inside[i][j]: the count of shell i's samples inside shell j.
        let count_inside = |i: usize, j: usize| {
            let (low, high) = boxes[j];
            let (other_low, other_high) = boxes[i];
            if i == j || other_high.cmplt(low).any() || other_low.cmpgt(high).any() {
                return 0;
            }
            samples[i]
                .iter()
                .filter(|p| {
                    p.cmpge(low).all()
                        && p.cmple(high).all()
                        && winding_number(**p, points, triangles, &shells[j]) > 0.5
                })
                .count()
        };
        let inside: Vec<Vec<usize>> = (0..n)
            .map(|i| (0..n).map(|j| count_inside(i, j)).collect())
            .collect();
        for (i, row) in inside.iter().enumerate() {
            for (j, &count) in row.iter().enumerate() {
                if i == j {
                    continue;
                }
                if count == samples[i].len() {
                    depth[i] += 1;
                } else if i < j
                    && (count > 0 || inside[j][i] > 0)
                    && inside[j][i] < samples[j].len()
                {
                    overlapping.push((i, j));
                }
            }
        }
        Nesting { depth, overlapping }
    }
}

/// The generalised winding number of the outward-wound closed shell `members` at `p`: 1
/// inside, 0 outside (the solid angles of its triangles seen from `p`, over 4π; van Oosterom
/// and Strackee 1983).
fn winding_number(p: DVec3, points: &[DVec3], triangles: &[[u32; 3]], members: &[u32]) -> f64 {
    let mut total = 0.0;
    for &t in members {
        let [a, b, c] = triangles[t as usize].map(|i| points[i as usize] - p);
        let (la, lb, lc) = (a.length(), b.length(), c.length());
        let numerator = a.dot(b.cross(c));
        let denominator = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
        total += 2.0 * numerator.atan2(denominator);
    }
    total / (4.0 * std::f64::consts::PI)
}

/// The volume of the convex hull of `mesh`'s vertices (m³), the closed alternative an open
/// mesh's note names; 0 when the vertices span no volume.
pub fn convex_hull_volume(mesh: &MeshData) -> f64 {
    let points: Vec<Vec3> = mesh
        .vertices
        .iter()
        .map(|v| Vec3::from(*v))
        .filter(|v| v.is_finite())
        .collect();
    if points.len() < 4 {
        return 0.0;
    }
    let Ok((vertices, indices)) = parry3d::transformation::try_convex_hull(&points) else {
        return 0.0;
    };
    let hull = MeshData {
        vertices: vertices.iter().map(|v| v.to_array()).collect(),
        indices,
    };
    match mesh_solid(&hull) {
        MeshSolid::Closed { moments, .. } => moments.volume.max(0.0),
        MeshSolid::Open { .. } => 0.0,
    }
}

#[cfg(test)]
#[path = "mesh_mass_tests.rs"]
mod tests;
