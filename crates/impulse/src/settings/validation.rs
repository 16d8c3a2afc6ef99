//! The one check of solver settings: every field in its allowed range ([`SettingError`]).

use super::{ContactRepair, SolverMethod, SolverSettings};

/// A setting outside its allowed range: which field, and what is allowed. Displayed as
/// `solver.<field>: <message>` for a solver setting, `<field>: <message>` for the world's
/// `dt` and `gravity`.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{}{field}: {message}", if Self::WORLD_FIELDS.contains(field) { "" } else { "solver." })]
pub struct SettingError {
    /// The field's key in a scene file's `solver` object (its name in [`SolverSettings`]'s
    /// file format, e.g. `substeps` or `repair.hertz`), or one of [`Self::WORLD_FIELDS`].
    pub field: &'static str,
    /// What is wrong and what is allowed, with the value found (e.g. `must be ≥ 0, got -1`).
    pub message: String,
}

impl SettingError {
    /// The world's settings outside the solver's, top-level keys of a scene file: the time
    /// step `dt` (s) and `gravity` (m/s²).
    pub const WORLD_FIELDS: [&'static str; 2] = ["dt", "gravity"];
}

impl SolverSettings {
    /// Every setting outside its allowed range, in field order; empty when all are valid.
    /// The one check of solver settings: the scene loader reports each problem at its place in
    /// the file; [`crate::World::new`], [`crate::World::set_settings`] and the snapshot loader
    /// the first one (the step trusts settings that came through them). Counts
    /// (`iterations`, `substeps`, split impulse's `repair.iterations`, `escalation_iterations`,
    /// `collision_steps`)
    /// must be ≥ 1 and ≤ [`Self::MAX_COUNT`] (`relax_iterations` and `impact_sweeps` ≤ it, 0 allowed); a soft repair's `hertz` > 0;
    /// tolerances, thresholds, rates, speeds, distances, frequencies and times finite and ≥ 0;
    /// `warm_start` in [0, 1].
    pub fn problems(&self) -> Vec<SettingError> {
        let mut problems = Vec::new();
        let position_iterations = match self.contact.repair {
            ContactRepair::SplitImpulse { iterations, .. } => iterations,
            _ => 1,
        };
        let (escalation_tolerance, escalation_iterations, mass_ratio_threshold) =
            self.auto_parameters();
        let counts = [
            ("iterations", self.solve.iterations),
            ("substeps", self.solve.substeps),
            ("repair.iterations", position_iterations),
            ("escalation_iterations", escalation_iterations),
            ("collision_steps", self.contact.collision_steps),
        ];
        for (field, value) in counts {
            if value == 0 {
                problems.push(SettingError {
                    field,
                    message: "must be ≥ 1, got 0".to_string(),
                });
            } else if value > Self::MAX_COUNT {
                problems.push(SettingError {
                    field,
                    message: format!("must be ≤ {}, got {value}", Self::MAX_COUNT),
                });
            }
        }
        let may_be_zero = [
            ("relax_iterations", self.solve.relax_iterations),
            ("impact_sweeps", self.solve.impact_sweeps),
        ];
        for (field, value) in may_be_zero {
            if value > Self::MAX_COUNT {
                problems.push(SettingError {
                    field,
                    message: format!("must be ≤ {}, got {value}", Self::MAX_COUNT),
                });
            }
        }
        let (rate, damping_ratio) = match self.contact.repair {
            ContactRepair::Bias { rate } | ContactRepair::SplitImpulse { rate, .. } => (rate, 0.0),
            ContactRepair::Soft {
                hertz,
                damping_ratio,
            } => {
                if hertz.is_finite() && hertz <= 0.0 {
                    problems.push(SettingError {
                        field: "repair.hertz",
                        message: format!("must be > 0, got {hertz}"),
                    });
                }
                (hertz, damping_ratio)
            }
        };
        let rate_field = match self.contact.repair {
            ContactRepair::Soft { .. } => "repair.hertz",
            _ => "repair.rate",
        };
        let sleep = self.sleep_parameters();
        let non_negative = [
            ("tolerance", self.solve.tolerance),
            ("escalation_tolerance", escalation_tolerance),
            ("mass_ratio_threshold", mass_ratio_threshold),
            (
                "heavy_on_light_mass_ratio",
                self.solve.heavy_on_light_mass_ratio,
            ),
            (rate_field, rate),
            ("repair.damping_ratio", damping_ratio),
            ("sleep_linear_speed", sleep.linear_speed),
            ("sleep_angular_speed", sleep.angular_speed),
            ("time_to_sleep", sleep.time_to_sleep),
            ("restitution_threshold", self.contact.restitution_threshold),
            ("overlap_slop", self.contact.overlap_slop),
            ("max_repair_speed", self.contact.max_repair_speed),
            ("prediction_distance", self.contact.prediction_distance),
            ("split_overlap", self.contact.split_overlap),
            ("recycle_distance", self.contact.recycle_distance),
        ];
        for (field, value) in non_negative {
            let message = if !value.is_finite() {
                format!("must be finite, got {value}")
            } else if value < 0.0 {
                format!("must be ≥ 0, got {value}")
            } else {
                continue;
            };
            problems.push(SettingError { field, message });
        }
        // A soft repair's coefficients overflow f32 far beyond any substep rate (as a joint
        // spring's do, `joint::rules::MAX_SPRING`).
        for (field, value) in [(rate_field, rate), ("repair.damping_ratio", damping_ratio)] {
            if value.is_finite() && value > 1.0e6 {
                problems.push(SettingError {
                    field,
                    message: format!("must be at most 1e6, got {value:e}"),
                });
            }
        }
        if self.limits.max_distance.is_nan() || self.limits.max_distance <= 0.0 {
            problems.push(SettingError {
                field: "max_distance",
                message: format!("must be > 0, got {}", self.limits.max_distance),
            });
        }
        for (field, value) in [
            ("max_linear_speed", self.limits.max_linear_speed),
            ("max_angular_speed", self.limits.max_angular_speed),
        ] {
            if !(value.is_finite() && value > 0.0) {
                problems.push(SettingError {
                    field,
                    message: format!("must be finite and > 0, got {value}"),
                });
            }
        }
        let warm_start = self.solve.warm_start;
        if !warm_start.is_finite() {
            problems.push(SettingError {
                field: "warm_start",
                message: format!("must be finite, got {warm_start}"),
            });
        } else if !(0.0..=1.0).contains(&warm_start) {
            problems.push(SettingError {
                field: "warm_start",
                message: format!("must be in [0, 1], got {warm_start}"),
            });
        }
        problems
    }

    /// Whether overlap is repaired by split impulse.
    pub fn split_impulse(&self) -> bool {
        matches!(self.contact.repair, ContactRepair::SplitImpulse { .. })
    }

    /// Whether an island of `contacts` contact points is solved in SIMD lanes
    /// ([`crate::settings::SolveSettings::simd_island_contacts`]): PGS without split impulse, at or above the threshold.
    pub fn solves_in_lanes(&self, contacts: usize) -> bool {
        self.solve.method == SolverMethod::Pgs
            && !self.split_impulse()
            && self.solve.simd_island_contacts > 0
            && contacts >= self.solve.simd_island_contacts as usize
    }

    /// Largest allowed `substeps`, `iterations`, `relax_iterations`, `repair.iterations` and
    /// `escalation_iterations`: 10,000. The presets use at most 48 substeps and 16 sweeps; a
    /// count far beyond this is a typo, and 4,294,967,295 substeps would run for days per step.
    pub const MAX_COUNT: u32 = 10_000;

    /// The first of [`Self::problems`], if any.
    pub fn validate(&self) -> Result<(), SettingError> {
        match self.problems().into_iter().next() {
            Some(problem) => Err(problem),
            None => Ok(()),
        }
    }
}
