//! Real modes computed once per stiffness/mass pair and shared between methods.
//!
//! Every basis that starts from the coupled real modes of a contact set (`enriched`,
//! `residue`, `modes`, `pod`, ...) asks its modal solver for the same `K_c x = omega^2
//! M_c x` band. Within one run the same contact set is met many times: the check sweeps of
//! `validate` visit the same equilibria with two bases, `bench` builds every basis and
//! its variants on one operator. [`CachedModal`] wraps the modal solver and serves a
//! repeated request from a [`ModalCache`] shared by every method of the run, so such a
//! Lanczos run (the largest fixed cost of a basis on a new contact set) is paid once.
//!
//! A request is the same when the solver, both matrices (their sizes, sparsity patterns
//! and the bits of their values, through a 64-bit fingerprint) and every eigen parameter
//! are the same; the answer is then the one the solver gave the first time. The cache
//! holds at most [`ModalCache::budget_bytes`] of mode shapes and drops the oldest entries
//! beyond that. Complex (frictional) solves are passed through unchanged.

use squeal_core::eigen::SymmetricProblem;
use squeal_core::faer::MatRef;
use squeal_core::operator::RealModes;
use squeal_core::operator::{ComplexModes, Qep};
use squeal_core::spectral::ShiftInvert;
use squeal_core::{EigenParams, EigenSolver, FrictionalOperator, Result, SparseRef};
use std::collections::VecDeque;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};

/// Default budget of a [`ModalCache`]: 512 MiB of mode shapes (18 contact sets of 21
/// modes on the 172k-DOF default rig: a check sweep of 17 mu points, step 0.05, fits
/// whole, so the next sweep over the same equilibria finds all of it; the oldest entry
/// goes first, so a sweep one set larger than the budget would find none).
pub const DEFAULT_BUDGET_BYTES: usize = 512 << 20;

/// What identifies a symmetric solve.
#[derive(Debug, Clone, PartialEq)]
struct Key {
    solver: String,
    k: Fingerprint,
    m: Fingerprint,
    params: EigenParams,
}

/// Size, pattern and values of a sparse matrix, hashed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Fingerprint {
    nrows: usize,
    ncols: usize,
    nnz: usize,
    hash: u64,
}

impl Fingerprint {
    fn of(a: SparseRef<'_>) -> Self {
        // FNV-1a over 64-bit words: the column pointers, the row indices and the bits of
        // the values (a few milliseconds for millions of entries)
        let mut h = 0xcbf2_9ce4_8422_2325u64;
        let mut mix = |w: u64| {
            h ^= w;
            h = h.wrapping_mul(0x0000_0100_0000_01b3);
        };
        let mut nnz = 0;
        for j in 0..a.ncols() {
            let rows = a.row_idx_of_col_raw(j);
            mix(rows.len() as u64);
            nnz += rows.len();
            for (&i, &v) in rows.iter().zip(a.val_of_col(j)) {
                mix(i as u64);
                mix(v.to_bits());
            }
        }
        Self {
            nrows: a.nrows(),
            ncols: a.ncols(),
            nnz,
            hash: h,
        }
    }
}

struct Entry {
    key: Key,
    modes: Arc<RealModes>,
    bytes: usize,
}

/// Real modes of earlier solves, shared by every method of a run (see the module docs).
pub struct ModalCache {
    /// Most bytes of mode shapes kept; older entries are dropped beyond it.
    pub budget_bytes: usize,
    entries: Mutex<VecDeque<Entry>>,
    hits: AtomicUsize,
}

impl Default for ModalCache {
    fn default() -> Self {
        Self::new(DEFAULT_BUDGET_BYTES)
    }
}

impl ModalCache {
    /// An empty cache that keeps at most `budget_bytes` of mode shapes.
    pub fn new(budget_bytes: usize) -> Self {
        Self {
            budget_bytes,
            entries: Mutex::new(VecDeque::new()),
            hits: AtomicUsize::new(0),
        }
    }

    /// How many requests were served from the cache.
    pub fn hits(&self) -> usize {
        self.hits.load(Ordering::Relaxed)
    }

    /// How many solves are kept.
    pub fn len(&self) -> usize {
        self.entries.lock().unwrap_or_else(|p| p.into_inner()).len()
    }

    /// Whether no solve is kept.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Drops every kept solve (the hit count stays).
    pub fn clear(&self) {
        self.entries
            .lock()
            .unwrap_or_else(|p| p.into_inner())
            .clear();
    }

    fn get(&self, key: &Key) -> Option<Arc<RealModes>> {
        let entries = self.entries.lock().unwrap_or_else(|p| p.into_inner());
        let found = entries
            .iter()
            .find(|e| &e.key == key)
            .map(|e| e.modes.clone());
        if found.is_some() {
            self.hits.fetch_add(1, Ordering::Relaxed);
        }
        found
    }

    fn put(&self, key: Key, modes: Arc<RealModes>) {
        let columns = modes.vectors.ncols() + modes.above_band.ncols();
        let bytes = modes.vectors.nrows() * columns * std::mem::size_of::<f64>();
        if bytes > self.budget_bytes {
            return;
        }
        let mut entries = self.entries.lock().unwrap_or_else(|p| p.into_inner());
        if entries.iter().any(|e| e.key == key) {
            return;
        }
        let mut total: usize = entries.iter().map(|e| e.bytes).sum::<usize>() + bytes;
        while total > self.budget_bytes {
            match entries.pop_front() {
                Some(old) => total -= old.bytes,
                None => break,
            }
        }
        entries.push_back(Entry { key, modes, bytes });
    }
}

/// A modal solver whose symmetric solves go through a [`ModalCache`].
pub struct CachedModal {
    inner: Arc<dyn EigenSolver>,
    cache: Arc<ModalCache>,
}

impl CachedModal {
    /// Wraps `inner`; the solves it is asked for again are served from `cache`.
    pub fn new(inner: Arc<dyn EigenSolver>, cache: Arc<ModalCache>) -> Self {
        Self { inner, cache }
    }

    /// The cached answer to `(problem, params)`, or `solve`'s, then cached.
    fn cached(
        &self,
        problem: &SymmetricProblem<'_>,
        params: &EigenParams,
        solve: impl FnOnce() -> Result<RealModes>,
    ) -> Result<RealModes> {
        let key = Key {
            solver: self.inner.name().to_string(),
            k: Fingerprint::of(problem.k),
            m: Fingerprint::of(problem.m),
            params: params.clone(),
        };
        if let Some(modes) = self.cache.get(&key) {
            let mut modes = (*modes).clone();
            modes.info.time_s = 0.0;
            modes.info.notes.push(
                "the same K, M and parameters were solved earlier in this run: modes reused".into(),
            );
            return Ok(modes);
        }
        let modes = solve()?;
        self.cache.put(key, Arc::new(modes.clone()));
        Ok(modes)
    }
}

impl EigenSolver for CachedModal {
    fn name(&self) -> &str {
        self.inner.name()
    }

    fn solve_symmetric(
        &self,
        problem: &SymmetricProblem<'_>,
        params: &EigenParams,
    ) -> Result<RealModes> {
        self.cached(problem, params, || {
            self.inner.solve_symmetric(problem, params)
        })
    }

    /// Served from the cache like [`solve_symmetric`](Self::solve_symmetric) (the modes of
    /// one band do not depend on the shift that found them, nor on where the iteration
    /// started: both meet the same tolerance); a miss solves on `op` from `start`.
    fn solve_symmetric_on(
        &self,
        problem: &SymmetricProblem<'_>,
        op: &ShiftInvert<'_>,
        start: Option<MatRef<'_, f64>>,
        params: &EigenParams,
    ) -> Result<RealModes> {
        self.cached(problem, params, || {
            self.inner.solve_symmetric_on(problem, op, start, params)
        })
    }

    fn solve_qep(&self, qep: &Qep, params: &EigenParams) -> Result<ComplexModes> {
        self.inner.solve_qep(qep, params)
    }

    fn solve_frictional(
        &self,
        op: &FrictionalOperator,
        mu: f64,
        params: &EigenParams,
    ) -> Result<ComplexModes> {
        self.inner.solve_frictional(op, mu, params)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use squeal_core::faer::sparse::Triplet;
    use squeal_core::faer::Mat;
    use squeal_core::operator::SolveInfo;
    use squeal_core::SparseMat;

    /// Diagonal "solver": the first `nev_hint` diagonal ratios, counting its calls.
    struct Counting(Arc<AtomicUsize>);

    impl EigenSolver for Counting {
        fn name(&self) -> &str {
            "counting"
        }
        fn solve_symmetric(
            &self,
            problem: &SymmetricProblem<'_>,
            params: &EigenParams,
        ) -> Result<RealModes> {
            self.0.fetch_add(1, Ordering::SeqCst);
            let n = problem.k.nrows();
            let k = params.nev_hint.unwrap_or(1).min(n);
            let diag = |a: SparseRef<'_>, j: usize| {
                a.row_idx_of_col(j)
                    .zip(a.val_of_col(j))
                    .find(|(i, _)| *i == j)
                    .map_or(0.0, |(_, v)| *v)
            };
            let omega2: Vec<f64> = (0..k)
                .map(|j| diag(problem.k, j) / diag(problem.m, j))
                .collect();
            Ok(RealModes {
                freq_hz: omega2
                    .iter()
                    .map(|l| l.sqrt() / std::f64::consts::TAU)
                    .collect(),
                omega2,
                vectors: Mat::from_fn(n, k, |i, j| if i == j { 1.0 } else { 0.0 }),
                residuals: vec![0.0; k],
                info: SolveInfo::new("counting"),
                above_band: Mat::zeros(n, 0),
            })
        }
    }

    fn diagonal(values: &[f64]) -> SparseMat {
        let t: Vec<_> = values
            .iter()
            .enumerate()
            .map(|(i, &v)| Triplet::new(i, i, v))
            .collect();
        SparseMat::try_new_from_triplets(values.len(), values.len(), &t).unwrap()
    }

    fn params(nev: usize) -> EigenParams {
        EigenParams {
            nev_hint: Some(nev),
            ..EigenParams::default()
        }
    }

    #[test]
    fn a_repeated_solve_is_served_from_the_cache_and_a_changed_one_is_not() {
        let calls = Arc::new(AtomicUsize::new(0));
        let cache = Arc::new(ModalCache::default());
        let solver = CachedModal::new(Arc::new(Counting(calls.clone())), cache.clone());
        let k = diagonal(&[4.0, 9.0, 16.0]);
        let m = diagonal(&[1.0, 1.0, 1.0]);
        let p = SymmetricProblem {
            k: k.as_ref(),
            m: m.as_ref(),
        };
        let first = solver.solve_symmetric(&p, &params(2)).unwrap();
        let again = solver.solve_symmetric(&p, &params(2)).unwrap();
        assert_eq!(calls.load(Ordering::SeqCst), 1);
        assert_eq!(cache.hits(), 1);
        assert_eq!(first.omega2, again.omega2);
        assert_eq!(first.vectors, again.vectors);
        assert!(again.info.notes.iter().any(|n| n.contains("reused")));
        // on a caller's factorization: the same band, so served from the cache too
        let si = ShiftInvert::new(k.as_ref(), m.as_ref(), 0.0).unwrap();
        let on = solver
            .solve_symmetric_on(&p, &si, None, &params(2))
            .unwrap();
        assert_eq!((calls.load(Ordering::SeqCst), cache.hits()), (1, 2));
        assert_eq!(on.omega2, first.omega2);

        // one changed value of K, or changed parameters: solved again
        let k2 = diagonal(&[4.0, 9.0, 16.000000000000004]);
        let p2 = SymmetricProblem {
            k: k2.as_ref(),
            m: m.as_ref(),
        };
        solver.solve_symmetric(&p2, &params(2)).unwrap();
        solver.solve_symmetric(&p, &params(3)).unwrap();
        assert_eq!(calls.load(Ordering::SeqCst), 3);
        assert_eq!(cache.len(), 3);
    }

    #[test]
    fn the_cache_keeps_no_more_than_its_budget() {
        let calls = Arc::new(AtomicUsize::new(0));
        // room for one 3 x 2 block of shapes (48 bytes), not two
        let cache = Arc::new(ModalCache::new(60));
        let solver = CachedModal::new(Arc::new(Counting(calls.clone())), cache.clone());
        let m = diagonal(&[1.0, 1.0, 1.0]);
        for top in [16.0, 25.0] {
            let k = diagonal(&[4.0, 9.0, top]);
            let p = SymmetricProblem {
                k: k.as_ref(),
                m: m.as_ref(),
            };
            solver.solve_symmetric(&p, &params(2)).unwrap();
        }
        assert_eq!(cache.len(), 1);
        // the first was dropped: asking for it again solves it again
        let k = diagonal(&[4.0, 9.0, 16.0]);
        let p = SymmetricProblem {
            k: k.as_ref(),
            m: m.as_ref(),
        };
        solver.solve_symmetric(&p, &params(2)).unwrap();
        assert_eq!(calls.load(Ordering::SeqCst), 3);
        assert_eq!(cache.hits(), 0);
    }
}
