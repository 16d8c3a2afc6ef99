//! The distance joint: the anchors' distance kept within [min, max] (a rod when min = max, a
//! rope when min = 0), with an optional spring towards a rest length; rotation is free.
//!
//! Its first translation coordinate is the anchor distance |d|, its main degree of freedom
//! (the limits are the lengths); its row's direction is e = d/|d| (A's frame x axis when the
//! anchors meet) with A's lever arm r_A: the derivative of |d|. Its translations are never
//! locked rows (a distance is held by its limits), so the other two are measured along A's
//! frame axes with the same arm and stay free.

use glam::Vec3;

use super::form::{AnchorGeometry, JointForm, JointProblem};
use crate::joint::types::{AxisMode, JointAxis, JointDof};

/// [`crate::JointKind::Distance`].
pub(crate) struct Distance;

impl JointForm for Distance {
    fn name(&self) -> &'static str {
        "distance"
    }

    /// All free: the lengths come with the builder's `distance` or `limits`.
    fn dofs(&self) -> [JointAxis; 6] {
        [JointAxis::FREE; 6]
    }

    fn main_dof(&self) -> Option<JointDof> {
        Some(JointDof::LinearX)
    }

    fn lockable(&self, dof: JointDof) -> bool {
        dof.is_angular()
    }

    fn translation_coordinates(&self, geometry: &AnchorGeometry) -> [f32; 3] {
        [geometry.separation.length(), 0.0, 0.0]
    }

    fn translation_rows(&self, geometry: &AnchorGeometry) -> [(Vec3, Vec3); 3] {
        let length = geometry.separation.length();
        let along = if length > 1e-6 {
            geometry.separation / length
        } else {
            geometry.axes.col(0)
        };
        let arm = geometry.r_a;
        [
            (along, arm),
            (geometry.axes.col(1), arm),
            (geometry.axes.col(2), arm),
        ]
    }

    fn check_limits(&self, dof: JointDof, lower: f32, upper: f32) -> Result<(), String> {
        if dof == JointDof::LinearX && (lower < 0.0 || upper <= 0.0) {
            Err(format!(
                "lengths must be ≥ 0 with max > 0, got [{lower}, {upper}]"
            ))
        } else {
            Ok(())
        }
    }

    fn check_dofs(&self, dofs: &[JointAxis; 6]) -> Result<(), JointProblem> {
        let length = &dofs[JointDof::LinearX.index()];
        if matches!(length.mode, AxisMode::Limited { .. }) || length.spring.is_some() {
            Ok(())
        } else {
            Err(JointProblem {
                field: "limits".into(),
                message: "a distance joint needs its lengths (min, max) or a spring".into(),
            })
        }
    }
}
