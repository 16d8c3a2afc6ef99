//! The energy and blow-up check, start to end ([`EnergyCheck`]): the reference (the lowest
//! mechanical energy since the last edit) restarts as a step starts after an edit, is raised by
//! what the continuous stage's clamps give back and reset by the step's forces and moving
//! kinematic bodies, and the step's end compares the energy with it ([`BLOW_UP_ENERGY_PER_KG`])
//! and checks every body's position for a non-finite value and its linear and angular speeds
//! against their bounds (`WorldLimits::max_linear_speed`, m/s, and `max_angular_speed`,
//! rad/s); a moving body beyond the world bound leaves the world instead.

use glam::Vec3;
use parry3d::math::Pose;

use crate::body::{Bodies, BodyHandle};
use crate::diagnostics::{self, EnergyTerms};
use crate::error::StepError;
use crate::parallel::{BODIES_PER_TASK, find_first, spread};
use crate::settings::SolverSettings;

/// Mechanical energy (kinetic + gravitational, [`crate::diagnostics::EnergyTerms`]) more than
/// this many joules per kilogram of moving mass above the lowest it has been since the last
/// edit means the simulation has blown up. Contacts only take energy out; what the overlap
/// repair puts in is lifting bodies out of each other (the `overlap_pyramid` scene, started
/// 25 % overlapping, gains about 10 J/kg). 50 J/kg is every body lifted 5 m or moving at
/// 10 m/s. A solve that fails to hold a pile can push it apart far faster than that while no
/// body comes near a speed bound (`impulse run pyramid100 --method pgs --substeps 4
/// --iterations 1 --position-iterations 1` is such a solve; tests/blow_up.rs). Changing
/// bodies between steps (velocities, poses, forces, new or removed bodies, gravity: every
/// edit that wakes a body, [`crate::World::wake_up`]) restarts the reference.
pub const BLOW_UP_ENERGY_PER_KG: f64 = 50.0;

/// The share of the largest kinetic energy the bodies have had since the last edit that a step
/// may add on top of [`BLOW_UP_ENERGY_PER_KG`] before it is a blow-up. The state is f32 (seven
/// significant digits) and a fast body's contacts are solved to a tolerance, not exactly: a
/// capsule hitting the ground at 766 m/s while spinning at 16,205 rad/s (about 3·10⁵ J/kg of
/// kinetic energy) rises by 60 J/kg in the steps after its impact, a five-thousandth of the
/// energy it came with. A blow-up multiplies the energy; a pile pushed apart from rest has had
/// almost none, so this share leaves its bound where it was.
pub(crate) const BLOW_UP_KINETIC_SHARE: f64 = 1.0e-3;

/// The energy check's state: the lowest mechanical energy since the last edit (J), and
/// whether that reference holds. Every edit of the bodies between steps wakes a body
/// ([`crate::World::wake_up`]), which clears `started`; inserting a body changes `bodies`.
#[derive(Clone, Copy, Debug, Default, serde::Serialize, serde::Deserialize)]
pub(crate) struct EnergyCheck {
    lowest: f64,
    bodies: usize,
    pub(crate) started: bool,
    /// What f32 rounding may have added since the reference restarted (J/kg).
    rounding: f64,
    /// The largest kinetic energy per kilogram of moving mass since the reference restarted
    /// (J/kg), for [`BLOW_UP_KINETIC_SHARE`].
    #[serde(default)]
    peak_kinetic: f64,
}

impl EnergyCheck {
    /// As the step starts: the reference restarts from the bodies' energy after an edit
    /// ([`crate::World::wake_up`] clears `started`) or when the body count changed.
    pub(super) fn start(&mut self, bodies: &Bodies, gravity: Vec3) {
        if !self.started || self.bodies != bodies.len() {
            let terms = diagnostics::energy_terms(bodies, gravity);
            *self = EnergyCheck {
                lowest: terms.mechanical(),
                bodies: bodies.len(),
                started: true,
                rounding: 0.0,
                peak_kinetic: terms.kinetic / terms.mass.max(f64::MIN_POSITIVE),
            };
        }
    }

    /// Raises the reference by the potential energy the continuous stage's clamps gave back
    /// (`clamps` as the stage left them, `unclamped` every body's pose before it): a clamped
    /// body is put back up its path with the velocity it reached at the end of the step, so it
    /// keeps the kinetic energy gravity gave it over the whole step but loses the descent that
    /// paid for it (a sphere clamped at 900 m/s, 7.4 m above where its step ended, gains
    /// 73 J/kg this way). That is the clamp's doing, not the solver's, and is not a blow-up.
    /// Only gains are credited.
    pub(super) fn credit_clamps(
        &mut self,
        clamps: &[(usize, Pose, f32)],
        unclamped: &[Pose],
        bodies: &Bodies,
        gravity: Vec3,
    ) {
        if clamps.is_empty() || unclamped.len() != bodies.len() {
            return;
        }
        let b = bodies;
        let credit: f64 = clamps
            .iter()
            .filter(|&&(i, _, _)| b.inverse_mass[i] > 0.0)
            .map(|&(i, _, _)| {
                let before = unclamped[i].transform_point(b.local_center_of_mass[i]);
                let rise = -gravity.dot(b.center_of_mass(i) - before);
                (f64::from(rise) / f64::from(b.inverse_mass[i])).max(0.0)
            })
            .sum();
        self.lowest += credit;
    }

    /// As the step ends, before [`EnergyCheck::check`]: the reference restarts from `energy`
    /// when the step had forces (their work is energy the contacts did not make) or a moving
    /// kinematic body (it does work on what it pushes or lifts, as a force does).
    pub(super) fn restart_after_work(
        &mut self,
        energy: &EnergyTerms,
        forces: bool,
        kinematic: bool,
    ) {
        if forces {
            self.lowest = energy.mechanical();
        }
        if kinematic {
            self.lowest = energy.mechanical();
        }
    }

    /// The blow-up check as step `step` ends, on the bodies' energy `terms`: the mechanical
    /// energy per kilogram against its lowest since the last edit, then every body's position
    /// and speed (bodies named in errors by `handles`, per dense index). Returns the moving bodies beyond `settings.max_distance`, in index order,
    /// which leave the world, or the blow-up.
    // The step's state this check reads, each part as the step holds it.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn check(
        &mut self,
        terms: &EnergyTerms,
        bodies: &Bodies,
        handles: &[BodyHandle],
        settings: &SolverSettings,
        gravity: Vec3,
        step: u64,
        parallel: bool,
    ) -> Result<Vec<usize>, StepError> {
        let energy = terms.mechanical();
        let gain = (energy - self.lowest) / terms.mass.max(f64::MIN_POSITIVE);
        self.lowest = self.lowest.min(energy);
        // Positions and velocities are f32: each substep's x += h·v and v += h·g round by up to
        // an ulp of |x| and |v|, which moves the energy per kg by up to |g|·ulp(|x|) and
        // |v|·ulp(|v|), the same way step after step in a long fall. Far from the origin or
        // fast (a body 25 km down after 70 s of free fall) that adds up to more than the bound;
        // near the origin it is negligible (1e-5 J/kg a substep at 10 m).
        let ulp = |x: f32| f64::from(x.abs().max(1.0) * f32::EPSILON);
        self.rounding += f64::from(settings.solve.substeps)
            * (f64::from(gravity.length()) * ulp(terms.largest_distance)
                + f64::from(terms.largest_speed) * ulp(terms.largest_speed));
        let bound =
            BLOW_UP_ENERGY_PER_KG + BLOW_UP_KINETIC_SHARE * self.peak_kinetic + self.rounding;
        let kinetic = terms.kinetic / terms.mass.max(f64::MIN_POSITIVE);
        if kinetic.is_finite() {
            self.peak_kinetic = self.peak_kinetic.max(kinetic);
        }
        if gain.is_nan() || gain > bound {
            let speed = |k: usize| bodies.linear_velocity[k].length();
            let fastest = (0..bodies.len())
                .max_by(|&i, &j| speed(i).total_cmp(&speed(j)))
                .unwrap_or(0);
            return Err(StepError::EnergyBlowUp {
                step,
                gain_per_kg: gain as f32,
                bound: bound as f32,
                fastest_body: handles.get(fastest).copied(),
                speed: if bodies.is_empty() {
                    0.0
                } else {
                    speed(fastest)
                },
            });
        }
        // One pass over the bodies finds the first bad one, and only then is the error built;
        // on rayon's threads for a large world, where a serial pass would be a large share of
        // the step's own work.
        let b = &bodies;
        let max_distance = settings.limits.max_distance;
        let position = |i: usize| b.pose[i].translation.length();
        let (max_linear_speed, max_angular_speed) = (
            settings.limits.max_linear_speed,
            settings.limits.max_angular_speed,
        );
        let linear_speed = |i: usize| b.linear_velocity[i].length();
        let angular_speed = |i: usize| b.angular_velocity[i].length();
        // NaN is beyond every bound.
        let beyond = |value: f32, bound: f32| value.is_nan() || value > bound;
        // A moving body beyond the world bound leaves the world (returned), unless it
        // also blew up; a sleeping one has not moved since it was checked.
        let far = |i: usize| !b.asleep[i] && b.inverse_mass[i] > 0.0 && position(i) > max_distance;
        let bad = |i: usize| {
            !position(i).is_finite()
                || beyond(linear_speed(i), max_linear_speed)
                || beyond(angular_speed(i), max_angular_speed)
        };
        let first = find_first(
            spread(parallel, b.len(), BODIES_PER_TASK),
            b.len(),
            BODIES_PER_TASK,
            |i| bad(i) || far(i),
        );
        let Some(first) = first else {
            return Ok(Vec::new());
        };
        let (first_bad, leaving) = {
            let mut leaving = Vec::new();
            let mut first_bad = None;
            for i in first..b.len() {
                if bad(i) {
                    first_bad = Some(i);
                    break;
                }
                if far(i) {
                    leaving.push(i);
                }
            }
            (first_bad, leaving)
        };
        let Some(i) = first_bad else {
            return Ok(leaving);
        };
        let position = position(i);
        let (linear, angular) = (linear_speed(i), angular_speed(i));
        let (quantity, value, unit, setting, bound) = if !position.is_finite() {
            ("position", position, "m", "max_distance", max_distance)
        } else if beyond(linear, max_linear_speed) {
            (
                "linear speed",
                linear,
                "m/s",
                "max_linear_speed",
                max_linear_speed,
            )
        } else {
            (
                "angular speed",
                angular,
                "rad/s",
                "max_angular_speed",
                max_angular_speed,
            )
        };
        Err(StepError::BlowUp {
            step,
            body: handles[i],
            quantity,
            value,
            unit,
            setting,
            bound,
        })
    }
}
