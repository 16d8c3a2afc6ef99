//! `impulse render anim.glb`: the frames of a binary glTF animation written by `impulse run
//! --out anim.glb` (docs/export.md), drawn like a simulated scene.
//!
//! Read: every node of the default scene with a mesh (its triangle primitives' `POSITION`,
//! `NORMAL` and indices, and their material's base colour), the node's rest transform, and the
//! first animation's `translation` and `rotation` channels. A node with no channel is static.
//! One image is drawn per keyframe of the animation (numbered 0, 1, … in the PNG names); the
//! GIF's frame delay is the time between the first two keyframes. Nodes are taken as rigid:
//! scales and node hierarchies other than the export's flat list are not applied.

use std::path::Path;

use anyhow::{Context, Result, anyhow, bail};
use gltf::animation::util::ReadOutputs;
use impulse::BodyKind;
use impulse::glam::{Quat, Vec3};

use super::{ColourBy, DrawnBody, FrameSink, Ground, RenderOptions, RenderSummary};
use crate::export::mesh::TriMesh;

/// One node as read: its mesh, colour, rest pose and keyframes.
struct Node {
    mesh: TriMesh,
    colour: Vec3,
    rest: (Quat, Vec3),
    translations: Vec<Vec3>,
    rotations: Vec<Quat>,
}

impl Node {
    fn is_static(&self) -> bool {
        self.translations.is_empty() && self.rotations.is_empty()
    }

    /// The pose at keyframe `k`: the channel's value where there is one, else the rest pose.
    fn pose(&self, k: usize) -> (Quat, Vec3) {
        let rotation = self.rotations.get(k).copied().unwrap_or(self.rest.0);
        let translation = self.translations.get(k).copied().unwrap_or(self.rest.1);
        (rotation, translation)
    }
}

/// Draws every keyframe of the `.glb` at `path`.
pub fn render_glb(path: &Path, options: &RenderOptions) -> Result<RenderSummary> {
    super::check_options(options)?;
    let bytes = std::fs::read(path).with_context(|| format!("cannot read {}", path.display()))?;
    let document = gltf::Gltf::from_slice(&bytes)
        .with_context(|| format!("{} is not a binary glTF file", path.display()))?;
    let blob = document
        .blob
        .as_deref()
        .ok_or_else(|| anyhow!("{} has no binary chunk", path.display()))?;
    let buffer = |b: gltf::Buffer| (b.index() == 0).then_some(blob);
    let scene = document
        .default_scene()
        .or_else(|| document.scenes().next())
        .ok_or_else(|| anyhow!("{} has no scene", path.display()))?;

    let mut nodes = Vec::new();
    let mut node_slot = vec![None; document.nodes().count()];
    for node in scene.nodes() {
        let Some(mesh) = node.mesh() else { continue };
        let mut tri = TriMesh::default();
        let mut colour = Vec3::splat(0.5);
        for primitive in mesh.primitives() {
            let reader = primitive.reader(buffer);
            let base = tri.positions.len() as u32;
            let positions: Vec<[f32; 3]> = reader
                .read_positions()
                .ok_or_else(|| anyhow!("{}: a mesh without positions", path.display()))?
                .collect();
            let normals: Vec<[f32; 3]> = match reader.read_normals() {
                Some(n) => n.collect(),
                None => vec![[0.0, 1.0, 0.0]; positions.len()],
            };
            let indices: Vec<u32> = match reader.read_indices() {
                Some(i) => i.into_u32().collect(),
                None => (0..positions.len() as u32).collect(),
            };
            if normals.len() != positions.len()
                || indices.iter().any(|&i| i as usize >= positions.len())
            {
                bail!("{}: a mesh with inconsistent accessors", path.display());
            }
            tri.positions.extend(positions);
            tri.normals.extend(normals);
            tri.indices.extend(indices.into_iter().map(|i| base + i));
            let [r, g, b, _] = primitive
                .material()
                .pbr_metallic_roughness()
                .base_color_factor();
            colour = Vec3::new(r, g, b);
        }
        let (translation, rotation, _) = node.transform().decomposed();
        node_slot[node.index()] = Some(nodes.len());
        nodes.push(Node {
            mesh: tri,
            colour,
            rest: (Quat::from_array(rotation), Vec3::from(translation)),
            translations: Vec::new(),
            rotations: Vec::new(),
        });
    }
    if nodes.is_empty() {
        bail!("{} has no meshes to draw", path.display());
    }
    let mut times: Vec<f32> = Vec::new();
    if let Some(animation) = document.animations().next() {
        for channel in animation.channels() {
            let Some(slot) = node_slot[channel.target().node().index()] else {
                continue;
            };
            let reader = channel.reader(buffer);
            if times.is_empty()
                && let Some(inputs) = reader.read_inputs()
            {
                times = inputs.collect();
            }
            match reader.read_outputs() {
                Some(ReadOutputs::Translations(t)) => {
                    nodes[slot].translations = t.map(Vec3::from).collect();
                }
                Some(ReadOutputs::Rotations(r)) => {
                    nodes[slot].rotations = r.into_f32().map(Quat::from_array).collect();
                }
                _ => {}
            }
        }
    }
    let frames = times.len().max(1);

    // The camera and the ground as for a scene, from the first keyframe.
    let mut min = Vec3::splat(f32::INFINITY);
    let mut max = Vec3::splat(f32::NEG_INFINITY);
    for node in nodes.iter().filter(|n| !n.is_static()) {
        let (rotation, translation) = node.pose(0);
        for p in &node.mesh.positions {
            let w = rotation * Vec3::from(*p) + translation;
            min = min.min(w);
            max = max.max(w);
        }
    }
    if min.x > max.x {
        (min, max) = (Vec3::splat(-0.5), Vec3::splat(0.5));
    }
    let radius = (0.5 * (max - min).length()).max(0.5);
    let camera = super::checked_camera(0.5 * (min + max), radius, options)?;
    // The ground, as for a scene: the highest static node that is at least as wide as the
    // moving bodies' box and whose top is not above its bottom (the export's ground square or
    // ground box). It is not drawn; the grid stands for it.
    let mut ground: Option<(usize, f32)> = None;
    for (i, node) in nodes.iter().enumerate() {
        if !node.is_static() {
            continue;
        }
        let (rotation, translation) = node.rest;
        let world: Vec<[f32; 3]> = node
            .mesh
            .positions
            .iter()
            .map(|p| (rotation * Vec3::from(*p) + translation).to_array())
            .collect();
        let (lo, hi) = crate::export::mesh::bounds(&world);
        let wide = (hi[0] - lo[0]).min(hi[2] - lo[2]) >= (max.x - min.x).max(max.z - min.z);
        if wide && hi[1] <= min.y + 0.05 && ground.is_none_or(|(_, g)| hi[1] > g) {
            ground = Some((i, hi[1]));
        }
    }
    let bodies: Vec<DrawnBody> = nodes
        .iter()
        .enumerate()
        .map(|(i, node)| DrawnBody {
            mesh: node.mesh.clone(),
            kind: if node.is_static() {
                BodyKind::Static
            } else {
                BodyKind::Dynamic
            },
            is_ground: ground.is_some_and(|(g, _)| g == i),
        })
        .collect();
    let ground = ground.map(|(_, h)| h);
    let ground = Ground {
        height: ground.unwrap_or(min.y),
        spacing: super::grid_spacing(radius),
    };

    let delay_s = match times[..] {
        [t0, t1, ..] => (t1 - t0) as f64,
        _ => 0.1,
    };
    let mut sink = FrameSink::create(options, (delay_s * 1e3).round().max(10.0) as u32)?;
    let name = path.display().to_string();
    let bar = crate::run::progress_bar(&name, frames as u64, options.quiet);
    for k in 0..frames {
        bar.inc(1);
        let poses: Vec<(Quat, Vec3)> = nodes.iter().map(|n| n.pose(k)).collect();
        let colours: Vec<Vec3> = nodes
            .iter()
            .enumerate()
            .map(|(i, node)| match options.colour {
                ColourBy::Speed if !node.is_static() => {
                    // Speed from the keyframes on either side (m/s).
                    let (a, b) = (k.saturating_sub(1), (k + 1).min(frames - 1));
                    let dt = times
                        .get(b)
                        .zip(times.get(a))
                        .map_or(0.0, |(tb, ta)| tb - ta);
                    let speed = if dt > 0.0 {
                        (node.pose(b).1 - node.pose(a).1).length() / dt
                    } else {
                        0.0
                    };
                    super::heat((speed / options.speed_max).clamp(0.0, 1.0)) * super::tint(i)
                }
                _ => node.colour,
            })
            .collect();
        let canvas = super::draw(&bodies, &poses, &colours, &ground, &camera, options);
        sink.write(k as u64, &canvas)?;
    }
    bar.finish_and_clear();
    sink.finish()?;
    Ok(RenderSummary { frames, camera })
}
