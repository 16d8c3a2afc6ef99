//! A breakable joint's strength in an island's step ([`Strength`]): how much impulse its locked
//! groups may pass in a substep before it breaks.
//!
//! A joint of strength F (N) measured over a window of w seconds breaks when the impulse its
//! locked translations passed over the last w seconds reaches F·w (torques alike). The impulse
//! of past substeps is kept as one sum per group, S ← d·S + λ after each substep with
//! d = 1 − h/w (an exponential window of time constant w): a steady force F' gives S = F'·w, so
//! a static load breaks the joint exactly when F' ≥ F, and a blow that passes an impulse J
//! within a few substeps breaks it when J ≥ F·w, however many substeps carry it. Bullet's
//! breaking threshold is that impulse (N·s) over one of its own substeps: a window of that
//! substep's length reproduces both its static and its impact strength at any substep length
//! of ours. With w ≤ h (w = 0 by default) the window is the substep itself (d = 0): the impulse
//! of each substep is compared with F·h alone.
//!
//! Within a substep the solve bounds the group's impulse by the rest of the budget,
//! |λ| ≤ F·max(w, h) − d·|S| (a ball centred on zero, so that the exact path's ball bounds
//! hold unchanged; when λ is along S, as under a steady load, |d·S + λ| ≤ F·max(w, h)
//! exactly), and a substep that ends at that bound breaks the joint.

use glam::Vec3;

/// The strength of a joint's locked groups (group 0 the translations, 1 the rotations).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Strength {
    /// Thresholds (N, N·m; infinite: unbreakable).
    force: f32,
    torque: f32,
    /// The window (s) over which the impulse is measured; at most a substep: the substep.
    window: f32,
    /// The locked groups' impulses of the past substeps, each multiplied by the decay once per
    /// later substep (world frame; N·s, N·m·s).
    pub sums: [Vec3; 2],
    /// The substep length (s) and the sums' decay per substep, set by [`Self::start_step`].
    h: f32,
    decay: f32,
}

impl Strength {
    /// Thresholds `force` (N) and `torque` (N·m) (`None`: unbreakable), measured over `window`
    /// seconds (0: per substep), with the sums `sums` carried from the last step.
    pub(crate) fn new(
        force: Option<f32>,
        torque: Option<f32>,
        window: f32,
        sums: [Vec3; 2],
    ) -> Self {
        Self {
            force: force.unwrap_or(f32::INFINITY),
            torque: torque.unwrap_or(f32::INFINITY),
            window,
            sums,
            h: 0.0,
            decay: 0.0,
        }
    }

    /// The substep length of this step's solves.
    pub(crate) fn start_step(&mut self, h: f32) {
        self.h = h;
        self.decay = if self.window > h {
            1.0 - h / self.window
        } else {
            0.0
        };
    }

    /// Whether a threshold is finite.
    pub(crate) fn is_breakable(&self) -> bool {
        self.force.is_finite() || self.torque.is_finite()
    }

    /// The length (s) the thresholds are multiplied by: the window, at least a substep.
    fn span(&self) -> f32 {
        self.window.max(self.h)
    }

    /// The bound on a locked group's impulse in the current substep (N·s or N·m·s; infinite:
    /// unbreakable): the threshold's impulse over the window less the decayed sum of the past
    /// substeps.
    pub(crate) fn bound(&self, group: usize) -> f32 {
        let threshold = if group == 0 { self.force } else { self.torque };
        if !threshold.is_finite() {
            return f32::INFINITY;
        }
        (threshold * self.span() - self.decay * self.sums[group].length()).max(0.0)
    }

    /// After a substep the joint survived: each group's impulse `impulses` (world) added to its
    /// decayed sum.
    pub(crate) fn record(&mut self, impulses: [Vec3; 2]) {
        for (sum, impulse) in self.sums.iter_mut().zip(impulses) {
            *sum = *sum * self.decay + impulse;
        }
    }

    /// The force and torque (N, N·m) the joint broke at, from the substep's reaction `force`
    /// and `torque` (its impulse over h): the decayed sums plus that substep's impulse, over the
    /// window.
    pub(crate) fn breaking_load(&self, force: Vec3, torque: Vec3) -> (Vec3, Vec3) {
        let span = self.span();
        (
            (self.sums[0] * self.decay + force * self.h) / span,
            (self.sums[1] * self.decay + torque * self.h) / span,
        )
    }
}
