//! Solver settings: every number the step pipeline uses that a user may want to tune.

use serde::{Deserialize, Serialize};

mod file;
mod validation;

pub use validation::SettingError;

/// The iterative method run on the contact rows. In scene files, `solver.method` names it
/// (`"pgs"`, `"nncg"`, `"apgd"`, `"auto"`) and `auto`'s parameters sit beside it in the `solver`
/// object (`escalation_tolerance`, `escalation_iterations`, `mass_ratio_threshold`).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub enum SolverMethod {
    /// Projected Gauss-Seidel, the basic method of docs/method.md (sweeps in alternating direction); the
    /// default, in the soft step ([`SolverSettings::soft_step`]).
    #[default]
    Pgs,
    /// Nonsmooth nonlinear conjugate gradient over PGS sweeps (Silcowitz et al. 2010).
    Nncg,
    /// Accelerated projected gradient descent with adaptive restart (Mazhar et al. 2015).
    Apgd,
    /// The automatic policy, per island and solve ([`SolverSettings::reference`]): NNCG within the iteration
    /// budget; an island whose last iteration still changed a row's velocity by more than
    /// `escalation_tolerance`, or whose mass ratio exceeds `mass_ratio_threshold`, escalates:
    /// to the exact path when it has at most [`SolveSettings::exact_max_contacts`] contact points (keeping the
    /// iterative result if pivoting fails), otherwise (only when unconverged) to
    /// `escalation_iterations` more NNCG iterations. An unconverged island that is not heavy
    /// but in an impact (a contact closing at the step's start faster than |g|·dt, the speed
    /// gravity gives in one step) takes the iterations, not the exact path: later steps repair
    /// what an impact leaves. Each island's choice is reported in the
    /// step diagnostics. It starts from NNCG rather than plain PGS because an NNCG iteration
    /// is a symmetric PGS sweep plus a momentum step, and on every standard scene it reached a
    /// given sink at less cost than PGS first (docs/solvers.md). [`SolverMethod::AUTO`] has the
    /// default parameters.
    Auto {
        /// An island escalates when the last iteration of its solve still changed some row's
        /// velocity by more than this (m/s), ≥ 0. Looser than
        /// [`SolveSettings::tolerance`], which only ends iterations early: a solve that
        /// stopped at its budget above it is not converged. Default 3·10⁻⁴.
        escalation_tolerance: f32,
        /// NNCG iterations an unconverged island gets beyond the budget, ≥ 1. Default 4.
        escalation_iterations: u32,
        /// Islands whose heaviest to lightest moving body mass ratio exceeds this escalate to
        /// the exact path even when the iterations look converged (iterative methods stall on
        /// heavy-on-light), ≥ 0. Default 10.
        mass_ratio_threshold: f32,
    },
}

impl SolverMethod {
    /// The automatic policy with its default parameters.
    pub const AUTO: SolverMethod = SolverMethod::Auto {
        escalation_tolerance: 3e-4,
        escalation_iterations: 4,
        mass_ratio_threshold: 10.0,
    };

    /// Every method, with default parameters, in the order the docs list them: what a
    /// command line or a scene file may name ([`Self::name`], [`str::parse`]).
    pub const ALL: [SolverMethod; 4] = [
        SolverMethod::Pgs,
        SolverMethod::Nncg,
        SolverMethod::Apgd,
        SolverMethod::AUTO,
    ];

    /// The name used in scene files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            SolverMethod::Pgs => "pgs",
            SolverMethod::Nncg => "nncg",
            SolverMethod::Apgd => "apgd",
            SolverMethod::Auto { .. } => "auto",
        }
    }

    /// Whether this is the automatic policy (with any parameters).
    pub fn is_auto(self) -> bool {
        matches!(self, SolverMethod::Auto { .. })
    }

    /// The automatic policy's parameters (escalation tolerance, escalation iterations, mass
    /// ratio threshold): this method's if it is `auto`, else [`Self::AUTO`]'s, which the
    /// heavy-on-light path and the scene writer use.
    pub fn auto_parameters(self) -> (f32, u32, f32) {
        match self {
            SolverMethod::Auto {
                escalation_tolerance,
                escalation_iterations,
                mass_ratio_threshold,
            } => (
                escalation_tolerance,
                escalation_iterations,
                mass_ratio_threshold,
            ),
            _ => SolverMethod::AUTO.auto_parameters(),
        }
    }
}

/// The method named `name` (one of [`SolverMethod::ALL`]'s names), `auto` with its default
/// parameters.
impl std::str::FromStr for SolverMethod {
    type Err = String;

    fn from_str(name: &str) -> Result<Self, String> {
        SolverMethod::ALL
            .into_iter()
            .find(|method| method.name() == name)
            .ok_or_else(|| {
                let names: Vec<_> = SolverMethod::ALL.iter().map(|m| m.name()).collect();
                format!("no method named '{name}'; methods: {}", names.join(", "))
            })
    }
}

/// How overlap is repaired: one of three methods, each with its own parameters (docs/method.md,
/// "Targets: restitution, gaps and repair"). In scene files, an object tagged by `type`:
/// `{"type": "soft", "hertz": 240, "damping_ratio": 10}`, `{"type": "bias", "rate": 12}` or
/// `{"type": "split_impulse", "rate": 12, "iterations": 16}`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum ContactRepair {
    /// Baumgarte stabilisation on rigid rows: an overlap d asks for a separating speed
    /// `rate`·max(d − slop, 0) (1/s), with a relax solve after position integration that
    /// removes it from the velocities (Box2D v3's relax; Baumgarte 1972).
    Bias {
        /// Repair rate c_d (1/s), ≥ 0.
        rate: f32,
    },
    /// Split impulse: the repair runs as a separate solve on pseudo-velocities that move
    /// positions and are then discarded, so repair never becomes kinetic energy (Catto 2006,
    /// Bullet's split impulse). The velocity rows stay rigid (target 0 when touching).
    SplitImpulse {
        /// Repair rate c_d (1/s) of the position solve, ≥ 0.
        rate: f32,
        /// PGS sweeps of the position solve per substep, at most (early exit at the
        /// tolerance), ≥ 1. A deep overlap in a tall pile is a chain the repair has to carry
        /// through, so this budget is separate from (and larger than) the velocity solve's.
        iterations: u32,
    },
    /// Soft contacts: each penetrating row is a damped spring of frequency `hertz` (capped at
    /// a fifth of the substep rate) and damping ratio `damping_ratio`, discretised implicitly
    /// over a substep (Box2D v3's soft step; Catto 2024).
    Soft {
        /// Spring frequency (Hz), > 0.
        hertz: f32,
        /// Damping ratio ζ (dimensionless), ≥ 0; Box2D v3 uses 10.
        damping_ratio: f32,
    },
}

impl ContactRepair {
    /// The name used on the command line and in scene files' `type`.
    pub fn name(self) -> &'static str {
        match self {
            ContactRepair::Bias { .. } => "bias",
            ContactRepair::SplitImpulse { .. } => "split_impulse",
            ContactRepair::Soft { .. } => "soft",
        }
    }
}

/// How the restitution of a step's impacts is resolved when several contacts collide at once
/// (docs/method.md, "Simultaneous impacts"). In scene files, `solver.impact`: `"simultaneous"`
/// (the default) or `"propagation"`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum ImpactModel {
    /// Newton's hypothesis v⁺ = −c_r·v⁻ on every colliding point together, in one LCP solve
    /// after the substeps: the method's restitution. Touching bodies that did not approach
    /// keep target 0, so a struck row of touching balls moves off together rather than
    /// passing the impact on (Newton's cradle does not give 1 in → 1 out).
    #[default]
    Simultaneous,
    /// Generalized reflections (Smith, Kaufman, Vouga, Tamstorf and Grinspun, "Reflections on
    /// simultaneous impact", SIGGRAPH 2012): from the velocities before the step, the
    /// contacts that approach are projected to rest together and reflected by 1 + c_r; the
    /// contacts this leaves approaching are treated the same way, round after round, until
    /// none approaches, so an impact travels through touching bodies as a sequence of
    /// collisions (`solver::impact`). Newton's cradle gives 1 in → 1 out, kinetic energy and
    /// momentum are kept at c_r = 1, and symmetric impacts stay symmetric.
    Propagation,
}

impl ImpactModel {
    /// The name used in scene files.
    pub fn name(self) -> &'static str {
        match self {
            ImpactModel::Simultaneous => "simultaneous",
            ImpactModel::Propagation => "propagation",
        }
    }
}

/// How a contact's friction or restitution coefficient is made from the two bodies' own
/// (`solver.friction_combine`, `solver.restitution_combine` in scene files). impulse's
/// defaults are Box2D v3's and Jolt's: the geometric mean √(μa·μb) for friction and the larger
/// restitution. Blender's rigid bodies (Bullet, `btManifoldResult`) multiply both; Rapier's
/// `CoefficientCombineRule` offers the average, the minimum, the product and the maximum.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CombineRule {
    /// √(a·b): friction's default. Zero when either is zero.
    GeometricMean,
    /// (a + b) / 2.
    Average,
    /// The smaller of the two.
    Min,
    /// The larger of the two: restitution's default (a bouncy ball bounces on any floor).
    Max,
    /// a·b: Blender's (Bullet's) rule for both coefficients.
    Multiply,
}

impl CombineRule {
    /// The pair's coefficient from the two bodies' coefficients `a` and `b` (each ≥ 0 and
    /// finite, as scenes are validated; restitutions in [0, 1] stay in [0, 1] under every
    /// rule).
    #[inline]
    pub fn combine(self, a: f32, b: f32) -> f32 {
        match self {
            CombineRule::GeometricMean => (a * b).sqrt(),
            CombineRule::Average => 0.5 * (a + b),
            CombineRule::Min => a.min(b),
            CombineRule::Max => a.max(b),
            CombineRule::Multiply => a * b,
        }
    }

    /// The name used in scene files.
    pub fn name(self) -> &'static str {
        match self {
            CombineRule::GeometricMean => "geometric_mean",
            CombineRule::Average => "average",
            CombineRule::Min => "min",
            CombineRule::Max => "max",
            CombineRule::Multiply => "multiply",
        }
    }
}

/// How hard and how the LCP is solved: the method, its budgets, the exact and heavy-on-light
/// paths, warm starting and how an island's rows are swept ([`SolverSettings::solve`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolveSettings {
    /// Method: `pgs`, `nncg`, `apgd`, or `auto` (the escalation policy, with its parameters).
    pub method: SolverMethod,
    /// Substeps per step. Contacts are found once per step; each substep of h = dt/substeps
    /// applies gravity, solves, and integrates positions, with each contact's separation
    /// updated from the bodies' motion (as Box2D v3's soft step and Rapier's TGS do). Shorter
    /// solves propagate load through a tall stack far better than more sweeps of one long
    /// solve. Must be ≥ 1; 1 is the basic method's one solve per step.
    pub substeps: u32,
    /// Projected Gauss-Seidel sweeps per substep, at most (with overlap repair). Must be ≥ 1.
    pub iterations: u32,
    /// Relax sweeps per substep after position integration, with the overlap repair removed
    /// from the targets: positions move with the repair velocity, but the velocities carried
    /// on do not keep it, so repair adds no kinetic energy (Box2D v3's "relax" stage).
    /// 0 keeps the plain velocity bias.
    pub relax_iterations: u32,
    /// Early exit: stop sweeping once no row's velocity changed by more than this in a sweep
    /// (m/s), i.e. max |Δγ_i|/m_eff,i ≤ tolerance. 0 disables early exit.
    pub tolerance: f32,
    /// Sweeps an impact may add to a substep's main solve and to its relax solve, at most
    /// (default [`DEFAULT_IMPACT_SWEEPS`]; PGS with soft or bias repair): in an island where
    /// some contact closes faster than the impact speed, max(|g|·dt, `restitution_threshold`),
    /// a substep whose last sweep still changed some row's velocity by more than that speed
    /// sweeps on towards convergence, so a face that lands on its corners at restitution 0
    /// stops dead instead of leaving spinning (docs/method.md, "Impacts"). 0 takes no impact
    /// sweeps: each substep keeps its `iterations` and `relax_iterations`, a cube dropped flat
    /// at restitution 0 rises again at 7-9 % of its impact speed, and a pour costs a fifth to
    /// a third less (docs/method.md, "Impacts"). An island with joints sweeps on as by default
    /// whatever this says: its impacts are told by the last sweep alone, and without the sweeps
    /// a ragdoll pile's limbs sank three times as deep into one another.
    pub impact_sweeps: u32,
    /// Islands with at most this many contact points may take the exact path: `auto`'s
    /// escalation ([`SolverMethod::Auto`]), and, times
    /// [`crate::HEAVY_ON_LIGHT_CONTACTS_FACTOR`], the heavy-on-light path of every method
    /// (0 = never).
    pub exact_max_contacts: u32,
    /// Methods other than `auto`: an island in which some contact joins two moving bodies
    /// whose masses differ by more than this factor (heavy on light), and which has at most
    /// [`crate::HEAVY_ON_LIGHT_CONTACTS_FACTOR`] × `exact_max_contacts` points, is stepped as one LCP per step on rigid rows (velocity bias
    /// at 12/s, relax solve after), solved exactly (Lemke, [`SolverMethod::Auto`]'s exact path),
    /// instead of in substeps. The soft step cannot hold such an island: a soft row's spring is
    /// as stiff as its effective mass, which is the light body's, so under a load R times the
    /// light body's weight it sinks R·g/ω², and Gauss-Seidel moves the load from the heavy
    /// body to the light one at a rate of about 1/R per sweep (docs/solvers.md, "Heavy on
    /// light"). 0 = never; every other island takes the ordinary path unchanged.
    pub heavy_on_light_mass_ratio: f32,
    /// Fraction of last step's impulses used as this step's starting guess (0 = cold start).
    /// Impulses are matched by Parry's contact feature ids.
    pub warm_start: f32,
    /// Solve the friction rows in the main (repairing) solve as well as in the relax solve.
    /// When false (the default), `pgs` with a relax solve (soft or bias repair, not split
    /// impulse) sweeps only the normal rows while it repairs overlap, and the friction rows
    /// with the normal rows in the relax solve, where the targets carry no repair: friction
    /// then never works against the repair velocity, which in a pile otherwise pushes the
    /// lower bodies sideways and spreads the pile (Rapier's `friction_in_bias_pass`, off by
    /// default, makes the same choice). The friction impulses are applied throughout (warm
    /// start). Other methods, split impulse, and solves without a relax solve always sweep
    /// friction with the normal rows ([`SolverSettings::main_solve_friction`]), and so do islands whose
    /// heaviest body is at least 200 times their lightest, where one friction sweep a substep
    /// converges too slowly (docs/solvers.md, "The soft step").
    pub friction_in_main_solve: bool,
    /// Solve an island's locked joint rows together, by a sparse Cholesky factorization of
    /// their K at each new pose (default), rather than one joint's locked group after another
    /// in each sweep. Together, a chain holds whatever its mass ratio (one joint after another
    /// passes a load on by one link a sweep, and a heavy end stretches the chain); apart costs
    /// less on joints that Gauss-Seidel already holds (ragdolls, bridges of equal planks).
    /// docs/method.md "Joints"; its cost in docs/benchmarks.md "chain20heavy".
    pub direct_joint_solve: bool,
    /// Islands with at least this many contact points are swept colour by colour (greedy graph
    /// colouring: no two points of a colour share a moving body), one colour's points spread
    /// over all worker threads; 0 = never (default). Colour order converges more slowly than
    /// narrow-phase order on piles and costs more on one thread; it pays on several threads
    /// (docs/benchmarks.md, "Threads"). Results do not depend on the thread count.
    /// Islands solved in SIMD lanes (`simd_island_contacts`) are always in colour order and
    /// spread each large colour over the threads whatever this says.
    pub parallel_island_contacts: u32,
    /// With `method: pgs` and without split impulse, islands with at least this many contact
    /// points are solved in SIMD lanes (docs/solvers.md): manifold groups (a pair's points)
    /// coloured greedily, four groups of a colour updated at once, each lane taking its group's
    /// points in turn. 0 = never. Default 16; smaller islands do not repay the packing. An
    /// island of fewer than 64 points with a polyhedral body turning more than 0.4 rad in the
    /// step stays on the scalar path, whose rows follow the turn (docs/method.md, "Rows that
    /// follow a turn"). Colour order converges a little more slowly than narrow-phase order. In islands of at least
    /// 8192 points, a colour of more than 8 lane groups is spread over the worker threads (the
    /// same result on any thread count).
    pub simd_island_contacts: u32,
    /// Let the SIMD lanes' sweeps fuse each multiply with the addition that follows it (one
    /// rounding instead of two: `vfmadd`) in the dot products J·v and the velocity updates
    /// M⁻¹Jᵀλ, on CPUs whose lanes' kernels have FMA (x86-64-v3 and x86-64-v4; not with the
    /// `lanes8` feature). About a tenth less solve time on the standard scenes
    /// (docs/benchmarks.md, "Fused multiply-adds"). Off by default: the kernels then give the
    /// same bits on every x86-64 CPU (and with `IMPULSE_INSTRUCTION_SET=baseline`); on, a
    /// trajectory differs in its last bits between a CPU with FMA and one without (which
    /// rounds twice as before), as Jolt's results do unless built for cross-platform
    /// determinism (`CROSS_PLATFORM_DETERMINISTIC`). Runs on one machine stay repeatable, on
    /// any thread count. The scalar solvers, the products and the step's record round twice
    /// either way.
    pub fused_multiply_add: bool,
}

/// How contacts are made and what they mean: restitution, overlap repair, speculative
/// contacts, friction, the impact model and how two bodies' coefficients combine
/// ([`SolverSettings::contact`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactSettings {
    /// Restitution hypothesis v⁺ = −c_r·v⁻ is applied only when the contact approaches faster
    /// than this (m/s), so resting contacts do not bounce (docs/method.md, "Targets: restitution, gaps and repair").
    pub restitution_threshold: f32,
    /// How overlap is repaired: soft contact springs (the default), a velocity bias, or
    /// split impulse ([`ContactRepair`]).
    pub repair: ContactRepair,
    /// Overlap (m) tolerated without repair, so resting contacts do not jitter.
    pub overlap_slop: f32,
    /// Cap (m/s) on the repair speed, so deep overlaps separate without an explosion.
    pub max_repair_speed: f32,
    /// Contacts are generated up to this separation (m) ahead of touching ("speculative"
    /// contacts), plus how far the pair can close in the step: a row with gap g > 0 only
    /// forbids closing faster than g/dt. For steps of 1/60 s or longer; a shorter step takes
    /// it in proportion to its dt (at 240 Hz a quarter), as the reach of a velocity change
    /// within the step is (docs/method.md, "Speculative contacts").
    pub prediction_distance: f32,
    /// A step after which two bodies that moved against each other overlap by more than this
    /// (m), and by more than a third of it beyond their overlap at the step's start, is taken
    /// again as two half steps, each with its own contacts, and so on up to
    /// [`MAX_STEP_SPLITS`] halvings (docs/method.md, "Split steps"): contacts found once a
    /// step go stale where bodies turn or stop within it (thin parts crossing, a pile
    /// stopping one of two bodies falling together). 0 turns it off (the default).
    pub split_overlap: f32,
    /// At most how many collision steps a step is taken in, each with its own contacts, where
    /// two dynamic bodies move far against their thickness within it: the step is taken in
    /// the fewest equal pieces, a power of two, in which no contact pair of two dynamic
    /// bodies moves by more than [`COLLISION_STEP_REACH`] times the thinner body's thickness
    /// (its local bounding box's smallest half extent; the motion is one body's points' in the
    /// other's frame, bounded from the velocities at the step's start), the substeps shared
    /// among the pieces (rounded up), so the solver's work is the same (docs/method.md,
    /// "Collision steps"; Jolt's `collisionSteps`, taken only where needed). A pair with a
    /// body thinner than [`THIN_BODY_THICKNESS`] (a card) may take
    /// [`THIN_COLLISION_STEP_FACTOR`] times as many. Default [`DEFAULT_COLLISION_STEPS`]; 1
    /// turns it off.
    pub collision_steps: u32,
    /// How far (m) the bodies of a pair of flat shapes (boxes, convex hulls, half-spaces and
    /// compounds of boxes and hulls) may move relative to each other, and its speculative
    /// distance grow, before its contacts are found again: until then the last computation's
    /// points stand, each a point of each body, and only their separations are updated
    /// (docs/method.md, "Contact recycling"). A compound's pair is found again after at most a
    /// twentieth of its smallest part's half-diagonal, whatever this says. A
    /// recycled point is at most this much (plus Parry's 1 mm and 1° of reuse) from where a
    /// full computation would put it. Default [`DEFAULT_RECYCLE_DISTANCE`]; the `fast` preset
    /// takes [`FAST_RECYCLE_DISTANCE`]; Rapier recycles up to 5 cm by default
    /// (`IntegrationParameters::contact_recycling`). 0 finds every moving pair's contacts
    /// every step.
    pub recycle_distance: f32,
    /// Apply Coulomb friction rows (two tangents per point, |γ_t| ≤ μ·γ_n).
    pub friction: bool,
    /// How simultaneous impacts are resolved: `simultaneous` (one LCP with Newton's
    /// restitution, the default) or `propagation` (generalized reflections). A physical
    /// choice of the scene, like the restitution coefficients ([`ImpactModel`]).
    pub impact: ImpactModel,
    /// How a contact's friction coefficient is made from its two bodies' ([`CombineRule`];
    /// default the geometric mean). A physical choice of the scene, which presets keep.
    pub friction_combine: CombineRule,
    /// How a contact's restitution is made from its two bodies' ([`CombineRule`]; default the
    /// larger). A physical choice of the scene, which presets keep.
    pub restitution_combine: CombineRule,
}

/// When quiet islands sleep ([`SolverSettings::sleep`]; `None` keeps every body awake).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SleepSettings {
    /// A body slower than this (m/s) …
    pub linear_speed: f32,
    /// … and spinning slower than this (rad/s) counts as quiet.
    pub angular_speed: f32,
    /// An island sleeps when all its bodies have been quiet this long (s).
    pub time_to_sleep: f32,
}

/// The world's bounds: where a moving body leaves the world, and which speeds are a blow-up
/// ([`SolverSettings::limits`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WorldLimits {
    /// World bound (m): a moving body whose centre of mass ends a step farther than this from
    /// the origin leaves the simulation ([`crate::World::left_world`]): it is frozen where it
    /// is and the run goes on. Default 10⁵ m ([`crate::settings::BLOW_UP_DISTANCE`]); must be > 0.
    pub max_distance: f32,
    /// Largest speed of a body's centre of mass (m/s): a body faster than this at a step's end
    /// is a blow-up ([`crate::StepError::BlowUp`]), and a body given a faster initial velocity
    /// is refused. Default 10⁵ m/s ([`DEFAULT_MAX_LINEAR_SPEED`]); must be finite and > 0.
    pub max_linear_speed: f32,
    /// Largest angular speed of a body (rad/s): a body spinning faster than this at a step's
    /// end is a blow-up ([`crate::StepError::BlowUp`]), and a body given a faster initial spin
    /// is refused. Default 10⁷ rad/s ([`DEFAULT_MAX_ANGULAR_SPEED`]); must be finite and > 0.
    pub max_angular_speed: f32,
}

/// Settings of the step: the solve, the contacts, sleeping, the world's limits, and two
/// switches of the bodies' motion.
///
/// Defaults are chosen for the standard scenes at dt = 1/60 s. Units are SI.
/// Each term is explained in docs/method.md with its source.
///
/// Scene files and snapshots hold them as one flat `solver` object (docs/scene-format.md),
/// each group's fields under their own names (the sleep group's as `sleep_linear_speed`,
/// `sleep_angular_speed`, `time_to_sleep`, with `sleep: false` for `None`).
#[derive(Clone, Debug, PartialEq)]
pub struct SolverSettings {
    /// How hard and how the LCP is solved ([`SolveSettings`]).
    pub solve: SolveSettings,
    /// How contacts are made and resolved ([`ContactSettings`]).
    pub contact: ContactSettings,
    /// Let quiet islands sleep (the finish stage, docs/architecture.md), when they have been
    /// quiet as [`SleepSettings`] says; `None` keeps every body awake, as benchmarks do.
    pub sleep: Option<SleepSettings>,
    /// Where a body leaves the world and which speeds are a blow-up ([`WorldLimits`]).
    pub limits: WorldLimits,
    /// Integrate the gyroscopic term ω × I·ω of rigid bodies, implicitly, once per substep
    /// (`integrate::gyroscopic`), so that a free body keeps its world angular momentum
    /// and a body spun near its intermediate axis tumbles (docs/method.md, "Gyroscopic
    /// motion"). Off keeps ω constant in the world frame between contacts.
    pub gyroscopic: bool,
    /// Continuous collision (motion clamping): a dynamic body that
    /// moved more than half its smallest half extent in a step is swept from its pose at the
    /// step's start to its pose at the end against the static and kinematic bodies (Parry's
    /// nonlinear shape cast), and put back to the first impact, its velocity kept for the
    /// next step's contacts (Rapier's CCD against fixed colliders, Box2D v3's continuous
    /// collision). Fast bodies then never pass through a thin wall, whatever their speed. On
    /// by default; the cost without fast bodies is a pass over the bodies' poses.
    pub continuous: bool,
    /// The parameters of options that are off ([`OffParameters`]), kept so that every key of
    /// a file's `solver` object reads and writes back whatever the method; the step never
    /// reads them.
    pub off: OffParameters,
}

/// Parameters a file gave for options that are off, kept only so that a scene or snapshot
/// read and written keeps them (docs/scene-format.md): `auto`'s when
/// [`SolveSettings::method`] is another method, the sleep group's when
/// [`SolverSettings::sleep`] is `None`. Each is the default while its option is on, so two
/// settings that run the same and came from the same file compare equal. Validated as if the
/// option were on ([`SolverSettings::problems`]), since switching it on in the file uses them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OffParameters {
    /// `auto`'s (escalation tolerance, escalation iterations, mass ratio threshold) as
    /// [`SolverMethod::Auto`] documents them, while the method is not `auto`.
    pub auto: (f32, u32, f32),
    /// The sleep parameters while [`SolverSettings::sleep`] is `None`.
    pub sleep: SleepSettings,
}

/// `auto`'s defaults ([`SolverMethod::AUTO`]) and [`SleepSettings::default`].
impl Default for OffParameters {
    fn default() -> Self {
        Self {
            auto: SolverMethod::AUTO.auto_parameters(),
            sleep: SleepSettings::default(),
        }
    }
}

/// The default world bound (m), [`WorldLimits::max_distance`]: a moving body farther than
/// this from the origin leaves the world ([`crate::LeftWorld`]); the run goes on. A non-finite
/// position is a blow-up.
pub const BLOW_UP_DISTANCE: f32 = 1.0e5;

/// The default [`SolveSettings::impact_sweeps`]: enough for the corners of a face landing at
/// speed to share the blow (docs/method.md, "Impacts").
pub const DEFAULT_IMPACT_SWEEPS: u32 = 32;

/// [`ContactSettings::recycle_distance`] of the default and `precise` presets (m): Parry's own
/// tolerance for reusing a manifold.
pub const DEFAULT_RECYCLE_DISTANCE: f32 = 1.0e-3;

/// [`ContactSettings::recycle_distance`] of the `fast` preset (m): in a pour most pairs move
/// more than a millimetre a step, and recycling them up to 2 cm takes a tenth to an eighth off
/// `fast`'s step on the cube pours, their largest overlaps within the seeds' spread on pour500
/// and pour2000 (docs/method.md, "Contact recycling", which gives pour8000's too); a kept
/// point is at most 2 cm off, within the 50 mm of `fast`'s quality bar.
pub const FAST_RECYCLE_DISTANCE: f32 = 0.02;

/// How many times a step may be halved ([`ContactSettings::split_overlap`]): into at most
/// 2² = 4 pieces, so a split step costs at most the three tries and four pieces' work.
pub const MAX_STEP_SPLITS: u32 = 2;

/// How far two dynamic bodies may move against each other within a collision step
/// ([`ContactSettings::collision_steps`]), as a fraction of the thinner one's thickness. At 1,
/// a bowling ball at 7.5 m/s (12.5 cm a step at 1/60 s) against a pin 6 cm thick takes four
/// collision steps, a unit cube landing at 17 m/s on another none (docs/method.md, "Collision
/// steps").
pub const COLLISION_STEP_REACH: f32 = 1.0;

/// How many times [`ContactSettings::collision_steps`] a step may be taken in where a pair
/// of two dynamic bodies has one thinner than [`THIN_BODY_THICKNESS`]: a card spinning off an
/// impact at 50 rad/s moves its corners 4 cm a step at 1/60 s against its 2 mm, and within
/// four collision steps its contacts go stale enough to let two cards cross by up to 4.2 mm;
/// within 32 by at most 0.86 mm (forty cards into a box, seeds 0-39; docs/testing.md, "Thin
/// shapes"). Only such pairs take more pieces, and only while they move that fast.
pub const THIN_COLLISION_STEP_FACTOR: u32 = 8;

/// A body whose local bounding box is thinner than this (m) in some direction is thin for
/// [`THIN_COLLISION_STEP_FACTOR`]: a flat shape's slab ([`crate::scene::DEFAULT_THICKNESS`]
/// is 2 mm), a sheet or a playing card; a mug, whose walls are thin but whose bounding box is
/// not, is not.
pub const THIN_BODY_THICKNESS: f32 = 0.005;

/// At most how many collision steps a step is taken in by default
/// ([`ContactSettings::collision_steps`], every preset): at 60 fps a fast pair's contacts
/// are found again every 1/240 s, the rate at which the 500-mug pour, a bowling ball among
/// pins and the ragdolls of a pile stay right (docs/method.md, "Collision steps"). Steps in
/// which nothing moves far against its thickness are taken whole and cost nothing more.
pub const DEFAULT_COLLISION_STEPS: u32 = 4;

/// The default [`WorldLimits::max_linear_speed`] (m/s): 100 km/s, beyond anything that
/// moves in a contact simulation (a rifle bullet flies at about 1 km/s, a light-gas gun's
/// projectile at 7 km/s, the fastest meteoroid meets the Earth at 72 km/s). A speed a step
/// cannot reach by physics is left to the energy check ([`crate::BLOW_UP_ENERGY_PER_KG`]);
/// this bound only catches a state that is finite but meaningless.
pub const DEFAULT_MAX_LINEAR_SPEED: f32 = 1.0e5;

/// The default [`WorldLimits::max_angular_speed`] (rad/s): 10⁷ rad/s, the spin of a 1 cm
/// ball rolling at [`DEFAULT_MAX_LINEAR_SPEED`], and 500 times a rifle bullet's
/// (18,850 rad/s). A small body that grazes the ground fast spins up to v/r (a 2 cm ball at
/// 700 m/s: 70,000 rad/s), which is physics, not a blow-up.
pub const DEFAULT_MAX_ANGULAR_SPEED: f32 = 1.0e7;

/// Most pairs of overlapping bounding boxes a start may have, per body: 32. Bodies that do not
/// overlap meet few boxes each: a box among equal boxes packed face to face touches 26, and a
/// large body (the ground) under many small ones adds one pair per small body; piles that
/// overlap by a fraction of a body (`overlap_pyramid`) stay far below it. Coincident bodies
/// reach it at about 65 (n·(n − 1)/2 pairs).
pub const MAX_PAIRS_PER_BODY: usize = 32;

impl SolverSettings {
    /// These settings with the solver effort of `preset` (e.g. [`Self::preset`]`("fast")`),
    /// for applying a preset to a scene: a preset sets accuracy, the scene sets physics.
    ///
    /// Taken from `preset` (how hard and how the LCP is solved): in [`Self::solve`], `method`
    /// (with `auto`'s parameters), `substeps`, `iterations`, `relax_iterations`, `tolerance`,
    /// `impact_sweeps`, `exact_max_contacts`, `warm_start`, `friction_in_main_solve`, `direct_joint_solve`,
    /// `parallel_island_contacts` and `simd_island_contacts`; in [`Self::contact`], `repair`
    /// (method, stiffness and its parameters), `overlap_slop`, `max_repair_speed` and
    /// `recycle_distance`.
    /// Kept from `self` (what the scene means to happen): the rest of [`Self::contact`]
    /// (`restitution_threshold`, `prediction_distance`, `split_overlap`, `collision_steps`, `friction`, `friction_combine`,
    /// `restitution_combine`, `impact`), [`Self::sleep`], [`Self::limits`], `gyroscopic`,
    /// `continuous`, and in [`Self::solve`] `heavy_on_light_mass_ratio` and
    /// `fused_multiply_add` (a choice between speed and bits the same on every CPU). The split
    /// is tabled in docs/solvers.md, "Presets and scenes".
    pub fn with_effort_of(&self, preset: &SolverSettings) -> SolverSettings {
        let (solve, contact) = (&preset.solve, &preset.contact);
        SolverSettings {
            solve: SolveSettings {
                method: solve.method,
                substeps: solve.substeps,
                iterations: solve.iterations,
                relax_iterations: solve.relax_iterations,
                tolerance: solve.tolerance,
                impact_sweeps: solve.impact_sweeps,
                exact_max_contacts: solve.exact_max_contacts,
                warm_start: solve.warm_start,
                friction_in_main_solve: solve.friction_in_main_solve,
                direct_joint_solve: solve.direct_joint_solve,
                parallel_island_contacts: solve.parallel_island_contacts,
                simd_island_contacts: solve.simd_island_contacts,
                ..self.solve
            },
            contact: ContactSettings {
                repair: contact.repair,
                overlap_slop: contact.overlap_slop,
                max_repair_speed: contact.max_repair_speed,
                recycle_distance: contact.recycle_distance,
                ..self.contact
            },
            ..self.clone()
        }
    }
}

impl SolverSettings {
    /// `auto`'s parameters as a file holds them: the method's when it is `auto`, else
    /// [`OffParameters::auto`].
    pub fn auto_parameters(&self) -> (f32, u32, f32) {
        if self.solve.method.is_auto() {
            self.solve.method.auto_parameters()
        } else {
            self.off.auto
        }
    }

    /// The sleep parameters as a file holds them: [`Self::sleep`]'s when sleep is on, else
    /// [`OffParameters::sleep`].
    pub fn sleep_parameters(&self) -> SleepSettings {
        self.sleep.unwrap_or(self.off.sleep)
    }

    /// Whether the main solve sweeps the friction rows: see [`SolveSettings::friction_in_main_solve`].
    pub fn main_solve_friction(&self) -> bool {
        self.solve.friction_in_main_solve
            || self.solve.method != SolverMethod::Pgs
            || self.split_impulse()
            || self.solve.relax_iterations == 0
    }

    /// The soft step at `substeps` substeps: one PGS sweep of the normal rows with overlap
    /// repair on soft contacts, position integration, and one relax sweep of all rows, per
    /// substep (Box2D v3's soft step; Rapier's TGS-soft solves contacts the same way). The
    /// contact spring is as stiff as the substep allows, a fifth of the substep rate
    /// (12·`substeps` Hz at dt = 1/60 s), with ζ = 10, and there is no overlap slop: a soft
    /// row's spring holds its load at a depth proportional to the load, so a slop below which
    /// nothing is repaired would add one slop of sink per layer of a pile. Large islands run in
    /// SIMD lanes. The quality error of the standard scenes falls about as 1/`substeps`²
    /// (docs/benchmarks.md, "The front"). Overlap is repaired at most at 0.5 m/s per contact:
    /// a repair velocity is partly kept by the bodies it separates and adds up along a chain of
    /// overlapping bodies, so a larger cap throws an overlapped pile apart (the
    /// `overlap_pyramid` scene).
    /// Everything else, the method, the sweeps, the slop and the repair cap included, as
    /// [`Self::default`], which is this step at 20 substeps.
    pub fn soft_step(substeps: u32) -> Self {
        let substeps = substeps.max(1);
        let default = Self::default();
        Self {
            solve: SolveSettings {
                substeps,
                ..default.solve
            },
            contact: ContactSettings {
                repair: ContactRepair::Soft {
                    hertz: 12.0 * substeps as f32,
                    damping_ratio: 10.0,
                },
                ..default.contact
            },
            ..default
        }
    }

    /// The named presets, cheapest first, with the quality bar each meets on the standard
    /// scenes at dt = 1/60 s (E, the largest of top sink, overlap and drift after 10 s):
    /// `fast` (E ≤ 50 mm, [`Self::fast`]), `default` (E ≤ 5 mm, [`Self::default`]), `precise`
    /// (E ≤ 1 mm, [`Self::precise`]) and `reference`
    /// ([`Self::reference`]: the LCP solved tightly, for research).
    pub const PRESETS: [&'static str; 4] = ["fast", "default", "precise", "reference"];

    /// The preset called `name` (see [`Self::PRESETS`]; `q50`, `q5` and `q1` name `fast`,
    /// `default` and `precise` by their bar); `None` for an unknown name.
    pub fn preset(name: &str) -> Option<Self> {
        match name {
            "fast" | "q50" => Some(Self::fast()),
            "default" | "q5" => Some(Self::default()),
            "precise" | "q1" => Some(Self::precise()),
            "reference" => Some(Self::reference()),
            _ => None,
        }
    }

    /// Speed before accuracy: the soft step at 8 substeps (96 Hz contacts) without impact
    /// sweeps ([`SolveSettings::impact_sweeps`] 0), contacts recycled up to
    /// [`FAST_RECYCLE_DISTANCE`] (2 cm; [`ContactSettings::recycle_distance`]). Meets E ≤ 50 mm
    /// on the standard scenes (docs/benchmarks.md, "The front"), where nothing lands, as the
    /// soft step at 8 substeps does; where bodies land, as in a pour, it costs a third less, and
    /// a face landing at restitution 0 rises again at 7-9 % of its impact speed (docs/method.md,
    /// "Impacts").
    pub fn fast() -> Self {
        let soft = Self::soft_step(8);
        Self {
            solve: SolveSettings {
                impact_sweeps: 0,
                ..soft.solve
            },
            contact: ContactSettings {
                recycle_distance: FAST_RECYCLE_DISTANCE,
                ..soft.contact
            },
            ..soft
        }
    }

    /// The soft step at 48 substeps (576 Hz contacts): E ≤ 1 mm on the standard scenes
    /// (docs/benchmarks.md, "The front").
    pub fn precise() -> Self {
        Self::soft_step(48)
    }

    /// The LCP solved tightly rather than cheaply, for reference and research: the automatic
    /// policy (NNCG, escalating per island to more iterations or the exact path), 4 substeps of
    /// at most 8 iterations, rigid velocity rows with split-impulse overlap repair (12/s above
    /// a 2 mm slop). Its per-step residual is small and its LCP can be compared with an exact
    /// solution; it costs several times the default for the same quality on stacks.
    pub fn reference() -> Self {
        let default = Self::default();
        Self {
            solve: SolveSettings {
                method: SolverMethod::AUTO,
                substeps: 4,
                iterations: 8,
                ..default.solve
            },
            contact: ContactSettings {
                repair: ContactRepair::SplitImpulse {
                    rate: 12.0,
                    iterations: 16,
                },
                overlap_slop: 0.002,
                max_repair_speed: 1.0,
                ..default.contact
            },
            ..default
        }
    }
}

/// The default: the soft step at 20 substeps (240 Hz contacts), the cheapest setting found
/// to meet E ≤ 5 mm on every standard scene (docs/benchmarks.md, "The front"). Other presets:
/// [`SolverSettings::PRESETS`].
impl Default for SolverSettings {
    fn default() -> Self {
        Self {
            solve: SolveSettings::default(),
            contact: ContactSettings::default(),
            sleep: Some(SleepSettings::default()),
            limits: WorldLimits::default(),
            gyroscopic: true,
            continuous: true,
            off: OffParameters::default(),
        }
    }
}

/// The default settings' solve: the soft step's PGS at 20 substeps ([`SolverSettings::default`]).
impl Default for SolveSettings {
    fn default() -> Self {
        Self {
            method: SolverMethod::Pgs,
            substeps: 20,
            iterations: 1,
            relax_iterations: 1,
            tolerance: 1e-5,
            impact_sweeps: DEFAULT_IMPACT_SWEEPS,
            exact_max_contacts: 32,
            heavy_on_light_mass_ratio: 200.0,
            warm_start: 1.0,
            friction_in_main_solve: false,
            direct_joint_solve: true,
            parallel_island_contacts: 0,
            simd_island_contacts: 16,
            fused_multiply_add: false,
        }
    }
}

/// The default settings' contacts: soft repair at 240 Hz, ζ = 10 ([`SolverSettings::default`]).
impl Default for ContactSettings {
    fn default() -> Self {
        Self {
            restitution_threshold: 0.5,
            repair: ContactRepair::Soft {
                hertz: 240.0,
                damping_ratio: 10.0,
            },
            overlap_slop: 0.0,
            max_repair_speed: 0.5,
            prediction_distance: 0.02,
            split_overlap: 0.0,
            collision_steps: DEFAULT_COLLISION_STEPS,
            recycle_distance: DEFAULT_RECYCLE_DISTANCE,
            friction: true,
            impact: ImpactModel::Simultaneous,
            friction_combine: CombineRule::GeometricMean,
            restitution_combine: CombineRule::Max,
        }
    }
}

/// Quiet below 0.05 m/s and 2°/s for 0.5 s.
impl Default for SleepSettings {
    fn default() -> Self {
        Self {
            linear_speed: 0.05,
            angular_speed: 2.0f32.to_radians(),
            time_to_sleep: 0.5,
        }
    }
}

/// [`BLOW_UP_DISTANCE`], [`DEFAULT_MAX_LINEAR_SPEED`] and [`DEFAULT_MAX_ANGULAR_SPEED`].
impl Default for WorldLimits {
    fn default() -> Self {
        Self {
            max_distance: BLOW_UP_DISTANCE,
            max_linear_speed: DEFAULT_MAX_LINEAR_SPEED,
            max_angular_speed: DEFAULT_MAX_ANGULAR_SPEED,
        }
    }
}

#[cfg(test)]
mod tests;
