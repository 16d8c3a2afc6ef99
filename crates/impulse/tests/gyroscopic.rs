//! The implicit gyroscopic term (`SolverSettings::gyroscopic`): a free rigid body keeps its
//! world angular momentum, tumbles about its intermediate axis with the period of Euler's
//! equations (the Dzhanibekov effect), spins stably about its major and minor axes, and never
//! gains kinetic energy.

use impulse::glam::{DVec3, Quat, Vec3};
use impulse::{BodyBuilder, BodyHandle, SharedShape, SolverSettings, World};

const DT: f32 = 1.0 / 60.0;
/// Half extents of the box: principal moments ∝ (hy² + hz², hx² + hz², hx² + hy²) =
/// (0.34, 0.10, 0.26), so x is the major axis, y the minor and z the intermediate.
const HALF: [f32; 3] = [0.1, 0.5, 0.3];
const DENSITY: f32 = 1000.0;

/// Principal moments (kg·m²) of the box about its centre: m/3·(b² + c²) for half extents.
fn moments() -> DVec3 {
    let [a, b, c] = HALF.map(f64::from);
    let m = f64::from(DENSITY) * 8.0 * a * b * c;
    DVec3::new(b * b + c * c, a * a + c * c, a * a + b * b) * (m / 3.0)
}

/// A world without gravity holding one free box at `rotation` spinning at `omega` (world).
fn free_box(rotation: Quat, omega: Vec3, gyroscopic: bool) -> (World, BodyHandle) {
    let settings = SolverSettings {
        sleep: false,
        gyroscopic,
        ..SolverSettings::default()
    };
    let mut world = World::new(Vec3::ZERO, DT, settings).unwrap();
    let body = world
        .insert(
            BodyBuilder::dynamic(SharedShape::cuboid(HALF[0], HALF[1], HALF[2]))
                .density(DENSITY)
                .rotation(rotation)
                .angular_velocity(omega),
        )
        .unwrap();
    (world, body)
}

/// World angular momentum R·I·Rᵀ·ω and kinetic energy ½ωᵀIω of the box, in f64.
fn momentum_and_energy(world: &World, body: BodyHandle) -> (DVec3, f64) {
    let b = world.body(body).unwrap();
    let q = b.rotation().as_dquat();
    let local = q.inverse() * b.angular_velocity().as_dvec3();
    let l = moments() * local;
    (q * l, 0.5 * local.dot(l))
}

/// Body-frame angular velocity.
fn body_omega(world: &World, body: BodyHandle) -> DVec3 {
    let b = world.body(body).unwrap();
    b.rotation().as_dquat().inverse() * b.angular_velocity().as_dvec3()
}

#[test]
fn the_moments_are_the_engines() {
    let (world, _) = free_box(Quat::IDENTITY, Vec3::ZERO, true);
    let inverse = world.bodies().local_inverse_inertia[0];
    let engine = DVec3::new(
        f64::from(inverse.x_axis.x).recip(),
        f64::from(inverse.y_axis.y).recip(),
        f64::from(inverse.z_axis.z).recip(),
    );
    let relative = ((engine - moments()) / moments()).abs().max_element();
    assert!(relative < 1e-4, "{engine} against {}", moments());
}

#[test]
fn a_free_body_keeps_its_world_angular_momentum_and_loses_no_energy_it_should_keep() {
    let rotation = Quat::from_euler(impulse::glam::EulerRot::XYZ, 0.4, -0.9, 1.3);
    let (mut world, body) = free_box(rotation, Vec3::new(1.0, 2.0, 3.0), true);
    let (l0, e0) = momentum_and_energy(&world, body);
    let mut worst = 0.0f64;
    for _ in 0..600 {
        world.step().unwrap();
        let (l, e) = momentum_and_energy(&world, body);
        worst = worst.max((l - l0).length() / l0.length());
        assert!(e <= e0 * (1.0 + 1e-4), "energy grew: {e} J from {e0} J");
    }
    eprintln!("largest drift of L over 10 s: {:.4} %", 100.0 * worst);
    assert!(
        worst < 0.005,
        "world angular momentum drifted by {:.3} %",
        100.0 * worst
    );
    // Without the term, ω stays constant in the world frame and L = R·I·Rᵀ·ω swings round.
    let (mut world, body) = free_box(rotation, Vec3::new(1.0, 2.0, 3.0), false);
    let mut worst_off = 0.0f64;
    for _ in 0..600 {
        world.step().unwrap();
        let (l, _) = momentum_and_energy(&world, body);
        worst_off = worst_off.max((l - l0).length() / l0.length());
    }
    assert!(worst_off > 0.1, "without the term L drifts: {worst_off}");
}

/// Times (s) at which the body-frame z component of ω changes sign.
fn flips_of(mut omega_z: impl FnMut() -> Option<(f64, f64)>) -> Vec<f64> {
    let mut flips = Vec::new();
    let mut last: Option<(f64, f64)> = None;
    while let Some((t, z)) = omega_z() {
        if let Some((t0, z0)) = last
            && z0.signum() != z.signum()
        {
            // Linear interpolation of the crossing.
            flips.push(t0 + (t - t0) * z0 / (z0 - z));
        }
        last = Some((t, z));
    }
    flips
}

/// Euler's torque-free equations I·ω̇ = (I·ω) × ω in the body frame, by RK4 at `h` (s).
fn reference_flips(omega0: DVec3, duration: f64, h: f64) -> Vec<f64> {
    let i = moments();
    let f = |w: DVec3| (i * w).cross(w) / i;
    let mut w = omega0;
    let mut t = 0.0;
    let steps = (duration / h) as usize;
    let mut k = 0;
    flips_of(|| {
        if k > steps {
            return None;
        }
        let out = (t, w.z);
        let k1 = f(w);
        let k2 = f(w + k1 * (h / 2.0));
        let k3 = f(w + k2 * (h / 2.0));
        let k4 = f(w + k3 * h);
        w += (k1 + 2.0 * k2 + 2.0 * k3 + k4) * (h / 6.0);
        t += h;
        k += 1;
        Some(out)
    })
}

fn mean_interval(flips: &[f64]) -> f64 {
    (flips[flips.len() - 1] - flips[0]) / (flips.len() - 1) as f64
}

#[test]
fn spin_near_the_intermediate_axis_flips_with_the_period_of_eulers_equations() {
    // Spin about the intermediate (z) axis with a small push about the major (x) axis.
    let omega0 = Vec3::new(0.05, 0.0, 5.0);
    let (mut world, body) = free_box(Quat::IDENTITY, omega0, true);
    let duration = 20.0;
    let steps = (duration / f64::from(DT)) as usize;
    let mut n = 0;
    let simulated = flips_of(|| {
        if n > steps {
            return None;
        }
        let out = (n as f64 * f64::from(DT), body_omega(&world, body).z);
        world.step().unwrap();
        n += 1;
        Some(out)
    });
    let reference = reference_flips(omega0.as_dvec3(), duration, 1e-4);
    assert!(
        reference.len() >= 3,
        "the reference flips at least three times in {duration} s: {reference:?}"
    );
    assert!(
        simulated.len() >= 3,
        "the body flips: {simulated:?} (reference {reference:?})"
    );
    let (t, t_ref) = (mean_interval(&simulated), mean_interval(&reference));
    eprintln!(
        "half period between flips: {t:.4} s simulated, {t_ref:.4} s by RK4 ({} and {} flips)",
        simulated.len(),
        reference.len()
    );
    assert!(
        (t - t_ref).abs() < 0.05 * t_ref,
        "half period {t:.3} s against {t_ref:.3} s (flips {simulated:?}, reference {reference:?})"
    );
    // Without the term the body never flips.
    let (mut world, body) = free_box(Quat::IDENTITY, omega0, false);
    for _ in 0..steps {
        world.step().unwrap();
        let z = world.body(body).unwrap().angular_velocity().z;
        assert!(z > 0.0);
    }
}

#[test]
fn spin_about_the_major_and_minor_axes_is_stable() {
    for (axis, push) in [
        (DVec3::X, DVec3::new(0.0, 0.05, 0.05)),
        (DVec3::Y, DVec3::new(0.05, 0.0, 0.05)),
    ] {
        let omega0 = axis * 5.0 + push;
        let (mut world, body) = free_box(Quat::IDENTITY, omega0.as_vec3(), true);
        let (_, e0) = momentum_and_energy(&world, body);
        for _ in 0..600 {
            world.step().unwrap();
            let w = body_omega(&world, body);
            assert!(
                w.dot(axis) > 4.9 && (w - axis * w.dot(axis)).length() < 0.2,
                "spin about {axis} wanders: ω = {w}"
            );
            let (_, e) = momentum_and_energy(&world, body);
            assert!(e <= e0 * (1.0 + 1e-4), "energy grew: {e} J from {e0} J");
        }
    }
}

#[test]
fn spheres_and_particles_are_untouched() {
    // An isotropic tensor has no gyroscopic term: the ball's ω stays exactly as given.
    let mut world = World::new(Vec3::ZERO, DT, SolverSettings::default()).unwrap();
    let omega = Vec3::new(1.0, -2.0, 3.0);
    let ball = world
        .insert(BodyBuilder::dynamic(SharedShape::ball(0.3)).angular_velocity(omega))
        .unwrap();
    for _ in 0..60 {
        world.step().unwrap();
    }
    assert_eq!(world.body(ball).unwrap().angular_velocity(), omega);
}

#[test]
fn the_scene_format_reads_the_setting_with_true_by_default() {
    let text = |solver: &str| {
        format!(
            r#"{{"gravity": [0, 0, 0], {solver} "bodies": [{{"kind": "dynamic", "shape": {{"type": "sphere", "radius": 1}}}}]}}"#
        )
    };
    let scene = impulse::scene::parse_scene_str(&text(""), "t").unwrap();
    assert!(scene.solver.gyroscopic);
    let scene =
        impulse::scene::parse_scene_str(&text(r#""solver": {"gyroscopic": false},"#), "t").unwrap();
    assert!(!scene.solver.gyroscopic);
    let written = impulse::scene::to_json_string(&scene);
    assert_eq!(
        impulse::scene::parse_scene_str(&written, "t").unwrap(),
        scene
    );
}
