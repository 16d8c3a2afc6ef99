//! [`Velocities`]: the mutable view of bodies' velocities that contact and joint solves update,
//! below both `solver/` and `joint/` so neither folder imports the other for it.

use glam::Vec3;

/// Velocities the solver updates in place: an island's local arrays, indexed by the
/// constraints' `local_a`/`local_b` (static bodies share an immovable slot; their zero inverse
/// mass and inertia make its updates exact no-ops). Public for the hidden `internals` module.
#[cfg_attr(not(feature = "internals"), allow(unreachable_pub))]
pub struct Velocities<'a> {
    /// Linear velocities (m/s).
    pub linear: &'a mut [Vec3],
    /// Angular velocities (rad/s).
    pub angular: &'a mut [Vec3],
}
