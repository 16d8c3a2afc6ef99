//! What an export holds: the bodies with their colours and the recorded frames of poses,
//! the input of both writers.

use impulse::{BodyKind, Scene, ShapeDesc};

/// One body as exported: its display name, kind and collision shape.
#[derive(Clone, Debug)]
pub struct BodyInfo {
    /// The scene's `name` for the body, else `body_<index>` (scene order).
    pub name: String,
    /// Dynamic, static or particle.
    pub kind: BodyKind,
    /// Collision shape in the body frame.
    pub shape: ShapeDesc,
}

impl BodyInfo {
    /// The bodies of `scene`, in scene order.
    pub fn from_scene(scene: &Scene) -> Vec<Self> {
        scene
            .bodies
            .iter()
            .enumerate()
            .map(|(i, body)| BodyInfo {
                name: body.name.clone().unwrap_or_else(|| format!("body_{i}")),
                kind: body.kind,
                shape: body.shape.clone(),
            })
            .collect()
    }

    /// Whether the body never moves (it gets no animation).
    pub fn is_static(&self) -> bool {
        self.kind == BodyKind::Static
    }
}

/// Base colours of moving bodies (linear RGB), cycled in scene order.
pub const PALETTE: [[f32; 3]; 6] = [
    [0.80, 0.25, 0.20],
    [0.20, 0.45, 0.80],
    [0.90, 0.65, 0.15],
    [0.25, 0.65, 0.35],
    [0.55, 0.30, 0.70],
    [0.15, 0.65, 0.70],
];
/// Base colour of static bodies (linear RGB).
pub const STATIC_GREY: [f32; 3] = [0.5, 0.5, 0.5];

/// Per body, the index into [`PALETTE`] of its colour, or `None` for a static body (grey).
pub fn palette_indices(bodies: &[BodyInfo]) -> Vec<Option<usize>> {
    let mut moving = 0;
    bodies
        .iter()
        .map(|body| {
            if body.is_static() {
                None
            } else {
                moving += 1;
                Some((moving - 1) % PALETTE.len())
            }
        })
        .collect()
}

/// Per body, its base colour (linear RGB): [`PALETTE`] in turn for moving bodies,
/// [`STATIC_GREY`] for static ones.
pub fn body_colours(bodies: &[BodyInfo]) -> Vec<[f32; 3]> {
    palette_indices(bodies)
        .into_iter()
        .map(|k| k.map_or(STATIC_GREY, |k| PALETTE[k]))
        .collect()
}

/// A body's pose: translation (m) and unit rotation quaternion `[x, y, z, w]` (scalar last).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PoseSample {
    pub translation: [f32; 3],
    pub rotation: [f32; 4],
}

/// The poses of all bodies at one written step.
#[derive(Clone, Debug)]
pub struct Frame {
    /// Step number (0 = the initial state).
    pub step: u64,
    /// One pose per body, scene order.
    pub poses: Vec<PoseSample>,
}

impl Frame {
    /// Time of the frame (s) for time step `dt`.
    pub fn time(&self, dt: f32) -> f64 {
        self.step as f64 * dt as f64
    }
}

/// What a run exports: the bodies, the time step and the frames written so far.
#[derive(Clone, Debug)]
pub struct Animation {
    /// Scene name (may be empty).
    pub scene_name: String,
    /// Time step (s).
    pub dt: f32,
    pub bodies: Vec<BodyInfo>,
    /// Written frames, by increasing step.
    pub frames: Vec<Frame>,
}

impl Animation {
    /// Half the side of the square drawn for a half-space: at least 50 m, and at least twice
    /// the largest distance of any body from the world origin over the frames, so the ground
    /// reaches beyond everything that moves on it.
    pub fn ground_half_size(&self) -> f32 {
        let mut reach = 0.0f32;
        for frame in &self.frames {
            for (pose, body) in frame.poses.iter().zip(&self.bodies) {
                if matches!(body.shape, ShapeDesc::HalfSpace { .. }) {
                    continue;
                }
                let [x, y, z] = pose.translation;
                let distance = (x * x + y * y + z * z).sqrt();
                if distance.is_finite() {
                    reach = reach.max(distance);
                }
            }
        }
        (2.0 * reach + 10.0).max(50.0)
    }
}
