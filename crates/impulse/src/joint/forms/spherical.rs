//! The spherical joint (ball and socket, Blender's "point"): the anchors coincide, rotation is
//! free.

use super::form::JointForm;
use crate::joint::types::JointAxis;

/// [`crate::JointKind::Spherical`].
pub(crate) struct Spherical;

impl JointForm for Spherical {
    fn name(&self) -> &'static str {
        "spherical"
    }

    fn dofs(&self) -> [JointAxis; 6] {
        let (locked, free) = (JointAxis::LOCKED, JointAxis::FREE);
        [locked, locked, locked, free, free, free]
    }
}
