//! Construction of a [`FreeInterface`] (modes, static contact responses, residual
//! contact flexibilities) and what it tells about itself.

use super::pairs::PairMoments;
use super::{
    add_pair_load, par, pn_rows, pt_rows, FreeInterface, PairDofs, Stored, SECOND_GAPS_LIMIT_BYTES,
    STORE_LIMIT_BYTES,
};
use squeal_core::faer::linalg::matmul::matmul;
use squeal_core::faer::{Accum, Mat};
use squeal_core::linalg::Cholesky;
use squeal_core::FrictionalOperator;
use squeal_core::RealModes;
use squeal_core::{Error, Result, SparseMat, SparseRef};
use std::sync::Arc;
use std::time::Instant;

/// `K^-1` in place on the columns of `x`, `BLOCK` at a time (bounded workspace).
fn solve_blocks(factor: &Cholesky, x: &mut Mat<f64>) {
    let mut c0 = 0;
    while c0 < x.ncols() {
        let b = BLOCK.min(x.ncols() - c0);
        factor.solve_in_place(x.as_mut().subcols_mut(c0, b));
        c0 += b;
    }
}

/// Columns solved together.
const BLOCK: usize = 64;

impl FreeInterface {
    /// The Cholesky factor of the free model's `K` the synthesis expands with.
    pub fn factor(&self) -> Arc<Cholesky> {
        self.factor.clone()
    }

    /// Builds the free-interface data of the model `(k, m)` (free DOFs, `K` positive
    /// definite) for the candidate `pairs`, with the free-interface `modes` (of the same
    /// `(K, M)`, `M`-orthonormal, e.g. from an [`EigenSolver`](squeal_core::EigenSolver) up to a
    /// cutoff above the band). The static responses of the pairs are stored when they fit
    /// in [`STORE_LIMIT_BYTES`] (and their second-order terms when both fit in
    /// [`STORE_SECOND_LIMIT_BYTES`]), otherwise solved for each expansion.
    ///
    /// [`STORE_SECOND_LIMIT_BYTES`]: super::STORE_SECOND_LIMIT_BYTES
    pub fn new(
        k: SparseRef<'_>,
        m: SparseRef<'_>,
        pairs: &[PairDofs],
        modes: &RealModes,
    ) -> Result<Self> {
        Self::with_store_limit(k, m, pairs, modes, STORE_LIMIT_BYTES)
    }

    /// [`FreeInterface::new`] with the memory limit (bytes) of the stored static
    /// responses (`32 n nR` bytes); 0 never stores them. Both ways give the same modes to
    /// round-off.
    pub fn with_store_limit(
        k: SparseRef<'_>,
        m: SparseRef<'_>,
        pairs: &[PairDofs],
        modes: &RealModes,
        store_limit_bytes: usize,
    ) -> Result<Self> {
        Self::build(k, m, pairs, modes, None, store_limit_bytes, false)
    }

    /// [`FreeInterface::with_store_limit`] with the memory limit of the second-order gaps
    /// too ([`SECOND_GAPS_LIMIT_BYTES`]; 0 never keeps them): the tests' way to reach
    /// each path.
    #[cfg(test)]
    pub(super) fn with_limits(
        k: SparseRef<'_>,
        m: SparseRef<'_>,
        pairs: &[PairDofs],
        modes: &RealModes,
        store_limit_bytes: usize,
        gaps_limit_bytes: usize,
    ) -> Result<Self> {
        let limits = (store_limit_bytes, gaps_limit_bytes);
        Self::build_with(k, m, pairs, modes, None, limits, false)
    }

    /// [`FreeInterface::new`] with the Cholesky factor of the same `K` already computed
    /// (by the contact condensation of the model, [`Condensation::factor`]): no second
    /// factorization.
    ///
    /// [`Condensation::factor`]: squeal_core::contact::Condensation::factor
    pub fn with_factor(
        k: SparseRef<'_>,
        m: SparseRef<'_>,
        pairs: &[PairDofs],
        modes: &RealModes,
        factor: Arc<Cholesky>,
    ) -> Result<Self> {
        Self::build(k, m, pairs, modes, Some(factor), STORE_LIMIT_BYTES, false)
    }

    /// [`FreeInterface::new`] (on the given factor of `K` when there is one) for a caller
    /// that will synthesize `contact_sets` contact sets: when the responses are solved per
    /// expansion (not stored) and there are at least `nR / 10` contact sets, the gaps of
    /// the second-order terms on the pairs are kept too ([`keeps_second_gaps`]: `2 nR`
    /// more solved columns here, `16 nR^2` bytes, one block solve fewer per expansion; the
    /// same modes to round-off).
    ///
    /// [`keeps_second_gaps`]: FreeInterface::keeps_second_gaps
    pub fn for_contact_sets(
        k: SparseRef<'_>,
        m: SparseRef<'_>,
        pairs: &[PairDofs],
        modes: &RealModes,
        factor: Option<Arc<Cholesky>>,
        contact_sets: usize,
    ) -> Result<Self> {
        let gaps = if gaps_pay(pairs.len(), contact_sets) {
            SECOND_GAPS_LIMIT_BYTES
        } else {
            0
        };
        let limits = (STORE_LIMIT_BYTES, gaps);
        Self::build_with(k, m, pairs, modes, factor, limits, false)
    }

    /// [`FreeInterface::new`] (on the given factor of `K` when there is one) with the
    /// moments of the static responses on the pairs as well, so that every contact set's
    /// operator can be projected on the pairs alone ([`FreeInterface::project_on_pairs`]):
    /// three more block solves per block of pairs, and `288 nR^2` bytes (an error beyond
    /// [`PAIR_MOMENTS_LIMIT_BYTES`]). The responses themselves are not stored: the
    /// projection on the pairs does not use them.
    ///
    /// [`PAIR_MOMENTS_LIMIT_BYTES`]: super::PAIR_MOMENTS_LIMIT_BYTES
    pub fn with_pair_moments(
        k: SparseRef<'_>,
        m: SparseRef<'_>,
        pairs: &[PairDofs],
        modes: &RealModes,
        factor: Option<Arc<Cholesky>>,
    ) -> Result<Self> {
        Self::build(k, m, pairs, modes, factor, STORE_LIMIT_BYTES, true)
    }

    fn build(
        k: SparseRef<'_>,
        m: SparseRef<'_>,
        pairs: &[PairDofs],
        modes: &RealModes,
        factor: Option<Arc<Cholesky>>,
        store_limit_bytes: usize,
        with_moments: bool,
    ) -> Result<Self> {
        Self::build_with(
            k,
            m,
            pairs,
            modes,
            factor,
            (store_limit_bytes, 0),
            with_moments,
        )
    }

    /// [`Self::build`] with the memory limits of the stored responses and of the
    /// second-order gaps.
    fn build_with(
        k: SparseRef<'_>,
        m: SparseRef<'_>,
        pairs: &[PairDofs],
        modes: &RealModes,
        factor: Option<Arc<Cholesky>>,
        (store_limit_bytes, gaps_limit_bytes): (usize, usize),
        with_moments: bool,
    ) -> Result<Self> {
        let start = Instant::now();
        let n = k.nrows();
        let nr = pairs.len();
        let nm = modes.omega2.len();
        check_inputs(k, m, pairs, modes)?;
        let mut moments = match with_moments {
            true => Some(PairMoments::zeros(
                k,
                m,
                pairs,
                modes,
                super::PAIR_MOMENTS_LIMIT_BYTES,
            )?),
            false => None,
        };
        let factor = match factor {
            Some(f) if f.dim() == n => f,
            Some(f) => {
                return Err(Error::Dimension {
                    context: "free-interface synthesis: the given factor of K".into(),
                    expected: n,
                    got: f.dim(),
                })
            }
            None => Arc::new(Cholesky::new(k, "K (free-interface synthesis)")?),
        };
        let phi = modes.vectors.clone();
        let pn_phi = pn_rows(pairs, phi.as_ref());
        let pt_phi = pt_rows(pairs, phi.as_ref());
        // Pn K^-1 Pn^T and Pn K^-1 Pt^T, a block of pairs at a time; the whole responses
        // kept when they fit
        let mut wfull = Mat::<f64>::zeros(nr, nr);
        let mut wt = Mat::<f64>::zeros(nr, nr);
        // the first-order responses take 16 n nR bytes, the second-order terms as much
        // again; with the moments nothing is stored: the projection on the pairs does not
        // use them (a damped operator, projected the full way, solves them per case)
        let store =
            !with_moments && 16usize.saturating_mul(n).saturating_mul(nr) <= store_limit_bytes;
        let store_second = 32usize.saturating_mul(n).saturating_mul(nr)
            <= store_limit_bytes.min(super::STORE_SECOND_LIMIT_BYTES);
        let mut stored = store.then(|| Stored {
            zn: Mat::zeros(n, nr),
            zt: Mat::zeros(n, nr),
            yn: Mat::zeros(0, 0),
            yt: Mat::zeros(0, 0),
        });
        // without stored responses, the gaps of the second-order terms (one more block
        // solve per block of pairs here, one fewer per expansion)
        let mut second_gaps = (stored.is_none()
            && moments.is_none()
            && 16usize.saturating_mul(nr).saturating_mul(nr) <= gaps_limit_bytes)
            .then(|| [Mat::<f64>::zeros(nr, nr), Mat::<f64>::zeros(nr, nr)]);
        let mut c0 = 0;
        while c0 < nr {
            let b = BLOCK.min(nr - c0);
            // unit normal loads in the first b columns, unit sliding loads in the next b
            let mut x = Mat::<f64>::zeros(n, 2 * b);
            for (j, p) in pairs[c0..c0 + b].iter().enumerate() {
                add_pair_load(&mut x, p, j, 1.0, 0.0);
                add_pair_load(&mut x, p, b + j, 0.0, 1.0);
            }
            factor.solve_in_place(x.as_mut());
            if let Some(mo) = moments.as_mut() {
                mo.add_block(&factor, m, pairs, (&phi, &pn_phi, &pt_phi), c0, b, &x);
            }
            if let Some(st) = stored.as_mut() {
                st.zn
                    .as_mut()
                    .subcols_mut(c0, b)
                    .copy_from(x.as_ref().subcols(0, b));
                st.zt
                    .as_mut()
                    .subcols_mut(c0, b)
                    .copy_from(x.as_ref().subcols(b, b));
            }
            if let Some([hn, ht]) = second_gaps.as_mut() {
                let mut y = squeal_core::linalg::symmetric_times(m, x.as_ref());
                factor.solve_in_place(y.as_mut());
                let rows = pn_rows(pairs, y.as_ref());
                hn.as_mut()
                    .subcols_mut(c0, b)
                    .copy_from(rows.as_ref().subcols(0, b));
                ht.as_mut()
                    .subcols_mut(c0, b)
                    .copy_from(rows.as_ref().subcols(b, b));
            }
            let rows = pn_rows(pairs, x.as_ref());
            wfull
                .as_mut()
                .subcols_mut(c0, b)
                .copy_from(rows.as_ref().subcols(0, b));
            wt.as_mut()
                .subcols_mut(c0, b)
                .copy_from(rows.as_ref().subcols(b, b));
            c0 += b;
        }
        if let Some(mo) = moments.as_mut() {
            mo.finish();
        }
        if let Some(st) = stored.as_mut().filter(|_| store_second) {
            // second-order residual terms K^-1 M K^-1 (Pn^T | Pt^T)
            for (z, y) in [(&st.zn, &mut st.yn), (&st.zt, &mut st.yt)] {
                *y = squeal_core::linalg::symmetric_times(m, z.as_ref());
                solve_blocks(&factor, y);
            }
        }
        let mut wn = wfull.clone();
        // residual flexibility: subtract Pn Phi Omega^-2 (Pn Phi | Pt Phi)^T
        let scaled = Mat::from_fn(nr, nm, |i, c| pn_phi[(i, c)] / modes.omega2[c]);
        matmul(
            wn.as_mut(),
            Accum::Add,
            scaled.as_ref(),
            pn_phi.transpose(),
            -1.0,
            par(),
        );
        matmul(
            wt.as_mut(),
            Accum::Add,
            scaled.as_ref(),
            pt_phi.transpose(),
            -1.0,
            par(),
        );
        let cutoff_hz = modes.omega2.iter().fold(0.0f64, |a, &w| a.max(w)).sqrt()
            / (2.0 * std::f64::consts::PI);
        Ok(Self {
            pairs: pairs.to_vec(),
            phi: Arc::new(phi),
            omega2: modes.omega2.clone(),
            factor,
            stored,
            m: Arc::new(SparseMat::new(
                m.symbolic()
                    .to_owned()
                    .map_err(|e| Error::Invalid(format!("copy of M: {e:?}")))?,
                m.val().to_vec(),
            )),
            moments,
            second_gaps,
            wfull,
            wn,
            wt,
            pn_phi,
            pt_phi,
            cutoff_hz,
            time_s: start.elapsed().as_secs_f64(),
        })
    }

    /// Whether the static responses of the pairs are stored (else solved per expansion).
    pub fn stores_responses(&self) -> bool {
        self.stored.is_some()
    }

    /// Whether the second-order terms `K^-1 M K^-1 (Pn^T | Pt^T)` are stored too (else
    /// solved per expansion from the first-order responses).
    pub fn stores_second_order(&self) -> bool {
        self.stored.as_ref().is_some_and(Stored::second_order)
    }

    /// Whether the gaps of the second-order terms are kept (responses solved per
    /// expansion, the second-order directions' tie correction joined to their solve).
    pub fn keeps_second_gaps(&self) -> bool {
        self.second_gaps.is_some()
    }

    /// Whether the moments of the static responses on the pairs are built (every contact
    /// set then projected on the pairs alone).
    pub fn has_pair_moments(&self) -> bool {
        self.moments.is_some()
    }

    /// Number of candidate pairs.
    pub fn pairs(&self) -> usize {
        self.pairs.len()
    }

    /// Number of free-interface modes.
    pub fn modes(&self) -> usize {
        self.omega2.len()
    }

    /// Number of unconstrained DOFs.
    pub fn dofs(&self) -> usize {
        self.phi.nrows()
    }

    /// The candidate pairs (region indices are positions in this list).
    pub fn pair_dofs(&self) -> &[PairDofs] {
        &self.pairs
    }

    /// The region indices of the pairs tied in `op` (its index map relabels their pin
    /// normal DOF onto the disc's). An error when `op` has no index map, another size, or
    /// active pairs outside the candidate set.
    pub fn active_in(&self, op: &FrictionalOperator) -> Result<Vec<usize>> {
        let t = op.t.as_ref().ok_or_else(|| {
            Error::Invalid(
                "free-interface synthesis: the operator has no index map T (it was read \
                 from files); build it from a scene"
                    .into(),
            )
        })?;
        if t.len() != self.dofs() {
            return Err(Error::Dimension {
                context: "free-interface synthesis: operator's unconstrained DOFs".into(),
                expected: self.dofs(),
                got: t.len(),
            });
        }
        let active: Vec<usize> = (0..self.pairs.len())
            .filter(|&i| t[self.pairs[i].pin[2]] == t[self.pairs[i].disc[2]])
            .collect();
        let tied = t.len() - op.dim();
        if tied != active.len() {
            return Err(Error::Invalid(format!(
                "free-interface synthesis: the operator ties {tied} pairs but only {} of \
                 them are among the {} candidate pairs of the synthesis",
                active.len(),
                self.pairs.len()
            )));
        }
        Ok(active)
    }
}

/// Whether the second-order gaps pay for `contact_sets` contact sets on `nr` candidate
/// pairs: they cost `2 nr` solved columns once and save about 20-40 per contact set (the
/// second-order directions of the modes expanded), so they pay from about `nr / 20`
/// contact sets; the rule asks for twice that.
pub(super) fn gaps_pay(nr: usize, contact_sets: usize) -> bool {
    contact_sets.saturating_mul(10) >= nr
}

/// The inputs of [`FreeInterface::build`]: pairs present and inside the model, modes and
/// `M` of the size of `K`, every kept eigenvalue positive (a held model).
fn check_inputs(
    k: SparseRef<'_>,
    m: SparseRef<'_>,
    pairs: &[PairDofs],
    modes: &RealModes,
) -> Result<()> {
    let n = k.nrows();
    let nr = pairs.len();
    let nm = modes.omega2.len();
    if nr == 0 {
        return Err(Error::Invalid(
            "free-interface synthesis: no candidate contact pair".into(),
        ));
    }
    if modes.vectors.nrows() != n || modes.vectors.ncols() != nm {
        return Err(Error::Dimension {
            context: "free-interface synthesis: mode shapes against K".into(),
            expected: n,
            got: modes.vectors.nrows(),
        });
    }
    if m.nrows() != n || m.ncols() != n {
        return Err(Error::Dimension {
            context: "free-interface synthesis: M against K".into(),
            expected: n,
            got: m.nrows(),
        });
    }
    if nm == 0 {
        return Err(Error::Invalid(
            "free-interface synthesis: no free-interface mode below the cutoff".into(),
        ));
    }
    if let Some(&w) = modes.omega2.iter().find(|w| !(w.is_finite() && **w > 0.0)) {
        return Err(Error::Invalid(format!(
            "free-interface synthesis: eigenvalue omega^2 = {w:e} (rad/s)^2 is not \
             positive: the unconstrained model must be held (no rigid-body mode)"
        )));
    }
    for (i, p) in pairs.iter().enumerate() {
        if p.pin.iter().chain(&p.disc).any(|&d| d >= n) {
            return Err(Error::Invalid(format!(
                "free-interface synthesis: pair {i} has a DOF beyond the model's {n}"
            )));
        }
    }
    Ok(())
}
