//! Stages 1 and 6 of the step: prospective velocities and position integration.

use glam::{Quat, Vec3};

use crate::body::Bodies;
use crate::scene::BodyKind;

/// Stage 1: v* = v + dt·M⁻¹·f_ext with gravity the only external force (seed: "compute
/// prospective velocities of all objects for this time step"). Static bodies are untouched.
pub fn prospective_velocities(bodies: &mut Bodies, gravity: Vec3, dt: f32) {
    let dv = gravity * dt;
    for (v, kind) in bodies.linear_velocity.iter_mut().zip(&bodies.kind) {
        if *kind != BodyKind::Static {
            *v += dv;
        }
    }
}

/// Stage 6: symplectic Euler on positions, x += dt·v, and q ← normalize(q + dt/2·ω⊗q) on
/// orientations, both about the centre of mass.
pub fn integrate_positions(bodies: &mut Bodies, dt: f32) {
    for i in 0..bodies.len() {
        if bodies.kind[i] == BodyKind::Static {
            continue;
        }
        let com = bodies.center_of_mass(i) + bodies.linear_velocity[i] * dt;
        let pose = &mut bodies.pose[i];
        let w = bodies.angular_velocity[i];
        if w != Vec3::ZERO {
            let q = pose.rotation;
            let spin = Quat::from_xyzw(w.x, w.y, w.z, 0.0) * q;
            pose.rotation = Quat::from_xyzw(
                q.x + 0.5 * dt * spin.x,
                q.y + 0.5 * dt * spin.y,
                q.z + 0.5 * dt * spin.z,
                q.w + 0.5 * dt * spin.w,
            )
            .normalize();
        }
        pose.translation = com - pose.rotation * bodies.local_center_of_mass[i];
    }
}
