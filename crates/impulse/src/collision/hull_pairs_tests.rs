//! The convex–convex contact between the mug's V-HACD parts (`scenes/mug.obj`, walls 6 mm
//! thick, so most parts are thin curved slabs) against an exact reference: the separating axis
//! theorem over both hulls' face normals and the cross products of their edges, in f64. For
//! two convex polyhedra the smallest overlap over those axes is the penetration depth (the
//! faces of their Minkowski difference have exactly those normals); apart, the largest
//! separation over them is a lower bound of the distance.
//!
//! The sweep places two parts at seeded random orientations, moved along a random direction
//! from just touching to 20 mm in (and 2 mm apart), and compares the engine's manifold
//! (its deepest point and its normal) and the overlap metric (`metrics::max_overlap_of_pairs`)
//! with the reference.

use std::sync::OnceLock;

use glam::{DQuat, DVec3, Vec3};
use parry3d::math::Pose;
use parry3d::query::{self, ContactManifold, DefaultQueryDispatcher, PersistentQueryDispatcher};
use parry3d::shape::{Shape, SharedShape};
use rand::rngs::ChaCha20Rng;
use rand::{RngExt, SeedableRng};
use rand_distr::{Distribution, UnitSphere};

use crate::collision::separating_axes;
use crate::scene::{ConvexPart, DecompositionDesc, decompose_mesh, load_mesh_file};

/// A convex polyhedron in world coordinates (m, f64) with its distinct face normals and edge
/// directions (edges between coplanar triangles left out: they are no edges of the solid).
pub(crate) struct Polytope {
    pub vertices: Vec<DVec3>,
    pub normals: Vec<DVec3>,
    pub edges: Vec<DVec3>,
}

/// Pushes `v` (unit) onto `list` unless it or (with `either_sign`) its opposite is already there.
fn push_distinct(list: &mut Vec<DVec3>, v: DVec3, either_sign: bool) {
    let same = |u: &DVec3| u.dot(v) > 1.0 - 1e-12 || (either_sign && u.dot(v) < -1.0 + 1e-12);
    if !list.iter().any(same) {
        list.push(v);
    }
}

impl Polytope {
    /// The part's triangles (counter-clockwise from outside) at `rotation`, `translation`.
    pub(crate) fn of(part: &ConvexPart, rotation: DQuat, translation: DVec3) -> Self {
        let vertices: Vec<DVec3> = part
            .vertices
            .iter()
            .map(|v| rotation * DVec3::from(v.map(f64::from)) + translation)
            .collect();
        let triangle_normal = |t: &[u32; 3]| {
            let [a, b, c] = t.map(|i| vertices[i as usize]);
            (b - a).cross(c - a).normalize_or_zero()
        };
        let mut normals = Vec::new();
        let mut edges = Vec::new();
        let mut edge_faces: std::collections::HashMap<(u32, u32), Vec<DVec3>> =
            std::collections::HashMap::new();
        for t in &part.indices {
            let n = triangle_normal(t);
            if n == DVec3::ZERO {
                continue;
            }
            push_distinct(&mut normals, n, false);
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                edge_faces.entry((a.min(b), a.max(b))).or_default().push(n);
            }
        }
        for ((a, b), faces) in edge_faces {
            let bends = faces.iter().any(|n| n.dot(faces[0]) < 1.0 - 1e-12);
            let dir = (vertices[b as usize] - vertices[a as usize]).normalize_or_zero();
            if bends && dir != DVec3::ZERO {
                push_distinct(&mut edges, dir, true);
            }
        }
        Self {
            vertices,
            normals,
            edges,
        }
    }

    fn extent(&self, axis: DVec3) -> (f64, f64) {
        self.vertices
            .iter()
            .map(|v| v.dot(axis))
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
                (lo.min(x), hi.max(x))
            })
    }

    pub(crate) fn centroid(&self) -> DVec3 {
        self.vertices.iter().copied().sum::<DVec3>() / self.vertices.len() as f64
    }
}

/// The overlap (m) of `a` and `b` along the unit `axis` pointing out of `a` towards `b`: how
/// far `b` would move along `axis` to clear `a`. Negative when apart along it.
pub(crate) fn overlap_along(a: &Polytope, b: &Polytope, axis: DVec3) -> f64 {
    a.extent(axis).1 - b.extent(axis).0
}

/// The exact penetration depth (m) of `a` and `b` and its axis (unit, out of `a`): the smallest
/// overlap over every face normal and edge cross product, each taken in the direction of its
/// smaller overlap. Negative when apart: then minus the largest separation over those axes, a
/// lower bound of the distance.
pub(crate) fn sat_depth(a: &Polytope, b: &Polytope) -> (f64, DVec3) {
    let mut best = (f64::INFINITY, DVec3::ZERO);
    let mut test = |axis: DVec3| {
        let (lo_a, hi_a) = a.extent(axis);
        let (lo_b, hi_b) = b.extent(axis);
        for (overlap, oriented) in [(hi_a - lo_b, axis), (hi_b - lo_a, -axis)] {
            if overlap < best.0 {
                best = (overlap, oriented);
            }
        }
    };
    for &n in a.normals.iter().chain(&b.normals) {
        test(n);
    }
    for &e1 in &a.edges {
        for &e2 in &b.edges {
            let c = e1.cross(e2);
            let length = c.length();
            if length > 1e-9 {
                test(c / length);
            }
        }
    }
    best
}

/// The mug's V-HACD parts with the engine's default parameters, decomposed once per process.
pub(crate) fn mug_parts() -> &'static [ConvexPart] {
    static PARTS: OnceLock<Vec<ConvexPart>> = OnceLock::new();
    PARTS.get_or_init(|| {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/mug.obj");
        let mesh = load_mesh_file(&path).unwrap();
        decompose_mesh(&mesh, &DecompositionDesc::default())
            .unwrap()
            .parts
            .clone()
    })
}

/// Parry's hull of `part` (at the identity), as the engine's compound holds it.
pub(crate) fn part_shape(part: &ConvexPart) -> SharedShape {
    let points = part.vertices.iter().map(|v| Vec3::from(*v)).collect();
    SharedShape::convex_mesh(points, &part.indices).unwrap()
}

/// One case of the sweep: parts `i` and `j` at their poses, the exact depth and axis.
pub(crate) struct Case {
    pub i: usize,
    pub j: usize,
    pub pose1: Pose,
    pub pose2: Pose,
    pub depth: f64,
    pub axis: DVec3,
    pub a: Polytope,
    pub b: Polytope,
}

fn random_rotation(rng: &mut ChaCha20Rng) -> DQuat {
    let axis: [f64; 3] = UnitSphere.sample(rng);
    let angle: f64 = rng.random_range(0.0..std::f64::consts::PI);
    DQuat::from_axis_angle(DVec3::from(axis), angle)
}

/// Case `index` of the sweep of `seed`: two random parts at random orientations, the second
/// moved along a random direction from the first's centroid to where they just touch, then
/// `in_by` (m, negative: apart) further in.
pub(crate) fn case(seed: u64, index: u64, in_by: std::ops::Range<f64>) -> Case {
    let parts = mug_parts();
    let mut rng = ChaCha20Rng::seed_from_u64(seed);
    rng.set_stream(index);
    let i = rng.random_range(0..parts.len());
    let j = rng.random_range(0..parts.len());
    let (r1, r2) = (random_rotation(&mut rng), random_rotation(&mut rng));
    let dir = DVec3::from(UnitSphere.sample(&mut rng) as [f64; 3]);
    let delta: f64 = rng.random_range(in_by);
    // Rotations are rounded to f32 first, so that the reference sees the engine's poses.
    let (r1, r2) = (r1.as_quat().as_dquat(), r2.as_quat().as_dquat());
    let a = Polytope::of(&parts[i], r1, DVec3::ZERO);
    let b0 = Polytope::of(&parts[j], r2, DVec3::ZERO);
    let base = a.centroid() - b0.centroid();
    let reach = |p: &Polytope| {
        let c = p.centroid();
        p.vertices
            .iter()
            .map(|v| (*v - c).length())
            .fold(0.0, f64::max)
    };
    // Centroids together overlap; beyond both reaches they are apart; the set of overlapping
    // offsets along `dir` is an interval (the Minkowski difference is convex). The engine's
    // separating-axis depth finds it (the reference below measures the case found).
    let (s1, s2) = (part_shape(&parts[i]), part_shape(&parts[j]));
    let (q1, q2) = (
        separating_axes::Polytope::of(s1.as_ref()).unwrap(),
        separating_axes::Polytope::of(s2.as_ref()).unwrap(),
    );
    let overlapping = |s: f64| {
        let pose1 = Pose::from_parts(Vec3::ZERO, r1.as_quat());
        let pose2 = Pose::from_parts((base + dir * s).as_vec3(), r2.as_quat());
        separating_axes::depth_beyond(&q1, &q2, &pose1.inv_mul(&pose2), 0.0).is_some()
    };
    let (mut lo, mut hi) = (0.0, reach(&a) + reach(&b0) + 0.01);
    for _ in 0..30 {
        let mid = 0.5 * (lo + hi);
        if overlapping(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let translation = (base + dir * (lo - delta)).as_vec3();
    let b = Polytope::of(&parts[j], r2, translation.as_dvec3());
    let (depth, axis) = sat_depth(&a, &b);
    Case {
        i,
        j,
        pose1: Pose::from_parts(Vec3::ZERO, r1.as_quat()),
        pose2: Pose::from_parts(translation, r2.as_quat()),
        depth,
        axis,
        a,
        b,
    }
}

/// What the engine's manifold, Parry's queries and the overlap metric read for a case.
pub(crate) struct Reading {
    /// The engine's deepest point (m, positive in overlap); −∞ without points.
    pub engine_depth: f64,
    /// The overlap along the engine's normal (m): the depth it pushes out along.
    pub engine_normal_overlap: f64,
    /// The angle (rad) between the engine's normal and the exact axis.
    pub engine_angle: f64,
    /// The smaller of Parry's `query::contact` and fresh-manifold depths (m), 0 when either
    /// reads the parts apart: what the overlap metric measured hulls by before it took the
    /// separating axes.
    pub parry: f64,
    /// `separating_axes::depth_beyond` with no floor (m, negative apart).
    pub separating_axes: f64,
    /// `metrics::max_overlap_of_pairs` of the two parts (m).
    pub metric: f64,
}

/// Speculative distance (m) of the engine's manifold in the sweep.
pub(crate) const PREDICTION: f32 = 0.005;

/// Parry's two depth estimates of `g1` at `pose1` and `g2` at `pose2`, the smaller, 0 apart.
fn parry_depth(pose1: &Pose, g1: &dyn Shape, pose2: &Pose, g2: &dyn Shape) -> f64 {
    let mut manifolds: Vec<ContactManifold<(), ()>> = Vec::new();
    DefaultQueryDispatcher
        .contact_manifolds(
            &pose1.inv_mul(pose2),
            g1,
            g2,
            0.0,
            &mut manifolds,
            &mut None,
        )
        .unwrap();
    let manifold = manifolds
        .iter()
        .flat_map(|m| m.points.iter())
        .map(|p| -p.dist)
        .fold(f32::NEG_INFINITY, f32::max);
    let single = match query::contact(pose1, g1, pose2, g2, 0.0).unwrap() {
        Some(contact) => -contact.dist,
        None => f32::NEG_INFINITY,
    };
    f64::from(manifold.min(single).max(0.0))
}

pub(crate) fn read(case: &Case) -> Reading {
    let parts = mug_parts();
    let (g1, g2) = (part_shape(&parts[case.i]), part_shape(&parts[case.j]));
    let manifold = crate::collision::dispatch::tests::manifold_within(
        &case.pose1,
        g1.as_ref(),
        &case.pose2,
        g2.as_ref(),
        PREDICTION,
    );
    let engine_depth = manifold
        .points
        .iter()
        .map(|p| -f64::from(p.dist))
        .fold(f64::NEG_INFINITY, f64::max);
    let normal = (case.pose1.rotation * manifold.local_n1)
        .as_dvec3()
        .normalize_or_zero();
    let (q1, q2) = (
        separating_axes::Polytope::of(g1.as_ref()).unwrap(),
        separating_axes::Polytope::of(g2.as_ref()).unwrap(),
    );
    let separating_axes = separating_axes::depth_beyond(
        &q1,
        &q2,
        &case.pose1.inv_mul(&case.pose2),
        f32::NEG_INFINITY,
    )
    .unwrap();
    let parry = parry_depth(&case.pose1, g1.as_ref(), &case.pose2, g2.as_ref());
    let metric =
        crate::metrics::max_overlap_of_pairs(&[g1, g2], &[case.pose1, case.pose2], &[(0, 1)]);
    Reading {
        engine_depth,
        engine_normal_overlap: overlap_along(&case.a, &case.b, normal),
        engine_angle: normal.dot(case.axis).clamp(-1.0, 1.0).acos(),
        parry,
        separating_axes: f64::from(separating_axes),
        metric: f64::from(metric),
    }
}

/// Tolerance (m) of the comparisons: f32 poses and GJK's tolerance move depths by far less.
const TOLERANCE: f64 = 2.5e-4;

/// The kinds of disagreement with the reference the sweep counts.
const KINDS: [&str; 6] = [
    "engine's deepest point deeper than the exact depth",
    "engine's deepest point shallower",
    "overlap along the engine's normal above the exact depth",
    "Parry's depth off",
    "separating-axis depth off",
    "overlap metric off",
];

/// Runs `count` cases of `seed`, printing each kind's count and worst case; returns the counts
/// in the order of [`KINDS`] and the worst errors (m).
fn sweep(seed: u64, count: u64) -> ([usize; 6], [f64; 6]) {
    let mut counts = [0usize; 6];
    let mut worst = [(0.0f64, 0u64); 6];
    for index in 0..count {
        let case = case(seed, index, -0.002..0.02);
        let r = read(&case);
        let exact = case.depth;
        let errors = [
            r.engine_depth - exact,
            if exact > 0.0 {
                exact - r.engine_depth.max(0.0)
            } else {
                0.0
            },
            if r.engine_depth > 0.0 {
                r.engine_normal_overlap - exact
            } else {
                0.0
            },
            (r.parry - exact.max(0.0)).abs(),
            (r.separating_axes - exact).abs(),
            (r.metric - exact.max(0.0)).abs(),
        ];
        for k in 0..KINDS.len() {
            if errors[k] > TOLERANCE {
                counts[k] += 1;
                if errors[k] > worst[k].0 {
                    worst[k] = (errors[k], index);
                }
            }
        }
        if std::env::var("IMPULSE_SAT_VERBOSE").is_ok() {
            println!(
                "{index}: parts {} {} exact {:.2} mm engine {:.2} mm (normal overlap {:.2} mm, \
                 {:.1}°) Parry {:.2} mm separating axes {:.2} mm metric {:.2} mm",
                case.i,
                case.j,
                exact * 1e3,
                r.engine_depth * 1e3,
                r.engine_normal_overlap * 1e3,
                r.engine_angle.to_degrees(),
                r.parry * 1e3,
                r.separating_axes * 1e3,
                r.metric * 1e3
            );
        }
    }
    for k in 0..KINDS.len() {
        println!(
            "{}: {} of {count} (by more than {:.2} mm), worst {:.2} mm (case {})",
            KINDS[k],
            counts[k],
            TOLERANCE * 1e3,
            worst[k].0 * 1e3,
            worst[k].1
        );
    }
    (counts, worst.map(|w| w.0))
}

/// Checks a sweep's counts: the separating-axis depth and the overlap metric are the exact
/// depth in every case; the engine's manifold is, but for a few cases in a hundred within
/// `engine_worst` (m).
fn check(counts: [usize; 6], worst: [f64; 6], count: usize, engine_worst: f64) {
    assert_eq!(counts[4], 0, "{}", KINDS[4]);
    assert_eq!(counts[5], 0, "{}", KINDS[5]);
    for k in 0..3 {
        assert!(
            counts[k] * 50 <= count && worst[k] <= engine_worst,
            "{}: {} of {count}, worst {:.2} mm",
            KINDS[k],
            counts[k],
            worst[k] * 1e3
        );
    }
}

/// 250 cases (seed 1): the default subset. Parry's depth is off in some (printed, not checked).
#[test]
fn the_overlap_metric_is_the_exact_depth_between_the_mugs_parts() {
    let (counts, worst) = sweep(1, 250);
    check(counts, worst, 250, 2e-3);
}

/// 5,000 cases (seed 2); figures in docs/testing.md, "The 500-mug pour":
/// `cargo test -p impulse --lib collision::hull_pairs_tests -- --ignored --nocapture`.
#[test]
#[ignore = "a minute: the long sweep"]
fn the_long_sweep_of_the_mugs_parts() {
    let (counts, worst) = sweep(2, 5000);
    check(counts, worst, 5000, 5e-3);
}

/// Two of the mug's part 8 as bodies 49 and 98 of the 98-mug pour held them at the start of
/// step 30 (at 1/240 s): 0.90 mm apart along a face normal, where Parry's `query::contact`
/// (EPA) reads them 26 mm deep along another axis and its manifold has points that deep,
/// which threw the two mugs apart. The engine's manifold has speculative points at the
/// separation along the face normal instead, none overlapping.
#[test]
fn thin_parts_apart_get_no_deep_points() {
    let parts = mug_parts();
    let g = part_shape(&parts[8]);
    let pos12 = Pose::from_parts(
        Vec3::new(-0.09006938, 0.105422206, -0.017122347),
        glam::Quat::from_array([-0.11325252, -0.36620712, -0.9226059, -0.04318267]),
    );
    let q = separating_axes::Polytope::of(g.as_ref()).unwrap();
    let exact = separating_axes::depth_beyond(&q, &q, &pos12, f32::NEG_INFINITY).unwrap();
    assert!(
        (exact + 0.9e-3).abs() < 1e-5,
        "apart by {} mm",
        -exact * 1e3
    );
    let parry = query::contact(&Pose::IDENTITY, g.as_ref(), &pos12, g.as_ref(), 0.0)
        .unwrap()
        .unwrap();
    assert!(
        parry.dist < -0.02,
        "Parry's contact reads {} mm",
        parry.dist * 1e3
    );
    for prediction in [0.0, 0.005, 0.05] {
        let manifold = crate::collision::dispatch::tests::manifold_within(
            &Pose::IDENTITY,
            g.as_ref(),
            &pos12,
            g.as_ref(),
            prediction,
        );
        for point in &manifold.points {
            assert!(
                point.dist >= -exact - 1e-5,
                "prediction {prediction}: a point {} mm apart",
                point.dist * 1e3
            );
        }
        assert_eq!(manifold.points.is_empty(), prediction < -exact);
    }
}

/// Parry's contact query between the mug's parts can end before GJK proves them farther apart
/// than asked and return a contact beyond the prediction, where Parry's manifold generator
/// (GJK from another start) finds them apart and gives no point. The engine then keeps no
/// point either (its fallback for pairs Parry leaves without points does not add that
/// contact), and a pair apart beyond the prediction by more than 2 mm (the exact reference's
/// separation) gets none.
#[test]
fn parts_apart_beyond_the_prediction_get_no_points() {
    let prediction: f32 = 0.024;
    let parts = mug_parts();
    let (mut beyond, mut parry_beyond, mut within) = (0, 0, 0);
    for index in 0..600 {
        let c = case(83, index, -0.04..-0.002);
        let (g1, g2) = (part_shape(&parts[c.i]), part_shape(&parts[c.j]));
        let (g1, g2) = (g1.as_ref(), g2.as_ref());
        let pos12 = c.pose1.inv_mul(&c.pose2);
        // As in a step: the manifold keeps last step's normal, which GJK starts from (here
        // the exact separating axis, shape 1's frame).
        let seeded = || {
            let mut m: ContactManifold<(), ()> = ContactManifold::new();
            m.local_n1 = c.pose1.rotation.inverse() * c.axis.as_vec3();
            m
        };
        let mut manifold = seeded();
        crate::collision::dispatch::ContactDispatcher::default()
            .contact_manifold_convex_convex(&pos12, g1, g2, None, None, prediction, &mut manifold)
            .unwrap();
        let mut parry = seeded();
        DefaultQueryDispatcher
            .contact_manifold_convex_convex(&pos12, g1, g2, None, None, prediction, &mut parry)
            .unwrap();
        if parry.points.is_empty()
            && let Some(contact) = query::contact(&c.pose1, g1, &c.pose2, g2, prediction).unwrap()
            && contact.dist > prediction
        {
            parry_beyond += 1;
            assert!(
                manifold.points.is_empty(),
                "case {index}: a point where Parry's contact is {} mm apart",
                contact.dist * 1e3
            );
        }
        // The reference's largest separation is at most the distance.
        if -c.depth > f64::from(prediction) + 2.0e-3 {
            beyond += 1;
            assert!(manifold.points.is_empty(), "case {index}: points beyond");
        } else if !manifold.points.is_empty() {
            within += 1;
        }
    }
    assert!(
        parry_beyond >= 5 && beyond >= 50 && within >= 50,
        "{parry_beyond} contacts beyond the prediction from Parry, {beyond} cases apart \
         beyond it, {within} with points: the sample tests too little"
    );
}
