//! Contact events: which pairs started or stopped touching in the last step, and the state
//! kept between steps to tell (the world fills it in `contacts.rs`).

use serde::{Deserialize, Serialize};

use crate::body::BodyHandle;

/// A change in which pairs of bodies touch, from one step to the next ([`crate::World::contact_events`]).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum ContactEvent {
    /// The bodies touch now and did not at the end of the step before.
    Started {
        /// The body with the smaller handle.
        body1: BodyHandle,
        /// The other body.
        body2: BodyHandle,
        /// Their total normal impulse in the step (N·s): how hard they met.
        normal_impulse: f32,
    },
    /// The bodies touched at the end of the step before and do not now (one may have been
    /// removed).
    Stopped {
        /// The body with the smaller handle.
        body1: BodyHandle,
        /// The other body.
        body2: BodyHandle,
    },
}

/// Which pairs touched at the end of the last step, and the events that step produced. Both
/// lists are kept and reused, so tracking events allocates nothing once they have grown.
#[derive(Clone, Default, Serialize, Deserialize)]
pub(crate) struct ContactEvents {
    /// Touching pairs (smaller handle first) with their total normal impulse, sorted.
    pub(super) touching: Vec<(BodyHandle, BodyHandle, f32)>,
    /// The same for the step just taken, before it replaces `touching`.
    pub(super) now: Vec<(BodyHandle, BodyHandle, f32)>,
    /// The events of the last step.
    pub(super) events: Vec<ContactEvent>,
}
