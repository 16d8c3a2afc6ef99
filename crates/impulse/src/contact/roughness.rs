//! Rough surfaces: each new contact manifold between bodies of which one is rough
//! ([`crate::BodyBuilder::roughness`]) gets a draw that tilts its normal by a small angle,
//! kept for as long as the manifold lasts (Chenney & Forsyth, "Sampling plausible solutions to
//! multi-body constraint problems", SIGGRAPH 2000; Barzel, Hughes & Wood, "Plausible motion
//! simulation for computer graphics animation", 1996: small random changes at contacts are
//! physically plausible, and they vary a pile's outcome from one seed to the next).
//!
//! A body's explicit draws ([`crate::BodyBuilder::roughness_draws`]: standard-normal pairs,
//! mapped by [`explicit_draw`] to the seeded draws' distribution) come first; otherwise the
//! draw is keyed by (world seed, step at which the manifold appeared, the pair's body
//! indices, the manifold's index in the pair) through the SplitMix64 finaliser (Steele, Lea &
//! Flood, "Fast splittable pseudorandom number generators", OOPSLA 2014): integer arithmetic, so
//! it is the same on every machine, thread count and backend. The tilt is uniform over the
//! spherical cap of half-angle `roughness` around the normal; its direction is measured from an
//! axis fixed in body 1's part frame, so it turns with the body and does not drift from step to
//! step.

use crate::body::Bodies;
use crate::collision::manifold::RoughnessDraw;
use crate::collision::narrow_phase::ContactPair;
use glam::Vec3;
use parry3d::math::Pose;
use parry3d::shape::{Shape, TypedShape};

/// The largest roughness (rad) of a pair's two bodies: the pair's.
#[inline]
pub(crate) fn pair_roughness(bodies: &Bodies, a: usize, b: usize) -> f32 {
    bodies.roughness[a].max(bodies.roughness[b])
}

/// Gives every manifold with points that has no draw yet, of every pair with a rough body, its
/// draw: the next explicit draw of the pair's first body ([`Bodies::roughness_draws`]), else
/// of its second, else the seeded draw for `seed` at `step`. Called once a step, after the
/// narrow phase. The pairs are sorted by (body1, body2) and each pair's manifolds are in
/// Parry's order, and this loop is sequential, so the explicit draws are given in the same
/// order on any number of threads.
pub(crate) fn draw_new_manifolds(
    pairs: &mut [ContactPair],
    bodies: &mut Bodies,
    seed: u64,
    step: u64,
) {
    for pair in pairs.iter_mut() {
        let (b1, b2) = (pair.body1, pair.body2);
        if pair_roughness(bodies, b1 as usize, b2 as usize) <= 0.0 {
            continue;
        }
        for (index, manifold) in pair.manifolds.iter_mut().enumerate() {
            if manifold.points.is_empty() || manifold.data.roughness.is_some() {
                continue;
            }
            let n = manifold.local_n1.abs();
            let axis = if n.x <= n.y && n.x <= n.z {
                0
            } else if n.y <= n.z {
                1
            } else {
                2
            };
            let (cap, azimuth) = match next_explicit_draw(bodies, b1 as usize)
                .or_else(|| next_explicit_draw(bodies, b2 as usize))
            {
                Some([a, b]) => explicit_draw(a, b),
                None => {
                    let key = [
                        seed,
                        step,
                        u64::from(b1) << 32 | u64::from(b2),
                        index as u64,
                    ];
                    let bits = mix(&key);
                    (unit(bits), unit(bits >> 32) * std::f32::consts::TAU)
                }
            };
            manifold.data.roughness = Some(RoughnessDraw { cap, azimuth, axis });
        }
    }
}

/// Body `body`'s next explicit draw, counted as given; `None` once it has given them all.
fn next_explicit_draw(bodies: &mut Bodies, body: usize) -> Option<[f32; 2]> {
    let given = &mut bodies.roughness_draws_given[body];
    let draw = *bodies.roughness_draws[body].get(*given as usize)?;
    *given += 1;
    Some(draw)
}

/// The largest f32 below 1: a cap is in [0, 1).
const LARGEST_CAP: f32 = 1.0 - f32::EPSILON / 2.0;

/// The (cap, azimuth) of an explicit draw (a, b) in standard-normal coordinates:
/// cap = 1 − exp(−(a² + b²)/2) in [0, 1) and azimuth = atan2(b, a) in [0, 2π) (rad). For
/// (a, b) ~ N(0, I₂), (a² + b²)/2 is exponential with mean 1, so the cap is uniform, and the
/// azimuth is uniform and independent of it: the seeded draws' distribution. Continuous in
/// (a, b) (the azimuth wraps from 2π to 0 along the positive a axis, the same direction).
/// Computed in f64 and rounded to f32 once.
pub(crate) fn explicit_draw(a: f32, b: f32) -> (f32, f32) {
    let (a, b) = (f64::from(a), f64::from(b));
    let cap = (-(-(a * a + b * b) / 2.0).exp_m1()) as f32;
    let mut azimuth = b.atan2(a);
    if azimuth < 0.0 {
        azimuth += std::f64::consts::TAU;
    }
    let azimuth = azimuth as f32;
    let azimuth = if azimuth < std::f32::consts::TAU {
        azimuth
    } else {
        0.0
    };
    (cap.clamp(0.0, LARGEST_CAP), azimuth)
}

/// `normal` (world, unit) tilted by `draw` for a pair of roughness `roughness` (rad), with
/// body 1's part pose `part1` (the azimuth's axis turns with it).
#[inline]
pub(crate) fn tilted(normal: Vec3, draw: &RoughnessDraw, roughness: f32, part1: &Pose) -> Vec3 {
    let cos_tilt = 1.0 - draw.cap * (1.0 - roughness.cos());
    let sin_tilt = (1.0 - cos_tilt * cos_tilt).max(0.0).sqrt();
    let mut reference = Vec3::ZERO;
    reference[draw.axis as usize] = 1.0;
    let reference = part1.rotation * reference;
    let along = reference - normal * normal.dot(reference);
    let (d0, d1) = if along.length_squared() > 1e-6 {
        let d0 = along.normalize();
        (d0, normal.cross(d0))
    } else {
        normal.any_orthonormal_pair()
    };
    let (s, c) = draw.azimuth.sin_cos();
    (normal * cos_tilt + (d0 * c + d1 * s) * sin_tilt).normalize()
}

/// How a part's surface is round where a contact touches it: the tilted normal of a rough
/// contact passes through its centre of curvature, so the contact point moves with the tilt.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Roundness {
    /// Round in every direction about a centre (world, m): a ball, a capsule's end.
    Centre(Vec3),
    /// Round about an axis through a point (world, m) along a unit direction (world): a
    /// capsule's side, a cylinder's side and rim, a cone's side and rim. Along the axis the
    /// surface is straight (a side) or sharp (a rim), so only the tilt about the axis moves
    /// the point.
    Axis(Vec3, Vec3),
}

/// Relative position along a capsule's segment within which a point counts as at its end.
const CAPSULE_END: f32 = 1e-3;

/// Shortest projection of a unit normal across a revolution axis below which the normal is
/// taken as along the axis (no turn about the axis is defined there).
const ACROSS_AXIS: f32 = 1e-3;

/// The part of `shape` that sub-shape index `subshape` names: a compound's part, or `shape`
/// itself (a convex shape; a triangle mesh's or height field's triangles are flat).
#[inline]
pub(crate) fn part_shape(shape: &dyn Shape, subshape: u32) -> &dyn Shape {
    match shape.as_compound() {
        Some(compound) => compound
            .shapes()
            .get(subshape as usize)
            .map_or(shape, |(_, part)| part.as_ref()),
        None => shape,
    }
}

/// How `part` (at world pose `pose`) is round at the contact point `at` (world), where its
/// outward normal tilted by the roughness is `outward` (world, unit) and the untilted contact
/// normal is `normal` (world, unit, either sign); `None` where it is flat or sharp in every
/// direction (a box, a hull, a triangle, a half-space, a cylinder's or cone's flat cap: the
/// normal of a cap contact is within `roughness` (rad) of the axis).
fn roundness(
    part: &dyn Shape,
    pose: &Pose,
    at: Vec3,
    normal: Vec3,
    outward: Vec3,
    roughness: f32,
) -> Option<Roundness> {
    match part.as_typed_shape() {
        TypedShape::Ball(_) => Some(Roundness::Centre(pose.translation)),
        TypedShape::Capsule(capsule) => {
            let (a, b) = (
                pose.transform_point(capsule.segment.a),
                pose.transform_point(capsule.segment.b),
            );
            let along = b - a;
            let length_squared = along.length_squared();
            if length_squared <= f32::EPSILON * f32::EPSILON {
                return Some(Roundness::Centre(a));
            }
            let t = (at - a).dot(along) / length_squared;
            // An end's hemisphere holds the normals that lean out past that end; a tilt that
            // leans in stays on the straight side.
            if t <= CAPSULE_END && outward.dot(along) < 0.0 {
                Some(Roundness::Centre(a))
            } else if t >= 1.0 - CAPSULE_END && outward.dot(along) > 0.0 {
                Some(Roundness::Centre(b))
            } else {
                Some(Roundness::Axis(a, along / length_squared.sqrt()))
            }
        }
        TypedShape::Cylinder(_) | TypedShape::Cone(_) => {
            let axis = pose.rotation * Vec3::Y;
            (normal.dot(axis).abs() < roughness.cos())
                .then_some(Roundness::Axis(pose.translation, axis))
        }
        _ => None,
    }
}

/// `point` (world) moved with the tilt to where the part's outward normal is `outward` (the
/// tilted normal, world, unit), at the same distance from the centre of curvature of
/// `roundness`: from the centre along `outward`, or from the axis along `outward`'s part
/// across it (the point's place along the axis stays). The impulse's line along `outward`
/// then passes through the centre, or meets the axis, to rounding.
fn moved(roundness: Roundness, point: Vec3, outward: Vec3) -> Vec3 {
    match roundness {
        Roundness::Centre(centre) => centre + outward * (point - centre).length(),
        Roundness::Axis(origin, axis) => {
            let foot = origin + axis * (point - origin).dot(axis);
            let across = outward - axis * outward.dot(axis);
            let length = across.length();
            if length < ACROSS_AXIS {
                return point;
            }
            foot + across * ((point - foot).length() / length)
        }
    }
}

/// One side of a rough contact for [`tilted_points`]: a body's part shape, its world pose and
/// the body's point of the contact (world, m).
pub(crate) struct Side<'a> {
    pub(crate) part: &'a dyn Shape,
    pub(crate) pose: &'a Pose,
    pub(crate) at: Vec3,
}

/// The points (world, m) at which a rough contact's impulse along `tilted` acts on bodies A
/// and B, for an untilted contact `normal` (world, unit, from B towards A) and `roughness`
/// (rad). A body round at the contact ([`Roundness`]) touches the tilted surface where its own
/// outward normal is the tilted one: its point turns about its centre of curvature with the
/// tilt, so the impulse's line passes through that centre (a ball's through its centre: no
/// torque, whatever the tilt). A flat body (a face, an edge, a vertex, a flat cap) against a
/// round one takes the round body's point, where the two touch; two flat bodies keep their
/// points (the tilt is a facet of the surface under the point); two round bodies each take
/// their own point (no point has both surfaces' normals at the tilt: the impulses pass through
/// both centres, so neither spins, and the couple of the two parallel lines is the tilt's).
pub(crate) fn tilted_points(
    a: Side<'_>,
    b: Side<'_>,
    normal: Vec3,
    tilted: Vec3,
    roughness: f32,
) -> (Vec3, Vec3) {
    // Body A's outward normal at the contact is −n, body B's +n.
    let round_a = roundness(a.part, a.pose, a.at, normal, -tilted, roughness);
    let round_b = roundness(b.part, b.pose, b.at, normal, tilted, roughness);
    let at_a = round_a.map(|r| moved(r, a.at, -tilted));
    let at_b = round_b.map(|r| moved(r, b.at, tilted));
    match (at_a, at_b) {
        (Some(at_a), Some(at_b)) => (at_a, at_b),
        (Some(at_a), None) => (at_a, b.at + (at_a - a.at)),
        (None, Some(at_b)) => (a.at + (at_b - b.at), at_b),
        (None, None) => (a.at, b.at),
    }
}

/// 64 well-mixed bits of a key: SplitMix64's finaliser over the key's words in turn.
pub(super) fn mix(key: &[u64]) -> u64 {
    let mut state = 0x9E37_79B9_7F4A_7C15u64;
    for &word in key {
        state = state.wrapping_add(word).wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        state = z ^ (z >> 31);
    }
    state
}

/// A number in [0, 1) from the low 24 bits of `bits` (exact in f32).
pub(super) fn unit(bits: u64) -> f32 {
    (bits & 0xFF_FFFF) as f32 / 16_777_216.0
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Tilts stay within the cap, cover it (the mean of 1 − cos over uniform draws on a cap is
    /// half the cap's), and are unit vectors.
    #[test]
    fn tilts_are_uniform_over_the_cap() {
        let roughness = 10f32.to_radians();
        let normal = Vec3::Y;
        let pose = Pose::IDENTITY;
        let mut sum = 0.0f64;
        let mut widest = 0.0f32;
        let count = 20_000;
        for k in 0..count {
            let bits = mix(&[7, k, 1, 0]);
            let draw = RoughnessDraw {
                cap: unit(bits),
                azimuth: unit(bits >> 32) * std::f32::consts::TAU,
                axis: 0,
            };
            let n = tilted(normal, &draw, roughness, &pose);
            assert!((n.length() - 1.0).abs() < 1e-5);
            let angle = n.dot(normal).clamp(-1.0, 1.0).acos();
            assert!(angle <= roughness + 1e-4, "tilt {angle} beyond {roughness}");
            widest = widest.max(angle);
            sum += f64::from(1.0 - n.dot(normal));
        }
        let mean = sum / count as f64;
        let half_cap = 0.5 * f64::from(1.0 - roughness.cos());
        assert!(
            (mean - half_cap).abs() < 0.02 * half_cap,
            "{mean} vs {half_cap}"
        );
        assert!(widest > 0.99 * roughness);
    }

    /// The tilt turns with body 1: the same draw on a turned body gives the turned normal.
    #[test]
    fn the_tilt_turns_with_body_one() {
        let draw = RoughnessDraw {
            cap: 0.7,
            azimuth: 1.0,
            axis: 0,
        };
        let roughness = 0.2;
        let turn = glam::Quat::from_rotation_y(0.9);
        let still = tilted(Vec3::Y, &draw, roughness, &Pose::IDENTITY);
        let turned = tilted(
            turn * Vec3::Y,
            &draw,
            roughness,
            &Pose::from_parts(Vec3::ZERO, turn),
        );
        assert!((turned - turn * still).length() < 1e-5);
    }

    /// Explicit draws of standard normals (Box–Muller pairs) have the seeded draws'
    /// distribution: cap and azimuth uniform (means 1/2 and π, a quarter of each below a
    /// quarter of its range); huge coordinates stay in range, and (0, 0) is no tilt.
    #[test]
    fn explicit_draws_of_standard_normals_are_uniform() {
        let count = 20_000u64;
        let (mut caps, mut azimuths, mut low_caps, mut low_azimuths) = (0.0f64, 0.0f64, 0, 0);
        for k in 0..count {
            let bits = mix(&[3, k]);
            let (u1, u2) = (f64::from(unit(bits)), f64::from(unit(bits >> 32)));
            let radius = (-2.0 * (1.0 - u1).ln()).sqrt();
            let angle = std::f64::consts::TAU * u2;
            let (a, b) = ((radius * angle.cos()) as f32, (radius * angle.sin()) as f32);
            let (cap, azimuth) = explicit_draw(a, b);
            assert!((0.0..1.0).contains(&cap) && (0.0..std::f32::consts::TAU).contains(&azimuth));
            caps += f64::from(cap);
            azimuths += f64::from(azimuth);
            low_caps += usize::from(cap < 0.25);
            low_azimuths += usize::from(azimuth < std::f32::consts::FRAC_PI_2);
        }
        let n = count as f64;
        assert!((caps / n - 0.5).abs() < 0.01, "{}", caps / n);
        assert!(
            (azimuths / n - std::f64::consts::PI).abs() < 0.03,
            "{}",
            azimuths / n
        );
        for low in [low_caps, low_azimuths] {
            assert!((low as f64 / n - 0.25).abs() < 0.01, "{low}");
        }
        for (a, b) in [(1e30, -1e30), (f32::MAX, 0.0), (40.0, -1e-30), (-3.0, -0.0)] {
            let (cap, azimuth) = explicit_draw(a, b);
            let draw = RoughnessDraw {
                cap,
                azimuth,
                axis: 0,
            };
            assert!(
                draw.is_valid() && azimuth < std::f32::consts::TAU,
                "{a}, {b}"
            );
        }
        assert_eq!(explicit_draw(0.0, 0.0).0, 0.0);
    }

    /// Different keys give different draws; the same key the same.
    #[test]
    fn draws_depend_on_every_part_of_the_key() {
        let base = mix(&[1, 2, 3, 4]);
        assert_eq!(base, mix(&[1, 2, 3, 4]));
        for other in [[0, 2, 3, 4], [1, 0, 3, 4], [1, 2, 0, 4], [1, 2, 3, 0]] {
            assert_ne!(base, mix(&other));
        }
    }
}
