//! Notes on a valid scene: what the engine does with a value that it accepts but that the
//! user may not expect (a flat shape given a default thickness). The command line prints them
//! as `warning:` lines, the Python package as warnings.

use std::fmt;

use super::error::{BodyLocation, FieldPath, SceneError, SceneErrorKind};
use super::thin::{DEFAULT_THICKNESS, flat_cuboid_axis, is_flat};
use super::{Scene, ShapeDesc};

/// A note on one value of a scene: where it is and what the engine makes of it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SceneNote {
    /// The body concerned.
    pub body: BodyLocation,
    /// Path of the value from the root of the scene (e.g. `bodies[2].shape`).
    pub field: FieldPath,
    /// What the engine does, without the location.
    pub message: String,
}

impl fmt::Display for SceneNote {
    /// `bodies[2] ("card").shape: …`, located as a [`SceneError`] is.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut located = SceneError::new(
            SceneErrorKind::Invalid,
            Some(self.field.clone()),
            self.message.clone(),
        );
        located.body = Some(self.body.clone());
        write!(f, "{located}")
    }
}

/// The notes on `scene`, in body order: each flat cuboid or convex hull without a
/// `thickness` (a thin shape simulated with [`DEFAULT_THICKNESS`], [`ShapeDesc::slab`]),
/// compound parts included. Meant for a scene that [`super::validate`] accepts.
pub fn notes(scene: &Scene) -> Vec<SceneNote> {
    let mut notes = Vec::new();
    for (index, body) in scene.bodies.iter().enumerate() {
        let location = BodyLocation {
            index,
            name: body.name.clone(),
        };
        let mut note = |field: FieldPath, message: String| {
            notes.push(SceneNote {
                body: location.clone(),
                field,
                message,
            });
        };
        let path = FieldPath::body(index).key("shape");
        match &body.shape {
            ShapeDesc::Compound { parts } => {
                for (k, part) in parts.iter().enumerate() {
                    let part_path = path.key("parts").index(k).key("shape");
                    if let Some(message) = default_thickness_note(&part.shape) {
                        note(part_path, message);
                    }
                }
            }
            shape => {
                if let Some(message) = default_thickness_note(shape) {
                    note(path, message);
                }
            }
        }
    }
    notes
}

/// The note on a flat shape without a thickness, or `None`.
fn default_thickness_note(shape: &ShapeDesc) -> Option<String> {
    let flat = match shape {
        ShapeDesc::Round { shape, .. } => shape.as_ref(),
        other => other,
    };
    if !is_flat(flat) {
        return None;
    }
    let what = match flat {
        ShapeDesc::Cuboid { half_extents } => {
            let axis = flat_cuboid_axis(half_extents).map_or(0, |a| a);
            format!("the box is flat (half_extents[{axis}] is 0)")
        }
        _ => "the convex hull points are coplanar".to_string(),
    };
    Some(format!(
        "{what}: simulated as a slab {} mm thick centred on its plane, the default thickness; \
         give \"thickness\" (m) to choose it",
        DEFAULT_THICKNESS * 1e3
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{BodyDesc, BodyKind, CompoundPart};

    #[test]
    fn a_flat_shape_without_thickness_is_noted() {
        let flat = ShapeDesc::Cuboid {
            half_extents: [1.0, 0.0, 1.0],
        };
        let mut scene = Scene::default();
        scene
            .bodies
            .push(BodyDesc::new(BodyKind::Static, flat.clone(), [0.0; 3]));
        let mut card = BodyDesc::new(
            BodyKind::Dynamic,
            ShapeDesc::Thickened {
                shape: Box::new(flat.clone()),
                thickness: 0.001,
            },
            [0.0; 3],
        );
        card.name = Some("card".into());
        scene.bodies.push(card);
        let mut compound = BodyDesc::new(
            BodyKind::Dynamic,
            ShapeDesc::Compound {
                parts: vec![CompoundPart {
                    shape: ShapeDesc::ConvexHull {
                        points: vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]],
                    },
                    position: [0.0; 3],
                    orientation: [0.0, 0.0, 0.0, 1.0],
                }],
            },
            [0.0; 3],
        );
        compound.name = Some("lid".into());
        scene.bodies.push(compound);
        let notes: Vec<String> = notes(&scene).iter().map(ToString::to_string).collect();
        assert_eq!(
            notes,
            [
                "bodies[0].shape: the box is flat (half_extents[1] is 0): simulated as a slab \
                 2 mm thick centred on its plane, the default thickness; give \"thickness\" (m) \
                 to choose it",
                "bodies[2] (\"lid\").shape.parts[0].shape: the convex hull points are coplanar: \
                 simulated as a slab 2 mm thick centred on its plane, the default thickness; \
                 give \"thickness\" (m) to choose it",
            ]
        );
    }
}
