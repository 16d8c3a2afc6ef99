//! The settings as scene files and snapshots hold them: one flat `solver` object
//! (docs/scene-format.md), `auto`'s parameters beside `method`. [`SolverSettings`] reads and
//! writes itself through [`SettingsFile`], so the format stays as it was when the Rust type
//! was given its variant parameters; a field missing from a file takes its default.

use serde::{Deserialize, Serialize};

use super::{CombineRule, ContactRepair, ImpactModel, SolverMethod, SolverSettings};

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
/// [`SolverSettings`] documents it. `auto`'s three parameters are read whatever the method
/// (other methods ignore them) and written as the method's, or `auto`'s defaults.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
struct SettingsFile {
    method: MethodName,
    substeps: u32,
    iterations: u32,
    relax_iterations: u32,
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
            s.method.auto_parameters();
        SettingsFile {
            method: match s.method {
                SolverMethod::Pgs => MethodName::Pgs,
                SolverMethod::Nncg => MethodName::Nncg,
                SolverMethod::Apgd => MethodName::Apgd,
                SolverMethod::Auto { .. } => MethodName::Auto,
            },
            substeps: s.substeps,
            iterations: s.iterations,
            relax_iterations: s.relax_iterations,
            tolerance: s.tolerance,
            escalation_tolerance,
            escalation_iterations,
            mass_ratio_threshold,
            exact_max_contacts: s.exact_max_contacts,
            heavy_on_light_mass_ratio: s.heavy_on_light_mass_ratio,
            restitution_threshold: s.restitution_threshold,
            repair: s.repair,
            overlap_slop: s.overlap_slop,
            max_repair_speed: s.max_repair_speed,
            warm_start: s.warm_start,
            prediction_distance: s.prediction_distance,
            sleep: s.sleep,
            sleep_linear_speed: s.sleep_linear_speed,
            sleep_angular_speed: s.sleep_angular_speed,
            time_to_sleep: s.time_to_sleep,
            friction: s.friction,
            friction_in_main_solve: s.friction_in_main_solve,
            direct_joint_solve: s.direct_joint_solve,
            parallel_island_contacts: s.parallel_island_contacts,
            simd_island_contacts: s.simd_island_contacts,
            fused_multiply_add: s.fused_multiply_add,
            gyroscopic: s.gyroscopic,
            continuous: s.continuous,
            impact: s.impact,
            friction_combine: s.friction_combine,
            restitution_combine: s.restitution_combine,
            max_distance: s.max_distance,
            max_linear_speed: s.max_linear_speed,
            max_angular_speed: s.max_angular_speed,
        }
    }
}

impl From<SettingsFile> for SolverSettings {
    fn from(f: SettingsFile) -> Self {
        SolverSettings {
            method: match f.method {
                MethodName::Pgs => SolverMethod::Pgs,
                MethodName::Nncg => SolverMethod::Nncg,
                MethodName::Apgd => SolverMethod::Apgd,
                MethodName::Auto => SolverMethod::Auto {
                    escalation_tolerance: f.escalation_tolerance,
                    escalation_iterations: f.escalation_iterations,
                    mass_ratio_threshold: f.mass_ratio_threshold,
                },
            },
            substeps: f.substeps,
            iterations: f.iterations,
            relax_iterations: f.relax_iterations,
            tolerance: f.tolerance,
            exact_max_contacts: f.exact_max_contacts,
            heavy_on_light_mass_ratio: f.heavy_on_light_mass_ratio,
            restitution_threshold: f.restitution_threshold,
            repair: f.repair,
            overlap_slop: f.overlap_slop,
            max_repair_speed: f.max_repair_speed,
            warm_start: f.warm_start,
            prediction_distance: f.prediction_distance,
            sleep: f.sleep,
            sleep_linear_speed: f.sleep_linear_speed,
            sleep_angular_speed: f.sleep_angular_speed,
            time_to_sleep: f.time_to_sleep,
            friction: f.friction,
            friction_in_main_solve: f.friction_in_main_solve,
            direct_joint_solve: f.direct_joint_solve,
            parallel_island_contacts: f.parallel_island_contacts,
            simd_island_contacts: f.simd_island_contacts,
            fused_multiply_add: f.fused_multiply_add,
            gyroscopic: f.gyroscopic,
            continuous: f.continuous,
            impact: f.impact,
            friction_combine: f.friction_combine,
            restitution_combine: f.restitution_combine,
            max_distance: f.max_distance,
            max_linear_speed: f.max_linear_speed,
            max_angular_speed: f.max_angular_speed,
        }
    }
}
