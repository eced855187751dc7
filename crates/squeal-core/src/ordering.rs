//! Fill-reducing orderings of the symmetric factorizations.
//!
//! Above [`NESTED_DISSECTION_MIN_DIM`] unknowns, every symmetric factorization (the
//! Cholesky of `K - sigma M`, the `L B L^T` of the constrained pencil) is ordered by METIS
//! nested dissection (`METIS_NodeND`, METIS 5 built from source by `metis-sys`); below it
//! by faer's approximate minimum degree. On the default rig's constrained pencil at
//! mu = 0.7 (171,767 unknowns; the `notes` of `squeal stability --operator DIR --eigen
//! arpack` on `squeal export --mu 0.7 --out DIR`) nested dissection leaves 100 M entries in
//! `L` where AMD left 147 M, and the full-order solve is about 10 % faster with 12 % less
//! memory; on the coarse rig (1,779 unknowns) it gains nothing. METIS's default options
//! seed its random choices with a fixed value, so the ordering, and with it every result,
//! is the same from run to run.

use crate::{Error, Result};
use faer::perm::PermRef;
use faer::sparse::linalg::cholesky::SymmetricOrdering;
use faer::sparse::SymbolicSparseColMatRef;

/// Problems of at least this many unknowns are ordered by nested dissection.
pub const NESTED_DISSECTION_MIN_DIM: usize = 20_000;

/// A fill-reducing permutation, `forward[new] = old` and `inverse[old] = new`.
#[derive(Debug, Clone)]
pub struct FillOrdering {
    forward: Vec<usize>,
    inverse: Vec<usize>,
}

impl FillOrdering {
    /// The ordering of a symmetric pattern (either triangle or both; the diagonal is
    /// ignored): nested dissection at [`NESTED_DISSECTION_MIN_DIM`] unknowns and above,
    /// `None` below (the factorization then uses AMD).
    ///
    /// The orderings of the most recent patterns are kept ([`CACHE_BYTES`]): every
    /// contact set of a model, once ordered, is ordered again for free when a later stage
    /// factorizes a matrix of the same pattern (the shifted stiffness of the real modes,
    /// the static responses, the full-order reference's pencil).
    pub fn of(pattern: SymbolicSparseColMatRef<'_, usize>) -> Result<Option<Self>> {
        if pattern.nrows() < NESTED_DISSECTION_MIN_DIM {
            return Ok(None);
        }
        let key = PatternKey::of(pattern);
        if let Some(hit) = cache::get(&key) {
            return Ok(Some(hit));
        }
        let ordering = nested_dissection(pattern)?;
        cache::put(key, &ordering);
        Ok(Some(ordering))
    }

    /// As faer's [`SymmetricOrdering`].
    pub fn as_symmetric(&self) -> SymmetricOrdering<'_, usize> {
        let n = self.forward.len();
        SymmetricOrdering::Custom(PermRef::new_checked(&self.forward, &self.inverse, n))
    }
}

/// Memory (bytes) the orderings of recent patterns may take ([`FillOrdering::of`]); at
/// most [`CACHE_ENTRIES`] are kept, the least recently used going first. Each is kept as
/// its forward permutation in 32-bit indices (0.7 MB for the default rig's 171,545
/// unknowns), so a study's sweeps, whose contact sets come back sweep after sweep, find
/// their orderings again.
pub const CACHE_BYTES: usize = 96 << 20;

/// Most orderings kept ([`CACHE_BYTES`]): more than the contact sets of a sweep at step
/// 0.05 (17 points), so a second sweep over the same sets finds every one.
pub const CACHE_ENTRIES: usize = 64;

/// A pattern's identity: its size, its number of entries and two independent 64-bit
/// hashes of its column pointers and row indices.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct PatternKey {
    n: usize,
    nnz: usize,
    hash: [u64; 2],
}

impl PatternKey {
    fn of(pattern: SymbolicSparseColMatRef<'_, usize>) -> Self {
        let mut hash = [0x9e37_79b9_7f4a_7c15u64, 0xc2b2_ae3d_27d4_eb4fu64];
        let mut mix = |w: u64| {
            hash[0] = (hash[0] ^ w)
                .wrapping_mul(0x0000_0100_0000_01b3)
                .rotate_left(29);
            hash[1] = (hash[1].rotate_left(17) ^ w).wrapping_mul(0xff51_afd7_ed55_8ccd);
        };
        let n = pattern.ncols();
        let mut nnz = 0;
        for j in 0..n {
            let rows = pattern.row_idx_of_col_raw(j);
            mix(rows.len() as u64 ^ ((j as u64) << 32));
            for &i in rows {
                mix(i as u64);
            }
            nnz += rows.len();
        }
        Self {
            n: pattern.nrows(),
            nnz,
            hash,
        }
    }
}

/// The orderings of recent patterns, most recent last.
mod cache {
    use super::{FillOrdering, PatternKey, CACHE_BYTES, CACHE_ENTRIES};
    use std::sync::Mutex;

    /// A kept ordering: `forward` in 32-bit indices (the inverse is rebuilt on a hit).
    struct Kept {
        key: PatternKey,
        forward: Vec<u32>,
    }

    static RECENT: Mutex<Vec<Kept>> = Mutex::new(Vec::new());

    fn bytes(k: &Kept) -> usize {
        k.forward.len() * std::mem::size_of::<u32>()
    }

    pub(super) fn get(key: &PatternKey) -> Option<FillOrdering> {
        let mut recent = RECENT.lock().unwrap_or_else(|e| e.into_inner());
        let at = recent.iter().position(|k| k.key == *key)?;
        let entry = recent.remove(at);
        let forward: Vec<usize> = entry.forward.iter().map(|&v| v as usize).collect();
        recent.push(entry);
        drop(recent);
        let mut inverse = vec![0; forward.len()];
        for (new, &old) in forward.iter().enumerate() {
            inverse[old] = new;
        }
        Some(FillOrdering { forward, inverse })
    }

    pub(super) fn put(key: PatternKey, ordering: &FillOrdering) {
        let Ok(forward) = ordering
            .forward
            .iter()
            .map(|&v| u32::try_from(v))
            .collect::<Result<Vec<u32>, _>>()
        else {
            return;
        };
        let kept = Kept { key, forward };
        if bytes(&kept) > CACHE_BYTES {
            return;
        }
        let mut recent = RECENT.lock().unwrap_or_else(|e| e.into_inner());
        recent.retain(|k| k.key != key);
        recent.push(kept);
        while recent.len() > CACHE_ENTRIES || recent.iter().map(bytes).sum::<usize>() > CACHE_BYTES
        {
            recent.remove(0);
        }
    }
}

/// The faer ordering for an optional [`FillOrdering`]: it, or AMD.
pub fn symmetric_ordering(ordering: Option<&FillOrdering>) -> SymmetricOrdering<'_, usize> {
    ordering.map_or(SymmetricOrdering::Amd, FillOrdering::as_symmetric)
}

/// METIS nested dissection of the graph of `pattern` (symmetrized, no diagonal).
fn nested_dissection(pattern: SymbolicSparseColMatRef<'_, usize>) -> Result<FillOrdering> {
    use metis_sys as m;
    let n = pattern.nrows();
    let fail = |reason: String| Error::Factorization {
        what: format!("nested dissection ordering (n = {n})"),
        reason,
    };
    let too_big = || fail("more edges than METIS's 32-bit indices hold".into());
    // both directions of every off-diagonal entry, then each list sorted and deduplicated
    let mut degree = vec![0usize; n];
    for j in 0..n {
        for i in pattern.row_idx_of_col(j).filter(|&i| i != j) {
            degree[i] += 1;
            degree[j] += 1;
        }
    }
    let mut start = vec![0usize; n + 1];
    for i in 0..n {
        start[i + 1] = start[i] + degree[i];
    }
    drop(degree);
    let mut next = start[..n].to_vec();
    let mut all: Vec<m::idx_t> = vec![0; start[n]];
    for j in 0..n {
        for i in pattern.row_idx_of_col(j).filter(|&i| i != j) {
            all[next[i]] = j as m::idx_t;
            next[i] += 1;
            all[next[j]] = i as m::idx_t;
            next[j] += 1;
        }
    }
    drop(next);
    let mut xadj: Vec<m::idx_t> = Vec::with_capacity(n + 1);
    xadj.push(0);
    let mut adjncy: Vec<m::idx_t> = Vec::with_capacity(all.len() / 2);
    for i in 0..n {
        let list = &mut all[start[i]..start[i + 1]];
        list.sort_unstable();
        let mut last = None;
        for &v in list.iter() {
            if last != Some(v) {
                adjncy.push(v);
                last = Some(v);
            }
        }
        xadj.push(m::idx_t::try_from(adjncy.len()).map_err(|_| too_big())?);
    }
    drop(all);
    let mut nv = m::idx_t::try_from(n).map_err(|_| too_big())?;
    let mut options = [0 as m::idx_t; m::METIS_NOPTIONS as usize];
    let mut perm = vec![0 as m::idx_t; n];
    let mut iperm = vec![0 as m::idx_t; n];
    // SAFETY: `xadj` has n + 1 nondecreasing offsets into `adjncy`, whose entries are
    // vertex numbers in 0..n (C numbering, set below); `perm` and `iperm` hold n entries;
    // the null pointer is METIS's "unit vertex weights".
    let status = unsafe {
        m::METIS_SetDefaultOptions(options.as_mut_ptr());
        options[m::moptions_et_METIS_OPTION_NUMBERING as usize] = 0;
        m::METIS_NodeND(
            &mut nv,
            xadj.as_mut_ptr(),
            adjncy.as_mut_ptr(),
            std::ptr::null_mut(),
            options.as_mut_ptr(),
            perm.as_mut_ptr(),
            iperm.as_mut_ptr(),
        )
    };
    if status != m::rstatus_et_METIS_OK {
        return Err(fail(format!("METIS_NodeND returned status {status}")));
    }
    // METIS's perm[new] = old and iperm[old] = new are faer's forward and inverse
    let forward: Vec<usize> = perm.iter().map(|&v| v as usize).collect();
    let inverse: Vec<usize> = iperm.iter().map(|&v| v as usize).collect();
    let mut seen = vec![false; n];
    for (new, &old) in forward.iter().enumerate() {
        if old >= n || seen[old] || inverse[old] != new {
            return Err(fail("METIS returned an invalid permutation".into()));
        }
        seen[old] = true;
    }
    Ok(FillOrdering { forward, inverse })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::Cholesky;
    use crate::SparseMat;
    use faer::sparse::linalg::cholesky::{factorize_symbolic_cholesky, CholeskySymbolicParams};
    use faer::sparse::Triplet;
    use faer::{Mat, Side};

    /// The 7-point Laplacian (plus a small shift) of an `a x b x c` grid, both triangles.
    fn laplacian(a: usize, b: usize, c: usize) -> SparseMat {
        let id = |i: usize, j: usize, k: usize| (k * b + j) * a + i;
        let mut t = Vec::new();
        for k in 0..c {
            for j in 0..b {
                for i in 0..a {
                    let p = id(i, j, k);
                    t.push(Triplet::new(p, p, 6.01));
                    let mut link = |q: usize| {
                        t.push(Triplet::new(p, q, -1.0));
                        t.push(Triplet::new(q, p, -1.0));
                    };
                    if i + 1 < a {
                        link(id(i + 1, j, k));
                    }
                    if j + 1 < b {
                        link(id(i, j + 1, k));
                    }
                    if k + 1 < c {
                        link(id(i, j, k + 1));
                    }
                }
            }
        }
        SparseMat::try_new_from_triplets(a * b * c, a * b * c, &t).unwrap()
    }

    fn fill(a: &SparseMat, ordering: Option<&FillOrdering>) -> usize {
        factorize_symbolic_cholesky(
            a.symbolic(),
            Side::Lower,
            symmetric_ordering(ordering),
            CholeskySymbolicParams::default(),
        )
        .unwrap()
        .len_val()
    }

    #[test]
    fn small_problems_keep_amd() {
        let a = laplacian(10, 10, 10);
        assert!(FillOrdering::of(a.symbolic()).unwrap().is_none());
    }

    #[test]
    fn nested_dissection_is_a_permutation_with_less_fill_and_solves() {
        let a = laplacian(30, 30, 24);
        let n = a.nrows();
        assert!(n >= NESTED_DISSECTION_MIN_DIM);
        let nd = FillOrdering::of(a.symbolic())
            .unwrap()
            .expect("nested dissection");
        let mut seen = vec![false; n];
        for (new, &old) in nd.forward.iter().enumerate() {
            assert!(!seen[old] && nd.inverse[old] == new);
            seen[old] = true;
        }
        // the same ordering again from METIS itself (its fixed seed): results repeat from
        // run to run; and from the cache of recent patterns
        let again = nested_dissection(a.symbolic()).unwrap();
        assert_eq!(nd.forward, again.forward);
        let key = PatternKey::of(a.symbolic());
        let hit = cache::get(&key).unwrap();
        assert_eq!((&hit.forward, &hit.inverse), (&nd.forward, &nd.inverse));
        // another pattern of the same size and entries count is another key
        let b = laplacian(24, 30, 30);
        assert_eq!((b.nrows(), b.compute_nnz()), (n, a.compute_nnz()));
        assert_ne!(PatternKey::of(b.symbolic()), key);
        let nb = FillOrdering::of(b.symbolic()).unwrap().unwrap();
        assert_ne!(nb.forward, nd.forward);
        let (with_nd, with_amd) = (fill(&a, Some(&nd)), fill(&a, None));
        assert!(
            with_nd < with_amd,
            "nested dissection {with_nd} entries in L, AMD {with_amd}"
        );
        // the factorization in that ordering solves A x = b
        let chol = Cholesky::new(a.as_ref(), "A").unwrap();
        assert_eq!(chol.factor_entries(), with_nd);
        let b: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
        let mut x = b.clone();
        chol.solve_vec_in_place(&mut x);
        let xm = Mat::from_fn(n, 1, |i, _| x[i]);
        let ax = &a * &xm;
        let r = (0..n)
            .map(|i| (ax[(i, 0)] - b[i]).abs())
            .fold(0.0, f64::max);
        let bmax = b.iter().map(|v| v.abs()).fold(0.0, f64::max);
        assert!(r < 1e-12 * bmax, "residual {r:e}");
    }
}
