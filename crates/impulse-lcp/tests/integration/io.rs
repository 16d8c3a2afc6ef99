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

/// Box bounds with infinities and awkward finite values (shortest decimal forms of random
/// doubles, tiny and huge magnitudes) round-trip bit for bit through the writer's `null`s.
#[test]
fn box_bounds_round_trip_exactly() {
    use impulse_lcp::{Bounds, DenseMatrix, Lcp, parse_json, to_json_string};
    let inf = f64::INFINITY;
    let lo = vec![-inf, 0.1 + 0.2, -1e-300, 5e-324, -inf, 1.0 / 3.0];
    let hi = vec![inf, 0.30000000000000004, 1e300, 5e-324, -0.0, inf];
    let mut a = DenseMatrix::zeros(6, 6);
    for i in 0..6 {
        a.data[i * 6 + i] = 1.0 + i as f64 / 7.0;
    }
    let lcp = Lcp::new(a, vec![0.7; 6], Bounds::Box { lo, hi }).unwrap();
    let back = parse_json(&to_json_string(&lcp).unwrap(), "t").unwrap();
    assert_eq!(back, lcp);
    let (Bounds::Box { lo: l1, hi: h1 }, Bounds::Box { lo: l2, hi: h2 }) =
        (&back.bounds, &lcp.bounds)
    else {
        panic!("box bounds expected");
    };
    for (x, y) in l1.iter().chain(h1).zip(l2.iter().chain(h2)) {
        assert_eq!(x.to_bits(), y.to_bits());
    }
}
