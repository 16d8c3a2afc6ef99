//! Bodies: what a body is ([`BodyKind`], [`LockedAxes`], [`Keyframe`]), how it is named
//! ([`BodyHandle`]), described ([`BodyBuilder`], from a builder or a scene's description) and
//! stored ([`Bodies`], one array per quantity).

mod builder;
mod from_scene;
mod handle;
mod kind;
mod locked_axes;
pub(crate) mod rules;
mod storage;
#[cfg(test)]
mod tests;

pub use builder::BodyBuilder;
pub(crate) use builder::build;
pub(crate) use from_scene::{builder_of, invalid};
pub use handle::BodyHandle;
pub(crate) use handle::Handles;
pub use kind::{BodyKind, Keyframe};
pub use locked_axes::LockedAxes;
// Public for the hidden `internals` module only.
#[cfg_attr(not(feature = "internals"), allow(unreachable_pub))]
pub use storage::Bodies;
