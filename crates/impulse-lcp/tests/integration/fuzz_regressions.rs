//! The committed corpus and seeds of the `lcp_readers` fuzz target (`fuzz/corpus/lcp_readers`,
//! `fuzz/seeds/lcp_readers`, docs/fuzzing.md) through the same code path: both readers, then the JSON writer and the JSON
//! reader again. Every input must give an error or a problem, never a panic, and a problem that
//! reads must survive the JSON round trip unchanged (the format promises exact numbers).

use std::path::{Path, PathBuf};

use impulse_lcp::{parse_json, parse_siconos, to_json_string};

/// The files of `fuzz/corpus/<target>` (libFuzzer names them by content hash) and
/// `fuzz/seeds/<target>`, sorted.
fn corpus(target: &str) -> Vec<PathBuf> {
    let fuzz = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fuzz");
    let mut files = Vec::new();
    for directory in [
        fuzz.join("corpus").join(target),
        fuzz.join("seeds").join(target),
    ] {
        files.extend(
            std::fs::read_dir(&directory)
                .unwrap_or_else(|e| panic!("cannot list {}: {e}", directory.display()))
                .map(|entry| entry.expect("directory entry").path())
                .filter(|path| path.is_file()),
        );
    }
    files.sort();
    files
}

#[test]
fn lcp_reader_corpus_reads_or_errors_and_round_trips() {
    let files = corpus("lcp_readers");
    assert!(!files.is_empty(), "the lcp_readers corpus is empty");
    let mut problems = 0;
    for path in &files {
        let Ok(text) = String::from_utf8(std::fs::read(path).expect("readable input")) else {
            continue;
        };
        for lcp in [
            parse_siconos(&text, "fuzz.dat"),
            parse_json(&text, "fuzz.json"),
        ]
        .into_iter()
        .flatten()
        {
            problems += 1;
            let json = to_json_string(&lcp).unwrap_or_else(|e| {
                panic!("{}: a read problem does not write: {e}", path.display())
            });
            let again = parse_json(&json, "round-trip.json").unwrap_or_else(|e| {
                panic!(
                    "{}: the written JSON does not read back: {e}",
                    path.display()
                )
            });
            assert_eq!(
                again,
                lcp,
                "{}: the JSON round trip changed the problem",
                path.display()
            );
        }
    }
    // The corpus holds the Siconos test problems and JSON seeds, so some inputs are problems.
    assert!(problems > 0, "no corpus input reads as a problem");
}
