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
//! and drift of a simulation's state). Inside, each stage of [`World::step`] ([`report::Stage`]
//! lists them in order) is one private module; docs/architecture.md in the repository maps
//! them.

#![warn(missing_docs)]
#![warn(unreachable_pub)]

// Every stage is private: the public API is the re-exports below, plus the namespaces
// [`scene`] (the JSON scene format and the built-in scenes), [`settings`] (the solver
// settings' parts), [`metrics`] (quality measures of a simulation's state), [`joints`] and
// [`report`] (below).
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
pub mod settings;
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
pub use diagnostics::StepDiagnostics;
pub use error::{SnapshotError, StepError, WorldError};
pub use joint::{JointBuilder, JointHandle, JointKind};
pub use scene::{BodyDesc, Material, Scene, SceneError, ShapeDesc};
pub use settings::{ContactRepair, SolverMethod, SolverSettings};
pub use world::{
    BodyRef, ContactEvent, ContactPairView, ContactPoint, LeftWorld, RayHit, ShapeHit, World,
    WorldSnapshot,
};
// The engine's own paths to items re-exported only in the modules below (its doc links name
// `crate::Stage` and the like).
#[allow(unused_imports)]
use report::{BLOW_UP_ENERGY_PER_KG, HEAVY_ON_LIGHT_CONTACTS_FACTOR, IslandReport, Stage};

/// Joints beyond their builder and handle: the axes and degrees of freedom a joint constrains,
/// its motors, springs and stiffness, and the events it reports ([`World::joint_events`]).
pub mod joints {
    pub use crate::joint::{
        AxisMode, JointAxis, JointDof, JointEvent, JointRef, JointStiffness, Motor, MotorMode,
        Spring,
    };
}

/// What a step reports beyond [`StepDiagnostics`]: the stages' timings ([`report::Stage`],
/// [`report::StepProfile`]), each island's solve ([`report::IslandReport`], with its
/// escalation level and heavy-on-light finding), the bodies' energy terms, the contact LCP's
/// export ([`World::contact_lcp`]), a crowded start ([`report::Crowd`]), and the bounds of the
/// blow-up check and of snapshots.
pub mod report {
    pub use crate::collision::crowding::Crowd;
    pub use crate::diagnostics::contact_lcp::ContactLcp;
    pub use crate::diagnostics::{EnergyTerms, SolvePhase, SolvePhaseProfile, Stage, StepProfile};
    pub use crate::solver::{
        EscalationLevel, HEAVY_ON_LIGHT_CONTACTS_FACTOR, HEAVY_ON_LIGHT_HELD_OVERLAP, HeavyOnLight,
        IslandContact, IslandReport,
    };
    pub use crate::world::{
        BLOW_UP_ENERGY_PER_KG, OLDEST_SNAPSHOT_FORMAT_VERSION, SNAPSHOT_FORMAT_VERSION,
    };
}

/// The engine's stages for benchmarks that time them one by one (`impulse-bench`'s
/// criterion benches). Not part of the supported API: names and signatures change without
/// notice. Enabled by the `internals` feature.
#[cfg(feature = "internals")]
#[doc(hidden)]
pub mod internals {
    pub use crate::body::Bodies;
    pub use crate::collision::broad_phase::BroadPhase;
    pub use crate::collision::narrow_phase::{NarrowPhase, SpeculativeMargins};
    pub use crate::contact::ContactConstraint;
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

/// The library tour's code (docs/library.md), compiled and run as a doc-test.
#[doc = include_str!("../../../docs/library.md")]
#[cfg(doctest)]
pub struct LibraryDocDoctests;
