//! The fixed joint: all six degrees of freedom locked, the bodies move as one (Blender's
//! "fixed", Box2D's weld joint).

use super::form::JointForm;
use crate::joint::types::JointAxis;

/// [`crate::JointKind::Fixed`].
pub(crate) struct Fixed;

impl JointForm for Fixed {
    fn name(&self) -> &'static str {
        "fixed"
    }

    fn dofs(&self) -> [JointAxis; 6] {
        [JointAxis::LOCKED; 6]
    }
}
