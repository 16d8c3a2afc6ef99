//! OpenUSD ASCII (`.usda`) writer, written as text: no maintained Rust USD writer runs on the
//! workspace's toolchain.
//!
//! The stage:
//! - layer metadata: `metersPerUnit = 1`, `upAxis = "Y"`, `timeCodesPerSecond` and
//!   `framesPerSecond` = 1/dt, `startTimeCode`/`endTimeCode` = the first and last written step;
//!   time codes are step numbers, so with `--every K` the samples sit at their real times;
//! - `/World` (the default prim), an `Xform` holding one `Xform` per body, named after the body
//!   (sanitised to a USD identifier) and carrying its scene index and name in `customData`;
//! - on each body `Xform`: `xformOp:translate` (`float3`, m) and `xformOp:orient` (`quatf`,
//!   written real part first as USD does), time-sampled at every written step for moving
//!   bodies, a single default value for static ones;
//! - a child `geometry` prim of the body's shape in the body frame: `Sphere` (radius), `Cube`
//!   (size 2 with `xformOp:scale` = half extents), `Capsule` (radius, height of the cylinder
//!   part, axis Y), `Mesh` of the convex hull (flat-shaded), or, for a half-space, a large square
//!   `Mesh` through the body origin; each with `extent` and a `primvars:displayColor`.

use std::collections::HashSet;
use std::fmt::Write as _;
use std::path::Path;

use anyhow::{Context, Result};
use impulse::ShapeDesc;

use super::animation::{Animation, PoseSample, body_colours};
use super::mesh::{Hull, bounds, convex_hull, cross, ground_corners, normalize, sub};

/// Writes `animation` as a USD ASCII stage.
pub fn write_usda(animation: &Animation, path: &Path) -> Result<()> {
    std::fs::write(path, stage_text(animation)?)?;
    Ok(())
}

/// The `.usda` text of `animation`.
pub fn stage_text(animation: &Animation) -> Result<String> {
    let mut out = Usda::default();
    let first = animation.frames.first().map_or(0, |f| f.step);
    let last = animation.frames.last().map_or(0, |f| f.step);
    let fps = time_codes_per_second(animation.dt);
    out.line("#usda 1.0");
    out.open_metadata();
    out.line("defaultPrim = \"World\"");
    out.line(&format!(
        "doc = {}",
        quoted(&format!(
            "impulse {}: {} bodies, {} frames, dt = {} s",
            env!("CARGO_PKG_VERSION"),
            animation.bodies.len(),
            animation.frames.len(),
            animation.dt
        ))
    ));
    out.line("metersPerUnit = 1");
    out.line("upAxis = \"Y\"");
    out.line(&format!("timeCodesPerSecond = {fps}"));
    out.line(&format!("framesPerSecond = {fps}"));
    out.line(&format!("startTimeCode = {first}"));
    out.line(&format!("endTimeCode = {last}"));
    out.close_metadata();
    out.blank();

    out.open_prim_metadata("Xform", "World");
    out.line("customData = {");
    out.line(&format!(
        "    string scene = {}",
        quoted(&animation.scene_name)
    ));
    out.line("}");
    out.close_metadata();
    out.open_block();
    let names = prim_names(animation.bodies.iter().map(|b| b.name.as_str()));
    let colours = body_colours(&animation.bodies);
    let ground_half_size = animation.ground_half_size();
    for (i, body) in animation.bodies.iter().enumerate() {
        let poses: Vec<(u64, PoseSample)> = animation
            .frames
            .iter()
            .map(|f| (f.step, f.poses[i]))
            .collect();
        out.open_prim_metadata("Xform", &names[i]);
        out.line("customData = {");
        out.line(&format!("    int bodyIndex = {i}"));
        out.line(&format!("    string name = {}", quoted(&body.name)));
        out.line("}");
        out.close_metadata();
        out.open_block();
        transform(&mut out, &poses, body.is_static());
        out.blank();
        geometry(&mut out, &body.shape, colours[i], ground_half_size)
            .with_context(|| format!("body {i} ({})", body.name))?;
        out.close_block();
    }
    out.close_block();
    Ok(out.text)
}

/// The translate and orient ops of a body prim: time-sampled at each `(step, pose)`, or single
/// values for a static body (or a single frame).
fn transform(out: &mut Usda, poses: &[(u64, PoseSample)], is_static: bool) {
    let Some((_, first)) = poses.first() else {
        return;
    };
    if is_static || poses.len() == 1 {
        out.line(&format!(
            "float3 xformOp:translate = {}",
            vector(&first.translation)
        ));
        out.line(&format!(
            "quatf xformOp:orient = {}",
            quaternion(first.rotation)
        ));
    } else {
        out.line("float3 xformOp:translate.timeSamples = {");
        for (step, pose) in poses {
            out.line(&format!("    {step}: {},", vector(&pose.translation)));
        }
        out.line("}");
        out.line("quatf xformOp:orient.timeSamples = {");
        for (step, pose) in poses {
            out.line(&format!("    {step}: {},", quaternion(pose.rotation)));
        }
        out.line("}");
    }
    out.line("uniform token[] xformOpOrder = [\"xformOp:translate\", \"xformOp:orient\"]");
}

/// Time codes per second for time step `dt`: 1/dt, rounded to a whole number when it is one
/// up to f32 precision (dt = 1/60 s stored as f32 gives 60, not 59.999997).
pub fn time_codes_per_second(dt: f32) -> f64 {
    let exact = 1.0 / dt as f64;
    let whole = exact.round();
    if whole > 0.0 && ((exact - whole) / whole).abs() < 1e-6 {
        whole
    } else {
        exact
    }
}

/// The `geometry` child prim of a body of `shape`.
fn geometry(out: &mut Usda, shape: &ShapeDesc, colour: [f32; 3], ground: f32) -> Result<()> {
    let colour_line = format!("color3f[] primvars:displayColor = [{}]", vector(&colour));
    // A thin shape is drawn as the slab it is simulated as.
    let slab = shape.slab();
    let shape = slab.as_ref().unwrap_or(shape);
    match shape {
        ShapeDesc::Sphere { radius } => {
            out.def("Sphere", "geometry");
            out.open_block();
            out.line(&format!("double radius = {}", number(*radius)));
            out.line(&extent([-*radius; 3], [*radius; 3]));
        }
        ShapeDesc::Cuboid { half_extents } => {
            out.def("Cube", "geometry");
            out.open_block();
            out.line("double size = 2");
            out.line(&format!("float3 xformOp:scale = {}", vector(half_extents)));
            out.line("uniform token[] xformOpOrder = [\"xformOp:scale\"]");
            out.line(&extent([-1.0; 3], [1.0; 3]));
        }
        ShapeDesc::Capsule {
            half_height,
            radius,
        } => {
            out.def("Capsule", "geometry");
            out.open_block();
            out.line("uniform token axis = \"Y\"");
            out.line(&format!("double height = {}", number(2.0 * half_height)));
            out.line(&format!("double radius = {}", number(*radius)));
            let reach = half_height + radius;
            out.line(&extent(
                [-*radius, -reach, -*radius],
                [*radius, reach, *radius],
            ));
        }
        ShapeDesc::Cylinder {
            half_height,
            radius,
        }
        | ShapeDesc::Cone {
            half_height,
            radius,
        } => {
            // UsdGeomCylinder and UsdGeomCone, both centred, along Y; a cone's apex is at
            // +height/2, as Parry's.
            let prim = if matches!(shape, ShapeDesc::Cone { .. }) {
                "Cone"
            } else {
                "Cylinder"
            };
            out.def(prim, "geometry");
            out.open_block();
            out.line("uniform token axis = \"Y\"");
            out.line(&format!("double height = {}", number(2.0 * half_height)));
            out.line(&format!("double radius = {}", number(*radius)));
            out.line(&extent(
                [-*radius, -*half_height, -*radius],
                [*radius, *half_height, *radius],
            ));
        }
        ShapeDesc::ConvexHull { points } => {
            let Hull {
                vertices,
                triangles,
            } = convex_hull(points)?;
            let indices: Vec<u32> = triangles.iter().flatten().copied().collect();
            let normals: Vec<[f32; 3]> = triangles
                .iter()
                .map(|t| {
                    let [a, b, c] = t.map(|k| vertices[k as usize]);
                    normalize(cross(sub(b, a), sub(c, a)))
                })
                .collect();
            out.def("Mesh", "geometry");
            out.open_block();
            mesh_attributes(out, &vertices, 3, &indices, Some(&normals));
        }
        ShapeDesc::Trimesh { .. }
        | ShapeDesc::HeightField { .. }
        | ShapeDesc::Compound { .. }
        | ShapeDesc::Round { .. }
        | ShapeDesc::Thickened { .. } => {
            // Triangle meshes as their triangles, height fields as their grid's triangles,
            // compounds as their parts, rounded shapes approximately (export::mesh).
            let mesh = super::mesh::shape_mesh(shape, ground)?;
            let normals: Vec<[f32; 3]> = mesh
                .indices
                .chunks_exact(3)
                .map(|t| {
                    let [a, b, c] = [t[0], t[1], t[2]].map(|k| mesh.positions[k as usize]);
                    normalize(cross(sub(b, a), sub(c, a)))
                })
                .collect();
            out.def("Mesh", "geometry");
            out.open_block();
            mesh_attributes(out, &mesh.positions, 3, &mesh.indices, Some(&normals));
        }
        ShapeDesc::HalfSpace { normal } => {
            let corners = ground_corners(*normal, ground);
            out.def("Mesh", "geometry");
            out.open_block();
            // One-sided geometry: show the ground from below too.
            out.line("uniform bool doubleSided = 1");
            mesh_attributes(out, &corners, 4, &[0, 1, 2, 3], None);
        }
    }
    out.line(&colour_line);
    out.close_block();
    Ok(())
}

/// The attributes of a polygon `Mesh`: points, faces, extent and, if given, one normal per face.
fn mesh_attributes(
    out: &mut Usda,
    points: &[[f32; 3]],
    per_face: usize,
    indices: &[u32],
    face_normals: Option<&[[f32; 3]]>,
) {
    let faces = indices.len() / per_face;
    let (min, max) = bounds(points);
    out.line(&extent(min, max));
    out.line(&format!(
        "int[] faceVertexCounts = [{}]",
        vec![per_face.to_string(); faces].join(", ")
    ));
    out.line(&format!(
        "int[] faceVertexIndices = [{}]",
        indices
            .iter()
            .map(|i| i.to_string())
            .collect::<Vec<_>>()
            .join(", ")
    ));
    out.line(&format!("point3f[] points = {}", vectors(points)));
    if let Some(normals) = face_normals {
        out.line(&format!("normal3f[] normals = {} (", vectors(normals)));
        out.line("    interpolation = \"uniform\"");
        out.line(")");
    }
    out.line("uniform token subdivisionScheme = \"none\"");
}

/// Valid, distinct USD prim names for `names`: characters other than ASCII letters, digits
/// and `_` become `_`, a leading digit (or an empty name) gets a `_` in front, and a name
/// already taken gets `_2`, `_3`, … appended.
pub fn prim_names<'a>(names: impl Iterator<Item = &'a str>) -> Vec<String> {
    let mut taken = HashSet::new();
    let mut out = Vec::new();
    for name in names {
        let mut base: String = name
            .chars()
            .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
            .collect();
        if base.is_empty() || base.starts_with(|c: char| c.is_ascii_digit()) {
            base.insert(0, '_');
        }
        let mut candidate = base.clone();
        let mut n = 2;
        while taken.contains(&candidate) {
            candidate = format!("{base}_{n}");
            n += 1;
        }
        taken.insert(candidate.clone());
        out.push(candidate);
    }
    out
}

/// A `.usda` text under construction, indented by nesting.
#[derive(Default)]
struct Usda {
    text: String,
    depth: usize,
}

impl Usda {
    fn line(&mut self, line: &str) {
        for _ in 0..self.depth {
            self.text.push_str("    ");
        }
        self.text.push_str(line);
        self.text.push('\n');
    }

    fn blank(&mut self) {
        self.text.push('\n');
    }

    /// Opens the layer's metadata: `(`.
    fn open_metadata(&mut self) {
        self.line("(");
        self.depth += 1;
    }

    /// Opens a prim with metadata: `def TYPE "NAME" (`.
    fn open_prim_metadata(&mut self, type_name: &str, name: &str) {
        self.line(&format!("def {type_name} \"{name}\" ("));
        self.depth += 1;
    }

    /// Ends metadata: `)`.
    fn close_metadata(&mut self) {
        self.depth -= 1;
        self.line(")");
    }

    /// Starts a prim without metadata: `def TYPE "NAME"`; its block follows.
    fn def(&mut self, type_name: &str, name: &str) {
        self.line(&format!("def {type_name} \"{name}\""));
    }

    fn open_block(&mut self) {
        self.line("{");
        self.depth += 1;
    }

    fn close_block(&mut self) {
        self.depth -= 1;
        self.line("}");
    }
}

/// A USD string literal.
fn quoted(s: &str) -> String {
    let mut out = String::with_capacity(s.len() + 2);
    out.push('"');
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            '\n' => out.push_str("\\n"),
            c if c.is_control() => {
                let _ = write!(out, "\\x{:02x}", c as u32);
            }
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// A number as USD text: the shortest decimal that reads back as the same `f32`.
fn number(x: f32) -> String {
    if x.is_nan() {
        "nan".to_string()
    } else if x.is_infinite() {
        if x > 0.0 { "inf" } else { "-inf" }.to_string()
    } else {
        // `+ 0.0` writes -0 as 0.
        format!("{}", x + 0.0)
    }
}

/// `(x, y, z)`.
fn vector(v: &[f32; 3]) -> String {
    format!("({}, {}, {})", number(v[0]), number(v[1]), number(v[2]))
}

/// `[(x, y, z), …]`.
fn vectors(vs: &[[f32; 3]]) -> String {
    let items: Vec<String> = vs.iter().map(vector).collect();
    format!("[{}]", items.join(", "))
}

/// A `quatf` value from `[x, y, z, w]`: USD writes the real part first, `(w, x, y, z)`.
fn quaternion(q: [f32; 4]) -> String {
    format!(
        "({}, {}, {}, {})",
        number(q[3]),
        number(q[0]),
        number(q[1]),
        number(q[2])
    )
}

fn extent(min: [f32; 3], max: [f32; 3]) -> String {
    format!("float3[] extent = [{}, {}]", vector(&min), vector(&max))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn prim_names_are_identifiers_and_distinct() {
        let names =
            prim_names(["ground", "left ball", "3", "", "a.b", "a_b", "ground"].into_iter());
        assert_eq!(
            names,
            ["ground", "left_ball", "_3", "_", "a_b", "a_b_2", "ground_2"]
        );
    }

    #[test]
    fn strings_and_quaternions_in_usd_syntax() {
        assert_eq!(quoted("a \"b\" \\ c"), r#""a \"b\" \\ c""#);
        assert_eq!(quaternion([0.0, 0.5, 0.0, 0.75]), "(0.75, 0, 0.5, 0)");
        assert_eq!(number(f32::NAN), "nan");
    }
}
