//! Animation export of a run: glTF 2.0 (`.glb`, `.gltf`) and OpenUSD ASCII (`.usda`).
//!
//! [`Recording`] keeps the poses of every written frame (the same frames the CSV/JSONL writer
//! writes: frame 0, every K-th step and the last) and [`Recording::write`] turns them, with the
//! bodies' shapes and names from the [`Scene`], into one file at the end of the run. What each
//! format holds is documented in `docs/export.md`.
//!
//! Conventions of both formats match the engine's: metres, y up, right-handed, unit
//! quaternions. Poses are those of the body frame (the shape's local frame), not of the centre
//! of mass.

pub mod gltf;
pub mod mesh;
pub mod usd;

use std::path::{Path, PathBuf};

use anyhow::{Result, bail};
use impulse::{BodyKind, Scene, ShapeDesc};
use parry3d::math::Pose;

/// An animation file format, chosen from the file extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// Binary glTF 2.0 (`.glb`): the JSON chunk and one buffer in the BIN chunk.
    Glb,
    /// glTF 2.0 JSON (`.gltf`) with its one buffer embedded as a base64 data URI.
    Gltf,
    /// OpenUSD ASCII stage (`.usda`).
    Usda,
}

impl Format {
    /// The format for `path`'s extension, or `None` when it is none of `glb`, `gltf`, `usda`.
    pub fn from_path(path: &Path) -> Option<Self> {
        match path.extension()?.to_str()? {
            "glb" => Some(Format::Glb),
            "gltf" => Some(Format::Gltf),
            "usda" => Some(Format::Usda),
            _ => None,
        }
    }
}

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

/// Records frames during a run and writes the animation file at its end.
pub struct Recording {
    path: PathBuf,
    format: Format,
    animation: Animation,
}

impl Recording {
    /// A recording of `scene`'s bodies to be written to `path` in `format`. Fails early if the
    /// file cannot be created, so a long run does not end in a write error.
    pub fn create(path: &Path, format: Format, scene: &Scene) -> Result<Self> {
        if let Err(e) = std::fs::File::create(path) {
            bail!("cannot create {}: {e}", path.display());
        }
        Ok(Self {
            path: path.to_path_buf(),
            format,
            animation: Animation {
                scene_name: scene.name.clone(),
                dt: scene.dt,
                bodies: BodyInfo::from_scene(scene),
                frames: Vec::new(),
            },
        })
    }

    /// Keeps `poses` (one per body, scene order) at `step`.
    ///
    /// A rotation quaternion whose dot product with the body's previous keyframe is negative is
    /// negated (q and −q are the same rotation), so consecutive keyframes lie in one hemisphere
    /// and tools that interpolate quaternions component by component (Blender's f-curves) turn
    /// the short way.
    pub fn record(&mut self, step: u64, poses: &[Pose]) {
        let previous = self.animation.frames.last();
        let poses = poses
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let rotation = p.rotation.to_array();
                PoseSample {
                    translation: p.translation.to_array(),
                    rotation: match previous {
                        Some(frame) => same_hemisphere(rotation, frame.poses[i].rotation),
                        None => rotation,
                    },
                }
            })
            .collect();
        self.animation.frames.push(Frame { step, poses });
    }

    /// Writes the file with every frame recorded so far.
    pub fn write(&self) -> Result<()> {
        let result = match self.format {
            Format::Glb => gltf::write_glb(&self.animation, &self.path),
            Format::Gltf => gltf::write_gltf(&self.animation, &self.path),
            Format::Usda => usd::write_usda(&self.animation, &self.path),
        };
        result.map_err(|e| e.context(format!("cannot write {}", self.path.display())))
    }
}

/// `q`, or −q (the same rotation) when that is nearer to `previous` (their dot product is
/// negative).
fn same_hemisphere(q: [f32; 4], previous: [f32; 4]) -> [f32; 4] {
    let dot: f32 = q.iter().zip(previous).map(|(a, b)| a * b).sum();
    if dot < 0.0 { q.map(|c| -c) } else { q }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keyframe_quaternions_stay_in_one_hemisphere() {
        let previous = [0.0, 0.6, 0.0, 0.8];
        assert_eq!(
            same_hemisphere([0.0, -0.7, 0.0, -0.71], previous),
            [0.0, 0.7, 0.0, 0.71]
        );
        assert_eq!(
            same_hemisphere([0.0, 0.7, 0.0, 0.71], previous),
            [0.0, 0.7, 0.0, 0.71]
        );
    }

    #[test]
    fn formats_by_extension() {
        assert_eq!(Format::from_path(Path::new("a.glb")), Some(Format::Glb));
        assert_eq!(Format::from_path(Path::new("a.gltf")), Some(Format::Gltf));
        assert_eq!(Format::from_path(Path::new("a.usda")), Some(Format::Usda));
        assert_eq!(Format::from_path(Path::new("a.usd")), None);
        assert_eq!(Format::from_path(Path::new("a.csv")), None);
    }
}
