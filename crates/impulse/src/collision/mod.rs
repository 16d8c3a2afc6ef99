//! Collision detection, the broad phase and narrow phase stages of the step
//! ([`crate::Stage::BroadPhase`], [`crate::Stage::NarrowPhase`]): the broad phase turns loosened
//! bounding boxes into candidate pairs, the narrow phase turns candidates into persistent contact
//! manifolds (Parry) with the speculative margins that decide how far ahead points are made;
//! and the sweeps of continuous collision (`continuous.rs`, for [`crate::Stage::Continuous`]).

pub(crate) mod axis_memory;
pub(crate) mod broad_phase;
pub(crate) mod caps;
pub(crate) mod concave_planes;
pub(crate) mod continuous;
pub(crate) mod crowding;
pub(crate) mod deepest_vertex;
pub(crate) mod dispatch;
pub(crate) mod faces;
pub(crate) mod manifold;
pub(crate) mod manifold_record;
pub(crate) mod margins;
pub(crate) mod narrow_phase;
pub(crate) mod overlap;
pub(crate) mod part_pairs;
pub(crate) mod separating_axes;

#[cfg(test)]
#[path = "hull_pairs_tests.rs"]
mod hull_pairs_tests;
