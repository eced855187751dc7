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
//! beyond that. A cache made by [`ModalCache::spilling`] keeps only the newest of them in
//! memory and the older ones in files of a folder of its own (the shapes' bits, read back
//! when asked for). Complex (frictional) solves are passed through unchanged.

use squeal_core::eigen::SymmetricProblem;
use squeal_core::faer::Mat;
use squeal_core::faer::MatRef;
use squeal_core::operator::RealModes;
use squeal_core::operator::{ComplexModes, Qep};
use squeal_core::spectral::ShiftInvert;
use squeal_core::{EigenParams, EigenSolver, FrictionalOperator, Result, SparseRef};
use std::collections::VecDeque;
use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};

/// Default budget of a [`ModalCache`]: 512 MiB of mode shapes (18 contact sets of 21
/// modes on the 172k-DOF default rig: a check sweep of 17 mu points, step 0.05, fits
/// whole, so the next sweep over the same equilibria finds all of it; the oldest entry
/// goes first, so a sweep one set larger than the budget would find none).
pub const DEFAULT_BUDGET_BYTES: usize = 512 << 20;

/// Name prefix of the folder a spilling cache makes ([`ModalCache::spilling`]).
pub const SPILL_PREFIX: &str = ".squeal-modal-cache-";

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
    modes: Kept,
    bytes: usize,
}

impl Entry {
    /// Drops the entry and its file, if it has one.
    fn forget(self) {
        if let Kept::File { path, .. } = self.modes {
            let _ = std::fs::remove_file(path);
        }
    }
}

/// Where an entry's modes are.
enum Kept {
    /// In memory.
    Memory(Arc<RealModes>),
    /// The shapes (`vectors`, then `above_band`, column by column, the bits of each
    /// value) in `path`; `head` holds the rest, its shapes `n x 0`.
    File {
        path: PathBuf,
        head: Box<RealModes>,
        vectors: usize,
        above_band: usize,
    },
}

/// The folder of a spilling cache's files (made at the first spill, removed with the
/// cache) and how many bytes of shapes stay in memory.
struct Spill {
    parent: PathBuf,
    dir: Option<tempfile::TempDir>,
    memory_bytes: usize,
    written: usize,
}

/// Real modes of earlier solves, shared by every method of a run (see the module docs).
pub struct ModalCache {
    /// Most bytes of mode shapes kept; older entries are dropped beyond it.
    pub budget_bytes: usize,
    entries: Mutex<VecDeque<Entry>>,
    spill: Option<Mutex<Spill>>,
    hits: AtomicUsize,
}

impl Default for ModalCache {
    fn default() -> Self {
        Self::new(DEFAULT_BUDGET_BYTES)
    }
}

impl ModalCache {
    /// An empty cache that keeps at most `budget_bytes` of mode shapes, in memory.
    pub fn new(budget_bytes: usize) -> Self {
        Self {
            budget_bytes,
            entries: Mutex::new(VecDeque::new()),
            spill: None,
            hits: AtomicUsize::new(0),
        }
    }

    /// An empty cache that keeps at most `budget_bytes` of mode shapes, of which the
    /// newest `memory_bytes` in memory and the older ones in files of a folder it makes
    /// in `parent` (at its first spill; removed with the cache). A file that cannot be
    /// written or read back loses its entry, which is then solved again.
    pub fn spilling(budget_bytes: usize, memory_bytes: usize, parent: &Path) -> Self {
        Self {
            spill: Some(Mutex::new(Spill {
                parent: parent.to_path_buf(),
                dir: None,
                memory_bytes,
                written: 0,
            })),
            ..Self::new(budget_bytes)
        }
    }

    /// Removes the folders that spilling caches made in `parent` and left there (their
    /// process stopped before dropping them); errors are ignored.
    pub fn remove_spill_folders(parent: &Path) {
        let Ok(entries) = std::fs::read_dir(parent) else {
            return;
        };
        for e in entries.flatten() {
            let ours = e.file_name().to_string_lossy().starts_with(SPILL_PREFIX);
            if ours && e.path().is_dir() {
                let _ = std::fs::remove_dir_all(e.path());
            }
        }
    }

    /// How many kept solves have their shapes in files.
    pub fn spilled(&self) -> usize {
        let entries = self.entries.lock().unwrap_or_else(|p| p.into_inner());
        entries
            .iter()
            .filter(|e| matches!(e.modes, Kept::File { .. }))
            .count()
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
        let mut entries = self.entries.lock().unwrap_or_else(|p| p.into_inner());
        entries.drain(..).for_each(Entry::forget);
    }

    fn get(&self, key: &Key) -> Option<Arc<RealModes>> {
        let mut entries = self.entries.lock().unwrap_or_else(|p| p.into_inner());
        let i = entries.iter().position(|e| &e.key == key)?;
        let found = match &entries[i].modes {
            Kept::Memory(modes) => Some(modes.clone()),
            Kept::File {
                path,
                head,
                vectors,
                above_band,
            } => read_shapes(path, head, *vectors, *above_band).map(Arc::new),
        };
        match found {
            Some(_) => {
                self.hits.fetch_add(1, Ordering::Relaxed);
            }
            // its file is gone or damaged: the entry is forgotten
            None => {
                if let Some(e) = entries.remove(i) {
                    e.forget();
                }
            }
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
                Some(old) => {
                    total -= old.bytes;
                    old.forget();
                }
                None => break,
            }
        }
        entries.push_back(Entry {
            key,
            modes: Kept::Memory(modes),
            bytes,
        });
        if let Some(spill) = &self.spill {
            let mut spill = spill.lock().unwrap_or_else(|p| p.into_inner());
            spill.move_out(&mut entries);
        }
    }
}

impl Spill {
    /// Writes the oldest entries kept in memory to files until the newest ones alone
    /// fit [`Spill::memory_bytes`]; an entry whose file cannot be written is dropped.
    fn move_out(&mut self, entries: &mut VecDeque<Entry>) {
        let in_memory = |entries: &VecDeque<Entry>| -> usize {
            entries
                .iter()
                .filter(|e| matches!(e.modes, Kept::Memory(_)))
                .map(|e| e.bytes)
                .sum()
        };
        while in_memory(entries) > self.memory_bytes {
            let oldest = entries
                .iter()
                .enumerate()
                .find_map(|(i, e)| match &e.modes {
                    Kept::Memory(modes) => Some((i, modes.clone())),
                    Kept::File { .. } => None,
                });
            let Some((i, modes)) = oldest else {
                break;
            };
            match self.write(&modes) {
                Some(kept) => entries[i].modes = kept,
                None => {
                    entries.remove(i);
                }
            }
        }
    }

    /// The shapes of `modes` in a new file of the folder.
    fn write(&mut self, modes: &RealModes) -> Option<Kept> {
        if self.dir.is_none() {
            self.dir = tempfile::Builder::new()
                .prefix(SPILL_PREFIX)
                .tempdir_in(&self.parent)
                .ok();
        }
        let path = self
            .dir
            .as_ref()?
            .path()
            .join(format!("modes-{}.f64", self.written));
        self.written += 1;
        let written = (|| -> std::io::Result<()> {
            let file = std::fs::File::create(&path)?;
            let mut out = std::io::BufWriter::with_capacity(1 << 20, file);
            for m in [&modes.vectors, &modes.above_band] {
                for c in 0..m.ncols() {
                    for v in m.col(c).iter() {
                        out.write_all(&v.to_bits().to_le_bytes())?;
                    }
                }
            }
            out.flush()
        })();
        if written.is_err() {
            // a partly written file (a full disk) is not left behind
            let _ = std::fs::remove_file(&path);
            return None;
        }
        let head = Box::new(with_shapes(
            modes,
            Mat::zeros(modes.vectors.nrows(), 0),
            Mat::zeros(modes.above_band.nrows(), 0),
        ));
        Some(Kept::File {
            path,
            head,
            vectors: modes.vectors.ncols(),
            above_band: modes.above_band.ncols(),
        })
    }
}

/// The modes of a spilled entry: `head` with its shapes read back from `path`; `None`
/// when the file is missing or not of the expected size.
fn read_shapes(
    path: &Path,
    head: &RealModes,
    vectors: usize,
    above_band: usize,
) -> Option<RealModes> {
    let mut file = std::io::BufReader::with_capacity(1 << 20, std::fs::File::open(path).ok()?);
    let mut read = |n: usize, k: usize| -> Option<Mat<f64>> {
        let mut m = Mat::<f64>::zeros(n, k);
        let mut word = [0u8; 8];
        for c in 0..k {
            for v in m.col_mut(c).iter_mut() {
                file.read_exact(&mut word).ok()?;
                *v = f64::from_bits(u64::from_le_bytes(word));
            }
        }
        Some(m)
    };
    let v = read(head.vectors.nrows(), vectors)?;
    let a = read(head.above_band.nrows(), above_band)?;
    let mut rest = [0u8; 1];
    if file.read(&mut rest).ok()? != 0 {
        return None;
    }
    Some(with_shapes(head, v, a))
}

/// `modes` with the shapes `vectors` and `above_band` in place of its own.
fn with_shapes(modes: &RealModes, vectors: Mat<f64>, above_band: Mat<f64>) -> RealModes {
    RealModes {
        omega2: modes.omega2.clone(),
        freq_hz: modes.freq_hz.clone(),
        vectors,
        residuals: modes.residuals.clone(),
        info: modes.info.clone(),
        above_band,
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

    /// Files of the spill folder under `parent`.
    fn spill_files(parent: &Path) -> Vec<PathBuf> {
        let mut files = Vec::new();
        for dir in std::fs::read_dir(parent).unwrap() {
            let dir = dir.unwrap().path();
            if dir.is_dir() {
                for f in std::fs::read_dir(&dir).unwrap() {
                    files.push(f.unwrap().path());
                }
            }
        }
        files
    }

    #[test]
    fn a_spilling_cache_serves_the_same_bits_from_its_files_and_removes_them() {
        let parent = tempfile::tempdir().unwrap();
        let calls = Arc::new(AtomicUsize::new(0));
        // room for both 3 x 2 blocks of shapes, none of it in memory
        let cache = Arc::new(ModalCache::spilling(1000, 0, parent.path()));
        let solver = CachedModal::new(Arc::new(Counting(calls.clone())), cache.clone());
        let m = diagonal(&[1.0, 1.0, 1.0]);
        let ks = [diagonal(&[4.0, 9.0, 16.0]), diagonal(&[4.0, 9.0, 25.0])];
        fn pencil<'a>(k: &'a SparseMat, m: &'a SparseMat) -> SymmetricProblem<'a> {
            SymmetricProblem {
                k: k.as_ref(),
                m: m.as_ref(),
            }
        }
        let problem = |k| pencil(k, &m);
        let first: Vec<RealModes> = ks
            .iter()
            .map(|k| solver.solve_symmetric(&problem(k), &params(2)).unwrap())
            .collect();
        assert_eq!(cache.spilled(), 2);
        assert_eq!(spill_files(parent.path()).len(), 2);
        for (k, f) in ks.iter().zip(&first) {
            let again = solver.solve_symmetric(&problem(k), &params(2)).unwrap();
            assert_eq!(again.omega2, f.omega2);
            assert_eq!(again.vectors, f.vectors);
            assert_eq!(again.above_band.ncols(), 0);
        }
        assert_eq!((calls.load(Ordering::SeqCst), cache.hits()), (2, 2));
        // shapes whose bits a decimal round trip would not keep, read back bit for bit
        let values = [1.0 / 3.0, -0.0, 1e-310, f64::NAN, -2.5e17, f64::INFINITY];
        let odd = RealModes {
            vectors: Mat::from_fn(3, 2, |i, j| values[i + 3 * j]),
            above_band: Mat::from_fn(3, 1, |i, _| values[5 - i]),
            ..first[0].clone()
        };
        let key = Key {
            solver: "odd".into(),
            k: Fingerprint::of(ks[0].as_ref()),
            m: Fingerprint::of(m.as_ref()),
            params: params(2),
        };
        cache.put(key.clone(), Arc::new(odd.clone()));
        assert_eq!(cache.spilled(), 3);
        let back = cache.get(&key).unwrap();
        let bits = |a: &Mat<f64>| -> Vec<u64> {
            (0..a.ncols())
                .flat_map(|c| a.col(c).iter().map(|v| v.to_bits()).collect::<Vec<_>>())
                .collect()
        };
        assert_eq!(bits(&back.vectors), bits(&odd.vectors));
        assert_eq!(bits(&back.above_band), bits(&odd.above_band));
        cache.clear();
        assert_eq!(cache.hits(), 3);
        // a file gone: its entry is forgotten and solved again
        for k in &ks {
            solver.solve_symmetric(&problem(k), &params(2)).unwrap();
        }
        assert_eq!(calls.load(Ordering::SeqCst), 4);
        std::fs::remove_file(&spill_files(parent.path())[0]).unwrap();
        for k in &ks {
            solver.solve_symmetric(&problem(k), &params(2)).unwrap();
        }
        assert_eq!(calls.load(Ordering::SeqCst), 5);
        assert_eq!(cache.len(), 2);
        cache.clear();
        assert!(spill_files(parent.path()).is_empty());
        drop((solver, cache));
        assert_eq!(std::fs::read_dir(parent.path()).unwrap().count(), 0);
        // room in memory for one entry: the older one goes to a file
        let cache = Arc::new(ModalCache::spilling(1000, 60, parent.path()));
        let solver = CachedModal::new(Arc::new(Counting(calls.clone())), cache.clone());
        for k in &ks {
            solver.solve_symmetric(&problem(k), &params(2)).unwrap();
        }
        assert_eq!((cache.len(), cache.spilled()), (2, 1));
        assert_eq!(spill_files(parent.path()).len(), 1);
        drop((solver, cache));
        // a folder left by a stopped run goes, other files stay
        let left = parent.path().join(format!("{SPILL_PREFIX}abc"));
        std::fs::create_dir(&left).unwrap();
        std::fs::write(left.join("modes-0.f64"), [0u8; 8]).unwrap();
        std::fs::write(parent.path().join("report.md"), "kept").unwrap();
        ModalCache::remove_spill_folders(parent.path());
        assert!(!left.exists());
        assert!(parent.path().join("report.md").exists());
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
