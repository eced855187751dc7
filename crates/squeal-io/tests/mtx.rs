//! Matrix Market reader and writer: bit-identical round trips, symmetric files, and one
//! test per malformed case checking that the message names the file, the line and the
//! problem.

use faer::sparse::Triplet;
use squeal_core::SparseMat;
use squeal_io::{read_mtx, read_square_mtx, write_mtx, IoError};
use std::path::{Path, PathBuf};

/// A fresh directory for one test.
fn tmp(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("squeal-io-mtx")
        .join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn mat(nrows: usize, ncols: usize, t: &[(usize, usize, f64)]) -> SparseMat {
    let t: Vec<_> = t.iter().map(|&(i, j, v)| Triplet::new(i, j, v)).collect();
    SparseMat::try_new_from_triplets(nrows, ncols, &t).unwrap()
}

/// Sizes, structure and value bits all equal.
fn assert_bit_identical(a: &SparseMat, b: &SparseMat) {
    assert_eq!((a.nrows(), a.ncols()), (b.nrows(), b.ncols()));
    for j in 0..a.ncols() {
        let ra: Vec<usize> = a.row_idx_of_col(j).collect();
        let rb: Vec<usize> = b.row_idx_of_col(j).collect();
        assert_eq!(ra, rb, "column {j} structure");
        let va: Vec<u64> = a.val_of_col(j).iter().map(|v| v.to_bits()).collect();
        let vb: Vec<u64> = b.val_of_col(j).iter().map(|v| v.to_bits()).collect();
        assert_eq!(va, vb, "column {j} values");
    }
}

/// Dense copy, for value checks.
fn dense(m: &SparseMat) -> Vec<Vec<f64>> {
    let mut d = vec![vec![0.0; m.ncols()]; m.nrows()];
    for j in 0..m.ncols() {
        for (i, v) in m.row_idx_of_col(j).zip(m.val_of_col(j)) {
            d[i][j] += v;
        }
    }
    d
}

#[test]
fn round_trip_is_bit_identical() {
    // Values that need all 17 significant digits, extremes, subnormals and -0.0, plus
    // pseudo-random mantissas and exponents.
    let mut vals = vec![
        0.1,
        1.0 / 3.0,
        -2.0 / 3.0,
        std::f64::consts::PI,
        -0.0,
        0.0,
        f64::MIN_POSITIVE,
        5e-324,
        -2.225_073_858_507_201e-308,
        f64::MAX,
        -f64::MAX,
        1.0 + f64::EPSILON,
        123_456_789_012_345_680.0,
    ];
    let mut s: u64 = 0x9E37_79B9_7F4A_7C15;
    while vals.len() < 60 {
        s = s.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
        let mant = (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
        let exp = ((s >> 3) % 80) as i32 - 40;
        vals.push(mant * 10f64.powi(exp));
    }
    let (nr, nc) = (11, 7);
    let t: Vec<_> = vals
        .iter()
        .enumerate()
        .map(|(k, &v)| ((k * 5) % nr, (k * 3 + k / nr) % nc, v))
        .collect();
    // Distinct positions, so no summation can alter a value.
    let mut pos: Vec<_> = t.iter().map(|&(i, j, _)| (i, j)).collect();
    pos.sort();
    pos.dedup();
    assert_eq!(pos.len(), t.len());
    let a = mat(nr, nc, &t);
    assert!(
        (0..nc).any(|j| a
            .val_of_col(j)
            .iter()
            .any(|v| v.to_bits() == (-0.0f64).to_bits())),
        "-0.0 must be among the stored values"
    );
    let d = tmp("round_trip");
    let p = d.join("a.mtx");
    write_mtx(&p, &a, "round trip\nsecond comment line").unwrap();
    let b = read_mtx(&p).unwrap();
    assert_bit_identical(&a, &b);
    // Writing what was read gives the same bytes.
    let p2 = d.join("b.mtx");
    write_mtx(&p2, &b, "round trip\nsecond comment line").unwrap();
    assert_eq!(std::fs::read(&p).unwrap(), std::fs::read(&p2).unwrap());
}

#[test]
fn written_file_has_scipy_banner_and_one_based_indices() {
    let a = mat(2, 3, &[(0, 0, 1.0), (1, 2, -0.1)]);
    let p = tmp("format").join("a.mtx");
    write_mtx(&p, &a, "hello").unwrap();
    let text = std::fs::read_to_string(&p).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(
        lines,
        [
            "%%MatrixMarket matrix coordinate real general",
            "% hello",
            "2 3 2",
            "1 1 1.00000000000000000e0",
            "2 3 -1.00000000000000006e-1",
        ]
    );
}

#[test]
fn empty_matrices_round_trip() {
    let d = tmp("empty");
    for (nr, nc) in [(0, 0), (3, 3), (2, 5)] {
        let a = mat(nr, nc, &[]);
        let p = d.join(format!("e{nr}x{nc}.mtx"));
        write_mtx(&p, &a, "").unwrap();
        let text = std::fs::read_to_string(&p).unwrap();
        // An empty comment writes no comment line: the banner is the only `%` line.
        assert_eq!(text.lines().filter(|l| l.starts_with('%')).count(), 1);
        assert_bit_identical(&a, &read_mtx(&p).unwrap());
    }
}

#[test]
fn symmetric_banner_expands_lower_triangle() {
    let p = tmp("symmetric").join("sym.mtx");
    std::fs::write(
        &p,
        "%%MatrixMarket matrix coordinate real symmetric\n% lower triangle\n\n3 3 4\n\
         1 1 4.0\n2 1 -1.5\n3 2 0.25\n3 3 2e0\n",
    )
    .unwrap();
    let m = read_mtx(&p).unwrap();
    assert_eq!(
        dense(&m),
        vec![
            vec![4.0, -1.5, 0.0],
            vec![-1.5, 0.0, 0.25],
            vec![0.0, 0.25, 2.0]
        ]
    );
    assert_eq!(m.compute_nnz(), 6);
    // Case-insensitive keywords and `integer` values are accepted too.
    let q = p.with_file_name("int.mtx");
    std::fs::write(
        &q,
        "%%matrixmarket MATRIX Coordinate integer Symmetric\n2 2 2\n1 1 3\n2 1 -1\n",
    )
    .unwrap();
    assert_eq!(
        dense(&read_mtx(&q).unwrap()),
        vec![vec![3.0, -1.0], vec![-1.0, 0.0]]
    );
}

#[test]
fn duplicates_are_summed() {
    let p = tmp("dups").join("dup.mtx");
    std::fs::write(
        &p,
        "%%MatrixMarket matrix coordinate real general\n2 2 3\n2 1 1.0\n1 1 2.0\n2 1 0.5\n",
    )
    .unwrap();
    let m = read_mtx(&p).unwrap();
    assert_eq!(dense(&m), vec![vec![2.0, 0.0], vec![1.5, 0.0]]);
    assert_eq!(m.compute_nnz(), 2);
}

/// Writes `text` to a file called `name` and returns the error message of reading it.
fn read_err(name: &str, text: &str) -> (IoError, String) {
    let p = tmp(name.trim_end_matches(".mtx")).join(name);
    std::fs::write(&p, text).unwrap();
    let e = read_mtx(&p).expect_err("malformed file must be rejected");
    let msg = e.to_string();
    assert!(msg.contains(name), "message does not name the file: {msg}");
    (e, msg)
}

fn assert_has(msg: &str, parts: &[&str]) {
    for p in parts {
        assert!(msg.contains(p), "`{p}` missing from: {msg}");
    }
}

const GEN: &str = "%%MatrixMarket matrix coordinate real general\n";

#[test]
fn bad_banner() {
    let (e, msg) = read_err("no_banner.mtx", "2 2 1\n1 1 1.0\n");
    assert!(matches!(e, IoError::Syntax { line: 1, .. }));
    assert_has(
        &msg,
        &[
            ":1:",
            "not a Matrix Market banner",
            "%%MatrixMarket matrix coordinate real general",
        ],
    );
    let (_, msg) = read_err(
        "short_banner.mtx",
        "%%MatrixMarket matrix coordinate real\n2 2 0\n",
    );
    assert_has(&msg, &[":1:", "4 words instead of 5"]);
    let (_, msg) = read_err("empty.mtx", "");
    assert_has(&msg, &[":1:", "empty"]);
    let (_, msg) = read_err(
        "vector.mtx",
        "%%MatrixMarket vector coordinate real general\n2 2 0\n",
    );
    assert_has(&msg, &["unsupported Matrix Market object `vector`"]);
}

#[test]
fn unsupported_field_and_format() {
    let (e, msg) = read_err(
        "complex.mtx",
        "%%MatrixMarket matrix coordinate complex general\n2 2 1\n1 1 1.0 0.0\n",
    );
    assert!(matches!(e, IoError::Unsupported { what: "field", .. }));
    assert_has(&msg, &[":1:", "field `complex`", "`real`"]);
    let (_, msg) = read_err(
        "pattern.mtx",
        "%%MatrixMarket matrix coordinate pattern general\n2 2 1\n1 1\n",
    );
    assert_has(&msg, &["field `pattern`"]);
    let (e, msg) = read_err(
        "array.mtx",
        "%%MatrixMarket matrix array real general\n2 2\n1\n2\n3\n4\n",
    );
    assert!(matches!(e, IoError::Unsupported { what: "format", .. }));
    assert_has(&msg, &["format `array`", "`coordinate`"]);
    let (_, msg) = read_err(
        "skew.mtx",
        "%%MatrixMarket matrix coordinate real skew-symmetric\n2 2 1\n2 1 1.0\n",
    );
    assert_has(
        &msg,
        &["symmetry `skew-symmetric`", "`general` or `symmetric`"],
    );
}

#[test]
fn bad_size_line() {
    let (_, msg) = read_err("size.mtx", &format!("{GEN}% c\n2 2\n1 1 1.0\n"));
    assert_has(
        &msg,
        &[":3:", "size line `2 2`", "<rows> <columns> <entries>"],
    );
    let (_, msg) = read_err("nosize.mtx", &format!("{GEN}% only a comment\n"));
    assert_has(&msg, &[":3:", "ends before the size line"]);
}

#[test]
fn index_out_of_range() {
    let (e, msg) = read_err("oob.mtx", &format!("{GEN}2 2 2\n1 1 1.0\n3 1 1.0\n"));
    assert!(matches!(
        e,
        IoError::IndexOutOfRange {
            line: 4,
            row: 3,
            col: 1,
            nrows: 2,
            ncols: 2,
            ..
        }
    ));
    assert_has(
        &msg,
        &[":4:", "(3, 1)", "outside the declared 2 x 2", "1-based"],
    );
    let (_, msg) = read_err("zero_index.mtx", &format!("{GEN}2 2 1\n0 1 1.0\n"));
    assert_has(&msg, &[":3:", "(0, 1)", "1-based"]);
    let (_, msg) = read_err("col_oob.mtx", &format!("{GEN}2 3 1\n2 4 1.0\n"));
    assert_has(&msg, &[":3:", "(2, 4)", "2 x 3"]);
}

#[test]
fn fewer_or_more_entries_than_declared() {
    let (e, msg) = read_err("few.mtx", &format!("{GEN}2 2 3\n1 1 1.0\n2 2 1.0\n"));
    assert!(matches!(
        e,
        IoError::EntryCount {
            declared: 3,
            found: 2,
            ..
        }
    ));
    assert_has(&msg, &["found 2 entries", "declares 3"]);
    let (e, msg) = read_err("many.mtx", &format!("{GEN}2 2 1\n1 1 1.0\n2 2 1.0\n"));
    assert!(matches!(
        e,
        IoError::EntryCount {
            line: 4,
            declared: 1,
            ..
        }
    ));
    assert_has(&msg, &[":4:", "found 2 entries or more", "declares 1"]);
}

#[test]
fn non_finite_values() {
    for (name, v) in [
        ("nan.mtx", "NaN"),
        ("inf.mtx", "inf"),
        ("minf.mtx", "-Infinity"),
    ] {
        let (e, msg) = read_err(name, &format!("{GEN}2 2 2\n1 1 1.0\n2 1 {v}\n"));
        assert!(
            matches!(e, IoError::NonFinite { line: Some(4), .. }),
            "{msg}"
        );
        assert_has(&msg, &[":4:", &format!("`{v}`"), "(2, 1)", "not finite"]);
    }
}

#[test]
fn bad_entries() {
    let (_, msg) = read_err("value.mtx", &format!("{GEN}2 2 1\n1 1 1,5\n"));
    assert_has(&msg, &[":3:", "value `1,5`", "not a real number"]);
    let (_, msg) = read_err("fields.mtx", &format!("{GEN}2 2 1\n1 1 1.0 0.0\n"));
    assert_has(&msg, &[":3:", "4 fields instead of 3"]);
    let (_, msg) = read_err("index.mtx", &format!("{GEN}2 2 1\n1.0 1 1.0\n"));
    assert_has(&msg, &[":3:", "row index `1.0`"]);
    let (_, msg) = read_err(
        "upper.mtx",
        "%%MatrixMarket matrix coordinate real symmetric\n2 2 1\n1 2 1.0\n",
    );
    assert_has(
        &msg,
        &[":3:", "(1, 2)", "above the diagonal", "lower triangle"],
    );
    let (_, msg) = read_err(
        "symrect.mtx",
        "%%MatrixMarket matrix coordinate real symmetric\n2 3 0\n",
    );
    assert_has(&msg, &["2 x 3", "square"]);
}

#[test]
fn square_required() {
    let d = tmp("square");
    let p = d.join("rect.mtx");
    write_mtx(&p, &mat(2, 3, &[(0, 0, 1.0)]), "").unwrap();
    let msg = read_square_mtx(&p, None).unwrap_err().to_string();
    assert_has(&msg, &["rect.mtx", "2 x 3", "expected a square matrix"]);
    let q = d.join("sq.mtx");
    write_mtx(&q, &mat(3, 3, &[(0, 0, 1.0)]), "").unwrap();
    let msg = read_square_mtx(&q, Some(4)).unwrap_err().to_string();
    assert_has(&msg, &["sq.mtx", "3 x 3", "4 x 4"]);
    assert_eq!(read_square_mtx(&q, Some(3)).unwrap().nrows(), 3);
    assert_eq!(read_square_mtx(&q, None).unwrap().nrows(), 3);
}

#[test]
fn unreadable_file() {
    let p = tmp("missing").join("does_not_exist.mtx");
    let e = read_mtx(&p).unwrap_err();
    assert!(matches!(e, IoError::Io { .. }));
    assert_has(&e.to_string(), &["does_not_exist.mtx", "cannot open"]);
    // A directory is not a file.
    let d = tmp("is_a_dir.mtx");
    assert_has(
        &read_mtx(&d).unwrap_err().to_string(),
        &["is_a_dir.mtx", "cannot"],
    );
}

#[test]
fn writing_nan_is_refused_and_writes_nothing() {
    let p = tmp("write_nan").join("w.mtx");
    let e = write_mtx(&p, &mat(2, 2, &[(1, 0, f64::NAN)]), "").unwrap_err();
    assert_has(&e.to_string(), &["w.mtx", "(2, 1)", "not finite"]);
    assert!(!p.exists());
}

#[test]
fn converts_to_core_error_keeping_the_message() {
    let p = tmp("convert").join("gone.mtx");
    let e = read_mtx(&p).unwrap_err();
    let msg = e.to_string();
    let core: squeal_core::Error = e.into();
    assert!(matches!(core, squeal_core::Error::Backend(_)));
    assert_eq!(core.to_string(), msg);
}
