//! Scene pieces shared by the solver tests (`mod common;` in each test file that uses them).
#![allow(dead_code)] // each test binary uses its own subset

use glam::Vec3;
use impulse::{BodyDesc, BodyKind, Material, ShapeDesc};

/// Material with Coulomb coefficient `friction`, no restitution, density 1000 kg/m³.
pub fn material(friction: f32) -> Material {
    Material {
        friction,
        restitution: 0.0,
        density: 1000.0,
    }
}

/// A static cuboid of half extents `half` (m) centred at `position` (m).
pub fn static_box(half: Vec3, position: Vec3) -> BodyDesc {
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
/// dt = 1/60 s, gravity −9.81 m/s² along y.
pub fn sphere_pile(settings: impulse::SolverSettings) -> impulse::World {
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

/// Checks the engine's own LCP at exit of the last step: for every point γ ≥ 0, w = J·v −
/// target ≥ −1e-3 m/s and |w·γ| ≤ 1e-3 of the largest γ, and the natural-map residual is
/// below 1e-2. Returns false (checks nothing) while the pile has fewer than 50 contacts.
pub fn check_complementarity_at_exit(w: &impulse::World) -> bool {
    let constraints = w.contact_constraints();
    if constraints.len() < 50 {
        return false;
    }
    let lin = &w.bodies.linear_velocity;
    let ang = &w.bodies.angular_velocity;
    let largest = constraints
        .iter()
        .map(|c| c.normal_impulse)
        .fold(0.0f32, f32::max);
    for c in constraints {
        let (a, b) = (c.body_a as usize, c.body_b as usize);
        let wv = c.normal.velocity(lin[a], ang[a], lin[b], ang[b]) - c.target_normal_velocity;
        assert!(c.normal_impulse >= 0.0);
        assert!(wv >= -1e-3, "w = {wv} < 0");
        assert!(
            (wv * c.normal_impulse).abs() <= 1e-3 * largest.max(1e-6),
            "complementarity: w = {wv}, γ = {}",
            c.normal_impulse
        );
    }
    assert!(w.diagnostics().natural_map_residual < 1e-2);
    true
}

/// Index of the body whose origin is highest (largest y): the top of a pile.
pub fn highest_body(bodies: &impulse::body::Bodies) -> usize {
    (0..bodies.len())
        .max_by(|&i, &j| {
            let (a, b) = (bodies.pose[i].translation.y, bodies.pose[j].translation.y);
            a.total_cmp(&b)
        })
        .unwrap()
}

/// Adds M⁻¹Jᵀγ of one of `c`'s rows, carrying `impulse` (N·s), to the (linear, angular)
/// velocity changes of its two bodies (`body_a` +, `body_b` −), indexed by world body, in f64:
/// a reference for the engine's f32 passes.
pub fn add_row_impulse(
    delta: &mut [([f64; 3], [f64; 3])],
    c: &impulse::constraints::ContactConstraint,
    row: &impulse::constraints::JacobianRow,
    impulse: f64,
) {
    let to64 = |v: Vec3| [v.x as f64, v.y as f64, v.z as f64];
    let (d, ma, mb, ia, ib) = (
        to64(row.direction),
        to64(c.inverse_mass_a),
        to64(c.inverse_mass_b),
        to64(row.inverse_inertia_angular_a),
        to64(row.inverse_inertia_angular_b),
    );
    let (a, b) = (c.body_a as usize, c.body_b as usize);
    for k in 0..3 {
        delta[a].0[k] += d[k] * ma[k] * impulse;
        delta[a].1[k] += ia[k] * impulse;
        delta[b].0[k] -= d[k] * mb[k] * impulse;
        delta[b].1[k] -= ib[k] * impulse;
    }
}

/// FNV-1a hash of a world's state: every body's pose and velocities and every contact point's
/// impulses and separation, as f32 bits. Equal hashes mean the same state to the bit.
pub fn hash_state(world: &impulse::World) -> u64 {
    let mut hash = 0xcbf2_9ce4_8422_2325u64;
    let mut add = |x: f32| {
        for byte in x.to_bits().to_le_bytes() {
            hash ^= u64::from(byte);
            hash = hash.wrapping_mul(0x0100_0000_01b3);
        }
    };
    let b = &world.bodies;
    for i in 0..b.len() {
        let (t, q) = (b.pose[i].translation, b.pose[i].rotation);
        for x in [t.x, t.y, t.z, q.x, q.y, q.z, q.w] {
            add(x);
        }
        for v in [b.linear_velocity[i], b.angular_velocity[i]] {
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
    hash
}
