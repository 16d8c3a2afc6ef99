//! Scene pieces shared by the solver tests (`mod common;` in each test file that uses them).
#![allow(dead_code)] // each test binary uses its own subset

use glam::Vec3;
use impulse::{BodyDesc, BodyKind, Material, ShapeDesc};

/// Material with Coulomb coefficient `friction`, no restitution, density 1000 kg/m³.
pub fn material(friction: f32) -> Material {
    Material {
        friction,
        restitution: 0.0,
        density: 1000.0,
    }
}

/// A static cuboid of half extents `half` (m) centred at `position` (m).
pub fn static_box(half: Vec3, position: Vec3) -> BodyDesc {
    BodyDesc::new(
        BodyKind::Static,
        ShapeDesc::Cuboid {
            half_extents: half.to_array(),
        },
        position.to_array(),
    )
}
