//! Integration within an island's substeps (the solve stage, [`crate::Stage::Solve`]), on its
//! local arrays: the prospective velocities before each substep's solve, position integration
//! after it (symplectic Euler), and the implicit gyroscopic term.

use glam::{Mat3, Quat, Vec3};

/// Prospective velocities: v* = v + h·M⁻¹·f_ext with gravity the only external force (docs/method.md: "compute
/// prospective velocities of all objects for this time step"). `linear` holds moving bodies
/// only.
pub(crate) fn prospective_velocities(linear: &mut [Vec3], gravity: Vec3, h: f32) {
    let dv = gravity * h;
    for v in linear {
        *v += dv;
    }
}

/// Position integration: x += h·v for the centres of mass (accumulated in `displacement`, m), the rotation
/// vector Σ h·ω (`rotation`, rad, used for contact separations), and
/// q ← normalize(q + h/2·ω⊗q) for the orientations. All slices are indexed alike.
pub(crate) fn integrate_positions(
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

/// q ← normalize(q + h/2·ω⊗q): first-order orientation update (the solve stage's position
/// integration, docs/architecture.md).
pub(crate) fn integrate_orientation(q: Quat, omega: Vec3, h: f32) -> Quat {
    let spin = Quat::from_xyzw(omega.x, omega.y, omega.z, 0.0) * q;
    Quat::from_xyzw(
        q.x + 0.5 * h * spin.x,
        q.y + 0.5 * h * spin.y,
        q.z + 0.5 * h * spin.z,
        q.w + 0.5 * h * spin.w,
    )
    .normalize()
}

/// The implicit gyroscopic step of every body, per substep of `h` seconds: between contacts a
/// free body keeps its world angular momentum L = R·I·Rᵀ·ω, so in the body frame ω obeys
/// Euler's equations I·ω̇ + ω × I·ω = 0. Backward Euler gives
/// f(ω') = I·(ω' − ω) + h·ω' × I·ω' = 0 in body coordinates, solved by one Newton step from
/// ω' = ω: ω' = ω − J⁻¹·h·ω × I·ω with J = I + h·([ω]×·I − [I·ω]×) (Catto, "Numerical Methods",
/// GDC 2015; Bullet's `btRigidBody::computeGyroscopicImpulseImplicit_Body`). Unlike the explicit
/// term it is stable at any spin: the exact backward-Euler solution has |I·ω'| ≤ |I·ω| and
/// ω'·I·ω' ≤ ω·I·ω (take f(ω') = 0 dotted with I·ω' and with ω'), so it never adds angular
/// momentum or energy. One Newton step is within O(h²) of it; a step that would raise the
/// energy (a body turning radians a substep) is scaled back to the energy it started with,
/// so no substep adds any.
///
/// `inertia` holds each body's inertia tensor about its centre of mass in the body frame
/// (kg·m²), or zero for a body with no gyroscopic term (a particle, a body that does not
/// rotate, an isotropic tensor for which ω × I·ω = 0); `orientation` its current orientation.
/// A body whose Newton matrix is singular or whose result is not finite keeps its ω.
pub(crate) fn gyroscopic(angular: &mut [Vec3], orientation: &[Quat], inertia: &[Mat3], h: f32) {
    for ((omega, &q), tensor) in angular.iter_mut().zip(orientation).zip(inertia) {
        if *omega == Vec3::ZERO || *tensor == Mat3::ZERO {
            continue;
        }
        let local = q.inverse() * *omega;
        let momentum = *tensor * local;
        let residual = h * local.cross(momentum);
        let jacobian = *tensor + (skew(local) * *tensor - skew(momentum)) * h;
        let determinant = jacobian.determinant();
        if !determinant.is_finite() || determinant.abs() <= f32::MIN_POSITIVE {
            continue;
        }
        let mut step = jacobian.inverse() * residual;
        // The exact backward-Euler solution never gains energy; one Newton step towards it can,
        // and by far once the body turns radians in a substep (the step's error grows as
        // (h·|ω|)²: a box spinning at 14,731 rad/s, 61 rad a substep at 240 Hz, gained
        // 380,000 J/kg in one step of free flight). Such a result keeps its direction and is
        // scaled back to the energy the body had.
        let next = local - step;
        let (before, after) = (local.dot(momentum), next.dot(*tensor * next));
        if after > before {
            step = local - next * (before / after).sqrt();
        }
        // Only the change goes back through the rotation: a round trip of ω itself through
        // a quaternion of norm 1 ± ulp scales it each substep, and in f32 that bias adds up
        // over many substeps (`gyroscopic_substeps_do_not_gain_energy` bounds the drift).
        let change = q * step;
        if change.is_finite() {
            *omega -= change;
        }
    }
}

/// The implicit gyroscopic step of [`gyroscopic`] for a body that may not turn about world
/// axis `locked` (0, 1, 2 for x, y, z) and turns freely about the other two, per substep of `h`
/// seconds. The lock's reaction is a torque λ·e along the locked axis e, so in world
/// coordinates, with the free world axes the columns of P and I_w = R·I·Rᵀ at the current
/// orientation, backward Euler asks for ω' = ω − P·Δ with
///
///   Pᵀ·f(ω') = 0,  f(ω') = I_w·(ω' − ω) + h·ω' × I_w·ω'
///
/// (f is the body-frame residual of [`gyroscopic`] rotated to the world frame; its component
/// along e is the lock's reaction). One Newton step from ω' = ω solves the 2×2 system
/// (Pᵀ·J·P)·Δ = Pᵀ·h·ω × I_w·ω with J = I_w + h·([ω]×·I_w − [I_w·ω]×). The exact solution
/// never adds kinetic energy: ω' lies in the free plane, so f(ω')·ω' = 0 gives
/// ω'·I_w·ω' = ω'·I_w·ω ≤ √(ω'·I_w·ω')·√(ω·I_w·ω); and it keeps the free components Pᵀ·L of the world
/// angular momentum L = I_w·ω up to O(h²) a step, as the exact motion keeps them (the lock
/// only torques about e). The component of ω along e is left as it is (zero for a locked body)
/// to the bit.
///
/// `inertia` is the body-frame tensor of [`gyroscopic_inertia`] (kg·m², zero for no term),
/// `orientation` the body's current orientation, `omega` its world angular velocity (rad/s).
/// A singular 2×2 system or a result that is not finite leaves ω as it is.
pub(crate) fn gyroscopic_in_plane(
    omega: &mut Vec3,
    orientation: Quat,
    inertia: &Mat3,
    locked: usize,
    h: f32,
) {
    if *omega == Vec3::ZERO || *inertia == Mat3::ZERO {
        return;
    }
    let (a, b) = match locked {
        0 => (1, 2),
        1 => (0, 2),
        _ => (0, 1),
    };
    let r = Mat3::from_quat(orientation);
    let tensor = r * *inertia * r.transpose();
    let momentum = tensor * *omega;
    let residual = h * omega.cross(momentum);
    let jacobian = tensor + (skew(*omega) * tensor - skew(momentum)) * h;
    // The free block of J (J_ij = column j, row i) and its determinant.
    let (jaa, jab) = (jacobian.col(a)[a], jacobian.col(b)[a]);
    let (jba, jbb) = (jacobian.col(a)[b], jacobian.col(b)[b]);
    let determinant = jaa * jbb - jab * jba;
    if !determinant.is_finite() || determinant.abs() <= f32::MIN_POSITIVE {
        return;
    }
    let mut change = Vec3::ZERO;
    change[a] = (jbb * residual[a] - jab * residual[b]) / determinant;
    change[b] = (jaa * residual[b] - jba * residual[a]) / determinant;
    if change.is_finite() {
        *omega -= change;
    }
}

/// [a]×: the matrix of b ↦ a × b.
fn skew(a: Vec3) -> Mat3 {
    Mat3::from_cols(
        Vec3::new(0.0, a.z, -a.y),
        Vec3::new(-a.z, 0.0, a.x),
        Vec3::new(a.y, -a.x, 0.0),
    )
}

/// The tensor [`gyroscopic`] needs for a body of local inverse inertia `inverse` (body frame):
/// its inverse, or zero when the gyroscopic term vanishes or cannot be formed (a particle or
/// static body, a singular tensor, or an isotropic one such as a ball's or a cube's, for which
/// ω × I·ω = 0 for every ω).
pub(crate) fn gyroscopic_inertia(inverse: &Mat3) -> Mat3 {
    let diagonal = Vec3::new(inverse.x_axis.x, inverse.y_axis.y, inverse.z_axis.z);
    let off_diagonal = inverse.x_axis.y != 0.0
        || inverse.x_axis.z != 0.0
        || inverse.y_axis.x != 0.0
        || inverse.y_axis.z != 0.0
        || inverse.z_axis.x != 0.0
        || inverse.z_axis.y != 0.0;
    if !off_diagonal {
        if diagonal.x == diagonal.y && diagonal.y == diagonal.z {
            return Mat3::ZERO;
        }
        if diagonal.cmpgt(Vec3::ZERO).all() {
            return Mat3::from_diagonal(diagonal.recip());
        }
        return Mat3::ZERO;
    }
    if inverse.determinant().abs() > f32::MIN_POSITIVE {
        let tensor = inverse.inverse();
        if tensor.is_finite() {
            return tensor;
        }
    }
    Mat3::ZERO
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Substeps of the gyroscopic term and the orientation update, as the substep loop runs
    /// them, keep a box's kinetic energy to f32 rounding for 10 s at 1200 substeps/s: the
    /// orientation update turns the body about ω, which leaves the body-frame ω unchanged, so
    /// only the gyroscopic step may change the energy, and backward Euler only takes it out.
    #[test]
    fn gyroscopic_substeps_do_not_gain_energy() {
        let tensor = Mat3::from_diagonal(Vec3::new(0.34, 0.10, 0.26) * 20.0);
        for start in [Vec3::new(5.0, 0.05, 0.05), Vec3::new(1.0, 2.0, 3.0)] {
            let mut omega = [start];
            let mut q = [Quat::from_rotation_y(0.3)];
            let energy = |omega: Vec3, q: Quat| {
                let local = q.inverse() * omega;
                0.5 * local.dot(tensor * local)
            };
            let e0 = energy(omega[0], q[0]);
            let h = 1.0 / 1200.0;
            for _ in 0..12_000 {
                gyroscopic(&mut omega, &q, &[tensor], h);
                q[0] = integrate_orientation(q[0], omega[0], h);
                let e = energy(omega[0], q[0]);
                assert!(e < e0 * (1.0 + 1e-4), "{e} J from {e0} J");
            }
        }
    }

    /// A body spinning at thousands of rad/s turns tens of radians a substep, where one Newton
    /// step of backward Euler overshoots: over seeded random spin axes, orientations and three
    /// boxes' tensors, at 1,000–20,000 rad/s and h = 1/240 s, no substep raises the kinetic
    /// energy (beyond f32 rounding) over 60 substeps.
    #[test]
    fn a_fast_spin_gains_no_energy_in_a_substep() {
        let tensors = [
            Mat3::from_diagonal(Vec3::new(0.34, 0.10, 0.26)),
            Mat3::from_diagonal(Vec3::new(0.0122, 0.0299, 0.0199)),
            Mat3::from_diagonal(Vec3::new(1.0e-4, 2.6e-2, 2.6e-2)),
        ];
        // xorshift32, seeded: uniform in [0, 1].
        fn uniform(state: &mut u32) -> f32 {
            *state ^= *state << 13;
            *state ^= *state >> 17;
            *state ^= *state << 5;
            *state as f32 / u32::MAX as f32
        }
        fn unit(state: &mut u32) -> Vec3 {
            Vec3::new(uniform(state), uniform(state), uniform(state)) * 2.0 - 1.0
        }
        let mut state = 0x9e37_79b9_u32;
        let h = 1.0 / 240.0;
        let mut gained = 0;
        for tensor in tensors {
            for _ in 0..50 {
                let axis = unit(&mut state).normalize_or(Vec3::X);
                let spin = 1_000.0 + 19_000.0 * uniform(&mut state);
                let mut q = [Quat::from_scaled_axis(unit(&mut state) * 3.0)];
                let mut omega = [axis * spin];
                let energy = |omega: Vec3, q: Quat| {
                    let local = q.inverse() * omega;
                    0.5 * local.dot(tensor * local)
                };
                let e0 = energy(omega[0], q[0]);
                for _ in 0..60 {
                    let e = energy(omega[0], q[0]);
                    gyroscopic(&mut omega, &q, &[tensor], h);
                    let after = energy(omega[0], q[0]);
                    gained += usize::from(after > e * (1.0 + 1e-5));
                    q[0] = integrate_orientation(q[0], omega[0], h);
                }
                assert!(energy(omega[0], q[0]) <= e0 * (1.0 + 1e-5));
            }
        }
        assert_eq!(gained, 0, "substeps that gained energy");
    }

    /// The constrained step with one locked world axis, substep after substep with the
    /// orientation update, at a rotation that puts no principal axis on a world axis: the
    /// locked component of ω stays zero to the bit, the kinetic energy ½ωᵀ·I_w·ω never grows
    /// beyond f32 rounding, and ω does change (the free part of ω × I_w·ω is not zero here).
    #[test]
    fn the_step_in_the_free_plane_keeps_the_lock_and_gains_no_energy() {
        let tensor = Mat3::from_diagonal(Vec3::new(0.34, 0.10, 0.26) * 40.0);
        let start = Quat::from_euler(glam::EulerRot::XYZ, 0.4, -0.9, 1.3);
        for (locked, omega) in [
            (0, Vec3::new(0.0, 2.0, -3.0)),
            (1, Vec3::new(2.0, 0.0, -3.0)),
            (2, Vec3::new(2.0, -3.0, 0.0)),
        ] {
            let (mut omega, mut q) = (omega, start);
            let energy = |omega: Vec3, q: Quat| {
                let local = q.inverse() * omega;
                0.5 * local.dot(tensor * local)
            };
            let (omega0, e0) = (omega, energy(omega, q));
            let h = 1.0 / 1200.0;
            let mut turned = 0.0f32;
            for _ in 0..12_000 {
                gyroscopic_in_plane(&mut omega, q, &tensor, locked, h);
                assert_eq!(omega[locked], 0.0);
                q = integrate_orientation(q, omega, h);
                let e = energy(omega, q);
                assert!(e < e0 * (1.0 + 1e-4), "{e} J from {e0} J");
                turned = turned.max((omega - omega0).length());
            }
            assert!(
                turned > 0.1 * omega0.length(),
                "ω moves by {turned} rad/s at most"
            );
        }
    }
}
