//! The JSON problem format, in the project's convention `w = Aγ − b` (docs/method.md).
//!
//! ```json
//! {
//!   "n": 3,
//!   "a": [[2.0, 1.0, 0.0], [1.0, 2.0, 0.0], [0.0, 0.0, 1.0]],
//!   "b": [5.0, 6.0, -1.0],
//!   "lo": [0.0, null, 0.0],
//!   "hi": [null, 4.0, null],
//!   "friction_index": [null, null, 0],
//!   "mu": [0.0, 0.0, 0.5]
//! }
//! ```
//!
//! - `n`: number of unknowns; `a` must be `n × n` and every vector has `n` entries.
//! - `a`: either dense rows (a list of `n` lists of `n` numbers) or a sparse matrix
//!   `{"csr": {"indptr": [...], "indices": [...], "values": [...]}}` (row pointers of length
//!   `n + 1`, column indices strictly increasing within each row; see [`CsrMatrix`]).
//! - `b`: right-hand side.
//! - `lo`, `hi` (optional): bounds, for free rows (equalities), one-sided rows (contacts, limits)
//!   and two-sided boxes (motors) alike. JSON has no infinity, so the infinite end of a bound is
//!   `null` (`−∞` in `lo`, `+∞` in `hi`: what the writer emits), or, for files written by hand,
//!   one of the strings `"-inf"`, `"inf"`, `"+inf"`, `"-infinity"`, `"infinity"`, `"+infinity"`
//!   (any case). A free row is `lo: null, hi: null`; a contact `lo: 0, hi: null`. A missing `lo`
//!   means all 0, a missing `hi` all `+∞`. Without `lo`, `hi` and `friction_index` the problem is
//!   the standard LCP `γ ≥ 0`. Files written before the strings were accepted read unchanged.
//! - `friction_index` (optional, requires `mu`): per row `null` or the index `j` of its normal
//!   row; such a row gets bounds `±mu[i]·γ_j` and ignores its `lo`/`hi` (ODE's `findex`). See
//!   [`Bounds::Friction`].
//!
//! Unknown fields are rejected, so a misspelt `"friction_idx"` is an error rather than silently
//! ignored. Numbers round-trip exactly (shortest representation that parses back to the same f64).

use super::file_error::{FileError, read_text};
use crate::matrix::{CsrMatrix, DenseMatrix, Matrix};
use crate::problem::{Bounds, Lcp};
use serde::{Deserialize, Serialize};
use serde_json::Value;
use std::path::Path;

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct JsonLcp {
    n: usize,
    a: Value,
    b: Vec<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    lo: Option<Vec<Option<JsonBound>>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    hi: Option<Vec<Option<JsonBound>>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    friction_index: Option<Vec<Option<usize>>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    mu: Option<Vec<f64>>,
}

/// One entry of `lo` or `hi`: a number, or an infinity spelled as a string (`null` is the
/// `None` around it).
#[derive(Serialize, Deserialize)]
#[serde(untagged)]
enum JsonBound {
    Number(f64),
    Text(String),
}

/// The bounds of field `field` (`lo` or `hi`), `null` standing for `missing` (−∞ or +∞).
fn bound_values(
    field: &str,
    values: Vec<Option<JsonBound>>,
    missing: f64,
) -> Result<Vec<f64>, String> {
    values
        .into_iter()
        .enumerate()
        .map(|(i, v)| match v {
            None => Ok(missing),
            Some(JsonBound::Number(x)) => Ok(x),
            Some(JsonBound::Text(t)) => match t.to_ascii_lowercase().as_str() {
                "inf" | "+inf" | "infinity" | "+infinity" => Ok(f64::INFINITY),
                "-inf" | "-infinity" => Ok(f64::NEG_INFINITY),
                _ => Err(format!(
                    "field {field}[{i}] is {t:?}: a bound is a number, null (no bound), \
                     \"-inf\" or \"inf\""
                )),
            },
        })
        .collect()
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct JsonCsr {
    indptr: Vec<usize>,
    indices: Vec<usize>,
    values: Vec<f64>,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct JsonCsrWrapper {
    csr: JsonCsr,
}

/// Reads and validates a JSON problem file. Errors name the file and the field.
pub fn read_json(path: &Path) -> Result<Lcp, FileError> {
    parse_json(&read_text(path)?, &path.display().to_string())
}

/// Parses JSON problem text; `file` labels error messages. A UTF-8 byte order mark at the
/// start is skipped.
pub fn parse_json(text: &str, file: &str) -> Result<Lcp, FileError> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let err = |message: String| FileError::Json {
        file: file.to_string(),
        message,
    };
    let raw: JsonLcp = serde_json::from_str(text).map_err(|e| err(e.to_string()))?;
    let n = raw.n;
    let check_len = |field: &str, len: usize| {
        if len == n {
            Ok(())
        } else {
            Err(err(format!("field {field} has {len} entries, but n = {n}")))
        }
    };
    let a: Matrix = match raw.a {
        Value::Array(_) => {
            let rows: Vec<Vec<f64>> = serde_json::from_value(raw.a)
                .map_err(|e| err(format!("field a (dense rows of numbers): {e}")))?;
            check_len("a (rows)", rows.len())?;
            for (i, row) in rows.iter().enumerate() {
                check_len(&format!("a[{i}]"), row.len())?;
            }
            DenseMatrix::from_rows(&rows)
                .map_err(|e| err(format!("field a: {e}")))?
                .into()
        }
        Value::Object(_) => {
            let JsonCsrWrapper { csr } = serde_json::from_value(raw.a).map_err(|e| {
                err(format!(
                    "field a (sparse {{\"csr\": {{indptr, indices, values}}}}): {e}"
                ))
            })?;
            CsrMatrix::new(n, n, csr.indptr, csr.indices, csr.values)
                .map_err(|e| err(format!("field a.csr: {e}")))?
                .into()
        }
        _ => {
            return Err(err(
                "field a must be a list of rows or {\"csr\": {...}}".into()
            ));
        }
    };
    check_len("b", raw.b.len())?;
    let lo = raw
        .lo
        .map(|v| bound_values("lo", v, f64::NEG_INFINITY))
        .transpose()
        .map_err(err)?;
    let hi = raw
        .hi
        .map(|v| bound_values("hi", v, f64::INFINITY))
        .transpose()
        .map_err(err)?;
    if let Some(lo) = &lo {
        check_len("lo", lo.len())?;
    }
    if let Some(hi) = &hi {
        check_len("hi", hi.len())?;
    }
    let bounds = match (raw.friction_index, raw.mu) {
        (Some(friction_index), Some(mu)) => {
            check_len("friction_index", friction_index.len())?;
            check_len("mu", mu.len())?;
            Bounds::Friction {
                lo: lo.unwrap_or_else(|| vec![0.0; n]),
                hi: hi.unwrap_or_else(|| vec![f64::INFINITY; n]),
                friction_index,
                mu,
            }
        }
        (Some(_), None) => return Err(err("field friction_index needs field mu".into())),
        (None, Some(_)) => return Err(err("field mu is given without friction_index".into())),
        (None, None) if lo.is_none() && hi.is_none() => Bounds::NonNegative,
        (None, None) => Bounds::Box {
            lo: lo.unwrap_or_else(|| vec![0.0; n]),
            hi: hi.unwrap_or_else(|| vec![f64::INFINITY; n]),
        },
    };
    Lcp::new(a, raw.b, bounds).map_err(|problem| FileError::Invalid {
        file: file.to_string(),
        problem,
    })
}

/// The problem as JSON text (compact, one line). Errors: the problem is invalid (it could not be
/// read back), with `file` = `"<json>"`.
pub fn to_json_string(lcp: &Lcp) -> Result<String, FileError> {
    lcp.validate().map_err(|problem| FileError::Invalid {
        file: "<json>".into(),
        problem,
    })?;
    let a = match &lcp.a {
        Matrix::Dense(m) => Value::from(
            (0..m.rows)
                .map(|i| Value::from(m.row(i).to_vec()))
                .collect::<Vec<_>>(),
        ),
        Matrix::Csr(m) => serde_json::to_value(JsonCsrWrapper {
            csr: JsonCsr {
                indptr: m.indptr.clone(),
                indices: m.indices.clone(),
                values: m.values.clone(),
            },
        })
        .map_err(|e| FileError::Json {
            file: "<json>".into(),
            message: e.to_string(),
        })?,
    };
    let finite = |v: &[f64]| {
        v.iter()
            .map(|&x| x.is_finite().then_some(JsonBound::Number(x)))
            .collect::<Vec<_>>()
    };
    let mut raw = JsonLcp {
        n: lcp.n(),
        a,
        b: lcp.b.clone(),
        lo: None,
        hi: None,
        friction_index: None,
        mu: None,
    };
    match &lcp.bounds {
        Bounds::NonNegative => {}
        Bounds::Box { lo, hi } => {
            raw.lo = Some(finite(lo));
            raw.hi = Some(finite(hi));
        }
        Bounds::Friction {
            lo,
            hi,
            friction_index,
            mu,
        } => {
            raw.lo = Some(finite(lo));
            raw.hi = Some(finite(hi));
            raw.friction_index = Some(friction_index.clone());
            raw.mu = Some(mu.clone());
        }
    }
    serde_json::to_string(&raw).map_err(|e| FileError::Json {
        file: "<json>".into(),
        message: e.to_string(),
    })
}

/// Writes the problem to `path` as JSON (see the module documentation for the format).
pub fn write_json(lcp: &Lcp, path: &Path) -> Result<(), FileError> {
    let file = path.display().to_string();
    let text = to_json_string(lcp).map_err(|e| match e {
        FileError::Invalid { problem, .. } => FileError::Invalid {
            file: file.clone(),
            problem,
        },
        other => other,
    })?;
    std::fs::write(path, text + "\n").map_err(|error| FileError::Io { file, error })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn documented_example_parses() {
        let text = r#"{
          "n": 3,
          "a": [[2.0, 1.0, 0.0], [1.0, 2.0, 0.0], [0.0, 0.0, 1.0]],
          "b": [5.0, 6.0, -1.0],
          "lo": [0.0, null, 0.0],
          "hi": [null, 4.0, null],
          "friction_index": [null, null, 0],
          "mu": [0.0, 0.0, 0.5]
        }"#;
        let lcp = parse_json(text, "t").unwrap();
        let Bounds::Friction { lo, hi, .. } = &lcp.bounds else {
            panic!("expected friction bounds");
        };
        assert_eq!(lo[1], f64::NEG_INFINITY);
        assert_eq!(hi[0], f64::INFINITY);
        let back = parse_json(&to_json_string(&lcp).unwrap(), "t").unwrap();
        assert_eq!(back, lcp);
    }

    #[test]
    fn infinities_as_null_or_strings() {
        let text = r#"{"n": 4, "a": [[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]], "b": [1,2,3,4],
          "lo": [null, "-inf", 0, "-Infinity"], "hi": ["inf", null, "+INF", 2.5]}"#;
        let lcp = parse_json(text, "t").unwrap();
        let inf = f64::INFINITY;
        assert_eq!(
            lcp.bounds,
            Bounds::Box {
                lo: vec![-inf, -inf, 0.0, -inf],
                hi: vec![inf, inf, inf, 2.5],
            }
        );
        // The writer uses null, which every reader of this format reads.
        let written = to_json_string(&lcp).unwrap();
        assert!(
            written.contains(r#""lo":[null,null,0.0,null],"hi":[null,null,null,2.5]"#),
            "{written}"
        );
        assert_eq!(parse_json(&written, "t").unwrap(), lcp);
        let msg = |t: &str| parse_json(t, "p.json").unwrap_err().to_string();
        let bad = msg(r#"{"n":1,"a":[[1]],"b":[1],"lo":["-infty"]}"#);
        assert!(bad.contains("lo[0]") && bad.contains("-infty"), "{bad}");
        // "inf" as a lower bound is a valid spelling of an invalid bound (lo < +∞ is required).
        assert!(msg(r#"{"n":1,"a":[[1]],"b":[1],"lo":["inf"]}"#).contains("invalid problem"));
        assert!(msg(r#"{"n":1,"a":[[1]],"b":[1],"lo":[true]}"#).contains("p.json"));
    }

    #[test]
    fn csr_round_trip_and_standard_default() {
        let text = r#"{"n":2,"a":{"csr":{"indptr":[0,1,2],"indices":[0,1],"values":[0.1,3e-7]}},"b":[1,2]}"#;
        let lcp = parse_json(text, "t").unwrap();
        assert_eq!(lcp.bounds, Bounds::NonNegative);
        assert!(matches!(lcp.a, Matrix::Csr(_)));
        assert_eq!(
            parse_json(&to_json_string(&lcp).unwrap(), "t").unwrap(),
            lcp
        );
    }

    #[test]
    fn field_errors_are_named() {
        let msg = |t: &str| parse_json(t, "p.json").unwrap_err().to_string();
        assert!(msg(r#"{"n":2,"a":[[1,0],[0,1]],"b":[1]}"#).contains("field b has 1 entries"));
        assert!(msg(r#"{"n":2,"a":[[1,0],[0]],"b":[1,1]}"#).contains("a[1]"));
        assert!(msg(r#"{"n":2,"a":[[1,0],[0,1]],"b":[1,1],"mu":[0,0]}"#).contains("mu"));
        assert!(msg(r#"{"n":2,"a":[[1,0],[0,1]],"b":[1,1],"bogus":1}"#).contains("bogus"));
        assert!(
            msg(r#"{"n":1,"a":{"csr":{"indptr":[0,1],"indices":[3],"values":[1]}},"b":[1]}"#)
                .contains("a.csr")
        );
        assert!(
            msg(r#"{"n":1,"a":[[1]],"b":[1],"lo":[2],"hi":[1]}"#)
                .starts_with("p.json: invalid problem")
        );
        let huge = format!(
            r#"{{"n":{},"a":{{"csr":{{"indptr":[0],"indices":[],"values":[]}}}},"b":[]}}"#,
            usize::MAX
        );
        assert!(msg(&huge).contains("indptr"), "{}", msg(&huge));
    }
}
