//! Stage 4 of the step: contact points → constraint rows (one normal row and two friction rows
//! per point), each a flat record of the numbers the solver needs and nothing else.
//!
//! Row i of the Jacobian J acting on (v_a, ω_a, v_b, ω_b) is (dᵀ, (r_a×d)ᵀ, −dᵀ, −(r_b×d)ᵀ)
//! for direction d (docs/method.md, "Contacts"); body A is the one the normal points towards.

use glam::{Mat3, Mat3A, Vec3, Vec3A};

use crate::body::Bodies;
use crate::collision::narrow_phase::{ContactPair, NarrowPhase};
use crate::island::Islands;
use crate::parallel::{PAIRS_PER_TASK, spread};
use crate::settings::{ContactRepair, SolverSettings};
use crate::simd::{InstructionSet, on_instruction_set};
use rayon::prelude::*;

/// One row of J for a direction d, with the products the solver reuses every sweep.
#[derive(Clone, Copy, Debug, Default)]
pub struct JacobianRow {
    /// Linear part d (unit vector) for body A; body B's is −d.
    pub direction: Vec3,
    /// Angular part for body A: r_a × d.
    pub angular_a: Vec3,
    /// Angular part for body B (with a minus sign in J): r_b × d.
    pub angular_b: Vec3,
    /// I_a⁻¹ (r_a × d): change of ω_a per unit impulse.
    pub inverse_inertia_angular_a: Vec3,
    /// I_b⁻¹ (r_b × d): change of ω_b per unit impulse (applied with a minus sign).
    pub inverse_inertia_angular_b: Vec3,
    /// m_eff = 1 / (J M⁻¹ Jᵀ) of this row alone (kg); 0 when both bodies are immovable.
    pub effective_mass: f32,
    /// J M⁻¹ Jᵀ of this row alone (1/kg): the row's velocity change per unit impulse.
    pub inverse_effective_mass: f32,
    /// J·v* before any impulse of this step (m/s): the row's v⁻.
    pub velocity_before: f32,
}

/// dᵀ·M⁻¹·e (1/kg) for a body of per-axis inverse mass `inverse_mass` (1/kg per world axis,
/// zero on locked translation axes) and directions d, e: the linear part of an entry of
/// J M⁻¹ Jᵀ. For an isotropic inverse mass m (no translation locked) it is m·(d·e),
/// computed so as that product (not through m·e), which keeps unlocked bodies' results to the
/// bit those of a scalar inverse mass.
#[inline]
pub(crate) fn linear_inverse_mass(inverse_mass: Vec3, d: Vec3, e: Vec3) -> f32 {
    if is_isotropic(inverse_mass) {
        inverse_mass.x * d.dot(e)
    } else {
        d.dot(inverse_mass * e)
    }
}

/// Whether a per-axis inverse mass is the same on every axis (no translation locked).
#[inline]
pub(crate) fn is_isotropic(inverse_mass: Vec3) -> bool {
    inverse_mass.x == inverse_mass.y && inverse_mass.y == inverse_mass.z
}

/// dᵀ·M⁻¹·d (1/kg) for a unit direction d: 1/m when no translation is locked (not
/// m·|d|², which rounds), the sum over the free axes of d_i²/m otherwise.
#[inline]
fn inverse_mass_along(inverse_mass: Vec3, d: Vec3) -> f32 {
    if is_isotropic(inverse_mass) {
        inverse_mass.x
    } else {
        d.dot(inverse_mass * d)
    }
}

/// The linear part of a pair's diagonal entries dᵀ(M_a⁻¹ + M_b⁻¹)d, decided once per pair:
/// with no translation locked it is the same 1/m_a + 1/m_b for every direction.
#[derive(Clone, Copy)]
enum PairInverseMass {
    /// 1/m_a + 1/m_b (1/kg).
    Isotropic(f32),
    /// The per-axis inverse masses of A and B.
    Locked(Vec3, Vec3),
}

impl PairInverseMass {
    fn new(inverse_mass_a: Vec3, inverse_mass_b: Vec3) -> Self {
        if is_isotropic(inverse_mass_a) && is_isotropic(inverse_mass_b) {
            Self::Isotropic(inverse_mass_a.x + inverse_mass_b.x)
        } else {
            Self::Locked(inverse_mass_a, inverse_mass_b)
        }
    }

    /// dᵀ(M_a⁻¹ + M_b⁻¹)d (1/kg) for a unit direction d.
    #[inline(always)]
    fn along(self, d: Vec3) -> f32 {
        match self {
            Self::Isotropic(sum) => sum,
            Self::Locked(a, b) => inverse_mass_along(a, d) + inverse_mass_along(b, d),
        }
    }
}

impl JacobianRow {
    /// Sets the row's angular parts r × d for its direction d and lever arms `r_a`, `r_b` (m).
    #[inline(always)]
    fn set_angular(&mut self, r_a: Vec3A, r_b: Vec3A) {
        let d = Vec3A::from(self.direction);
        self.angular_a = r_a.cross(d).into();
        self.angular_b = r_b.cross(d).into();
    }

    /// Computes I⁻¹(r × d) for both bodies and the row's effective mass from its angular parts,
    /// for bodies of world inverse inertia `inverse_inertia_a`, `inverse_inertia_b`. In SIMD
    /// registers (`Vec3A`, `Mat3A`): the same products and sums in the same order as with
    /// `Vec3`, so the same results to the bit, in fewer instructions; the SIMD lanes compute
    /// them in this order too (`wide::Bundles::pack`).
    #[inline(always)]
    fn fill_products(
        &mut self,
        inverse_mass: PairInverseMass,
        inverse_inertia_a: &Mat3A,
        inverse_inertia_b: &Mat3A,
    ) {
        let angular_a = Vec3A::from(self.angular_a);
        let angular_b = Vec3A::from(self.angular_b);
        let inverse_inertia_angular_a = *inverse_inertia_a * angular_a;
        let inverse_inertia_angular_b = *inverse_inertia_b * angular_b;
        let k = inverse_mass.along(self.direction)
            + angular_a.dot(inverse_inertia_angular_a)
            + angular_b.dot(inverse_inertia_angular_b);
        self.inverse_inertia_angular_a = inverse_inertia_angular_a.into();
        self.inverse_inertia_angular_b = inverse_inertia_angular_b.into();
        self.effective_mass = if k > 0.0 { 1.0 / k } else { 0.0 };
        self.inverse_effective_mass = k;
    }

    /// J·v for the current velocities of A and B (m/s); positive means separating.
    #[inline(always)]
    pub fn velocity(
        &self,
        linear_a: Vec3,
        angular_a: Vec3,
        linear_b: Vec3,
        angular_b: Vec3,
    ) -> f32 {
        self.direction.dot(linear_a - linear_b) + self.angular_a.dot(angular_a)
            - self.angular_b.dot(angular_b)
    }
}

/// All rows of one contact point: 376 bytes, the size the solver's comments and
/// docs/benchmarks.md reason with (checked below).
#[derive(Clone, Copy, Debug, Default)]
pub struct ContactConstraint {
    /// Body the normal points towards.
    pub body_a: u32,
    /// The other body.
    pub body_b: u32,
    /// A's index in its island's local arrays (set by the island stage); static bodies map to
    /// the island's immovable slot.
    pub local_a: u32,
    /// B's index in its island's local arrays.
    pub local_b: u32,
    /// Per-axis inverse mass of A (1/kg per world axis): 1/m_a on free translation axes, 0 on
    /// locked ones; a linear impulse p changes v_a by `inverse_mass_a * p` component by
    /// component. `Vec3::splat(1/m_a)` for a body with no translation locked.
    pub inverse_mass_a: Vec3,
    /// Per-axis inverse mass of B, as `inverse_mass_a`.
    pub inverse_mass_b: Vec3,
    /// Normal row; its impulse γ_n ≥ 0.
    pub normal: JacobianRow,
    /// Two friction rows along orthonormal tangents. Solved together, with the friction
    /// impulse (γ_t1, γ_t2) kept inside Coulomb's disc |γ_t| ≤ μ·γ_n.
    pub tangents: [JacobianRow; 2],
    /// Inverse of the 2×2 tangent block K = J_t M⁻¹ J_tᵀ, as (K⁻¹₁₁, K⁻¹₁₂, K⁻¹₂₂) (kg). The
    /// two rows are coupled through the bodies' rotation (K₁₂ ≠ 0 off the centre line); solving
    /// them one at a time leaves a residual that rotates between the tangents and, iterated over
    /// a tall stack, pumps energy into it.
    pub tangent_inverse_block: [f32; 3],
    /// The tangent block K itself, (K₁₁, K₁₂, K₂₂) (1/kg), for the friction disc projection.
    pub tangent_block: [f32; 3],
    /// Target normal velocity of the current solve (m/s): v⁺ ≥ target, equality where γ_n > 0.
    /// Set per substep by [`update_targets`] from the current separation, and for bouncing
    /// contacts by [`restitution_targets`].
    pub target_normal_velocity: f32,
    /// Softness of the normal row in the current solve, (mass scale, impulse scale): the update
    /// is Δγ = m_eff·mass_scale·(target − v) − impulse_scale·γ. (1, 0) is a rigid row.
    pub softness: (f32, f32),
    /// Split impulse: the repair speed the position solve aims for (m/s, ≥ 0; 0 = no push),
    /// and the pseudo-impulse it has accumulated this substep (N·s).
    pub position_target: f32,
    /// See `position_target`.
    pub position_impulse: f32,
    /// Lever arm r_a from A's centre of mass to the contact point at assembly (m): A's own
    /// surface point for a speculative contact (a gap), else the middle of the two surface
    /// points.
    pub lever_a: Vec3,
    /// Lever arm r_b from B's centre of mass to the contact point at assembly (m), as
    /// `lever_a`.
    pub lever_b: Vec3,
    /// Restitution coefficient c_r of the pair.
    pub restitution: f32,
    /// Coulomb coefficient μ of the pair.
    pub friction: f32,
    /// Accumulated normal impulse γ_n (N·s).
    pub normal_impulse: f32,
    /// Accumulated friction impulses along the two tangents (N·s).
    pub tangent_impulses: [f32; 2],
    /// Penetration depth d (m) at assembly, > 0 when overlapping, < 0 for a speculative gap.
    pub depth: f32,
    /// Largest normal impulse this point received during the step (N·s): a contact that
    /// never pushed did not collide, so it does not bounce.
    pub max_normal_impulse: f32,
    /// Impulses (normal, tangent 1, tangent 2) the point applied over the whole step (N·s):
    /// the sum of each substep's final impulses, plus what the restitution solve added. What
    /// the world reports per contact; the solver never reads it.
    pub step_impulses: [f32; 3],
    /// Where the point lives: (pair, manifold, point) in the narrow phase, for write-back.
    pub source: (u32, u16, u16),
    /// Whether the rows' lever-arm products are yet to be computed: each row's angular parts
    /// `angular_a`/`_b` (r × d, from the lever arms and the direction),
    /// `inverse_inertia_angular_a`/`_b`, `effective_mass` and `inverse_effective_mass`, and the
    /// tangent blocks, which until then hold whatever the row held before (meaningless), as
    /// does the normal row's `velocity_before` (v⁻, which only restitution reads; the step's
    /// record sets every row's J·v* as the step ends). Directions and lever arms are always
    /// set. Assembly leaves the products to the SIMD lanes, which
    /// compute them four points at a time as they pack (`wide::Bundles::pack`), for the points
    /// of islands the lanes solve with no restitution solve after them, whose bodies have no
    /// translation locked; [`complete_products`] computes them for any other reader.
    pub products_pending: bool,
}

const _: () = assert!(std::mem::size_of::<ContactConstraint>() == 376);

impl ContactConstraint {
    /// Computes the rows' angular parts and lever-arm products (see
    /// [`Self::products_pending`]) from the directions and lever arms, for bodies of world
    /// inverse inertia `inverse_inertia_a` and `inverse_inertia_b` (1/(kg·m²)).
    #[inline(always)]
    fn fill_products(&mut self, inverse_inertia_a: &Mat3A, inverse_inertia_b: &Mat3A) {
        let inverse_mass = PairInverseMass::new(self.inverse_mass_a, self.inverse_mass_b);
        let (r_a, r_b) = (Vec3A::from(self.lever_a), Vec3A::from(self.lever_b));
        let [t1, t2] = &mut self.tangents;
        for row in [&mut self.normal, t1, t2] {
            row.set_angular(r_a, r_b);
            row.fill_products(inverse_mass, inverse_inertia_a, inverse_inertia_b);
        }
        let block = tangent_block(&self.tangents, inverse_mass);
        self.tangent_block = block;
        self.tangent_inverse_block = inverse_block(block);
        self.products_pending = false;
    }

    /// The soft normal row's extra diagonal term of A (1/kg): a row with softness (s, i)
    /// updates by Δγ = m_eff·s·(target − v) − i·γ, whose fixed point with γ > 0 is
    /// (v − target) + (i/s)·(1/m_eff)·γ = 0, the rigid row plus (i/s)/m_eff on the diagonal
    /// (ODE's constraint force mixing). 0 for a rigid row, (1, 0).
    #[inline]
    pub fn soft_diagonal(&self) -> f32 {
        let (mass_scale, impulse_scale) = self.softness;
        if impulse_scale != 0.0 && mass_scale > 0.0 {
            impulse_scale / mass_scale * self.normal.inverse_effective_mass
        } else {
            0.0
        }
    }
}

/// Builds one constraint per contact point, laid out island by island as `islands` placed
/// them (within an island, narrow-phase order), with each constraint's local body slots set.
/// `velocity_before` is read from the current velocities: called before gravity is applied, it
/// is the approach velocity v⁻ that restitution reflects. Targets are left at zero. The
/// carried-over impulses are scaled by `settings.warm_start` ([`crate::solver::scale_impulses`]).
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
        let com_a = bodies.center_of_mass(a);
        let com_b = bodies.center_of_mass(b);
        let friction = (bodies.friction[a] * bodies.friction[b]).sqrt();
        let restitution = bodies.restitution[a].max(bodies.restitution[b]);
        let inverse_mass_a = bodies.effective_inverse_mass(a);
        let inverse_mass_b = bodies.effective_inverse_mass(b);
        // The lanes compute the products of points whose bodies have no translation locked
        // (the common case, which their arithmetic covers).
        let lanes_compute_products = self.lanes_compute_products
            && is_isotropic(inverse_mass_a)
            && is_isotropic(inverse_mass_b)
            && settings.solves_in_lanes(self.islands.constraint_range(island).len());
        let inertia_a = &Mat3A::from(self.world_inverse_inertia[a]);
        let inertia_b = &Mat3A::from(self.world_inverse_inertia[b]);
        for (manifold_index, manifold) in pair.manifolds.iter().enumerate() {
            if manifold.points.is_empty() {
                continue;
            }
            // Body B is shape 1: its points and normal are in its part's frame.
            let (part_b, part_a) =
                crate::collision::narrow_phase::manifold_poses(manifold, pose_b, pose_a);
            let normal = part_b.rotation * manifold.local_n1;
            let (t1, t2) = tangent_basis(normal, manifold.data.tangent);
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
                let (at_a, at_b) = if point.dist > WITNESS_LEVER_GAP {
                    (p_a, p_b)
                } else {
                    let middle = 0.5 * (p_a + p_b);
                    (middle, middle)
                };
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
                c.friction = if settings.friction { friction } else { 0.0 };
                c.normal_impulse = warm.normal;
                c.tangent_impulses = [warm.friction.dot(t1), warm.friction.dot(t2)];
                c.depth = -point.dist;
                c.max_normal_impulse = 0.0;
                // Last step's totals, which a sleeping island keeps reporting; an awake
                // island's step starts them from zero.
                c.step_impulses = [
                    warm.step_normal,
                    warm.step_friction.dot(t1),
                    warm.step_friction.dot(t2),
                ];
                c.source = (pair_index, manifold_index as u16, point_index as u16);
                c.products_pending = true;
                if !lanes_compute_products {
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
        // While the rows are in cache, rather than in a pass of its own over every row.
        scale_impulses(out, settings.warm_start);
    }
}

/// (K₁₁, K₁₂, K₂₂) of the tangent block K = J_t M⁻¹ J_tᵀ (1/kg), for bodies of per-axis
/// inverse masses `inverse_mass_a` and `inverse_mass_b`.
fn tangent_block(tangents: &[JacobianRow; 2], inverse_mass: PairInverseMass) -> [f32; 3] {
    let [t1, t2] = tangents;
    let mut k12 = t1.angular_a.dot(t2.inverse_inertia_angular_a)
        + t1.angular_b.dot(t2.inverse_inertia_angular_b);
    // The linear parts couple the rows only through a locked translation axis (t1 ⊥ t2, so
    // t1ᵀ·(m·I)·t2 = 0).
    if let PairInverseMass::Locked(inverse_mass_a, inverse_mass_b) = inverse_mass {
        for inverse_mass in [inverse_mass_a, inverse_mass_b] {
            if !is_isotropic(inverse_mass) {
                k12 += t1.direction.dot(inverse_mass * t2.direction);
            }
        }
    }
    [t1.inverse_effective_mass, k12, t2.inverse_effective_mass]
}

/// (K⁻¹₁₁, K⁻¹₁₂, K⁻¹₂₂) of the tangent block; its pseudo-inverse when the block has rank one,
/// zeros when it is zero (both bodies immovable along the tangents).
fn inverse_block([k11, k12, k22]: [f32; 3]) -> [f32; 3] {
    let determinant = k11 * k22 - k12 * k12;
    if determinant > f32::EPSILON * (k11 * k22).max(f32::MIN_POSITIVE) {
        let inverse = 1.0 / determinant;
        [k22 * inverse, -k12 * inverse, k11 * inverse]
    } else {
        // Rank one: the bodies slide along one tangent direction u only (locked axes, e.g. a
        // body confined to a plane touching it along a line). K = tr(K)·u·uᵀ, whose
        // pseudo-inverse K/tr(K)² stops the motion along u and asks for no impulse across it.
        // Unlocked bodies never get here with K ≠ 0: each contributes at least 1/m on every
        // direction.
        let trace = k11 + k22;
        if trace > 0.0 && trace.is_finite() {
            let scale = 1.0 / (trace * trace);
            [k11 * scale, k12 * scale, k22 * scale]
        } else {
            [0.0; 3]
        }
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

/// Sets every normal row's target for a solve of duration `h` (s), from the separation the
/// contact has now: its separation at assembly plus the normal component of the two bodies'
/// displacement since then, Δp = Δx + Δθ × r (linearised; `displacement` and `rotation` are
/// per body, m and rad). With separation s (= −depth):
///
/// - s > 0, a speculative gap: v⁺ ≥ −s/h, the bodies may close the gap but not overlap;
/// - s ≤ 0, overlap d = −s, `with_repair`: the overlap repair (Baumgarte) v⁺ ≥ c_d·max(d − slop, 0),
///   capped at `max_repair_speed`. With soft repair ([`ContactRepair::Soft`]), c_d and the row's softness
///   come from a damped spring instead ([`soft_contact`]);
/// - s ≤ 0 without repair (the relax solve): v⁺ ≥ 0, rigid.
///
/// A speculative row of a body that had turned by more than [`SPECULATIVE_TURN`] since the step
/// began, as the substep started (`turn`: per body, the square of that angle), is stale
/// ([`speculative_row_is_stale`]) and gets no push: its target is [`STALE_TARGET`], which
/// releases the impulse the warm start gave it. A row whose lever arm lies along its normal (a ball's)
/// does not depend on the body's rotation and is never stale.
///
/// With split impulse, returns whether any row has a repair to make, a position target above
/// `settings.tolerance`: when none has, the position solve would end after its first sweep
/// having changed no row's velocity by more than the tolerance, and the caller skips it. At rest
/// this is the usual case: the repair decays exponentially towards the slop and never quite
/// reaches it. Without split impulse, returns false.
pub(crate) fn update_targets(
    constraints: &mut [ContactConstraint],
    displacement: &[Vec3],
    rotation: &[Vec3],
    turn: &[f32],
    settings: &SolverSettings,
    h: f32,
    with_repair: bool,
) -> bool {
    let mut any_repair = false;
    let (repair_rate, softness) = repair_terms(&settings.repair, h);
    for c in constraints.iter_mut() {
        let (a, b) = (c.local_a as usize, c.local_b as usize);
        let moved = (displacement[a] + rotation[a].cross(c.lever_a))
            - (displacement[b] + rotation[b].cross(c.lever_b));
        let separation = -c.depth + c.normal.direction.dot(moved);
        let stale = separation > 0.0
            && !turn.is_empty()
            && (speculative_row_is_stale(turn[a], c.normal.angular_a, c.lever_a)
                || speculative_row_is_stale(turn[b], c.normal.angular_b, c.lever_b));
        let gap_target = if stale { STALE_TARGET } else { -separation / h };
        let repair = (repair_rate * (-separation - settings.overlap_slop).max(0.0))
            .min(settings.max_repair_speed);
        if settings.split_impulse() {
            // The repair goes to the position solve; the velocity rows stay rigid.
            c.position_target = repair;
            c.position_impulse = 0.0;
            any_repair |= repair > settings.tolerance;
            c.target_normal_velocity = if separation > 0.0 { gap_target } else { 0.0 };
            c.softness = (1.0, 0.0);
            continue;
        }
        (c.target_normal_velocity, c.softness) = if separation > 0.0 {
            (gap_target, (1.0, 0.0))
        } else if with_repair {
            (repair, softness)
        } else {
            (0.0, (1.0, 0.0))
        };
    }
    any_repair
}

/// How far (rad) a body may have turned since the step began for its speculative rows to
/// still push it. A row's gap and its lever arm were taken at the step's start; each substep
/// moves the contact point by the linearised Δθ × r, off by about |Δθ|²·|r|/2, and its
/// response (r × n and I⁻¹ at the start orientation) no longer matches the body. Turned by
/// several radians, a gap that the real motion has opened reads as closed, and the row stops
/// a body where nothing touches it (a "ghost" contact); worse, its impulse, applied through
/// the start orientation's inverse inertia, can add energy as the body's inertia now counts it
/// (a dart that hit a wall at 200 m/s and spins at 460–970 rad/s gained 265–1,140 J/kg in one
/// or two substeps so, tests/ccd.rs). At an eighth of a turn the linearised point is already
/// off by 0.3·|r|. Over the tumbling impacts of tests/ccd.rs (darts and plates at 0, 30 and
/// 100 rad/s about three axes, four angles), the largest energy rise above the lowest was 28
/// J/kg with this limit or with 0.5 rad, 36 J/kg with a quarter turn, and 851 J/kg (21 runs
/// over the blow-up guard) without one. Touching and overlapping rows keep acting: dropping
/// them too let darts through the wall; they hold a body where it is pressed, and continuous
/// collision sweeps its true motion as the step ends.
pub(crate) const SPECULATIVE_TURN: f32 = std::f32::consts::FRAC_PI_4;

/// The target (m/s) of a stale speculative row: far below any approach speed (the blow-up guard
/// stops a body at 10⁴ m/s), so the row's impulse goes to zero, yet small enough that no
/// solver's products of it overflow.
pub(crate) const STALE_TARGET: f32 = -1.0e15;

/// Whether a body's part of a speculative row is stale: the body had turned by more than
/// [`SPECULATIVE_TURN`] since the step began (`turn`, the square of that angle, rad²) and the
/// row's angular part `angular` (r × n) is not negligible next to its lever arm `lever`. A
/// lever arm along the normal (|r × n| ≤ 10⁻³·|r|) gives n·(Δθ × r) = Δθ·(r × n) ≈ 0 and no
/// torque: the row does not depend on the body's rotation.
#[inline]
pub(crate) fn speculative_row_is_stale(turn: f32, angular: Vec3, lever: Vec3) -> bool {
    turn > SPECULATIVE_TURN * SPECULATIVE_TURN
        && angular.length_squared() > 1e-6 * lever.length_squared()
}

/// The stiffest contact spring the soft step takes, as a fraction of the substep rate 1/h.
/// With one sweep a substep, a spring at a quarter of the rate (Box2D v3's cap) pumped energy
/// into resting piles: pyramid20 gained tens of joules, the 400:1 `plate` kept rising; at a
/// fifth they come to rest (docs/benchmarks.md, "Why the soft step is set this way").
pub(crate) const MAX_SOFT_HERTZ_PER_SUBSTEP_RATE: f32 = 0.2;

/// Soft contact as a damped spring of frequency `hertz` (capped at a fifth of the substep
/// rate, [`MAX_SOFT_HERTZ_PER_SUBSTEP_RATE`]) and damping ratio ζ, discretised implicitly over
/// `h` (Catto, "Solver2D" and Box2D v3 `b2MakeSoft`): returns the repair rate (1/s) and (mass
/// scale, impulse scale).
pub(crate) fn soft_contact(hertz: f32, damping_ratio: f32, h: f32) -> (f32, (f32, f32)) {
    let hertz = hertz.min(MAX_SOFT_HERTZ_PER_SUBSTEP_RATE / h);
    let omega = 2.0 * std::f32::consts::PI * hertz;
    let a1 = 2.0 * damping_ratio + h * omega;
    let a2 = h * omega * a1;
    let a3 = 1.0 / (1.0 + a2);
    (omega / a1, (a2 * a3, a3))
}

/// The repair rate (1/s) and the soft rows' (mass scale, impulse scale) of `repair` for a
/// substep of `h` seconds: the spring's for soft repair ([`soft_contact`]), the rate with
/// rigid rows (1, 0) otherwise.
pub(crate) fn repair_terms(repair: &ContactRepair, h: f32) -> (f32, (f32, f32)) {
    match *repair {
        ContactRepair::Soft {
            hertz,
            damping_ratio,
        } => soft_contact(hertz, damping_ratio, h),
        ContactRepair::Bias { rate } | ContactRepair::SplitImpulse { rate, .. } => {
            (rate, (1.0, 0.0))
        }
    }
}

/// Newton's restitution hypothesis, v⁺ = −c_r·v⁻, for the points that collided this
/// step: approach speed −v⁻ above the threshold and a normal impulse received. Sets their
/// targets and returns whether any point bounces; other targets are left as they are.
pub(crate) fn restitution_targets(constraints: &mut [ContactConstraint], threshold: f32) -> bool {
    let mut any = false;
    for c in constraints.iter_mut() {
        let approach = c.normal.velocity_before;
        if c.restitution > 0.0 && approach < -threshold && c.max_normal_impulse > 0.0 {
            c.target_normal_velocity = -c.restitution * approach;
            any = true;
        }
    }
    any
}

/// Rewrites each row's `velocity_before` as J·v* for the solve that produced the current
/// impulses: v* = v − M⁻¹Jᵀγ, the velocities without this solve's impulses. With it,
/// (A, b = target − J·v*) is exactly the LCP whose solution the rows now hold, so it can be
/// exported and checked ([`crate::diagnostics::contact_lcp`]). O(rows); `scratch` holds per-body deltas.
///
/// The deltas are summed in up to [`RECORD_PARTS`] parts of consecutive rows, each into its
/// own per-body array, then added part after part; the parts depend only on the number of
/// rows, so the sums are the same on any thread count. With `parallel`, the parts and the
/// second pass (one row at a time, no shared writes) run on rayon's threads, so that a large
/// island does not leave the other threads idle.
/// An island's step ends with the same two passes, the second one fused with its residual
/// ([`crate::diagnostics::record_velocity_before_and_residual`]).
///
/// `slots` says how rows name their bodies, and so how `linear` and `angular` are indexed.
pub(crate) fn record_velocity_before(
    constraints: &mut [ContactConstraint],
    slots: BodySlots,
    linear: &[Vec3],
    angular: &[Vec3],
    parallel: bool,
    scratch: &mut Vec<(Vec3, Vec3)>,
) {
    let parallel = spread(parallel, 1, 0);
    let Some(changes) =
        impulse_velocity_changes(constraints, slots, linear.len(), parallel, scratch)
    else {
        return;
    };
    let bodies_of = slots.bodies_of();
    let record = |c: &mut ContactConstraint| {
        let (a, b) = bodies_of(c);
        record_row(c, a, b, linear, angular, changes);
    };
    if parallel && constraints.len() > PAIRS_PER_TASK {
        constraints
            .par_iter_mut()
            .with_min_len(PAIRS_PER_TASK)
            .for_each(record);
    } else {
        constraints.iter_mut().for_each(record);
    }
}

/// The first pass of [`record_velocity_before`]: per body slot (below `bodies`), the velocity
/// change M⁻¹Jᵀγ of the rows' current impulses, as (linear, angular), summed in parts as
/// described there. `None` when there are no bodies.
pub(crate) fn impulse_velocity_changes<'s>(
    constraints: &[ContactConstraint],
    slots: BodySlots,
    bodies: usize,
    parallel: bool,
    scratch: &'s mut Vec<(Vec3, Vec3)>,
) -> Option<&'s [(Vec3, Vec3)]> {
    if bodies == 0 {
        return None;
    }
    let bodies_of = slots.bodies_of();
    let parts = constraints
        .len()
        .div_ceil(RECORD_POINTS_PER_PART)
        .clamp(1, RECORD_PARTS);
    let per_part = constraints.len().div_ceil(parts).max(1);
    scratch.clear();
    scratch.resize(parts * bodies, (Vec3::ZERO, Vec3::ZERO));
    let add_part = |(rows, deltas): (&[ContactConstraint], &mut [(Vec3, Vec3)])| {
        for c in rows {
            let (a, b) = bodies_of(c);
            let rows = [
                (&c.normal, c.normal_impulse),
                (&c.tangents[0], c.tangent_impulses[0]),
                (&c.tangents[1], c.tangent_impulses[1]),
            ];
            for (row, impulse) in rows {
                deltas[a].0 += row.direction * (c.inverse_mass_a * impulse);
                deltas[a].1 += row.inverse_inertia_angular_a * impulse;
                deltas[b].0 -= row.direction * (c.inverse_mass_b * impulse);
                deltas[b].1 -= row.inverse_inertia_angular_b * impulse;
            }
        }
    };
    if parallel && parts > 1 {
        constraints
            .par_chunks(per_part)
            .zip(scratch.par_chunks_mut(bodies))
            .for_each(add_part);
    } else {
        constraints
            .chunks(per_part)
            .zip(scratch.chunks_mut(bodies))
            .for_each(add_part);
    }
    let (first, later) = scratch.split_at_mut(bodies);
    let later = &*later;
    let sum = |(i, delta): (usize, &mut (Vec3, Vec3))| {
        for part in 1..parts {
            let (l, a) = later[(part - 1) * bodies + i];
            delta.0 += l;
            delta.1 += a;
        }
    };
    if parts > 1 {
        if parallel {
            first.par_iter_mut().enumerate().for_each(sum);
        } else {
            first.iter_mut().enumerate().for_each(sum);
        }
    }
    Some(first)
}

/// The second pass of [`record_velocity_before`] on one row, whose bodies are at `a` and `b`:
/// its rows' J·v* from the velocities and the `changes` of [`impulse_velocity_changes`].
#[inline(always)]
pub(crate) fn record_row(
    c: &mut ContactConstraint,
    a: usize,
    b: usize,
    linear: &[Vec3],
    angular: &[Vec3],
    changes: &[(Vec3, Vec3)],
) {
    let (la, aa) = (linear[a] - changes[a].0, angular[a] - changes[a].1);
    let (lb, ab) = (linear[b] - changes[b].0, angular[b] - changes[b].1);
    c.normal.velocity_before = c.normal.velocity(la, aa, lb, ab);
    for t in &mut c.tangents {
        t.velocity_before = t.velocity(la, aa, lb, ab);
    }
}

/// Most parts of [`record_velocity_before`]'s first pass: each costs a per-body array.
pub(crate) const RECORD_PARTS: usize = 4;

/// Rows per part of [`record_velocity_before`]'s first pass below [`RECORD_PARTS`] parts:
/// smaller sets of rows are summed in one part, as before the parts existed.
const RECORD_POINTS_PER_PART: usize = 8192;

/// Which indices of a [`ContactConstraint`] name its bodies in a pass over velocity arrays.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum BodySlots {
    /// `body_a` / `body_b`: the world's body arrays.
    World,
    /// `local_a` / `local_b`: one island's local arrays (the immovable slot last, at rest).
    /// The island's step records its rows this way while its data is in cache, on whichever
    /// thread solved it; the result is the world-wide pass's once the velocities are
    /// scattered back.
    Island,
}

impl BodySlots {
    /// A row's two indices into the velocity arrays, (A, B).
    pub(crate) fn bodies_of(self) -> fn(&ContactConstraint) -> (usize, usize) {
        match self {
            BodySlots::World => |c| (c.body_a as usize, c.body_b as usize),
            BodySlots::Island => |c| (c.local_a as usize, c.local_b as usize),
        }
    }
}

/// Scales the impulses carried over from the last step by `fraction` (0 = cold start) and
/// keeps the friction impulse inside its disc.
pub(crate) fn scale_impulses(constraints: &mut [ContactConstraint], fraction: f32) {
    for c in constraints.iter_mut() {
        c.normal_impulse *= fraction;
        c.tangent_impulses[0] *= fraction;
        c.tangent_impulses[1] *= fraction;
        c.tangent_impulses = cap_to_disc(c.tangent_impulses, c.friction * c.normal_impulse);
        c.max_normal_impulse = c.normal_impulse;
    }
}

/// Projects a friction impulse onto Coulomb's disc of radius `limit` (N·s).
#[inline(always)]
pub(crate) fn cap_to_disc(impulse: [f32; 2], limit: f32) -> [f32; 2] {
    let squared = impulse[0] * impulse[0] + impulse[1] * impulse[1];
    if squared <= limit * limit {
        impulse
    } else if squared > 0.0 {
        let scale = limit / squared.sqrt();
        [impulse[0] * scale, impulse[1] * scale]
    } else {
        [0.0, 0.0]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The warm start's fraction scales all three impulses alike, then Coulomb's disc of the
    /// scaled normal impulse caps the friction impulse (a 3-4-5 triangle: |γ_t| = 2.5 after
    /// halving, inside the disc of radius 1.0·5 and outside 0.4·5 = 2).
    #[test]
    fn a_warm_start_fraction_scales_every_impulse_then_caps_friction() {
        let row = |friction| ContactConstraint {
            friction,
            normal_impulse: 10.0,
            tangent_impulses: [3.0, 4.0],
            ..ContactConstraint::default()
        };
        let mut rows = [row(1.0), row(0.4)];
        scale_impulses(&mut rows, 0.5);
        assert_eq!(rows[0].normal_impulse, 5.0);
        assert_eq!(rows[0].tangent_impulses, [1.5, 2.0]);
        assert_eq!(rows[0].max_normal_impulse, 5.0);
        assert_eq!(rows[1].normal_impulse, 5.0);
        let [t1, t2] = rows[1].tangent_impulses;
        assert!(
            (t1 - 1.2).abs() < 1e-6 && (t2 - 1.6).abs() < 1e-6,
            "{t1}, {t2}"
        );
    }

    /// The tangent block's inverse: K·K⁻¹ = I for a full-rank block, and for a rank-one block
    /// K = tr(K)·u·uᵀ (bodies that can slide along one direction u only) the Moore–Penrose
    /// pseudo-inverse K/tr(K)², which satisfies K·K⁺·K = K and K⁺·K·K⁺ = K⁺, here with u off
    /// both tangents (u = (0.6, 0.8)); zeros for a zero block.
    #[test]
    fn the_tangent_block_inverse_is_the_inverse_or_the_pseudo_inverse() {
        let product = |[a11, a12, a22]: [f32; 3], [b11, b12, b22]: [f32; 3]| {
            [
                a11 * b11 + a12 * b12,
                a11 * b12 + a12 * b22,
                a12 * b12 + a22 * b22,
            ]
        };
        let close = |x: [f32; 3], y: [f32; 3]| (0..3).all(|i| (x[i] - y[i]).abs() < 1e-5);
        let full = [2.0, 0.5, 1.0];
        assert!(close(product(full, inverse_block(full)), [1.0, 0.0, 1.0]));
        let rank_one = [2.0 * 0.36, 2.0 * 0.48, 2.0 * 0.64];
        let pseudo = inverse_block(rank_one);
        assert!(
            close(product(product(rank_one, pseudo), rank_one), rank_one),
            "{pseudo:?}"
        );
        assert!(
            close(product(product(pseudo, rank_one), pseudo), pseudo),
            "{pseudo:?}"
        );
        assert_eq!(inverse_block([0.0; 3]), [0.0; 3]);
    }

    /// A speculative row is stale once its body has turned by more than
    /// [`SPECULATIVE_TURN`], not at it, and never when its lever arm lies along its normal (a
    /// ball's row, r × n = 0) or is zero.
    #[test]
    fn a_row_goes_stale_past_the_turn_limit_unless_its_lever_lies_along_the_normal() {
        let limit = SPECULATIVE_TURN * SPECULATIVE_TURN;
        let lever = Vec3::new(0.3, -0.5, 0.0);
        let angular = lever.cross(Vec3::Y);
        assert!(!speculative_row_is_stale(limit, angular, lever));
        assert!(speculative_row_is_stale(limit * 1.001, angular, lever));
        assert!(!speculative_row_is_stale(0.0, angular, lever));
        let along = Vec3::new(0.0, -0.5, 0.0);
        assert!(!speculative_row_is_stale(
            100.0,
            along.cross(Vec3::Y),
            along
        ));
        // A contact at the centre of mass has no lever arm at all.
        assert!(!speculative_row_is_stale(100.0, Vec3::ZERO, Vec3::ZERO));
    }
}
