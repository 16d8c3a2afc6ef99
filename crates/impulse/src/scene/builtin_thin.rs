//! The built-in scene of thin shapes: `card_house_thin`, a two-storey house of playing cards
//! given as flat cuboids (no thickness in the scene: each is simulated as a slab of
//! [`DEFAULT_THICKNESS`], `super::thin`).

use super::thin::DEFAULT_THICKNESS;
use super::{BodyDesc, BodyKind, Material, Scene, ShapeDesc};

/// Half extents (m) of a playing card of `card_house_thin` (88 × 63 mm): 0 along local x (the
/// card is flat), height along local y, width along local z.
pub(super) const PLAYING_CARD_HALF_EXTENTS: [f32; 3] = [0.0, 0.044, 0.0315];
/// Tilt (degrees) of the leaning cards of `card_house_thin` from the vertical.
pub(super) const PLAYING_CARD_TILT_DEGREES: f64 = 22.5;
/// Distance (m) in x between the apexes of the two bottom A-frames of `card_house_thin`:
/// 0.86 of a card's height, as `card_house`'s.
pub(super) const PLAYING_CARD_APEX_SPACING: f64 = 0.86 * 0.088;

/// A card at `position` turned by `angle` (radians) about the z axis, `thickness` thick if
/// given (else flat without a thickness).
fn card(position: [f64; 3], angle: f64, thickness: Option<f32>) -> BodyDesc {
    let flat = ShapeDesc::Cuboid {
        half_extents: PLAYING_CARD_HALF_EXTENTS,
    };
    let shape = match thickness {
        Some(thickness) => ShapeDesc::Thickened {
            shape: Box::new(flat),
            thickness,
        },
        None => flat,
    };
    let mut card = BodyDesc::new(BodyKind::Dynamic, shape, position.map(|x| x as f32));
    let half = angle / 2.0;
    card.orientation = [0.0, 0.0, half.sin() as f32, half.cos() as f32];
    card
}

/// Two storeys of leaning playing cards, each covered by a flat card, on a static ground
/// box of half extents (1, 0.5, 1) whose top is y = 0; friction 0.6, density 1000.
///
/// The cards stand as `card_house`'s (its A-frame formula, with t half the default thickness
/// of a flat shape and (h, w) = (0.044, 0.0315) m): storey 0 is two A-frames with apexes at
/// x = ∓0.0378 and a flat card on them; storey 1 is one A-frame at x = 0 on that flat card
/// and a flat card on top. 8 cards. Nothing overlaps; the contacts touch exactly. (A third
/// storey, an A-frame on the top card, rests on a ridge as wide as two card thicknesses and
/// falls at friction 0.6: `card_house_thin` is `card_house` at playing-card size.)
pub(super) fn card_house_thin() -> Scene {
    card_house(None)
}

/// `card_house_thin` with cards `thickness` thick (the default when `None`).
fn card_house(thickness: Option<f32>) -> Scene {
    let mut scene = Scene {
        name: "card_house_thin".to_string(),
        materials: [(
            "default".to_string(),
            Material {
                friction: 0.6,
                restitution: 0.0,
                density: 1000.0,
                roughness: 0.0,
                impact_perturbation: 0.0,
            },
        )]
        .into(),
        ..Scene::default()
    };
    let mut ground = BodyDesc::new(
        BodyKind::Static,
        ShapeDesc::Cuboid {
            half_extents: [1.0, 0.5, 1.0],
        },
        [0.0, -0.5, 0.0],
    );
    ground.name = Some("ground".to_string());
    scene.bodies.push(ground);
    let theta = PLAYING_CARD_TILT_DEGREES.to_radians();
    let t = 0.5 * f64::from(thickness.unwrap_or(DEFAULT_THICKNESS));
    let h = f64::from(PLAYING_CARD_HALF_EXTENTS[1]);
    let dx = h * theta.sin() + t * theta.cos();
    let dy = h * theta.cos() + t * theta.sin();
    let frame_height = 2.0 * dy;
    let flat = std::f64::consts::FRAC_PI_2;
    let a_frame = |scene: &mut Scene, apex: f64, floor: f64| {
        scene
            .bodies
            .push(card([apex - dx, floor + dy, 0.0], -theta, thickness));
        scene
            .bodies
            .push(card([apex + dx, floor + dy, 0.0], theta, thickness));
    };
    let a = PLAYING_CARD_APEX_SPACING / 2.0;
    a_frame(&mut scene, -a, 0.0);
    a_frame(&mut scene, a, 0.0);
    let storey = frame_height + 2.0 * t;
    scene
        .bodies
        .push(card([0.0, storey - t, 0.0], flat, thickness));
    a_frame(&mut scene, 0.0, storey);
    scene
        .bodies
        .push(card([0.0, 2.0 * storey - t, 0.0], flat, thickness));
    scene
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{SolverSettings, World};

    /// The largest distance (m) any card of `scene` moves from its start in `steps` steps.
    fn largest_drift(scene: &Scene, steps: usize) -> f32 {
        let mut world = World::from_scene(scene).unwrap();
        let start: Vec<_> = world.poses().iter().map(|p| p.translation).collect();
        let mut drift = 0.0f32;
        for _ in 0..steps {
            world.step().unwrap();
            for (pose, start) in world.poses().iter().zip(&start) {
                drift = drift.max((pose.translation - *start).length());
            }
        }
        drift
    }

    /// The measurement behind [`DEFAULT_THICKNESS`]: the card house's largest drift in 10 s at
    /// each thickness and preset (docs/testing.md, "Thin shapes").
    #[test]
    #[ignore = "a sweep of 10 s runs; run explicitly"]
    fn card_house_drift_by_thickness() {
        for preset in ["fast", "default"] {
            for thickness in [0.0003f32, 0.0005, 0.001, 0.002, 0.005] {
                let mut scene = card_house(Some(thickness));
                scene.solver = SolverSettings::preset(preset).unwrap();
                let drift = largest_drift(&scene, 600);
                println!(
                    "{preset}: thickness {:.1} mm: largest drift {:.3} mm",
                    thickness * 1e3,
                    drift * 1e3
                );
            }
        }
    }
}
