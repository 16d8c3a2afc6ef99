//! What was derived from the last few triangle meshes, kept per thread: a scene of many bodies
//! of one mesh (a pour of hundreds of mugs) is checked and built body by body, and each check
//! (validation, building the world, the mass notes) would otherwise build the same Parry
//! triangle mesh (its BVH and pseudo-normals) and the same convex hull again for every body.
//! Entries are told apart by the meshes' full content, bit for bit, so a result is the one a
//! fresh derivation gives; at most [`RECENT_MESHES`] are kept, the oldest dropped first, so the
//! memory held is bounded whatever a process loads.

use std::cell::RefCell;
use std::collections::VecDeque;

use parry3d::shape::SharedShape;

use super::mesh_data::MeshData;

/// How many meshes' results each thread keeps.
pub(crate) const RECENT_MESHES: usize = 4;

/// A mesh's vertices and triangles with how its shape is built (`two_sided`).
struct MeshKey {
    mesh: MeshData,
    two_sided: bool,
}

impl MeshKey {
    /// Whether `mesh` with `two_sided` is this key's, every vertex coordinate bit for bit.
    fn is(&self, mesh: &MeshData, two_sided: bool) -> bool {
        self.two_sided == two_sided
            && self.mesh.indices == mesh.indices
            && same_vertices(&self.mesh.vertices, &mesh.vertices)
    }
}

fn same_vertices(a: &[[f32; 3]], b: &[[f32; 3]]) -> bool {
    a.len() == b.len()
        && a.iter()
            .zip(b)
            .all(|(p, q)| p.map(f32::to_bits) == q.map(f32::to_bits))
}

/// The last few meshes' results, newest last.
struct Recent<K, V> {
    entries: VecDeque<(K, V)>,
}

impl<K, V: Clone> Recent<K, V> {
    const fn new() -> Self {
        Recent {
            entries: VecDeque::new(),
        }
    }

    /// The value kept for the key `is` accepts, else `make`'s, kept (an error is not).
    fn get_or_make<E>(
        &mut self,
        is: impl Fn(&K) -> bool,
        key: impl FnOnce() -> K,
        make: impl FnOnce() -> Result<V, E>,
    ) -> Result<V, E> {
        if let Some((_, value)) = self.entries.iter().find(|(k, _)| is(k)) {
            return Ok(value.clone());
        }
        let value = make()?;
        if self.entries.len() == RECENT_MESHES {
            self.entries.pop_front();
        }
        self.entries.push_back((key(), value.clone()));
        Ok(value)
    }
}

thread_local! {
    static TRIANGLE_MESHES: RefCell<Recent<MeshKey, SharedShape>> =
        const { RefCell::new(Recent::new()) };
    static HULL_CHECKS: RefCell<Recent<Vec<[f32; 3]>, Option<&'static str>>> =
        const { RefCell::new(Recent::new()) };
}

/// The Parry triangle mesh of `mesh` built by `build` (with `two_sided`), or the one built
/// for the same mesh lately on this thread (the same `Arc`: shapes are immutable).
///
/// # Errors
/// `build`'s, which are not kept.
pub(crate) fn triangle_mesh<E>(
    mesh: &MeshData,
    two_sided: bool,
    build: impl FnOnce() -> Result<SharedShape, E>,
) -> Result<SharedShape, E> {
    TRIANGLE_MESHES.with_borrow_mut(|recent| {
        recent.get_or_make(
            |key| key.is(mesh, two_sided),
            || MeshKey {
                mesh: mesh.clone(),
                two_sided,
            },
            build,
        )
    })
}

/// `check`'s verdict on the convex hull of `vertices`, or the one given for the same vertices
/// lately on this thread.
pub(crate) fn hull_check(
    vertices: &[[f32; 3]],
    check: impl FnOnce(&[[f32; 3]]) -> Option<&'static str>,
) -> Option<&'static str> {
    HULL_CHECKS.with_borrow_mut(|recent| {
        let Ok(verdict) = recent.get_or_make::<std::convert::Infallible>(
            |key| same_vertices(key, vertices),
            || vertices.to_vec(),
            || Ok(check(vertices)),
        );
        verdict
    })
}

#[cfg(test)]
mod tests {
    use super::{RECENT_MESHES, hull_check, triangle_mesh};
    use crate::scene::mesh_data::MeshData;
    use parry3d::shape::SharedShape;
    use std::cell::Cell;
    use std::convert::Infallible;

    fn tetrahedron(scale: f32) -> MeshData {
        MeshData {
            vertices: vec![
                [0.0, 0.0, 0.0],
                [scale, 0.0, 0.0],
                [0.0, scale, 0.0],
                [0.0, 0.0, scale],
            ],
            indices: vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
        }
    }

    fn build(mesh: &MeshData, builds: &Cell<usize>) -> Result<SharedShape, Infallible> {
        builds.set(builds.get() + 1);
        let vertices = mesh.vertices.iter().map(|&v| v.into()).collect();
        Ok(SharedShape::trimesh(vertices, mesh.indices.clone()).unwrap())
    }

    /// A mesh built lately is built once and shared; another mesh, another winding flag, a
    /// vertex that differs only in the sign of a zero, or a mesh pushed out by
    /// `RECENT_MESHES` newer ones is built again.
    #[test]
    fn a_recent_mesh_is_built_once_and_any_other_again() {
        let builds = Cell::new(0);
        let mesh = tetrahedron(1.0);
        let first = triangle_mesh(&mesh, false, || build(&mesh, &builds)).unwrap();
        let again = triangle_mesh(&mesh.clone(), false, || build(&mesh, &builds)).unwrap();
        assert_eq!(builds.get(), 1);
        assert!(std::sync::Arc::ptr_eq(&first.0, &again.0));
        triangle_mesh(&mesh, true, || build(&mesh, &builds)).unwrap();
        assert_eq!(builds.get(), 2, "two-sided is another shape");
        let mut signed = mesh.clone();
        signed.vertices[0] = [-0.0, 0.0, 0.0];
        triangle_mesh(&signed, false, || build(&signed, &builds)).unwrap();
        assert_eq!(builds.get(), 3, "-0 is not +0 bit for bit");
        for k in 0..RECENT_MESHES {
            let other = tetrahedron(2.0 + k as f32);
            triangle_mesh(&other, false, || build(&other, &builds)).unwrap();
        }
        let before = builds.get();
        triangle_mesh(&mesh, false, || build(&mesh, &builds)).unwrap();
        assert_eq!(builds.get(), before + 1, "pushed out by newer meshes");
    }

    /// An error is returned and not kept: the next call builds again.
    #[test]
    fn a_failed_build_is_not_kept() {
        let mesh = tetrahedron(3.5);
        let failed: Result<SharedShape, &str> = triangle_mesh(&mesh, false, || Err("no"));
        assert_eq!(failed.err(), Some("no"));
        let builds = Cell::new(0);
        triangle_mesh(&mesh, false, || build(&mesh, &builds)).unwrap();
        assert_eq!(builds.get(), 1);
    }

    /// The hull check runs once for vertices checked lately, and gives what it gave.
    #[test]
    fn a_recent_hull_check_is_not_run_again() {
        let runs = Cell::new(0);
        let check = |_: &[[f32; 3]]| {
            runs.set(runs.get() + 1);
            Some("coplanar")
        };
        let vertices = tetrahedron(7.0).vertices;
        assert_eq!(hull_check(&vertices, check), Some("coplanar"));
        assert_eq!(hull_check(&vertices, check), Some("coplanar"));
        assert_eq!(runs.get(), 1);
    }
}
