//! The contact row type: one [`ContactConstraint`] per contact point, each a flat record of
//! the numbers the solver needs and nothing else, with its three [`JacobianRow`]s (one normal
//! row, two friction rows), their lever-arm products and Coulomb's disc of its friction
//! impulse ([`cap_to_disc`]).
//!
//! Row i of the Jacobian J acting on (v_a, ω_a, v_b, ω_b) is (dᵀ, (r_a×d)ᵀ, −dᵀ, −(r_b×d)ᵀ)
//! for direction d (docs/method.md, "Contacts"); body A is the one the normal points towards.

use glam::{Mat3A, Vec3, Vec3A};

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
    /// Where the point lives: (pair, manifold, point) in the narrow phase, where the store-impulses stage writes the impulses back.
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
    /// The rows' lever-arm products and effective masses (every row's, and the tangent
    /// block's) for the lever arms `arm_a`, `arm_b` (m, world frame) and world inverse inertia
    /// tensors `inverse_inertia_a`, `inverse_inertia_b` (1/(kg·m²)) of bodies that have turned
    /// since assembly; `lever_a` and `lever_b` stay the arms at assembly, from which the
    /// targets measure the separation.
    pub(crate) fn turn_products(
        &mut self,
        arm_a: Vec3,
        arm_b: Vec3,
        inverse_inertia_a: &glam::Mat3,
        inverse_inertia_b: &glam::Mat3,
    ) {
        let levers = (self.lever_a, self.lever_b);
        (self.lever_a, self.lever_b) = (arm_a, arm_b);
        self.fill_products(
            &Mat3A::from(*inverse_inertia_a),
            &Mat3A::from(*inverse_inertia_b),
        );
        (self.lever_a, self.lever_b) = levers;
    }

    /// Computes the rows' angular parts and lever-arm products (see
    /// [`Self::products_pending`]) from the directions and lever arms, for bodies of world
    /// inverse inertia `inverse_inertia_a` and `inverse_inertia_b` (1/(kg·m²)).
    #[inline(always)]
    pub(super) fn fill_products(&mut self, inverse_inertia_a: &Mat3A, inverse_inertia_b: &Mat3A) {
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
pub(super) fn inverse_block([k11, k12, k22]: [f32; 3]) -> [f32; 3] {
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

/// Whether some row closed faster than `speed` (m/s) as the step started: its J·v⁻
/// (`velocity_before`, set at assembly and rewritten only as the island's step ends) below
/// −`speed`. What makes a step an impact for the escalation. Only for rows whose products
/// assembly computed (not [`ContactConstraint::products_pending`]): a pending row's
/// `velocity_before` is whatever its slot held; [`closes_faster_than_from_bodies`] serves
/// those.
pub(crate) fn closes_faster_than(constraints: &[ContactConstraint], speed: f32) -> bool {
    constraints
        .iter()
        .any(|c| c.normal.velocity_before < -speed)
}

/// Whether some row closed faster than `speed` (m/s) as the step started, with J·v⁻ computed
/// from the row's normal and lever arms and the bodies' velocities as the step started
/// (`linear` in m/s, `angular` in rad/s, indexed by body as `body_a`, `body_b`): the value
/// assembly gives `velocity_before` (the same operations, so the same bits), for rows whose
/// products are pending too. What makes a step an impact for the solver's extra sweeps.
pub(crate) fn closes_faster_than_from_bodies(
    constraints: &[ContactConstraint],
    linear: &[Vec3],
    angular: &[Vec3],
    speed: f32,
) -> bool {
    constraints
        .iter()
        .any(|c| row_closes_faster_than(c, linear, angular, speed))
}

/// Whether the one row `c` closed faster than `speed` (m/s) as the step started, as
/// [`closes_faster_than_from_bodies`] tests each row.
#[inline]
pub(crate) fn row_closes_faster_than(
    c: &ContactConstraint,
    linear: &[Vec3],
    angular: &[Vec3],
    speed: f32,
) -> bool {
    let (a, b) = (c.body_a as usize, c.body_b as usize);
    normal_jacobian(c).velocity(linear[a], angular[a], linear[b], angular[b]) < -speed
}

/// The normal row's Jacobian of `c` from its normal and lever arms (r × n per body), for the
/// tests that read a row's normal velocity from body velocities.
#[inline]
pub(crate) fn normal_jacobian(c: &ContactConstraint) -> JacobianRow {
    let d = Vec3A::from(c.normal.direction);
    JacobianRow {
        direction: c.normal.direction,
        angular_a: Vec3A::from(c.lever_a).cross(d).into(),
        angular_b: Vec3A::from(c.lever_b).cross(d).into(),
        ..JacobianRow::default()
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
