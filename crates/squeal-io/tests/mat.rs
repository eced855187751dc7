//! MAT-file reader against files written by SciPy (`benches/parametric_operator.py
//! mat-fixtures`): every matrix of `fixtures.mat` (uncompressed, MAT v5) and
//! `fixtures_z.mat` (zlib-compressed, MAT v7) equals the Matrix Market file SciPy wrote
//! for it (sparse, dense double, int32, single, an empty sparse matrix); what squeal
//! cannot read is refused with a message naming the file and the variable.

use squeal_core::SparseMat;
use squeal_io::{read_mtx, IoError, MatFile};
use std::path::{Path, PathBuf};

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/mat")
        .join(name)
}

/// Same size and same entries; values equal to a relative 1e-15 (the single-precision
/// matrix goes through a decimal file).
fn assert_same(a: &SparseMat, b: &SparseMat, what: &str) {
    assert_eq!((a.nrows(), a.ncols()), (b.nrows(), b.ncols()), "{what}");
    let (da, db) = (a.as_ref().to_dense(), b.as_ref().to_dense());
    let mut count = 0;
    for j in 0..a.ncols() {
        for i in 0..a.nrows() {
            let (x, y) = (da[(i, j)], db[(i, j)]);
            assert!(
                (x - y).abs() <= 1e-15 * x.abs().max(y.abs()),
                "{what} ({i}, {j}): {x} vs {y}"
            );
            count += usize::from(x != 0.0);
        }
    }
    assert_eq!(a.compute_nnz(), count, "{what}: stored zeros");
}

#[test]
fn every_fixture_matrix_equals_the_scipy_matrix_market_file() {
    for file in ["fixtures.mat", "fixtures_z.mat"] {
        let m = MatFile::open(data(file)).unwrap();
        let mut names = m.names();
        names.sort();
        assert_eq!(names, ["A", "B", "E", "I32", "R", "S"], "{file}");
        for name in names {
            let got = m.matrix(name).unwrap();
            let want = read_mtx(data(&format!("{name}.mtx"))).unwrap();
            assert_same(&got, &want, &format!("{file}:{name}"));
        }
        // spot values: the tiny and the huge entry of A survive exactly
        let a = m.matrix("A").unwrap().as_ref().to_dense();
        assert_eq!((a[(1, 3)], a[(2, 0)], a[(0, 2)]), (2.25e-9, 1e12, -1.5));
        assert_eq!(m.matrix("R").unwrap().compute_nnz(), 216);
        assert_eq!(m.matrix("E").unwrap().compute_nnz(), 0);
    }
}

fn err(file: &str, var: &str) -> String {
    let e = MatFile::open(data(file)).unwrap().matrix(var).unwrap_err();
    assert!(matches!(e, IoError::Mat { .. }), "{e:?}");
    e.to_string()
}

#[test]
fn unreadable_variables_are_refused_by_name() {
    for (var, says) in [
        ("Z", "complex"),
        ("Zs", "complex"),
        ("cell", "cell array"),
        ("txt", "character array"),
        ("cube", "not a 2-D matrix"),
        ("nan", "not finite"),
        ("absent", "no such variable; the file holds: "),
    ] {
        let e = err("refused.mat", var);
        assert!(
            e.contains("refused.mat")
                && e.contains(&format!("variable `{var}`"))
                && e.contains(says),
            "{var}: {e}"
        );
    }
}

#[test]
fn files_that_are_not_level_5_are_refused() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("squeal-io-mat");
    std::fs::create_dir_all(&dir).unwrap();
    let good = std::fs::read(data("fixtures_z.mat")).unwrap();
    let cases: Vec<(&str, Vec<u8>, &str)> = vec![
        (
            "short.mat",
            b"MATLAB 5.0".to_vec(),
            "shorter than the 128-byte header",
        ),
        (
            "v73.mat",
            {
                let mut h = b"MATLAB 7.3 MAT-file, Platform: GLNXA64".to_vec();
                h.resize(600, 0);
                h
            },
            "v7.3",
        ),
        (
            "v4.mat",
            {
                let mut h = vec![0u8; 200];
                h[4] = 3;
                h
            },
            "Level 4",
        ),
        (
            "truncated.mat",
            good[..good.len() - 100].to_vec(),
            "element at byte",
        ),
    ];
    for (name, bytes, says) in cases {
        let p = dir.join(name);
        std::fs::write(&p, bytes).unwrap();
        let e = MatFile::open(&p).unwrap_err().to_string();
        assert!(e.contains(name) && e.contains(says), "{name}: {e}");
    }
    let e = MatFile::open(dir.join("absent.mat"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("absent.mat"), "{e}");
}
