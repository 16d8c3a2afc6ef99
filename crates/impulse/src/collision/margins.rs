//! Speculative margins: how far ahead the broad and narrow phases look in one step, per body
//! and per pair, and the reach a pair's bodies can close in the step ([`SweptReach`]), past
//! which a speculative point is dropped.

use glam::Vec3;
use parry3d::math::Pose;
use parry3d::query::{QueryDispatcher, ShapeCastOptions};

use super::dispatch::ContactDispatcher;
use super::manifold::Manifold;
use crate::body::Bodies;
use crate::parallel::{BODIES_PER_TASK, spread};

/// Cap on a body's speculative margin (m), so a body thrown at absurd speed does not pair
/// with the whole scene.
pub(crate) const MAX_SPECULATIVE_MARGIN: f32 = 2.0;

/// How far ahead the broad and narrow phases look in one step (speculative contacts), from
/// the poses and velocities at the step's start.
///
/// - Per body ([`SpeculativeMargins::margins`], for the broad phase, which grows each body's
///   box by it): half the base prediction distance plus the distance the body can travel in
///   one step, dt·(|v| + |ω|·R + |g|·dt) with R its bounding radius. Pairs are then found
///   before fast bodies meet rather than after they have tunnelled into each other; a fixed
///   margin lets a ball falling at 19 m/s overlap its neighbours by a tenth of a metre.
/// - Per pair ([`SpeculativeMargins::pair_prediction`], for the narrow phase): contact points
///   are generated up to the base prediction distance plus how far the two bodies can close
///   in one step, dt·(|v_a − v_b| + |ω_a|·R_a + |ω_b|·R_b), plus |g|·dt² when only one of them
///   is dynamic (gravity moves both alike otherwise); never more than the two bodies' margins.
///   A kinematic body counts with its prescribed velocities and no gravity.
///   Balls falling side by side close at 0 m/s, so they get no speculative contact and do not
///   join one island; with the sum of the per-body margins every column of `balls16k` joined
///   one island of 16,000 balls while falling.
#[derive(Default)]
pub struct SpeculativeMargins {
    margins: Vec<f32>,
    /// Per body, |ω|·R (m/s), the fastest any of its points moves by rotation, and the
    /// fastest any of them can move by rotation after contacts within the step: R times the
    /// spin its kinetic energy could give it ([`spin_bound`]).
    spin_speeds: Vec<(f32, f32)>,
    prediction_distance: f32,
    dt: f32,
    /// |g|·dt (m/s).
    gravity_speed: f32,
    /// Gravity (m/s²).
    gravity: Vec3,
    /// Substeps per step (0: not set, taken as 1).
    substeps: u32,
    /// The collision steps the step is taken in (0: not set, taken as 1).
    collision_steps: u32,
    /// The whole step's dt (s) that the base prediction distance scales with
    /// ([`base_prediction`]); 0 until set, then the dt [`Self::update`] is given.
    step_dt: f32,
}

/// The step (s) at and above which the base prediction distance holds whole:
/// [`crate::settings::ContactSettings::prediction_distance`] is for steps of 1/60 s.
const PREDICTION_REFERENCE_STEP: f32 = 1.0 / 60.0;

/// The base prediction distance (m) of a step of `step_dt` seconds: `prediction_distance`
/// at steps of [`PREDICTION_REFERENCE_STEP`] or longer, in proportion below. The base is for
/// points that only velocity changes within the step can bring into contact (a settling pile
/// pushed by its neighbours), whose reach is a velocity times the step: at 240 Hz a fixed
/// 2 cm was four times the reach it is at 60 Hz, and between the mug's thin parts most of the
/// pairs the narrow phase built a manifold for were 1 to 2 cm apart.
pub(crate) fn base_prediction(prediction_distance: f32, step_dt: f32) -> f32 {
    prediction_distance * (step_dt / PREDICTION_REFERENCE_STEP).min(1.0)
}

impl SpeculativeMargins {
    /// Recomputes the margins for a step of `dt` seconds (`prediction_distance` in m, the
    /// settings' base, taken in proportion below 1/60 s of the step [`Self::set_step_dt`] set,
    /// else of `dt`: [`base_prediction`]; `gravity` in m/s²). With `parallel`, in runs of
    /// [`BODIES_PER_TASK`] bodies on rayon's threads: each body's margin depends on that body
    /// alone, so the margins are the same on any thread count.
    pub fn update(
        &mut self,
        bodies: &Bodies,
        prediction_distance: f32,
        gravity: Vec3,
        dt: f32,
        parallel: bool,
    ) {
        let step_dt = if self.step_dt > 0.0 { self.step_dt } else { dt };
        let prediction_distance = base_prediction(prediction_distance, step_dt);
        self.prediction_distance = prediction_distance;
        self.dt = dt;
        self.gravity_speed = gravity.length() * dt;
        self.gravity = gravity;
        let gravity_speed = self.gravity_speed;
        // (margin, (spin speed, spin bound)) of body i.
        let of = |i: usize| {
            if bodies.is_moving(i) {
                let radius = bodies.shape[i].compute_local_aabb().half_extents().length();
                let spin_speed = bodies.angular_velocity[i].length() * radius;
                let gravity_speed = if bodies.is_dynamic(i) {
                    gravity_speed
                } else {
                    0.0
                };
                let speed = bodies.linear_velocity[i].length() + spin_speed + gravity_speed;
                let bound = if bodies.is_dynamic(i) {
                    spin_bound(bodies, i) * radius
                } else {
                    spin_speed
                };
                (
                    (0.5 * prediction_distance + speed * dt).min(MAX_SPECULATIVE_MARGIN),
                    (spin_speed, bound.max(spin_speed)),
                )
            } else {
                (0.5 * prediction_distance, (0.0, 0.0))
            }
        };
        self.margins.clear();
        self.spin_speeds.clear();
        if spread(parallel, bodies.len(), BODIES_PER_TASK) {
            use rayon::prelude::*;
            (0..bodies.len())
                .into_par_iter()
                .with_min_len(BODIES_PER_TASK)
                .map(of)
                .unzip_into_vecs(&mut self.margins, &mut self.spin_speeds);
        } else {
            for i in 0..bodies.len() {
                let (margin, spin) = of(i);
                self.margins.push(margin);
                self.spin_speeds.push(spin);
            }
        }
    }

    /// Sets the substeps per step, which the reach of a pair's speculative points depends on
    /// ([`SweptReach::horizon`]); 1 until set.
    pub fn set_substeps(&mut self, substeps: u32) {
        self.substeps = substeps;
    }

    /// Sets the whole step's dt (s), which the base prediction distance scales with
    /// ([`base_prediction`]): a collision step or a split step's piece keeps its step's base.
    pub fn set_step_dt(&mut self, step_dt: f32) {
        self.step_dt = step_dt;
    }

    /// Sets how many collision steps the step is taken in, this one among them
    /// ([`crate::settings::ContactSettings::collision_steps`]): a pair is aimed where its
    /// motion over the whole step is large against its size ([`SweptReach::collision_steps`]);
    /// 1 until set.
    pub fn set_collision_steps(&mut self, collision_steps: u32) {
        self.collision_steps = collision_steps;
    }

    /// Per-body margins (m), indexed like the bodies.
    pub fn margins(&self) -> &[f32] {
        &self.margins
    }

    /// The separation (m) up to which pair (`a`, `b`) gets contact points this step.
    #[inline]
    pub fn pair_prediction(&self, bodies: &Bodies, a: usize, b: usize) -> f32 {
        let velocity = |i: usize| moving_velocity(bodies, i);
        let gravity = self.relative_gravity_speed(bodies, a, b);
        let closing = (velocity(a) - velocity(b)).length()
            + self.spin_speeds[a].0
            + self.spin_speeds[b].0
            + gravity;
        (self.prediction_distance + closing * self.dt).min(self.margins[a] + self.margins[b])
    }

    /// Pair (`a`, `b`)'s straight relative motion over the step and how far rotation can
    /// add to it ([`SweptReach`]).
    #[inline]
    pub(crate) fn pair_reach(&self, bodies: &Bodies, a: usize, b: usize) -> SweptReach {
        let velocity = |i: usize| self.step_velocity(bodies, i);
        SweptReach {
            displacement: (velocity(b) - velocity(a)) * self.dt,
            turn_reach: (self.spin_speeds[a].0 + self.spin_speeds[b].0) * self.dt,
            turn_bound: (self.spin_speeds[a].1 + self.spin_speeds[b].1) * self.dt,
            horizon: 1.0 + 1.0 / self.substeps.max(1) as f32,
            collision_steps: self.collision_steps.max(1) as f32,
        }
    }

    /// How far (m, ≥ 0) the point of pair (`a`, `b`) at `position` (body `a`'s frame) closes
    /// along `normal` (body `a`'s frame, out of body `a`) over the step, from the bodies'
    /// velocities at its start, their spins about their centres of mass included, and gravity
    /// as [`Self::pair_reach`] takes it: dt·max(0, −(v_b(x) − v_a(x))·n), v_i(x) = v_i + ω_i ×
    /// (x − c_i). First order in the step: a turning body's point moves along its velocity.
    pub(crate) fn point_closing(
        &self,
        bodies: &Bodies,
        a: usize,
        b: usize,
    ) -> impl Fn(Vec3, Vec3) -> f32 {
        let pose = bodies.pose[a];
        let motion = |i: usize| {
            let spin = if bodies.is_moving(i) {
                bodies.angular_velocity[i]
            } else {
                Vec3::ZERO
            };
            (
                self.step_velocity(bodies, i),
                spin,
                bodies.center_of_mass(i),
            )
        };
        let ((va, wa, ca), (vb, wb, cb)) = (motion(a), motion(b));
        let dt = self.dt;
        move |position: Vec3, normal: Vec3| {
            let x = pose.transform_point(position);
            let relative = (vb + wb.cross(x - cb)) - (va + wa.cross(x - ca));
            (-relative.dot(pose.rotation * normal)).max(0.0) * dt
        }
    }

    /// Body `i`'s velocity (m/s) over the step before contacts: with the step's gravity added
    /// (semi-implicit Euler) for a dynamic body, the prescribed one for a kinematic body, zero
    /// for a static one.
    #[inline]
    fn step_velocity(&self, bodies: &Bodies, i: usize) -> Vec3 {
        let gravity = if bodies.is_dynamic(i) {
            self.gravity * self.dt
        } else {
            Vec3::ZERO
        };
        moving_velocity(bodies, i) + gravity
    }

    /// The speed (m/s) gravity can add to pair (`a`, `b`)'s closing: it moves dynamic bodies
    /// alike, and kinematic and static ones not at all.
    #[inline]
    fn relative_gravity_speed(&self, bodies: &Bodies, a: usize, b: usize) -> f32 {
        if bodies.is_dynamic(a) != bodies.is_dynamic(b) {
            self.gravity_speed
        } else {
            0.0
        }
    }
}

/// The fastest spin (rad/s) dynamic body `i` can have after the step's contacts if they add
/// no kinetic energy: with E = ½·m·|v|² + ½·ωᵀIω its kinetic energy, a spin ω' has
/// ½·ω'ᵀIω' ≤ E, so |ω'|² ≤ 2E / I_min, I_min bounded below by the inverse of the largest
/// absolute row sum of the inverse inertia (which bounds its largest eigenvalue). Left out:
/// the step's gravity (what a resting body's contacts take away each step; counted, it would
/// give every resting body a turn) and energy other bodies bring through their contacts. A
/// body with a locked rotation axis (a singular inertia) gets its current spin.
fn spin_bound(bodies: &Bodies, i: usize) -> f32 {
    let inverse_inertia = bodies.local_inverse_inertia[i];
    let omega = bodies.pose[i].rotation.inverse() * bodies.angular_velocity[i];
    let spin = omega.length();
    if inverse_inertia.determinant().abs() <= f32::MIN_POSITIVE || bodies.inverse_mass[i] <= 0.0 {
        return spin;
    }
    let rotational = omega.dot(inverse_inertia.inverse() * omega);
    let linear = bodies.linear_velocity[i].length_squared() / bodies.inverse_mass[i];
    let rows = inverse_inertia.transpose();
    let largest = [rows.x_axis, rows.y_axis, rows.z_axis]
        .iter()
        .map(|row| row.abs().element_sum())
        .fold(0.0, f32::max);
    let bound = ((linear + rotational.max(0.0)) * largest).sqrt();
    if bound.is_finite() {
        bound.max(spin)
    } else {
        spin
    }
}

/// `manifold`'s normal in shape 1's frame: a compound part's normal turned into its body's.
#[inline]
fn body_normal(manifold: &Manifold) -> Vec3 {
    match manifold.subshape_pos1() {
        Some(part) => part.rotation * manifold.local_n1,
        None => manifold.local_n1,
    }
}

/// Body `i`'s linear velocity (m/s) if it moves, else zero.
#[inline]
fn moving_velocity(bodies: &Bodies, i: usize) -> Vec3 {
    if bodies.is_moving(i) {
        bodies.linear_velocity[i]
    } else {
        Vec3::ZERO
    }
}

/// What a pair's speculative points must meet to stand: the pair's shapes, moved apart by
/// the step's straight relative motion (body 2 by `displacement` against body 1), touch
/// (come within `turn_reach` plus [`TOUCH_TOLERANCE`]) at some time of the step.
///
/// A speculative point holds its pair's closing speed along the manifold's normal n to the
/// gap s over the step, v·n ≥ −s/dt: it acts as a plane through the witness point, unbounded
/// across the normal. For convex shapes that plane separates them, so along a straight
/// motion d it binds (s + d·n < 0) no later than the shapes touch. A path that passes beside
/// the point's feature crosses the plane outside the feature and never touches; a point kept
/// there stops the body on nothing (a 7.3 cm ball at 188 m/s passing 1.9 cm from a wall's
/// edge was stopped 0.41 m from the wall and sent back). Each point whose plane the step's
/// motion reaches is therefore checked against the motion itself, whatever its separation:
/// where the pair's shape cast along d misses, every such point is dropped. Points the
/// motion does not reach (every resting contact, a body sliding along a face) stay, with
/// the base prediction distance, for velocity changes within the step (a body pushed by
/// its neighbours); so do all points of a pair already touching, which the cast would find
/// at time 0.
///
/// `turn_reach` is how far rotation can carry any point of either body in the step
/// (|ω_a|·R_a·dt + |ω_b|·R_b·dt), which the straight cast does not follow: it widens both the
/// points checked and the cast's target distance, so a spinning body's real contact is kept.
/// Gravity is in `displacement` (|g|·dt² for a dynamic body against a static or kinematic
/// one), as the step integrates it before the contacts.
///
/// Box2D v3 avoids the same phantoms by keeping its speculative distance small (4 linear
/// slops, `B2_SPECULATIVE_DISTANCE` in `constants.h`, the cut-off of every manifold function
/// in `manifold.c`) and leaving fast bodies to its continuous collision; here the margin
/// grows with the speed, so that fast bodies meet each other too, and the cast bounds it.
#[derive(Clone, Copy, Debug)]
pub(crate) struct SweptReach {
    /// Displacement of body 2 relative to body 1 over the step (m, world frame).
    pub displacement: Vec3,
    /// How far (m) rotation can carry any point of either body in the step.
    pub turn_reach: f32,
    /// How far (m) rotation can carry any point of either body in the step once contacts
    /// have turned the bodies' kinetic energy into spin ([`spin_bound`]): a pin landing on one
    /// end swings its other end down faster than it turned before.
    pub turn_bound: f32,
    /// How many steps ahead a speculative point is checked, 1 + 1/substeps: the relax solve
    /// that ends the step's last substep holds the velocity to the gap left after it, so a
    /// plane the motion would cross in the next step's first substep already acts on the
    /// velocity the step ends with (a 2 cm ball passing 6 mm from a wall's corner, whose
    /// plane it would have crossed 3 cm after the step, was turned, then bounced back).
    pub horizon: f32,
    /// How many collision steps the step is taken in, this one among them (≥ 1): a pair whose
    /// motion over the whole step, this many times its displacement, is large against its
    /// size is aimed in each collision step, as it would be in an unsplit step.
    pub collision_steps: f32,
}

/// A pair's two shapes where the narrow phase finds their contacts: body 2 at `pos12` in body
/// 1's frame, body 1 at world rotation `rotation1`.
#[derive(Clone, Copy)]
pub(crate) struct PairShapes<'a> {
    pub pos12: &'a Pose,
    pub rotation1: glam::Quat,
    pub shape1: &'a dyn parry3d::shape::Shape,
    pub shape2: &'a dyn parry3d::shape::Shape,
}

/// The distance (m) within which the step's cast counts shapes as touching: half the
/// smallest miss the sweeps check (0.2 mm), and far above the distance query's rounding
/// (f32 over a 5 m step).
pub(crate) const TOUCH_TOLERANCE: f32 = 1.0e-4;

impl SweptReach {
    /// Drops every point of `manifolds` (of `pair`) whose plane the step's straight motion
    /// reaches when the shapes, moved by that motion, do not touch; whether any point was
    /// dropped. Shape pairs Parry cannot cast keep their points.
    pub(crate) fn drop_unreachable(
        &self,
        pair: PairShapes<'_>,
        manifolds: &mut [Manifold],
    ) -> bool {
        let PairShapes {
            pos12,
            rotation1,
            shape1,
            shape2,
        } = pair;
        let turn_reach = self.horizon * self.turn_reach;
        let target = turn_reach + TOUCH_TOLERANCE;
        let local_displacement = rotation1.inverse() * self.displacement;
        // Whether the motion reaches, within the horizon, the plane of a point at separation
        // `dist` of a manifold whose normal (in shape 1's frame) is `normal`.
        let reached = |dist: f32, normal: Vec3| {
            dist + self.horizon * local_displacement.dot(normal) < turn_reach
        };
        if manifolds
            .iter()
            .flat_map(|m| &m.points)
            .any(|p| p.dist <= target)
            || !manifolds.iter().any(|m| {
                let normal = body_normal(m);
                m.points.iter().any(|p| reached(p.dist, normal))
            })
        {
            return false;
        }
        let options = ShapeCastOptions {
            max_time_of_impact: self.horizon,
            target_distance: turn_reach,
            stop_at_penetration: true,
            compute_impact_geometry_on_penetration: false,
        };
        let cast = ContactDispatcher::default().cast_shapes(
            pos12,
            local_displacement,
            shape1,
            shape2,
            options,
        );
        match cast {
            Ok(None) => {}
            // Parry's cast can report an impact for shapes that pass within a few tenths of a
            // millimetre (a ball 0.24 mm past a box's edge, cast 1.9 m with a target distance
            // of 0.01 mm), and GJK's distance at a true impact can read the shapes apart (a
            // point cloud falling face-down on a box, 0.2-1.7 mm; its points were dropped and
            // it fell 17 mm in): an impact stands where the motion brings the shapes within
            // the tolerance, followed from the cast's time to the horizon
            // ([`touches_along`]).
            // Against a triangle mesh or a height field the distance query and the cast see
            // different triangles (a hull dropped on a 2-triangle floor measured 0.3-1.8 mm
            // apart at the cast's impact, and fell 11 cm through with its points dropped), so
            // there the cast's impact stands as it is.
            Ok(Some(_)) if is_composite(shape1) || is_composite(shape2) => return false,
            Ok(Some(hit)) => {
                if touches_along(
                    pos12,
                    local_displacement,
                    shape1,
                    shape2,
                    hit.time_of_impact,
                    self.horizon,
                    target,
                ) {
                    return false;
                }
            }
            Err(_) => return false,
        }
        for manifold in manifolds.iter_mut() {
            let normal = body_normal(manifold);
            manifold.points.retain(|p| !reached(p.dist, normal));
        }
        true
    }
}

impl SweptReach {
    /// Aims a fast pair's speculative contacts at where it will touch (a ball's point here; a
    /// pair of other convex shapes that does not turn, [`Self::aim_polyhedral_manifold`],
    /// below): for a ball and a convex
    /// shape or a compound's convex part (each of a compound's manifolds on its own part; not
    /// a mesh or height field) apart at the step's start, whose step
    /// moves them more than [`AIMED_DISPLACEMENT`] times the ball's radius (the smaller of two
    /// balls') against each other, the pair's single point gets the contact at the time the
    /// step's straight motion first brings them into touch: that of Parry's cast (`cast_shapes`,
    /// target distance 0, up to the horizon), moved by Newton's steps on the exact gap
    /// ([`ball_contact_at`]). Its normal runs from the other shape's nearest point to the
    /// ball's centre, its separation is the start poses' gap between the witnesses along that
    /// normal, and its solver data (last step's impulses, for warm starting) stays. Whether a
    /// contact was moved.
    ///
    /// Why: a speculative point's normal is that of the shapes' closest points at the step's
    /// start, and the impulse goes along it. For a ball closing by more than its size in a
    /// step that is not the normal where the two touch: a ball at 7.5 m/s, 12.5 cm a step at
    /// 1/60 s, striking a resting ball of the same size 10 cm off centre sent it 24° from its
    /// path where the line of centres at impact is 30° (`fast_pairs` in the integration
    /// tests). A ball's contact normal passes through its centre, so the normal at the time of
    /// impact is the impact's, whatever the step. The cast's own normal and time come from
    /// GJK's last simplex: its normal was 7° off at a cube's corner, its time 2.4° off in the
    /// normal at another, hence the projection and the Newton steps. Where the normal found is
    /// within [`MIN_AIMED_TURN`] of the closest points' (a ball falling onto a face, a head-on
    /// hit) the point is kept as it was. A pair of other convex shapes that does not turn gets
    /// its whole manifold taken where the cast brings it into touch
    /// ([`Self::aim_polyhedral_manifold`]). Not aimed: such pairs that turn, whose turn within
    /// the step the straight cast does not follow (aiming a tumbling pin's manifold at one
    /// point sank pins past the 5 mm the tumbling-pin tests allow), and pairs already touching,
    /// which have no time of impact.
    pub(crate) fn aim_at_impact(&self, pair: PairShapes<'_>, manifolds: &mut [Manifold]) -> bool {
        if let [manifold] = manifolds
            && self.aims_polyhedra(pair, manifold)
        {
            return self.aim_polyhedral_manifold(pair, manifold);
        }
        // Most pairs (boxes in a pile, anything touching) have no lone speculative point: they
        // leave before the shapes are asked anything.
        if !manifolds.iter().any(lone_speculative_point) {
            return false;
        }
        let (compound1, compound2) = (pair.shape1.as_compound(), pair.shape2.as_compound());
        if compound1.is_none() && compound2.is_none() {
            let [manifold] = manifolds else {
                return false;
            };
            return self.aim_manifold(pair, manifold);
        }
        // A compound's manifolds are its parts': each part's point is aimed at that part.
        let mut aimed = false;
        for manifold in manifolds.iter_mut().filter(|m| lone_speculative_point(m)) {
            let (part1, part2) = (
                compound1.and_then(|c| c.shapes().get(manifold.subshape1 as usize)),
                compound2.and_then(|c| c.shapes().get(manifold.subshape2 as usize)),
            );
            let (pose1, shape1) = part1.map_or((Pose::IDENTITY, pair.shape1), |(pose, shape)| {
                (*pose, shape.as_ref())
            });
            let (pose2, shape2) = part2.map_or((Pose::IDENTITY, pair.shape2), |(pose, shape)| {
                (*pose, shape.as_ref())
            });
            let pos12 = pose1.inverse() * *pair.pos12 * pose2;
            let shapes = PairShapes {
                pos12: &pos12,
                rotation1: pair.rotation1 * pose1.rotation,
                shape1,
                shape2,
            };
            aimed |= self.aim_manifold(shapes, manifold);
        }
        aimed
    }

    /// [`Self::aim_at_impact`] for one manifold of two convex shapes `pair`.
    fn aim_manifold(&self, pair: PairShapes<'_>, manifold: &mut Manifold) -> bool {
        let (ball1, ball2) = (pair.shape1.as_ball(), pair.shape2.as_ball());
        let radius = match (ball1, ball2) {
            (Some(ball1), Some(ball2)) => ball1.radius.min(ball2.radius),
            (Some(ball), _) if pair.shape2.is_convex() && !is_composite(pair.shape2) => ball.radius,
            (_, Some(ball)) if pair.shape1.is_convex() && !is_composite(pair.shape1) => ball.radius,
            _ => return false,
        };
        if !lone_speculative_point(manifold)
            || self.displacement.length() * self.collision_steps <= AIMED_DISPLACEMENT * radius
        {
            return false;
        }
        let Some((time_of_impact, local_displacement)) = self.straight_impact(pair) else {
            return false;
        };
        // The normal of a ball's contact runs from the other shape's nearest point to the
        // ball's centre, which the projection of the centre gives exactly; the cast's own
        // normal and time, from GJK's last simplex, are not as close (its normal was 7° off at
        // a cube's corner, and its time, taken as it stands, 2.4° off at another). So the
        // contact is taken anew at the cast's time, and the time moved by Newton's steps on
        // the gap, which a straight motion changes at the rate displacement·n.
        let at = |t: f32| {
            Pose::from_parts(
                pair.pos12.translation + local_displacement * t,
                pair.pos12.rotation,
            )
        };
        let mut t = time_of_impact;
        let mut contact = None;
        for _ in 0..IMPACT_NEWTON_STEPS {
            let pose = at(t);
            let Some((normal1, witness1, witness2)) =
                ball_contact_at(&pose, pair.shape1, pair.shape2)
            else {
                break;
            };
            contact = Some((normal1, witness1, witness2));
            let gap = (pose.transform_point(witness2) - witness1).dot(normal1);
            let rate = local_displacement.dot(normal1);
            if gap.abs() <= IMPACT_GAP_TOLERANCE || rate >= 0.0 {
                break;
            }
            t = (t - gap / rate).clamp(0.0, self.horizon);
        }
        let Some((normal1, witness1, witness2)) = contact else {
            return false;
        };
        if normal1.dot(manifold.local_n1) > MIN_AIMED_TURN.cos() {
            return false;
        }
        manifold.local_n1 = normal1;
        manifold.local_n2 = pair.pos12.rotation.inverse() * -normal1;
        let point = &mut manifold.points[0];
        point.local_p1 = witness1;
        point.local_p2 = witness2;
        point.dist = (pair.pos12.transform_point(witness2) - witness1).dot(normal1);
        true
    }
}

impl SweptReach {
    /// Whether [`Self::aim_polyhedral_manifold`] is asked for `manifold` of `pair`: two convex
    /// shapes, neither a ball (whose point [`Self::aim_manifold`] aims) nor made of parts, apart
    /// at the step's start (every point speculative), that the step's straight motion moves
    /// more than [`AIMED_DISPLACEMENT`] times the smaller bounding radius against each other,
    /// and that turn too little for the straight cast to stand for their motion: rotation
    /// carries their points less than [`AIMED_MAX_TURN`] times that displacement.
    fn aims_polyhedra(&self, pair: PairShapes<'_>, manifold: &Manifold) -> bool {
        let convex = |shape: &dyn parry3d::shape::Shape| {
            shape.is_convex() && !is_composite(shape) && shape.as_ball().is_none()
        };
        if manifold.points.is_empty()
            || manifold.points.iter().any(|p| p.dist <= 0.0)
            || !convex(pair.shape1)
            || !convex(pair.shape2)
        {
            return false;
        }
        let displacement = self.displacement.length();
        if displacement <= 0.0 || self.horizon * self.turn_reach > AIMED_MAX_TURN * displacement {
            return false;
        }
        let radius = pair
            .shape1
            .compute_local_bounding_sphere()
            .radius
            .min(pair.shape2.compute_local_bounding_sphere().radius);
        displacement * self.collision_steps > AIMED_DISPLACEMENT * radius
    }

    /// When (in steps, in (0, horizon]) the step's straight motion first brings `pair` into
    /// touch (Parry's cast, target distance 0), with that motion in shape 1's frame; `None`
    /// for a miss, a pair already touching, or shapes Parry cannot cast.
    fn straight_impact(&self, pair: PairShapes<'_>) -> Option<(f32, Vec3)> {
        let options = ShapeCastOptions {
            max_time_of_impact: self.horizon,
            target_distance: 0.0,
            stop_at_penetration: true,
            compute_impact_geometry_on_penetration: false,
        };
        let local_displacement = pair.rotation1.inverse() * self.displacement;
        let hit = ContactDispatcher::default()
            .cast_shapes(
                pair.pos12,
                local_displacement,
                pair.shape1,
                pair.shape2,
                options,
            )
            .ok()??;
        let t = hit.time_of_impact;
        (t > 0.0 && t <= self.horizon).then_some((t, local_displacement))
    }

    /// [`Self::aim_at_impact`] for a pair of polyhedra (or other convex shapes but balls) that
    /// [`Self::aims_polyhedra`] picks: the manifold becomes the one the shapes have where the
    /// step's straight motion first brings them into touch (Parry's cast, target distance 0,
    /// up to the horizon; the manifold there from [`ContactDispatcher`], within the motion
    /// left after it), its points' separations those of their witnesses at the start poses
    /// along its normal. A point keeps the solver data of the held point of the same features.
    /// Where the normal there is within [`MIN_AIMED_TURN`] of the held one (a box falling onto
    /// a face, a head-on hit) the manifold is kept as it was. Whether it was replaced.
    ///
    /// Why: the held manifold is that of the shapes' closest features at the step's start. A
    /// bowling pin flying at 5 m/s along its axis, 8.3 cm a step at 1/60 s, struck a standing
    /// pin 9 cm off its axis along the closest points' normal, 43° from the one where they
    /// touch, and sent it 23° off its path against 51° at 1/480 s and finer. The cast is
    /// straight, so pairs that turn are left alone (see [`Self::aims_polyhedra`]).
    fn aim_polyhedral_manifold(&self, pair: PairShapes<'_>, manifold: &mut Manifold) -> bool {
        let Some((t, local_displacement)) = self.straight_impact(pair) else {
            return false;
        };
        let dispatcher = ContactDispatcher::default();
        // Just before the touch, where the nearest points (and so the normal) are well
        // defined: at the touch itself a corner on an edge has a whole cone of normals.
        let length = local_displacement.length();
        let t = (t - AIMED_BACK_OFF / length).max(0.0);
        let pose = Pose::from_parts(
            pair.pos12.translation + local_displacement * t,
            pair.pos12.rotation,
        );
        let left = (self.horizon - t) * length + TOUCH_TOLERANCE;
        let mut found: Vec<Manifold> = Vec::new();
        if parry3d::query::PersistentQueryDispatcher::contact_manifolds(
            &dispatcher,
            &pose,
            pair.shape1,
            pair.shape2,
            left,
            &mut found,
            &mut None,
        )
        .is_err()
        {
            return false;
        }
        let Some(aimed) = found.into_iter().find(|m| !m.points.is_empty()) else {
            return false;
        };
        if aimed.local_n1.dot(manifold.local_n1) > MIN_AIMED_TURN.cos()
            || local_displacement.dot(aimed.local_n1) >= 0.0
        {
            return false;
        }
        let held = std::mem::take(&mut manifold.points);
        manifold.local_n1 = aimed.local_n1;
        manifold.local_n2 = aimed.local_n2;
        manifold.data.face_axes = None;
        manifold.points = aimed.points;
        for point in &mut manifold.points {
            point.dist =
                (pair.pos12.transform_point(point.local_p2) - point.local_p1).dot(aimed.local_n1);
            point.data = held
                .iter()
                .find(|h| (h.fid1, h.fid2) == (point.fid1, point.fid2))
                .map_or_else(Default::default, |h| h.data);
        }
        true
    }
}

/// Whether `manifold` holds one point, apart: the speculative point of a ball's pair
/// [`SweptReach::aim_at_impact`] may aim.
fn lone_speculative_point(manifold: &Manifold) -> bool {
    manifold.points.len() == 1 && manifold.points[0].dist > 0.0
}

/// The contact of a ball and a convex shape touching at `pos12` (shape 2 in shape 1's frame):
/// the normal from shape 1 toward shape 2 and the witness points (each in its shape's frame),
/// from the projection of the ball's centre on the other shape (of shape 2's on shape 1 when
/// both are balls). `None` where neither is a ball or the centre is inside the other shape.
fn ball_contact_at(
    pos12: &Pose,
    shape1: &dyn parry3d::shape::Shape,
    shape2: &dyn parry3d::shape::Shape,
) -> Option<(Vec3, Vec3, Vec3)> {
    if let Some(ball2) = shape2.as_ball() {
        let centre = pos12.translation;
        let projection = shape1.project_local_point(centre, true);
        let normal1 = (centre - projection.point).try_normalize()?;
        let witness2 = pos12.rotation.inverse() * (-normal1 * ball2.radius);
        return (!projection.is_inside).then_some((normal1, projection.point, witness2));
    }
    let ball1 = shape1.as_ball()?;
    let centre = pos12.inverse_transform_point(Vec3::ZERO);
    let projection = shape2.project_local_point(centre, true);
    let normal2 = (centre - projection.point).try_normalize()?;
    let normal1 = pos12.rotation * -normal2;
    (!projection.is_inside).then_some((normal1, normal1 * ball1.radius, projection.point))
}

/// Most Newton steps [`SweptReach::aim_at_impact`] takes on the gap from the cast's time of
/// impact.
const IMPACT_NEWTON_STEPS: usize = 4;

/// The gap (m) at which [`SweptReach::aim_at_impact`] takes a time as the impact's.
const IMPACT_GAP_TOLERANCE: f32 = 1.0e-6;

/// How far (in the ball's radii; the smaller of two balls') a ball's step must move it against
/// the other shape before [`SweptReach::aim_at_impact`] aims its point. Below a quarter radius the closest points'
/// normal is off by a degree or two at most (1.4° in the 15 cm strike of `fast_pairs` at
/// 1/960 s, 7.8 mm a step), which a cast for nearly every moving ball of a pile is not spent
/// on.
const AIMED_DISPLACEMENT: f32 = 0.25;

/// How far, as a fraction of the step's straight displacement of a pair against each other,
/// rotation may carry their points over the horizon at their spins as the step starts
/// ([`SweptReach::turn_reach`]) for [`SweptReach::aim_polyhedral_manifold`] to aim them by a
/// straight cast.
const AIMED_MAX_TURN: f32 = 0.1;

/// How far (m) before the touch along the step's motion [`SweptReach::aim_polyhedral_manifold`]
/// takes the pair's manifold.
const AIMED_BACK_OFF: f32 = 1.0e-3;

/// The least turn (rad, 1°) of a ball's speculative normal that
/// [`SweptReach::aim_at_impact`] makes.
const MIN_AIMED_TURN: f32 = 0.0175;

/// Most Newton steps [`touches_along`] takes before it takes the shapes to pass apart.
const MAX_ADVANCES: usize = 8;

/// Whether convex `shape2`, at `pos12` in `shape1`'s frame moved by `displacement` (m, shape
/// 1's frame) times t, comes within `target` (m) of `shape1` for some t in [`start`, `end`].
///
/// Where the shapes are within `target` at `end`, they are. Otherwise: under a straight motion
/// the distance between two convex shapes is a convex function of t (a point moving on a line,
/// the distance to their Minkowski difference), so Newton's steps on it from `start` never
/// pass its first zero: each moves t on by the distance over the closing speed along the
/// nearest points' normal. The motion misses where that speed is not positive (the distance
/// is at its least), where t passes `end`, or where [`MAX_ADVANCES`] queries do not reach the
/// target (a graze within a hair of it). The end is checked first because GJK's distance is
/// least reliable just where two flat faces touch (a cloud's face just touching a box's top
/// measured 1.65 mm apart, and 1.6 mm deep 2 mm further on). A pair Parry cannot query
/// counts as touching.
fn touches_along(
    pos12: &Pose,
    displacement: Vec3,
    shape1: &dyn parry3d::shape::Shape,
    shape2: &dyn parry3d::shape::Shape,
    start: f32,
    end: f32,
    target: f32,
) -> bool {
    let at = |t: f32| Pose::from_parts(pos12.translation + displacement * t, pos12.rotation);
    let contact = |t: f32| ContactDispatcher::default().contact(&at(t), shape1, shape2, f32::MAX);
    match contact(end) {
        Ok(Some(contact)) if contact.dist > target => {}
        _ => return true,
    }
    let mut t = start;
    for _ in 0..MAX_ADVANCES {
        let Ok(Some(contact)) = contact(t) else {
            return true;
        };
        if contact.dist <= target {
            return true;
        }
        let closing = -displacement.dot(contact.normal1);
        if closing <= 0.0 {
            return false;
        }
        // Aim inside the target, so that rounding does not leave the last step just short.
        t += (contact.dist - 0.5 * target) / closing;
        if t > end {
            return false;
        }
    }
    false
}

/// Whether `shape` is made of parts (a triangle mesh, a height field, a compound).
fn is_composite(shape: &dyn parry3d::shape::Shape) -> bool {
    shape.as_composite_shape().is_some()
        || matches!(
            shape.shape_type(),
            parry3d::shape::ShapeType::TriMesh | parry3d::shape::ShapeType::HeightField
        )
}

#[cfg(test)]
#[path = "margins_tests.rs"]
mod tests;
