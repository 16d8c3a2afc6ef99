//! Bad meshes, height fields, compounds and rounded shapes (degenerate or missing meshes,
//! meshes on moving bodies): each refused with the file, line, body and field, never a panic.

use crate::meshes::scratch;
use impulse::World;
use impulse::scene::{
    BodyDesc, BodyKind, SceneErrorKind, ShapeDesc, load_scene_file, parse_scene_str,
};

/// A scene whose body 1 (`"thing"`, on line 4) is `body`, in a file `name.json` of a scratch
/// directory holding `extra` files too; the error of loading it.
fn load_error(name: &str, body: &str, extra: &[(&str, &[u8])]) -> impulse::scene::SceneError {
    let dir = scratch(name);
    for (file, content) in extra {
        std::fs::write(dir.join(file), content).unwrap();
    }
    let text = format!(
        "{{\n  \"bodies\": [\n    {{\"kind\": \"static\", \"shape\": {{\"type\": \"half_space\", \"normal\": [0, 1, 0]}}}},\n    {{\"name\": \"thing\", {body}}}\n  ]\n}}\n"
    );
    let path = dir.join(format!("{name}.json"));
    std::fs::write(&path, text).unwrap();
    let error = load_scene_file(&path).expect_err("the scene must be refused");
    let _ = std::fs::remove_dir_all(dir);
    error
}

fn check(error: &impulse::scene::SceneError, field: &str, message: &str) {
    let text = error.to_string();
    assert_eq!(error.kind, SceneErrorKind::Invalid, "{text}");
    assert_eq!(
        error.field.as_ref().map(ToString::to_string).as_deref(),
        Some(field),
        "{text}"
    );
    assert_eq!(error.body.as_ref().map(|b| b.index), Some(1), "{text}");
    assert_eq!(error.line(), Some(4), "{text}");
    assert!(error.origin.is_some(), "{text}");
    assert!(
        error.message.contains(message),
        "{text}\nshould contain: {message}"
    );
    assert!(text.contains("(\"thing\")"), "{text}");
}

const TRIANGLE: &str = r#""vertices": [[0, 0, 0], [1, 0, 0], [0, 0, 1]], "indices": [[0, 2, 1]]"#;

/// A moving body's mesh is decomposed into convex parts: a flat one (one triangle) has none.
#[test]
fn a_flat_trimesh_on_a_moving_body_is_refused() {
    let error = load_error(
        "dynamic-mesh",
        &format!(r#""kind": "dynamic", "shape": {{"type": "trimesh", {TRIANGLE}}}"#),
        &[],
    );
    check(
        &error,
        "bodies[1].shape.vertices",
        "a moving body's trimesh is decomposed into convex parts and must enclose a volume",
    );
}

#[test]
fn a_trimesh_on_a_particle_is_refused() {
    let error = load_error(
        "particle-mesh",
        &format!(r#""kind": "particle", "shape": {{"type": "trimesh", {TRIANGLE}}}"#),
        &[],
    );
    check(
        &error,
        "bodies[1].shape.type",
        "a particle must have a sphere shape, got trimesh",
    );
}

#[test]
fn a_heightfield_on_a_moving_body_is_refused() {
    let error = load_error(
        "dynamic-field",
        r#""kind": "dynamic", "shape": {"type": "heightfield", "heights": [[0, 0], [0, 0]], "scale": [1, 1, 1]}"#,
        &[],
    );
    check(
        &error,
        "bodies[1].shape.type",
        "a heightfield shape is only allowed on a static body",
    );
}

#[test]
fn a_missing_mesh_file_is_refused() {
    let error = load_error(
        "missing-mesh",
        r#""kind": "static", "shape": {"type": "trimesh", "file": "nowhere.obj"}"#,
        &[],
    );
    check(&error, "bodies[1].shape.file", "cannot read");
    assert!(error.message.contains("nowhere.obj"), "{error}");
}

#[test]
fn a_corrupt_obj_file_is_refused() {
    let error = load_error(
        "corrupt-obj",
        r#""kind": "static", "shape": {"type": "trimesh", "file": "bad.obj"}"#,
        &[("bad.obj", b"v 0 0 0\nv 1 0 x\nf 1 2 3\n")],
    );
    check(&error, "bodies[1].shape.file", "not a valid OBJ file");
}

#[test]
fn a_corrupt_gltf_file_is_refused() {
    let error = load_error(
        "corrupt-gltf",
        r#""kind": "static", "shape": {"type": "trimesh", "file": "bad.glb"}"#,
        &[("bad.glb", b"glTF\x02\0\0\0 truncated")],
    );
    check(&error, "bodies[1].shape.file", "not a valid glTF file");
}

#[test]
fn a_mesh_file_of_unknown_type_is_refused() {
    let error = load_error(
        "stl-mesh",
        r#""kind": "static", "shape": {"type": "trimesh", "file": "part.stl"}"#,
        &[("part.stl", b"solid x\nendsolid x\n")],
    );
    check(&error, "bodies[1].shape.file", "allowed: .obj");
}

#[test]
fn an_obj_file_without_triangles_is_refused() {
    let error = load_error(
        "empty-obj",
        r#""kind": "static", "shape": {"type": "trimesh", "file": "points.obj"}"#,
        &[("points.obj", b"v 0 0 0\nv 1 0 0\n")],
    );
    check(&error, "bodies[1].shape.file", "the file has no faces");
}

#[test]
fn a_mesh_file_with_a_degenerate_triangle_is_refused() {
    let error = load_error(
        "flat-obj",
        r#""kind": "static", "shape": {"type": "trimesh", "file": "line.obj"}"#,
        &[(
            "line.obj",
            b"v 0 0 0\nv 1 0 0\nv 0 0 1\nv 2 0 0\nf 1 3 2\nf 1 2 4\n",
        )],
    );
    check(
        &error,
        "bodies[1].shape.file",
        "has no area: its corners coincide or are collinear",
    );
}

#[test]
fn an_inline_mesh_with_an_index_out_of_range_is_refused() {
    let error = load_error(
        "index-range",
        r#""kind": "static", "shape": {"type": "trimesh", "vertices": [[0, 0, 0], [1, 0, 0], [0, 0, 1]], "indices": [[0, 2, 1], [0, 1, 3]]}"#,
        &[],
    );
    check(
        &error,
        "bodies[1].shape.indices[1]",
        "triangle 1 refers to vertex 3, but there are 3 vertices",
    );
}

#[test]
fn a_trimesh_with_both_file_and_vertices_is_refused() {
    let error = load_error(
        "both-sources",
        &format!(
            r#""kind": "static", "shape": {{"type": "trimesh", "file": "t.obj", {TRIANGLE}}}"#
        ),
        &[("t.obj", b"v 0 0 0\nv 1 0 0\nv 0 0 1\nf 1 3 2\n")],
    );
    check(&error, "bodies[1].shape.file", "not both");
}

#[test]
fn a_ragged_heightfield_is_refused() {
    let error = load_error(
        "ragged-field",
        r#""kind": "static", "shape": {"type": "heightfield", "heights": [[0, 0, 0], [0, 0]], "scale": [1, 1, 1]}"#,
        &[],
    );
    check(
        &error,
        "bodies[1].shape.heights[1]",
        "the same number of heights as the first (3), got 2",
    );
}

#[test]
fn a_compound_of_a_mesh_is_refused() {
    let error = load_error(
        "compound-mesh",
        &format!(
            r#""kind": "dynamic", "shape": {{"type": "compound", "parts": [{{"shape": {{"type": "trimesh", {TRIANGLE}}}}}]}}"#
        ),
        &[],
    );
    check(
        &error,
        "bodies[1].shape.parts[0].shape.type",
        "a compound part must be a sphere, cuboid, capsule, cylinder, cone or convex_hull, got trimesh",
    );
}

#[test]
fn a_negative_border_radius_is_refused() {
    let error = load_error(
        "border",
        r#""kind": "dynamic", "shape": {"type": "cuboid", "half_extents": [1, 1, 1], "border_radius": -0.1}"#,
        &[],
    );
    check(
        &error,
        "bodies[1].shape.border_radius",
        "must be > 0, got -0.1",
    );
}

/// Each size within bounds, but a compound part 900 km out and 200 km long reaches beyond
/// 1,000 km of the body's origin: refused at the shape, with the reach; a mesh vertex beyond
/// it likewise.
#[test]
fn a_shape_reaching_beyond_1000_km_is_refused() {
    let error = load_error(
        "reach",
        r#""kind": "dynamic", "shape": {"type": "compound", "parts": [{"shape": {"type": "cuboid", "half_extents": [2e5, 1, 1]}, "position": [9e5, 0, 0]}]}"#,
        &[],
    );
    check(
        &error,
        "bodies[1].shape",
        "the shape reaches 1100000 m from the body's origin; at most 1000000 m",
    );
    let error = load_error(
        "far_vertex",
        r#""kind": "static", "shape": {"type": "trimesh", "vertices": [[0, 0, 0], [2e6, 0, 0], [0, 0, 1]], "indices": [[0, 2, 1]]}"#,
        &[],
    );
    check(&error, "bodies[1].shape", "the shape reaches 2000000 m");
}

/// The library refuses the same shapes when a world is built from a scene made in code (not
/// validated): a typed error, no panic.
#[test]
fn world_from_an_unvalidated_scene_refuses_bad_meshes() {
    let mut scene = parse_scene_str(r#"{"bodies": []}"#, "code").unwrap();
    scene.bodies.push(BodyDesc::new(
        BodyKind::Static,
        ShapeDesc::trimesh(
            vec![[0.0; 3], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]],
            vec![[0, 1, 2]],
        ),
        [0.0; 3],
    ));
    let error = World::from_scene(&scene).err().expect("a degenerate mesh");
    assert!(error.to_string().contains("has no area"), "{error}");
    scene.bodies[0].shape = ShapeDesc::trimesh_file("/no/such/mesh.obj");
    let error = World::from_scene(&scene)
        .err()
        .expect("a missing mesh file");
    assert!(error.to_string().contains("shape.file"), "{error}");
    scene.bodies[0].shape = ShapeDesc::Compound { parts: Vec::new() };
    let error = World::from_scene(&scene).err().expect("an empty compound");
    assert!(error.to_string().contains("at least one part"), "{error}");
}

/// A named mesh: its name, positions and triangles.
type NamedMesh<'a> = (&'a str, Vec<[f32; 3]>, Vec<[u32; 3]>);

/// A glTF file (JSON, one data-URI buffer) of one mesh per entry of `meshes` (indices as
/// 32-bit integers).
fn gltf_of(meshes: &[NamedMesh<'_>]) -> String {
    use base64::Engine as _;
    let (mut bin, mut views, mut accessors, mut json_meshes, mut nodes) =
        (Vec::<u8>::new(), vec![], vec![], vec![], vec![]);
    for (m, (name, positions, triangles)) in meshes.iter().enumerate() {
        let start = bin.len();
        for p in positions {
            for x in p {
                bin.extend(x.to_le_bytes());
            }
        }
        views.push(
            serde_json::json!({"buffer": 0, "byteOffset": start, "byteLength": bin.len() - start}),
        );
        // glTF asks for the bounds of positions; a NaN coordinate is left out of them.
        let bound = |pick: fn(f32, f32) -> f32, from: f32| {
            (0..3)
                .map(|k| {
                    positions
                        .iter()
                        .map(|p| p[k])
                        .filter(|x| x.is_finite())
                        .fold(from, pick)
                })
                .collect::<Vec<f32>>()
        };
        accessors.push(serde_json::json!({"bufferView": views.len() - 1, "componentType": 5126, "count": positions.len(), "type": "VEC3", "min": bound(f32::min, f32::MAX), "max": bound(f32::max, f32::MIN)}));
        let start = bin.len();
        for t in triangles {
            for i in t {
                bin.extend(i.to_le_bytes());
            }
        }
        views.push(
            serde_json::json!({"buffer": 0, "byteOffset": start, "byteLength": bin.len() - start}),
        );
        accessors.push(serde_json::json!({"bufferView": views.len() - 1, "componentType": 5125, "count": 3 * triangles.len(), "type": "SCALAR"}));
        json_meshes.push(serde_json::json!({"name": name, "primitives": [{"attributes": {"POSITION": accessors.len() - 2}, "indices": accessors.len() - 1}]}));
        nodes.push(serde_json::json!({"mesh": m}));
    }
    let uri = format!(
        "data:application/octet-stream;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(&bin)
    );
    serde_json::json!({
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": (0..meshes.len()).collect::<Vec<_>>()}],
        "nodes": nodes,
        "meshes": json_meshes,
        "buffers": [{"byteLength": bin.len(), "uri": uri}],
        "bufferViews": views,
        "accessors": accessors,
    })
    .to_string()
}

/// A glTF vertex that is not finite, or a triangle without area, is refused naming the mesh,
/// the primitive, the accessor and the element a modelling tool wrote, not only its place in
/// the merged mesh.
#[test]
fn gltf_geometry_errors_name_the_accessor_and_element() {
    let square = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 0.0, 1.0],
        [0.0, 0.0, 1.0],
    ];
    let good = ("Floor", square.clone(), vec![[0, 1, 2], [0, 2, 3]]);
    let mut nan = square.clone();
    nan[2][1] = f32::NAN;
    let cases = [
        (
            ("Lid", nan, vec![[0, 1, 2]]),
            "mesh 1 (\"Lid\") primitive 0, POSITION accessor 2 element 2",
        ),
        (
            ("Handle", square, vec![[0, 1, 2], [1, 1, 3]]),
            "mesh 1 (\"Handle\") primitive 0, triangle 1 of the primitive (indices accessor 3, POSITION accessor 2)",
        ),
    ];
    for (bad, expected) in cases {
        let text = gltf_of(&[good.clone(), bad]);
        let error = load_error(
            "gltf-geometry",
            r#""kind": "static", "shape": {"type": "trimesh", "file": "part.gltf"}"#,
            &[("part.gltf", text.as_bytes())],
        );
        check(&error, "bodies[1].shape.file", expected);
        assert!(error.message.contains("part.gltf"), "{}", error.message);
    }
    // The same meshes without the fault are read.
    let text = gltf_of(&[good.clone(), good]);
    let mesh = impulse::scene::read_mesh_bytes(
        text.as_bytes(),
        impulse::scene::MeshFormat::Gltf,
        "part.gltf",
        None,
    )
    .unwrap();
    assert_eq!(mesh.indices.len(), 4);
}

/// An OBJ face without area, or a vertex that is not finite, is refused naming the file's line
/// it is on, although the reader renumbers vertices and regroups faces by object.
#[test]
fn obj_geometry_errors_name_the_line() {
    let degenerate = b"o floor\nv 0 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 1\nf 1 2 3\nf 1 3 4\no lid\nv 0 1 0\nv 1 1 0\nv 2 1 0\nf -3 -2 -1\n";
    let error = load_error(
        "obj-degenerate",
        r#""kind": "static", "shape": {"type": "trimesh", "file": "part.obj"}"#,
        &[("part.obj", degenerate)],
    );
    check(
        &error,
        "bodies[1].shape.file",
        "line 12 (\"f -3 -2 -1\"): triangle 2",
    );
    let not_finite = b"v 0 0 0\nv 1 0 0\nv 1 inf 1\nf 1 2 3\n";
    let error = load_error(
        "obj-not-finite",
        r#""kind": "static", "shape": {"type": "trimesh", "file": "part.obj"}"#,
        &[("part.obj", not_finite)],
    );
    check(&error, "bodies[1].shape.file", "line 3");
}
