//! Free-interface modal synthesis with residual flexibility (MacNeal) for a family of
//! contact sets drawn from one set of candidate pairs: the machinery behind the `cms`
//! basis, built once per model and region and then reused for every contact set and mu.
//!
//! For the active pairs `A` the linearized problem is the descriptor system
//! `(lambda^2 M + K) u = B_A^T r`, `Pn_A u = 0`, `B_A = Pn_A + mu Pt_A` (METHODS.md
//! section 2, undamped). With the free-interface modes `Phi` of the unconstrained model
//! (no pair tied: `K Phi = M Phi Omega^2`, `Phi^T M Phi = I`) up to a cutoff, and the
//! residual flexibility `G = K^-1 - Phi Omega^-2 Phi^T` taken at `lambda = 0`,
//!
//! `u = Phi eta + G B_A^T r`, `(lambda^2 + Omega^2) eta = Phi^T B_A^T r`.
//!
//! The ties give `r = -S^-1 P eta` with `S = Pn_A G B_A^T` (`nA x nA`) and `P = Pn_A Phi`,
//! hence the `m x m` standard eigenproblem `lambda^2 eta = -(Omega^2 + Q^T S^-1 P) eta`,
//! `Q = B_A Phi`, whatever the number of pairs. The residual contact flexibilities
//! `Pn G Pn^T`, `Pn G Pt^T` of the candidate pairs are computed once (one Cholesky
//! factorization of `K`, kept, and `2 nR` solves whose pair rows alone are kept, so the
//! memory is `O(nR^2)`, not `O(n nR)`; the whole responses `K^-1 (Pn^T | Pt^T)` and their
//! second-order terms are stored too when they fit [`STORE_LIMIT_BYTES`]): a new contact
//! set or mu then costs one `nA x nA` LU, one `m x m` eigen decomposition and the
//! expansion `u = Phi (eta - Omega^-2 Q^T r) + K^-1 B_A^T r` (products with the stored
//! responses, or block solves for the modes expanded), which satisfies `Pn_A u = 0`
//! exactly.
//!
//! The residual flexibility is static (its inertia is neglected), so the synthesized modes
//! are approximations whose error falls with the ratio of the band to the modal cutoff;
//! the `cms` basis uses them as Ritz vectors of the exact operator of the contact set, so
//! every returned mode still carries its backward error on the full operator.
//!
//! Normals are `+e_z` (flat disc face), as in the operator builder.

use crate::contact::FrictionalOperator;
use crate::eigen::RealModes;
use crate::linalg::Cholesky;
use crate::{c64, Error, Result, SparseMat, SparseRef};
use faer::linalg::matmul::matmul;
use faer::{Accum, Mat, MatRef, Par};
use std::time::Instant;

/// The DOFs of one candidate contact pair in the unconstrained (free) numbering.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PairDofs {
    /// Pin node DOFs (x, y, z).
    pub pin: [usize; 3],
    /// Disc node DOFs (x, y, z).
    pub disc: [usize; 3],
    /// Unit in-plane sliding direction `e_i` (the friction on the pin points along it).
    pub direction: [f64; 3],
}

/// The free-interface data of one model and one set of candidate pairs (see the module
/// docs): modes, static contact responses and residual contact flexibilities.
pub struct FreeInterface {
    pairs: Vec<PairDofs>,
    phi: Mat<f64>,
    omega2: Vec<f64>,
    /// Cholesky factor of `K`: the static responses `K^-1 (Pn^T | Pt^T) r` of the
    /// expansion, solved for the modes expanded (when they are not stored).
    factor: Cholesky,
    /// The static responses of every candidate pair, stored when they fit the memory
    /// limit: faster expansions, `4 n nR` values.
    stored: Option<Stored>,
    /// `M`, for the second-order residual terms `K^-1 M K^-1 (.)`.
    m: SparseMat,
    /// Full static `Pn K^-1 Pn^T` (`nR x nR`, m/N).
    wfull: Mat<f64>,
    /// Residual `Pn G Pn^T` (`nR x nR`, m/N).
    wn: Mat<f64>,
    /// Residual `Pn G Pt^T` (`nR x nR`, m/N).
    wt: Mat<f64>,
    /// `Pn Phi`, `Pt Phi` (`nR x m`).
    pn_phi: Mat<f64>,
    pt_phi: Mat<f64>,
    /// Highest free-interface frequency kept (Hz).
    pub cutoff_hz: f64,
    /// Wall time of the construction, modes excluded (s).
    pub time_s: f64,
}

/// `K^-1 Pn^T`, `K^-1 Pt^T` and the second-order terms `K^-1 M K^-1 (Pn^T | Pt^T)`
/// (`n x nR` each).
struct Stored {
    zn: Mat<f64>,
    zt: Mat<f64>,
    yn: Mat<f64>,
    yt: Mat<f64>,
}

/// Largest memory (bytes) [`FreeInterface::new`] spends on stored static responses.
pub const STORE_LIMIT_BYTES: usize = 3 << 30;

/// The synthesized modes of one contact set at one mu.
#[derive(Debug, Clone)]
pub struct Synthesized {
    /// Eigenvalues `s = -lambda^2` ((rad/s)^2), one per free-interface mode.
    pub s: Vec<c64>,
    /// Modal coordinates `eta` (`m x m`, one column per `s`).
    pub eta: Mat<c64>,
    /// Normal reactions `r = -S^-1 P eta` of the active pairs (`nA x m`, N).
    pub r: Mat<c64>,
    /// Region indices of the active pairs (rows of `r`).
    pub active: Vec<usize>,
    /// Friction coefficient.
    pub mu: f64,
}

impl Synthesized {
    /// `lambda = i sqrt(s)` on the branch with `Im(lambda) >= 0`; its frequency (Hz) is
    /// `Im(lambda) / 2 pi`.
    pub fn lambda(&self, k: usize) -> c64 {
        let root = self.s[k].sqrt();
        c64::new(-root.im, root.re)
    }

    /// Frequency of synthesized mode `k` (Hz).
    pub fn freq_hz(&self, k: usize) -> f64 {
        self.lambda(k).im / (2.0 * std::f64::consts::PI)
    }
}

fn par() -> Par {
    faer::get_global_parallelism()
}

/// Adds to column `c` of `x` the pair loads `Pn^T normal + Pt^T sliding` of pair `p`
/// (on the pin node, and opposite on the disc node).
fn add_pair_load(x: &mut Mat<f64>, p: &PairDofs, c: usize, normal: f64, sliding: f64) {
    x[(p.pin[2], c)] += normal;
    x[(p.disc[2], c)] -= normal;
    if sliding != 0.0 {
        for a in 0..2 {
            x[(p.pin[a], c)] += sliding * p.direction[a];
            x[(p.disc[a], c)] -= sliding * p.direction[a];
        }
    }
}

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
    /// Builds the free-interface data of the model `(k, m)` (free DOFs, `K` positive
    /// definite) for the candidate `pairs`, with the free-interface `modes` (of the same
    /// `(K, M)`, `M`-orthonormal, e.g. from an [`EigenSolver`](crate::EigenSolver) up to a
    /// cutoff above the band). The static responses of the pairs are stored when they fit
    /// in [`STORE_LIMIT_BYTES`], otherwise solved for each expansion.
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
        let start = Instant::now();
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
        let factor = Cholesky::new(k, "K (free-interface synthesis)")?;
        let pn_rows = |x: MatRef<'_, f64>| {
            Mat::from_fn(nr, x.ncols(), |i, c| {
                x[(pairs[i].pin[2], c)] - x[(pairs[i].disc[2], c)]
            })
        };
        let pt_rows = |x: MatRef<'_, f64>| {
            Mat::from_fn(nr, x.ncols(), |i, c| {
                let p = &pairs[i];
                (0..2)
                    .map(|a| p.direction[a] * (x[(p.pin[a], c)] - x[(p.disc[a], c)]))
                    .sum()
            })
        };
        let phi = modes.vectors.clone();
        let pn_phi = pn_rows(phi.as_ref());
        let pt_phi = pt_rows(phi.as_ref());
        // Pn K^-1 Pn^T and Pn K^-1 Pt^T, a block of pairs at a time; the whole responses
        // kept when they fit
        let mut wfull = Mat::<f64>::zeros(nr, nr);
        let mut wt = Mat::<f64>::zeros(nr, nr);
        let store = 32usize.saturating_mul(n).saturating_mul(nr) <= store_limit_bytes;
        let mut stored = store.then(|| Stored {
            zn: Mat::zeros(n, nr),
            zt: Mat::zeros(n, nr),
            yn: Mat::zeros(0, 0),
            yt: Mat::zeros(0, 0),
        });
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
            let rows = pn_rows(x.as_ref());
            wfull
                .as_mut()
                .subcols_mut(c0, b)
                .copy_from(rows.as_ref().subcols(0, b));
            wt.as_mut()
                .subcols_mut(c0, b)
                .copy_from(rows.as_ref().subcols(b, b));
            c0 += b;
        }
        if let Some(st) = stored.as_mut() {
            // second-order residual terms K^-1 M K^-1 (Pn^T | Pt^T)
            for (z, y) in [(&st.zn, &mut st.yn), (&st.zt, &mut st.yt)] {
                *y = crate::reduction::sparse_times(m, z.as_ref());
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
            phi,
            omega2: modes.omega2.clone(),
            factor,
            stored,
            m: SparseMat::new(
                m.symbolic()
                    .to_owned()
                    .map_err(|e| Error::Invalid(format!("copy of M: {e:?}")))?,
                m.val().to_vec(),
            ),
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

    /// The synthesized modes of the contact set `active` (region indices) at `mu`.
    pub fn synthesize(&self, active: &[usize], mu: f64) -> Result<Synthesized> {
        if !mu.is_finite() {
            return Err(Error::param("mu", format!("must be finite, got {mu}")));
        }
        if let Some(&i) = active.iter().find(|&&i| i >= self.pairs.len()) {
            return Err(Error::Invalid(format!(
                "free-interface synthesis: pair index {i} beyond the {} candidates",
                self.pairs.len()
            )));
        }
        let na = active.len();
        let nm = self.modes();
        let p = Mat::from_fn(na, nm, |i, c| self.pn_phi[(active[i], c)]);
        let q = Mat::from_fn(na, nm, |i, c| {
            self.pn_phi[(active[i], c)] + mu * self.pt_phi[(active[i], c)]
        });
        let mut a = Mat::from_fn(nm, nm, |i, j| if i == j { self.omega2[i] } else { 0.0 });
        let mut x = Mat::<f64>::zeros(na, nm);
        if na > 0 {
            let s = Mat::from_fn(na, na, |i, j| {
                self.wn[(active[i], active[j])] + mu * self.wt[(active[i], active[j])]
            });
            let lu = s.partial_piv_lu();
            let u = lu.U();
            let (mut pmin, mut pmax) = (f64::INFINITY, 0.0f64);
            for i in 0..na {
                pmin = pmin.min(u[(i, i)].abs());
                pmax = pmax.max(u[(i, i)].abs());
            }
            if pmin.is_nan() || pmin <= 1e-13 * pmax {
                return Err(Error::Factorization {
                    what: format!("residual contact flexibility S ({na} pairs)"),
                    reason: format!(
                        "numerically singular (pivot ratio {:.2e}): a pair repeated, or \
                         the free-interface modes span the contact motions exactly",
                        pmin / pmax
                    ),
                });
            }
            x = faer::linalg::solvers::Solve::solve(&lu, &p);
            matmul(
                a.as_mut(),
                Accum::Add,
                q.transpose(),
                x.as_ref(),
                1.0,
                par(),
            );
        }
        let eig = faer::linalg::solvers::Eigen::new_from_real(a.as_ref()).map_err(|e| {
            Error::NotConverged {
                method: "free-interface synthesis (dense eigen)".into(),
                iterations: 0,
                detail: format!("{e:?}"),
            }
        })?;
        let s: Vec<c64> = (0..nm).map(|k| eig.S()[k]).collect();
        let eta = eig.U().to_owned();
        let mut r = Mat::<c64>::zeros(na, nm);
        for k in 0..nm {
            for i in 0..na {
                let mut acc = c64::new(0.0, 0.0);
                for c in 0..nm {
                    acc += eta[(c, k)] * x[(i, c)];
                }
                r[(i, k)] = -acc;
            }
        }
        Ok(Synthesized {
            s,
            eta,
            r,
            active: active.to_vec(),
            mu,
        })
    }

    /// The unconstrained displacements `u = Phi (eta - Omega^-2 Q^T r) + K^-1 B_A^T r` of the
    /// synthesized modes `which` (`n x which.len()`).
    pub fn expand(&self, syn: &Synthesized, which: &[usize]) -> Mat<c64> {
        let (u, _) = self.combine(syn, which, false, None);
        self.complex(&u, which.len())
    }

    /// [`FreeInterface::expand`] and [`FreeInterface::correction`] together: when the
    /// static responses are solved (not stored), the correction reuses the expansion's
    /// `K^-1 B_A^T r` (one block solve fewer).
    pub fn expand_with_correction(
        &self,
        syn: &Synthesized,
        which: &[usize],
    ) -> Result<(Mat<c64>, Mat<c64>)> {
        let (u, z) = self.combine(syn, which, false, None);
        let w = self.correction_from(syn, which, z.as_ref())?;
        Ok((self.complex(&u, which.len()), w))
    }

    /// Real and imaginary parts side by side (`n x 2k`) to complex columns (`n x k`).
    fn complex(&self, u: &Mat<f64>, k: usize) -> Mat<c64> {
        Mat::from_fn(self.dofs(), k, |i, c| c64::new(u[(i, c)], u[(i, k + c)]))
    }

    /// `Phi e + (Y_n + mu Y_t) r` for the modes `which`, real and imaginary parts side by
    /// side (`n x 2 which.len()`): with `second = false`, `e = eta - Omega^-2 Q^T r` and
    /// `Y = K^-1 (Pn^T | Pt^T)` (the expansion); with `second = true`, `e = -Omega^-4 Q^T r`
    /// and `Y = K^-1 M K^-1 (Pn^T | Pt^T)` (the second-order residual term). When the
    /// responses are solved, the first-order call also returns `K^-1 B^T r` and the
    /// second-order one takes it back as `reuse`.
    fn combine(
        &self,
        syn: &Synthesized,
        which: &[usize],
        second: bool,
        reuse: Option<&Mat<f64>>,
    ) -> (Mat<f64>, Option<Mat<f64>>) {
        let nm = self.modes();
        let k = which.len();
        let mu = syn.mu;
        let mut coef = Mat::<f64>::zeros(nm, 2 * k);
        let mut rfull = Mat::<f64>::zeros(self.pairs(), 2 * k);
        for (c, &w) in which.iter().enumerate() {
            for (row, &i) in syn.active.iter().enumerate() {
                let rv = syn.r[(row, w)];
                rfull[(i, c)] = rv.re;
                rfull[(i, k + c)] = rv.im;
            }
            for j in 0..nm {
                let mut qtr = c64::new(0.0, 0.0);
                for (row, &i) in syn.active.iter().enumerate() {
                    qtr += syn.r[(row, w)] * (self.pn_phi[(i, j)] + mu * self.pt_phi[(i, j)]);
                }
                let e = if second {
                    qtr * (-1.0 / (self.omega2[j] * self.omega2[j]))
                } else {
                    syn.eta[(j, w)] - qtr * (1.0 / self.omega2[j])
                };
                coef[(j, c)] = e.re;
                coef[(j, k + c)] = e.im;
            }
        }
        // K^-1 B^T r, or K^-1 M K^-1 B^T r
        let mut first = None;
        let mut u = match &self.stored {
            Some(st) => {
                let (yn, yt) = if second {
                    (&st.yn, &st.yt)
                } else {
                    (&st.zn, &st.zt)
                };
                let mut u = Mat::<f64>::zeros(self.dofs(), 2 * k);
                matmul(
                    u.as_mut(),
                    Accum::Replace,
                    yn.as_ref(),
                    rfull.as_ref(),
                    1.0,
                    par(),
                );
                if mu != 0.0 {
                    matmul(
                        u.as_mut(),
                        Accum::Add,
                        yt.as_ref(),
                        rfull.as_ref(),
                        mu,
                        par(),
                    );
                }
                u
            }
            None => {
                let z = match reuse {
                    Some(z) => z.clone(),
                    None => self.static_response(rfull.as_ref(), mu),
                };
                if second {
                    let mut u = crate::reduction::sparse_times(self.m.as_ref(), z.as_ref());
                    self.factor.solve_in_place(u.as_mut());
                    u
                } else {
                    first = Some(z.clone());
                    z
                }
            }
        };
        matmul(
            u.as_mut(),
            Accum::Add,
            self.phi.as_ref(),
            coef.as_ref(),
            1.0,
            par(),
        );
        (u, first)
    }

    /// `K^-1 (Pn^T + mu Pt^T) r` for the pair loads `r` (`nR x c`, N): `n x c` (m).
    fn static_response(&self, r: MatRef<'_, f64>, mu: f64) -> Mat<f64> {
        let mut x = Mat::<f64>::zeros(self.dofs(), r.ncols());
        for (i, p) in self.pairs.iter().enumerate() {
            for c in 0..r.ncols() {
                let v = r[(i, c)];
                if v != 0.0 {
                    add_pair_load(&mut x, p, c, v, mu * v);
                }
            }
        }
        if r.ncols() > 0 {
            self.factor.solve_in_place(x.as_mut());
        }
        x
    }

    /// The second-order residual directions of the synthesized modes `which`:
    /// `w = G2 B_A^T r`, `G2 = K^-1 M K^-1 - Phi Omega^-4 Phi^T` (the first term the static
    /// residual flexibility leaves out, `R(lambda) = G - lambda^2 G2 + ...`), made to satisfy
    /// the ties by the static correction `w - K^-1 Pn_A^T (Pn_A K^-1 Pn_A^T)^-1 Pn_A w`
    /// (`n x which.len()`). Added to the expanded modes they let the Ritz step recover most
    /// of the residual inertia.
    pub fn correction(&self, syn: &Synthesized, which: &[usize]) -> Result<Mat<c64>> {
        self.correction_from(syn, which, None)
    }

    /// [`FreeInterface::correction`], reusing the expansion's `K^-1 B_A^T r` if given.
    fn correction_from(
        &self,
        syn: &Synthesized,
        which: &[usize],
        reuse: Option<&Mat<f64>>,
    ) -> Result<Mat<c64>> {
        let n = self.dofs();
        let nr = self.pairs();
        let na = syn.active.len();
        let k = which.len();
        let (mut w, _) = self.combine(syn, which, true, reuse);
        if na > 0 {
            // static correction onto the ties: c = W_AA^-1 Pn_A w, w -= K^-1 Pn_A^T c
            let waa = Mat::from_fn(na, na, |i, j| self.wfull[(syn.active[i], syn.active[j])]);
            let gaps = Mat::from_fn(na, 2 * k, |i, c| {
                let p = &self.pairs[syn.active[i]];
                w[(p.pin[2], c)] - w[(p.disc[2], c)]
            });
            let lu = waa.partial_piv_lu();
            let cfix = faer::linalg::solvers::Solve::solve(&lu, &gaps);
            if !(0..2 * k).all(|c| (0..na).all(|i| cfix[(i, c)].is_finite())) {
                return Err(Error::Factorization {
                    what: format!("static contact flexibility ({na} pairs)"),
                    reason: "singular: a pair repeated".into(),
                });
            }
            let mut cf = Mat::<f64>::zeros(nr, 2 * k);
            for (row, &i) in syn.active.iter().enumerate() {
                for c in 0..2 * k {
                    cf[(i, c)] = cfix[(row, c)];
                }
            }
            match &self.stored {
                Some(st) => matmul(
                    w.as_mut(),
                    Accum::Add,
                    st.zn.as_ref(),
                    cf.as_ref(),
                    -1.0,
                    par(),
                ),
                None => w -= &self.static_response(cf.as_ref(), 0.0),
            }
        }
        Ok(Mat::from_fn(n, k, |i, c| {
            c64::new(w[(i, c)], w[(i, k + c)])
        }))
    }
}

#[cfg(test)]
mod tests;
