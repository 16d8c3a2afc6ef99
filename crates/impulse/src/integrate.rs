//! Stages 1 and 6 of the step, on an island's local arrays: prospective velocities and
//! position integration (symplectic Euler, per substep).

use glam::{Quat, Vec3};

/// Stage 1: v* = v + h·M⁻¹·f_ext with gravity the only external force (docs/method.md: "compute
/// prospective velocities of all objects for this time step"). `linear` holds moving bodies
/// only.
pub fn prospective_velocities(linear: &mut [Vec3], gravity: Vec3, h: f32) {
    let dv = gravity * h;
    for v in linear {
        *v += dv;
    }
}

/// Stage 6: x += h·v for the centres of mass (accumulated in `displacement`, m), the rotation
/// vector Σ h·ω (`rotation`, rad, used for contact separations), and
/// q ← normalize(q + h/2·ω⊗q) for the orientations. All slices are indexed alike.
pub fn integrate_positions(
    linear: &[Vec3],
    angular: &[Vec3],
    displacement: &mut [Vec3],
    rotation: &mut [Vec3],
    orientation: &mut [Quat],
    h: f32,
) {
    for k in 0..orientation.len() {
        displacement[k] += linear[k] * h;
        let omega = angular[k];
        if omega != Vec3::ZERO {
            rotation[k] += omega * h;
            orientation[k] = integrate_orientation(orientation[k], omega, h);
        }
    }
}

/// q ← normalize(q + h/2·ω⊗q): first-order orientation update (step 6 of docs/architecture.md).
pub fn integrate_orientation(q: Quat, omega: Vec3, h: f32) -> Quat {
    let spin = Quat::from_xyzw(omega.x, omega.y, omega.z, 0.0) * q;
    Quat::from_xyzw(
        q.x + 0.5 * h * spin.x,
        q.y + 0.5 * h * spin.y,
        q.z + 0.5 * h * spin.z,
        q.w + 0.5 * h * spin.w,
    )
    .normalize()
}
