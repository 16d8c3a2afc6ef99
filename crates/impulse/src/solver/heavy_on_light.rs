//! Heavy on light: an island whose mass ratio between two touching moving bodies exceeds
//! [`crate::settings::SolveSettings::heavy_on_light_mass_ratio`] is reported ([`HeavyOnLight`]) and, when small
//! enough, solved as one exact LCP a step on rigid rows (the path's settings:
//! [`heavy_on_light_settings`]).

use crate::body::Bodies;
use crate::contact::ContactConstraint;
use crate::settings::{ContactRepair, SolverMethod, SolverSettings};

/// A heavy-on-light island: its contact of largest mass ratio, and how the island was treated
/// ([`crate::IslandReport::heavy_on_light`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct HeavyOnLight {
    /// Index of the heavier body of that contact.
    pub heavy_body: u32,
    /// Index of the lighter body.
    pub light_body: u32,
    /// Their mass ratio, heavier over lighter (> 1).
    pub mass_ratio: f32,
    /// Whether the island took the exact path: with the soft step or bias repair, the
    /// heavy-on-light path, one exact LCP per step on rigid rows; with split impulse
    /// (`reference`), the automatic policy's exact path in every substep. It has at most
    /// [`HEAVY_ON_LIGHT_CONTACTS_FACTOR`] × `exact_max_contacts` points. If not, it took the
    /// ordinary path.
    pub exact: bool,
    /// Whether the island looks held: its deepest overlap at the step's start is at most
    /// [`HEAVY_ON_LIGHT_HELD_OVERLAP`]. An island not held is sinking through, or has sunk.
    pub held: bool,
}

/// Deepest overlap (m) of a heavy-on-light island that is still reported as held
/// ([`HeavyOnLight::held`]). A held island's contacts overlap by far less: the soft step's
/// spring holds a contact at the 200:1 threshold at R·g/ω² ≈ 0.9 mm (240 Hz), the exact path
/// holds it at the slop; an island the soft step lets sink passes this within a few steps.
pub const HEAVY_ON_LIGHT_HELD_OVERLAP: f32 = 0.01;

/// The heavy-on-light path's overlap repair: a velocity bias at this rate (1/s), removed by
/// the relax solve, on rigid rows.
const HEAVY_ON_LIGHT_REPAIR_RATE: f32 = 12.0;

/// A heavy-on-light island may take the exact path with up to this many times
/// [`crate::settings::SolveSettings::exact_max_contacts`] contact points (128 at the default). A heavy body on
/// light ones is held by no iterative budget (docs/method.md, "Heavy on light"), so an exact
/// solve of a larger island, a few milliseconds a step, is the price of holding it at all: a
/// 10,000 kg slab on a 3 × 3 grid of 1 kg boxes (72 points) sank through them at 32.
pub const HEAVY_ON_LIGHT_CONTACTS_FACTOR: u32 = 4;

/// Most contact points of a heavy-on-light island that takes the exact path under `settings`
/// ([`HEAVY_ON_LIGHT_CONTACTS_FACTOR`] times `exact_max_contacts`; 0 = never).
pub(crate) fn heavy_on_light_max_contacts(settings: &SolverSettings) -> u32 {
    settings
        .solve
        .exact_max_contacts
        .saturating_mul(HEAVY_ON_LIGHT_CONTACTS_FACTOR)
}

/// The settings of the heavy-on-light path ([`crate::settings::SolveSettings::heavy_on_light_mass_ratio`]):
/// the basic method's one LCP per step (one substep), on rigid rows with a velocity bias
/// ([`HEAVY_ON_LIGHT_REPAIR_RATE`]) and a relax solve, solved by the automatic policy with every
/// solve escalating to the exact path (Lemke; NNCG's result stands if pivoting fails; `auto`'s
/// other parameters as `settings.solve.method`'s, or their defaults). The
/// rest, repair cap, friction and warm start included, is `settings`'.
pub(crate) fn heavy_on_light_settings(settings: &SolverSettings) -> SolverSettings {
    let (escalation_tolerance, escalation_iterations, _) = settings.solve.method.auto_parameters();
    let mut light = settings.clone();
    light.solve.method = SolverMethod::Auto {
        escalation_tolerance,
        escalation_iterations,
        mass_ratio_threshold: 0.0,
    };
    light.solve.substeps = 1;
    light.solve.relax_iterations = settings.solve.relax_iterations.max(1);
    light.solve.exact_max_contacts = heavy_on_light_max_contacts(settings);
    light.contact.repair = ContactRepair::Bias {
        rate: HEAVY_ON_LIGHT_REPAIR_RATE,
    };
    light
}

/// The contact of `constraints` of largest mass ratio between two moving bodies, if above
/// `threshold`, with `held` from the deepest overlap of any contact (`exact` left false).
pub(crate) fn heavy_on_light(
    island_bodies: &[u32],
    constraints: &[ContactConstraint],
    bodies: &Bodies,
    threshold: f32,
) -> Option<HeavyOnLight> {
    let mut found: Option<HeavyOnLight> = None;
    let mut deepest = 0.0f32;
    let moving = |slot: u32| {
        let body = *island_bodies.get(slot as usize)?;
        let inverse_mass = bodies.inverse_mass[body as usize];
        (inverse_mass > 0.0).then_some((body, inverse_mass))
    };
    for c in constraints {
        deepest = deepest.max(c.depth);
        let (Some(a), Some(b)) = (moving(c.local_a), moving(c.local_b)) else {
            continue;
        };
        // The heavier body has the smaller inverse mass.
        let (heavy, light) = if a.1 <= b.1 { (a, b) } else { (b, a) };
        let mass_ratio = light.1 / heavy.1;
        if mass_ratio > threshold && found.is_none_or(|f| mass_ratio > f.mass_ratio) {
            found = Some(HeavyOnLight {
                heavy_body: heavy.0,
                light_body: light.0,
                mass_ratio,
                exact: false,
                held: false,
            });
        }
    }
    found.map(|f| HeavyOnLight {
        held: deepest <= HEAVY_ON_LIGHT_HELD_OVERLAP,
        ..f
    })
}

/// Heaviest to lightest moving body of an island (1 when it has one body).
pub(crate) fn mass_ratio(island_bodies: &[u32], bodies: &Bodies) -> f32 {
    let (mut lightest, mut heaviest) = (f32::INFINITY, 0.0f32);
    for &i in island_bodies {
        let inverse_mass = bodies.inverse_mass[i as usize];
        if inverse_mass > 0.0 {
            lightest = lightest.min(1.0 / inverse_mass);
            heaviest = heaviest.max(1.0 / inverse_mass);
        }
    }
    if heaviest > 0.0 {
        heaviest / lightest
    } else {
        1.0
    }
}
