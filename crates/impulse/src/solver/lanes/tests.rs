//! The lanes solver's tests: unit tests of the packing, the lever-arm products, the update and
//! the record against the scalar rows (here), whole scenes solved in lanes ([`scenes`]), and
//! the lanes against the scalar rows on whole scenes ([`scalar_agreement`]).

use super::bundles::Bundles;
use super::lane::*;
use super::layout::*;
use super::sweep::*;
use crate::contact::{ContactConstraint, JacobianRow};
use crate::graph::COLOURS;
use crate::joint::IslandJoints;
use crate::solver::interface::{SolvePass, Sweep};
use crate::solver::rows::Velocities;
use glam::{Mat3, Vec3};
use proptest::prelude::*;

/// Values in `low..high` on a grid of 2²⁰ steps. proptest's own f32 range sampler trips
/// an internal assertion on some seeds when debug assertions are on (as in our test
/// profile): proptest-rs/proptest#343 and #479 describe the assertion.
fn float(low: f32, high: f32) -> impl Strategy<Value = f32> {
    const STEPS: u32 = 1 << 20;
    (0..STEPS).prop_map(move |k| low + (high - low) * (k as f32 / STEPS as f32))
}

/// Every number of a lane group's shared part a sweep reads, as bits, in a fixed order.
fn group_bits(g: &Group) -> Vec<u32> {
    let mut bits = vec![g.start, g.len];
    bits.extend(g.local_a.iter().chain(&g.local_b));
    let mut lanes: Vec<Lane> = Vec::new();
    lanes.extend(g.inverse_mass_a.iter().chain(&g.inverse_mass_b));
    lanes.extend(g.directions.iter().flatten());
    lanes.push(g.friction);
    bits.extend(lanes.iter().flat_map(|l| l.as_array().map(f32::to_bits)));
    bits
}

/// [`group_bits`] of every lane group, then [`bundle_bits`] of every bundle, one entry each.
fn packed_bits(packed: &Bundles) -> Vec<Vec<u32>> {
    let groups = packed.groups.iter().map(group_bits);
    groups
        .chain(packed.bundles.iter().map(bundle_bits))
        .collect()
}

/// Every number of a bundle a sweep reads, as bits, in a fixed order.
fn bundle_bits(b: &Bundle) -> Vec<u32> {
    let mut lanes: Vec<Lane> = Vec::new();
    for row in [&b.normal, &b.tangents[0], &b.tangents[1]] {
        for v in [
            &row.angular_a,
            &row.angular_b,
            &row.inverse_inertia_angular_a,
            &row.inverse_inertia_angular_b,
        ] {
            lanes.extend(v);
        }
        lanes.extend([row.effective_mass, row.inverse_effective_mass]);
    }
    lanes.extend(&b.tangent_inverse_block);
    lanes.extend([b.sliding_step, b.normal_impulse]);
    lanes.extend(&b.tangent_impulses);
    lanes.extend([
        b.target,
        b.mass_scale,
        b.impulse_scale,
        b.max_normal_impulse,
    ]);
    lanes
        .iter()
        .flat_map(|l| l.as_array().map(f32::to_bits))
        .collect()
}

/// A symmetric positive semi-definite tensor L·Lᵀ from nine numbers (1/(kg·m²)).
fn tensor(entries: &[f32]) -> Mat3 {
    let l = Mat3::from_cols_slice(entries);
    l * l.transpose()
}

proptest! {
    /// The lever-arm products the lanes compute from lever arms, directions and the
    /// slots' tensors as they pack (`products_pending`) are those of the scalar assembly
    /// (`complete_products` before packing) to the bit, padding lanes included: random
    /// points between five moving slots of random mass and inertia, a heavy rod (friction
    /// blocks of rank one, the pseudo-inverse), one slot that is immovable by its masses,
    /// and the island's immovable slot. And a pack on the last pack's layout, which resets
    /// no bundle, gives the bits of a fresh pack.
    #[test]
    fn lanes_compute_the_lever_arm_products_of_the_scalar_assembly_to_the_bit(
        masses in prop::collection::vec(float(0.05, 20.0), 7),
        tensors in prop::collection::vec(prop::collection::vec(float(-1.0, 1.0), 9), 7),
        points in prop::collection::vec(
            (0u32..8, 0u32..8, prop::collection::vec(float(-1.0, 1.0), 9), 1usize..5),
            1..24,
        ),
    ) {
        // Slots 0–5 move; slot 5 is a heavy rod (1000 t, free to turn about x alone),
        // whose friction block against an immovable body is nearly rank one and takes the
        // pseudo-inverse; slot 6 has no mass or inertia (a body that cannot move); slot 7
        // is the island's immovable slot. Body i sits in slot i.
        let slots = 8;
        let mut inertia: Vec<Mat3> = tensors.iter().map(|t| tensor(t)).collect();
        inertia[5] = Mat3::from_diagonal(Vec3::new(1000.0, 0.0, 0.0));
        inertia[6] = Mat3::ZERO;
        inertia.push(Mat3::ZERO);
        let inverse_mass = |slot: u32| match slot {
            0..=4 => Vec3::splat(1.0 / masses[slot as usize]),
            5 => Vec3::splat(1e-6),
            _ => Vec3::ZERO,
        };
        let mut pending = Vec::new();
        for (pair, (a, b, numbers, repeat)) in points.into_iter().enumerate() {
            let b = if a == b { 7 } else { b };
            let normal = Vec3::new(numbers[0], numbers[1], numbers[2] + 1.5).normalize();
            let (t1, t2) = normal.any_orthonormal_pair();
            let lever_a = Vec3::new(numbers[3], numbers[4], numbers[5]);
            let lever_b = Vec3::new(numbers[6], numbers[7], numbers[8]);
            let row = |d: Vec3| JacobianRow {
                direction: d,
                angular_a: lever_a.cross(d),
                angular_b: lever_b.cross(d),
                ..JacobianRow::default()
            };
            // A manifold's points come together: `repeat` points of this pair.
            for k in 0..repeat {
                pending.push(ContactConstraint {
                    body_a: a,
                    body_b: b,
                    local_a: a,
                    local_b: b,
                    inverse_mass_a: inverse_mass(a),
                    inverse_mass_b: inverse_mass(b),
                    normal: row(normal),
                    tangents: [row(t1), row(t2)],
                    lever_a,
                    lever_b,
                    friction: 0.5,
                    normal_impulse: k as f32,
                    products_pending: true,
                    source: (pair as u32, 0, k as u16),
                    ..ContactConstraint::default()
                });
            }
        }
        let mut complete = pending.clone();
        crate::contact::complete_products(&mut complete, &inertia);
        prop_assert!(complete.iter().all(|c| !c.products_pending));
        let mut from_lanes = Bundles::default();
        from_lanes.pack(&pending, slots, &inertia, false);
        let mut from_rows = Bundles::default();
        from_rows.pack(&complete, slots, &inertia, false);
        prop_assert_eq!(packed_bits(&from_lanes), packed_bits(&from_rows));
        // A pack on the last pack's layout resets no bundle: whatever other rows of the
        // same points, and a solve on them, left in the bundles, padding included, a pack
        // of `pending` or `complete` overwrites to the bits of a fresh pack.
        let other: Vec<ContactConstraint> = complete
            .iter()
            .map(|c| {
                let mut c = *c;
                let [t1, t2] = &mut c.tangents;
                for row in [&mut c.normal, t1, t2] {
                    row.angular_a *= 2.0;
                    row.angular_b *= -1.5;
                    row.inverse_inertia_angular_a *= 3.0;
                    row.inverse_inertia_angular_b *= 0.5;
                    row.effective_mass *= 2.0;
                    row.inverse_effective_mass *= 0.5;
                }
                c.tangent_inverse_block = c.tangent_inverse_block.map(|x| 2.0 * x + 1.0);
                c.tangent_block = c.tangent_block.map(|x| 3.0 * x + 0.5);
                (c.lever_a, c.lever_b) = (-c.lever_b, 2.0 * c.lever_a);
                (c.friction, c.normal_impulse) = (0.25, c.normal_impulse + 2.0);
                c.tangent_impulses = [0.125, -0.25];
                c.max_normal_impulse = 7.0;
                c
            })
            .collect();
        let pass = SolvePass {
            iterations: 2,
            tolerance: 0.0,
            friction: true,
            half_turn: false,
            warm_start_follows: false,
            escalate: false,
            targets: None,
            sweep: Sweep::default(),
        };
        for (rows, fresh) in [(&pending, &from_lanes), (&complete, &from_rows)] {
            let mut reused = Bundles::default();
            reused.pack(&other, slots, &inertia, false);
            let (mut linear, mut angular) = (vec![Vec3::ZERO; slots], vec![Vec3::ZERO; slots]);
            let mut velocities = Velocities { linear: &mut linear, angular: &mut angular };
            reused.solve_pgs(&mut velocities, &mut IslandJoints::default(), &pass);
            reused.pack(rows, slots, &inertia, false);
            prop_assert_eq!(packed_bits(&reused), packed_bits(fresh));
        }
    }
}

/// Packing cuts each pair's run of points into manifold groups of at most
/// [`GROUP_POINTS`], puts every point in exactly one lane, keeps a group's points in order
/// in one lane of one lane group, gives no two lane groups of a colour a common moving
/// body, keeps each lane's bodies and masses in the lane group, and leaves every other
/// lane without impulse or effective mass (a lane with no group: the immovable slot and
/// zero masses).
/// The same points in an island of one more slot (another immovable slot) are laid out
/// again: the padding lanes name the new immovable slot, as a fresh pack's do, though no
/// point's body slots changed.
#[test]
fn packing_with_another_slot_count_lays_out_again() {
    let pairs: [((u32, u32), usize); 3] = [((0, 1), 4), ((1, 2), 1), ((2, 3), 3)];
    let mut constraints = Vec::new();
    for ((a, b), points) in pairs {
        for _ in 0..points {
            constraints.push(ContactConstraint {
                local_a: a,
                local_b: b,
                inverse_mass_a: Vec3::ONE,
                inverse_mass_b: Vec3::ONE,
                normal_impulse: 1.0,
                ..ContactConstraint::default()
            });
        }
    }
    let mut reused = Bundles::default();
    reused.pack(&constraints, 5, &[Mat3::ZERO; 5], false);
    reused.pack(&constraints, 6, &[Mat3::ZERO; 6], false);
    let mut fresh = Bundles::default();
    fresh.pack(&constraints, 6, &[Mat3::ZERO; 6], false);
    assert!(fresh.groups.iter().any(|g| g.local_a.contains(&5)));
    assert_eq!(packed_bits(&reused), packed_bits(&fresh));
}

#[test]
fn packing_puts_each_manifold_group_in_one_lane_of_one_lane_group() {
    // Slots 0–6 move, 7 is immovable. (pair, points): a box face (4), a ball (1), an edge
    // (2), a face on the ground (4), a run of 5 that must be cut, and single points that
    // share bodies with all of them.
    let pairs: [((u32, u32), usize); 8] = [
        ((0, 1), 4),
        ((1, 2), 1),
        ((2, 3), 2),
        ((0, 7), 4),
        ((3, 4), 5),
        ((4, 5), 1),
        ((5, 6), 1),
        ((6, 0), 3),
    ];
    let mut constraints = Vec::new();
    for ((a, b), points) in pairs {
        for _ in 0..points {
            let k = constraints.len();
            constraints.push(ContactConstraint {
                local_a: a,
                local_b: b,
                inverse_mass_a: Vec3::ONE,
                inverse_mass_b: if b == 7 { Vec3::ZERO } else { Vec3::ONE },
                normal_impulse: k as f32 + 1.0,
                ..ContactConstraint::default()
            });
        }
    }
    let mut packed = Bundles::default();
    packed.pack(&constraints, 8, &[Mat3::ZERO; 8], false);
    // Every point in exactly one lane, found where `slots` says.
    let mut seen = vec![0; constraints.len()];
    for (index, lanes) in packed.sources.iter().enumerate() {
        for (lane, &k) in lanes.iter().enumerate() {
            let b = &packed.bundles[index];
            if k == u32::MAX {
                assert_eq!(b.normal_impulse.as_array()[lane], 0.0);
                assert_eq!(b.normal.effective_mass.as_array()[lane], 0.0);
                continue;
            }
            seen[k as usize] += 1;
            assert_eq!(packed.slots[k as usize] as usize, index * LANES + lane);
            assert_eq!(b.normal_impulse.as_array()[lane], k as f32 + 1.0);
        }
    }
    assert!(seen.iter().all(|&n| n == 1), "{seen:?}");
    // Lane groups: each lane holds one manifold group, whose bodies and masses the lane
    // group keeps for the lane, its points in order from the first bundle on, at most
    // GROUP_POINTS of them; a lane with none has the immovable slot and zero masses.
    for group in &packed.groups {
        let (start, len) = (group.start as usize, group.len as usize);
        assert!((1..=GROUP_POINTS).contains(&len));
        for lane in 0..LANES {
            let mut previous = None;
            let mut ended = false;
            let slots = (group.local_a[lane], group.local_b[lane]);
            let mass_b = group.inverse_mass_b[0].as_array()[lane];
            for index in start..start + len {
                match packed.sources[index][lane] {
                    u32::MAX => ended = true,
                    k => {
                        assert!(!ended, "a hole inside lane {lane}'s group");
                        let c = &constraints[k as usize];
                        assert_eq!((c.local_a, c.local_b), slots);
                        assert_eq!(c.inverse_mass_b.x, mass_b);
                        if let Some(p) = previous {
                            assert_eq!(k, p + 1, "points out of order");
                        }
                        previous = Some(k);
                    }
                }
            }
            if previous.is_none() {
                assert_eq!(slots, (7, 7));
                for axis in 0..3 {
                    assert_eq!(group.inverse_mass_a[axis].as_array()[lane], 0.0);
                    assert_eq!(group.inverse_mass_b[axis].as_array()[lane], 0.0);
                }
            }
        }
    }
    // Colours: no moving body twice among one colour's lane groups.
    for colour in 0..COLOURS {
        let mut bodies = std::collections::HashSet::new();
        let groups = packed.group_colour_starts[colour]..packed.group_colour_starts[colour + 1];
        for group in &packed.groups[groups] {
            for lane in 0..LANES {
                if packed.sources[group.start as usize][lane] == u32::MAX {
                    continue;
                }
                for slot in [group.local_a[lane], group.local_b[lane]] {
                    assert!(
                        slot == 7 || bodies.insert(slot),
                        "slot {slot} twice in colour {colour}"
                    );
                }
            }
        }
    }
    // The run of five was cut into four and one.
    let lengths: Vec<u32> = packed.groups.iter().map(|g| g.len).collect();
    assert!(
        lengths.iter().all(|&n| n as usize <= GROUP_POINTS),
        "{lengths:?}"
    );
}

/// Each colour's (and half's) manifold groups go into lane groups longest first, so its lane
/// groups take the fewest bundles its groups allow: the sum, over runs of four of its groups'
/// lengths sorted longest first, of each run's longest. Every lane group but the last of a
/// colour and half has all its lanes, and every point is in one lane. Seeded random islands:
/// pairs among 40 moving slots and the ground (the immovable slot), each a run of 1 to 6
/// points (runs of more than four are cut), unsplit and split.
#[test]
fn a_colours_lane_groups_take_the_fewest_bundles() {
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = |n: u64| {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state % n
    };
    for case in 0..40 {
        let slots = 42;
        let immovable = (slots - 1) as u32;
        let mut constraints = Vec::new();
        for pair in 0..60 + next(200) as u32 {
            let a = next(40) as u32;
            let b = match next(41) as u32 {
                b if b == a || b == 40 => immovable,
                b => b,
            };
            for k in 0..1 + next(6) as u16 {
                constraints.push(ContactConstraint {
                    local_a: a,
                    local_b: b,
                    inverse_mass_a: Vec3::ONE,
                    inverse_mass_b: if b == immovable {
                        Vec3::ZERO
                    } else {
                        Vec3::ONE
                    },
                    source: (pair, 0, k),
                    ..ContactConstraint::default()
                });
            }
        }
        let mut packed = Bundles::default();
        if case % 2 == 1 {
            packed.set_second_half(Some(20));
        }
        packed.pack(&constraints, slots, &[Mat3::ZERO; 42], false);
        let mut seen = vec![0; constraints.len()];
        for colour in 0..=COLOURS {
            let starts = &packed.group_colour_starts;
            let halves = [
                starts[colour]..packed.group_half_starts[colour],
                packed.group_half_starts[colour]..starts[colour + 1],
            ];
            for range in halves {
                let mut lengths = Vec::new();
                let mut bundles = 0;
                let last = range.end.saturating_sub(1);
                for g in range {
                    let group = &packed.groups[g];
                    let (start, len) = (group.start as usize, group.len as usize);
                    bundles += len;
                    let mut filled = 0;
                    for lane in 0..LANES {
                        let points = packed.sources[start..start + len]
                            .iter()
                            .filter(|lanes| lanes[lane] != u32::MAX)
                            .inspect(|lanes| seen[lanes[lane] as usize] += 1)
                            .count();
                        if points > 0 {
                            lengths.push(points);
                            filled += 1;
                        }
                    }
                    assert!(filled > 0, "case {case}: an empty lane group");
                    if colour < COLOURS && g != last {
                        assert_eq!(filled, LANES, "case {case}: colour {colour}");
                    }
                }
                lengths.sort_unstable_by(|x, y| y.cmp(x));
                let per = if colour < COLOURS { LANES } else { 1 };
                let fewest: usize = lengths.chunks(per).map(|run| run[0]).sum();
                assert_eq!(bundles, fewest, "case {case}: colour {colour} {lengths:?}");
            }
        }
        assert!(seen.iter().all(|&n| n == 1), "case {case}: {seen:?}");
    }
}

/// A pair's manifolds (a compound's parts, a mesh's triangles) have normals of their own,
/// which their lane group keeps per lane: each manifold is a manifold group of its own,
/// even where its points follow another manifold's of the same pair, and its lane's
/// directions are its points'.
#[test]
fn packing_gives_each_manifold_of_a_pair_its_own_lane_and_directions() {
    // One pair (slots 0 and 1, 2 immovable) with two manifolds of two points each, whose
    // normals differ: up the y axis and tilted.
    let tilted = Vec3::new(0.6, 0.8, 0.0);
    let mut constraints = Vec::new();
    for (manifold, normal) in [(0u16, Vec3::Y), (1, tilted)] {
        for point in 0..2u16 {
            let mut c = ContactConstraint {
                local_a: 0,
                local_b: 1,
                inverse_mass_a: Vec3::ONE,
                inverse_mass_b: Vec3::ONE,
                friction: 0.5,
                source: (0, manifold, point),
                ..ContactConstraint::default()
            };
            c.normal.direction = normal;
            c.tangents[0].direction = normal.any_orthonormal_vector();
            c.tangents[1].direction = normal.cross(c.tangents[0].direction);
            constraints.push(c);
        }
    }
    let mut packed = Bundles::default();
    packed.pack(&constraints, 3, &[Mat3::ZERO; 3], false);
    // Two manifold groups of two points: two lane groups (they share both bodies).
    assert_eq!(packed.runs, [0, 2, 4]);
    assert_eq!(packed.groups.len(), 2);
    for (k, c) in constraints.iter().enumerate() {
        let slot = packed.slots[k] as usize;
        let (index, lane) = (slot / LANES, slot % LANES);
        let group = packed
            .groups
            .iter()
            .find(|g| (g.start as usize..(g.start + g.len) as usize).contains(&index))
            .expect("every bundle belongs to a lane group");
        let lanes = |v: &LaneVec| Vec3::from_array(v.map(|x| x.as_array()[lane]));
        assert_eq!(lanes(&group.directions[0]), c.normal.direction);
        assert_eq!(lanes(&group.directions[1]), c.tangents[0].direction);
        assert_eq!(lanes(&group.directions[2]), c.tangents[1].direction);
        assert_eq!(group.friction.as_array()[lane], 0.5);
    }
}

#[test]
fn sliding_step_is_the_inverse_of_the_larger_eigenvalue() {
    assert_eq!(sliding_step([2.0, 0.0, 1.0]), 0.5);
    assert_eq!(sliding_step([1.0, 0.0, 4.0]), 0.25);
    // [[2, 1], [1, 2]] has eigenvalues 3 and 1.
    assert!((sliding_step([2.0, 1.0, 2.0]) - 1.0 / 3.0).abs() < 1e-7);
    assert_eq!(sliding_step([0.0, 0.0, 0.0]), 0.0);
    assert_eq!(sliding_step([f32::NAN, 0.0, 1.0]), 0.0);
}

/// One lane's case: the unconstrained solution's offset c (2), K's a, correlation ρ, d, and
/// the disc's radius.
type Case = (f32, f32, f32, f32, f32, f32);

proptest! {
    /// The lanes' update repeated on one point's block problem, min ½γᵀKγ + cᵀγ over the
    /// disc |γ| ≤ r (the tangent velocity is v = Kγ + c), reaches the problem's solution:
    /// the projection of q = −K⁻¹c onto the disc in K's metric, which the scalar update
    /// computes directly ([`crate::solver::project_to_friction_disc`]). Each lane gets a
    /// different case; sticking lanes reach it in one update, sliding ones converge.
    #[test]
    fn repeated_update_reaches_the_block_problems_solution(
        cases in proptest::collection::vec(
            (
                float(-10.0, 10.0),
                float(-10.0, 10.0),
                float(0.5, 5.0),
                float(-0.8, 0.8),
                float(0.5, 5.0),
                float(0.0, 5.0),
            ),
            LANES,
        )
    ) {
        // K = [[a, b], [b, d]] with b = ρ·√(a d), |ρ| < 1: symmetric positive definite,
        // with a condition number below 90.
        let block = |c: &Case| [c.2, c.3 * (c.2 * c.4).sqrt(), c.4];
        let lane = |f: &dyn Fn(&Case) -> f32| {
            Lane::new(std::array::from_fn(|i| f(&cases[i])))
        };
        let inverse = |c: &Case| {
            let [a, b, d] = block(c);
            let det = a * d - b * b;
            [d / det, -b / det, a / det]
        };
        let k = [lane(&|c| block(c)[0]), lane(&|c| block(c)[1]), lane(&|c| block(c)[2])];
        let k_inverse = [
            lane(&|c| inverse(c)[0]),
            lane(&|c| inverse(c)[1]),
            lane(&|c| inverse(c)[2]),
        ];
        let offset = [lane(&|c| c.0), lane(&|c| c.1)];
        let step = lane(&|c| sliding_step(block(c)));
        let limit = lane(&|c| c.5);
        let mut impulse = [Lane::splat(0.0); 2];
        for _ in 0..2000 {
            let velocity = [
                k[0] * impulse[0] + k[1] * impulse[1] + offset[0],
                k[1] * impulse[0] + k[2] * impulse[1] + offset[1],
            ];
            impulse = friction_update(impulse, velocity, k_inverse, step, limit);
        }
        let [x, y] = impulse.map(|v| v.to_array());
        for (i, c) in cases.iter().enumerate() {
            let [i11, i12, i22] = inverse(c);
            let q = [-(i11 * c.0 + i12 * c.1), -(i12 * c.0 + i22 * c.1)];
            let expected = crate::solver::project_to_friction_disc(q, block(c), c.5);
            let norm = (x[i] * x[i] + y[i] * y[i]).sqrt();
            prop_assert!(norm <= c.5 * (1.0 + 1e-5) + 1e-7, "lane {i}: |γ| = {norm} > {}", c.5);
            let scale = c.5.max(1e-3);
            prop_assert!(
                (x[i] - expected[0]).abs() <= 1e-3 * scale
                    && (y[i] - expected[1]).abs() <= 1e-3 * scale,
                "lane {i}: ({}, {}) against the block solution {:?}", x[i], y[i], expected
            );
        }
    }
}

/// `Fused` rounds a·b + c once, `Separate` twice: with a = b = 1 + 2⁻¹² and c = −(1 + 2⁻¹¹),
/// a·b = 1 + 2⁻¹¹ + 2⁻²⁴ exactly, which single precision (spacing 2⁻²³ above one) rounds to
/// 1 + 2⁻¹¹ (the tie to even), so the separate sum is 0 and the fused one 2⁻²⁴. On a CPU
/// whose kernels have no FMA the fused kernel is never chosen, and this checks `Separate` only.
#[test]
fn fused_multiply_add_rounds_once() {
    use crate::simd::{InstructionSet, on_instruction_set};
    let a = Lane::splat(1.0 + 2f32.powi(-12));
    let c = Lane::splat(-(1.0 + 2f32.powi(-11)));
    assert_eq!(Separate::mul_add(a, a, c).to_array(), [0.0; LANES]);
    let widest = InstructionSet::supported_widest();
    if widest == InstructionSet::Baseline || cfg!(feature = "lanes8") {
        eprintln!("no kernel with FMA on this CPU or build: only the separate rounding checked");
        return;
    }
    // SAFETY (of `Fused` inside): `widest` runs on this CPU and has FMA.
    let fused = on_instruction_set!(widest, Fused::mul_add(a, a, c));
    assert_eq!(fused.to_array(), [2f32.powi(-24); LANES]);
    // The dot product and the scaled addition are built from it.
    let v = [a, Lane::splat(0.0), Lane::splat(0.0)];
    let fused_dot = on_instruction_set!(widest, dot::<Fused>(v, v));
    assert_eq!(fused_dot.to_array(), (a * a).to_array());
    let fused_add = on_instruction_set!(widest, add_scaled::<Fused>([c; 3], v, a));
    assert_eq!(fused_add[0].to_array(), [2f32.powi(-24); LANES]);
    assert_eq!(
        add_scaled::<Separate>([c; 3], v, a)[0].to_array(),
        [0.0; LANES]
    );
}

mod scalar_agreement;
mod scenes;

/// A split island's pack (`set_second_half`) holds the same manifold groups as the unsplit
/// one; the groups joining the two halves take colours after every other group's
/// (`halves_apart`); in each colour before those, the first half's lane groups (by the lower
/// moving slot) come first and the second half's after `group_half_starts`, no lane group
/// holding both, and the two halves' lane groups of all those colours share no moving slot,
/// so they can be swept at once.
#[test]
fn a_split_pack_puts_the_groups_joining_the_halves_last_and_keeps_the_halves_apart() {
    // A chain of 12 moving slots (12 immovable, which the last link reaches): links of 1 to 4
    // points, and every slot on the ground; the second half starts at slot 6, so the link
    // between slots 5 and 6 joins the halves.
    let (slots, second) = (13usize, 6u32);
    let mut constraints = Vec::new();
    for a in 0..12u32 {
        let pairs = [(a, a + 1, 1 + (a as usize % 4)), (a, 12, 2)];
        for (a, b, points) in pairs {
            for _ in 0..points {
                constraints.push(ContactConstraint {
                    local_a: a,
                    local_b: b,
                    inverse_mass_a: Vec3::ONE,
                    inverse_mass_b: if b == 12 { Vec3::ZERO } else { Vec3::ONE },
                    ..ContactConstraint::default()
                });
            }
        }
    }
    let inertia = vec![Mat3::ZERO; slots];
    let mut whole = Bundles::default();
    whole.pack(&constraints, slots, &inertia, false);
    let mut split = Bundles::default();
    split.set_second_half(Some(second));
    split.pack(&constraints, slots, &inertia, false);
    assert!(split.split() && !whole.split());
    assert_eq!(whole.halves_apart, 0);
    let lanes_of = |packed: &Bundles, groups: std::ops::Range<usize>| -> Vec<(u32, u32)> {
        packed.groups[groups]
            .iter()
            .flat_map(|g| (0..LANES).map(move |lane| (g.local_a[lane], g.local_b[lane])))
            .filter(|&pair| pair != (12, 12))
            .collect()
    };
    let colours = split.group_colour_starts.len() - 1;
    let apart = split.halves_apart;
    assert!(apart > 0 && apart < colours, "{apart} of {colours} colours");
    let mut halves_slots = [Vec::new(), Vec::new()];
    for colour in 0..colours {
        let (start, middle, end) = (
            split.group_colour_starts[colour],
            split.group_half_starts[colour],
            split.group_colour_starts[colour + 1],
        );
        assert!(start <= middle && middle <= end);
        for (half, groups) in [(0, start..middle), (1, middle..end)] {
            for (a, b) in lanes_of(&split, groups) {
                let joins = b != 12 && (a < second) != (b < second);
                assert_eq!(joins, colour >= apart, "colour {colour}: ({a}, {b})");
                if colour < apart {
                    assert_eq!(u32::from(a.min(b) >= second), half, "colour {colour}");
                    halves_slots[half as usize].extend([a, b].into_iter().filter(|&s| s != 12));
                }
            }
        }
    }
    let [first, second_slots] = &halves_slots;
    assert!(!first.is_empty() && !second_slots.is_empty());
    assert!(first.iter().all(|slot| !second_slots.contains(slot)));
    // The same manifold groups, as a multiset of body pairs.
    let mut pairs = [&split, &whole].map(|packed| {
        let mut pairs = lanes_of(packed, 0..packed.groups.len());
        pairs.sort_unstable();
        pairs
    });
    let [split_pairs, whole_pairs] = &mut pairs;
    assert_eq!(split_pairs, whole_pairs);
}

/// A bundle whose points carry no impulse and stay apart (no normal impulse after the normal
/// rows' update) skips its friction update: over seeded random rows and velocities, the
/// update gives the impulses, velocities and row velocity change that the normal and friction
/// updates give one after the other (equal as numbers: a zero's sign may differ), and so does
/// a bundle apart whose friction impulses the update must take back (every other case).
#[test]
fn a_bundle_carrying_no_impulse_skips_friction_without_changing_anything() {
    let uniform =
        std::cell::RefCell::new(crate::test_support::seeded_uniform(0x5851_f42d_4c95_7f2d));
    let lanes =
        |low: f32, high: f32| Lane::new(std::array::from_fn(|_| (uniform.borrow_mut())(low, high)));
    for case in 0..200 {
        let vector = |low: f32, high: f32| [lanes(low, high), lanes(low, high), lanes(low, high)];
        let row = || RowLanes {
            angular_a: vector(-1.0, 1.0),
            angular_b: vector(-1.0, 1.0),
            inverse_inertia_angular_a: vector(-2.0, 2.0),
            inverse_inertia_angular_b: vector(-2.0, 2.0),
            effective_mass: lanes(0.1, 5.0),
            inverse_effective_mass: lanes(0.2, 10.0),
        };
        let (normal, tangents) = (row(), [row(), row()]);
        let bundle = Bundle {
            normal,
            // Far below any closing speed here: the normal impulse stays zero.
            target: Lane::splat(-100.0),
            mass_scale: Lane::splat(1.0),
            tangents,
            tangent_inverse_block: [lanes(0.5, 2.0), lanes(-0.2, 0.2), lanes(0.5, 2.0)],
            sliding_step: lanes(0.1, 1.0),
            // Every other case carries friction impulses the update must take back.
            tangent_impulses: if case % 2 == 0 {
                [Lane::splat(0.0); 2]
            } else {
                [lanes(-1.0, 1.0), lanes(-1.0, 1.0)]
            },
            ..Bundle::default()
        };
        let group = Group {
            inverse_mass_a: vector(0.0, 2.0),
            inverse_mass_b: vector(0.0, 2.0),
            directions: [vector(-1.0, 1.0), vector(-1.0, 1.0), vector(-1.0, 1.0)],
            friction: lanes(0.0, 1.0),
            ..Group::default()
        };
        let velocities = BodyLanes {
            linear_a: vector(-3.0, 3.0),
            angular_a: vector(-3.0, 3.0),
            linear_b: vector(-3.0, 3.0),
            angular_b: vector(-3.0, 3.0),
        };
        let (mut skipped, mut skipped_velocities) = (bundle, velocities);
        let change = solve_bundle::<Separate, true>(&mut skipped, &group, &mut skipped_velocities);
        let (mut full, mut full_velocities) = (bundle, velocities);
        let full_change = solve_normal::<Separate>(&mut full, &group, &mut full_velocities).max(
            solve_friction::<Separate>(&mut full, &group, &mut full_velocities),
        );
        let numbers =
            |lanes: &[Lane]| -> Vec<f32> { lanes.iter().flat_map(|l| l.to_array()).collect() };
        let state = |b: &Bundle, v: &BodyLanes| {
            let mut all = vec![
                b.normal_impulse,
                b.tangent_impulses[0],
                b.tangent_impulses[1],
            ];
            all.extend(
                v.linear_a
                    .iter()
                    .chain(&v.angular_a)
                    .chain(&v.linear_b)
                    .chain(&v.angular_b),
            );
            numbers(&all)
        };
        assert!(
            numbers(&[skipped.normal_impulse]).iter().all(|&x| x == 0.0),
            "case {case}"
        );
        assert_eq!(
            state(&skipped, &skipped_velocities),
            state(&full, &full_velocities),
            "case {case}"
        );
        assert_eq!(numbers(&[change]), numbers(&[full_change]), "case {case}");
    }
}
