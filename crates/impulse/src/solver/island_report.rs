//! What the solver did on one island in a step ([`IslandReport`]), part of every step's
//! diagnostics.

use super::heavy_on_light::HeavyOnLight;
use super::interface::EscalationLevel;
#[cfg(doc)]
use crate::settings::SolverSettings;

/// What the solver did on one island during a step: every step can say how well its LCP was
/// solved, here per island.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct IslandReport {
    /// Smallest body index in the island: a stable name for it within the step.
    pub first_body: u32,
    /// Moving bodies in the island.
    pub bodies: u32,
    /// Contact points (normal rows) in the island.
    pub contacts: u32,
    /// Heaviest to lightest moving body mass (1 for one body).
    pub mass_ratio: f32,
    /// The strongest method any of its solves used: `pgs`, `nncg`, `apgd`, `nncg_extended` or
    /// `exact`. For `auto`: `exact` if any solve was exact, as `last_change` is then the exact
    /// solve's residual (m/s).
    pub method: EscalationLevel,
    /// Solves (one per substep) that escalated beyond their first method.
    pub escalations: u32,
    /// Exact solves attempted that failed (their iterative result was kept).
    pub exact_failures: u32,
    /// Lemke pivots of the exact solves.
    pub exact_pivots: u32,
    /// Iterations used in the step, all solves and methods together.
    pub iterations: u32,
    /// Largest row velocity change of the last iteration of the last main solve (m/s): how far
    /// from converged the island's final solve stopped.
    pub last_change: f32,
    /// Sweeps the step's impacts took beyond the solves' budgets (docs/method.md, "Impacts"),
    /// over the whole island or over the points around the impact; part of `iterations`.
    #[serde(default)]
    pub impact_sweeps: u32,
    /// Contact points those impact sweeps updated, summed over the sweeps: `impact_sweeps` ×
    /// `contacts` when they swept the whole island, fewer when they swept the points around
    /// the impact alone (in SIMD lanes: the points of the lane groups they visited).
    #[serde(default)]
    pub impact_points: u64,
    /// Substeps whose main solve found an impact and swept on (`impact_sweeps` is their sum):
    /// one for a landing resolved where it happened, up to `substeps` when every later
    /// substep of the step took sweeps again.
    #[serde(default)]
    pub impact_substeps: u32,
    /// Whether the substeps' solves ran in SIMD lanes.
    pub simd: bool,
    /// Bundles the island's contact points were packed into for the SIMD lanes (`simd`),
    /// padding included: one point a lane, 4 lanes a bundle (8 with the `lanes8` feature);
    /// 0 when not in lanes. `contacts` / (4 × `bundles`) is the share of lanes that hold a
    /// point, which the sweeps' cost follows (docs/method.md, "Graph colouring and SIMD lanes").
    #[serde(default)]
    pub bundles: u32,
    /// Natural-map residual of the island's rows at the end of the step (see
    /// [`crate::diagnostics::StepDiagnostics::natural_map_residual`]); set by the world as the
    /// island's step ends.
    pub natural_map_residual: f32,
    /// Substeps the island took in the step: the settings' `substeps`, or 1 on the
    /// heavy-on-light path ([`HeavyOnLight::exact`]).
    #[serde(default)]
    pub substeps: u32,
    /// The island's contact of largest mass ratio between two moving bodies, when that ratio
    /// exceeds [`crate::settings::SolveSettings::heavy_on_light_mass_ratio`]; `None` otherwise (and for
    /// split-impulse repair, which holds such islands on its own).
    #[serde(default)]
    pub heavy_on_light: Option<HeavyOnLight>,
    /// The island's deepest contact point as the step's contacts were found (see
    /// [`IslandContact`]); `None` for an island without contact points. Set by the world as the
    /// step ends.
    #[serde(default)]
    pub deepest_contact: Option<IslandContact>,
}

/// One contact point of an island named by its bodies and, on a compound (a decomposed mesh's
/// convex parts, or a `compound` shape's parts), the part it is on: where an island's overlap
/// is, down to the part of a mug's wall.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct IslandContact {
    /// Index of the first body of the point's pair (the lower index; a static body included).
    pub body1: u32,
    /// Index of the pair's second body.
    pub body2: u32,
    /// The part of `body1`'s shape the point is on, when that shape is a compound: an index
    /// into its parts, in their order; `None` for any other shape.
    pub part1: Option<u32>,
    /// The part of `body2`'s shape the point is on (as `part1`).
    pub part2: Option<u32>,
    /// Penetration depth (m) when the contacts were found: > 0 overlapping, < 0 a speculative
    /// point's gap.
    pub depth: f32,
}
