//! Joints against closed forms: pendulum periods (the exact elliptic-integral period), a double
//! pendulum's energy, chains hanging at rest (stretch, a 1:100 heavy end), a hinge door hit by a
//! ball (limit, impact closed form), a door slammed onto its limit, a motorised wheel, a ragdoll
//! at rest on stairs, a breakable wall, a beam broken by a falling ball; and the API's checks,
//! snapshots and the exported mixed LCP.

mod chains;
mod devices;
mod exact;
mod fracture;
mod limits;
mod pendulum;

use impulse::glam::Vec3;
use impulse::{BodyBuilder, BodyHandle, SharedShape, SolverSettings, World};

/// A world with gravity −9.81 m/s² along y at dt = 1/60 s with `settings`.
pub(crate) fn world(settings: SolverSettings) -> World {
    World::new(Vec3::new(0.0, -9.81, 0.0), 1.0 / 60.0, settings).expect("a valid world")
}

/// A static anchor (a small ball that collides with nothing) at `at`.
pub(crate) fn anchor(world: &mut World, at: Vec3) -> BodyHandle {
    world
        .insert(
            BodyBuilder::fixed(SharedShape::ball(0.01))
                .translation(at)
                .collision_groups(0, 0),
        )
        .expect("an anchor")
}

/// Kinetic energy of all bodies plus their gravitational energy (J) relative to y = 0.
pub(crate) fn mechanical_energy(world: &World) -> f64 {
    let e = world.energy();
    e.mechanical()
}
