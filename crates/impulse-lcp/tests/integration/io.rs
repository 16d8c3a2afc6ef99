//! The JSON writer round-trips every Siconos problem exactly, through a real file.

use crate::common::siconos_dir;
use impulse_lcp::{FileFormat, read_json, read_lcp, read_siconos, write_json};

#[test]
fn every_siconos_problem_round_trips_through_json() {
    let dir = std::env::temp_dir().join(format!("impulse-lcp-io-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for entry in std::fs::read_dir(siconos_dir()).unwrap() {
        let path = entry.unwrap().path();
        let lcp = read_siconos(&path).unwrap();
        let out = dir.join(path.with_extension("json").file_name().unwrap());
        write_json(&lcp, &out).unwrap();
        // Same storage (dense stays dense, CSR stays CSR), bit-identical numbers.
        assert_eq!(read_json(&out).unwrap(), lcp, "{}", path.display());
        let (again, format) = read_lcp(&out).unwrap();
        assert_eq!(format, FileFormat::Json);
        assert_eq!(again, lcp);
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
