//! Contact constraints, built in the assembly stage ([`crate::Stage::Assembly`]): one constraint per contact point, assembled from
//! the manifolds (Jacobian rows, effective masses, restitution and repair targets, softness)
//! and warm-started from the impulses of the last step.
//!
//! One job per file, each using only the files listed before it:
//! - [`roughness`]: rough surfaces' seeded tilts of new contacts' normals;
//! - [`impact`]: impacts' seeded perturbations of restitution;
//! - [`row`]: the row type ([`ContactConstraint`], [`JacobianRow`]) and its lever-arm products;
//! - [`assembly`]: contact points → rows, island by island, warm-started;
//! - [`targets`]: the rows' target velocities, per substep, and restitution's;
//! - [`record`]: J·v* per row for the step's diagnostics.

pub(crate) mod assembly;
pub(crate) mod impact;
pub(crate) mod record;
pub(crate) mod roughness;
pub(crate) mod row;
pub(crate) mod targets;

pub(crate) use assembly::*;
pub(crate) use record::*;
pub use row::*;
pub(crate) use targets::*;

#[cfg(test)]
mod tests;
