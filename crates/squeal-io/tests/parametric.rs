//! Parametric operators (`operator.toml`, docs/operators.md) on the small lattice operator
//! written by `benches/parametric_operator.py` (84 DOFs, components in `.mtx` and in a
//! compressed `.mat`): the parts at a parameter value equal the sums of the components
//! with their coefficients; invalid descriptions, non-finite coefficients and singular or
//! indefinite masses are refused with the file and the key named; a plain operator
//! directory reads as a constant parametric operator.

use faer::sparse::Triplet;
use squeal_core::{FrictionalOperator, SparseMat};
use squeal_io::{read_mtx, write_operator_dir, MatFile, OperatorMeta, ParametricOperator};
use std::path::{Path, PathBuf};

fn lattice() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/parametric-lattice")
}

/// A fresh copy of the lattice directory with `operator.toml` replaced by `toml`.
fn variant(name: &str, toml: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("squeal-io-parametric")
        .join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    for e in std::fs::read_dir(lattice()).unwrap() {
        let p = e.unwrap().path();
        std::fs::copy(&p, d.join(p.file_name().unwrap())).unwrap();
    }
    std::fs::write(d.join("operator.toml"), toml).unwrap();
    d
}

fn max_rel_diff(a: &SparseMat, b: &SparseMat) -> f64 {
    let (da, db) = (a.as_ref().to_dense(), b.as_ref().to_dense());
    let mut worst = 0.0f64;
    let mut scale = 0.0f64;
    for j in 0..a.ncols() {
        for i in 0..a.nrows() {
            worst = worst.max((da[(i, j)] - db[(i, j)]).abs());
            scale = scale.max(da[(i, j)].abs());
        }
    }
    worst / scale
}

/// `sum c_i A_i` densely.
fn combo(parts: &[(f64, &SparseMat)]) -> SparseMat {
    let n = parts[0].1.nrows();
    let mut t = Vec::new();
    for (c, a) in parts {
        for j in 0..n {
            for (i, v) in a.row_idx_of_col(j).zip(a.val_of_col(j)) {
                t.push(Triplet::new(i, j, c * v));
            }
        }
    }
    SparseMat::try_new_from_triplets(n, n, &t).unwrap()
}

#[test]
fn parts_at_a_value_are_the_weighted_sums_of_the_components() {
    let p = ParametricOperator::read(lattice()).unwrap();
    assert_eq!((p.dim(), p.parameter()), (84, Some("W")));
    assert_eq!(p.range(), Some((1.0, 100.0)));
    let coeffs: Vec<&str> = p.terms("C").iter().map(|t| t.coeff_text.as_str()).collect();
    assert_eq!(coeffs, ["1", "1/W", "W"]);
    assert!(p.terms("K")[2].source.ends_with("components.mat:KGeo"));
    let dir = lattice();
    let mtx = |n: &str| read_mtx(dir.join(format!("{n}.mtx"))).unwrap();
    let mat = MatFile::open(dir.join("components.mat")).unwrap();
    let (m, k1, d1, fk) = (mtx("M"), mtx("K1"), mtx("D1"), mtx("FK"));
    let (kr, kgeo, dr, dg) = (
        mat.matrix("KR").unwrap(),
        mat.matrix("KGeo").unwrap(),
        mat.matrix("DR").unwrap(),
        mat.matrix("DG").unwrap(),
    );
    for w in [1.0, 5.0, 20.0] {
        let op = p.at(w).unwrap();
        assert!(max_rel_diff(&op.mc, &m) <= 1e-15);
        let c = combo(&[(1.0, &d1), (1.0 / w, &dr), (w, &dg)]);
        assert!(
            max_rel_diff(op.cc.as_ref().unwrap(), &c) <= 1e-15,
            "W = {w}"
        );
        let k = combo(&[(1.0, &k1), (1.0, &kr), (w * w, &kgeo)]);
        assert!(max_rel_diff(&op.kc, &k) <= 1e-15, "W = {w}");
        assert!(max_rel_diff(&op.fk, &fk) <= 1e-15);
        assert!(op.fc.is_none() && op.fm.compute_nnz() == 0 && op.t.is_none());
    }
    // the gyroscopic part is skew and the friction part not symmetric: both kept as is
    let dgd = dg.as_ref().to_dense();
    assert!((0..84).any(|i| dgd[(i, i ^ 1)] != 0.0 && dgd[(i, i ^ 1)] == -dgd[(i ^ 1, i)]));
    assert!(p
        .at(0.5)
        .unwrap_err()
        .to_string()
        .contains("outside the declared range"));
    assert!(p.at(f64::NAN).is_err());
}

const HEAD: &str = "format = \"squeal-parametric-operator\"\nversion = 1\nparameter = \"W\"\n\
                    mat = \"components.mat\"\n";

fn refused(name: &str, body: &str) -> String {
    let d = variant(name, &format!("{HEAD}{body}"));
    let e = ParametricOperator::read(&d).unwrap_err().to_string();
    assert!(e.contains(name), "{name}: the message names the file: {e}");
    e
}

#[test]
fn invalid_descriptions_are_refused_with_the_key_named() {
    let ok_mk = "M = [\"M\"]\nK = [\"K1\"]\n";
    for (name, body, says) in [
        (
            "typo",
            "M = [\"M\"]\nK = [\"K1\"]\nKK = [\"K1\"]\n",
            "KK: unknown key",
        ),
        (
            "formula",
            "M = [\"M\"]\nK = [{ matrix = \"K1\", coeff = \"W^\" }]\n",
            "K[0].coeff",
        ),
        (
            "name",
            "M = [\"M\"]\nK = [{ matrix = \"K1\", coeff = \"V*2\" }]\n",
            "unknown name `V`",
        ),
        ("nomass", "K = [\"K1\"]\n", "M: missing"),
        ("empty", "M = [\"M\"]\nK = []\n", "K: empty list"),
        (
            "term",
            "M = [\"M\"]\nK = [{ matrix = \"K1\", scale = 2 }]\n",
            "unknown key `scale`",
        ),
        ("absent", "M = [\"M\"]\nK = [\"K9\"]\n", "K9"),
    ] {
        let e = refused(name, body);
        assert!(e.contains(says), "{name}: {e}");
    }
    // a component of another size
    let d = variant("size", &format!("{HEAD}{ok_mk}C = [\"FK\"]\n"));
    let mut t = vec![Triplet::new(0, 0, 1.0)];
    t.push(Triplet::new(2, 2, 1.0));
    let small = SparseMat::try_new_from_triplets(3, 3, &t).unwrap();
    squeal_io::write_mtx(d.join("FK.mtx"), &small, "3 x 3").unwrap();
    let e = ParametricOperator::read(&d).unwrap_err().to_string();
    assert!(e.contains("FK.mtx") && e.contains("84 x 84"), "{e}");
}

#[test]
fn a_coefficient_that_is_not_finite_is_refused_at_that_value() {
    let d = variant(
        "pole",
        &format!("{HEAD}M = [\"M\"]\nC = [{{ matrix = \"DR\", coeff = \"1/W\" }}]\nK = [\"K1\"]\n"),
    );
    let p = ParametricOperator::read(&d).unwrap();
    assert!(p.at(2.0).is_ok());
    let e = p.at(0.0).unwrap_err().to_string();
    assert!(
        e.contains("C[0].coeff") && e.contains("`1/W` of `DR` is inf at W = 0"),
        "{e}"
    );
}

#[test]
fn singular_or_indefinite_masses_are_refused() {
    for (name, m, says) in [
        (
            "zero",
            "[\"M\", { matrix = \"M\", coeff = \"-1\" }]",
            "the mass is zero",
        ),
        (
            "negative",
            "[{ matrix = \"M\", coeff = \"1 - W\" }]",
            "indefinite or singular at W = 3",
        ),
        (
            "massless",
            "[\"M\", { matrix = \"Mx\", coeff = \"-1\" }]",
            "singular",
        ),
    ] {
        let d = variant(name, &format!("{HEAD}M = {m}\nK = [\"K1\"]\n"));
        // Mx: the mass of DOF 0 alone, so that M - Mx leaves DOF 0 massless
        let m0 = read_mtx(d.join("M.mtx")).unwrap();
        let v = m0.as_ref().to_dense()[(0, 0)];
        let mx = SparseMat::try_new_from_triplets(84, 84, &[Triplet::new(0, 0, v)]).unwrap();
        squeal_io::write_mtx(d.join("Mx.mtx"), &mx, "mass of DOF 0").unwrap();
        let p = ParametricOperator::read(&d).unwrap();
        let e = p.at(3.0).unwrap_err().to_string();
        assert!(e.contains(": M: ") && e.contains(says), "{name}: {e}");
    }
}

#[test]
fn a_plain_operator_directory_is_a_constant_parametric_operator() {
    let p = ParametricOperator::read(lattice()).unwrap();
    let op: FrictionalOperator = p.at(7.0).unwrap();
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join("squeal-io-parametric/plain");
    let _ = std::fs::remove_dir_all(&d);
    write_operator_dir(&d, &op, &OperatorMeta::default()).unwrap();
    let c = ParametricOperator::read(&d).unwrap();
    assert_eq!(c.parameter(), None);
    let back = c.at(123.0).unwrap();
    assert!(max_rel_diff(&back.kc, &op.kc) == 0.0);
    assert!(max_rel_diff(back.cc.as_ref().unwrap(), op.cc.as_ref().unwrap()) == 0.0);
    assert!(max_rel_diff(&back.fk, &op.fk) == 0.0);
}
