//! `World::step`: the step as its stages, in the order of docs/architecture.md. Each stage is
//! one method here, and [`Stage`] names them for the profile ([`StepProfile`]) and the docs.

use glam::{Mat3, Vec3};
use rayon::prelude::*;

use super::{BLOW_UP_ENERGY_PER_KG, BLOW_UP_SPEED, World};
use crate::body::Bodies;
use crate::collision::narrow_phase::{self, ContactImpulse};
use crate::contact::constraints::{self, ContactConstraint};
use crate::diagnostics::{self, EnergyTerms, Stage, StepDiagnostics, StepProfile};
use crate::error::StepError;
use crate::island::Islands;
use crate::parallel::{BODIES_PER_TASK, ISLANDS_PER_TASK, PAIRS_PER_TASK, SharedItems, spread};
use crate::settings::SolverSettings;
use crate::solver::substep::{self, IslandWorkspace, StepContext};

/// The energy check's state: the lowest mechanical energy since the last edit (J), and
/// whether that reference holds. Every edit of the bodies between steps wakes a body
/// ([`World::wake_up`]), which clears `started`; inserting a body changes `bodies`.
#[derive(Clone, Copy, Debug, Default, serde::Serialize, serde::Deserialize)]
pub(super) struct EnergyCheck {
    lowest: f64,
    bodies: usize,
    pub(super) started: bool,
    /// What f32 rounding may have added since the reference restarted (J/kg).
    rounding: f64,
}

/// Times the stages of one step for [`StepProfile`].
struct StageClock {
    start: std::time::Instant,
    last: std::time::Instant,
    profile: StepProfile,
}

impl StageClock {
    fn start() -> Self {
        let now = std::time::Instant::now();
        Self {
            start: now,
            last: now,
            profile: StepProfile::default(),
        }
    }

    /// Ends `stage`: its time is the time since the last stage ended (or the start).
    fn end(&mut self, stage: Stage) {
        let now = std::time::Instant::now();
        self.profile
            .set(stage, ((now - self.last).as_secs_f64() * 1e3) as f32);
        self.last = now;
    }

    /// The stages' times and the total (ms).
    fn profile(&self) -> StepProfile {
        StepProfile {
            total: ((self.last - self.start).as_secs_f64() * 1e3) as f32,
            ..self.profile
        }
    }
}

impl World {
    /// Advances the world by dt through the stages of docs/architecture.md. Settings are
    /// checked first; a blow-up is reported with the step number, after the state that caused
    /// it was written.
    ///
    /// Threads: with [`World::parallel`] on, the step spreads its work over rayon's current
    /// pool. Called from a thread outside any pool (a program's main thread), the whole step
    /// runs on a thread of rayon's global pool: work spread from outside a pool waits for each
    /// piece to be handed over and back, and a step spreads hundreds of pieces (each colour of
    /// each substep), which made pyramid20 on two threads run at 2.2 ms/step from the main
    /// thread against 1.0 ms inside the pool (`impulse run pyramid20 --no-sleep` against
    /// `--threads 2`, before this).
    pub fn step(&mut self) -> Result<&StepDiagnostics, StepError> {
        if self.parallel && rayon::current_thread_index().is_none() {
            rayon::scope(|_| self.step_here().map(|_| ()))?;
            return Ok(&self.diagnostics);
        }
        self.step_here()
    }

    /// [`World::step`] on the calling thread.
    fn step_here(&mut self) -> Result<&StepDiagnostics, StepError> {
        let settings = self.settings.clone();
        self.step_count += 1;
        self.left_world.clear();
        let parallel = spread(self.parallel, 1, 0);
        let mut clock = StageClock::start();
        self.kinematic_velocities();
        self.record_start_poses(&settings);
        self.broad_phase_stage(&settings, parallel);
        clock.end(Stage::BroadPhase);
        self.narrow_phase_stage(parallel)?;
        clock.end(Stage::NarrowPhase);
        self.islands_stage(parallel);
        clock.end(Stage::Islands);
        self.assembly_stage(&settings);
        clock.end(Stage::Assembly);
        self.solve_stage(&settings);
        clock.end(Stage::Solve);
        self.scatter_islands();
        self.move_kinematic_bodies();
        clock.end(Stage::Scatter);
        if settings.continuous {
            self.unclamped_poses.clone_from(&self.bodies.pose);
        }
        self.continuous_stage(&settings);
        self.credit_clamps();
        clock.end(Stage::Continuous);
        self.store_impulses();
        clock.end(Stage::StoreImpulses);
        let energy = self.finish_stage(&settings, parallel);
        clock.end(Stage::Finish);
        self.profile = clock.profile();
        self.time += f64::from(self.dt);
        self.end_step(&energy)?;
        Ok(&self.diagnostics)
    }

    /// Raises the energy check's reference by the potential energy the continuous stage's
    /// clamps gave back: a clamped body is put back up its path with the velocity it reached
    /// at the end of the step, so it keeps the kinetic energy gravity gave it over the whole
    /// step but loses the descent that paid for it (a sphere clamped at 900 m/s, 7.4 m above
    /// where its step ended, gains 73 J/kg this way). That is the clamp's doing, not the
    /// solver's, and is not a blow-up. Only gains are credited.
    fn credit_clamps(&mut self) {
        if self.clamps.is_empty() || self.unclamped_poses.len() != self.bodies.len() {
            return;
        }
        let b = &self.bodies;
        let credit: f64 = self
            .clamps
            .iter()
            .filter(|&&(i, _, _)| b.inverse_mass[i] > 0.0)
            .map(|&(i, _, _)| {
                let before = self.unclamped_poses[i].transform_point(b.local_center_of_mass[i]);
                let rise = -self.gravity.dot(b.center_of_mass(i) - before);
                (f64::from(rise) / f64::from(b.inverse_mass[i])).max(0.0)
            })
            .sum();
        self.energy.lowest += credit;
    }

    /// Speculative margins and candidate pairs on the poses and velocities at the step's start;
    /// the energy check's reference restarts here after an edit.
    fn broad_phase_stage(&mut self, settings: &SolverSettings, parallel: bool) {
        if !self.energy.started || self.energy.bodies != self.bodies.len() {
            let start_energy = diagnostics::energy_terms(&self.bodies, self.gravity).mechanical();
            self.energy = EnergyCheck {
                lowest: start_energy,
                bodies: self.bodies.len(),
                started: true,
                rounding: 0.0,
            };
        }
        self.margins.update(
            &self.bodies,
            settings.prediction_distance,
            self.gravity,
            self.dt,
        );
        self.broad_phase.candidate_pairs(
            &self.bodies,
            self.margins.margins(),
            parallel,
            &mut self.candidates,
        );
    }

    /// Contact manifolds of the candidate pairs (Parry), beside the broad phase tree's upkeep.
    fn narrow_phase_stage(&mut self, parallel: bool) -> Result<(), StepError> {
        let (broad_phase, narrow_phase) = (&mut self.broad_phase, &mut self.narrow_phase);
        let (bodies, candidates, margins) = (&self.bodies, &self.candidates, &self.margins);
        let mut narrow = || narrow_phase.update(bodies, candidates, margins, parallel);
        if parallel {
            rayon::join(|| broad_phase.optimize(), narrow).1?;
        } else {
            broad_phase.optimize();
            narrow()?;
        }
        Ok(())
    }

    /// Islands from the pairs, so that assembly writes each island's constraints contiguously
    /// and nothing has to be moved afterwards.
    fn islands_stage(&mut self, parallel: bool) {
        // Islands from the pairs first, so that assembly writes each island's constraints
        // contiguously and nothing has to be moved afterwards. The union-find is serial; the
        // world inertia tensors (from the poses alone) are computed beside it.
        let (islands, world_inverse_inertia) = (&mut self.islands, &mut self.world_inverse_inertia);
        let (bodies, pairs) = (&self.bodies, &self.narrow_phase.pairs);
        if parallel {
            rayon::join(
                || islands.build(bodies, pairs),
                || world_inverse_inertia_of(bodies, parallel, world_inverse_inertia),
            );
        } else {
            world_inverse_inertia_of(bodies, parallel, world_inverse_inertia);
            islands.build(bodies, pairs);
        }
    }

    /// One constraint per contact point: Jacobian rows, effective masses, warm-start impulses.
    fn assembly_stage(&mut self, settings: &SolverSettings) {
        constraints::assemble(
            &self.bodies,
            &self.narrow_phase,
            &self.islands,
            settings,
            &self.world_inverse_inertia,
            !self.any_restitution(),
            self.parallel,
            &mut self.constraints,
        );
    }

    /// Whether any body has a restitution coefficient above zero (then islands end their step
    /// with a restitution solve).
    fn any_restitution(&self) -> bool {
        self.bodies.restitution.iter().any(|&r| r > 0.0)
    }

    /// Stages 1, 5 and 6 per island: each island's substeps touch only its own bodies.
    fn solve_stage(&mut self, settings: &SolverSettings) {
        let dt = self.dt;
        let islands = self.islands.len();
        self.wake_or_skip_islands();
        if self.workspaces.len() < islands {
            self.workspaces
                .resize_with(islands, IslandWorkspace::default);
        }
        {
            let context = StepContext {
                bodies: &self.bodies,
                gravity: self.gravity,
                dt,
                settings,
                parallel: self.parallel,
                restitution: self.any_restitution(),
                world_inverse_inertia: &self.world_inverse_inertia,
                forces: self.forces_pending,
            };
            // Each island ends its step with the passes that read its rows once more, while
            // they are still in cache: its rows' v*, its natural-map residual and its
            // friction-row count, in one pass, instead of world-wide passes over every row
            // that wait on memory; the results are the same to the bit. Islands solved in SIMD
            // lanes have taken them from their bundles already (`IslandWorkspace::rows`).
            let run = |bodies: &[u32],
                       guests: &[u32],
                       constraints: &mut [ContactConstraint],
                       workspace: &mut IslandWorkspace| {
                substep::step_island(bodies, guests, constraints, &context, workspace);
                let rows = match workspace.rows.take() {
                    Some(rows) => rows,
                    None => diagnostics::record_velocity_before_and_residual(
                        constraints,
                        constraints::BodySlots::Island,
                        &workspace.linear,
                        &workspace.angular,
                        context.parallel,
                        &mut workspace.record_scratch,
                    ),
                };
                workspace.report.natural_map_residual = rows.natural_map_residual;
                workspace.friction_rows = rows.friction_rows;
            };
            let islands_of = &self.islands;
            let awake = &self.island_awake;
            let workspaces = &mut self.workspaces[..islands];
            let awake_count = awake.iter().take(islands).filter(|&&a| a).count();
            if spread(self.parallel, awake_count, 1) {
                // Islands differ in cost by orders of magnitude (an exact solve against a
                // resting column), so the jobs are split finely enough for work stealing to
                // even them out: in balls16k's landing, 800 columns each solved exactly, rayon's
                // default split left one thread with three quarters of the work.
                let rows = SharedItems(self.constraints.as_mut_ptr());
                let total = self.constraints.len();
                workspaces
                    .par_iter_mut()
                    .enumerate()
                    .with_max_len(ISLANDS_PER_TASK)
                    .for_each(|(k, workspace)| {
                        // Capture the whole wrapper (Sync), not its raw-pointer field.
                        #[allow(clippy::redundant_locals)]
                        let rows = rows;
                        if !awake[k] {
                            return;
                        }
                        let range = islands_of.constraint_range(k);
                        assert!(range.end <= total);
                        // SAFETY: the islands' constraint ranges are disjoint and inside the
                        // constraints (checked above), and each island is visited once.
                        let mine = unsafe {
                            std::slice::from_raw_parts_mut(rows.0.add(range.start), range.len())
                        };
                        run(islands_of.bodies(k), islands_of.guests(k), mine, workspace);
                    });
            } else {
                let mut rest: &mut [ContactConstraint] = &mut self.constraints;
                for (k, workspace) in workspaces.iter_mut().enumerate() {
                    let (mine, others) = rest.split_at_mut(islands_of.constraint_range(k).len());
                    rest = others;
                    if awake[k] {
                        run(islands_of.bodies(k), islands_of.guests(k), mine, workspace);
                    }
                }
            }
        }
    }

    /// Sleep, energy, momentum and the step's diagnostics; returns the energy terms for the
    /// blow-up check.
    fn finish_stage(&mut self, settings: &SolverSettings, parallel: bool) -> EnergyTerms {
        let dt = self.dt;
        let islands = self.islands.len();
        let mut iterations = 0;
        for k in 0..islands {
            if self.island_awake[k] {
                iterations = iterations.max(self.workspaces[k].report.iterations);
            }
        }
        // Awake islands recorded their rows' v* as their step ended; a sleeping island's rows
        // take it from the bodies' velocities. One pass over every row covers them (rows of
        // awake islands come out as their own record, to the last bits where the SIMD lanes
        // took it: see `wide::Bundles::record`).
        if self.island_awake.iter().take(islands).any(|awake| !awake) {
            // The pass reads every row's I⁻¹(r × d), which the lanes keep in their bundles.
            constraints::complete_products(&mut self.constraints, &self.world_inverse_inertia);
            constraints::record_velocity_before(
                &mut self.constraints,
                constraints::BodySlots::World,
                &self.bodies.linear_velocity,
                &self.bodies.angular_velocity,
                self.parallel,
                &mut self.scratch,
            );
        }
        // Only awake islands were solved this step; sleeping ones keep last step's state.
        let mut squared = 0.0f64;
        let mut friction_rows = 0;
        // Reuse last step's list: no allocation per step once it has grown.
        let mut island_reports = std::mem::take(&mut self.diagnostics.islands);
        island_reports.clear();
        for k in 0..islands {
            let range = self.islands.constraint_range(k);
            if self.island_awake[k] {
                let report = self.workspaces[k].report;
                let part = report.natural_map_residual as f64;
                squared += part * part;
                friction_rows += self.workspaces[k].friction_rows;
                if !range.is_empty() {
                    island_reports.push(report);
                }
            } else {
                friction_rows += self::friction_rows(&self.constraints[range]);
            }
        }
        let residual = squared.sqrt() as f32;
        // Sleep last: it zeroes velocities, which must not leak into this step's LCP. The
        // counts over pairs need no bodies, so they run beside it and the energy.
        let (bodies, gravity) = (&mut self.bodies, self.gravity);
        let (islands_of, awake) = (&self.islands, &self.island_awake);
        let pairs = &self.narrow_phase;
        let mut sleep_and_energy = || {
            update_sleep(bodies, islands_of, awake, settings, dt, parallel);
            diagnostics::energy_terms_on(bodies, gravity, parallel)
        };
        let counts = || {
            (
                pairs.pairs.iter().filter(|p| p.point_count() > 0).count(),
                pairs.max_depth(),
            )
        };
        let (energy, (contact_pairs, max_depth)) = if parallel {
            rayon::join(sleep_and_energy, counts)
        } else {
            (sleep_and_energy(), counts())
        };
        self.diagnostics = StepDiagnostics {
            step: self.step_count,
            contact_pairs,
            contacts: self.constraints.len(),
            rows: self.constraints.len() + 2 * friction_rows,
            iterations,
            natural_map_residual: residual,
            islands: island_reports,
            max_depth,
            kinetic_energy: energy.kinetic as f32,
            linear_momentum: energy.momentum.to_array(),
        };
        energy
    }

    /// Contact events, the end of this step's forces, and the blow-up check.
    fn end_step(&mut self, energy: &EnergyTerms) -> Result<(), StepError> {
        self.record_contact_events();
        if std::mem::take(&mut self.forces_pending) {
            // Forces are for one step. Their work is energy the contacts did not make, so the
            // energy check starts again from here.
            self.bodies.force.fill(Vec3::ZERO);
            self.bodies.torque.fill(Vec3::ZERO);
            self.energy.lowest = energy.mechanical();
        }
        if !self.moving_kinematic.is_empty() {
            // A moving kinematic body does work on what it pushes or lifts, as a force does.
            self.energy.lowest = energy.mechanical();
        }
        self.check_blow_up(energy)?;
        Ok(())
    }

    /// Marks which islands run this step: an island with any awake body or moving kinematic
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
    fn wake_or_skip_islands(&mut self) {
        self.island_awake.clear();
        for k in 0..self.islands.len() {
            let bodies = self.islands.bodies(k);
            let awake = bodies
                .iter()
                .chain(self.islands.guests(k))
                .any(|&i| !self.bodies.asleep[i as usize]);
            if awake {
                for &i in bodies {
                    self.bodies.asleep[i as usize] = false;
                }
            }
            self.island_awake.push(awake);
        }
    }

    /// Writes every awake island's velocities and poses back into the bodies. In parallel,
    /// runs of bodies each look up their island and local index (islands can be many and
    /// small, or one and large; body runs split either evenly).
    fn scatter_islands(&mut self) {
        let islands = &self.islands;
        let (workspaces, awake) = (&self.workspaces, &self.island_awake);
        if !spread(self.parallel, self.bodies.len(), BODIES_PER_TASK) {
            for k in 0..islands.len() {
                if awake[k] {
                    substep::scatter(islands.bodies(k), &workspaces[k], &mut self.bodies);
                }
            }
            return;
        }
        let Bodies {
            pose,
            linear_velocity,
            angular_velocity,
            local_center_of_mass,
            ..
        } = &mut self.bodies;
        pose.par_iter_mut()
            .zip(linear_velocity.par_iter_mut())
            .zip(angular_velocity.par_iter_mut())
            .enumerate()
            .with_min_len(BODIES_PER_TASK)
            .for_each(|(i, ((pose, linear), angular))| {
                let Some(&k) = islands.island_of_body.get(i) else {
                    return;
                };
                if k == u32::MAX || !awake[k as usize] {
                    return;
                }
                substep::scatter_body(
                    &workspaces[k as usize],
                    islands.local_index(i),
                    local_center_of_mass[i],
                    pose,
                    linear,
                    angular,
                );
            });
    }

    /// Writes the solved impulses back into the manifolds' points for next step's warm start.
    ///
    /// Runs over the pairs (in parallel runs of [`PAIRS_PER_TASK`]), each finding
    /// its rows where assembly put them, so every manifold is written by one task and the
    /// manifolds' scattered heap blocks are visited in memory order. An island swept colour by
    /// colour has its rows re-sorted by colour; a row found out of its place (its `source` not
    /// the pair, manifold and point where assembly put it) then sends the whole write-back to
    /// the serial path, which follows each row's `source`.
    fn store_impulses(&mut self) {
        let constraints = &self.constraints;
        let islands = &self.islands;
        let store = |first_pair: usize, pairs: &mut [narrow_phase::ContactPair]| {
            for i in 0..pairs.len() {
                narrow_phase::prefetch_manifolds(pairs, i);
                let (pair_index, pair) = (first_pair + i, &mut pairs[i]);
                let mut row = if pair.point_count() > 0 {
                    islands.first_row(pair_index)
                } else {
                    0
                };
                let mut step_normal_impulse = 0.0;
                for (manifold_index, manifold) in pair.manifolds.iter_mut().enumerate() {
                    let count = manifold.points.len();
                    if count == 0 {
                        continue;
                    }
                    let Some(rows) = constraints.get(row..row + count) else {
                        return false;
                    };
                    row += count;
                    // Assembly gives every point of a manifold its friction directions, so
                    // they are read once here and each point's row only for its impulses.
                    let tangents = [rows[0].tangents[0].direction, rows[0].tangents[1].direction];
                    manifold.data.tangent = tangents[0];
                    for (point_index, (point, c)) in
                        manifold.points.iter_mut().zip(rows).enumerate()
                    {
                        if c.source
                            != (pair_index as u32, manifold_index as u16, point_index as u16)
                        {
                            return false;
                        }
                        point.data = contact_impulse(c, tangents);
                        step_normal_impulse += c.step_impulses[0];
                    }
                }
                pair.step_normal_impulse = step_normal_impulse;
            }
            true
        };
        let pairs = &mut self.narrow_phase.pairs;
        let in_place = if spread(self.parallel, pairs.len(), PAIRS_PER_TASK) {
            pairs
                .par_chunks_mut(PAIRS_PER_TASK)
                .enumerate()
                .map(|(k, chunk)| store(k * PAIRS_PER_TASK, chunk))
                .reduce(|| true, |x, y| x && y)
        } else {
            store(0, pairs)
        };
        if !in_place {
            for pair in pairs.iter_mut() {
                pair.step_normal_impulse = 0.0;
            }
            for c in constraints {
                let pair = &mut pairs[c.source.0 as usize];
                let (_, manifold, point) = c.source;
                let manifold = &mut pair.manifolds[manifold as usize];
                let tangents = [c.tangents[0].direction, c.tangents[1].direction];
                manifold.data.tangent = tangents[0];
                manifold.points[point as usize].data = contact_impulse(c, tangents);
                pair.step_normal_impulse += c.step_impulses[0];
            }
        }
    }

    fn check_blow_up(&mut self, terms: &diagnostics::EnergyTerms) -> Result<(), StepError> {
        let energy = terms.mechanical();
        let gain = (energy - self.energy.lowest) / terms.mass.max(f64::MIN_POSITIVE);
        self.energy.lowest = self.energy.lowest.min(energy);
        // Positions and velocities are f32: each substep's x += h·v and v += h·g round by up to
        // an ulp of |x| and |v|, which moves the energy per kg by up to |g|·ulp(|x|) and
        // |v|·ulp(|v|), the same way step after step in a long fall. Far from the origin or
        // fast (a body 25 km down after 70 s of free fall) that adds up to more than the bound;
        // near the origin it is negligible (1e-5 J/kg a substep at 10 m).
        let ulp = |x: f32| f64::from(x.abs().max(1.0) * f32::EPSILON);
        self.energy.rounding += f64::from(self.settings.substeps)
            * (f64::from(self.gravity.length()) * ulp(terms.largest_distance)
                + f64::from(terms.largest_speed) * ulp(terms.largest_speed));
        let bound = BLOW_UP_ENERGY_PER_KG + self.energy.rounding;
        if gain.is_nan() || gain > bound {
            let speed = |k: usize| self.bodies.linear_velocity[k].length();
            let fastest = (0..self.bodies.len())
                .max_by(|&i, &j| speed(i).total_cmp(&speed(j)))
                .unwrap_or(0);
            return Err(StepError::EnergyBlowUp {
                step: self.step_count,
                gain_per_kg: gain as f32,
                bound: bound as f32,
                fastest_body: fastest,
                speed: if self.bodies.is_empty() {
                    0.0
                } else {
                    speed(fastest)
                },
            });
        }
        // One pass over the bodies finds the first bad one, and only then is the error built.
        // On rayon's threads for a large world: serial, it was a quarter of `World::step`'s
        // own samples in a two-thread balls16k run.
        let b = &self.bodies;
        let max_distance = self.settings.max_distance;
        let position = |i: usize| b.pose[i].translation.length();
        let speed = |i: usize| {
            b.linear_velocity[i]
                .length()
                .max(b.angular_velocity[i].length())
        };
        // A moving body beyond the world bound leaves the world (`leave_world`), unless it
        // also blew up; a sleeping one has not moved since it was checked.
        let far = |i: usize| !b.asleep[i] && b.inverse_mass[i] > 0.0 && position(i) > max_distance;
        let bad = |i: usize| {
            let (position, speed) = (position(i), speed(i));
            position.is_nan() || position.is_infinite() || speed.is_nan() || speed > BLOW_UP_SPEED
        };
        let first = if spread(self.parallel, b.len(), BODIES_PER_TASK) {
            (0..b.len())
                .into_par_iter()
                .with_min_len(BODIES_PER_TASK)
                .find_first(|&i| bad(i) || far(i))
        } else {
            (0..b.len()).find(|&i| bad(i) || far(i))
        };
        let Some(first) = first else {
            return Ok(());
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
            for i in leaving {
                self.leave_world(i);
            }
            return Ok(());
        };
        let position = position(i);
        if !position.is_finite() {
            return Err(StepError::BlowUp {
                step: self.step_count,
                body: i,
                quantity: "position",
                value: position,
                bound: max_distance,
            });
        }
        Err(StepError::BlowUp {
            step: self.step_count,
            body: i,
            quantity: "velocity",
            value: speed(i),
            bound: BLOW_UP_SPEED,
        })
    }
}

impl World {
    /// Takes body `i` out of the simulation where it is ([`super::LeftWorld`]) and records
    /// the event. The energy check's reference restarts at the next step, as after an edit.
    fn leave_world(&mut self, i: usize) {
        let b = &mut self.bodies;
        let position = b.center_of_mass(i);
        b.linear_velocity[i] = Vec3::ZERO;
        b.angular_velocity[i] = Vec3::ZERO;
        b.asleep[i] = true;
        b.groups[i] = 0;
        b.mask[i] = 0;
        b.inverse_mass[i] = 0.0;
        b.local_inverse_inertia[i] = Mat3::ZERO;
        b.force[i] = Vec3::ZERO;
        b.torque[i] = Vec3::ZERO;
        self.energy.started = false;
        let Some(handle) = self.handle_of(i) else {
            return;
        };
        self.left_world.push(super::LeftWorld {
            body: i,
            handle,
            name: self.bodies.name[i].clone(),
            step: self.step_count,
            position,
            bound: self.settings.max_distance,
        });
    }
}

/// Constraint `c`'s impulses as its point keeps them, friction as world vectors along
/// `tangents`, its rows' two friction directions.
fn contact_impulse(c: &ContactConstraint, [t1, t2]: [Vec3; 2]) -> ContactImpulse {
    ContactImpulse {
        normal: c.normal_impulse,
        friction: t1 * c.tangent_impulses[0] + t2 * c.tangent_impulses[1],
        step_normal: c.step_impulses[0],
        step_friction: t1 * c.step_impulses[1] + t2 * c.step_impulses[2],
    }
}

/// Contact points with friction (μ > 0): each adds two tangent rows to the step's LCP.
fn friction_rows(constraints: &[ContactConstraint]) -> usize {
    constraints.iter().filter(|c| c.friction > 0.0).count()
}

/// Puts an island to sleep once every body in it has been slower than the thresholds for
/// `time_to_sleep` seconds (Box2D's rule); its velocities are zeroed and it costs nothing
/// until something touches it. Sleep timers advance for the bodies of awake islands.
fn update_sleep(
    bodies: &mut Bodies,
    islands: &Islands,
    awake: &[bool],
    s: &SolverSettings,
    dt: f32,
    parallel: bool,
) {
    // Per body first (the bodies of awake islands), then per island; both passes are
    // independent per item, so they run on rayon's threads when the world is large (serial
    // they were 0.5 % of the samples of a two-thread balls16k run, the other thread idle).
    let in_awake_island = |i: usize| {
        islands
            .island_of_body
            .get(i)
            .is_some_and(|&k| k != u32::MAX && awake.get(k as usize).copied().unwrap_or(false))
    };
    let quiet = |linear: Vec3, angular: Vec3| {
        linear.length() < s.sleep_linear_speed && angular.length() < s.sleep_angular_speed
    };
    let parallel = spread(parallel, bodies.len(), BODIES_PER_TASK);
    {
        let Bodies {
            linear_velocity,
            angular_velocity,
            sleep_time,
            ..
        } = &mut *bodies;
        let update = |(i, ((time, linear), angular)): (usize, ((&mut f32, &Vec3), &Vec3))| {
            if in_awake_island(i) {
                *time = if quiet(*linear, *angular) {
                    *time + dt
                } else {
                    0.0
                };
            }
        };
        if parallel {
            sleep_time
                .par_iter_mut()
                .zip(linear_velocity.par_iter())
                .zip(angular_velocity.par_iter())
                .enumerate()
                .with_min_len(BODIES_PER_TASK)
                .for_each(update);
        } else {
            sleep_time
                .iter_mut()
                .zip(linear_velocity.iter())
                .zip(angular_velocity.iter())
                .enumerate()
                .for_each(update);
        }
    }
    if !s.sleep {
        return;
    }
    // An island touching a moving kinematic body stays awake: the body may carry it at any
    // speed, below the thresholds too.
    let falls_asleep = |k: usize| {
        awake[k]
            && islands
                .bodies(k)
                .iter()
                .all(|&i| bodies.sleep_time[i as usize] >= s.time_to_sleep)
            && islands.guests(k).iter().all(|&i| bodies.asleep[i as usize])
    };
    let sleepers: Vec<usize> = if parallel {
        (0..awake.len())
            .into_par_iter()
            .filter(|&k| falls_asleep(k))
            .collect()
    } else {
        (0..awake.len()).filter(|&k| falls_asleep(k)).collect()
    };
    for k in sleepers {
        for &i in islands.bodies(k) {
            let i = i as usize;
            bodies.asleep[i] = true;
            bodies.linear_velocity[i] = Vec3::ZERO;
            bodies.angular_velocity[i] = Vec3::ZERO;
        }
    }
}

/// World-frame inverse inertia tensors I⁻¹ = R I_local⁻¹ Rᵀ (1/(kg·m²)) of every body at its
/// current pose, restricted to the free rotations of bodies with locked rotation axes
/// (`Bodies::world_inverse_inertia`); zero for bodies that do not rotate.
fn world_inverse_inertia_of(bodies: &Bodies, parallel: bool, out: &mut Vec<Mat3>) {
    let world = |i: usize| bodies.world_inverse_inertia(i);
    if spread(parallel, 1, 0) {
        (0..bodies.len())
            .into_par_iter()
            .with_min_len(BODIES_PER_TASK)
            .map(world)
            .collect_into_vec(out);
    } else {
        out.clear();
        out.extend((0..bodies.len()).map(world));
    }
}

#[cfg(test)]
#[path = "step_tests.rs"]
mod tests;
