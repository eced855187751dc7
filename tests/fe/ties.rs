//! Node ties (a fine mesh hanging on a coarser one): a fine 4 x 4 x 2 block under a coarse
//! 2 x 2 x 2 block (both distorted in their interiors), the fine block's top nodes tied
//! bilinearly to the coarse block's bottom face. The tied pair must behave as one body:
//! six rigid modes (twelve if the tie were lost), rigid motions strain nothing, a uniform
//! strain stores exactly its energy (the tie is conforming), the mass is the volumes'.

use crate::common::{norm1, perturb, quad, steel, E_STEEL, RHO_STEEL};
use approx::assert_relative_eq;
use squeal_core::eigen::dense_symmetric;
use squeal_core::{Material, SymmetricProblem};
use squeal_fe::mesh::{face_ties, hex_volume, linspace};
use squeal_fe::{assemble, DofMap, Mesh, Tie};

const L: f64 = 0.02;
const H: f64 = 0.01;

/// The two blocks (fine below, coarse above, not merged) and the ties of the fine top.
fn tied_blocks() -> (Mesh, Vec<Tie>) {
    let mut fine = Mesh::block(
        &linspace(0.0, L, 4),
        &linspace(0.0, L, 4),
        &linspace(0.0, H, 2),
    );
    let top: Vec<usize> = fine.node_set("zmax").unwrap().to_vec();
    let bottom: Vec<usize> = fine.node_set("zmin").unwrap().to_vec();
    // distort the interior only: the tied face and the free bottom stay planar grids
    perturb(
        &mut fine,
        [L / 4.0, L / 4.0, H / 2.0],
        0.15,
        0xfeed_0001,
        &|n| top.contains(&n) || bottom.contains(&n),
    );
    let mut coarse = Mesh::block(
        &linspace(0.0, L, 2),
        &linspace(0.0, L, 2),
        &linspace(H, 2.0 * H, 2),
    );
    let face: Vec<usize> = coarse.node_set("zmin").unwrap().to_vec();
    perturb(
        &mut coarse,
        [L / 2.0, L / 2.0, H / 2.0],
        0.15,
        0xfeed_0002,
        &|n| face.contains(&n),
    );
    let mut mesh = Mesh::default();
    mesh.append(&coarse, "coarse.", None);
    mesh.append(&fine, "fine.", None);
    let ties = face_ties(
        &mesh,
        mesh.node_set("fine.zmax").unwrap(),
        mesh.node_set("coarse.zmin").unwrap(),
        &linspace(0.0, L, 2),
        &linspace(0.0, L, 2),
    )
    .expect("ties");
    (mesh, ties)
}

/// The linear field `u = A x` on the free DOFs.
fn linear_field(mesh: &Mesh, dofs: &DofMap, a: [[f64; 3]; 3]) -> Vec<f64> {
    dofs.full_of_free
        .iter()
        .map(|&d| {
            let p = mesh.nodes[d / 3];
            (0..3).map(|j| a[d % 3][j] * p[j]).sum()
        })
        .collect()
}

#[test]
fn tied_blocks_act_as_one_body() {
    let (mesh, ties) = tied_blocks();
    assert_eq!(ties.len(), 25, "every node of the fine top is tied");
    assert!(
        ties.iter().filter(|t| t.masters.len() == 1).count() == 9,
        "the 9 fine nodes on coarse grid points follow one master"
    );
    let dofs = DofMap::with_ties(&mesh, &[], &ties).expect("dof map");
    assert_eq!(dofs.n_free(), 3 * (mesh.n_nodes() - 25));
    assert_eq!(dofs.tied.len(), 75);
    let asm = assemble(&mesh, &dofs, &[&steel()]).expect("assembly");
    let (k, m) = (asm.k.as_ref(), asm.m.as_ref());
    let volume: f64 = (0..mesh.hexes.len())
        .map(|e| hex_volume(&mesh.hex_coords(e)))
        .sum();
    // translations carry the whole mass through the masters
    for c in 0..3 {
        let t: Vec<f64> = dofs
            .full_of_free
            .iter()
            .map(|&d| if d % 3 == c { 1.0 } else { 0.0 })
            .collect();
        assert_relative_eq!(quad(m, &t, &t), RHO_STEEL * volume, max_relative = 1e-12);
    }
    // rigid rotations strain nothing
    let kn = norm1(k);
    for axis in 0..3 {
        let mut a = [[0.0; 3]; 3];
        let (i, j) = ((axis + 1) % 3, (axis + 2) % 3);
        a[i][j] = -1.0 / L;
        a[j][i] = 1.0 / L;
        let r = linear_field(&mesh, &dofs, a);
        let mut kr = vec![0.0; r.len()];
        squeal_core::linalg::spmv(k, &r, &mut kr);
        let rel = kr.iter().fold(0.0f64, |s, v| s.max(v.abs()))
            / (kn * r.iter().fold(0.0f64, |s, v| s.max(v.abs())));
        eprintln!("ties: rotation about axis {axis}: |K r| / (|K| |r|) = {rel:.2e}");
        assert!(
            rel < 1e-12,
            "a rigid rotation strains the tied blocks: {rel:e}"
        );
    }
    // a uniform strain stores exactly V eps^T D eps
    let eps = [
        [1.0e-3, 0.4e-3, -0.2e-3],
        [0.4e-3, -0.5e-3, 0.3e-3],
        [-0.2e-3, 0.3e-3, 0.8e-3],
    ];
    let q = linear_field(&mesh, &dofs, eps);
    let voigt = [
        eps[0][0],
        eps[1][1],
        eps[2][2],
        2.0 * eps[0][1],
        2.0 * eps[1][2],
        2.0 * eps[2][0],
    ];
    let dm = steel().elasticity();
    let exact: f64 = (0..6)
        .flat_map(|r| (0..6).map(move |c| (r, c)))
        .map(|(r, c)| voigt[r] * dm[r][c] * voigt[c])
        .sum::<f64>()
        * volume;
    let energy = quad(k, &q, &q);
    eprintln!("ties: uniform strain energy {energy:.9e} J, exact {exact:.9e} J");
    assert_relative_eq!(energy, exact, max_relative = 1e-10);
    // the tied nodes follow the field: expand gives them A x too
    let full = dofs.expand(&q);
    for t in &ties {
        let p = mesh.nodes[t.slave];
        for c in 0..3 {
            let want: f64 = (0..3).map(|j| eps[c][j] * p[j]).sum();
            assert!((full[3 * t.slave + c] - want).abs() <= 1e-15 + 1e-12 * want.abs());
        }
    }
    // six rigid modes, then elastic ones (twelve zeros if the blocks were not tied)
    let (mut lam, _) = dense_symmetric(&SymmetricProblem { k, m }).expect("eigen");
    lam.sort_by(f64::total_cmp);
    let scale = E_STEEL / RHO_STEEL / (L * L);
    let zeros = lam.iter().filter(|l| l.abs() < 1e-8 * lam[6]).count();
    eprintln!(
        "ties: omega^2[0..8] / (c/L)^2 = {:?}",
        lam[..8].iter().map(|l| l / scale).collect::<Vec<_>>()
    );
    assert_eq!(zeros, 6);
    assert!(
        lam[6] > 0.05 * scale,
        "7th eigenvalue not elastic: {:e}",
        lam[6]
    );
}

#[test]
fn untied_blocks_have_twelve_rigid_modes() {
    // the control: the same mesh without its ties is two free bodies
    let (mesh, _) = tied_blocks();
    let dofs = DofMap::new(&mesh, &[]);
    let asm = assemble(&mesh, &dofs, &[&steel()]).expect("assembly");
    let (mut lam, _) = dense_symmetric(&SymmetricProblem {
        k: asm.k.as_ref(),
        m: asm.m.as_ref(),
    })
    .expect("eigen");
    lam.sort_by(f64::total_cmp);
    let zeros = lam.iter().filter(|l| l.abs() < 1e-8 * lam[12]).count();
    assert_eq!(zeros, 12);
}

#[test]
fn bad_ties_are_errors() {
    let (mesh, ties) = tied_blocks();
    let mut twice = ties.clone();
    twice.push(ties[0].clone());
    let e = DofMap::with_ties(&mesh, &[], &twice).unwrap_err();
    assert!(e.contains("tied twice"), "{e}");
    let mut chain = ties.clone();
    chain.push(Tie {
        slave: ties[1].masters[0].0,
        masters: vec![(ties[0].slave, 1.0)],
    });
    let e = DofMap::with_ties(&mesh, &[], &chain).unwrap_err();
    assert!(e.contains("tied itself"), "{e}");
    let mut nan = ties.clone();
    nan[0].masters[0].1 = f64::NAN;
    let e = DofMap::with_ties(&mesh, &[], &nan).unwrap_err();
    assert!(e.contains("finite"), "{e}");
    // a slave beyond the master grid
    let e = face_ties(
        &mesh,
        mesh.node_set("fine.zmax").unwrap(),
        mesh.node_set("coarse.zmin").unwrap(),
        &linspace(0.0, 0.5 * L, 1),
        &linspace(0.0, L, 2),
    )
    .unwrap_err();
    assert!(e.contains("no master node") || e.contains("outside"), "{e}");
}
