//! The rows' targets, set per substep: the normal rows' target velocities and softness from
//! the separation each point has reached (gap closing, overlap repair, stale speculative
//! rows), the soft contact's terms, and restitution's targets after the substeps.

use glam::{Mat3, Quat, Vec3};

use super::row::ContactConstraint;
use crate::settings::{ContactRepair, SolverSettings};

/// Sets every normal row's target for a solve of duration `h` (s), from the separation the
/// contact has now: its separation at assembly plus the normal component of the two bodies'
/// displacement since then, Δp = Δx + Δθ × r (linearised; `displacement` and `rotation` are
/// per body, m and rad), plus K·r for a body whose `curvature` K is given (the rest of the
/// turned lever arm, [`turned_arm_remainder`]). With separation s (= −depth):
///
/// - s > 0, a speculative gap: v⁺ ≥ −s/h, the bodies may close the gap but not overlap;
/// - s ≤ 0, overlap d = −s, `with_repair`: the overlap repair (Baumgarte) v⁺ ≥ c_d·max(d − slop, 0),
///   capped at `max_repair_speed`. With soft repair ([`ContactRepair::Soft`]), c_d and the row's softness
///   come from a damped spring instead ([`soft_contact`]);
/// - s ≤ 0 without repair (the relax solve): v⁺ ≥ 0, rigid.
///
/// A speculative row (a gap now, or at assembly) of a body that had turned by more than
/// [`SPECULATIVE_TURN`] since the step began, as the substep started (`turn`: per body, the
/// square of that angle), is stale ([`speculative_row_is_stale`]) and gets no push: its target is [`STALE_TARGET`], which
/// releases the impulse the warm start gave it. A row whose lever arm lies along its normal (a ball's)
/// does not depend on the body's rotation and is never stale.
///
/// With split impulse, returns whether any row has a repair to make, a position target above
/// `settings.tolerance`: when none has, the position solve would end after its first sweep
/// having changed no row's velocity by more than the tolerance, and the caller skips it. At rest
/// this is the usual case: the repair decays exponentially towards the slop and never quite
/// reaches it. Without split impulse, returns false.
#[allow(clippy::too_many_arguments)]
pub(crate) fn update_targets(
    constraints: &mut [ContactConstraint],
    displacement: &[Vec3],
    rotation: &[Vec3],
    turn: &[f32],
    curvature: &[Option<Mat3>],
    settings: &SolverSettings,
    h: f32,
    with_repair: bool,
) -> bool {
    let mut any_repair = false;
    let (repair_rate, softness) = repair_terms(&settings.contact.repair, h);
    for c in constraints.iter_mut() {
        let (a, b) = (c.local_a as usize, c.local_b as usize);
        let mut moved = (displacement[a] + rotation[a].cross(c.lever_a))
            - (displacement[b] + rotation[b].cross(c.lever_b));
        if !curvature.is_empty() {
            let remainder =
                |slot: usize, lever: Vec3| curvature[slot].map_or(Vec3::ZERO, |k| k * lever);
            moved += remainder(a, c.lever_a) - remainder(b, c.lever_b);
        }
        let separation = -c.depth + c.normal.direction.dot(moved);
        // Speculative at assembly (depth < 0) counts too: past the turn limit the linearised
        // separation may read a gap the real motion has opened as closed (see
        // `SPECULATIVE_TURN`), and the row would act as a touching one.
        let stale = (separation > 0.0 || c.depth < 0.0)
            && !turn.is_empty()
            && (speculative_row_is_stale(turn[a], c.normal.angular_a, c.lever_a)
                || speculative_row_is_stale(turn[b], c.normal.angular_b, c.lever_b));
        let gap_target = if stale { STALE_TARGET } else { -separation / h };
        let repair = if stale {
            0.0
        } else {
            (repair_rate * (-separation - settings.contact.overlap_slop).max(0.0))
                .min(settings.contact.max_repair_speed)
        };
        if settings.split_impulse() {
            // The repair goes to the position solve; the velocity rows stay rigid.
            c.position_target = repair;
            c.position_impulse = 0.0;
            any_repair |= repair > settings.solve.tolerance;
            c.target_normal_velocity = if separation > 0.0 || stale {
                gap_target
            } else {
                0.0
            };
            c.softness = (1.0, 0.0);
            continue;
        }
        (c.target_normal_velocity, c.softness) = if separation > 0.0 || stale {
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
/// over the blow-up guard) without one. A row with a gap at assembly is stale past the limit
/// even when its linearised separation reads an overlap: a capsule spun to 800 rad/s by its
/// impact on a height field turned 8 rad in the next step, where such rows held it at lever
/// arms turned away and it gained 3,884 J/kg (tests/integration/fast_impacts.rs). Rows touching or overlapping at
/// assembly keep acting: dropping them too let darts through the wall; they hold a body where
/// it is pressed, and continuous collision sweeps its true motion as the step ends.
pub(crate) const SPECULATIVE_TURN: f32 = std::f32::consts::FRAC_PI_4;

/// The target (m/s) of a stale speculative row: far below any approach speed (the blow-up guard
/// stops a body at `max_linear_speed`, 10⁵ m/s by default), so the row's impulse goes to zero, yet small enough that no
/// solver's products of it overflow.
pub(crate) const STALE_TARGET: f32 = -1.0e15;

/// How far (rad) a body of an island whose rows follow its bodies' turn (docs/method.md, "Rows
/// that follow a turn") must have turned since the step began for its contact points to be
/// moved by the whole turn rather than the linearised Δθ × r ([`turned_arm_remainder`]). The
/// linearised point is off by about |Δθ|²·|r|/2: under 1 mm for lever arms within 0.8 m at
/// this angle, but 0.18·|r| at 0.6 rad, a bowling pin's turn in its landing step at 24 Hz
/// (docs/testing.md, "Tumbling hulls").
pub(crate) const CURVED_TURN: f32 = 0.05;

/// K = R − I − [Δθ]×, what the whole turn adds to a lever arm beyond the linearised Δθ × r:
/// R r = r + Δθ × r + K r, with R the body's turn since the step began (`now` times the
/// inverse of `start`, world frame) and Δθ its rotation vector (rad) as the separations read
/// it (Σ h·ω). Taken for bodies whose contact points are points of the body (polyhedra,
/// meshes); a round shape's contact point slides over its surface as it turns and the
/// linearised term, zero along a ball's normal, stays (see [`CURVED_TURN`]).
pub(crate) fn turned_arm_remainder(start: Quat, now: Quat, rotation: Vec3) -> Mat3 {
    let turn = Mat3::from_quat(now * start.inverse());
    let skew = Mat3::from_cols(
        Vec3::new(0.0, rotation.z, -rotation.y),
        Vec3::new(-rotation.z, 0.0, rotation.x),
        Vec3::new(rotation.y, -rotation.x, 0.0),
    );
    turn - Mat3::IDENTITY - skew
}

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
///
/// A point of a body that turned by more than [`SPECULATIVE_TURN`] over the step (`rotation`:
/// per local body slot, the rotation vector Σ h·ω of the substeps, rad) does not bounce
/// ([`speculative_row_is_stale`]): its lever arm, taken as the step began, no longer reaches
/// the body's point that struck, and its row reads the spin ω × r at a point turned away from
/// the contact as the velocity to reflect. Bounced there, spinning boxes striking corner-first
/// gained up to 10⁵ J/kg in a step (tests/integration/fast_impacts.rs). The substeps' rows
/// already stopped the approach; the point only loses its rebound.
pub(crate) fn restitution_targets(
    constraints: &mut [ContactConstraint],
    threshold: f32,
    rotation: &[Vec3],
) -> bool {
    let mut any = false;
    for c in constraints.iter_mut() {
        let approach = c.normal.velocity_before;
        if c.restitution > 0.0
            && approach < -threshold
            && c.max_normal_impulse > 0.0
            && !turned_away(c, rotation)
        {
            c.target_normal_velocity = -c.restitution * approach;
            any = true;
        }
    }
    any
}

/// Whether either body of `c` turned past [`SPECULATIVE_TURN`] over the step (`rotation`, per
/// local body slot, rad) where the row depends on its rotation ([`speculative_row_is_stale`]).
#[inline]
fn turned_away(c: &ContactConstraint, rotation: &[Vec3]) -> bool {
    let turn = |slot: u32| {
        rotation
            .get(slot as usize)
            .map_or(0.0, |r| r.length_squared())
    };
    speculative_row_is_stale(turn(c.local_a), c.normal.angular_a, c.lever_a)
        || speculative_row_is_stale(turn(c.local_b), c.normal.angular_b, c.lever_b)
}
