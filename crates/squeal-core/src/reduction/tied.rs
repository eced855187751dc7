//! Solves with the tied stiffness `K_c` of any contact set through one factorization of
//! the free model ([`PairSolves`], [`TiedSolve`]).
//!
//! A contact set ties the normal DOFs of its active pairs `A`: `u = T u_c` spans the null
//! space of `C_A`, whose row `i` is `e_pin - e_disc` on the normal (`z`) DOFs of pair `i`,
//! and `K_c = T^T K T`. For a right-hand side `b_c`, with `f = T D^-1 b_c` (`D = T^T T`,
//! the number of free DOFs of each constrained one: a tied load is shared by both nodes),
//! the saddle-point system `K u + C_A^T l = f`, `C_A u = 0` gives
//!
//! ```text
//! u = K^-1 f - Z_A S_AA^-1 C_A K^-1 f,      Z = K^-1 C^T,  S = C K^-1 C^T,
//! ```
//!
//! and `u = T u_c` with `K_c u_c = T^T f = b_c` (`C_A T = 0`). `Z` and `S` are computed once
//! per model for every candidate pair (`np` solves with the free factor, `n x np` values
//! kept); a contact set then costs the `nA x nA` Cholesky of `S_AA`, and each solve one
//! free solve, one `n x nA` product and an `nA x nA` triangular pair, instead of a sparse
//! factorization of its own `K_c`.
//!
//! The static responses to the friction loads (`K_c^-1 U`, one column per active pair,
//! [`TiedSolve::friction_statics`]) need no solve of their own per contact set: a friction
//! load `p_i` acts on in-plane DOFs, which no tie touches, so `T D^-1 U = P~t^T` and its
//! free response `x_i = K^-1 p_i` is the same for every contact set that ties pair `i`.
//! Each is solved once, the first time a contact set asks for it, and kept; a contact set
//! then costs the correction onto its ties alone.
//!
//! Accuracy: the tied displacement is the difference of the free one and the ties'
//! correction, so it carries their rounding: on the default rig at mu 0.3 the relative
//! residuals `|K_c u_c - b_c| / |b_c|` of the static responses to the friction loads
//! are 4e-12 to 4e-10. The modal solvers check their eigenpairs on `K_c` and `M_c` (not
//! on the solves), and a static response is a basis direction, so neither needs more: the
//! frequencies of an `enriched` sweep built on these solves agree with those on a
//! factorized `K_c` to 1e-9, their backward errors to the printed digits.

use crate::contact::{FreeModel, ModelStage};
use crate::linalg::{BlockSolve, Cholesky};
use crate::operator::FrictionalOperator;
use crate::{Error, Result, SparseRef};
use faer::linalg::matmul::matmul;
use faer::{Accum, Mat, MatMut, Par, Side};
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::Instant;

/// Largest memory (bytes) the kept responses of the candidate pairs may take: `Z`, and
/// the responses to their friction loads ([`TiedSolve::friction_statics`]) when they fit
/// next to it.
pub const PAIR_SOLVES_LIMIT_BYTES: usize = 4 << 30;

/// The free model's responses to unit normal pair loads, kept for every contact set drawn
/// from its candidate pairs (see the module docs): the factor of `K`, `Z = K^-1 C^T` and
/// `S = C Z`.
pub struct PairSolves {
    factor: Arc<Cholesky>,
    /// Normal (`z`) DOFs `(pin, disc)` of each candidate pair, free numbering.
    normals: Vec<(usize, usize)>,
    z: Normals,
    s: Mat<f64>,
    /// In-plane DOFs of each candidate pair's pin and disc node and its sliding direction:
    /// its friction load is `+e` on the pin's DOFs and `-e` on the disc's.
    sliding: Vec<([usize; 2], [usize; 2], [f64; 2])>,
    /// The responses `K^-1 p_i` to the friction loads of the pairs solved so far.
    friction: Mutex<FrictionResponses>,
    /// Wall time of the construction (s), the factorization of `K` included when it was
    /// not given.
    pub time_s: f64,
}

/// `Z = K^-1 C^T`: kept, or as `Q_1 R_11` in a static space's basis once one is built on
/// the same responses ([`PairSolves::share_normals_with`]: `[Z | X] = Q R` with `R` upper
/// triangular, so `Z = Q_1 R_11`, `Q_1` the first `nR` columns of `Q`), which saves its
/// `n nR` values.
enum Normals {
    Kept(Mat<f64>),
    InSpace { q: Arc<Mat<f64>>, r11: Mat<f64> },
}

impl Normals {
    fn nrows(&self) -> usize {
        match self {
            Normals::Kept(z) => z.nrows(),
            Normals::InSpace { q, .. } => q.nrows(),
        }
    }
}

/// Bytes of the responses `Z` of the free model's candidate pairs.
fn response_bytes(free: &FreeModel<'_>) -> usize {
    free.k
        .nrows()
        .saturating_mul(free.pairs.len())
        .saturating_mul(8)
}

/// The model-stage key ([`crate::ReductionBasis::stage_key`]) of [`PairSolves`]: bases
/// that solve with `K_c` return it and share one stage.
pub const PAIR_SOLVES_STAGE_KEY: &str = "tied solves: the free model's factor and pair responses";

impl PairSolves {
    /// The model stage of a basis that solves with `K_c` ([`crate::ReductionBasis::prepare`]):
    /// the pair solves of `free`, or `None` (the basis then factorizes each `K_c`) when
    /// their responses would pass [`PAIR_SOLVES_LIMIT_BYTES`].
    pub fn stage(free: &FreeModel<'_>) -> Result<Option<ModelStage>> {
        if response_bytes(free) > PAIR_SOLVES_LIMIT_BYTES || free.pairs.is_empty() {
            return Ok(None);
        }
        Ok(Some(Arc::new(Self::new(free)?)))
    }

    /// The Cholesky factor of the free model's `K` the pair solves run on.
    pub fn factor(&self) -> Arc<Cholesky> {
        self.factor.clone()
    }

    /// The pair solves in a basis request's model stage, if that is what it holds.
    pub fn in_stage(stage: Option<&(dyn std::any::Any + Send + Sync)>) -> Option<&Self> {
        stage.and_then(|s| s.downcast_ref::<Self>())
    }

    /// Builds the responses on the free model's candidate pairs, on its factor of `K`
    /// (`free.k_factor`) or on one computed here.
    pub fn new(free: &FreeModel<'_>) -> Result<Self> {
        let start = Instant::now();
        let n = free.k.nrows();
        let np = free.pairs.len();
        let bytes = response_bytes(free);
        if bytes > PAIR_SOLVES_LIMIT_BYTES {
            return Err(Error::Invalid(format!(
                "tied solves on the free model need {:.2} GiB for the responses of {np} \
                 candidate pairs on {n} DOFs (limit {:.2} GiB)",
                bytes as f64 / (1u64 << 30) as f64,
                PAIR_SOLVES_LIMIT_BYTES as f64 / (1u64 << 30) as f64
            )));
        }
        let mut normals = Vec::with_capacity(np);
        let mut sliding = Vec::with_capacity(np);
        for (i, p) in free.pairs.iter().enumerate() {
            if let Some(&d) = p.pin.iter().chain(&p.disc).find(|&&d| d >= n) {
                return Err(Error::Invalid(format!(
                    "tied solves: candidate pair {i} has DOF {d} for a model of {n} DOFs \
                     (expected DOFs below {n})"
                )));
            }
            let (a, b) = (p.pin[2], p.disc[2]);
            if a == b {
                return Err(Error::Invalid(format!(
                    "tied solves: candidate pair {i} has one normal DOF {a} for pin and disc \
                     (expected two distinct DOFs)"
                )));
            }
            normals.push((a, b));
            sliding.push((
                [p.pin[0], p.pin[1]],
                [p.disc[0], p.disc[1]],
                [p.direction[0], p.direction[1]],
            ));
        }
        let factor = match &free.k_factor {
            Some(f) if f.dim() == n => f.clone(),
            Some(f) => {
                return Err(Error::Dimension {
                    context: "tied solves: the given factor of K".into(),
                    expected: n,
                    got: f.dim(),
                })
            }
            None => Arc::new(Cholesky::new(free.k, "K (tied solves on the free model)")?),
        };
        let mut z = Mat::<f64>::zeros(n, np);
        for (c, &(a, b)) in normals.iter().enumerate() {
            z[(a, c)] = 1.0;
            z[(b, c)] = -1.0;
        }
        factor.solve_in_place(z.as_mut());
        let s = Mat::from_fn(np, np, |i, j| {
            let (a, b) = normals[i];
            0.5 * (z[(a, j)] - z[(b, j)] + z[(normals[j].0, i)] - z[(normals[j].1, i)])
        });
        Ok(Self {
            factor,
            normals,
            z: Normals::Kept(z),
            s,
            sliding,
            friction: Mutex::new(FrictionResponses { x: Vec::new() }),
            time_s: start.elapsed().as_secs_f64(),
        })
    }

    /// How many candidate pairs' friction-load responses are kept.
    pub fn kept_friction_responses(&self) -> usize {
        let kept = self.friction.lock().unwrap_or_else(|p| p.into_inner());
        kept.x.iter().filter(|x| x.is_some()).count()
    }

    /// Solves the free responses to the friction loads of every candidate pair not solved
    /// yet (one block solve) and keeps them, so that no later contact set solves any
    /// ([`TiedSolve::friction_statics`]); nothing when they would not fit
    /// ([`PAIR_SOLVES_LIMIT_BYTES`]).
    pub fn solve_friction_responses(&self) {
        if let Some(mut kept) = self.kept_responses() {
            let all: Vec<usize> = (0..self.pairs()).collect();
            self.solve_missing(&mut kept, &all);
        }
    }

    /// The kept friction-load responses (sized for every candidate pair at the first
    /// use), or `None` when they would pass [`PAIR_SOLVES_LIMIT_BYTES`] next to `Z`.
    fn kept_responses(&self) -> Option<MutexGuard<'_, FrictionResponses>> {
        let bytes = self.dim().saturating_mul(self.pairs()).saturating_mul(8);
        if bytes.saturating_mul(2) > PAIR_SOLVES_LIMIT_BYTES {
            return None;
        }
        let mut kept = self.friction.lock().unwrap_or_else(|p| p.into_inner());
        if kept.x.len() != self.pairs() {
            kept.x = vec![None; self.pairs()];
        }
        Some(kept)
    }

    /// Solves (one block solve) and keeps the responses of the pairs among `pairs` not
    /// kept yet; returns those pairs and the solved block (`n x` their count).
    fn solve_missing(
        &self,
        kept: &mut FrictionResponses,
        pairs: &[usize],
    ) -> (Vec<usize>, Mat<f64>) {
        let missing: Vec<usize> = pairs
            .iter()
            .copied()
            .filter(|&i| kept.x[i].is_none())
            .collect();
        let mut loads = Mat::<f64>::zeros(self.dim(), missing.len());
        if !missing.is_empty() {
            self.friction_responses_into(&missing, loads.as_mut());
            for (c, &i) in missing.iter().enumerate() {
                let col = loads.col(c).try_as_col_major().unwrap().as_slice();
                kept.x[i] = Some(col.into());
            }
        }
        (missing, loads)
    }

    /// The free responses `K^-1 p_i` to the friction loads of the candidate pairs `pairs`
    /// gathered into the columns of an `n x pairs.len()` block; the pairs met for the first
    /// time are solved (one block solve) and kept. `None` when the kept responses would
    /// pass [`PAIR_SOLVES_LIMIT_BYTES`] next to `Z`.
    fn friction_responses(&self, pairs: &[usize]) -> Option<Mat<f64>> {
        let mut kept = self.kept_responses()?;
        let (missing, solved) = self.solve_missing(&mut kept, pairs);
        // every pair solved now, in the order asked: the solved block is the answer
        if missing == pairs {
            return Some(solved);
        }
        let cols: Vec<&[f64]> = pairs
            .iter()
            .map(|&i| kept.x[i].as_deref())
            .collect::<Option<_>>()?;
        Some(Mat::from_fn(self.dim(), pairs.len(), |j, c| cols[c][j]))
    }

    /// Number of candidate pairs.
    pub fn pairs(&self) -> usize {
        self.normals.len()
    }

    /// `Z = K^-1 C^T` (`n x nR`), the free responses to the candidate pairs' unit normal
    /// loads, written into `out`.
    pub fn normal_responses_into(&self, mut out: MatMut<'_, f64>) {
        match &self.z {
            Normals::Kept(z) => out.copy_from(z.as_ref()),
            Normals::InSpace { q, r11 } => {
                let nr = r11.nrows();
                matmul(
                    out,
                    Accum::Replace,
                    q.as_ref().subcols(0, nr),
                    r11.as_ref(),
                    1.0,
                    faer::get_global_parallelism(),
                );
            }
        }
    }

    /// Gives up the kept `Z` for its form `Q_1 R_11` in `space`, a static space built on
    /// these pair solves ([`super::StaticSpace::new`]): `n nR` values fewer, and every
    /// tied solve's correction one product with `Q_1` (the columns up to the last active
    /// pair) instead of with `Z_A`.
    pub fn share_normals_with(&mut self, space: &super::StaticSpace) -> Result<()> {
        let (q, r11) = space.normal_factors();
        if q.nrows() != self.dim() || r11.nrows() != self.pairs() {
            return Err(Error::Dimension {
                context: "tied solves: the static space of other pair solves".into(),
                expected: self.pairs(),
                got: r11.nrows(),
            });
        }
        self.z = Normals::InSpace { q, r11 };
        Ok(())
    }

    /// The normal DOFs `(pin, disc)` of each candidate pair.
    pub fn normal_dofs(&self) -> &[(usize, usize)] {
        &self.normals
    }

    /// Solves the free responses to the friction loads of the candidate pairs `pairs`
    /// into the columns of `out` (`n x pairs.len()`, one block solve), without keeping
    /// them.
    pub fn friction_responses_into(&self, pairs: &[usize], mut out: MatMut<'_, f64>) {
        out.fill(0.0);
        for (c, &i) in pairs.iter().enumerate() {
            let (pin, disc, e) = self.sliding[i];
            for a in 0..2 {
                out[(pin[a], c)] += e[a];
                out[(disc[a], c)] -= e[a];
            }
        }
        if !pairs.is_empty() {
            self.factor.solve_in_place(out);
        }
    }

    /// Number of DOFs of the free model.
    pub fn dim(&self) -> usize {
        self.z.nrows()
    }

    /// The tied solve of the contact set of `op`: its active pairs read from its index
    /// map `T` (a pair is active when its two normal DOFs map to one constrained DOF).
    /// Refused for an operator without `T`, of another model, or whose map ties DOFs
    /// that are not the normals of candidate pairs.
    pub fn on<'a>(&'a self, op: &'a FrictionalOperator) -> Result<TiedSolve<'a>> {
        let t = op.t.as_deref().ok_or_else(|| {
            Error::Invalid(
                "tied solves: the operator has no index map T (it was read from files)".into(),
            )
        })?;
        let n = self.dim();
        if t.len() != n {
            return Err(Error::Dimension {
                context: "tied solves: the operator's unconstrained DOFs".into(),
                expected: n,
                got: t.len(),
            });
        }
        let nc = op.dim();
        let mut count = vec![0usize; nc];
        let mut rep = vec![usize::MAX; nc];
        for (j, &c) in t.iter().enumerate() {
            if c >= nc {
                return Err(Error::Invalid(format!(
                    "tied solves: T maps free DOF {j} to {c}, beyond the {nc} constrained DOFs"
                )));
            }
            count[c] += 1;
            if rep[c] == usize::MAX {
                rep[c] = j;
            }
        }
        let active: Vec<usize> = (0..self.pairs())
            .filter(|&i| t[self.normals[i].0] == t[self.normals[i].1])
            .collect();
        let tied = n.saturating_sub(nc);
        if nc > n || tied != active.len() || count.iter().any(|&k| k == 0 || k > 2) {
            return Err(Error::Invalid(format!(
                "tied solves: the operator ties {tied} DOFs, not the normals of {} candidate \
                 pairs alone",
                active.len()
            )));
        }
        let na = active.len();
        let saa = Mat::from_fn(na, na, |i, j| self.s[(active[i], active[j])]);
        let llt = saa.llt(Side::Lower).map_err(|e| Error::Factorization {
            what: format!("S_AA = C_A K^-1 C_A^T ({na} active pairs)"),
            reason: format!(
                "{}: the pair flexibility must be positive definite",
                crate::linalg::explain::llt(&e, na)
            ),
        })?;
        // runs of consecutive active pairs: `Z_A lambda` as a few products on column
        // ranges of `Z` instead of a copy of `Z_A`
        let mut runs: Vec<(usize, usize)> = Vec::new();
        for (k, &p) in active.iter().enumerate() {
            match runs.last_mut() {
                Some((start, len)) if active[*start + *len - 1] + 1 == p => *len += 1,
                _ => runs.push((k, 1)),
            }
        }
        Ok(TiedSolve {
            solves: self,
            t,
            inv_count: count.iter().map(|&k| 1.0 / k as f64).collect(),
            rep,
            active,
            l: llt.L().to_owned(),
            runs,
        })
    }
}

/// The kept responses to the candidate pairs' friction loads ([`PairSolves`]).
struct FrictionResponses {
    /// `K^-1 p_i` of each candidate pair `i`, once solved (`np` entries from the first
    /// use).
    x: Vec<Option<Box<[f64]>>>,
}

/// Solves with `K_c` of one contact set through the free model's [`PairSolves`] (module
/// docs).
pub struct TiedSolve<'a> {
    solves: &'a PairSolves,
    t: &'a [usize],
    /// `1 / (free DOFs of each constrained DOF)`.
    inv_count: Vec<f64>,
    /// One free DOF of each constrained DOF.
    rep: Vec<usize>,
    active: Vec<usize>,
    /// Cholesky factor of `S_AA`.
    l: Mat<f64>,
    /// Runs `(first index into active, length)` of consecutive active pairs.
    runs: Vec<(usize, usize)>,
}

impl TiedSolve<'_> {
    /// Number of active pairs.
    pub fn active_pairs(&self) -> usize {
        self.active.len()
    }

    /// The active pairs (candidate indices, ascending: the order of the operator's
    /// friction loads).
    pub fn active(&self) -> &[usize] {
        &self.active
    }

    /// One free DOF of each constrained DOF (the row a free vector is read at).
    pub fn rep(&self) -> &[usize] {
        &self.rep
    }

    /// `G <- S_AA^-1 G` for a block with one row per active pair.
    pub fn solve_pairs(&self, mut g: MatMut<'_, f64>) {
        faer::linalg::triangular_solve::solve_lower_triangular_in_place(
            self.l.as_ref(),
            g.as_mut(),
            Par::Seq,
        );
        faer::linalg::triangular_solve::solve_upper_triangular_in_place(
            self.l.transpose(),
            g.as_mut(),
            Par::Seq,
        );
    }

    /// `B <- K_c^-1 B`.
    pub fn solve(&self, b: MatMut<'_, f64>) {
        let (n, r) = (self.t.len(), b.ncols());
        let mut f = Mat::from_fn(n, r, |j, c| {
            let k = self.t[j];
            b[(k, c)] * self.inv_count[k]
        });
        self.solves.factor.solve_in_place(f.as_mut());
        self.tie(f, b);
    }

    /// `K_c^-1 U` for the friction load directions `u` of the operator (`n_c x nA`, one
    /// column per active pair, in the order of the candidate pairs), from the free model's
    /// kept responses to the pairs' friction loads (module docs; the pairs no contact set
    /// tied before are solved now). `None` when a column of `u` is not the friction load
    /// of its pair or the kept responses would not fit ([`PAIR_SOLVES_LIMIT_BYTES`]): the
    /// caller then solves `u`.
    pub fn friction_statics(&self, u: SparseRef<'_>) -> Option<Mat<f64>> {
        let na = self.active.len();
        if u.ncols() != na || u.nrows() != self.rep.len() {
            return None;
        }
        for (c, &i) in self.active.iter().enumerate() {
            let (pin, disc, e) = self.solves.sliding[i];
            let mut want: Vec<(usize, f64)> = (0..2)
                .filter(|&a| e[a] != 0.0)
                .flat_map(|a| [(self.t[pin[a]], e[a]), (self.t[disc[a]], -e[a])])
                .collect();
            want.sort_by_key(|w| w.0);
            let rows = u.row_idx_of_col_raw(c);
            let vals = u.val_of_col(c);
            let same = rows.len() == want.len()
                && rows
                    .iter()
                    .zip(vals)
                    .zip(&want)
                    .all(|((&r, &v), &(wr, wv))| r == wr && v == wv);
            if !same {
                return None;
            }
        }
        let f = self.solves.friction_responses(&self.active)?;
        let mut out = Mat::<f64>::zeros(self.rep.len(), na);
        self.tie(f, out.as_mut());
        Some(out)
    }

    /// The tied solution from the free one `f = K^-1 T D^-1 b` (the correction onto the
    /// ties, module docs), written into `b` in the constrained numbering.
    fn tie(&self, mut f: Mat<f64>, mut b: MatMut<'_, f64>) {
        let r = f.ncols();
        let na = self.active.len();
        if na > 0 {
            let normals = &self.solves.normals;
            let mut g = Mat::from_fn(na, r, |i, c| {
                let (p, d) = normals[self.active[i]];
                f[(p, c)] - f[(d, c)]
            });
            self.solve_pairs(g.as_mut());
            let par = faer::get_global_parallelism();
            match &self.solves.z {
                Normals::Kept(z) => {
                    for &(k, len) in &self.runs {
                        let zr = z.as_ref().subcols(self.active[k], len);
                        matmul(
                            f.as_mut(),
                            Accum::Add,
                            zr,
                            g.as_ref().subrows(k, len),
                            -1.0,
                            par,
                        );
                    }
                }
                Normals::InSpace { q, r11 } => {
                    // Z_A g = Q_1 (R_11 E_A g), R_11 upper triangular: the columns of
                    // Q_1 up to the last active pair
                    let p = self.active[na - 1] + 1;
                    let mut h = Mat::<f64>::zeros(p, r);
                    for (k, &i) in self.active.iter().enumerate() {
                        for c in 0..r {
                            h[(i, c)] = g[(k, c)];
                        }
                    }
                    let mut y = Mat::<f64>::zeros(p, r);
                    faer::linalg::matmul::triangular::matmul(
                        y.as_mut(),
                        faer::linalg::matmul::triangular::BlockStructure::Rectangular,
                        Accum::Replace,
                        r11.as_ref().submatrix(0, 0, p, p),
                        faer::linalg::matmul::triangular::BlockStructure::TriangularUpper,
                        h.as_ref(),
                        faer::linalg::matmul::triangular::BlockStructure::Rectangular,
                        1.0,
                        Par::Seq,
                    );
                    matmul(
                        f.as_mut(),
                        Accum::Add,
                        q.as_ref().subcols(0, p),
                        y.as_ref(),
                        -1.0,
                        par,
                    );
                }
            }
        }
        for col in 0..r {
            for (c, &j) in self.rep.iter().enumerate() {
                b[(c, col)] = f[(j, col)];
            }
        }
    }
}

impl BlockSolve for TiedSolve<'_> {
    fn solve_block(&self, b: MatMut<'_, f64>) {
        if b.ncols() > 0 {
            self.solve(b);
        }
    }
}
