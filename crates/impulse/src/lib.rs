//! impulse: simultaneous contact resolution for computer animation.
//!
//! Spheres, particles and rigid bodies in piles and stacks, whose contact impulses are found
//! together as one linear complementarity problem per step and solved by Projected
//! Gauss-Seidel and its relatives (docs/method.md in the repository).
//!
//! ```
//! use impulse::glam::Vec3;
//! use impulse::{BodyBuilder, SharedShape, SolverSettings, World};
//!
//! let mut world = World::new(Vec3::new(0.0, -9.81, 0.0), 1.0 / 60.0, SolverSettings::default())?;
//! world.insert(BodyBuilder::fixed(SharedShape::cuboid(10.0, 0.5, 10.0))
//!     .translation(Vec3::new(0.0, -0.5, 0.0)))?;
//! let cube = world.insert(BodyBuilder::dynamic(SharedShape::cuboid(0.5, 0.5, 0.5))
//!     .translation(Vec3::new(0.0, 3.0, 0.0)))?;
//! for _ in 0..120 {
//!     let diagnostics = world.step()?;
//!     // How well this step's LCP was solved (m/s).
//!     assert!(diagnostics.natural_map_residual.is_finite());
//! }
//! let y = world.body(cube).unwrap().translation().y;
//! assert!((y - 0.5).abs() < 0.01, "the cube rests on the ground: y = {y}");
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! Where to start: [`World`] (insert, edit, step, read contacts and events, query),
//! [`BodyBuilder`] and [`BodyHandle`], [`SolverSettings`] (presets along the quality/speed
//! front), [`Scene`] (the JSON scene format). Each stage of the step is one module:
//! `integrate` (1, 6) → [`broad_phase`] (2) → [`narrow_phase`] (3) → [`constraints`] (4) →
//! `island` and [`solver`] (5: one island at a time, [`solver::substep`], each method behind
//! [`solver::ContactSolver`]) → `kinematic` and [`continuous`] (kinematic bodies' motion,
//! continuous collision) → [`diagnostics`] (7), driven by [`World::step`].

#![warn(missing_docs)]

pub mod body;
pub mod broad_phase;
pub mod constraints;
pub mod contact_lcp;
pub mod continuous;
pub mod diagnostics;
pub mod error;
pub(crate) mod graph;
pub(crate) mod integrate;
pub(crate) mod island;
pub(crate) mod kinematic;
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
/// `::capsule_y(half_height, r)`, `::cylinder(half_height, r)` and `::cone(half_height, r)`
/// (along y), `::convex_hull(&points)`, `::halfspace(normal)`.
pub use parry3d::shape::SharedShape;

pub use body::{BodyBuilder, BodyHandle, BodyKind, Keyframe, LockedAxes};
pub use diagnostics::StepDiagnostics;
pub use error::{SnapshotError, StepError, WorldError};
pub use scene::{BodyDesc, LockedAxesDesc, Material, MaterialRef, Scene, ShapeDesc, WorldAxis};
pub use settings::{SettingError, SolverSettings};
pub use world::{
    BodyRef, ContactEvent, ContactPairView, ContactPoint, RayHit, ShapeHit, World, WorldSnapshot,
};

/// The README's code, compiled and run as a doc-test.
#[doc = include_str!("../../../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;
