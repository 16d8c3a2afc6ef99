//! Stage 3 of the step: candidate pairs → persistent contact manifolds (Parry).
//!
//! Each pair keeps its manifolds from step to step, so Parry can match new contact points to
//! old ones by feature id and carry the solver's impulses over ([`ContactImpulse`]): that is
//! what warm starting reads.

use std::collections::HashMap;

use glam::Vec3;
use parry3d::query::{
    ContactManifold, ContactManifoldsWorkspace, DefaultQueryDispatcher, PersistentQueryDispatcher,
};
use rayon::prelude::*;

use crate::body::Bodies;
use crate::error::StepError;

/// Impulses a contact point received in the last solve, kept with the point across steps.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ContactImpulse {
    /// Normal impulse γ_n ≥ 0 (N·s).
    pub normal: f32,
    /// Friction impulse as a world vector (N·s), so it survives a change of tangent basis.
    pub friction: Vec3,
}

/// Per-manifold state kept across steps.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ManifoldState {
    /// First friction direction of the last step (zero before the first solve). Reusing it
    /// keeps the friction basis continuous: a basis rebuilt from the normal alone can flip
    /// between steps, and warm-started friction then lands on the wrong axes.
    pub tangent: Vec3,
}

/// Parry's manifold type with our per-manifold and per-point data.
pub type Manifold = ContactManifold<ManifoldState, ContactImpulse>;

/// The contact state of one pair of bodies. Shape 1 belongs to `body1`, shape 2 to `body2`,
/// and `body1 < body2`.
pub struct ContactPair {
    /// Lower body index.
    pub body1: u32,
    /// Higher body index.
    pub body2: u32,
    /// Manifolds (one for convex-convex pairs) with points in each body's local frame.
    pub manifolds: Vec<Manifold>,
    workspace: Option<ContactManifoldsWorkspace>,
}

impl ContactPair {
    /// Number of contact points over all manifolds.
    pub fn point_count(&self) -> usize {
        self.manifolds.iter().map(|m| m.points.len()).sum()
    }
}

/// Per-body speculative margins (m): half the base prediction distance plus the distance the
/// body can travel in one step, dt·(|v| + |ω|·R + |g|·dt) with R its bounding radius. Pairs
/// are then found, and contact points generated, before fast bodies meet rather than after
/// they have tunnelled into each other; a fixed margin lets a ball falling at 19 m/s overlap
/// its neighbours by a tenth of a metre.
pub fn speculative_margins(
    bodies: &Bodies,
    prediction_distance: f32,
    gravity: Vec3,
    dt: f32,
    out: &mut Vec<f32>,
) {
    out.clear();
    for i in 0..bodies.len() {
        let margin = if bodies.is_moving(i) {
            let radius = bodies.shape[i].compute_local_aabb().half_extents().length();
            let speed = bodies.linear_velocity[i].length()
                + bodies.angular_velocity[i].length() * radius
                + gravity.length() * dt;
            (0.5 * prediction_distance + speed * dt).min(MAX_SPECULATIVE_MARGIN)
        } else {
            0.5 * prediction_distance
        };
        out.push(margin);
    }
}

/// Cap on a body's speculative margin (m), so a body thrown at absurd speed does not pair
/// with the whole scene.
pub const MAX_SPECULATIVE_MARGIN: f32 = 2.0;

/// All pairs that the broad phase reported this step, with their manifolds.
#[derive(Default)]
pub struct NarrowPhase {
    /// This step's pairs, in the broad phase's sorted order.
    pub pairs: Vec<ContactPair>,
    previous: HashMap<(u32, u32), ContactPair>,
}

impl NarrowPhase {
    /// Updates manifolds for `candidates`; pairs no longer candidates are dropped with their
    /// history. Points of pair (i, j) are generated up to `margins[i] + margins[j]` (m) of
    /// separation (see [`speculative_margins`]).
    pub fn update(
        &mut self,
        bodies: &Bodies,
        candidates: &[(u32, u32)],
        margins: &[f32],
        parallel: bool,
    ) -> Result<(), StepError> {
        self.previous.clear();
        for pair in self.pairs.drain(..) {
            self.previous.insert((pair.body1, pair.body2), pair);
        }
        for &(i, j) in candidates {
            let pair = self.previous.remove(&(i, j)).unwrap_or(ContactPair {
                body1: i,
                body2: j,
                manifolds: Vec::new(),
                workspace: None,
            });
            self.pairs.push(pair);
        }
        let update = |pair: &mut ContactPair| -> Result<(), StepError> {
            let (a, b) = (pair.body1 as usize, pair.body2 as usize);
            // A pair with no awake body keeps its manifolds as they were: nothing moved.
            if !bodies.is_awake(a) && !bodies.is_awake(b) {
                return Ok(());
            }
            let prediction = margins[a] + margins[b];
            let pos12 = bodies.pose[a].inv_mul(&bodies.pose[b]);
            DefaultQueryDispatcher
                .contact_manifolds(
                    &pos12,
                    bodies.shape[a].as_ref(),
                    bodies.shape[b].as_ref(),
                    prediction,
                    &mut pair.manifolds,
                    &mut pair.workspace,
                )
                .map_err(|_| StepError::UnsupportedShapePair { body1: a, body2: b })
        };
        if parallel && rayon::current_num_threads() > 1 {
            self.pairs.par_iter_mut().try_for_each(update)?;
        } else {
            self.pairs.iter_mut().try_for_each(update)?;
        }
        // Pairs whose manifolds Parry emptied are kept for their workspace; pairs Parry never
        // gave a manifold are dropped.
        self.pairs.retain(|p| !p.manifolds.is_empty());
        Ok(())
    }

    /// Largest penetration depth (m) among current contact points, 0 if none overlap.
    pub fn max_depth(&self) -> f32 {
        self.pairs
            .iter()
            .flat_map(|p| p.manifolds.iter())
            .flat_map(|m| m.points.iter())
            .map(|p| -p.dist)
            .fold(0.0, f32::max)
    }
}
