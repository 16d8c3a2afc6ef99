//! Scene pieces shared by the integration tests (the unit tests reach them through
//! `test_support`). Public API only.

use glam::Vec3;
use impulse::{BodyDesc, BodyKind, Material, ShapeDesc};

/// Material with Coulomb coefficient `friction`, no restitution, density 1000 kg/m³.
pub(crate) fn material(friction: f32) -> Material {
    Material {
        friction,
        restitution: 0.0,
        density: 1000.0,
        roughness: 0.0,
        impact_perturbation: 0.0,
    }
}

/// A static cuboid of half extents `half` (m) centred at `position` (m).
pub(crate) fn static_box(half: Vec3, position: Vec3) -> BodyDesc {
    BodyDesc::new(
        BodyKind::Static,
        ShapeDesc::Cuboid {
            half_extents: half.to_array(),
        },
        position.to_array(),
    )
}

/// The 64-sphere pile of the complementarity tests: 4 layers of 4×4 frictionless spheres
/// (r = 0.45 m, jittered) on a static ground inside four static walls, with `settings`,
/// dt = 1/60 s, gravity −9.81 m/s² along y. Used by the unit tests (through `test_support`).
#[allow(dead_code)]
pub(crate) fn sphere_pile(settings: impulse::SolverSettings) -> impulse::World {
    let mut w = impulse::World::new(Vec3::new(0.0, -9.81, 0.0), 1.0 / 60.0, settings).unwrap();
    w.add_body(
        &static_box(Vec3::new(50.0, 0.5, 50.0), Vec3::new(0.0, -0.5, 0.0)),
        &material(0.0),
    )
    .unwrap();
    // Walls keep the frictionless pile together.
    for (x, z) in [(2.6, 0.0), (-2.6, 0.0), (0.0, 2.6), (0.0, -2.6)] {
        let half = if x != 0.0 {
            Vec3::new(0.5, 3.0, 3.0)
        } else {
            Vec3::new(3.0, 3.0, 0.5)
        };
        w.add_body(&static_box(half, Vec3::new(x, 3.0, z)), &material(0.0))
            .unwrap();
    }
    for layer in 0..4 {
        for i in 0..4 {
            for k in 0..4 {
                let jitter = 0.05 * ((i * 7 + k * 3 + layer) % 5) as f32;
                let p = Vec3::new(
                    -1.5 + i as f32 + jitter,
                    0.5 + 1.05 * layer as f32,
                    -1.5 + k as f32,
                );
                let sphere = BodyDesc::new(
                    BodyKind::Dynamic,
                    ShapeDesc::Sphere { radius: 0.45 },
                    p.to_array(),
                );
                w.add_body(&sphere, &material(0.0)).unwrap();
            }
        }
    }
    w
}

/// Index of the body whose origin is highest (largest y): the top of a pile.
pub(crate) fn highest_body(world: &impulse::World) -> usize {
    let poses = world.poses();
    (0..poses.len())
        .max_by(|&i, &j| {
            let (a, b) = (poses[i].translation.y, poses[j].translation.y);
            a.total_cmp(&b)
        })
        .unwrap()
}

/// FNV-1a hash of a world's state: every body's pose and velocities, every contact point's
/// impulses and separation, and every joint's reaction and broken flag, as f32 bits. Equal hashes mean the same state to the bit.
pub(crate) fn hash_state(world: &impulse::World) -> u64 {
    let mut hash = 0xcbf2_9ce4_8422_2325u64;
    let mut add = |x: f32| {
        for byte in x.to_bits().to_le_bytes() {
            hash ^= u64::from(byte);
            hash = hash.wrapping_mul(0x0100_0000_01b3);
        }
    };
    let (poses, linear, angular) = (
        world.poses(),
        world.linear_velocities(),
        world.angular_velocities(),
    );
    for i in 0..world.body_count() {
        let (t, q) = (poses[i].translation, poses[i].rotation);
        for x in [t.x, t.y, t.z, q.x, q.y, q.z, q.w] {
            add(x);
        }
        for v in [linear[i], angular[i]] {
            v.to_array().into_iter().for_each(&mut add);
        }
    }
    for pair in world.contact_pairs() {
        for point in pair.points() {
            add(point.normal_impulse);
            point
                .friction_impulse
                .to_array()
                .into_iter()
                .for_each(&mut add);
            add(point.separation);
        }
    }
    for joint in world.joints() {
        for v in [joint.force(), joint.torque()] {
            v.to_array().into_iter().for_each(&mut add);
        }
        add(if joint.broken() { 1.0 } else { 0.0 });
    }
    hash
}

/// SplitMix64: a small seeded generator for the seeded sweeps, so every case can be rebuilt
/// from its seed.
pub(crate) struct Rng(pub(crate) u64);

impl Rng {
    /// The next 64 random bits.
    pub(crate) fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in [lo, hi).
    pub(crate) fn range(&mut self, lo: f32, hi: f32) -> f32 {
        let unit = (self.next() >> 40) as f32 / (1u64 << 24) as f32;
        lo + (hi - lo) * unit
    }

    /// Uniform integer in [lo, hi].
    pub(crate) fn integer(&mut self, lo: usize, hi: usize) -> usize {
        lo + (self.next() % (hi - lo + 1) as u64) as usize
    }

    /// A random orientation: yaw, pitch and roll (Euler angles Y, X, Z) each uniform in
    /// [0, 2π), drawn in that order.
    pub(crate) fn orientation(&mut self) -> glam::Quat {
        glam::Quat::from_euler(
            glam::EulerRot::YXZ,
            self.range(0.0, std::f32::consts::TAU),
            self.range(0.0, std::f32::consts::TAU),
            self.range(0.0, std::f32::consts::TAU),
        )
    }
}

/// The lowest height (y, m) of `points` (in a body's frame) at `pose`.
pub(crate) fn lowest_height(points: &[Vec3], pose: &impulse::parry3d::math::Pose) -> f32 {
    points
        .iter()
        .map(|p| pose.transform_point(*p).y)
        .fold(f32::INFINITY, f32::min)
}

/// Whether the segment a–b passes through the box of half extents `extents` centred on the
/// origin, axes aligned (the slab test): a centre's path through a wall.
pub(crate) fn segment_crosses_box(a: Vec3, b: Vec3, extents: Vec3) -> bool {
    let (mut enter, mut leave) = (0.0f32, 1.0f32);
    for axis in 0..3 {
        let (start, delta, e) = (a[axis], b[axis] - a[axis], extents[axis]);
        if delta.abs() < 1e-12 {
            if start.abs() > e {
                return false;
            }
            continue;
        }
        let (t1, t2) = ((-e - start) / delta, (e - start) / delta);
        enter = enter.max(t1.min(t2));
        leave = leave.min(t1.max(t2));
    }
    enter <= leave
}

/// Steps `world` `steps` times (each step must succeed) and returns its bodies' poses then.
pub(crate) fn poses_after(
    world: &mut impulse::World,
    steps: usize,
) -> Vec<impulse::parry3d::math::Pose> {
    for _ in 0..steps {
        world.step().unwrap();
    }
    world.poses().to_vec()
}

/// Points on the faces of a cube of half extent `half` (m), 6 to 59 of them drawn from
/// `rng`, each moved by up to 0.1 µm per axis: a box as a scanner or a modelling tool's
/// snapping leaves it, all but coplanar on each face.
pub(crate) fn jittered_box_points(rng: &mut rand::rngs::ChaCha20Rng, half: f32) -> Vec<Vec3> {
    use rand::RngExt;
    let count = rng.random_range(6..60);
    let unit = |rng: &mut rand::rngs::ChaCha20Rng| {
        Vec3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        )
    };
    (0..count)
        .map(|_| {
            let mut p = unit(rng);
            let k = rng.random_range(0..3);
            p[k] = if rng.random_bool(0.5) { 1.0 } else { -1.0 };
            p * half + unit(rng) * 1.0e-7
        })
        .collect()
}

/// The first of [`jittered_box_points`] (half extent `half`, drawn from a ChaCha20 stream
/// seeded with `seed`) whose Parry hull holds an edge with a face index past its faces
/// (beside a degenerate triangle). Panics if none comes in 20,000 draws.
pub(crate) fn box_points_with_an_edge_past_the_faces(seed: u64, half: f32) -> Vec<Vec3> {
    use rand::SeedableRng;
    let mut rng = rand::rngs::ChaCha20Rng::seed_from_u64(seed);
    (0..20_000)
        .find_map(|_| {
            let points = jittered_box_points(&mut rng, half);
            let hull = impulse::parry3d::shape::ConvexPolyhedron::from_convex_hull(&points)?;
            let faces = hull.faces().len() as u32;
            hull.edges()
                .iter()
                .any(|e| e.faces.iter().any(|&f| f >= faces))
                .then_some(points)
        })
        .expect("no hull with an edge past its faces in 20,000 draws")
}
