//! Bodies: what a body is ([`BodyKind`], [`LockedAxes`], [`Keyframe`]), how it is named
//! ([`BodyHandle`]), described ([`BodyBuilder`]) and
//! stored ([`Bodies`], one array per quantity), the view of velocities a solve updates
//! ([`Velocities`]), and kinematic bodies' prescribed motion (`motion.rs`).

mod builder;
mod handle;
mod kind;
mod locked_axes;
pub(crate) mod motion;
pub(crate) mod rules;
mod shape_table;
mod storage;
#[cfg(test)]
mod tests;
mod velocities;

pub use builder::BodyBuilder;
pub(crate) use builder::build;
pub use handle::BodyHandle;
pub(crate) use handle::Handles;
pub use kind::{BodyKind, Keyframe};
pub use locked_axes::LockedAxes;
pub use rules::{MAX_IMPACT_PERTURBATION, MAX_ROUGHNESS_DEGREES, MAX_ROUGHNESS_DRAWS};
// Public for the hidden `internals` module only.
#[cfg_attr(not(feature = "internals"), allow(unreachable_pub))]
pub use storage::Bodies;
pub(crate) use storage::inertia_form;
// Public for the hidden `internals` module only.
#[cfg_attr(not(feature = "internals"), allow(unreachable_pub))]
pub use velocities::Velocities;
