//! Unit tests of `mesh_mass`: seeded families of closed meshes (boxes, hollow boxes, L-shaped
//! prisms, tori), each shell and each triangle wound either way, turned and moved, against their
//! closed-form volume, centre of mass and inertia within 0.5 %.

use glam::{DMat3, DQuat, DVec3};
use rand::rngs::ChaCha20Rng;
use rand::{RngExt, SeedableRng};

use super::*;

/// Meshes per family in the default suite.
const CASES: u64 = 60;

/// A solid's closed form: volume, centre, inertia about the centre (density 1).
#[derive(Clone, Copy, Debug)]
struct Expected {
    volume: f64,
    center: DVec3,
    inertia: DMat3,
}

impl Expected {
    /// An axis-aligned box of half extents `h` centred at `center`.
    fn cuboid(center: DVec3, h: DVec3) -> Expected {
        let volume = 8.0 * h.x * h.y * h.z;
        let diagonal = DVec3::new(
            h.y * h.y + h.z * h.z,
            h.x * h.x + h.z * h.z,
            h.x * h.x + h.y * h.y,
        );
        Expected {
            volume,
            center,
            inertia: DMat3::from_diagonal(diagonal * (volume / 3.0)),
        }
    }

    /// The solid of `self` with `other` added (`sign` 1) or cut out (`sign` −1): volumes and
    /// first moments add, inertias move to the new centre by the parallel-axis theorem.
    fn combined(self, other: Expected, sign: f64) -> Expected {
        let volume = self.volume + sign * other.volume;
        let center = (self.center * self.volume + other.center * other.volume * sign) / volume;
        let shifted = |e: Expected| {
            let r = e.center - center;
            e.inertia + (DMat3::from_diagonal(DVec3::splat(r.dot(r))) - outer(r)) * e.volume
        };
        Expected {
            volume,
            center,
            inertia: shifted(self) + shifted(other) * sign,
        }
    }

    /// Turned by `rotation` about the origin, then moved by `offset`.
    fn moved(self, rotation: DQuat, offset: DVec3) -> Expected {
        let r = DMat3::from_quat(rotation);
        Expected {
            volume: self.volume,
            center: rotation * self.center + offset,
            inertia: r * self.inertia * r.transpose(),
        }
    }
}

fn outer(u: DVec3) -> DMat3 {
    DMat3::from_cols(u * u.x, u * u.y, u * u.z)
}

/// The closed, outward-wound box of half extents `h` about `center`, as (vertices, triangles).
fn box_shell(center: DVec3, h: DVec3) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let vertices = (0..8)
        .map(|i| {
            center
                + DVec3::new(
                    if i & 1 == 0 { -h.x } else { h.x },
                    if i & 2 == 0 { -h.y } else { h.y },
                    if i & 4 == 0 { -h.z } else { h.z },
                )
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
    let triangles = quads
        .iter()
        .flat_map(|[a, b, c, d]| [[*a, *b, *c], [*a, *c, *d]])
        .collect();
    (vertices, triangles)
}

/// The prism of the counter-clockwise polygon `outline` (x, y), fanned from its vertex
/// `fan_from` (which must see every other), from z = 0 to z = `depth`, outward-wound.
fn prism_shell(outline: &[[f64; 2]], fan_from: usize, depth: f64) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let n = outline.len() as u32;
    let mut vertices: Vec<DVec3> = outline
        .iter()
        .map(|p| DVec3::new(p[0], p[1], 0.0))
        .collect();
    vertices.extend(outline.iter().map(|p| DVec3::new(p[0], p[1], depth)));
    let mut triangles = Vec::new();
    let f = fan_from as u32;
    for k in 1..n - 1 {
        let (a, b) = ((f + k) % n, (f + k + 1) % n);
        triangles.push([n + f, n + a, n + b]); // top, counter-clockwise seen from +z
        triangles.push([f, b, a]); // bottom, seen from −z
    }
    for k in 0..n {
        let next = (k + 1) % n;
        triangles.push([k, next, n + next]);
        triangles.push([k, n + next, n + k]);
    }
    (vertices, triangles)
}

/// The shells as one mesh, turned and moved, each shell wound backwards with probability ½
/// and then each triangle with probability `flip_triangle`.
fn assemble(
    shells: &[(Vec<DVec3>, Vec<[u32; 3]>)],
    rotation: DQuat,
    offset: DVec3,
    flip_triangle: f64,
    generator: &mut ChaCha20Rng,
) -> MeshData {
    let mut mesh = MeshData::default();
    for (vertices, triangles) in shells {
        let base = mesh.vertices.len() as u32;
        mesh.vertices.extend(
            vertices
                .iter()
                .map(|v| (rotation * *v + offset).as_vec3().to_array()),
        );
        let shell_backwards = generator.random::<bool>();
        for t in triangles {
            let mut t = t.map(|i| base + i);
            if shell_backwards != (generator.random::<f64>() < flip_triangle) {
                t.swap(1, 2);
            }
            mesh.indices.push(t);
        }
    }
    mesh
}

/// Asserts that the solid of `mesh` is `expected` within 0.5 % (the centre within 0.5 % of
/// the solid's size, the inertia within 0.5 % of its largest entry).
fn assert_close(mesh: &MeshData, expected: Expected, size: f64, what: &str) {
    let MeshSolid::Closed { moments, .. } = mesh_solid(mesh) else {
        panic!("{what}: not closed");
    };
    let tolerance = 5e-3;
    assert!(
        (moments.volume - expected.volume).abs() <= tolerance * expected.volume,
        "{what}: volume {} expected {}",
        moments.volume,
        expected.volume
    );
    assert!(
        (moments.center - expected.center).length() <= tolerance * size,
        "{what}: centre {} expected {}",
        moments.center,
        expected.center
    );
    let scale = expected
        .inertia
        .to_cols_array()
        .iter()
        .fold(0.0f64, |m, x| m.max(x.abs()));
    let error = (moments.inertia - expected.inertia)
        .to_cols_array()
        .iter()
        .fold(0.0f64, |m, x| m.max(x.abs()));
    assert!(
        error <= tolerance * scale,
        "{what}: inertia {:?} expected {:?}",
        moments.inertia,
        expected.inertia
    );
}

fn random_pose(generator: &mut ChaCha20Rng) -> (DQuat, DVec3) {
    let axis = DVec3::new(
        generator.random::<f64>() - 0.5,
        generator.random::<f64>() - 0.5,
        generator.random::<f64>() - 0.5,
    )
    .try_normalize()
    .unwrap_or(DVec3::Y);
    let rotation = DQuat::from_axis_angle(axis, generator.random::<f64>() * std::f64::consts::TAU);
    let offset = DVec3::new(
        generator.random::<f64>() * 4.0 - 2.0,
        generator.random::<f64>() * 4.0 - 2.0,
        generator.random::<f64>() * 4.0 - 2.0,
    );
    (rotation, offset)
}

fn half_extents(generator: &mut ChaCha20Rng, low: f64, high: f64) -> DVec3 {
    DVec3::new(
        low + generator.random::<f64>() * (high - low),
        low + generator.random::<f64>() * (high - low),
        low + generator.random::<f64>() * (high - low),
    )
}

#[test]
fn boxes_wound_any_way_have_their_closed_form() {
    for seed in 0..CASES {
        let mut generator = ChaCha20Rng::seed_from_u64(seed);
        let h = half_extents(&mut generator, 0.05, 1.0);
        let (rotation, offset) = random_pose(&mut generator);
        let flip = [0.0, 0.3, 1.0][seed as usize % 3];
        let mesh = assemble(
            &[box_shell(DVec3::ZERO, h)],
            rotation,
            offset,
            flip,
            &mut generator,
        );
        let expected = Expected::cuboid(DVec3::ZERO, h).moved(rotation, offset);
        assert_close(&mesh, expected, h.length(), &format!("box seed {seed}"));
    }
}

/// A box with a box-shaped cavity off its centre: the inner shell counts negatively whichever
/// way either shell is wound.
#[test]
fn hollow_boxes_wound_any_way_subtract_their_cavity() {
    for seed in 0..CASES {
        let mut generator = ChaCha20Rng::seed_from_u64(1000 + seed);
        let outer_h = half_extents(&mut generator, 0.5, 1.0);
        let inner_h = outer_h * (0.3 + 0.3 * generator.random::<f64>());
        let room = outer_h - inner_h;
        let inner_center = DVec3::new(
            room.x * (generator.random::<f64>() - 0.5),
            room.y * (generator.random::<f64>() - 0.5),
            room.z * (generator.random::<f64>() - 0.5),
        );
        let (rotation, offset) = random_pose(&mut generator);
        let mesh = assemble(
            &[
                box_shell(DVec3::ZERO, outer_h),
                box_shell(inner_center, inner_h),
            ],
            rotation,
            offset,
            if seed.is_multiple_of(2) { 0.0 } else { 0.25 },
            &mut generator,
        );
        let expected = Expected::cuboid(DVec3::ZERO, outer_h)
            .combined(Expected::cuboid(inner_center, inner_h), -1.0)
            .moved(rotation, offset);
        assert_close(
            &mesh,
            expected,
            outer_h.length(),
            &format!("hollow box seed {seed}"),
        );
        let MeshSolid::Closed {
            cavities,
            overlapping,
            ..
        } = mesh_solid(&mesh)
        else {
            unreachable!()
        };
        assert_eq!((cavities, overlapping.len()), (1, 0), "seed {seed}");
    }
}

/// An L-shaped prism (a concave polygon extruded) beside a separate box: two solids.
#[test]
fn l_shapes_and_separate_boxes_wound_any_way_have_their_closed_form() {
    for seed in 0..CASES {
        let mut generator = ChaCha20Rng::seed_from_u64(2000 + seed);
        let (sx, sy) = (
            0.2 + generator.random::<f64>(),
            0.2 + generator.random::<f64>(),
        );
        let depth = 0.2 + generator.random::<f64>();
        let outline: Vec<[f64; 2]> = [
            [0.0, 0.0],
            [2.0, 0.0],
            [2.0, 1.0],
            [1.0, 1.0],
            [1.0, 2.0],
            [0.0, 2.0],
        ]
        .iter()
        .map(|p| [p[0] * sx, p[1] * sy])
        .collect();
        let box_center = DVec3::new(5.0, 0.0, 0.0);
        let box_h = half_extents(&mut generator, 0.1, 0.5);
        let (rotation, offset) = random_pose(&mut generator);
        let mesh = assemble(
            &[
                prism_shell(&outline, 3, depth),
                box_shell(box_center, box_h),
            ],
            rotation,
            offset,
            0.3,
            &mut generator,
        );
        let half_depth = depth / 2.0;
        let l_shape = Expected::cuboid(
            DVec3::new(sx, sy / 2.0, half_depth),
            DVec3::new(sx, sy / 2.0, half_depth),
        )
        .combined(
            Expected::cuboid(
                DVec3::new(sx / 2.0, 1.5 * sy, half_depth),
                DVec3::new(sx / 2.0, sy / 2.0, half_depth),
            ),
            1.0,
        );
        let expected = l_shape
            .combined(Expected::cuboid(box_center, box_h), 1.0)
            .moved(rotation, offset);
        assert_close(&mesh, expected, 6.0, &format!("L shape seed {seed}"));
    }
}

/// A torus about the y axis, ring radius `ring`, tube radius `tube`, of `around` × `tube_steps`
/// quads (two triangles each), wound outward.
fn torus_shell(ring: f64, tube: f64, around: u32, tube_steps: u32) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let mut vertices = Vec::new();
    for i in 0..around {
        let u = i as f64 * std::f64::consts::TAU / around as f64;
        for j in 0..tube_steps {
            let v = j as f64 * std::f64::consts::TAU / tube_steps as f64;
            let radial = ring + tube * v.cos();
            vertices.push(DVec3::new(
                radial * u.cos(),
                tube * v.sin(),
                radial * u.sin(),
            ));
        }
    }
    let index = |i: u32, j: u32| (i % around) * tube_steps + j % tube_steps;
    let mut triangles = Vec::new();
    for i in 0..around {
        for j in 0..tube_steps {
            let (a, b) = (index(i, j), index(i + 1, j));
            let (c, d) = (index(i + 1, j + 1), index(i, j + 1));
            triangles.push([a, d, c]);
            triangles.push([a, c, b]);
        }
    }
    (vertices, triangles)
}

/// Tori (a shell of genus one) of ring radius 0.2-1.5 m and tube up to 0.9 of it, turned and
/// moved, wound either way, against the smooth torus's closed form (V = 2π²Rr², about its
/// axis I = V(R² + ¾r²), across it V(R²/2 + ⅝r²)): at 192 × 96 quads the facets cost 0.1 %.
#[test]
fn tori_wound_any_way_have_their_closed_form() {
    for seed in 0..CASES / 3 {
        let mut generator = ChaCha20Rng::seed_from_u64(3000 + seed);
        let ring = 0.2 + 1.3 * generator.random::<f64>();
        let tube = ring * (0.05 + 0.85 * generator.random::<f64>());
        let (rotation, offset) = random_pose(&mut generator);
        let flip = [0.0, 0.25, 1.0][seed as usize % 3];
        let mesh = assemble(
            &[torus_shell(ring, tube, 192, 96)],
            rotation,
            offset,
            flip,
            &mut generator,
        );
        let volume = 2.0 * std::f64::consts::PI.powi(2) * ring * tube * tube;
        let across = volume * (ring * ring / 2.0 + 0.625 * tube * tube);
        let expected = Expected {
            volume,
            center: DVec3::ZERO,
            inertia: DMat3::from_diagonal(DVec3::new(
                across,
                volume * (ring * ring + 0.75 * tube * tube),
                across,
            )),
        }
        .moved(rotation, offset);
        assert_close(&mesh, expected, ring + tube, &format!("torus seed {seed}"));
    }
}

/// Overlapping shells are reported, with the sum of the shells as the moments; an open box
/// and a mesh that cannot be wound consistently are open.
#[test]
fn overlaps_are_named_and_open_meshes_are_open() {
    let mut generator = ChaCha20Rng::seed_from_u64(7);
    let mesh = assemble(
        &[
            box_shell(DVec3::ZERO, DVec3::splat(0.5)),
            box_shell(DVec3::new(0.5, 0.3, 0.2), DVec3::splat(0.5)),
        ],
        DQuat::IDENTITY,
        DVec3::ZERO,
        0.0,
        &mut generator,
    );
    let MeshSolid::Closed {
        moments,
        overlapping,
        ..
    } = mesh_solid(&mesh)
    else {
        panic!("two cubes are closed")
    };
    assert_eq!(overlapping, [(0, 1)]);
    assert!((moments.volume - 2.0).abs() < 1e-6, "{}", moments.volume);

    let (vertices, mut triangles) = box_shell(DVec3::ZERO, DVec3::splat(0.5));
    triangles.truncate(10);
    let open = MeshData {
        vertices: vertices.iter().map(|v| v.as_vec3().to_array()).collect(),
        indices: triangles,
    };
    assert_eq!(mesh_solid(&open), MeshSolid::Open { open_edges: 4 });
    assert_eq!(open_edge_count(&open), 4);
    assert!((convex_hull_volume(&open) - 1.0).abs() < 1e-6);
}

/// A box 300 km and one 1,000 km across: the moments stay finite and right, in f32 too.
#[test]
fn meshes_hundreds_of_kilometres_across_have_finite_mass_properties() {
    let mut generator = ChaCha20Rng::seed_from_u64(11);
    for h in [1.5e5, 5.0e5] {
        let h = DVec3::new(h, h * 0.5, h * 0.25);
        let mesh = assemble(
            &[box_shell(DVec3::ZERO, h)],
            DQuat::IDENTITY,
            DVec3::ZERO,
            0.0,
            &mut generator,
        );
        let expected = Expected::cuboid(DVec3::ZERO, h);
        assert_close(&mesh, expected, h.length(), "large box");
        let MeshSolid::Closed { moments, .. } = mesh_solid(&mesh) else {
            unreachable!()
        };
        let properties = moments.to_mass_properties().expect("finite in f32");
        let principal = properties.principal_inertia();
        assert!(
            principal.is_finite() && principal.min_element() > 0.0,
            "{principal}"
        );
    }
}

/// A closed box mesh from 1 m to 600 km across keeps its closed-form principal moments in
/// Parry's f32 mass properties (the tensor of the 600 km box at density 1, about 10²⁶ kg·m²,
/// has squares beyond f32's range), turned so that its tensor has off-diagonal entries.
#[test]
fn large_meshes_keep_their_moments_in_f32() {
    let mut generator = ChaCha20Rng::seed_from_u64(7);
    for half in [0.5, 5.0e3, 3.0e5] {
        let h = DVec3::new(half, 0.5 * half, 0.25 * half);
        let (rotation, _) = random_pose(&mut generator);
        let mesh = assemble(
            &[box_shell(DVec3::ZERO, h)],
            rotation,
            DVec3::ZERO,
            0.0,
            &mut generator,
        );
        let MeshSolid::Closed { moments, .. } = mesh_solid(&mesh) else {
            panic!("the box is closed");
        };
        let properties = moments.to_mass_properties().expect("finite properties");
        let volume = 8.0 * h.x * h.y * h.z;
        let mut found = properties.principal_inertia().as_dvec3().to_array();
        found.sort_by(f64::total_cmp);
        let mut expected = [
            volume * (h.y * h.y + h.z * h.z) / 3.0,
            volume * (h.x * h.x + h.z * h.z) / 3.0,
            volume * (h.x * h.x + h.y * h.y) / 3.0,
        ];
        expected.sort_by(f64::total_cmp);
        for (f, e) in found.iter().zip(expected) {
            assert!(
                (f - e).abs() <= 1e-3 * e,
                "half extent {half}: {found:?} against {expected:?}"
            );
        }
        assert!((f64::from(properties.mass()) - volume).abs() <= 1e-4 * volume);
    }
}
