//! impulse: simultaneous contact resolution for computer animation.
//!
//! Spheres, particles and rigid bodies in piles and stacks, whose contact impulses are found
//! together as one linear complementarity problem per step and solved by Projected
//! Gauss-Seidel and its relatives (docs/method.md). Each stage of the step is one module:
//! [`integrate`] (1, 6) → [`broad_phase`] (2) → [`narrow_phase`] (3) → [`constraints`] (4) →
//! [`island`] and [`solver`] (5: one island at a time, [`solver::substep`], each method behind
//! [`solver::ContactSolver`]) → [`diagnostics`] (7), driven by [`World::step`].

pub mod body;
pub mod broad_phase;
pub mod constraints;
pub mod contact_lcp;
pub mod diagnostics;
pub mod error;
pub(crate) mod graph;
pub mod integrate;
pub mod island;
pub mod metrics;
pub mod narrow_phase;
pub(crate) mod parallel;
pub mod scene;
pub mod settings;
pub mod solver;
pub mod world;

/// The vector types of the API (the version Parry uses), so a user needs no glam of their own.
pub use glam;
/// The geometry library behind shapes and queries, so a user needs no parry3d of their own.
pub use parry3d;
/// Shapes to build bodies from: `SharedShape::ball(r)`, `::cuboid(hx, hy, hz)`,
/// `::capsule_y(half_height, r)`, `::convex_hull(&points)`, `::halfspace(normal)`.
pub use parry3d::shape::SharedShape;

pub use body::{BodyBuilder, BodyHandle, BodyKind};
pub use diagnostics::StepDiagnostics;
pub use error::{StepError, WorldError};
pub use scene::{BodyDesc, Material, MaterialRef, Scene, ShapeDesc};
pub use settings::SolverSettings;
pub use world::{BodyRef, ContactEvent, ContactPairView, ContactPoint, RayHit, ShapeHit, World};
