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
//! Accuracy: the tied displacement is the difference of the free one and the ties'
//! correction, so it carries their rounding: on the default rig at mu 0.3 the relative
//! residuals `|K_c u_c - b_c| / |b_c|` of the `enriched` basis's solves are 4e-12 to
//! 4e-10. The modal solvers check their eigenpairs on `K_c` and `M_c` (not on the
//! solves), and a static response is a basis direction, so neither needs more: the
//! frequencies of the `enriched` sweep of `squeal validate` agree with those on a
//! factorized `K_c` to 1e-9, their backward errors to the printed digits.

use crate::contact::{FreeModel, ModelStage};
use crate::linalg::{BlockSolve, Cholesky};
use crate::operator::FrictionalOperator;
use crate::{Error, Result};
use faer::linalg::matmul::matmul;
use faer::{Accum, Mat, MatMut, Par, Side};
use std::sync::Arc;
use std::time::Instant;

/// Largest memory (bytes) the kept responses `Z` of the candidate pairs may take.
pub const PAIR_SOLVES_LIMIT_BYTES: usize = 4 << 30;

/// The free model's responses to unit normal pair loads, kept for every contact set drawn
/// from its candidate pairs (see the module docs): the factor of `K`, `Z = K^-1 C^T` and
/// `S = C Z`.
pub struct PairSolves {
    factor: Arc<Cholesky>,
    /// Normal (`z`) DOFs `(pin, disc)` of each candidate pair, free numbering.
    normals: Vec<(usize, usize)>,
    z: Mat<f64>,
    s: Mat<f64>,
    /// Wall time of the construction (s), the factorization of `K` included when it was
    /// not given.
    pub time_s: f64,
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
        for (i, p) in free.pairs.iter().enumerate() {
            let (a, b) = (p.pin[2], p.disc[2]);
            if a >= n || b >= n || a == b {
                return Err(Error::Invalid(format!(
                    "tied solves: candidate pair {i} has normal DOFs ({a}, {b}) for a model of \
                     {n} DOFs (expected two distinct DOFs below {n})"
                )));
            }
            normals.push((a, b));
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
            z,
            s,
            time_s: start.elapsed().as_secs_f64(),
        })
    }

    /// Number of candidate pairs.
    pub fn pairs(&self) -> usize {
        self.normals.len()
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
            reason: format!("{e:?}: the pair flexibility must be positive definite"),
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

    /// `B <- K_c^-1 B`.
    pub fn solve(&self, mut b: MatMut<'_, f64>) {
        let (n, r) = (self.t.len(), b.ncols());
        let mut f = Mat::from_fn(n, r, |j, c| {
            let k = self.t[j];
            b[(k, c)] * self.inv_count[k]
        });
        self.solves.factor.solve_in_place(f.as_mut());
        let na = self.active.len();
        if na > 0 {
            let normals = &self.solves.normals;
            let mut g = Mat::from_fn(na, r, |i, c| {
                let (p, d) = normals[self.active[i]];
                f[(p, c)] - f[(d, c)]
            });
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
            let par = faer::get_global_parallelism();
            for &(k, len) in &self.runs {
                let zr = self.solves.z.as_ref().subcols(self.active[k], len);
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
