//! Contact constraints, stage 4 of the step: one constraint per contact point, assembled from
//! the manifolds (Jacobian rows, effective masses, restitution and repair targets, softness)
//! and warm-started from the impulses of the last step.

pub(crate) mod constraints;
