//! The solver options of `impulse run`: one clap `Args` group applied on top of a scene's (or a
//! preset's) `SolverSettings`.

use clap::builder::TypedValueParser;
use clap::{Args, ValueEnum};
use impulse::{ContactRepair, SolverMethod, SolverSettings};

/// A preset, named by speed or by the quality bar it meets on the standard scenes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum PresetArg {
    /// The soft step at 8 substeps without impact sweeps, contacts recycled within 2 cm: E ≤ 50 mm.
    #[value(alias = "q50")]
    Fast,
    /// The soft step at 20 substeps: E ≤ 5 mm.
    #[value(alias = "q5")]
    Default,
    /// The soft step at 48 substeps: E ≤ 1 mm.
    #[value(alias = "q1")]
    Precise,
    /// NNCG with split impulse and the exact path: the LCP solved tightly.
    Reference,
}

impl PresetArg {
    fn name(self) -> &'static str {
        match self {
            PresetArg::Fast => "fast",
            PresetArg::Default => "default",
            PresetArg::Precise => "precise",
            PresetArg::Reference => "reference",
        }
    }
}

/// `--method`: one of [`SolverMethod::ALL`] by its name, with `auto`'s parameters at their
/// defaults (the escalation options set them).
fn method_parser() -> impl TypedValueParser<Value = SolverMethod> {
    clap::builder::PossibleValuesParser::new(SolverMethod::ALL.map(SolverMethod::name))
        .try_map(|name| name.parse::<SolverMethod>())
}

/// How overlap is repaired.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum RepairArg {
    /// A velocity bias c_d·d, with relax.
    Bias,
    /// Split impulse: a separate position solve.
    Split,
    /// Soft contact springs, with relax.
    Soft,
}

/// Solver options; each one given overrides the scene's settings (or the preset's).
#[derive(Args, Debug, Default)]
pub struct SolverArgs {
    /// Start from a preset instead of the scene's solver settings, named by speed or by the
    /// quality bar it meets on the standard scenes (E = largest of sink, overlap and drift
    /// after 10 s): `fast`/`q50` (the soft step at 8 substeps without impact sweeps, contacts recycled within 2 cm, E ≤ 50 mm), `default`/`q5`
    /// (20 substeps, E ≤ 5 mm), `precise`/`q1` (48 substeps, E ≤ 1 mm) or `reference` (NNCG
    /// with split impulse and the exact path: the LCP solved tightly). A preset sets only
    /// the solver's effort (method, substeps, iterations, repair, contact recycling); the scene's physics
    /// (restitution threshold, sleeping, continuous collision, gyroscopic motion, friction)
    /// stay as the scene says. The other options apply on top of it.
    #[arg(long, alias = "quality", value_enum)]
    pub preset: Option<PresetArg>,
    /// Solver iterations per substep at most (≤ 10,000).
    #[arg(long)]
    pub iterations: Option<u32>,
    /// Substeps per step (≤ 10,000).
    #[arg(long)]
    pub substeps: Option<u32>,
    /// Relax iterations per substep (≤ 10,000).
    #[arg(long)]
    pub relax: Option<u32>,
    /// Sweeps an impact may add to a substep's solves, at most (≤ 10,000; default 32; 0 = no
    /// impact sweeps but in islands with joints: cheaper, and a face landing at restitution 0
    /// rises again at 7-9 % of its impact speed; see `SolveSettings::impact_sweeps`).
    #[arg(long)]
    pub impact_sweeps: Option<u32>,
    /// At most this many collision steps a step, each finding contacts again, where two
    /// dynamic bodies move farther than their thickness within it, eight times as many where
    /// one is thinner than 5 mm (1 = off; see `ContactSettings::collision_steps`).
    #[arg(long)]
    pub collision_steps: Option<u32>,
    /// Method of every island's solve: `pgs` (projected Gauss-Seidel), `nncg` (nonsmooth
    /// nonlinear conjugate gradient), `apgd` (accelerated projected gradient descent) or `auto`
    /// (NNCG escalating per island to more iterations or the exact path).
    #[arg(long, value_parser = method_parser())]
    pub method: Option<SolverMethod>,
    /// Early exit: a solve stops when no row's velocity changed by more than this in a sweep
    /// (m/s).
    #[arg(long)]
    pub tolerance: Option<f32>,
    /// Split impulse: position-solve sweeps per substep at most (with `--repair split` or
    /// settings that repair by split impulse).
    #[arg(long)]
    pub position_iterations: Option<u32>,
    /// Sweep islands of at least this many contact points colour by colour, one colour over
    /// all threads (0 = never). Islands, assembly and the per-body passes use the threads
    /// anyway; islands solved in SIMD lanes, as at every soft-step preset, are spread from
    /// 1024 points without this option. The result is the same on any thread count.
    #[arg(long)]
    pub parallel_island_contacts: Option<u32>,
    /// With `--method pgs` and bias or soft repair, solve islands of at least this many
    /// contact points four at a time in SIMD lanes (0 = never).
    #[arg(long)]
    pub simd_island_contacts: Option<u32>,
    /// `auto`: escalate an island whose last iteration changed a row velocity by more than
    /// this (m/s).
    #[arg(long)]
    pub escalation_tolerance: Option<f32>,
    /// `auto`: NNCG iterations per substep after an island escalates.
    #[arg(long)]
    pub escalation_iterations: Option<u32>,
    /// Solve islands of at most this many contact points exactly: `auto` when NNCG does not
    /// converge, and every method's heavy-on-light islands up to 4 times as many (0 = never).
    #[arg(long)]
    pub exact_max_contacts: Option<u32>,
    /// Overlap (m) left unrepaired, so resting rigid contacts do not jitter (the soft-step
    /// presets use 0).
    #[arg(long)]
    pub overlap_slop: Option<f32>,
    /// Sweep the friction rows in the soft step's main (repairing) solve too, not only in its
    /// relax solve (see `SolveSettings::friction_in_main_solve`).
    #[arg(long)]
    pub friction_in_main_solve: bool,
    /// Let the SIMD lanes' sweeps fuse multiplies and additions on CPUs that have FMA
    /// (x86-64-v3 and up): about a tenth less solve time, results that differ in their last
    /// bits from a CPU without FMA (off, every x86-64 CPU gives the same bits; see
    /// `SolveSettings::fused_multiply_add`).
    #[arg(long)]
    pub fused_multiply_add: bool,
    /// Soft contact frequency in Hz, > 0 (with `--repair soft` or settings that repair with
    /// soft springs).
    #[arg(long)]
    pub soft_hertz: Option<f32>,
    /// Fraction of last step's impulses to start from (0 = cold start, 1 = full warm start).
    #[arg(long)]
    pub warm_start: Option<f32>,
    /// Overlap repair rate c_d in 1/s (with `--repair bias|split` or settings that repair by
    /// a bias or split impulse).
    #[arg(long)]
    pub repair_rate: Option<f32>,
    /// Overlap repair: `soft` springs (30 Hz, ζ = 10 unless the settings already repair with
    /// springs or `--soft-hertz` says), a velocity `bias` or `split` impulse (the settings'
    /// rate, or 12/s, unless `--repair-rate` says; split impulse with 16 position sweeps unless
    /// `--position-iterations` says).
    #[arg(long, value_enum)]
    pub repair: Option<RepairArg>,
    /// Keep every body awake (no sleeping of quiet islands), as benchmarks do.
    #[arg(long)]
    pub no_sleep: bool,
}

impl SolverArgs {
    /// The settings these options make of `settings`: the preset's solver effort first
    /// ([`SolverSettings::with_effort_of`]: the scene keeps its physics, restitution threshold,
    /// sleeping, continuous collision, gyroscopic motion, friction and the impact model), then every
    /// option given.
    /// The world checks the values before its first step. Errors: a repair parameter given for
    /// a repair method that has none (`--soft-hertz` with a bias, say).
    pub fn apply(&self, settings: &SolverSettings) -> Result<SolverSettings, String> {
        let mut s = match self.preset {
            Some(preset) => {
                settings.with_effort_of(&SolverSettings::preset(preset.name()).unwrap_or_default())
            }
            None => settings.clone(),
        };
        let set = |field: &mut u32, value: Option<u32>| {
            if let Some(v) = value {
                *field = v;
            }
        };
        set(&mut s.solve.iterations, self.iterations);
        set(&mut s.solve.substeps, self.substeps);
        set(&mut s.solve.relax_iterations, self.relax);
        set(&mut s.solve.impact_sweeps, self.impact_sweeps);
        set(&mut s.contact.collision_steps, self.collision_steps);
        if let Some(fraction) = self.warm_start {
            s.solve.warm_start = fraction;
        }
        s.contact.repair = self.repair(s.contact.repair)?;
        if let Some(slop) = self.overlap_slop {
            s.contact.overlap_slop = slop;
        }
        if self.friction_in_main_solve {
            s.solve.friction_in_main_solve = true;
        }
        if self.fused_multiply_add {
            s.solve.fused_multiply_add = true;
        }
        if self.no_sleep {
            s.sleep = None;
        }
        if let Some(tolerance) = self.tolerance {
            s.solve.tolerance = tolerance;
        }
        set(
            &mut s.solve.parallel_island_contacts,
            self.parallel_island_contacts,
        );
        set(&mut s.solve.simd_island_contacts, self.simd_island_contacts);
        set(&mut s.solve.exact_max_contacts, self.exact_max_contacts);
        if let Some(method) = self.method {
            // `--method auto` on settings that already solve by `auto` keeps their parameters.
            if !(method.is_auto() && s.solve.method.is_auto()) {
                s.solve.method = method;
            }
        }
        s.solve.method = self.escalation(s.solve.method)?;
        Ok(s)
    }

    /// `method` with the escalation options applied. Errors: an escalation option given for
    /// a method other than `auto`.
    fn escalation(&self, method: SolverMethod) -> Result<SolverMethod, String> {
        let SolverMethod::Auto {
            mut escalation_tolerance,
            mut escalation_iterations,
            mass_ratio_threshold,
        } = method
        else {
            return match (self.escalation_tolerance, self.escalation_iterations) {
                (None, None) => Ok(method),
                _ => Err(format!(
                    "--escalation-tolerance and --escalation-iterations are parameters of method \
                     auto; these settings solve by {} (add --method auto)",
                    method.name()
                )),
            };
        };
        if let Some(tolerance) = self.escalation_tolerance {
            escalation_tolerance = tolerance;
        }
        if let Some(iterations) = self.escalation_iterations {
            escalation_iterations = iterations;
        }
        Ok(SolverMethod::Auto {
            escalation_tolerance,
            escalation_iterations,
            mass_ratio_threshold,
        })
    }

    /// `repair` with `--repair`, then the repair parameters, applied.
    fn repair(&self, repair: ContactRepair) -> Result<ContactRepair, String> {
        const RATE: f32 = 12.0;
        const POSITION_ITERATIONS: u32 = 16;
        const HERTZ: f32 = 30.0;
        const DAMPING_RATIO: f32 = 10.0;
        let rate = match repair {
            ContactRepair::Bias { rate } | ContactRepair::SplitImpulse { rate, .. } => rate,
            ContactRepair::Soft { .. } => RATE,
        };
        let mut repair = match self.repair {
            None => repair,
            Some(RepairArg::Bias) => ContactRepair::Bias { rate },
            Some(RepairArg::Split) => ContactRepair::SplitImpulse {
                rate,
                iterations: match repair {
                    ContactRepair::SplitImpulse { iterations, .. } => iterations,
                    _ => POSITION_ITERATIONS,
                },
            },
            Some(RepairArg::Soft) => match repair {
                ContactRepair::Soft { .. } => repair,
                _ => ContactRepair::Soft {
                    hertz: HERTZ,
                    damping_ratio: DAMPING_RATIO,
                },
            },
        };
        let method = repair.name();
        if let Some(new_rate) = self.repair_rate {
            match &mut repair {
                ContactRepair::Bias { rate } | ContactRepair::SplitImpulse { rate, .. } => {
                    *rate = new_rate;
                }
                ContactRepair::Soft { .. } => {
                    return Err(
                        "--repair-rate is the rate of bias or split-impulse repair; these \
                         settings repair with soft springs (add --repair bias or --repair split, \
                         or set --soft-hertz)"
                            .to_string(),
                    );
                }
            }
        }
        if let Some(new_hertz) = self.soft_hertz {
            match &mut repair {
                ContactRepair::Soft { hertz, .. } => *hertz = new_hertz,
                _ => {
                    return Err(format!(
                        "--soft-hertz is the frequency of soft repair; these settings repair \
                         by {method} (add --repair soft)"
                    ));
                }
            }
        }
        if let Some(sweeps) = self.position_iterations {
            match &mut repair {
                ContactRepair::SplitImpulse { iterations, .. } => *iterations = sweeps,
                _ => {
                    return Err(format!(
                        "--position-iterations is the budget of split-impulse repair; these \
                         settings repair by {method} (add --repair split)"
                    ));
                }
            }
        }
        Ok(repair)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_preset_then_the_options_on_top() {
        let args = SolverArgs {
            preset: Some(PresetArg::Fast),
            substeps: Some(3),
            repair: Some(RepairArg::Split),
            method: Some(SolverMethod::Nncg),
            no_sleep: true,
            ..SolverArgs::default()
        };
        let mut scene = SolverSettings::reference();
        scene.sleep = Some(impulse::settings::SleepSettings::default());
        let s = args.apply(&scene).unwrap();
        assert_eq!(s.solve.substeps, 3);
        assert_eq!(
            s.contact.repair,
            ContactRepair::SplitImpulse {
                rate: 12.0,
                iterations: 16
            }
        );
        assert_eq!(s.solve.method, SolverMethod::Nncg);
        assert_eq!(s.sleep, None);
        assert_eq!(
            s.solve.relax_iterations,
            SolverSettings::preset("fast")
                .unwrap()
                .solve
                .relax_iterations
        );
        // Without options the settings stay as they are.
        assert_eq!(SolverArgs::default().apply(&scene), Ok(scene));
    }

    /// `--fused-multiply-add` turns the setting on; a preset keeps the scene's choice (the
    /// machine's, not the solver's effort).
    #[test]
    fn fused_multiply_add_is_an_option_that_presets_keep() {
        let on = SolverArgs {
            fused_multiply_add: true,
            ..SolverArgs::default()
        };
        assert!(
            on.apply(&SolverSettings::default())
                .unwrap()
                .solve
                .fused_multiply_add
        );
        let scene = SolverSettings {
            solve: impulse::settings::SolveSettings {
                fused_multiply_add: true,
                ..SolverSettings::default().solve
            },
            ..SolverSettings::default()
        };
        let fast = SolverArgs {
            preset: Some(PresetArg::Fast),
            ..SolverArgs::default()
        };
        assert!(fast.apply(&scene).unwrap().solve.fused_multiply_add);
        assert!(
            !SolverArgs::default()
                .apply(&SolverSettings::default())
                .unwrap()
                .solve
                .fused_multiply_add
        );
    }

    #[test]
    fn repair_parameters_apply_to_their_method_only() {
        let soft = SolverSettings::default();
        let args = SolverArgs {
            soft_hertz: Some(60.0),
            ..SolverArgs::default()
        };
        assert_eq!(
            args.apply(&soft).unwrap().contact.repair,
            ContactRepair::Soft {
                hertz: 60.0,
                damping_ratio: 10.0
            }
        );
        let rate = SolverArgs {
            repair_rate: Some(5.0),
            ..SolverArgs::default()
        };
        assert!(rate.apply(&soft).unwrap_err().contains("--repair-rate"));
        let bias = SolverArgs {
            repair: Some(RepairArg::Bias),
            repair_rate: Some(5.0),
            ..SolverArgs::default()
        };
        assert_eq!(
            bias.apply(&soft).unwrap().contact.repair,
            ContactRepair::Bias { rate: 5.0 }
        );
        let sweeps = SolverArgs {
            position_iterations: Some(4),
            ..SolverArgs::default()
        };
        assert!(sweeps.apply(&soft).unwrap_err().contains("--repair split"));
    }

    /// `--method` takes the library's method names, `auto` with the escalation options as its
    /// parameters; an escalation option for another method is an error naming it.
    #[test]
    fn methods_are_the_librarys_and_escalation_options_are_autos() {
        use clap::Parser;
        #[derive(Parser)]
        struct Command {
            #[command(flatten)]
            solver: SolverArgs,
        }
        let parse = |args: &[&str]| {
            Command::try_parse_from(std::iter::once("impulse").chain(args.iter().copied()))
                .map(|command| command.solver)
        };
        for method in SolverMethod::ALL {
            let args = parse(&["--method", method.name()]).unwrap();
            let settings = args.apply(&SolverSettings::default()).unwrap();
            assert_eq!(settings.solve.method, method);
        }
        assert!(parse(&["--method", "lemke"]).is_err());
        let args = parse(&["--method", "auto", "--escalation-iterations", "9"]).unwrap();
        let SolverMethod::Auto {
            escalation_iterations,
            ..
        } = args.apply(&SolverSettings::default()).unwrap().solve.method
        else {
            panic!("not auto");
        };
        assert_eq!(escalation_iterations, 9);
        let error = parse(&["--escalation-tolerance", "0.1"])
            .unwrap()
            .apply(&SolverSettings::default())
            .unwrap_err();
        assert!(error.contains("--method auto"), "{error}");
    }
}
