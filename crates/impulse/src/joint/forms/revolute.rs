//! The revolute joint (a hinge): the anchors coincide and the only rotation is about the
//! frame's x axis, the hinge angle, its main degree of freedom (limits, spring, motor).

use super::form::JointForm;
use crate::joint::types::{JointAxis, JointDof};

/// [`crate::JointKind::Revolute`].
pub(crate) struct Revolute;

impl JointForm for Revolute {
    fn name(&self) -> &'static str {
        "revolute"
    }

    fn dofs(&self) -> [JointAxis; 6] {
        let mut dofs = [JointAxis::LOCKED; 6];
        dofs[JointDof::AngularX.index()] = JointAxis::FREE;
        dofs
    }

    fn main_dof(&self) -> Option<JointDof> {
        Some(JointDof::AngularX)
    }
}
