//! The assembly stage ([`crate::Stage::Assembly`]): contact points → constraint rows, laid out island by island,
//! with friction directions kept from the last step and the impulses of the last step scaled
//! for the warm start.

use glam::{Mat3, Mat3A, Vec3};

use super::row::{ContactConstraint, cap_to_disc, is_isotropic};
use crate::body::Bodies;
use crate::collision::narrow_phase::{ContactPair, NarrowPhase};
use crate::island::Islands;
use crate::parallel::{PAIRS_PER_TASK, spread};
use crate::settings::SolverSettings;
use crate::simd::{InstructionSet, on_instruction_set};
use rayon::prelude::*;

/// Builds one constraint per contact point, laid out island by island as `islands` placed
/// them (within an island, narrow-phase order), with each constraint's local body slots set.
/// `velocity_before` is read from the current velocities: called before gravity is applied, it
/// is the approach velocity v⁻ that restitution reflects. Targets are left at zero. The
/// carried-over impulses are scaled by `settings.warm_start` ([`warm_start_impulses`]).
/// Lever arms reach from `world_center_of_mass` (per body, m, the islands stage's); products
/// come from `world_inverse_inertia` (per body).
///
/// Pairs are read in memory order and written to their islands' rows. With `parallel`, runs of
/// `PAIRS_PER_TASK` (1024) pairs are assembled on rayon's threads, each pair into its own rows of
/// `out` (the narrow phase knows every pair's row count); the result is the same as on one
/// thread.
///
/// With `lanes_compute_products`, the points of islands that `settings` solves in SIMD lanes
/// ([`SolverSettings::solves_in_lanes`]) are left with their lever-arm products pending
/// ([`ContactConstraint::products_pending`]): the lanes compute them as they pack, four points
/// at a time. The caller passes it only when nothing reads those rows' products before the
/// lanes have solved them (no restitution solve after the substeps).
#[allow(clippy::too_many_arguments)]
pub(crate) fn assemble(
    bodies: &Bodies,
    narrow_phase: &NarrowPhase,
    islands: &Islands,
    settings: &SolverSettings,
    world_inverse_inertia: &[Mat3],
    world_center_of_mass: &[Vec3],
    lanes_compute_products: bool,
    parallel: bool,
    out: &mut Vec<ContactConstraint>,
) {
    let pairs = &narrow_phase.pairs;
    let set = InstructionSet::detected();
    let total = islands.constraint_count();
    // Every slot's fields are set below (but a pending point's lever-arm products, see
    // `ContactConstraint::products_pending`); resizing only fills slots the vector did not have.
    out.truncate(total);
    out.resize(total, ContactConstraint::default());
    let context = Assembly {
        bodies,
        pairs,
        islands,
        settings,
        world_inverse_inertia,
        world_center_of_mass,
        lanes_compute_products,
    };
    if spread(parallel, pairs.len(), PAIRS_PER_TASK) {
        let rows = IslandRows {
            start: out.as_mut_ptr(),
            len: out.len(),
        };
        pairs
            .par_chunks(PAIRS_PER_TASK)
            .enumerate()
            .for_each(|(chunk, run)| {
                let first_pair = chunk * PAIRS_PER_TASK;
                on_instruction_set!(set, {
                    for (pair, first, count) in
                        context.rows_in_memory_order(first_pair..first_pair + run.len())
                    {
                        // SAFETY: `Islands::build` gives the pairs with constraints consecutive
                        // row ranges in island order, so no two pairs' ranges overlap, and each
                        // pair belongs to exactly one task; `get` checks the bounds.
                        context.pair(pair, unsafe { rows.get(first, count) });
                    }
                })
            });
    } else {
        on_instruction_set!(set, {
            for (pair, first, count) in context.rows_in_memory_order(0..pairs.len()) {
                context.pair(pair, &mut out[first..first + count]);
            }
        });
    }
}

/// The assembled array shared by the tasks of a parallel assembly, each writing the rows of
/// its own pairs.
#[derive(Clone, Copy)]
struct IslandRows {
    start: *mut ContactConstraint,
    len: usize,
}

// SAFETY: tasks write disjoint row ranges (see `IslandRows::get`'s contract).
unsafe impl Send for IslandRows {}
unsafe impl Sync for IslandRows {}

impl IslandRows {
    /// Rows `first..first + count`.
    ///
    /// # Safety
    /// No other live reference covers any of these rows.
    #[allow(clippy::mut_from_ref)]
    unsafe fn get(&self, first: usize, count: usize) -> &mut [ContactConstraint] {
        assert!(
            first <= self.len && count <= self.len - first,
            "assembly rows out of range"
        );
        // SAFETY: in bounds (checked above); exclusive by the caller's contract.
        unsafe { std::slice::from_raw_parts_mut(self.start.add(first), count) }
    }
}

/// Speculative gap (m) above which a contact's lever arms reach each body's own witness point
/// rather than their middle (see `Assembly::pair`). Resting contacts sit at gaps far below it:
/// lever arms that switched with every micrometre of gap made the `reference` preset's
/// iterations on pyramid20 converge several times more slowly, while the spin error of the
/// middle, gap/(2r), is below 0.5 % of a 10 cm ball's spin under 1 mm.
pub(crate) const WITNESS_LEVER_GAP: f32 = 1e-3;

struct Assembly<'a> {
    bodies: &'a Bodies,
    pairs: &'a [ContactPair],
    islands: &'a Islands,
    settings: &'a SolverSettings,
    world_inverse_inertia: &'a [Mat3],
    world_center_of_mass: &'a [Vec3],
    lanes_compute_products: bool,
}

/// Computes the pending lever-arm products ([`ContactConstraint::products_pending`]) of
/// `constraints`, with `world_inverse_inertia` per body (indexed by `body_a`, `body_b`): the
/// tensors assembly had, so the products are those assembly would have computed, to the bit.
/// For readers of the rows other than the SIMD lanes.
pub(crate) fn complete_products(
    constraints: &mut [ContactConstraint],
    world_inverse_inertia: &[Mat3],
) {
    for c in constraints.iter_mut().filter(|c| c.products_pending) {
        let inertia_a = Mat3A::from(world_inverse_inertia[c.body_a as usize]);
        let inertia_b = Mat3A::from(world_inverse_inertia[c.body_b as usize]);
        c.fill_products(&inertia_a, &inertia_b);
    }
}

impl Assembly<'_> {
    /// The pairs with constraints among `pairs` (a range of pair indices) in memory order, as
    /// (pair index, first row, row count), asking ahead for their manifolds. Assembly reads
    /// the pairs in this order, the narrow phase's, so that pairs, manifolds and bodies come in
    /// sequence, and writes each pair into its island's rows (at [`Islands::first_row`]).
    /// Reading in island order instead would chase pairs all over memory (on balls16k a
    /// column's bodies are 800 indices apart).
    fn rows_in_memory_order(
        &self,
        pairs: std::ops::Range<usize>,
    ) -> impl Iterator<Item = (u32, usize, usize)> + '_ {
        pairs.filter_map(|index| {
            crate::collision::narrow_phase::prefetch_manifolds(self.pairs, index);
            let count = self.pairs[index].point_count();
            (count > 0).then(|| (index as u32, self.islands.first_row(index), count))
        })
    }

    /// Assembles pair `pair_index` into `out`, which has exactly its row count. Inlined
    /// into `assemble`'s loops, which are compiled for each instruction set.
    #[inline(always)]
    fn pair(&self, pair_index: u32, out: &mut [ContactConstraint]) {
        let (bodies, settings) = (self.bodies, self.settings);
        let mut slots = out.iter_mut();
        let pairs = self.pairs;
        let pair = &pairs[pair_index as usize];
        // Parry's shape 1 is body1 and its normal n1 points from shape 1 towards shape 2,
        // so in our convention (n points from B towards A): B = body1, A = body2.
        let (b, a) = (pair.body1 as usize, pair.body2 as usize);
        let island = self.islands.island_of_pair(b, a);
        let (local_a, local_b) = (self.islands.slot(a, island), self.islands.slot(b, island));
        let pose_a = &bodies.pose[a];
        let pose_b = &bodies.pose[b];
        let com_a = self.world_center_of_mass[a];
        let com_b = self.world_center_of_mass[b];
        let friction = settings
            .contact
            .friction_combine
            .combine(bodies.friction[a], bodies.friction[b]);
        let restitution = settings
            .contact
            .restitution_combine
            .combine(bodies.restitution[a], bodies.restitution[b]);
        let roughness = super::roughness::pair_roughness(bodies, a, b);
        let perturbation = super::impact::pair_perturbation(bodies, a, b);
        let inverse_mass_a = bodies.effective_inverse_mass(a);
        let inverse_mass_b = bodies.effective_inverse_mass(b);
        // The lanes compute the products of points whose bodies have no translation locked
        // (the common case, which their arithmetic covers).
        let lanes_compute_products = self.lanes_compute_products
            && is_isotropic(inverse_mass_a)
            && is_isotropic(inverse_mass_b)
            && settings.solves_in_lanes(self.islands.constraint_range(island).len());
        // Only points whose products assembly computes read the tensors.
        let inertia = (!lanes_compute_products).then(|| {
            (
                Mat3A::from(self.world_inverse_inertia[a]),
                Mat3A::from(self.world_inverse_inertia[b]),
            )
        });
        let friction = if settings.contact.friction {
            friction
        } else {
            0.0
        };
        for (manifold_index, manifold) in pair.manifolds.iter().enumerate() {
            if manifold.points.is_empty() {
                continue;
            }
            // Body B is shape 1: its points and normal are in its part's frame.
            let (part_b, part_a) =
                crate::collision::narrow_phase::manifold_poses(manifold, pose_b, pose_a);
            let untilted = part_b.rotation * manifold.local_n1;
            let mut normal = untilted;
            // A rough contact's parts, whose points move with its tilt where they are round.
            let mut rough_parts = None;
            if let Some(draw) = &manifold.data.roughness
                && roughness > 0.0
            {
                normal = super::roughness::tilted(untilted, draw, roughness, &part_b);
                rough_parts = Some((
                    super::roughness::part_shape(bodies.shape[a].as_ref(), manifold.subshape2),
                    super::roughness::part_shape(bodies.shape[b].as_ref(), manifold.subshape1),
                ));
            }
            let (t1, t2) = tangent_basis(normal, manifold.data.tangent);
            // An impact perturbation moves the manifold's restitution by this step's draw.
            let restitution = match manifold.data.impact {
                Some(draw) if perturbation > 0.0 => {
                    super::impact::perturbed_restitution(restitution, perturbation, draw)
                }
                _ => restitution,
            };
            for (point_index, point) in manifold.points.iter().enumerate() {
                let warm = point.data;
                // A speculative contact's impulse acts once its gap has closed, where the two
                // witness points meet: each body's lever arm then reaches its own surface
                // point, so a sphere's is its radius and an oblique impact spins it at the
                // analytic rate (the middle of a gap g gave r + g/2, off by g/(2r): up to a
                // quarter of the spin at dt = 1/60 s; tests/impacts.rs). Touching and
                // overlapping points, and gaps below `WITNESS_LEVER_GAP`, take the middle of
                // the two witness points.
                let p_b = part_b.transform_point(point.local_p1);
                let p_a = part_a.transform_point(point.local_p2);
                let (mut at_a, mut at_b) = if point.dist > WITNESS_LEVER_GAP {
                    (p_a, p_b)
                } else {
                    let middle = 0.5 * (p_a + p_b);
                    (middle, middle)
                };
                // A rough contact's impulse acts where the tilted surfaces touch: through the
                // centre of curvature of a round part (`roughness::tilted_points`).
                if let Some((shape_a, shape_b)) = rough_parts {
                    use super::roughness::{Side, tilted_points};
                    (at_a, at_b) = tilted_points(
                        Side {
                            part: shape_a,
                            pose: &part_a,
                            at: at_a,
                        },
                        Side {
                            part: shape_b,
                            pose: &part_b,
                            at: at_b,
                        },
                        untilted,
                        normal,
                        roughness,
                    );
                }
                let r_a = at_a - com_a;
                let r_b = at_b - com_b;
                let Some(c) = slots.next() else {
                    debug_assert!(false, "fewer slots than the narrow phase's row count");
                    return;
                };
                // Field by field into the row, whose lever-arm products stay as the last step
                // left them while pending (see `ContactConstraint::products_pending`): building
                // the whole row and copying it in cost a sixth of assembly.
                c.body_a = a as u32;
                c.body_b = b as u32;
                c.local_a = local_a;
                c.local_b = local_b;
                c.inverse_mass_a = inverse_mass_a;
                c.inverse_mass_b = inverse_mass_b;
                c.normal.direction = normal;
                c.tangents[0].direction = t1;
                c.tangents[1].direction = t2;
                c.target_normal_velocity = 0.0;
                c.softness = (1.0, 0.0);
                c.position_target = 0.0;
                c.position_impulse = 0.0;
                c.lever_a = r_a;
                c.lever_b = r_b;
                c.restitution = restitution;
                c.friction = friction;
                // Last step's impulses, scaled for the warm start; none after an impact
                // stopped at the step's end (see `impact_stopped_at_step_end`).
                let stopped = impact_stopped_at_step_end(
                    &warm,
                    (inverse_mass_a + inverse_mass_b).dot(normal * normal),
                    settings.contact.restitution_threshold,
                );
                let (normal_impulse, tangent_impulses) = warm_start_impulses(
                    if stopped { 0.0 } else { warm.normal },
                    [warm.friction.dot(t1), warm.friction.dot(t2)],
                    friction,
                    settings.solve.warm_start,
                );
                c.normal_impulse = normal_impulse;
                c.tangent_impulses = tangent_impulses;
                c.max_normal_impulse = normal_impulse;
                c.depth = -point.dist;
                // Last step's totals, which a sleeping island keeps reporting; an awake
                // island's step starts them from zero.
                c.step_impulses = [
                    warm.step_normal,
                    warm.step_friction.dot(t1),
                    warm.step_friction.dot(t2),
                ];
                c.source = (pair_index, manifold_index as u16, point_index as u16);
                c.products_pending = true;
                if let Some((inertia_a, inertia_b)) = &inertia {
                    // Only the normal row's v⁻ is read before the step ends, by restitution,
                    // which a point with pending products never meets; every row's is
                    // rewritten as the step ends ([`record_velocity_before`], or the lanes'
                    // record).
                    c.fill_products(inertia_a, inertia_b);
                    c.normal.velocity_before = c.normal.velocity(
                        bodies.linear_velocity[a],
                        bodies.angular_velocity[a],
                        bodies.linear_velocity[b],
                        bodies.angular_velocity[b],
                    );
                }
            }
        }
        debug_assert!(slots.next().is_none(), "more slots than rows");
    }
}

/// Friction directions: last step's t1 made orthogonal to the new normal, so that a sticking
/// contact keeps its basis and its warm-started friction impulse; any orthonormal pair for a
/// new manifold. The friction impulse is kept inside Coulomb's disc (|γ_t| ≤ μ·γ_n), which
/// does not depend on the basis, so the basis need not follow the sliding direction.
fn tangent_basis(normal: Vec3, previous: Vec3) -> (Vec3, Vec3) {
    let kept = previous - normal * normal.dot(previous);
    if kept.length_squared() > 0.25 {
        let t1 = kept.normalize();
        (t1, normal.cross(t1))
    } else {
        normal.any_orthonormal_pair()
    }
}

/// Whether a point's last step ended with an impact stopped: its last substep took more than
/// half of the step's normal impulse (`warm.normal` against `warm.step_normal`, N·s), enough to
/// change the bodies' approach along the normal by more than `impact_speed` (m/s) with the
/// translational `inverse_mass` along the normal alone (kg⁻¹, the two bodies' summed; turning
/// adds to the change). The last substep's impulse stands for the load a resting point
/// carries into the next step's first substep; such an impulse is a velocity change instead,
/// and warm started onto the bodies now at rest it throws them back (a cube landing flat at
/// 10 m/s just as a step ends rose 11 cm and turned 17° at restitution 0). The point then
/// starts cold, as a new point does. A resting point's impulse comes about evenly over the
/// substeps, and a small one changes no velocity that matters: neither is touched.
#[inline(always)]
pub(crate) fn impact_stopped_at_step_end(
    warm: &crate::collision::manifold::ContactImpulse,
    inverse_mass: f32,
    impact_speed: f32,
) -> bool {
    warm.normal > 0.5 * warm.step_normal && warm.normal * inverse_mass > impact_speed
}

/// The warm start of a point whose last step left it the normal impulse `normal` and the
/// friction impulses `tangents` along its new friction directions (N·s): each scaled by
/// `fraction` (0 = cold start), the friction then kept inside Coulomb's disc of the scaled
/// normal impulse for the point's coefficient `friction`.
#[inline(always)]
pub(crate) fn warm_start_impulses(
    normal: f32,
    tangents: [f32; 2],
    friction: f32,
    fraction: f32,
) -> (f32, [f32; 2]) {
    let normal = normal * fraction;
    let tangents = [tangents[0] * fraction, tangents[1] * fraction];
    (normal, cap_to_disc(tangents, friction * normal))
}
