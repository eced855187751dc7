//! Parallel sparse assembly of the stiffness and mass matrices on the free DOFs.
//!
//! The compressed-column pattern is built once from the node graph (3x3 blocks between
//! nodes sharing an element, eliminated DOFs left out). Elements are then split into one
//! chunk per worker thread; each chunk scatters its element matrices into a private
//! value array (binary search of the row in the column), and the arrays are summed.
//! Memory: one value array (8 bytes x nnz) per worker and matrix. A tied node's entries
//! go to its masters' DOFs, times their weights (`T^T K_e T`).

use crate::dofs::{tied_node_graph, DofMap};
use crate::hex8::hex8_matrices;
use crate::mesh::Mesh;
use rayon::prelude::*;
use squeal_core::faer::sparse::SymbolicSparseColMat;
use squeal_core::{Error, Material, Result, SparseMat};

/// Assembled global matrices on the free DOFs.
#[derive(Debug, Clone)]
pub struct Assembled {
    /// Stiffness (N/m).
    pub k: SparseMat,
    /// Consistent mass (kg).
    pub m: SparseMat,
    /// Total mass of the mesh (kg), eliminated DOFs included.
    pub total_mass: f64,
    /// Smallest Jacobian determinant met at a Gauss point (m^3 per unit reference volume).
    pub min_det_j: f64,
}

/// The symbolic pattern on the free DOFs: `(col_ptr, row_idx)`, rows sorted.
pub fn pattern(mesh: &Mesh, dofs: &DofMap) -> (Vec<usize>, Vec<usize>) {
    let adj = tied_node_graph(mesh, &dofs.node_ties());
    let n = dofs.n_free();
    let mut col_ptr = Vec::with_capacity(n + 1);
    let mut row_idx = Vec::new();
    col_ptr.push(0);
    for &full in &dofs.full_of_free {
        let node = full / 3;
        let mut rows: Vec<usize> = std::iter::once(node)
            .chain(adj[node].iter().copied())
            .flat_map(|b| (0..3).filter_map(move |c| dofs.free_of_full[3 * b + c]))
            .collect();
        rows.sort_unstable();
        row_idx.extend_from_slice(&rows);
        col_ptr.push(row_idx.len());
    }
    (col_ptr, row_idx)
}

/// Assembles `K` and `M` of `mesh` on the free DOFs of `dofs`; element `e` uses
/// `materials[mesh.hex_body[e]]`.
pub fn assemble(mesh: &Mesh, dofs: &DofMap, materials: &[&dyn Material]) -> Result<Assembled> {
    if let Some(&b) = mesh.hex_body.iter().find(|&&b| b >= materials.len()) {
        return Err(Error::Invalid(format!(
            "element of body {b} but only {} materials given",
            materials.len()
        )));
    }
    let n = dofs.n_free();
    let (col_ptr, row_idx) = pattern(mesh, dofs);
    let nnz = row_idx.len();
    let props: Vec<_> = materials
        .iter()
        .map(|m| (m.elasticity(), m.density()))
        .collect();
    let mut has_tie = vec![false; mesh.n_nodes()];
    for (d, _) in &dofs.tied {
        has_tie[d / 3] = true;
    }
    let threads = rayon::current_num_threads().max(1);
    let chunk = mesh.hexes.len().div_ceil(threads).max(1);
    let parts: Vec<(Vec<f64>, Vec<f64>, f64, f64)> = (0..mesh.hexes.len())
        .collect::<Vec<_>>()
        .par_chunks(chunk)
        .map(|elems| {
            let mut kv = vec![0.0; nnz];
            let mut mv = vec![0.0; nnz];
            let mut mass = 0.0;
            let mut min_det = f64::INFINITY;
            let mut buf = Vec::new();
            let mut lists: Vec<Vec<(usize, f64)>> = vec![Vec::new(); 24];
            for &e in elems {
                let (d, rho) = &props[mesh.hex_body[e]];
                let em = hex8_matrices(&mesh.hex_coords(e), d, *rho);
                mass += rho * em.volume;
                min_det = min_det.min(em.min_det_j);
                if mesh.hexes[e].iter().any(|&n| has_tie[n]) {
                    // T^T K_e T: each local DOF follows a list of free DOFs
                    for (a, l) in lists.iter_mut().enumerate() {
                        dofs.follows(3 * mesh.hexes[e][a / 3] + a % 3, &mut buf);
                        l.clone_from(&buf);
                    }
                    for (b, lb) in lists.iter().enumerate() {
                        for &(col, wb) in lb {
                            let rows = &row_idx[col_ptr[col]..col_ptr[col + 1]];
                            for (a, la) in lists.iter().enumerate() {
                                for &(row, wa) in la {
                                    let pos =
                                        col_ptr[col] + rows.binary_search(&row).expect("pattern");
                                    kv[pos] += wa * wb * em.ke[a][b];
                                    mv[pos] += wa * wb * em.me[a][b];
                                }
                            }
                        }
                    }
                    continue;
                }
                let free: [Option<usize>; 24] =
                    std::array::from_fn(|a| dofs.free_of_full[3 * mesh.hexes[e][a / 3] + a % 3]);
                for (b, fb) in free.iter().enumerate() {
                    let Some(col) = *fb else { continue };
                    let rows = &row_idx[col_ptr[col]..col_ptr[col + 1]];
                    for (a, fa) in free.iter().enumerate() {
                        let Some(row) = *fa else { continue };
                        let pos = col_ptr[col] + rows.binary_search(&row).expect("pattern");
                        kv[pos] += em.ke[a][b];
                        mv[pos] += em.me[a][b];
                    }
                }
            }
            (kv, mv, mass, min_det)
        })
        .collect();
    let mut kv = vec![0.0; nnz];
    let mut mv = vec![0.0; nnz];
    let (mut total_mass, mut min_det_j) = (0.0, f64::INFINITY);
    for (k, m, mass, det) in parts {
        kv.iter_mut().zip(&k).for_each(|(a, b)| *a += b);
        mv.iter_mut().zip(&m).for_each(|(a, b)| *a += b);
        total_mass += mass;
        min_det_j = min_det_j.min(det);
    }
    if min_det_j <= 0.0 {
        return Err(Error::Invalid(format!(
            "inverted or degenerate hexahedron: min det J = {min_det_j:e}"
        )));
    }
    let sym = SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx);
    Ok(Assembled {
        k: SparseMat::new(sym.clone(), kv),
        m: SparseMat::new(sym, mv),
        total_mass,
        min_det_j,
    })
}
