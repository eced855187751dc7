//! Patch test on a distorted multi-element mesh: an affine displacement imposed on the
//! boundary must be reproduced exactly inside (constant strain, equilibrium).

use crate::common::{perturb, steel};
use squeal_core::faer::linalg::solvers::Solve;
use squeal_core::faer::sparse::linalg::solvers::{Llt, SymbolicLlt};
use squeal_core::faer::sparse::Triplet;
use squeal_core::faer::{MatMut, Side};
use squeal_core::{Material, SparseMat};
use squeal_fe::mesh::linspace;
use squeal_fe::{assemble, DofMap, Mesh};

const LX: f64 = 0.03;
const LY: f64 = 0.02;
const LZ: f64 = 0.025;
const NX: usize = 4;
const NY: usize = 3;
const NZ: usize = 3;

/// The affine field `u = A x + c` (general A: strain and rotation).
const A: [[f64; 3]; 3] = [
    [1.0e-3, 0.3e-3, -0.4e-3],
    [0.2e-3, -0.7e-3, 0.5e-3],
    [-0.6e-3, 0.1e-3, 0.8e-3],
];
const C: [f64; 3] = [1e-5, -2e-5, 3e-5];

fn affine(p: [f64; 3], comp: usize) -> f64 {
    C[comp] + (0..3).map(|j| A[comp][j] * p[j]).sum::<f64>()
}

/// A 4 x 3 x 3 block: interior nodes moved by up to 25 % of the spacing, boundary nodes
/// by up to 10 % (faces become warped, so no element is a parallelepiped).
fn distorted_patch() -> (Mesh, Vec<bool>) {
    let mut mesh = Mesh::block(
        &linspace(0.0, LX, NX),
        &linspace(0.0, LY, NY),
        &linspace(0.0, LZ, NZ),
    );
    let mut boundary = vec![false; mesh.n_nodes()];
    for set in ["xmin", "xmax", "ymin", "ymax", "zmin", "zmax"] {
        for &n in mesh.node_set(set).unwrap() {
            boundary[n] = true;
        }
    }
    let h = [LX / NX as f64, LY / NY as f64, LZ / NZ as f64];
    perturb(&mut mesh, h, 0.25, 0xface_cafe, &|n| boundary[n]);
    perturb(&mut mesh, h, 0.10, 0xdead_beef, &|n| !boundary[n]);
    (mesh, boundary)
}

/// Imposes the affine field on the boundary nodes, solves for the interior ones and
/// returns `max |u - u_exact| / max |u_exact|` over the interior DOFs.
fn patch_error(mat: &dyn Material) -> f64 {
    let (mesh, boundary) = distorted_patch();
    // full K on all DOFs; the Dirichlet elimination is done here by hand
    let dofs = DofMap::new(&mesh, &[]);
    let asm = assemble(&mesh, &dofs, &[mat]).expect("assembly");
    assert!(asm.min_det_j > 0.0);
    let k = asm.k.as_ref();
    let n = dofs.n_free();
    // local index of each interior (unknown) DOF, exact value of every DOF
    let mut local = vec![None; n];
    let mut interior = Vec::new();
    let mut exact = vec![0.0; n];
    for (i, &d) in dofs.full_of_free.iter().enumerate() {
        let (node, comp) = (d / 3, d % 3);
        exact[i] = affine(mesh.nodes[node], comp);
        if !boundary[node] {
            local[i] = Some(interior.len());
            interior.push(i);
        }
    }
    let ni = interior.len();
    assert_eq!(ni, 3 * (NX - 1) * (NY - 1) * (NZ - 1));
    // K_ii and rhs = -K_ib u_b
    let mut trip = Vec::new();
    let mut rhs = vec![0.0; ni];
    for j in 0..n {
        for (i, &v) in k.row_idx_of_col(j).zip(k.val_of_col(j)) {
            let Some(li) = local[i] else { continue };
            match local[j] {
                Some(lj) => trip.push(Triplet::new(li, lj, v)),
                None => rhs[li] -= v * exact[j],
            }
        }
    }
    let kii = SparseMat::try_new_from_triplets(ni, ni, &trip).expect("K_ii");
    let symbolic = SymbolicLlt::try_new(kii.symbolic(), Side::Lower).expect("symbolic LLT");
    let llt = Llt::try_new_with_symbolic(symbolic, kii.as_ref(), Side::Lower).expect("K_ii is SPD");
    let mut u = rhs;
    llt.solve_in_place(MatMut::from_column_major_slice_mut(&mut u, ni, 1));
    let scale = exact.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    let err = interior
        .iter()
        .zip(&u)
        .fold(0.0f64, |a, (&i, v)| a.max((v - exact[i]).abs()));
    err / scale
}

#[test]
fn affine_field_is_exact_on_a_distorted_patch_isotropic() {
    let err = patch_error(&steel());
    eprintln!("patch: isotropic steel: max interior error / max |u| = {err:.2e}");
    assert!(err < 1e-10, "patch test failed (isotropic): {err:e}");
}

#[test]
fn affine_field_is_exact_on_a_distorted_patch_transversely_isotropic() {
    let mat = squeal_materials::TransverselyIsotropic::new(
        15.3e9,
        5.4e9,
        0.15,
        0.15,
        None,
        [0.3, 0.2, 1.0],
        4000.0,
    )
    .expect("valid lining material");
    // the tilted axis couples every Voigt component
    let d = mat.elasticity();
    assert!(d[0][4].abs() > 1e6 && d[3][5].abs() > 1e6, "D = {d:?}");
    let err = patch_error(&mat);
    eprintln!("patch: transversely isotropic (axis [0.3, 0.2, 1]): max interior error / max |u| = {err:.2e}");
    assert!(
        err < 1e-10,
        "patch test failed (transversely isotropic): {err:e}"
    );
}
