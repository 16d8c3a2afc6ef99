//! [`JointForm`]: what one joint form decides (its name, its degrees of freedom, the geometry of
//! its translation rows and its own checks), with the frame-aligned defaults most forms keep.

use glam::{Mat3, Vec3};

use crate::joint::types::{JointAxis, JointDof};

/// A broken rule of a joint's values: the field (relative to the joint, e.g. `limits.lower`)
/// and what is wrong.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct JointProblem {
    pub field: String,
    pub message: String,
}

/// Where a joint's anchors and A's frame are at given poses: what a form's translation rows
/// are measured from.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct AnchorGeometry {
    /// World lever arm from A's centre of mass to A's anchor (m).
    pub r_a: Vec3,
    /// World lever arm from B's centre of mass to B's anchor (m).
    pub r_b: Vec3,
    /// B's anchor minus A's (m).
    pub separation: Vec3,
    /// A's frame axes in the world, as columns (x, y, z).
    pub axes: Mat3,
}

/// One joint form (fixed, spherical, revolute, …): a unit type in its own file of
/// `joint/forms/`, registered once in `joint/forms/mod.rs`, which makes it a [`JointKind`]
/// variant. The solver, the direct solve of the locked rows and the world ask the form only
/// through these methods; every form solves the same rows per degree of freedom (lock, limits,
/// spring, motor: `joint/rows.rs`), and a form changes which are there and how its
/// translations are measured.
///
/// The defaults are the frame-aligned joint: translations along A's frame axes, with the
/// Jacobian (−e, −(r_A + d) × e, e, r_B × e) of the derivative of e·d as e turns with A (d the
/// anchor separation); every locked degree of freedom held by a lock row; no checks beyond the
/// common ones (`joint/rules.rs`).
///
/// [`JointKind`]: crate::JointKind
pub(crate) trait JointForm: Sync {
    /// Its name in scene files (`"type"`), errors and Python: lower case, unique.
    fn name(&self) -> &'static str;

    /// The degrees of freedom a new joint of this form starts with (index order of
    /// [`JointDof`]).
    fn dofs(&self) -> [JointAxis; 6];

    /// The one non-locked degree of freedom that the builder's `limits`, `spring` and `motor`
    /// act on (and the scene format's fields of those names); `None`: the form has none.
    fn main_dof(&self) -> Option<JointDof> {
        None
    }

    /// Whether a locked degree of freedom is held by a lock row (in a locked group and the
    /// direct solve); a form measuring its translations otherwise may leave them unlocked.
    fn lockable(&self, _dof: JointDof) -> bool {
        true
    }

    /// The translation coordinates of B's anchor relative to A's at `geometry` (m): by
    /// default the separation along A's frame axes.
    fn translation_coordinates(&self, geometry: &AnchorGeometry) -> [f32; 3] {
        std::array::from_fn(|i| geometry.axes.col(i).dot(geometry.separation))
    }

    /// Each translation row's direction e and A's lever arm at `geometry`: its Jacobian is
    /// (−e, −arm × e, e, r_B × e). By default e is A's frame axis and the arm r_A + d.
    fn translation_rows(&self, geometry: &AnchorGeometry) -> [(Vec3, Vec3); 3] {
        std::array::from_fn(|i| (geometry.axes.col(i), geometry.r_a + geometry.separation))
    }

    /// Checks limits [`lower`, `upper`] on `dof`, after the common checks (finite, ordered,
    /// angles within [−π, π]); the message of the first problem.
    fn check_limits(&self, _dof: JointDof, _lower: f32, _upper: f32) -> Result<(), String> {
        Ok(())
    }

    /// Checks the degrees of freedom together, after the common checks of each.
    fn check_dofs(&self, _dofs: &[JointAxis; 6]) -> Result<(), JointProblem> {
        Ok(())
    }
}
