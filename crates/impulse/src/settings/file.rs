//! The settings as scene files and snapshots hold them: one flat `solver` object
//! (docs/scene-format.md), `auto`'s parameters beside `method`, every group's fields side by
//! side. [`SolverSettings`] reads and writes itself through [`SettingsFile`], so the format
//! stays as it was before the Rust type was grouped; a field missing from a file takes its
//! default. `sleep: false` is [`SolverSettings::sleep`] `None` (its three parameters are then
//! kept in [`SolverSettings::off`] and written back as read).

use serde::{Deserialize, Serialize};

use super::{
    CombineRule, ContactRepair, ContactSettings, ImpactModel, OffParameters, SleepSettings,
    SolveSettings, SolverMethod, SolverSettings, WorldLimits,
};

/// `solver.method`: the method's name alone.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
enum MethodName {
    Pgs,
    Nncg,
    Apgd,
    Auto,
}

/// The `solver` object, field for field in the order files are written; each field as
/// [`SolverSettings`] documents it. `auto`'s three parameters and the sleep parameters are
/// read whatever the method and `sleep` say, and written back as read: into the method or
/// [`SolverSettings::sleep`] while the option is on, into [`super::OffParameters`] while it
/// is off.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
struct SettingsFile {
    method: MethodName,
    substeps: u32,
    iterations: u32,
    relax_iterations: u32,
    impact_sweeps: u32,
    tolerance: f32,
    escalation_tolerance: f32,
    escalation_iterations: u32,
    mass_ratio_threshold: f32,
    exact_max_contacts: u32,
    heavy_on_light_mass_ratio: f32,
    restitution_threshold: f32,
    repair: ContactRepair,
    overlap_slop: f32,
    max_repair_speed: f32,
    warm_start: f32,
    prediction_distance: f32,
    split_overlap: f32,
    collision_steps: u32,
    recycle_distance: f32,
    sleep: bool,
    sleep_linear_speed: f32,
    sleep_angular_speed: f32,
    time_to_sleep: f32,
    friction: bool,
    friction_in_main_solve: bool,
    direct_joint_solve: bool,
    parallel_island_contacts: u32,
    simd_island_contacts: u32,
    fused_multiply_add: bool,
    gyroscopic: bool,
    continuous: bool,
    impact: ImpactModel,
    friction_combine: CombineRule,
    restitution_combine: CombineRule,
    max_distance: f32,
    max_linear_speed: f32,
    max_angular_speed: f32,
}

/// As the flat `solver` object.
impl Serialize for SolverSettings {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        SettingsFile::from(self.clone()).serialize(serializer)
    }
}

/// From the flat `solver` object; missing fields take their defaults, unknown ones are errors.
impl<'de> Deserialize<'de> for SolverSettings {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        SettingsFile::deserialize(deserializer).map(Self::from)
    }
}

impl Default for SettingsFile {
    fn default() -> Self {
        SolverSettings::default().into()
    }
}

impl From<SolverSettings> for SettingsFile {
    fn from(s: SolverSettings) -> Self {
        let (escalation_tolerance, escalation_iterations, mass_ratio_threshold) =
            s.auto_parameters();
        let sleep = s.sleep_parameters();
        SettingsFile {
            method: match s.solve.method {
                SolverMethod::Pgs => MethodName::Pgs,
                SolverMethod::Nncg => MethodName::Nncg,
                SolverMethod::Apgd => MethodName::Apgd,
                SolverMethod::Auto { .. } => MethodName::Auto,
            },
            substeps: s.solve.substeps,
            iterations: s.solve.iterations,
            relax_iterations: s.solve.relax_iterations,
            impact_sweeps: s.solve.impact_sweeps,
            tolerance: s.solve.tolerance,
            escalation_tolerance,
            escalation_iterations,
            mass_ratio_threshold,
            exact_max_contacts: s.solve.exact_max_contacts,
            heavy_on_light_mass_ratio: s.solve.heavy_on_light_mass_ratio,
            restitution_threshold: s.contact.restitution_threshold,
            repair: s.contact.repair,
            overlap_slop: s.contact.overlap_slop,
            max_repair_speed: s.contact.max_repair_speed,
            warm_start: s.solve.warm_start,
            prediction_distance: s.contact.prediction_distance,
            split_overlap: s.contact.split_overlap,
            collision_steps: s.contact.collision_steps,
            recycle_distance: s.contact.recycle_distance,
            sleep: s.sleep.is_some(),
            sleep_linear_speed: sleep.linear_speed,
            sleep_angular_speed: sleep.angular_speed,
            time_to_sleep: sleep.time_to_sleep,
            friction: s.contact.friction,
            friction_in_main_solve: s.solve.friction_in_main_solve,
            direct_joint_solve: s.solve.direct_joint_solve,
            parallel_island_contacts: s.solve.parallel_island_contacts,
            simd_island_contacts: s.solve.simd_island_contacts,
            fused_multiply_add: s.solve.fused_multiply_add,
            gyroscopic: s.gyroscopic,
            continuous: s.continuous,
            impact: s.contact.impact,
            friction_combine: s.contact.friction_combine,
            restitution_combine: s.contact.restitution_combine,
            max_distance: s.limits.max_distance,
            max_linear_speed: s.limits.max_linear_speed,
            max_angular_speed: s.limits.max_angular_speed,
        }
    }
}

impl From<SettingsFile> for SolverSettings {
    fn from(f: SettingsFile) -> Self {
        let auto = (
            f.escalation_tolerance,
            f.escalation_iterations,
            f.mass_ratio_threshold,
        );
        let sleep = SleepSettings {
            linear_speed: f.sleep_linear_speed,
            angular_speed: f.sleep_angular_speed,
            time_to_sleep: f.time_to_sleep,
        };
        let defaults = OffParameters::default();
        SolverSettings {
            solve: SolveSettings {
                method: match f.method {
                    MethodName::Pgs => SolverMethod::Pgs,
                    MethodName::Nncg => SolverMethod::Nncg,
                    MethodName::Apgd => SolverMethod::Apgd,
                    MethodName::Auto => SolverMethod::Auto {
                        escalation_tolerance: auto.0,
                        escalation_iterations: auto.1,
                        mass_ratio_threshold: auto.2,
                    },
                },
                substeps: f.substeps,
                iterations: f.iterations,
                relax_iterations: f.relax_iterations,
                impact_sweeps: f.impact_sweeps,
                tolerance: f.tolerance,
                exact_max_contacts: f.exact_max_contacts,
                heavy_on_light_mass_ratio: f.heavy_on_light_mass_ratio,
                warm_start: f.warm_start,
                friction_in_main_solve: f.friction_in_main_solve,
                direct_joint_solve: f.direct_joint_solve,
                parallel_island_contacts: f.parallel_island_contacts,
                simd_island_contacts: f.simd_island_contacts,
                fused_multiply_add: f.fused_multiply_add,
            },
            contact: ContactSettings {
                restitution_threshold: f.restitution_threshold,
                repair: f.repair,
                overlap_slop: f.overlap_slop,
                max_repair_speed: f.max_repair_speed,
                prediction_distance: f.prediction_distance,
                split_overlap: f.split_overlap,
                collision_steps: f.collision_steps,
                recycle_distance: f.recycle_distance,
                friction: f.friction,
                impact: f.impact,
                friction_combine: f.friction_combine,
                restitution_combine: f.restitution_combine,
            },
            sleep: f.sleep.then_some(sleep),
            limits: WorldLimits {
                max_distance: f.max_distance,
                max_linear_speed: f.max_linear_speed,
                max_angular_speed: f.max_angular_speed,
            },
            gyroscopic: f.gyroscopic,
            continuous: f.continuous,
            off: OffParameters {
                auto: match f.method {
                    MethodName::Auto => defaults.auto,
                    _ => auto,
                },
                sleep: if f.sleep { defaults.sleep } else { sleep },
            },
        }
    }
}
