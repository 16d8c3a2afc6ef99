//! `impulse run --profile`'s summary: the median of a run's step times, of each stage's and of
//! each solve phase's, so one slow step (a page fault, a busy machine) does not move it.

use impulse::report::{SolvePhase, Stage, StepProfile};

/// Each stage's and each solve phase's median over `profiles`.
pub fn median_profile(profiles: &[StepProfile]) -> StepProfile {
    let of = |time: &dyn Fn(&StepProfile) -> f32| {
        let mut times: Vec<f64> = profiles.iter().map(|p| time(p) as f64).collect();
        median(&mut times) as f32
    };
    let mut profile = StepProfile {
        total: of(&|p| p.total),
        ..StepProfile::default()
    };
    for stage in Stage::ALL {
        profile.set(stage, of(&|p| p.get(stage)));
    }
    for phase in SolvePhase::ALL {
        profile
            .solve_phases
            .set(phase, of(&|p| p.solve_phases.get(phase)));
    }
    profile
}

/// The median of `values` (sorted in place; 0 when empty).
pub fn median(values: &mut [f64]) -> f64 {
    if values.is_empty() {
        return 0.0;
    }
    values.sort_by(f64::total_cmp);
    let n = values.len();
    if n % 2 == 1 {
        values[n / 2]
    } else {
        0.5 * (values[n / 2 - 1] + values[n / 2])
    }
}
