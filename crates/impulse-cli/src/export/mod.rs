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

mod animation;
pub mod gltf;
pub mod mesh;
pub mod usd;

pub use animation::{Animation, BodyInfo, Frame, PALETTE, PoseSample, STATIC_GREY};

use std::path::{Path, PathBuf};

use anyhow::{Result, bail};
use impulse::Scene;
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
