//! glTF 2.0 writer: one node and one mesh per body, one animation for the moving bodies.
//!
//! Layout of the document:
//! - one scene whose root nodes are the bodies, in scene order, named after them; each node's
//!   own translation and rotation are the body's pose at the first frame;
//! - one mesh per body (named like it), one triangle primitive with `POSITION`, `NORMAL`,
//!   `u32` indices and a material: a base colour from a small palette per dynamic body, grey
//!   for static bodies; bodies of the same shape share those accessors;
//! - one animation (`"trajectory"`) with a `translation` and a `rotation` channel per non-static
//!   body, linear interpolation, all sharing one input accessor of frame times in seconds;
//! - one buffer holding all of it, in the GLB BIN chunk or as a base64 data URI.
//!
//! Units are metres and seconds, y up, as glTF specifies and the engine uses.

use std::collections::{BTreeMap, HashMap};
use std::path::Path;

use anyhow::{Context, Result};
use base64::Engine as _;
use gltf::json;
use json::validation::{Checked::Valid, USize64};

use super::animation::{Animation, PALETTE, STATIC_GREY, palette_indices};
use super::mesh::shape_mesh;

/// Writes `animation` as binary glTF (`.glb`).
pub fn write_glb(animation: &Animation, path: &Path) -> Result<()> {
    let (root, bin) = document(animation)?;
    let json = json::serialize::to_vec(&root).context("cannot serialise the glTF JSON")?;
    let glb = gltf::binary::Glb {
        header: gltf::binary::Header {
            magic: *b"glTF",
            version: 2,
            // Computed by the writer.
            length: 0,
        },
        json: json.into(),
        bin: Some(bin.into()),
    };
    let file = std::fs::File::create(path)?;
    glb.to_writer(std::io::BufWriter::new(file))
        .context("cannot write the GLB container")?;
    Ok(())
}

/// Writes `animation` as glTF JSON (`.gltf`) with the buffer embedded as a base64 data URI.
pub fn write_gltf(animation: &Animation, path: &Path) -> Result<()> {
    let (mut root, bin) = document(animation)?;
    let uri = format!(
        "data:application/octet-stream;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(&bin)
    );
    root.buffers[0].uri = Some(uri);
    let text = json::serialize::to_string_pretty(&root).context("cannot serialise the glTF")?;
    std::fs::write(path, text + "\n")?;
    Ok(())
}

/// Builds the glTF document and its one buffer (no URI: the caller places it).
fn document(animation: &Animation) -> Result<(json::Root, Vec<u8>)> {
    let mut root = json::Root {
        asset: json::Asset {
            generator: Some(format!("impulse {}", env!("CARGO_PKG_VERSION"))),
            ..Default::default()
        },
        ..Default::default()
    };
    let mut buffer = BufferBuilder::default();
    // Materials are made on first use: a glTF validator flags unused ones.
    let mut materials: BTreeMap<Option<usize>, json::Index<json::Material>> = BTreeMap::new();
    let palette = palette_indices(&animation.bodies);
    type Accessor = json::Index<json::Accessor>;
    let mut geometry: HashMap<String, (Accessor, Accessor, Accessor)> = HashMap::new();
    let ground_half_size = animation.ground_half_size();
    let first = animation.frames.first();
    let mut nodes = Vec::with_capacity(animation.bodies.len());
    for (i, body) in animation.bodies.iter().enumerate() {
        // Bodies of the same shape share the vertex data (each still has its own mesh).
        let key = format!("{:?}", body.shape);
        let (positions, normals, indices) = match geometry.get(&key) {
            Some(&accessors) => accessors,
            None => {
                let mesh = shape_mesh(&body.shape, ground_half_size)
                    .with_context(|| format!("body {i} ({})", body.name))?;
                let (min, max) = mesh.bounds();
                let accessors = (
                    buffer.accessor(
                        &mut root,
                        &mesh.positions,
                        Some(json::buffer::Target::ArrayBuffer),
                        Some((min.to_vec(), max.to_vec())),
                    ),
                    buffer.accessor(
                        &mut root,
                        &mesh.normals,
                        Some(json::buffer::Target::ArrayBuffer),
                        None,
                    ),
                    buffer.indices(&mut root, &mesh.indices),
                );
                geometry.insert(key, accessors);
                accessors
            }
        };
        let material = *materials
            .entry(palette[i])
            .or_insert_with(|| match palette[i] {
                Some(k) => root.push(material(&format!("moving_{k}"), PALETTE[k])),
                None => root.push(material("static", STATIC_GREY)),
            });
        let primitive = json::mesh::Primitive {
            attributes: BTreeMap::from([
                (Valid(json::mesh::Semantic::Positions), positions),
                (Valid(json::mesh::Semantic::Normals), normals),
            ]),
            extensions: None,
            extras: Default::default(),
            indices: Some(indices),
            material: Some(material),
            mode: Valid(json::mesh::Mode::Triangles),
            targets: None,
        };
        let mesh = root.push(json::Mesh {
            extensions: None,
            extras: Default::default(),
            name: Some(body.name.clone()),
            primitives: vec![primitive],
            weights: None,
        });
        let pose = first.map(|f| f.poses[i]);
        nodes.push(root.push(json::Node {
            mesh: Some(mesh),
            name: Some(body.name.clone()),
            translation: pose.map(|p| p.translation),
            rotation: pose.map(|p| json::scene::UnitQuaternion(unit(p.rotation))),
            ..Default::default()
        }));
    }
    let scene = root.push(json::Scene {
        extensions: None,
        extras: Default::default(),
        name: Some(scene_name(animation)),
        nodes: nodes.clone(),
    });
    root.scene = Some(scene);
    trajectory(animation, &nodes, &mut root, &mut buffer);

    let bin = buffer.data;
    root.push(json::Buffer {
        byte_length: USize64::from(bin.len()),
        extensions: None,
        extras: Default::default(),
        name: None,
        uri: None,
    });
    Ok((root, bin))
}

/// Adds the animation: translation and rotation samplers of every non-static body over all
/// frames. Nothing is added when no body moves or there are no frames (glTF allows no
/// animation without channels).
fn trajectory(
    animation: &Animation,
    nodes: &[json::Index<json::Node>],
    root: &mut json::Root,
    buffer: &mut BufferBuilder,
) {
    let moving: Vec<usize> = (0..animation.bodies.len())
        .filter(|&i| !animation.bodies[i].is_static())
        .collect();
    if moving.is_empty() || animation.frames.is_empty() {
        return;
    }
    let times: Vec<[f32; 1]> = animation
        .frames
        .iter()
        .map(|f| [f.time(animation.dt) as f32])
        .collect();
    let (tmin, tmax) = bounds_1(&times);
    let input = buffer.accessor(root, &times, None, Some((vec![tmin], vec![tmax])));
    let mut channels = Vec::new();
    let mut samplers = Vec::new();
    for i in moving {
        let translations: Vec<[f32; 3]> = animation
            .frames
            .iter()
            .map(|f| f.poses[i].translation)
            .collect();
        let rotations: Vec<[f32; 4]> = animation
            .frames
            .iter()
            .map(|f| unit(f.poses[i].rotation))
            .collect();
        let outputs = [
            (
                json::animation::Property::Translation,
                buffer.accessor(root, &translations, None, None),
            ),
            (
                json::animation::Property::Rotation,
                buffer.accessor(root, &rotations, None, None),
            ),
        ];
        for (property, output) in outputs {
            let sampler = json::Index::new(samplers.len() as u32);
            samplers.push(json::animation::Sampler {
                extensions: None,
                extras: Default::default(),
                input,
                interpolation: Valid(json::animation::Interpolation::Linear),
                output,
            });
            channels.push(json::animation::Channel {
                sampler,
                target: json::animation::Target {
                    extensions: None,
                    extras: Default::default(),
                    node: nodes[i],
                    path: Valid(property),
                },
                extensions: None,
                extras: Default::default(),
            });
        }
    }
    root.push(json::Animation {
        extensions: None,
        extras: Default::default(),
        channels,
        name: Some("trajectory".to_string()),
        samplers,
    });
}

/// The scene's name, or `impulse` when it has none.
fn scene_name(animation: &Animation) -> String {
    if animation.scene_name.is_empty() {
        "impulse".to_string()
    } else {
        animation.scene_name.clone()
    }
}

/// A rough, non-metallic material of base colour `rgb`.
fn material(name: &str, rgb: [f32; 3]) -> json::Material {
    json::Material {
        name: Some(name.to_string()),
        pbr_metallic_roughness: json::material::PbrMetallicRoughness {
            base_color_factor: json::material::PbrBaseColorFactor([rgb[0], rgb[1], rgb[2], 1.0]),
            metallic_factor: json::material::StrengthFactor(0.0),
            roughness_factor: json::material::StrengthFactor(0.8),
            ..Default::default()
        },
        // The ground square is one-sided geometry; show it from below too.
        double_sided: true,
        ..Default::default()
    }
}

/// `q` scaled to unit length (quaternions drift from it in f32 arithmetic; glTF requires it).
fn unit(q: [f32; 4]) -> [f32; 4] {
    let length = q.iter().map(|c| c * c).sum::<f32>().sqrt();
    if length > 0.0 && length.is_finite() {
        q.map(|c| c / length)
    } else {
        [0.0, 0.0, 0.0, 1.0]
    }
}

fn bounds_1(values: &[[f32; 1]]) -> (f32, f32) {
    values
        .iter()
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v[0]), hi.max(v[0]))
        })
}

/// Appends typed arrays to the one buffer, each in its own buffer view (4-byte aligned, as
/// every component here is 4 bytes).
#[derive(Default)]
struct BufferBuilder {
    data: Vec<u8>,
}

/// Element types written as `f32` accessors: `[f32; N]` for N = 1 (SCALAR), 3 (VEC3), 4 (VEC4).
trait Element: Copy {
    const TYPE: json::accessor::Type;
    fn components(&self) -> &[f32];
}

impl Element for [f32; 1] {
    const TYPE: json::accessor::Type = json::accessor::Type::Scalar;
    fn components(&self) -> &[f32] {
        self
    }
}

impl Element for [f32; 3] {
    const TYPE: json::accessor::Type = json::accessor::Type::Vec3;
    fn components(&self) -> &[f32] {
        self
    }
}

impl Element for [f32; 4] {
    const TYPE: json::accessor::Type = json::accessor::Type::Vec4;
    fn components(&self) -> &[f32] {
        self
    }
}

impl BufferBuilder {
    /// A buffer view over `bytes`, appended to the buffer.
    fn view(
        &mut self,
        root: &mut json::Root,
        bytes: &[u8],
        target: Option<json::buffer::Target>,
    ) -> json::Index<json::buffer::View> {
        let offset = self.data.len();
        self.data.extend_from_slice(bytes);
        root.push(json::buffer::View {
            buffer: json::Index::new(0),
            byte_length: USize64::from(bytes.len()),
            byte_offset: Some(USize64::from(offset)),
            byte_stride: None,
            name: None,
            target: target.map(Valid),
            extensions: None,
            extras: Default::default(),
        })
    }

    /// An `f32` accessor over `values`, with `min`/`max` when given (required for positions
    /// and animation inputs).
    fn accessor<T: Element>(
        &mut self,
        root: &mut json::Root,
        values: &[T],
        target: Option<json::buffer::Target>,
        min_max: Option<(Vec<f32>, Vec<f32>)>,
    ) -> json::Index<json::Accessor> {
        let bytes: Vec<u8> = values
            .iter()
            .flat_map(|v| v.components().iter().flat_map(|c| c.to_le_bytes()))
            .collect();
        let view = self.view(root, &bytes, target);
        let (min, max) = match min_max {
            Some((min, max)) => (Some(json::Value::from(min)), Some(json::Value::from(max))),
            None => (None, None),
        };
        root.push(json::Accessor {
            buffer_view: Some(view),
            byte_offset: None,
            count: USize64::from(values.len()),
            component_type: Valid(json::accessor::GenericComponentType(
                json::accessor::ComponentType::F32,
            )),
            extensions: None,
            extras: Default::default(),
            type_: Valid(T::TYPE),
            min,
            max,
            name: None,
            normalized: false,
            sparse: None,
        })
    }

    /// A `u32` index accessor over `indices`.
    fn indices(&mut self, root: &mut json::Root, indices: &[u32]) -> json::Index<json::Accessor> {
        let bytes: Vec<u8> = indices.iter().flat_map(|i| i.to_le_bytes()).collect();
        let view = self.view(root, &bytes, Some(json::buffer::Target::ElementArrayBuffer));
        root.push(json::Accessor {
            buffer_view: Some(view),
            byte_offset: None,
            count: USize64::from(indices.len()),
            component_type: Valid(json::accessor::GenericComponentType(
                json::accessor::ComponentType::U32,
            )),
            extensions: None,
            extras: Default::default(),
            type_: Valid(json::accessor::Type::Scalar),
            min: None,
            max: None,
            name: None,
            normalized: false,
            sparse: None,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::export::{BodyInfo, Frame, PoseSample};
    use impulse::{BodyKind, ShapeDesc};

    #[test]
    fn a_scene_without_moving_bodies_has_no_animation() {
        let animation = Animation {
            scene_name: String::new(),
            dt: 0.01,
            bodies: vec![BodyInfo {
                name: "ground".into(),
                kind: BodyKind::Static,
                shape: ShapeDesc::HalfSpace {
                    normal: [0.0, 1.0, 0.0],
                },
            }],
            frames: vec![Frame {
                step: 0,
                poses: vec![PoseSample {
                    translation: [0.0; 3],
                    rotation: [0.0, 0.0, 0.0, 1.0],
                }],
            }],
        };
        let (root, bin) = document(&animation).unwrap();
        assert!(root.animations.is_empty());
        assert_eq!(root.nodes.len(), 1);
        assert_eq!(root.buffers[0].byte_length.0 as usize, bin.len());
        assert_eq!(bin.len() % 4, 0);
    }
}
