//! Malformed scenes are rejected with errors that name the file, line, body and field; the
//! locator finds nested paths in a realistic file.

use std::path::Path;

use impulse::scene::{
    FieldPath, SceneError, SceneErrorKind, builtin_scene, load_scene_file, locate, locate_closest,
    parse_scene_str, to_json_string,
};
/// A scene whose body 2 ("lid") starts on line 8; its fields are on lines 9–13:
/// name 9, kind 10, shape 11, position 12, material 13 (+ `extra` after it).
struct Bad<'a> {
    dt: &'a str,
    materials: &'a str,
    kind: &'a str,
    shape: &'a str,
    position: &'a str,
    material: &'a str,
    extra: &'a str,
}

impl Default for Bad<'_> {
    fn default() -> Self {
        Self {
            dt: "0.01",
            materials: r#"{"rubber": {"friction": 0.9, "restitution": 0.5}}"#,
            kind: "dynamic",
            shape: r#"{"type": "sphere", "radius": 0.5}"#,
            position: "[0, 2, 0]",
            material: r#""rubber""#,
            extra: "",
        }
    }
}

impl Bad<'_> {
    fn text(&self) -> String {
        format!(
            r#"{{
  "name": "bad",
  "dt": {},
  "materials": {},
  "bodies": [
    {{"name": "ground", "kind": "static", "shape": {{"type": "cuboid", "half_extents": [50, 0.5, 50]}}, "position": [0, -0.5, 0]}},
    {{"kind": "dynamic", "shape": {{"type": "sphere", "radius": 0.5}}, "position": [0, 0.5, 0]}},
    {{
      "name": "lid",
      "kind": "{}",
      "shape": {},
      "position": {},
      "material": {}{}
    }}
  ]
}}
"#,
            self.dt,
            self.materials,
            self.kind,
            self.shape,
            self.position,
            self.material,
            self.extra
        )
    }
}

/// Writes `text` to a file named after `case` and loads it; returns the error and the path.
/// The file is in a directory of its own, removed after the load.
fn load_err(case: &str, text: &str) -> (SceneError, String) {
    static CALLS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let call = CALLS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let dir =
        std::env::temp_dir().join(format!("impulse-scene-files-{}-{call}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(format!("{case}.json"));
    std::fs::write(&path, text).unwrap();
    let result = load_scene_file(&path);
    let _ = std::fs::remove_dir_all(&dir);
    match result {
        Ok(_) => panic!("{case}: loaded although malformed:\n{text}"),
        Err(e) => (e, path.display().to_string()),
    }
}

/// Checks a malformed case: kind, line, column, body, field path and message.
#[allow(clippy::too_many_arguments)]
fn check(
    case: &str,
    text: &str,
    kind: SceneErrorKind,
    line: usize,
    column: usize,
    body: Option<(usize, Option<&str>)>,
    field: &str,
    message: &str,
) {
    let (e, path) = load_err(case, text);
    let shown = e.to_string();
    assert_eq!(e.kind, kind, "{case}: {shown}");
    assert_eq!(e.origin.as_deref(), Some(path.as_str()), "{case}: {shown}");
    assert_eq!(
        (e.line(), e.column()),
        (Some(line), Some(column)),
        "{case}: {shown}"
    );
    assert_eq!(
        e.body.as_ref().map(|b| (b.index, b.name.as_deref())),
        body,
        "{case}: {shown}"
    );
    assert_eq!(
        e.field.as_ref().map(ToString::to_string).as_deref(),
        Some(field),
        "{case}: {shown}"
    );
    assert!(e.message.contains(message), "{case}: {shown}");
    // The rendered message names all of it.
    let shown_field = match body {
        Some((i, Some(name))) => field.replacen(
            &format!("bodies[{i}]"),
            &format!("bodies[{i}] ({name:?})"),
            1,
        ),
        _ => field.to_string(),
    };
    let expected_start = format!("{path}:{line}:{column}: {shown_field}: ");
    assert!(
        shown.starts_with(&expected_start),
        "{case}: {shown:?} should start with {expected_start:?}"
    );
}

const LID: Option<(usize, Option<&str>)> = Some((2, Some("lid")));

#[test]
fn baseline_of_malformed_cases_is_valid() {
    parse_scene_str(&Bad::default().text(), "baseline").unwrap();
}

#[test]
fn unknown_field_in_a_body() {
    let text = Bad {
        extra: ",\n      \"colour\": \"red\"",
        ..Bad::default()
    }
    .text();
    check(
        "unknown-field",
        &text,
        SceneErrorKind::Structure,
        14,
        14,
        LID,
        "bodies[2].colour",
        "unknown field `colour`",
    );
}

#[test]
fn wrong_type() {
    let text = Bad {
        position: r#"[0, "two", 0]"#,
        ..Bad::default()
    }
    .text();
    check(
        "wrong-type",
        &text,
        SceneErrorKind::Structure,
        12,
        27,
        LID,
        "bodies[2].position[1]",
        "invalid type: string \"two\", expected f32",
    );
}

#[test]
fn missing_field() {
    let text = Bad::default()
        .text()
        .replace("      \"kind\": \"dynamic\",\n", "");
    check(
        "missing-field",
        &text,
        SceneErrorKind::Structure,
        13,
        5,
        LID,
        "bodies[2]",
        "missing field `kind`",
    );
}

#[test]
fn bad_enum_value() {
    let text = Bad {
        kind: "ghost",
        ..Bad::default()
    }
    .text();
    check(
        "bad-kind",
        &text,
        SceneErrorKind::Structure,
        10,
        21,
        LID,
        "bodies[2].kind",
        "unknown variant `ghost`",
    );
}

#[test]
fn negative_radius() {
    let text = Bad {
        shape: r#"{"type": "sphere", "radius": -0.5}"#,
        ..Bad::default()
    }
    .text();
    check(
        "negative-radius",
        &text,
        SceneErrorKind::Invalid,
        11,
        45,
        LID,
        "bodies[2].shape.radius",
        "must be > 0, got -0.5",
    );
}

/// One zero half extent is a flat box (a thin shape); two make a line.
#[test]
fn two_zero_half_extents() {
    let text = Bad {
        shape: r#"{"type": "cuboid", "half_extents": [0.5, 0, 0]}"#,
        ..Bad::default()
    }
    .text();
    check(
        "zero-half-extents",
        &text,
        SceneErrorKind::Invalid,
        11,
        51,
        LID,
        "bodies[2].shape.half_extents",
        "a cuboid needs at least two half extents > 0",
    );
}

#[test]
fn negative_capsule_half_height() {
    let text = Bad {
        shape: r#"{"type": "capsule", "half_height": -1, "radius": 0.5}"#,
        ..Bad::default()
    }
    .text();
    check(
        "capsule",
        &text,
        SceneErrorKind::Invalid,
        11,
        51,
        LID,
        "bodies[2].shape.half_height",
        "must be ≥ 0, got -1",
    );
}

#[test]
fn negative_mass() {
    let text = Bad {
        extra: ",\n      \"mass\": -2",
        ..Bad::default()
    }
    .text();
    check(
        "negative-mass",
        &text,
        SceneErrorKind::Invalid,
        14,
        15,
        LID,
        "bodies[2].mass",
        "must be > 0, got -2",
    );
}

#[test]
fn density_zero() {
    // In a named material: no body.
    let text = Bad {
        materials: r#"{"rubber": {"friction": 0.9, "density": 0}}"#,
        ..Bad::default()
    }
    .text();
    check(
        "density-zero",
        &text,
        SceneErrorKind::Invalid,
        4,
        56,
        None,
        "materials.rubber.density",
        "must be > 0, got 0",
    );
    // Inline on a body.
    let text = Bad {
        material: r#"{"friction": 0.2, "density": 0}"#,
        ..Bad::default()
    }
    .text();
    check(
        "density-zero-inline",
        &text,
        SceneErrorKind::Invalid,
        13,
        48,
        LID,
        "bodies[2].material.density",
        "must be > 0, got 0",
    );
}

#[test]
fn dt_zero_and_negative() {
    let text = Bad {
        dt: "0",
        ..Bad::default()
    }
    .text();
    check(
        "dt-zero",
        &text,
        SceneErrorKind::Invalid,
        3,
        9,
        None,
        "dt",
        "must be finite and within [1e-6, 1] s, got 0",
    );
    let text = Bad {
        dt: "-0.01",
        ..Bad::default()
    }
    .text();
    check(
        "dt-negative",
        &text,
        SceneErrorKind::Invalid,
        3,
        9,
        None,
        "dt",
        "must be finite and within [1e-6, 1] s, got -0.01",
    );
}

#[test]
fn restitution_above_one() {
    let text = Bad {
        materials: r#"{"rubber": {"friction": 0.9, "restitution": 1.5}}"#,
        ..Bad::default()
    }
    .text();
    check(
        "restitution",
        &text,
        SceneErrorKind::Invalid,
        4,
        60,
        None,
        "materials.rubber.restitution",
        "must be in [0, 1], got 1.5",
    );
}

#[test]
fn undefined_material() {
    let text = Bad {
        material: r#""steel""#,
        ..Bad::default()
    }
    .text();
    check(
        "undefined-material",
        &text,
        SceneErrorKind::Invalid,
        13,
        19,
        LID,
        "bodies[2].material",
        "material \"steel\" is not defined (defined: default, rubber)",
    );
}

#[test]
fn inline_material_errors_name_the_field() {
    // serde's untagged MaterialRef forgets why an object failed; the loader finds out again.
    let text = Bad {
        material: r#"{"frction": 0.2}"#,
        ..Bad::default()
    }
    .text();
    check(
        "material-typo",
        &text,
        SceneErrorKind::Structure,
        13,
        28,
        LID,
        "bodies[2].material.frction",
        "unknown field `frction`",
    );
    let text = Bad {
        material: r#"{"friction": 0.2,
        "density": "heavy"}"#,
        ..Bad::default()
    }
    .text();
    check(
        "material-type",
        &text,
        SceneErrorKind::Structure,
        14,
        26,
        LID,
        "bodies[2].material.density",
        "invalid type: string \"heavy\", expected f32",
    );
    let text = Bad {
        material: "5",
        ..Bad::default()
    }
    .text();
    check(
        "material-number",
        &text,
        SceneErrorKind::Structure,
        13,
        19,
        LID,
        "bodies[2].material",
        "must be a material name (a string) or an inline material",
    );
}

#[test]
fn half_space_on_a_dynamic_body() {
    let text = Bad {
        shape: r#"{"type": "half_space", "normal": [0, 1, 0]}"#,
        ..Bad::default()
    }
    .text();
    check(
        "half-space-dynamic",
        &text,
        SceneErrorKind::Invalid,
        11,
        25,
        LID,
        "bodies[2].shape.type",
        "only allowed on a static body, this body is dynamic",
    );
}

#[test]
fn zero_half_space_normal() {
    let text = Bad {
        kind: "static",
        shape: r#"{"type": "half_space", "normal": [0, 0, 0]}"#,
        ..Bad::default()
    }
    .text();
    check(
        "half-space-zero",
        &text,
        SceneErrorKind::Invalid,
        11,
        49,
        LID,
        "bodies[2].shape.normal",
        "must not be zero",
    );
}

#[test]
fn particle_with_a_cuboid() {
    let text = Bad {
        kind: "particle",
        shape: r#"{"type": "cuboid", "half_extents": [0.5, 0.5, 0.5]}"#,
        ..Bad::default()
    }
    .text();
    check(
        "particle-cuboid",
        &text,
        SceneErrorKind::Invalid,
        11,
        25,
        LID,
        "bodies[2].shape.type",
        "a particle must have a sphere shape, got cuboid",
    );
}

/// Three points make a flat hull (a thin shape); two make none.
#[test]
fn convex_hull_with_two_points() {
    let text = Bad {
        shape: r#"{"type": "convex_hull", "points": [[0, 0, 0], [1, 0, 0]]}"#,
        ..Bad::default()
    }
    .text();
    check(
        "hull-3",
        &text,
        SceneErrorKind::Invalid,
        11,
        50,
        LID,
        "bodies[2].shape.points",
        "at least 4 points (3 for a flat one), got 2",
    );
}

/// Coplanar points make a flat hull (a thin shape); collinear ones make none.
#[test]
fn collinear_convex_hull() {
    let text = Bad {
        shape: r#"{"type": "convex_hull", "points": [[0, 0, 0], [1, 1, 1], [2, 2, 2], [3, 3, 3]]}"#,
        ..Bad::default()
    }
    .text();
    check(
        "hull-collinear",
        &text,
        SceneErrorKind::Invalid,
        11,
        50,
        LID,
        "bodies[2].shape.points",
        "collinear",
    );
}

#[test]
fn zero_quaternion() {
    let text = Bad {
        extra: ",\n      \"orientation\": [0, 0, 0, 0]",
        ..Bad::default()
    }
    .text();
    check(
        "zero-quaternion",
        &text,
        SceneErrorKind::Invalid,
        14,
        22,
        LID,
        "bodies[2].orientation",
        "must not be zero",
    );
}

#[test]
fn huge_numbers() {
    // Beyond f64: serde_json refuses it.
    let text = Bad {
        position: "[0, 1e999, 0]",
        ..Bad::default()
    }
    .text();
    check(
        "huge-f64",
        &text,
        SceneErrorKind::Syntax,
        12,
        27,
        LID,
        "bodies[2].position[1]",
        "number out of range",
    );
    // Beyond f32 only: serde_json (with `float_roundtrip`, which the workspace enables)
    // refuses it as out of range for f32, before any validation.
    let text = Bad {
        position: "[0, 1e39, 0]",
        ..Bad::default()
    }
    .text();
    check(
        "huge-f32",
        &text,
        SceneErrorKind::Syntax,
        12,
        26,
        LID,
        "bodies[2].position[1]",
        "number out of range",
    );
    let text = Bad {
        dt: "-1e999",
        ..Bad::default()
    }
    .text();
    check(
        "huge-dt",
        &text,
        SceneErrorKind::Syntax,
        3,
        14,
        None,
        "dt",
        "number out of range",
    );
}

#[test]
fn syntax_errors() {
    let text = Bad::default()
        .text()
        .replace("\"position\": [0, 2, 0],", "\"position\": [0, 2, 0],,");
    let (e, path) = load_err("syntax", &text);
    assert_eq!(e.kind, SceneErrorKind::Syntax, "{e}");
    assert_eq!(e.line(), Some(12), "{e}");
    assert_eq!(e.body.as_ref().map(|b| b.index), Some(2), "{e}");
    assert!(e.to_string().starts_with(&format!("{path}:12:")), "{e}");
    let (e, _) = load_err("trailing", &format!("{}\n]", Bad::default().text()));
    assert_eq!(e.kind, SceneErrorKind::Syntax, "{e}");
    assert_eq!(e.line(), Some(18), "{e}");
    assert!(e.message.contains("trailing characters"), "{e}");
}

#[test]
fn unreadable_file() {
    let e = load_scene_file(Path::new("/nonexistent/impulse/scene.json")).unwrap_err();
    assert_eq!(e.kind, SceneErrorKind::Io);
    assert!(
        e.to_string()
            .starts_with("/nonexistent/impulse/scene.json: cannot read:"),
        "{e}"
    );
}

#[test]
fn solver_settings_are_checked() {
    for (setting, message) in [
        (r#""iterations": 0"#, "must be ≥ 1, got 0"),
        (r#""tolerance": -1"#, "must be ≥ 0, got -1"),
        (r#""overlap_slop": -0.1"#, "must be ≥ 0, got -0.1"),
        (r#""warm_start": 1.5"#, "must be in [0, 1], got 1.5"),
        (r#""substeps": 0"#, "must be ≥ 1, got 0"),
    ] {
        let text = format!("{{\n  \"solver\": {{{setting}}},\n  \"bodies\": []\n}}");
        let e = parse_scene_str(&text, "s.json").unwrap_err();
        let key = setting.split('"').nth(1).unwrap();
        assert_eq!(
            e.to_string(),
            format!("s.json:2:{}: solver.{key}: {message}", 15 + key.len() + 3)
        );
    }
    // The repair's parameters, at their place inside the `repair` object.
    for (repair, path, message) in [
        (
            r#"{"type": "soft", "hertz": 240, "damping_ratio": -1}"#,
            "solver.repair.damping_ratio",
            "must be ≥ 0, got -1",
        ),
        (
            r#"{"type": "soft", "hertz": 0, "damping_ratio": 10}"#,
            "solver.repair.hertz",
            "must be > 0, got 0",
        ),
        (
            r#"{"type": "split_impulse", "rate": 12, "iterations": 0}"#,
            "solver.repair.iterations",
            "must be ≥ 1, got 0",
        ),
        (
            r#"{"type": "bias", "rate": -2}"#,
            "solver.repair.rate",
            "must be ≥ 0, got -2",
        ),
    ] {
        let text = format!("{{\n  \"solver\": {{\"repair\": {repair}}},\n  \"bodies\": []\n}}");
        let e = parse_scene_str(&text, "s.json").unwrap_err().to_string();
        assert!(
            e.starts_with("s.json:2:") && e.ends_with(&format!("{path}: {message}")),
            "{e}"
        );
    }
    let unknown = "{\n  \"solver\": {\"repair\": {\"type\": \"springs\"}},\n  \"bodies\": []\n}";
    let e = parse_scene_str(unknown, "s.json").unwrap_err().to_string();
    assert!(e.contains("springs") && e.contains("soft"), "{e}");
}

// ---------------------------------------------------------------------------------------------
// The locator on a realistic file.

#[test]
fn locator_finds_nested_paths_in_a_scene_file() {
    let text = Bad {
        shape: r#"{"type": "convex_hull", "points": [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]]}"#,
        materials: r#"{"rubber": {"friction": 0.9}, "ice": {"friction": 0.01}}"#,
        ..Bad::default()
    }
    .text();
    let at =
        |path: &str| locate(&text, &FieldPath::parse(path).unwrap()).map(|p| (p.line, p.column));
    assert_eq!(at("dt"), Some((3, 9)));
    assert_eq!(at("materials.ice.friction"), Some((4, 66)));
    assert_eq!(at("bodies[0].shape.half_extents[2]"), Some((6, 96)));
    assert_eq!(at("bodies[1].position[1]"), Some((7, 85)));
    assert_eq!(at("bodies[2]"), Some((8, 5)));
    assert_eq!(at("bodies[2].name"), Some((9, 15)));
    assert_eq!(at("bodies[2].shape.points[3][2]"), Some((11, 91)));
    assert_eq!(at("bodies[2].material"), Some((13, 19)));
    assert_eq!(at("bodies[2].mass"), None);
    assert_eq!(at("bodies[3]"), None);
    assert_eq!(
        locate_closest(&text, &FieldPath::parse("bodies[2].mass").unwrap())
            .map(|p| (p.line, p.column)),
        Some((8, 5))
    );
    // Every body of a generated scene file is found on its own line: after `{`, 4 lines of settings,
    // `"materials": {`, one line per material, `},` and `"bodies": [`.
    let scene = builtin_scene("pyramid20").unwrap();
    let text = to_json_string(&scene);
    for i in [0, 1, 100, 210] {
        let p = locate(&text, &FieldPath::body(i).key("position")).unwrap();
        assert_eq!(p.line as usize, 9 + scene.materials.len() + i, "body {i}");
    }
}
