//! Bodies: mass properties and state, stored as parallel arrays (structure of arrays) so the
//! stages of the step touch only the fields they need.

use glam::{Mat3, Quat, Vec3};
use parry3d::math::Pose;
use parry3d::shape::SharedShape;

use crate::scene::BodyKind;

/// All bodies of a world. Index `i` of every array is body `i` in scene order.
///
/// Velocities are those of the centre of mass; `pose` is the body frame the scene gave
/// (trajectories report it), and `local_center_of_mass` locates the centre of mass in it.
#[derive(Clone, Default)]
pub struct Bodies {
    /// Dynamic, static or particle.
    pub kind: Vec<BodyKind>,
    /// Body frame in world coordinates.
    pub pose: Vec<Pose>,
    /// Centre of mass in the body frame (m).
    pub local_center_of_mass: Vec<Vec3>,
    /// Linear velocity of the centre of mass (m/s).
    pub linear_velocity: Vec<Vec3>,
    /// Angular velocity, world frame (rad/s). Always zero for particles and static bodies.
    pub angular_velocity: Vec<Vec3>,
    /// 1/m (1/kg); 0 for static bodies.
    pub inverse_mass: Vec<f32>,
    /// Inverse inertia tensor about the centre of mass, body frame (1/(kg·m²)); zero for
    /// static bodies and particles (rotation locked).
    pub local_inverse_inertia: Vec<Mat3>,
    /// Collision shape in the body frame.
    pub shape: Vec<SharedShape>,
    /// Coulomb friction coefficient μ.
    pub friction: Vec<f32>,
    /// Restitution coefficient c_r.
    pub restitution: Vec<f32>,
    /// Asleep: skipped by the step until something awake touches its island.
    pub asleep: Vec<bool>,
    /// How long (s) the body has been below the sleep thresholds.
    pub sleep_time: Vec<f32>,
}

impl Bodies {
    /// Number of bodies.
    pub fn len(&self) -> usize {
        self.kind.len()
    }

    /// True when there are no bodies.
    pub fn is_empty(&self) -> bool {
        self.kind.is_empty()
    }

    /// True for moving bodies that are awake: the ones the step simulates.
    pub fn is_awake(&self, i: usize) -> bool {
        self.kind[i] != BodyKind::Static && !self.asleep[i]
    }

    /// True for bodies that move (dynamic rigid bodies and particles).
    pub fn is_moving(&self, i: usize) -> bool {
        self.kind[i] != BodyKind::Static
    }

    /// World position of body `i`'s centre of mass (m).
    pub fn center_of_mass(&self, i: usize) -> Vec3 {
        self.pose[i].transform_point(self.local_center_of_mass[i])
    }

    /// World-frame inverse inertia R·I⁻¹·Rᵀ of body `i`.
    pub fn world_inverse_inertia(&self, i: usize) -> Mat3 {
        rotate_tensor(self.pose[i].rotation, &self.local_inverse_inertia[i])
    }

    /// Mass (kg) of body `i`; infinity for static bodies.
    pub fn mass(&self, i: usize) -> f32 {
        if self.inverse_mass[i] > 0.0 {
            1.0 / self.inverse_mass[i]
        } else {
            f32::INFINITY
        }
    }

    /// Kinetic energy ½mv² + ½ωᵀIω of body `i` (J); 0 for static bodies.
    pub fn kinetic_energy(&self, i: usize) -> f32 {
        if self.inverse_mass[i] == 0.0 {
            return 0.0;
        }
        let v = self.linear_velocity[i];
        let mut energy = 0.5 * v.length_squared() / self.inverse_mass[i];
        let w = self.angular_velocity[i];
        if w != Vec3::ZERO {
            // ωᵀ·I_world·ω = ω_lᵀ·I_local·ω_l with ω_l = Rᵀω: no world tensor to build, and
            // I_local = (I⁻¹_local)⁻¹ is a division per axis for the usual diagonal tensor.
            let local = self.pose[i].rotation.inverse() * w;
            let inv = &self.local_inverse_inertia[i];
            let diagonal = Vec3::new(inv.x_axis.x, inv.y_axis.y, inv.z_axis.z);
            let off_diagonal = inv.x_axis.y != 0.0
                || inv.x_axis.z != 0.0
                || inv.y_axis.x != 0.0
                || inv.y_axis.z != 0.0
                || inv.z_axis.x != 0.0
                || inv.z_axis.y != 0.0;
            if !off_diagonal && diagonal.cmpgt(Vec3::ZERO).all() {
                energy += 0.5 * local.dot(local / diagonal);
            } else if inv.determinant().abs() > f32::MIN_POSITIVE {
                energy += 0.5 * local.dot(inv.inverse() * local);
            }
        }
        energy
    }
}

/// R·T·Rᵀ: a body-frame tensor expressed in world coordinates.
pub(crate) fn rotate_tensor(rotation: Quat, tensor: &Mat3) -> Mat3 {
    let r = Mat3::from_quat(rotation);
    r * *tensor * r.transpose()
}

#[cfg(test)]
mod tests {
    use super::*;
    use parry3d::shape::Ball;

    /// ½ωᵀIω computed in the body frame equals the world-frame formula ½ωᵀ(R·I⁻¹·Rᵀ)⁻¹ω, for
    /// a diagonal tensor and a full one, at a rotation that mixes all three axes.
    #[test]
    fn rotational_energy_in_the_body_frame_matches_the_world_tensor() {
        let rotation = Quat::from_euler(glam::EulerRot::XYZ, 0.7, -1.1, 2.3);
        let full = Mat3::from_cols_array(&[0.5, 0.1, -0.05, 0.1, 0.8, 0.2, -0.05, 0.2, 1.3]);
        for inverse_inertia in [Mat3::from_diagonal(Vec3::new(0.5, 2.0, 4.0)), full] {
            let mut bodies = Bodies::default();
            bodies.kind.push(BodyKind::Dynamic);
            bodies
                .pose
                .push(Pose::from_parts(Vec3::new(1.0, 2.0, 3.0), rotation));
            bodies.local_center_of_mass.push(Vec3::ZERO);
            bodies.linear_velocity.push(Vec3::new(1.0, -2.0, 0.5));
            let omega = Vec3::new(3.0, -1.0, 2.0);
            bodies.angular_velocity.push(omega);
            bodies.inverse_mass.push(0.25);
            bodies.local_inverse_inertia.push(inverse_inertia);
            bodies.shape.push(SharedShape::new(Ball::new(0.5)));
            bodies.friction.push(0.5);
            bodies.restitution.push(0.0);
            bodies.asleep.push(false);
            bodies.sleep_time.push(0.0);
            let world = rotate_tensor(rotation, &inverse_inertia);
            let expected = 0.5 * 4.0 * Vec3::new(1.0, -2.0, 0.5).length_squared()
                + 0.5 * omega.dot(world.inverse() * omega);
            let energy = bodies.kinetic_energy(0);
            assert!(
                (energy - expected).abs() < 1e-4 * expected,
                "{energy} J against {expected} J"
            );
        }
    }
}
