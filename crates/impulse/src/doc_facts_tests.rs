//! The numbers the docs state that the code fixes (the constraint row's size, the SIMD lane
//! threshold, the size limits, the default settings), read from the doc files and compared
//! with the constants, `size_of` and the defaults. A doc that states a number differently from
//! the code, or no longer states it where this test looks, fails here.

use crate::contact::constraints::ContactConstraint;
use crate::{Scene, SolverSettings};

const ARCHITECTURE: &str = include_str!("../../../docs/architecture.md");
const BENCHMARKS: &str = include_str!("../../../docs/benchmarks.md");
const ERRORS: &str = include_str!("../../../docs/errors.md");
const SOLVERS: &str = include_str!("../../../docs/solvers.md");
const SCENE_FORMAT: &str = include_str!("../../../docs/scene-format.md");

/// `doc` with every run of whitespace one space, so a phrase may break across lines.
fn flat(doc: &str) -> String {
    doc.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// The number right after each occurrence of `prefix` in `doc` (thousands separated by
/// commas allowed); fails if `prefix` occurs nowhere or is not followed by a number.
fn stated_after(doc: &str, prefix: &str) -> Vec<f64> {
    let doc = flat(doc);
    let found: Vec<f64> = doc
        .match_indices(prefix)
        .map(|(at, _)| {
            let rest = &doc[at + prefix.len()..];
            let token: String = rest
                .chars()
                .take_while(|c| c.is_ascii_digit() || matches!(c, ',' | '.' | 'e' | '-'))
                .collect();
            let token = token.trim_end_matches(['.', ',']).replace(',', "");
            token
                .parse()
                .unwrap_or_else(|_| panic!("no number after {prefix:?}: {:?}", &rest[..40]))
        })
        .collect();
    assert!(!found.is_empty(), "the docs no longer say {prefix:?}");
    found
}

fn assert_stated(doc: &str, prefix: &str, value: f64) {
    for stated in stated_after(doc, prefix) {
        assert_eq!(
            stated, value,
            "the docs say {prefix:?} {stated}, the code {value}"
        );
    }
}

#[test]
fn the_constraint_row_size_is_the_code_s() {
    let bytes = std::mem::size_of::<ContactConstraint>() as f64;
    assert_stated(ARCHITECTURE, "the constraints (", bytes);
    assert_stated(BENCHMARKS, "(`ContactConstraint`, ", bytes);
}

#[test]
fn the_simd_lane_threshold_is_the_default() {
    let default = f64::from(SolverSettings::default().simd_island_contacts);
    assert_stated(BENCHMARKS, "`simd_island_contacts` points, ", default);
}

#[test]
fn the_size_limits_are_the_code_s() {
    let scene_bytes = crate::scene::MAX_SCENE_FILE_BYTES as f64;
    assert_stated(
        ERRORS,
        "`MAX_SCENE_FILE_BYTES` = ",
        scene_bytes / f64::from(1 << 20),
    );
    assert_stated(ERRORS, "more than the ", scene_bytes);
    assert_stated(
        ERRORS,
        "regular files of at most ",
        scene_bytes / f64::from(1 << 20),
    );
    let max_count = f64::from(SolverSettings::MAX_COUNT);
    assert_stated(ERRORS, "`SolverSettings::MAX_COUNT` = ", max_count);
    assert_stated(SOLVERS, "`SolverSettings::MAX_COUNT` = ", max_count);
    let lemke = impulse_lcp::solvers::lemke::MAX_DIMENSION as f64;
    assert_stated(ERRORS, "`lemke::MAX_DIMENSION` = ", lemke);
    assert_stated(ERRORS, "it accepts n ≤ ", lemke);
}

/// The JSON value of a default cell of a scene-format.md table (`` `1e-5` ``, `` `"pgs"` ``,
/// `` `1/60` (`0.016666668`) ``: the last back-quoted value that is JSON), or `None` for a cell
/// without one ("all defaults", "**required**").
fn default_cell(cell: &str) -> Option<serde_json::Value> {
    cell.split('`')
        .skip(1)
        .step_by(2)
        .filter_map(|quoted| serde_json::from_str(quoted).ok())
        .last()
}

/// Whether a value the docs state equals the code's: numbers to the docs' precision (at least
/// four significant digits are never stated differently), arrays and objects entry by entry.
fn same(doc: &serde_json::Value, code: &serde_json::Value) -> bool {
    use serde_json::Value;
    match (doc, code) {
        (Value::Number(d), Value::Number(c)) => {
            let (d, c) = (d.as_f64().unwrap(), c.as_f64().unwrap());
            (d - c).abs() <= 5e-4 * c.abs()
        }
        (Value::Array(d), Value::Array(c)) => {
            d.len() == c.len() && d.iter().zip(c).all(|(d, c)| same(d, c))
        }
        (Value::Object(d), Value::Object(c)) => {
            d.len() == c.len() && d.iter().all(|(k, d)| c.get(k).is_some_and(|c| same(d, c)))
        }
        _ => doc == code,
    }
}

/// Checks every row of the table under `heading` in scene-format.md whose default cell holds
/// a value against `code`'s field of the same name; returns how many rows it checked.
fn check_default_table(heading: &str, code: &serde_json::Value) -> usize {
    let section = SCENE_FORMAT
        .split(heading)
        .nth(1)
        .unwrap_or_else(|| panic!("scene-format.md has no {heading:?}"));
    let section = section.split("\n## ").next().unwrap();
    let mut checked = 0;
    for line in section.lines().filter(|l| l.starts_with("| `")) {
        let cells: Vec<&str> = line.split('|').map(str::trim).collect();
        let field = cells[1].trim_matches('`');
        if field.contains(' ') || field.contains('`') {
            continue; // a variant's own row (`repair` `{"type": …}`): no default of its own
        }
        let Some(stated) = default_cell(cells[4]) else {
            continue;
        };
        let actual = code
            .get(field)
            .unwrap_or_else(|| panic!("scene-format.md documents `{field}`, the code has none"));
        assert!(
            same(&stated, actual),
            "scene-format.md: `{field}` defaults to {stated}, the code to {actual}"
        );
        checked += 1;
    }
    checked
}

/// What the file format makes of `json` (a scene-format.md object with its required fields
/// only), written back as JSON: every absent field at its default.
fn read_back<T: serde::de::DeserializeOwned + serde::Serialize>(json: &str) -> serde_json::Value {
    serde_json::to_value(serde_json::from_str::<T>(json).unwrap()).unwrap()
}

#[test]
fn the_documented_defaults_are_the_code_s() {
    let settings = read_back::<SolverSettings>("{}");
    assert_eq!(
        settings,
        serde_json::to_value(SolverSettings::default()).unwrap()
    );
    let rows = check_default_table("## Solver settings", &settings);
    assert!(rows >= 20, "only {rows} settings rows found");
    let rows = check_default_table("## Top level", &read_back::<Scene>(r#"{"bodies": []}"#));
    assert!(rows >= 4, "only {rows} scene rows found");
    let rows = check_default_table("## Materials", &read_back::<crate::Material>("{}"));
    assert!(rows >= 3, "only {rows} material rows found");
    let body = r#"{"kind": "dynamic", "shape": {"type": "sphere", "radius": 1}}"#;
    let rows = check_default_table("## Bodies", &read_back::<crate::BodyDesc>(body));
    assert!(rows >= 8, "only {rows} body rows found");
}
