//! The constrained frictional operator of one active set (METHODS.md section 2).
//!
//! Linearized about the sliding equilibrium with the active pairs bilateral and sliding:
//! `(lambda^2 M + lambda C + K) u = (P~n + mu P~t)^T r`, `P~n u = 0`. With the slave-normal
//! selector `L = E_s` (the pin node's normal equation is the normal reaction) and the index
//! map `T` (each active pair's pin-normal DOF relabelled onto its disc partner,
//! `range T = ker P~n`), the reaction is eliminated:
//! `T^T (I - mu P~t^T L) (lambda^2 M + lambda C + K) T u_c = 0`.
//!
//! Stored apart for every `X` in {M, C, K}: `X_c = T^T X T` (relabel the triplets, sum
//! duplicates, O(nnz)) and `F_X = T^T P~t^T E_s X T` (the slave-normal rows of `X`,
//! columns relabelled, scattered with weights `+e_i` into the in-plane rows of the pin
//! node and `-e_i` into those of the disc node: `4 nc` rows touched), so that
//! `X~_c(mu) = X_c - mu F_X` costs nothing per mu. `T` is never a matrix. The friction load
//! directions `U = T^T P~t^T` (`F_X = U V_X^T`) are kept too, for reduction bases.
//!
//! Assumes the normals are `+e_z` (flat disc face) and `X` symmetric (rows of `X` are
//! read as its columns).

use crate::{ContactError, ContactSet, Result};
use squeal_core::faer::sparse::Triplet;
use squeal_core::{FrictionalOperator, SparseMat, SparseRef};

/// Builds the operator of the pairs `active` (a mask over `set`) for the model matrices
/// `m`, `k` and optional `c` (free DOFs, symmetric).
pub fn build_operator(
    m: SparseRef<'_>,
    c: Option<SparseRef<'_>>,
    k: SparseRef<'_>,
    set: &ContactSet,
    active: &[bool],
) -> Result<FrictionalOperator> {
    let n = k.nrows();
    if active.len() != set.len() {
        return Err(ContactError::Setup {
            field: "active".into(),
            message: format!(
                "active-set mask has {} entries, the contact set {} pairs",
                active.len(),
                set.len()
            ),
        });
    }
    if !active.iter().any(|&a| a) {
        return Err(ContactError::Setup {
            field: "active".into(),
            message: "no active pair: the operator needs at least one closed pair".into(),
        });
    }
    // T: eliminated pin-normal DOFs point at their disc partner
    let mut partner: Vec<Option<usize>> = vec![None; n];
    for i in (0..set.len()).filter(|&i| active[i]) {
        partner[set.pin_dofs[i][2]] = Some(set.disc_dofs[i][2]);
    }
    let mut t = vec![usize::MAX; n];
    let mut nc = 0;
    for j in 0..n {
        if partner[j].is_none() {
            t[j] = nc;
            nc += 1;
        }
    }
    for j in 0..n {
        if let Some(p) = partner[j] {
            t[j] = t[p];
        }
    }
    let relabel = |x: SparseRef<'_>| -> Result<SparseMat> {
        let mut trip = Vec::with_capacity(x.compute_nnz());
        for col in 0..x.ncols() {
            for (r, v) in x.row_idx_of_col(col).zip(x.val_of_col(col)) {
                trip.push(Triplet::new(t[r], t[col], *v));
            }
        }
        SparseMat::try_new_from_triplets(nc, nc, &trip).map_err(|e| ContactError::Setup {
            field: "operator".into(),
            message: format!("T^T X T: {e:?}"),
        })
    };
    let friction = |x: SparseRef<'_>| -> Result<SparseMat> {
        let mut trip = Vec::new();
        for i in (0..set.len()).filter(|&i| active[i]) {
            let s = set.pin_dofs[i];
            let md = set.disc_dofs[i];
            let e = set.direction[i];
            // row s_z of X = column s_z (X symmetric), columns relabelled by T
            for (col, v) in x.row_idx_of_col(s[2]).zip(x.val_of_col(s[2])) {
                for a in 0..2 {
                    if e[a] != 0.0 {
                        trip.push(Triplet::new(t[s[a]], t[col], e[a] * v));
                        trip.push(Triplet::new(t[md[a]], t[col], -e[a] * v));
                    }
                }
            }
        }
        SparseMat::try_new_from_triplets(nc, nc, &trip).map_err(|e| ContactError::Setup {
            field: "operator".into(),
            message: format!("F_X: {e:?}"),
        })
    };
    // U = T^T P~t^T: one column per active pair, +e_i on the pin's in-plane DOFs and
    // -e_i on the disc's (the friction load directions, F_X = U V_X^T)
    let mut loads = Vec::new();
    for (col, i) in (0..set.len()).filter(|&i| active[i]).enumerate() {
        let (s, md, e) = (set.pin_dofs[i], set.disc_dofs[i], set.direction[i]);
        for a in 0..2 {
            if e[a] != 0.0 {
                loads.push(Triplet::new(t[s[a]], col, e[a]));
                loads.push(Triplet::new(t[md[a]], col, -e[a]));
            }
        }
    }
    let n_active = active.iter().filter(|&&a| a).count();
    let friction_loads = SparseMat::try_new_from_triplets(nc, n_active, &loads).map_err(|e| {
        ContactError::Setup {
            field: "operator".into(),
            message: format!("U = T^T P~t^T: {e:?}"),
        }
    })?;
    Ok(FrictionalOperator {
        mc: relabel(m)?,
        cc: c.map(relabel).transpose()?,
        kc: relabel(k)?,
        fm: friction(m)?,
        fc: c.map(friction).transpose()?,
        fk: friction(k)?,
        t: Some(t),
        friction_loads: Some(friction_loads),
    })
}
