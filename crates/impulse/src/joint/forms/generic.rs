//! The generic (six-DOF) joint: each degree of freedom locked, limited or free on its own
//! (the builder's `dof`, the scene format's `dofs`), all locked to start with (PhysX's D6
//! joint, Jolt's six-DOF constraint, Blender's "generic").

use super::form::JointForm;
use crate::joint::types::JointAxis;

/// [`crate::JointKind::Generic`].
pub(crate) struct Generic;

impl JointForm for Generic {
    fn name(&self) -> &'static str {
        "generic"
    }

    fn dofs(&self) -> [JointAxis; 6] {
        [JointAxis::LOCKED; 6]
    }
}
