//! Property tests of the readers: arbitrary bytes, and valid files cut or corrupted at
//! random, give a result or an error naming the file, never a panic or an abort.

use proptest::prelude::*;
use std::path::Path;

const MTX: &str = "%%MatrixMarket matrix coordinate real symmetric\n% comment\n3 3 4\n1 1 2.0\n2 2 3.0\n3 3 4.0\n3 1 -1.0\n";

fn mtx(bytes: &[u8]) -> String {
    match squeal_io::read_mtx_from(bytes, Path::new("fuzz.mtx")) {
        Ok(m) => format!("{} x {}", m.nrows(), m.ncols()),
        Err(e) => e.to_string(),
    }
}

fn msh(bytes: &[u8]) -> String {
    match squeal_io::read_msh_bytes(bytes, Path::new("fuzz.msh")) {
        Ok(m) => format!("{} hexahedra", m.hexes.len()),
        Err(e) => e.to_string(),
    }
}

/// A one-hexahedron MSH 4.1 file (a unit cube with one physical volume).
fn one_hex() -> String {
    let mesh = squeal_fe::Mesh::block(&[0.0, 1.0], &[0.0, 1.0], &[0.0, 1.0]);
    squeal_io::msh_string(&mesh, &["zmin"], Path::new("cube.msh")).unwrap()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn matrix_market_never_panics(bytes in proptest::collection::vec(any::<u8>(), 0..400)) {
        let _ = mtx(&bytes);
    }

    #[test]
    fn matrix_market_cut_or_corrupted(cut in 0usize..MTX.len(), at in 0usize..MTX.len(), b in any::<u8>()) {
        let mut v = MTX.as_bytes()[..cut].to_vec();
        if at < v.len() {
            v[at] = b;
        }
        let r = mtx(&v);
        prop_assert!(r.contains("x") || r.contains("fuzz.mtx"), "{}", r);
    }

    #[test]
    fn gmsh_never_panics(bytes in proptest::collection::vec(any::<u8>(), 0..400)) {
        let _ = msh(&bytes);
    }

    #[test]
    fn gmsh_cut_or_corrupted(cut in 0usize..2000, at in 0usize..2000, b in any::<u8>()) {
        let file = one_hex();
        let cut = cut.min(file.len());
        let mut v = file.as_bytes()[..cut].to_vec();
        if at < v.len() {
            v[at] = b;
        }
        let r = msh(&v);
        prop_assert!(r.contains("hexahedra") || r.contains("fuzz.msh"), "{}", r);
    }
}

#[test]
fn the_valid_files_of_the_properties_read() {
    assert_eq!(mtx(MTX.as_bytes()), "3 x 3");
    assert_eq!(msh(one_hex().as_bytes()), "1 hexahedra");
}
