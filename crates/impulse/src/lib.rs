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
//! front), [`Scene`] and the [`scene`] module (the JSON scene format and built-in scenes),
//! [`StepDiagnostics`] (how well each step's LCP was solved) and [`metrics`] (sink, overlap
//! and drift of a simulation's state). Inside, each stage of [`World::step`] is one private
//! module: integrate (1, 6) → broad phase (2) → narrow phase (3) → constraints (4) → islands
//! and the solver (5: one island at a time, each method behind one interface) → kinematic
//! bodies and continuous collision → diagnostics (7); docs/architecture.md in the repository
//! maps them.

#![warn(missing_docs)]
#![warn(unreachable_pub)]

// Every stage is private: the public API is the re-exports below, plus two namespaces,
// [`scene`] (the JSON scene format and the built-in scenes) and [`metrics`] (quality measures
// of a simulation's state).
mod body;
// The stages the hidden `internals` module re-exports keep those items `pub`: without the
// feature they are unreachable, which is their point.
#[cfg_attr(not(feature = "internals"), allow(unreachable_pub))]
mod collision;
#[cfg_attr(not(feature = "internals"), allow(unreachable_pub))]
mod contact;
mod diagnostics;
mod error;
mod graph;
mod integrate;
mod island;
mod joint;
mod parallel;
mod profile;
mod settings;
#[cfg_attr(not(feature = "internals"), allow(unreachable_pub))]
mod solver;
mod world;

pub mod metrics;
pub mod scene;
pub mod simd;

// The unit tests share `tests/integration/common.rs` with the integration tests, whose paths start with
// `impulse::`.
#[cfg(test)]
extern crate self as impulse;
#[cfg(test)]
mod test_support;
// The numbers the docs state that the code fixes, checked against the code.
#[cfg(test)]
mod doc_facts_tests;

/// The vector types of the API (the version Parry uses), so a user needs no glam of their own.
pub use glam;
/// The LCP types of [`World::contact_lcp`]'s export and the solvers to run on it.
pub use impulse_lcp;
/// The geometry library behind shapes and queries, so a user needs no parry3d of their own.
pub use parry3d;
/// Shapes to build bodies from: `SharedShape::ball(r)`, `::cuboid(hx, hy, hz)`,
/// `::capsule_y(half_height, r)`, `::cylinder(half_height, r)` and `::cone(half_height, r)`
/// (along y), `::convex_hull(&points)`, `::halfspace(normal)`.
pub use parry3d::shape::SharedShape;

pub use body::{BodyBuilder, BodyHandle, BodyKind, Keyframe, LockedAxes};
pub use collision::crowding::Crowd;
pub use diagnostics::contact_lcp::ContactLcp;
pub use diagnostics::{
    EnergyTerms, SolvePhase, SolvePhaseProfile, Stage, StepDiagnostics, StepProfile,
};
pub use error::{SnapshotError, StepError, WorldError};
pub use joint::{
    AxisMode, JointAxis, JointBuilder, JointDof, JointEvent, JointHandle, JointKind, JointRef,
    JointStiffness, Motor, MotorMode, Spring,
};
pub use scene::{
    BodyDesc, LockedAxesDesc, Material, MaterialRef, Scene, SceneError, ShapeDesc, WorldAxis,
};
pub use scene::{Jitter, Override, Variation};
pub use settings::{
    CombineRule, ContactRepair, DEFAULT_MAX_ANGULAR_SPEED, DEFAULT_MAX_LINEAR_SPEED, ImpactModel,
    MAX_PAIRS_PER_BODY, SettingError, SolverMethod, SolverSettings,
};
pub use solver::{
    EscalationLevel, HEAVY_ON_LIGHT_CONTACTS_FACTOR, HEAVY_ON_LIGHT_HELD_OVERLAP, HeavyOnLight,
    IslandContact, IslandReport,
};
pub use world::LeftWorld;
pub use world::{
    BLOW_UP_DISTANCE, BLOW_UP_ENERGY_PER_KG, BodyRef, ContactEvent, ContactPairView, ContactPoint,
    OLDEST_SNAPSHOT_FORMAT_VERSION, RayHit, SNAPSHOT_FORMAT_VERSION, ShapeHit, World,
    WorldSnapshot,
};

/// The engine's stages for benchmarks that time them one by one (`impulse-bench`'s
/// criterion benches). Not part of the supported API: names and signatures change without
/// notice. Enabled by the `internals` feature.
#[cfg(feature = "internals")]
#[doc(hidden)]
pub mod internals {
    pub use crate::body::Bodies;
    pub use crate::collision::broad_phase::BroadPhase;
    pub use crate::collision::narrow_phase::{NarrowPhase, SpeculativeMargins};
    pub use crate::contact::constraints::ContactConstraint;
    pub use crate::solver::nncg::{NncgWorkspace, solve_nncg};
    pub use crate::solver::pgs::solve_pgs;
    pub use crate::solver::{Sweep, Velocities, warm_start};

    /// The world's body storage, as the stages read it.
    pub fn bodies(world: &crate::World) -> &Bodies {
        &world.bodies
    }

    /// The last step's solved contact constraints (impulses as the solver left them).
    pub fn contact_constraints(world: &crate::World) -> Vec<ContactConstraint> {
        world.contact_constraints()
    }
}

/// The README's code, compiled and run as a doc-test.
#[doc = include_str!("../../../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;
