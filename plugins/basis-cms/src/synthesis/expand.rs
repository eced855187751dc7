//! Expansion of synthesized modes to the unconstrained DOFs ([`FreeInterface::expand`])
//! and their second-order residual correction ([`FreeInterface::correction`]).

use super::{add_pair_load, par, FreeInterface, Synthesized};
use squeal_core::faer::linalg::matmul::matmul;
use squeal_core::faer::{Accum, Mat, MatRef};
use squeal_core::{c64, Error, Result};

impl FreeInterface {
    /// The unconstrained displacements `u = Phi (eta - Omega^-2 Q^T r) + K^-1 B_A^T r` of the
    /// synthesized modes `which` (`n x which.len()`).
    pub fn expand(&self, syn: &Synthesized, which: &[usize]) -> Mat<c64> {
        self.complex(&self.expand_parts(syn, which), which.len())
    }

    /// [`FreeInterface::expand`] as real and imaginary parts side by side (`n x 2
    /// which.len()`: column `c` real, `which.len() + c` imaginary).
    pub fn expand_parts(&self, syn: &Synthesized, which: &[usize]) -> Mat<f64> {
        self.combine(syn, which, false, None).0
    }

    /// [`FreeInterface::expand`] and [`FreeInterface::correction`] together: when the
    /// second-order terms are solved (not stored), the correction reuses the expansion's
    /// `K^-1 B_A^T r` (one block solve or product fewer).
    pub fn expand_with_correction(
        &self,
        syn: &Synthesized,
        which: &[usize],
    ) -> Result<(Mat<c64>, Mat<c64>)> {
        let (u, w) = self.expand_parts_with_correction(syn, which)?;
        let k = which.len();
        Ok((self.complex(&u, k), self.complex(&w, k)))
    }

    /// [`FreeInterface::expand_with_correction`] as real and imaginary parts side by side
    /// ([`FreeInterface::expand_parts`]): no complex copies, for a caller that wants the
    /// parts (the basis's columns).
    pub fn expand_parts_with_correction(
        &self,
        syn: &Synthesized,
        which: &[usize],
    ) -> Result<(Mat<f64>, Mat<f64>)> {
        let (u, z) = self.combine(syn, which, false, None);
        let w = self.correction_parts(syn, which, z.as_ref())?;
        Ok((u, w))
    }

    /// Real and imaginary parts side by side (`n x 2k`) to complex columns (`n x k`).
    fn complex(&self, u: &Mat<f64>, k: usize) -> Mat<c64> {
        Mat::from_fn(self.dofs(), k, |i, c| c64::new(u[(i, c)], u[(i, k + c)]))
    }

    /// The modal coefficients `e` and the pair loads `r` (region rows) of [`Self::combine`]
    /// for the modes `which`, restricted to the columns that have a nonzero entry in
    /// either (real and imaginary parts side by side), and those columns' indices.
    fn coefficients(
        &self,
        syn: &Synthesized,
        which: &[usize],
        second: bool,
    ) -> (Mat<f64>, Mat<f64>, Vec<usize>) {
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
        // only the columns with a nonzero coefficient are formed: a synthesized mode at a
        // real root `s` (most of them: the undamped synthesis is real) has zero imaginary
        // parts, so half of the products and solves would be on zeros
        let live: Vec<usize> = (0..2 * k)
            .filter(|&c| {
                (0..nm).any(|j| coef[(j, c)] != 0.0)
                    || (0..self.pairs()).any(|i| rfull[(i, c)] != 0.0)
            })
            .collect();
        (
            select(coef.as_ref(), &live),
            select(rfull.as_ref(), &live),
            live,
        )
    }

    /// `Phi e + (Y_n + mu Y_t) r` for the modes `which`, real and imaginary parts side by
    /// side (`n x 2 which.len()`): with `second = false`, `e = eta - Omega^-2 Q^T r` and
    /// `Y = K^-1 (Pn^T | Pt^T)` (the expansion); with `second = true`, `e = -Omega^-4 Q^T r`
    /// and `Y = K^-1 M K^-1 (Pn^T | Pt^T)` (the second-order residual term). When the
    /// second-order terms are solved, the first-order call also returns `K^-1 B^T r` and the
    /// second-order one takes it back as `reuse`.
    fn combine(
        &self,
        syn: &Synthesized,
        which: &[usize],
        second: bool,
        reuse: Option<&Mat<f64>>,
    ) -> (Mat<f64>, Option<Mat<f64>>) {
        let k = which.len();
        let mu = syn.mu;
        let (coef, rfull, live) = self.coefficients(syn, which, second);
        // K^-1 B^T r, or K^-1 M K^-1 B^T r
        let mut first = None;
        let mut u = match self
            .stored
            .as_ref()
            .filter(|st| !second || st.second_order())
        {
            Some(st) => {
                let (yn, yt) = if second {
                    (&st.yn, &st.yt)
                } else {
                    (&st.zn, &st.zt)
                };
                let u = combined(yn, yt, rfull.as_ref(), mu);
                if !second && !st.second_order() {
                    // the second-order term will be solved from it
                    first = Some(u.clone());
                }
                u
            }
            None => {
                let z = match reuse {
                    Some(z) => select(z.as_ref(), &live),
                    None => self.static_response(rfull.as_ref(), mu),
                };
                if second {
                    let mut u =
                        squeal_core::linalg::symmetric_times(self.m.as_ref().as_ref(), z.as_ref());
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
            self.phi.as_ref().as_ref(),
            coef.as_ref(),
            1.0,
            par(),
        );
        let width = 2 * k;
        (
            scatter(u, &live, width),
            first.map(|f| scatter(f, &live, width)),
        )
    }

    /// `K^-1 (Pn^T + mu Pt^T) r` for the pair loads `r` (`nR x c`, N): `n x c` (m), from
    /// the stored responses when there are, else by a block solve; the zero columns of
    /// `r` are left out of the products and solves.
    fn static_response(&self, r: MatRef<'_, f64>, mu: f64) -> Mat<f64> {
        let live = live_columns(r);
        if live.len() < r.ncols() {
            let x = self.static_response(select(r, &live).as_ref(), mu);
            return scatter(x, &live, r.ncols());
        }
        if let Some(st) = &self.stored {
            return combined(&st.zn, &st.zt, r, mu);
        }
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
        let w = self.correction_parts(syn, which, None)?;
        Ok(self.complex(&w, which.len()))
    }

    /// [`FreeInterface::correction`] as real and imaginary parts side by side, reusing the
    /// expansion's `K^-1 B_A^T r` if given.
    fn correction_parts(
        &self,
        syn: &Synthesized,
        which: &[usize],
        reuse: Option<&Mat<f64>>,
    ) -> Result<Mat<f64>> {
        let nr = self.pairs();
        let na = syn.active.len();
        let k = which.len();
        // the gaps are kept only when the responses are not stored
        if let Some(gaps) = self.second_gaps.as_ref().filter(|_| na > 0) {
            return self.correction_merged(syn, which, reuse, gaps);
        }
        let (mut w, _) = self.combine(syn, which, true, reuse);
        if na > 0 {
            // static correction onto the ties: c = W_AA^-1 Pn_A w, w -= K^-1 Pn_A^T c
            let gaps = Mat::from_fn(na, 2 * k, |i, c| {
                let p = &self.pairs[syn.active[i]];
                w[(p.pin[2], c)] - w[(p.disc[2], c)]
            });
            let cfix = self.tie_loads(&syn.active, gaps)?;
            let mut cf = Mat::<f64>::zeros(nr, 2 * k);
            for (row, &i) in syn.active.iter().enumerate() {
                for c in 0..2 * k {
                    cf[(i, c)] = cfix[(row, c)];
                }
            }
            w -= &self.static_response(cf.as_ref(), 0.0);
        }
        Ok(w)
    }

    /// The normal loads `W_AA^-1 g` on the active pairs that cancel the gaps `g`
    /// (`nA x c`), `W_AA` the static contact flexibility of the active pairs (symmetric
    /// positive definite: Cholesky, an error when it is not).
    fn tie_loads(&self, active: &[usize], gaps: Mat<f64>) -> Result<Mat<f64>> {
        use squeal_core::faer::linalg::solvers::Solve;
        let na = active.len();
        let singular = || Error::Factorization {
            what: format!("static contact flexibility ({na} pairs)"),
            reason: "not positive definite: a pair repeated".into(),
        };
        let waa = Mat::from_fn(na, na, |i, j| self.wfull[(active[i], active[j])]);
        let cfix = waa
            .llt(squeal_core::faer::Side::Lower)
            .map_err(|_| singular())?
            .solve(&gaps);
        if !(0..cfix.ncols()).all(|c| (0..na).all(|i| cfix[(i, c)].is_finite())) {
            return Err(singular());
        }
        Ok(cfix)
    }

    /// [`Self::correction_parts`] when the responses are solved and the second-order gaps
    /// are kept: the tie loads come from the gaps `Pn_A (K^-1 M K^-1 B_A^T r + Phi e)`
    /// before any solve, so that `K^-1 (M K^-1 B_A^T r - Pn_A^T c) + Phi e` takes one block
    /// solve instead of two.
    fn correction_merged(
        &self,
        syn: &Synthesized,
        which: &[usize],
        reuse: Option<&Mat<f64>>,
        [hn, ht]: &[Mat<f64>; 2],
    ) -> Result<Mat<f64>> {
        let (coef, rfull, live) = self.coefficients(syn, which, true);
        let width = 2 * which.len();
        let (act, mu) = (&syn.active, syn.mu);
        let z = match reuse {
            Some(z) => select(z.as_ref(), &live),
            None => self.static_response(rfull.as_ref(), mu),
        };
        // Pn_A K^-1 M K^-1 B_A^T r + Pn_A Phi e, from the kept gaps
        let na = act.len();
        let h = Mat::from_fn(na, na, |i, j| {
            hn[(act[i], act[j])] + mu * ht[(act[i], act[j])]
        });
        let ra = Mat::from_fn(na, live.len(), |i, c| rfull[(act[i], c)]);
        let pa = Mat::from_fn(na, coef.nrows(), |i, j| self.pn_phi[(act[i], j)]);
        let mut gaps = Mat::<f64>::zeros(na, live.len());
        matmul(
            gaps.as_mut(),
            Accum::Replace,
            h.as_ref(),
            ra.as_ref(),
            1.0,
            par(),
        );
        matmul(
            gaps.as_mut(),
            Accum::Add,
            pa.as_ref(),
            coef.as_ref(),
            1.0,
            par(),
        );
        let cfix = self.tie_loads(act, gaps)?;
        let mut w = squeal_core::linalg::symmetric_times(self.m.as_ref().as_ref(), z.as_ref());
        for (row, &i) in act.iter().enumerate() {
            for c in 0..live.len() {
                add_pair_load(&mut w, &self.pairs[i], c, -cfix[(row, c)], 0.0);
            }
        }
        self.factor.solve_in_place(w.as_mut());
        matmul(
            w.as_mut(),
            Accum::Add,
            self.phi.as_ref().as_ref(),
            coef.as_ref(),
            1.0,
            par(),
        );
        Ok(scatter(w, &live, width))
    }
}

/// The columns of `x` with a nonzero entry.
fn live_columns(x: MatRef<'_, f64>) -> Vec<usize> {
    (0..x.ncols())
        .filter(|&c| x.col(c).iter().any(|&v| v != 0.0))
        .collect()
}

/// The columns `cols` of `x`.
fn select(x: MatRef<'_, f64>, cols: &[usize]) -> Mat<f64> {
    Mat::from_fn(x.nrows(), cols.len(), |i, j| x[(i, cols[j])])
}

/// `x` (one column per entry of `cols`) as the columns `cols` of a matrix of `width`
/// columns, the others zero.
fn scatter(x: Mat<f64>, cols: &[usize], width: usize) -> Mat<f64> {
    if cols.len() == width {
        return x;
    }
    let mut out = Mat::<f64>::zeros(x.nrows(), width);
    for (j, &c) in cols.iter().enumerate() {
        out.col_mut(c).copy_from(x.col(j));
    }
    out
}

/// `(Yn + mu Yt) r` from stored responses (`n x nR` each) and pair loads `r` (`nR x c`).
fn combined(yn: &Mat<f64>, yt: &Mat<f64>, r: MatRef<'_, f64>, mu: f64) -> Mat<f64> {
    let mut x = Mat::<f64>::zeros(yn.nrows(), r.ncols());
    matmul(x.as_mut(), Accum::Replace, yn.as_ref(), r, 1.0, par());
    if mu != 0.0 {
        matmul(x.as_mut(), Accum::Add, yt.as_ref(), r, mu, par());
    }
    x
}
