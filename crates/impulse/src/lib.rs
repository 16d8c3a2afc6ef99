//! impulse: simultaneous contact resolution for computer animation.
//!
//! Spheres, particles and rigid bodies in piles and stacks, whose contact impulses are found
//! together as one linear complementarity problem per step and solved by Projected
//! Gauss-Seidel, following `contact-resolution-notes.md` (the "seed"). See DESIGN.md for the
//! pipeline; each stage is one module:
//! [`integrate`] (1, 6) → [`broad_phase`] (2) → [`narrow_phase`] (3) → [`constraints`] (4) →
//! [`solver`] (5; in SIMD lanes [`simd`]; with [`apgd`], [`exact`] and the per-island policy of [`island`]) →
//! [`diagnostics`] (7), driven by [`World::step`].

pub mod apgd;
pub mod body;
pub mod broad_phase;
pub mod constraints;
pub mod contact_lcp;
pub mod diagnostics;
pub mod error;
pub mod exact;
pub mod integrate;
pub mod island;
pub mod metrics;
pub mod narrow_phase;
pub mod scene;
pub mod settings;
pub mod simd;
pub mod solver;
pub mod world;

pub use error::{StepError, WorldError};
pub use scene::{BodyDesc, BodyKind, Material, MaterialRef, Scene, ShapeDesc};
pub use settings::SolverSettings;
pub use world::World;
