//! A pair's manifolds as a snapshot stores them: each manifold and point as a list of its
//! values in a fixed order, without the field names that Parry's own serde form repeats for
//! every manifold and point, and without the face-axis memory, which is derived state (the
//! contacts do not depend on it: `axis_memory`). A mid-pour snapshot holds tens of thousands of
//! part-pair manifolds, most of them without a point, so the names were most of its bytes.
//!
//! Reading takes either form, so snapshots written before this one (Parry's form, format
//! versions 2 to 4) still read.

use glam::{Quat, Vec3};
use parry3d::math::{Pose, Real, Vector};
use parry3d::query::TrackedContact;
use parry3d::shape::PackedFeatureId;
use serde::{Deserialize, Deserializer, Serialize, Serializer};

use super::manifold::{ContactImpulse, Manifold, ManifoldState, RoughnessDraw};

/// A pose as (rotation, translation).
#[derive(Serialize, Deserialize)]
struct PoseRecord(Quat, Vector);

impl From<&Pose> for PoseRecord {
    fn from(pose: &Pose) -> Self {
        PoseRecord(pose.rotation, pose.translation)
    }
}

impl From<PoseRecord> for Pose {
    fn from(PoseRecord(rotation, translation): PoseRecord) -> Self {
        Pose::from_parts(translation, rotation)
    }
}

/// A point: `local_p1`, `local_p2`, `dist`, `fid1`, `fid2`, then its [`ContactImpulse`]
/// (`normal`, `friction`, `step_normal`, `step_friction`).
#[derive(Serialize, Deserialize)]
struct PointRecord(Vector, Vector, Real, u32, u32, Real, Vec3, Real, Vec3);

/// A manifold: its points, `local_n1`, `local_n2`, `subshape1`, `subshape2`, the subshapes'
/// poses, then its [`ManifoldState`] without the face-axis memory (`tangent`, `roughness`,
/// `impact`).
#[derive(Serialize, Deserialize)]
struct ManifoldRecord(
    Vec<PointRecord>,
    Vector,
    Vector,
    u32,
    u32,
    Option<(Option<PoseRecord>, Option<PoseRecord>)>,
    Vec3,
    Option<RoughnessDraw>,
    Option<f32>,
);

impl From<&Manifold> for ManifoldRecord {
    fn from(m: &Manifold) -> Self {
        let points = m
            .points
            .iter()
            .map(|p| {
                let d = p.data;
                PointRecord(
                    p.local_p1,
                    p.local_p2,
                    p.dist,
                    p.fid1.0,
                    p.fid2.0,
                    d.normal,
                    d.friction,
                    d.step_normal,
                    d.step_friction,
                )
            })
            .collect();
        let poses = m.subshape_poses.as_ref().map(|poses| {
            (
                poses.pos1.as_ref().map(PoseRecord::from),
                poses.pos2.as_ref().map(PoseRecord::from),
            )
        });
        ManifoldRecord(
            points,
            m.local_n1,
            m.local_n2,
            m.subshape1,
            m.subshape2,
            poses,
            m.data.tangent,
            m.data.roughness,
            m.data.impact,
        )
    }
}

impl From<ManifoldRecord> for Manifold {
    fn from(record: ManifoldRecord) -> Self {
        let ManifoldRecord(
            points,
            local_n1,
            local_n2,
            subshape1,
            subshape2,
            poses,
            tangent,
            roughness,
            impact,
        ) = record;
        let points = points
            .into_iter()
            .map(
                |PointRecord(
                    local_p1,
                    local_p2,
                    dist,
                    fid1,
                    fid2,
                    normal,
                    friction,
                    step_normal,
                    step_friction,
                )| {
                    TrackedContact {
                        local_p1,
                        local_p2,
                        dist,
                        fid1: PackedFeatureId(fid1),
                        fid2: PackedFeatureId(fid2),
                        data: ContactImpulse {
                            normal,
                            friction,
                            step_normal,
                            step_friction,
                        },
                    }
                },
            )
            .collect();
        let mut manifold = Manifold {
            points,
            local_n1,
            local_n2,
            subshape1,
            subshape2,
            subshape_poses: None,
            data: ManifoldState {
                tangent,
                roughness,
                impact,
                face_axes: None,
            },
        };
        // Parry's `SubshapePoses` is not public: its setters build it. The first call makes
        // the box whatever `pos1` is, so a box of two absent poses comes back as one.
        if let Some((pos1, pos2)) = poses {
            manifold.set_subshape_pos1(Some(Pose::IDENTITY));
            manifold.set_subshape_pos1(pos1.map(Pose::from));
            manifold.set_subshape_pos2(pos2.map(Pose::from));
        }
        manifold
    }
}

/// A manifold in either form: this module's list, or Parry's map (format versions 2 to 4).
#[derive(Deserialize)]
#[serde(untagged)]
enum EitherForm {
    Record(ManifoldRecord),
    Parry(Manifold),
}

/// Writes `manifolds` as [`ManifoldRecord`]s (`#[serde(with)]` of a pair's manifolds).
pub(crate) fn serialize<S: Serializer>(
    manifolds: &[Manifold],
    serializer: S,
) -> Result<S::Ok, S::Error> {
    serializer.collect_seq(manifolds.iter().map(ManifoldRecord::from))
}

/// Reads manifolds written by [`serialize`], or in Parry's form.
pub(crate) fn deserialize<'de, D: Deserializer<'de>>(
    deserializer: D,
) -> Result<Vec<Manifold>, D::Error> {
    let manifolds = Vec::<EitherForm>::deserialize(deserializer)?;
    Ok(manifolds
        .into_iter()
        .map(|m| match m {
            EitherForm::Record(record) => record.into(),
            EitherForm::Parry(manifold) => manifold,
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use parry3d::query::ContactManifold;

    /// A pair's manifolds as `PairState` holds them.
    #[derive(Serialize, Deserialize)]
    struct Held(#[serde(with = "super")] Vec<Manifold>);

    /// A part-pair manifold with two points, both subshape poses, a roughness draw and an impact
    /// draw; and an empty one whose poses box holds two absent poses.
    fn manifolds() -> Vec<Manifold> {
        let mut full: Manifold = ContactManifold::new();
        full.local_n1 = Vector::new(0.0, 1.0, 0.0);
        full.local_n2 = Vector::new(0.6, -0.8, 0.0);
        (full.subshape1, full.subshape2) = (3, 17);
        full.set_subshape_pos1(Some(Pose::from_parts(
            Vector::new(0.1, 0.2, 0.3),
            Quat::from_rotation_y(0.7),
        )));
        full.set_subshape_pos2(Some(Pose::from_translation(Vector::new(-1.0, 0.0, 2.5))));
        for k in 0..2 {
            let mut point = TrackedContact::new(
                Vector::new(k as f32, 0.5, -0.25),
                Vector::new(0.125, k as f32 * 1e-7, 3.0),
                PackedFeatureId::face(k),
                PackedFeatureId::vertex(40 + k),
                -1.5e-3 * k as f32,
            );
            point.data = ContactImpulse {
                normal: 0.25 + k as f32,
                friction: Vec3::new(1e-9, -2.0, 0.5),
                step_normal: 3.0,
                step_friction: Vec3::new(-0.0, 7.0, f32::MIN_POSITIVE),
            };
            full.points.push(point);
        }
        full.data = ManifoldState {
            tangent: Vec3::new(0.0, 0.0, 1.0),
            roughness: Some(RoughnessDraw {
                cap: 0.3,
                azimuth: 2.0,
                axis: 1,
            }),
            impact: Some(-0.5),
            face_axes: None,
        };
        let mut empty: Manifold = ContactManifold::new();
        empty.set_subshape_pos1(Some(Pose::IDENTITY));
        empty.set_subshape_pos1(None);
        vec![full, empty]
    }

    /// Every value comes back with its bits, through CBOR and JSON.
    #[test]
    fn manifolds_come_back_to_the_bit() {
        let original = manifolds();
        let mut cbor = Vec::new();
        ciborium::into_writer(&Held(original.clone()), &mut cbor).unwrap();
        let json = serde_json::to_string(&Held(original.clone())).unwrap();
        for Held(back) in [
            ciborium::from_reader::<Held, _>(&cbor[..]).unwrap(),
            serde_json::from_str::<Held>(&json).unwrap(),
        ] {
            assert_eq!(back.len(), original.len());
            for (a, b) in original.iter().zip(&back) {
                assert_eq!(format!("{a:?}"), format!("{b:?}"));
            }
        }
    }

    /// Parry's own form (snapshot format versions 2 to 4) still reads, and the compact form is
    /// less than half its size.
    #[test]
    fn parrys_form_still_reads() {
        let original = manifolds();
        let mut parry = Vec::new();
        ciborium::into_writer(&original, &mut parry).unwrap();
        let Held(back) = ciborium::from_reader::<Held, _>(&parry[..]).unwrap();
        for (a, b) in original.iter().zip(&back) {
            assert_eq!(format!("{a:?}"), format!("{b:?}"));
        }
        let mut compact = Vec::new();
        ciborium::into_writer(&Held(original), &mut compact).unwrap();
        assert!(
            2 * compact.len() < parry.len(),
            "{} of {}",
            compact.len(),
            parry.len()
        );
    }
}
