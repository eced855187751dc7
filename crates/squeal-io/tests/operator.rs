//! Operator directories: the shipped Hoffmann example, write/read round trips, stale
//! files, and errors naming the offending file.

use faer::sparse::Triplet;
use squeal_core::{FrictionalOperator, SparseMat};
use squeal_io::{read_operator_dir, write_mtx, write_operator_dir, IoError, OperatorMeta};
use std::path::{Path, PathBuf};

fn tmp(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("squeal-io-op")
        .join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn data_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/hoffmann")
}

fn mat(n: usize, t: &[(usize, usize, f64)]) -> SparseMat {
    let t: Vec<_> = t.iter().map(|&(i, j, v)| Triplet::new(i, j, v)).collect();
    SparseMat::try_new_from_triplets(n, n, &t).unwrap()
}

fn dense(m: &SparseMat) -> Vec<Vec<f64>> {
    let mut d = vec![vec![0.0; m.ncols()]; m.nrows()];
    for j in 0..m.ncols() {
        for (i, v) in m.row_idx_of_col(j).zip(m.val_of_col(j)) {
            d[i][j] += v;
        }
    }
    d
}

fn bits(m: &SparseMat) -> (usize, usize, Vec<(usize, usize, u64)>) {
    let mut v = Vec::new();
    for j in 0..m.ncols() {
        for (i, x) in m.row_idx_of_col(j).zip(m.val_of_col(j)) {
            v.push((i, j, x.to_bits()));
        }
    }
    (m.nrows(), m.ncols(), v)
}

fn assert_same(a: &FrictionalOperator, b: &FrictionalOperator) {
    assert_eq!(bits(&a.mc), bits(&b.mc), "mc");
    assert_eq!(bits(&a.kc), bits(&b.kc), "kc");
    assert_eq!(bits(&a.fm), bits(&b.fm), "fm");
    assert_eq!(bits(&a.fk), bits(&b.fk), "fk");
    assert_eq!(a.cc.as_ref().map(bits), b.cc.as_ref().map(bits), "cc");
    assert_eq!(a.fc.as_ref().map(bits), b.fc.as_ref().map(bits), "fc");
    assert_eq!(a.t, b.t, "t");
    assert_eq!(
        a.friction_loads.as_ref().map(bits),
        b.friction_loads.as_ref().map(bits),
        "friction_loads"
    );
}

fn hoffmann() -> FrictionalOperator {
    FrictionalOperator {
        mc: mat(2, &[(0, 0, 1.0), (1, 1, 1.0)]),
        cc: None,
        kc: mat(2, &[(0, 0, 1.0), (0, 1, 0.1), (1, 0, 0.1), (1, 1, 1.2)]),
        fm: mat(2, &[]),
        fc: None,
        fk: mat(2, &[(0, 1, 1.0)]),
        t: None,
        friction_loads: None,
        modal: Default::default(),
    }
}

/// The eigenvalue with `Im > 0` and `Re >= 0` of `(lambda^2 I + K) u = 0` for a 2 x 2 `K`:
/// `lambda^2 = -s` with `s` an eigenvalue of `K`.
fn hoffmann_lambda(k: &[Vec<f64>]) -> (f64, f64) {
    let tr = k[0][0] + k[1][1];
    let det = k[0][0] * k[1][1] - k[0][1] * k[1][0];
    let disc = tr * tr - 4.0 * det;
    assert!(disc < 0.0, "no flutter: disc = {disc}");
    // s = tr/2 + i sqrt(-disc)/2, lambda^2 = -s = a + i b.
    let (a, b) = (-tr / 2.0, -(-disc).sqrt() / 2.0);
    let r = (a * a + b * b).sqrt();
    let re = ((r + a) / 2.0).sqrt();
    let im = ((r - a) / 2.0).sqrt() * b.signum();
    // Both roots +-(re + i im); pick Im > 0.
    let (re, im) = if im < 0.0 { (-re, -im) } else { (re, im) };
    (re.abs(), im)
}

#[test]
fn shipped_hoffmann_dir_is_the_methods_oracle() {
    let op = read_operator_dir(data_dir()).unwrap();
    assert_eq!(op.dim(), 2);
    assert_eq!(dense(&op.mc), vec![vec![1.0, 0.0], vec![0.0, 1.0]]);
    assert_eq!(dense(&op.kc), vec![vec![1.0, 0.1], vec![0.1, 1.2]]);
    assert_eq!(dense(&op.fk), vec![vec![0.0, 1.0], vec![0.0, 0.0]]);
    assert_eq!(op.fm.compute_nnz(), 0);
    assert!(op.cc.is_none() && op.fc.is_none() && op.t.is_none());
    assert_same(&op, &hoffmann());

    let qep = op.at(0.3).unwrap();
    let k = dense(&qep.k);
    assert_eq!(k[0][1], 0.1 - 0.3);
    let (re, im) = hoffmann_lambda(&k);
    assert!((re - 0.04762).abs() < 5e-6, "Re = {re}");
    assert!((im - 1.04989).abs() < 5e-6, "Im = {im}");
    // Below mu_c = 0.2 the pair is stable: the discriminant is positive.
    let k = dense(&op.at(0.1).unwrap().k);
    let tr = k[0][0] + k[1][1];
    assert!(tr * tr - 4.0 * (k[0][0] * k[1][1] - k[0][1] * k[1][0]) > 0.0);
}

#[test]
fn hoffmann_written_and_read_back() {
    let d = tmp("hoffmann");
    let op = hoffmann();
    let meta = OperatorMeta {
        scene: "hoffmann-2dof".into(),
        mu: 0.3,
        active_pairs: 0,
        source: "squeal-io test".into(),
    };
    write_operator_dir(&d, &op, &meta).unwrap();
    for f in ["Mc.mtx", "Kc.mtx", "FK.mtx", "README.txt", "operator.toml"] {
        assert!(d.join(f).is_file(), "{f} not written");
    }
    for f in ["Cc.mtx", "FM.mtx", "FC.mtx", "T.txt"] {
        assert!(!d.join(f).exists(), "{f} written for a zero part");
    }
    let back = read_operator_dir(&d).unwrap();
    assert_same(&op, &back);

    let readme = std::fs::read_to_string(d.join("README.txt")).unwrap();
    for s in [
        "X~ = X_c - mu F_X",
        "(lambda^2 M~ + lambda C~ + K~) u = 0",
        "Re(lambda) > 0",
        "kg",
        "N s/m",
        "N/m",
        "hoffmann-2dof",
        "0.3",
        "dofs:          2",
        "active pairs:  0",
    ] {
        assert!(readme.contains(s), "README lacks `{s}`:\n{readme}");
    }
    let meta_toml: toml::Table = std::fs::read_to_string(d.join("operator.toml"))
        .unwrap()
        .parse()
        .unwrap();
    assert_eq!(meta_toml["dofs"].as_integer(), Some(2));
    assert_eq!(meta_toml["has_damping"].as_bool(), Some(false));
    assert_eq!(meta_toml["units"].as_str(), Some("SI"));
    assert_eq!(meta_toml["source"].as_str(), Some("squeal-io test"));
    assert_eq!(meta_toml["scene"].as_str(), Some("hoffmann-2dof"));
    assert_eq!(meta_toml["mu_export"].as_float(), Some(0.3));
    let files: Vec<_> = meta_toml["files"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_str().unwrap())
        .collect();
    assert_eq!(files, ["Mc.mtx", "Kc.mtx", "FK.mtx"]);
}

/// A 4-DOF operator with every part and an index map from 5 unconstrained DOFs.
fn full_operator() -> FrictionalOperator {
    let m = |s: f64| {
        mat(
            4,
            &[
                (0, 0, 2.0 * s),
                (1, 0, 0.1 / 3.0),
                (0, 1, 0.1 / 3.0),
                (1, 1, s),
                (2, 2, std::f64::consts::E),
                (3, 3, 7.0 / 11.0),
                (3, 1, -1e-12),
            ],
        )
    };
    FrictionalOperator {
        mc: m(1.5),
        cc: Some(m(1e-3)),
        kc: m(3.3e7),
        fm: mat(4, &[(2, 0, -0.125), (3, 1, 1.0 / 7.0)]),
        fc: Some(mat(4, &[(2, 1, 2e-5)])),
        fk: mat(4, &[(2, 0, -4.4e6), (3, 1, 1.0e6 / 3.0)]),
        t: Some(vec![0, 1, 2, 3, 2]),
        friction_loads: Some(
            SparseMat::try_new_from_triplets(
                4,
                2,
                &[
                    faer::sparse::Triplet::new(2, 0, 1.0),
                    faer::sparse::Triplet::new(3, 1, -0.5),
                ],
            )
            .unwrap(),
        ),
        modal: Default::default(),
    }
}

#[test]
fn full_operator_round_trip_reproducible_and_stale_files_removed() {
    let d = tmp("full");
    let op = full_operator();
    let meta = OperatorMeta {
        scene: "pin \"on\" disc\\x".into(),
        mu: 0.45,
        active_pairs: 1,
        source: "test".into(),
    };
    write_operator_dir(&d, &op, &meta).unwrap();
    assert_same(&op, &read_operator_dir(&d).unwrap());
    let toml_text = std::fs::read_to_string(d.join("operator.toml")).unwrap();
    let t: toml::Table = toml_text.parse().unwrap();
    assert_eq!(t["scene"].as_str(), Some("pin \"on\" disc\\x"));
    assert_eq!(t["has_damping"].as_bool(), Some(true));
    assert_eq!(t["full_dofs"].as_integer(), Some(5));
    assert_eq!(
        std::fs::read_to_string(d.join("T.txt")).unwrap(),
        "0\n1\n2\n3\n2\n"
    );

    // Same operator, same bytes.
    let snapshot = |d: &Path| {
        let mut v: Vec<_> = std::fs::read_dir(d)
            .unwrap()
            .map(|e| {
                let p = e.unwrap().path();
                (
                    p.file_name().unwrap().to_owned(),
                    std::fs::read(&p).unwrap(),
                )
            })
            .collect();
        v.sort();
        v
    };
    let first = snapshot(&d);
    let d2 = tmp("full2");
    write_operator_dir(&d2, &op, &meta).unwrap();
    assert_eq!(first, snapshot(&d2));

    // Re-exporting an undamped operator without a map into the same directory.
    let mut undamped = op.clone();
    undamped.cc = None;
    undamped.fc = None;
    undamped.t = None;
    undamped.friction_loads = None;
    assert!(d.join("U.mtx").exists());
    write_operator_dir(&d, &undamped, &meta).unwrap();
    assert!(!d.join("Cc.mtx").exists() && !d.join("FC.mtx").exists());
    assert!(!d.join("T.txt").exists() && !d.join("U.mtx").exists());
    assert_same(&undamped, &read_operator_dir(&d).unwrap());
}

fn write_hoffmann_files(d: &Path) {
    for f in ["Mc.mtx", "Kc.mtx", "FK.mtx"] {
        std::fs::copy(data_dir().join(f), d.join(f)).unwrap();
    }
}

fn err_msg(d: &Path) -> String {
    read_operator_dir(d)
        .expect_err("invalid operator directory must be rejected")
        .to_string()
}

fn assert_has(msg: &str, parts: &[&str]) {
    for p in parts {
        assert!(msg.contains(p), "`{p}` missing from: {msg}");
    }
}

#[test]
fn missing_required_files() {
    let d = tmp("missing_kc");
    std::fs::copy(data_dir().join("Mc.mtx"), d.join("Mc.mtx")).unwrap();
    assert_has(
        &err_msg(&d),
        &["Kc.mtx", "required file is missing", "stiffness"],
    );
    let d = tmp("missing_mc");
    std::fs::copy(data_dir().join("Kc.mtx"), d.join("Kc.mtx")).unwrap();
    assert_has(
        &err_msg(&d),
        &["Mc.mtx", "required file is missing", "mass"],
    );
    let d = tmp("missing_dir").join("nope");
    assert_has(&err_msg(&d), &["nope", "operator directory"]);
}

#[test]
fn size_mismatch_names_the_file() {
    let d = tmp("mismatch");
    write_hoffmann_files(&d);
    write_mtx(d.join("FC.mtx"), &mat(3, &[(0, 0, 1.0)]), "").unwrap();
    let msg = err_msg(&d);
    assert_has(&msg, &["FC.mtx", "3 x 3", "expected 2 x 2 like Mc.mtx"]);
    assert!(!msg.contains("FK.mtx"));

    let d = tmp("mismatch_kc");
    write_hoffmann_files(&d);
    let rect = {
        let t = [Triplet::new(0usize, 0usize, 1.0)];
        SparseMat::try_new_from_triplets(2, 3, &t).unwrap()
    };
    write_mtx(d.join("Kc.mtx"), &rect, "").unwrap();
    assert_has(&err_msg(&d), &["Kc.mtx", "2 x 3", "2 x 2 like Mc.mtx"]);

    let d = tmp("nonsquare_mc");
    write_hoffmann_files(&d);
    write_mtx(d.join("Mc.mtx"), &rect, "").unwrap();
    assert_has(&err_msg(&d), &["Mc.mtx", "2 x 3", "square"]);
}

#[test]
fn malformed_member_file_is_named() {
    let d = tmp("malformed_fk");
    write_hoffmann_files(&d);
    std::fs::write(
        d.join("FK.mtx"),
        "%%MatrixMarket matrix coordinate real general\n2 2 1\n1 2 nan\n",
    )
    .unwrap();
    assert_has(&err_msg(&d), &["FK.mtx:3:", "not finite"]);
}

#[test]
fn index_map_is_validated() {
    let cases: [(&str, &str, &[&str]); 4] = [
        (
            "t_range",
            "0\n1\n2\n",
            &["T.txt:3:", "constrained DOF 2", "below the operator size 2"],
        ),
        ("t_short", "0\n", &["T.txt", "1 entries", "at least 2"]),
        (
            "t_text",
            "0\n# comment\n1\nx\n",
            &["T.txt:4:", "`x`", "integer"],
        ),
        (
            "t_onto",
            "0\n0\n0\n",
            &["T.txt", "constrained DOF 1 is the image of no"],
        ),
    ];
    for (name, text, parts) in cases {
        let d = tmp(name);
        write_hoffmann_files(&d);
        std::fs::write(d.join("T.txt"), text).unwrap();
        let e = read_operator_dir(&d).unwrap_err();
        assert!(matches!(e, IoError::IndexMap { .. }), "{name}: {e}");
        assert_has(&e.to_string(), parts);
    }
    let d = tmp("t_ok");
    write_hoffmann_files(&d);
    std::fs::write(d.join("T.txt"), "# pin normal -> disc\n0\n1\n1\n\n").unwrap();
    assert_eq!(read_operator_dir(&d).unwrap().t, Some(vec![0, 1, 1]));
}

#[test]
fn invalid_operator_is_not_written() {
    let d = tmp("bad_write");
    let meta = OperatorMeta::default();
    let mut op = hoffmann();
    op.fc = Some(mat(3, &[]));
    let msg = write_operator_dir(&d, &op, &meta).unwrap_err().to_string();
    assert_has(&msg, &["FC.mtx", "3 x 3", "2 x 2"]);
    let mut op = hoffmann();
    op.t = Some(vec![0, 2]);
    let msg = write_operator_dir(&d, &op, &meta).unwrap_err().to_string();
    assert_has(&msg, &["T.txt", "below the operator size 2"]);
    let mut op = hoffmann();
    op.fk = mat(2, &[(0, 1, f64::INFINITY)]);
    let msg = write_operator_dir(&d, &op, &meta).unwrap_err().to_string();
    assert_has(&msg, &["FK.mtx", "not finite"]);
    let bad_mu = OperatorMeta {
        mu: f64::NAN,
        ..OperatorMeta::default()
    };
    let msg = write_operator_dir(&d, &hoffmann(), &bad_mu)
        .unwrap_err()
        .to_string();
    assert_has(&msg, &["operator.toml", "mu = NaN"]);
    assert_eq!(
        std::fs::read_dir(&d).unwrap().count(),
        0,
        "nothing may be written"
    );
}

#[test]
fn friction_loads_with_the_wrong_row_count_are_rejected_naming_the_file() {
    let d = tmp("bad_u");
    write_hoffmann_files(&d);
    std::fs::write(
        d.join("U.mtx"),
        "%%MatrixMarket matrix coordinate real general\n3 1 1\n1 1 1.0\n",
    )
    .unwrap();
    let msg = err_msg(&d);
    assert_has(&msg, &["U.mtx", "3 x 1", "2 x nA"]);
}
