//! The constrained frictional operator of one active set.
//!
//! Linearized about the sliding equilibrium with the active pairs bilateral and sliding:
//! `(lambda^2 M + lambda C + K) u = (P~n + mu P~t)^T r`, `P~n u = 0`. With the slave-normal
//! selector `L = E_s` (the pin node's normal equation is the normal reaction) and the index
//! map `T` (each active pair's pin-normal DOF relabelled onto its disc partner,
//! `range T = ker P~n`), the reaction is eliminated:
//! `T^T (I - mu P~t^T L) (lambda^2 M + lambda C + K) T u_c = 0`.
//!
//! Stored apart for every `X` in {M, C, K}: `X_c = T^T X T` (each column of `X_c` gathers
//! the one or two columns of `X` that `T` maps onto it, rows relabelled, duplicates summed:
//! O(nnz)) and `F_X = T^T P~t^T E_s X T` (the slave-normal rows of `X`,
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
    let (t, nc) = index_map(&partner);
    let relabel = |x: SparseRef<'_>| -> Result<SparseMat> { Ok(relabel(x, &t, nc)) };
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
        modal: Default::default(),
    })
}

/// The index map `T` of the eliminated DOFs (`partner[j]`: the DOF that DOF `j` is tied
/// to, itself kept): the kept DOFs numbered in order, each eliminated one onto its
/// partner's number. Returns the map and the number of constrained DOFs.
fn index_map(partner: &[Option<usize>]) -> (Vec<usize>, usize) {
    let n = partner.len();
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
    (t, nc)
}

/// `T^T X T` for the index map `t` onto `nc` constrained DOFs: column `c` gathers the
/// columns `j` with `t[j] = c` (in ascending `j`), each entry's row relabelled to `t[r]`,
/// then sorted by row (stable, so duplicates are summed in the order of the columns of
/// `X`, as a column-major triplet list would sum them).
fn relabel(x: SparseRef<'_>, t: &[usize], nc: usize) -> SparseMat {
    use squeal_core::faer::sparse::{SparseColMat, SymbolicSparseColMat};
    // the source columns of every target column, grouped
    let mut start = vec![0usize; nc + 1];
    for &c in t {
        start[c + 1] += 1;
    }
    for c in 0..nc {
        start[c + 1] += start[c];
    }
    let mut next = start.clone();
    let mut sources = vec![0usize; t.len()];
    for (j, &c) in t.iter().enumerate() {
        sources[next[c]] = j;
        next[c] += 1;
    }
    let mut col_ptr = Vec::with_capacity(nc + 1);
    col_ptr.push(0usize);
    let mut rows = Vec::with_capacity(x.compute_nnz());
    let mut vals = Vec::with_capacity(x.compute_nnz());
    let mut buf: Vec<(usize, f64)> = Vec::new();
    for c in 0..nc {
        buf.clear();
        for &j in &sources[start[c]..start[c + 1]] {
            buf.extend(
                x.row_idx_of_col(j)
                    .zip(x.val_of_col(j))
                    .map(|(r, &v)| (t[r], v)),
            );
        }
        buf.sort_by_key(|e| e.0);
        for &(r, v) in &buf {
            if rows.len() > col_ptr[c] && rows[rows.len() - 1] == r {
                *vals.last_mut().expect("an entry before") += v;
            } else {
                rows.push(r);
                vals.push(v);
            }
        }
        col_ptr.push(rows.len());
    }
    let symbolic = SymbolicSparseColMat::new_checked(nc, nc, col_ptr, None, rows);
    SparseColMat::new(symbolic, vals)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn relabel_is_the_summed_triplets_of_t_x_t() {
        // 9 DOFs, DOF 2 onto 7's place and DOF 5 onto 0's: 7 constrained DOFs
        let n = 9;
        let partner = [None, None, Some(7), None, None, Some(0), None, None, None];
        let (t, nc) = index_map(&partner);
        assert_eq!((nc, t[2], t[5], t[8]), (7, t[7], t[0], 6));
        let mut trip = Vec::new();
        for j in 0..n {
            for i in 0..n {
                if (i * 3 + j * 5) % 4 != 1 {
                    trip.push(Triplet::new(i, j, 1.0 + (i * n + j) as f64 / 7.0));
                }
            }
        }
        let x = SparseMat::try_new_from_triplets(n, n, &trip).unwrap();
        let got = relabel(x.as_ref(), &t, nc);
        let relabelled: Vec<_> = trip
            .iter()
            .map(|e| Triplet::new(t[e.row], t[e.col], e.val))
            .collect();
        let want = SparseMat::try_new_from_triplets(nc, nc, &relabelled).unwrap();
        assert_eq!(got.compute_nnz(), want.compute_nnz());
        let (g, w) = (got.to_dense(), want.to_dense());
        for j in 0..nc {
            for i in 0..nc {
                assert!(
                    (g[(i, j)] - w[(i, j)]).abs() <= 1e-14 * w[(i, j)].abs(),
                    "({i}, {j})"
                );
            }
        }
        // a merged column holds the entries of both source columns
        assert!(w[(t[0], t[0])] > x.to_dense()[(0, 0)]);
    }
}
