//! The continuous-collision stage: fast dynamic bodies swept against static and kinematic
//! bodies, their motion clamped to the first impact ([`crate::continuous`]).

use parry3d::bounding_volume::BoundingVolume;

use super::World;
use crate::body::BodyKind;
use crate::continuous::{self, FAST_FRACTION, FastBody, Sweep};
use crate::settings::SolverSettings;

impl World {
    /// Keeps the step's start poses for the sweep (when continuous collision is on).
    pub(super) fn record_start_poses(&mut self, settings: &SolverSettings) {
        if settings.continuous {
            self.start_poses.clone_from(&self.bodies.pose);
        } else {
            self.start_poses.clear();
        }
    }

    /// Sweeps every awake dynamic body that moved more than [`FAST_FRACTION`] of its smallest
    /// half extent this step against the static and kinematic bodies in its swept box (the
    /// broad phase's tree, and the moving kinematic bodies), and puts it back to the earliest
    /// clamp ([`continuous::clamp_fraction`]) with the velocity gravity had given it by then. Each body's clamp reads only its own poses and
    /// the static and kinematic bodies', which no clamp changes, so the order does not matter.
    pub(super) fn continuous_stage(&mut self, settings: &SolverSettings) {
        let n = self.bodies.len();
        if !settings.continuous || self.start_poses.len() != n {
            return;
        }
        let mut clamps = std::mem::take(&mut self.clamps);
        clamps.clear();
        let b = &self.bodies;
        for i in 0..n {
            if !b.is_dynamic(i) || b.asleep[i] || b.pose[i] == self.start_poses[i] {
                continue;
            }
            let (start, end) = (self.start_poses[i], b.pose[i]);
            let (center_of_mass, spin) =
                (b.local_center_of_mass[i], b.angular_velocity[i] * self.dt);
            let shape = &*b.shape[i];
            let local = shape.compute_local_aabb();
            let half = local.half_extents();
            let min_half_extent = half.min_element();
            let radius = (local.center() - center_of_mass).length() + half.length();
            // Most bodies are slow: a cheap bound settles them before the sweep's trigonometry.
            let limit = FAST_FRACTION * min_half_extent;
            if continuous::travel_bound(&start, &end, center_of_mass, spin, radius)
                .is_some_and(|bound| bound <= limit)
            {
                continue;
            }
            let sweep = Sweep::new(start, end, center_of_mass, spin);
            let travel = sweep.travel(radius);
            if !travel.is_finite() || travel <= limit {
                continue;
            }
            let body = FastBody {
                shape,
                sweep,
                min_half_extent,
                travel,
                radius,
            };
            let swept = shape.compute_swept_aabb(&sweep.start, &sweep.end);
            let mut earliest = 1.0f32;
            let mut visit = |j: usize| {
                if j == i || !b.groups_interact(i, j) {
                    return;
                }
                let target = Sweep::new(
                    self.start_poses[j],
                    b.pose[j],
                    b.local_center_of_mass[j],
                    b.angular_velocity[j] * self.dt,
                );
                let in_contact = self.narrow_phase.has_points(i as u32, j as u32);
                if let Some(t) =
                    continuous::clamp_fraction(&body, &*b.shape[j], &target, in_contact)
                {
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
            for &j in &self.moving_kinematic {
                let j = j as usize;
                if b.shape[j]
                    .compute_swept_aabb(&self.start_poses[j], &b.pose[j])
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
        let gravity = self.gravity * self.dt;
        for &(i, pose, t) in &clamps {
            self.bodies.pose[i] = pose;
            let unspent = self.bodies.locked_axes[i].lock_linear_velocity(gravity * (1.0 - t));
            self.bodies.linear_velocity[i] -= unspent;
        }
        self.clamps = clamps;
    }
}
