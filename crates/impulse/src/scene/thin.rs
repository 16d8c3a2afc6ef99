//! Thin shapes: a cuboid with a zero half extent (a plane, a card, Blender's plane exported as
//! a box) or a convex hull of coplanar points (Blender's convex hull of a plane) has no
//! volume, so no mass and no inside to push out of. It is simulated as a slab: the flat
//! shape extruded by a thickness, half on each side of its plane. The slab is an ordinary
//! solid (a cuboid, or the convex hull of the polygon's two faces), so it collides from both
//! sides, may be static, kinematic or dynamic, and has the mass and inertia of a box or
//! prism of that thickness at the material's density (a density per area σ is a density
//! σ / thickness).
//!
//! The thickness is the shape's `thickness` ([`ShapeDesc::Thickened`]), else
//! [`DEFAULT_THICKNESS`]; a flat shape without one is reported by [`super::notes`].

use super::ShapeDesc;
use super::degeneracy::{HULL_FLATNESS_TOLERANCE, hull_plane_normal};

/// Thickness (m) of a flat shape that gives none: 2 mm.
///
/// A real playing card is about 0.3 mm thick; Blender's default collision margin is 4 cm
/// (a slab of 8 cm), far too thick for a card. The thinner the slab, the sooner a body is
/// swept against static ones (continuous collision sweeps a body that moves a quarter of its
/// thickness in a step) and the narrower the ridge a card leans on. Measured on
/// `card_house_thin` (10 s, largest drift of a card): at the `default` preset it holds at 0.3,
/// 0.5, 1 and 2 mm (0.07 mm) and falls at 5 mm; at `fast` it holds at 0.5 to 2 mm (0.47 mm)
/// and falls at 0.3 and 5 mm (docs/testing.md, "Thin shapes"). 2 mm is the thickest that holds
/// at both and is thin to the eye at card size (88 × 63 mm).
pub const DEFAULT_THICKNESS: f32 = 0.002;

/// Relative tolerance of flatness: a cuboid is flat when a half extent is at most this
/// fraction of its largest, a convex hull when its points deviate from a plane by at most
/// this fraction of their extent (the tolerance of the hull volume test).
pub const FLATNESS_TOLERANCE: f64 = HULL_FLATNESS_TOLERANCE;

/// The flat axis (0, 1, 2 for x, y, z) of a cuboid whose half extents are finite and ≥ 0 and
/// exactly one of which is at most [`FLATNESS_TOLERANCE`] of the largest; `None` for a box
/// with volume, a line, a point or invalid extents.
pub(crate) fn flat_cuboid_axis(half_extents: &[f32; 3]) -> Option<usize> {
    if !half_extents.iter().all(|h| h.is_finite() && *h >= 0.0) {
        return None;
    }
    let largest = half_extents.iter().fold(0.0f32, |m, &h| m.max(h));
    let tolerance = FLATNESS_TOLERANCE * f64::from(largest);
    let mut flat = (0..3).filter(|&i| f64::from(half_extents[i]) <= tolerance);
    match (flat.next(), flat.next()) {
        (Some(axis), None) => Some(axis),
        _ => None,
    }
}

/// The unit normal of the plane of a convex hull's points when they are at least 3, finite,
/// coplanar and not collinear; `None` otherwise.
pub(crate) fn flat_hull_normal(points: &[[f32; 3]]) -> Option<[f64; 3]> {
    if points.len() < 3 || !points.iter().flatten().all(|x| x.is_finite()) {
        return None;
    }
    hull_plane_normal(points)
}

/// Whether `shape` is a flat cuboid or convex hull (by itself, not rounded or thickened).
pub(crate) fn is_flat(shape: &ShapeDesc) -> bool {
    match shape {
        ShapeDesc::Cuboid { half_extents } => flat_cuboid_axis(half_extents).is_some(),
        ShapeDesc::ConvexHull { points } => flat_hull_normal(points).is_some(),
        _ => false,
    }
}

impl ShapeDesc {
    /// The solid a thin shape is simulated as; `None` for any other shape.
    ///
    /// A flat cuboid (one half extent 0) becomes the cuboid whose half extent on that axis is
    /// half the thickness; a convex hull of coplanar points becomes the hull of those points
    /// projected on their plane (through their mean) and moved half the thickness along its
    /// normal to either side. The thickness is a [`ShapeDesc::Thickened`]'s, else
    /// [`DEFAULT_THICKNESS`]. A rounded thin shape is the slab rounded. A thickened shape
    /// that is not flat has no slab (validation rejects it).
    pub fn slab(&self) -> Option<ShapeDesc> {
        match self {
            ShapeDesc::Cuboid { .. } | ShapeDesc::ConvexHull { .. } => {
                slab_of(self, DEFAULT_THICKNESS)
            }
            ShapeDesc::Thickened { shape, thickness } => slab_of(shape, *thickness),
            ShapeDesc::Round {
                shape,
                border_radius,
            } => shape.slab().map(|slab| ShapeDesc::Round {
                shape: Box::new(slab),
                border_radius: *border_radius,
            }),
            _ => None,
        }
    }

    /// The thickness (m) a thin shape is simulated with ([`ShapeDesc::slab`]): its own or
    /// [`DEFAULT_THICKNESS`]; `None` for a shape that is not thin.
    pub fn thin_thickness(&self) -> Option<f32> {
        match self {
            ShapeDesc::Cuboid { .. } | ShapeDesc::ConvexHull { .. } if is_flat(self) => {
                Some(DEFAULT_THICKNESS)
            }
            ShapeDesc::Thickened { shape, thickness } if is_flat(shape) => Some(*thickness),
            ShapeDesc::Round { shape, .. } => shape.thin_thickness(),
            _ => None,
        }
    }
}

/// The slab of flat `shape` (a cuboid or convex hull), `thickness` thick.
fn slab_of(shape: &ShapeDesc, thickness: f32) -> Option<ShapeDesc> {
    match shape {
        ShapeDesc::Cuboid { half_extents } => {
            let axis = flat_cuboid_axis(half_extents)?;
            let mut half_extents = *half_extents;
            half_extents[axis] = 0.5 * thickness;
            Some(ShapeDesc::Cuboid { half_extents })
        }
        ShapeDesc::ConvexHull { points } => {
            let normal = flat_hull_normal(points)?;
            let to_f64 = |p: &[f32; 3]| p.map(f64::from);
            let count = points.len() as f64;
            let mut mean = [0.0f64; 3];
            for p in points {
                for (m, x) in mean.iter_mut().zip(to_f64(p)) {
                    *m += x / count;
                }
            }
            let half = 0.5 * f64::from(thickness);
            let mut slab = Vec::with_capacity(2 * points.len());
            for side in [-1.0, 1.0] {
                for p in points {
                    let p = to_f64(p);
                    let height: f64 = (0..3).map(|k| (p[k] - mean[k]) * normal[k]).sum();
                    let shift = side * half - height;
                    slab.push(std::array::from_fn(|k| (p[k] + shift * normal[k]) as f32));
                }
            }
            Some(ShapeDesc::ConvexHull { points: slab })
        }
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cuboid_is_flat_along_one_zero_half_extent() {
        assert_eq!(flat_cuboid_axis(&[10.0, 10.0, 0.0]), Some(2));
        assert_eq!(flat_cuboid_axis(&[1.0, 1e-7, 1.0]), Some(1));
        assert_eq!(flat_cuboid_axis(&[1.0, 0.5, 1.0]), None);
        assert_eq!(flat_cuboid_axis(&[1.0, 0.0, 0.0]), None, "a line");
        assert_eq!(flat_cuboid_axis(&[0.0; 3]), None, "a point");
        assert_eq!(flat_cuboid_axis(&[1.0, -1.0, 1.0]), None);
        let slab = ShapeDesc::Thickened {
            shape: Box::new(ShapeDesc::Cuboid {
                half_extents: [10.0, 10.0, 0.0],
            }),
            thickness: 0.01,
        }
        .slab();
        assert_eq!(
            slab,
            Some(ShapeDesc::Cuboid {
                half_extents: [10.0, 10.0, 0.005]
            })
        );
    }

    #[test]
    fn a_coplanar_hull_becomes_a_prism_of_its_thickness() {
        // A triangle in the tilted plane x + y + z = 1 (normal (1, 1, 1)/√3).
        let points = vec![[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let hull = ShapeDesc::ConvexHull {
            points: points.clone(),
        };
        assert_eq!(hull.thin_thickness(), Some(DEFAULT_THICKNESS));
        let Some(ShapeDesc::ConvexHull { points: slab }) = hull.slab() else {
            panic!("a flat hull has a slab");
        };
        assert_eq!(slab.len(), 6);
        let n = 1.0 / 3.0f32.sqrt();
        for (k, p) in slab.iter().enumerate() {
            // Each corner moved along the normal by ±thickness/2 from the plane.
            let height = (p[0] + p[1] + p[2]) * n - n;
            let side = if k < 3 { -1.0 } else { 1.0 };
            assert!(
                (height - side * 0.5 * DEFAULT_THICKNESS).abs() < 1e-6,
                "{p:?}"
            );
        }
        let solid = ShapeDesc::ConvexHull {
            points: vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        };
        assert_eq!(solid.slab(), None);
        assert_eq!(solid.thin_thickness(), None);
    }
}
