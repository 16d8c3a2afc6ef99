//! The prismatic joint (a slider): the frames keep their orientation and the only translation
//! is along the frame's x axis, its main degree of freedom (limits, spring, motor).

use super::form::JointForm;
use crate::joint::types::{JointAxis, JointDof};

/// [`crate::JointKind::Prismatic`].
pub(crate) struct Prismatic;

impl JointForm for Prismatic {
    fn name(&self) -> &'static str {
        "prismatic"
    }

    fn dofs(&self) -> [JointAxis; 6] {
        let mut dofs = [JointAxis::LOCKED; 6];
        dofs[JointDof::LinearX.index()] = JointAxis::FREE;
        dofs
    }

    fn main_dof(&self) -> Option<JointDof> {
        Some(JointDof::LinearX)
    }
}
