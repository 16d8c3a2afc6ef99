//! The continuous stage ([`crate::Stage::Continuous`]): which bodies are swept against which,
//! and the clamps applied (the sweeps' geometry in `collision/continuous.rs`); then the energy
//! check credited with what the clamps gave back (`energy.rs`).

use crate::World;
use crate::body::BodyKind;
use crate::collision::continuous::{FastBody, Sweep, clamp_fraction};
use crate::contact::SPECULATIVE_TURN;
use crate::settings::SolverSettings;
use parry3d::bounding_volume::BoundingVolume;
use parry3d::math::Pose;

impl World {
    /// The continuous stage: fast bodies swept from `start_poses` (the kinematic stage's) and
    /// clamped (writes `clamps` and `unclamped_poses`), then the energy check credited with what
    /// the clamps gave back ([`super::EnergyCheck::credit_clamps`]).
    pub(super) fn continuous_stage(
        &mut self,
        settings: &SolverSettings,
        start_poses: &[Pose],
        moving_kinematic: &[u32],
        clamps: &mut Vec<(usize, Pose, f32)>,
        unclamped_poses: &mut Vec<Pose>,
    ) {
        self.sweep_and_clamp(
            settings,
            start_poses,
            moving_kinematic,
            clamps,
            unclamped_poses,
        );
        self.energy
            .credit_clamps(clamps, unclamped_poses, &self.bodies, self.gravity);
    }

    /// Sweeps every awake dynamic body that moved more than
    /// [`FAST_FRACTION`](crate::collision::continuous::FAST_FRACTION) of its smallest
    /// half extent this step against the static and kinematic bodies in its swept box (the
    /// broad phase's tree, and the moving kinematic bodies; not the bodies it is joined to unless
    /// the joint lets them collide), and puts it back to the earliest
    /// clamp ([`clamp_fraction`]) with the velocity gravity had given it by then. Each body's clamp reads only its own poses and
    /// the static and kinematic bodies', which no clamp changes, so the order does not matter.
    fn sweep_and_clamp(
        &mut self,
        settings: &SolverSettings,
        start_poses: &[Pose],
        moving_kinematic: &[u32],
        clamps: &mut Vec<(usize, Pose, f32)>,
        unclamped_poses: &mut Vec<Pose>,
    ) {
        // Last step's clamps are no reading for this step's energy credit.
        clamps.clear();
        if settings.continuous {
            // The poses before any clamp, for the energy check's credit (`credit_clamps`).
            unclamped_poses.clone_from(&self.bodies.pose);
        }
        let n = self.bodies.len();
        if !settings.continuous || start_poses.len() != n {
            return;
        }
        // Bodies joined without `collide_connected` pass through each other, as in the broad
        // phase: a door sweeping through its own post is not clamped there.
        let joined = self.joined_pairs();
        let b = &self.bodies;
        for i in 0..n {
            if !b.is_dynamic(i) || b.asleep[i] || b.pose[i] == start_poses[i] {
                continue;
            }
            let (start, end) = (start_poses[i], b.pose[i]);
            let (center_of_mass, spin) =
                (b.local_center_of_mass[i], b.angular_velocity[i] * self.dt);
            let shape = &*b.shape[i];
            let Some(mut body) = FastBody::moving_fast(shape, start, end, center_of_mass, spin)
            else {
                continue;
            };
            let sweep = body.sweep;
            // Whether the solver released this body's speculative rows as stale (a ball's
            // rows, whose lever arms lie along their normals, never are).
            let released = sweep.turn.length() > SPECULATIVE_TURN && shape.as_ball().is_none();
            body.released = released.then_some(SPECULATIVE_TURN);
            let swept = shape.compute_swept_aabb(&sweep.start, &sweep.end);
            let mut earliest = 1.0f32;
            let mut visit = |j: usize| {
                if j == i
                    || !b.groups_interact(i, j)
                    || joined
                        .binary_search(&(i.min(j) as u32, i.max(j) as u32))
                        .is_ok()
                {
                    return;
                }
                let target = Sweep::new(
                    start_poses[j],
                    b.pose[j],
                    b.local_center_of_mass[j],
                    b.angular_velocity[j] * self.dt,
                );
                // Held at its points: the core sphere stands for the body
                // (`clamp_fraction_castable`). Points that all had a gap at assembly did not
                // hold a body that then turned past `SPECULATIVE_TURN`: the solver released
                // them as stale, and only its whole shape's sweep keeps it out (a card
                // tumbling off its first corner's impact passed a plane to its centre).
                let in_contact = self
                    .narrow_phase
                    .min_separation(i as u32, j as u32)
                    .is_some_and(|s| s <= 0.0 || !released);
                if let Some(t) = clamp_fraction(&body, &*b.shape[j], &target, in_contact) {
                    earliest = earliest.min(t);
                }
            };
            // Static bodies and resting kinematic ones from the tree (their boxes there are
            // where they are); moving kinematic bodies from their own swept boxes.
            for j in self.broad_phase.bodies_in(&swept) {
                let j = j as usize;
                if j < n
                    && (b.kind[j] == BodyKind::Static
                        || (b.kind[j] == BodyKind::Kinematic && b.asleep[j]))
                {
                    visit(j);
                }
            }
            for &j in moving_kinematic {
                let j = j as usize;
                if b.shape[j]
                    .compute_swept_aabb(&start_poses[j], &b.pose[j])
                    .intersects(&swept)
                {
                    visit(j);
                }
            }
            if earliest < 1.0 {
                clamps.push((i, sweep.pose_at(earliest), earliest));
            }
        }
        // A clamped body stands where it was at fraction t of the step, so it takes the
        // velocity gravity had given it by then: with the whole step's, the potential energy
        // of the (1 − t)·dt it did not travel would come back as kinetic energy
        // (|v·g|·(1 − t)·dt per kg, 80 J/kg for a ball falling at 500 m/s at 60 Hz).
        // It is turned back too, and its spin with it: the angular velocity keeps its
        // components in the body's frame, and so its kinetic energy ½·ωᵀ·R·I·Rᵀ·ω. Kept in
        // the world's frame instead, a spinning box's energy would change with the turn (a box
        // at 4,890 rad/s, turned back by a few radians, gained 6,761 J/kg). A body with a
        // locked rotation axis turns about its free axes only and keeps its ω as it is.
        let gravity = self.gravity * self.dt;
        for &(i, pose, t) in clamps.iter() {
            let end = self.bodies.pose[i].rotation;
            self.bodies.pose[i] = pose;
            let unspent = self.bodies.locked_axes[i].lock_linear_velocity(gravity * (1.0 - t));
            self.bodies.linear_velocity[i] -= unspent;
            if !self.bodies.locked_axes[i].locks_rotation() {
                let back = pose.rotation * end.inverse();
                self.bodies.angular_velocity[i] = back * self.bodies.angular_velocity[i];
            }
        }
    }
}
