//! Sleep, both ends: as the solve stage starts, which islands wake and which are skipped
//! ([`World::wake_or_skip_islands`]); as the finish stage ends, the bodies' sleep timers and
//! which islands fall asleep ([`update_sleep`], Box2D's rule).

use glam::Vec3;

use crate::World;
use crate::body::Bodies;
use crate::island::Islands;
use crate::parallel::{BODIES_PER_TASK, for_each_indexed, indices_where, spread};
use crate::settings::SolverSettings;

impl World {
    /// Marks which `islands` run this step (writes `island_awake`): an island with any awake body or moving kinematic
    /// guest runs and wakes all its bodies (a sleeping pile hit by an awake body, or carried
    /// off by a kinematic one, wakes whole); an island whose bodies are all asleep and whose
    /// guests are still is skipped.
    ///
    /// A woken body keeps its sleep timer: it has been quiet that long, and its own velocity
    /// ends the quiet as soon as the wake moves it; the island falls asleep only once every
    /// body in it, the one that woke it too, has been quiet long enough. Reset on wake, two
    /// islands linked by a contact that comes and goes from step to step (Parry's manifold of
    /// two cones side by side, 0.15 mm apart, flickers so) woke each other for ever, each
    /// falling asleep on a step the link was gone while the other was still counting.
    pub(super) fn wake_or_skip_islands(&mut self, islands: &Islands, island_awake: &mut Vec<bool>) {
        island_awake.clear();
        for k in 0..islands.len() {
            let bodies = islands.bodies(k);
            let awake = bodies
                .iter()
                .chain(islands.guests(k))
                .any(|&i| !self.bodies.asleep[i as usize]);
            if awake {
                for &i in bodies {
                    self.bodies.asleep[i as usize] = false;
                }
            }
            island_awake.push(awake);
        }
    }
}

/// Puts a component of the contact graph (an island, or part of one that the solve groups)
/// to sleep once every body in it has been slower than the thresholds for
/// `time_to_sleep` seconds (Box2D's rule); its velocities are zeroed and it costs nothing
/// until something touches it. Sleep timers advance for the bodies of awake islands.
pub(super) fn update_sleep(
    bodies: &mut Bodies,
    islands: &Islands,
    awake: &[bool],
    s: &SolverSettings,
    dt: f32,
    parallel: bool,
) {
    // Without sleeping the timers still run, at the default thresholds.
    let thresholds = s.sleep.unwrap_or_default();
    // Per body first (the bodies of awake islands), then per island; both passes are
    // independent per item, so they run on rayon's threads when the world is large.
    let in_awake_island = |i: usize| {
        islands
            .island_of_body
            .get(i)
            .is_some_and(|&k| k != u32::MAX && awake.get(k as usize).copied().unwrap_or(false))
    };
    let quiet = |linear: Vec3, angular: Vec3| {
        linear.length() < thresholds.linear_speed && angular.length() < thresholds.angular_speed
    };
    let parallel = spread(parallel, bodies.len(), BODIES_PER_TASK);
    {
        let Bodies {
            linear_velocity,
            angular_velocity,
            sleep_time,
            ..
        } = &mut *bodies;
        let (linear_velocity, angular_velocity) = (&*linear_velocity, &*angular_velocity);
        for_each_indexed(parallel, sleep_time, BODIES_PER_TASK, |i, time| {
            if in_awake_island(i) {
                *time = if quiet(linear_velocity[i], angular_velocity[i]) {
                    *time + dt
                } else {
                    0.0
                };
            }
        });
    }
    if s.sleep.is_none() {
        return;
    }
    // Per component of the contact graph, not per island of the solve (which may join
    // several, `Islands::build`). An island touching a moving kinematic body stays awake: the
    // body may carry it at any speed, below the thresholds too.
    let falls_asleep = |c: usize| {
        let k = islands.island_of_component(c);
        awake[k]
            && islands
                .component_bodies(c)
                .iter()
                .all(|&i| bodies.sleep_time[i as usize] >= thresholds.time_to_sleep)
            && islands.guests(k).iter().all(|&i| bodies.asleep[i as usize])
    };
    let sleepers = indices_where(parallel, islands.components(), falls_asleep);
    for c in sleepers {
        for &i in islands.component_bodies(c) {
            let i = i as usize;
            bodies.asleep[i] = true;
            bodies.linear_velocity[i] = Vec3::ZERO;
            bodies.angular_velocity[i] = Vec3::ZERO;
        }
    }
}
