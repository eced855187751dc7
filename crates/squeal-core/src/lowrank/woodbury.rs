//! The Woodbury solve of an undamped frictional QEP's shifted matrix ([`Woodbury`]):
//! `A(s)^-1 b = S^-1 b + mu Z G^-1 W^T S^-1 b` on a [`SymmetricShift`].

use super::SymmetricShift;
use crate::linalg::norm1;
use crate::operator::Qep;
use crate::{Error, Result};
use faer::linalg::matmul::matmul;
use faer::linalg::solvers::{PartialPivLu, Solve};
use faer::{Accum, Mat, MatMut};
use std::sync::Arc;

/// Relative residual of a probe solve above which [`Woodbury`] adds one step of
/// iterative refinement to every application.
pub const REFINE_ABOVE: f64 = 1e-11;

/// Solves with `A(s) = K~ - s M~` of an undamped frictional QEP through its low-rank
/// structure: the Woodbury identity on a [`SymmetricShift`] (see the module docs). The
/// squared transformation ([`SquaredShift::low_rank`](crate::spectral::SquaredShift::low_rank))
/// applies it.
pub struct Woodbury<'a> {
    qep: &'a Qep,
    shift: Arc<SymmetricShift>,
    mu: f64,
    g: PartialPivLu<f64>,
    refine: bool,
    residual: f64,
}

impl<'a> Woodbury<'a> {
    /// Builds the solver for `qep = op.at(mu)` (undamped) on a factorized shift: forms
    /// and factorizes `G = I - mu W^T Z`, then checks one solve with `A(s)`; when its
    /// relative residual exceeds [`REFINE_ABOVE`], every application adds one step of
    /// iterative refinement.
    pub fn new(qep: &'a Qep, shift: Arc<SymmetricShift>, mu: f64) -> Result<Self> {
        let n = qep.dim();
        if qep.c.is_some() {
            return Err(Error::Invalid(
                "the squared spectral transformation needs C = 0".into(),
            ));
        }
        if shift.dim() != n {
            return Err(Error::Dimension {
                context: "Woodbury: shift factorization of another size".into(),
                expected: n,
                got: shift.dim(),
            });
        }
        let na = shift.z.ncols();
        // G = I - mu W^T Z
        let w = shift.w.as_ref();
        let mut gm = Mat::<f64>::identity(na, na);
        for p in 0..na {
            for (r, v) in w.row_idx_of_col(p).zip(w.val_of_col(p)) {
                let zr = shift.z.row(r);
                for q in 0..na {
                    gm[(p, q)] -= mu * v * zr[q];
                }
            }
        }
        let g = gm.partial_piv_lu();
        let s_shift = shift.s;
        let what = move || {
            format!("Woodbury capacitance I - mu W^T Z (nA = {na}, mu = {mu}, s = {s_shift:.6e})")
        };
        if na > 0 {
            let u = g.U();
            let (mut pmin, mut pmax) = (f64::INFINITY, 0.0f64);
            for i in 0..na {
                pmin = pmin.min(u[(i, i)].abs());
                pmax = pmax.max(u[(i, i)].abs());
            }
            if pmin.is_nan() || pmin <= 1e-14 * pmax {
                return Err(Error::Factorization {
                    what: what(),
                    reason: "numerically singular (is the shift an eigenvalue?)".into(),
                });
            }
        }
        let mut this = Self {
            qep,
            shift,
            mu,
            g,
            refine: false,
            residual: 0.0,
        };
        let b = Mat::<f64>::from_fn(n, 1, |i, _| 1.0 + 0.1 * (i as f64).sin());
        let mut x = b.clone();
        this.solve_in_place(x.as_mut());
        if (0..n).any(|i| !x[(i, 0)].is_finite()) {
            return Err(Error::Factorization {
                what: what(),
                reason: "non-finite solve (is the shift an eigenvalue?)".into(),
            });
        }
        this.residual = this.relative_residual(b.as_ref(), x.as_ref());
        if this.residual > REFINE_ABOVE {
            this.refine = true;
            let mut x = b.clone();
            this.solve_in_place(x.as_mut());
            this.residual = this.relative_residual(b.as_ref(), x.as_ref());
        }
        Ok(this)
    }

    /// The shift data (shareable across `mu`).
    pub fn shift(&self) -> &Arc<SymmetricShift> {
        &self.shift
    }

    /// Relative residual `||b - A x|| / ((||K~||_1 + |s| ||M~||_1) ||x||)` of the probe
    /// solve (after refinement when it is on).
    pub fn probe_residual(&self) -> f64 {
        self.residual
    }

    /// Whether applications add a step of iterative refinement.
    pub fn refines(&self) -> bool {
        self.refine
    }

    /// `B <- A(s)^-1 B` by Woodbury (plus refinement when [`refines`](Self::refines)).
    pub fn solve_in_place(&self, mut b: MatMut<'_, f64>) {
        if !self.refine {
            self.woodbury_in_place(b);
            return;
        }
        let rhs = b.to_owned();
        self.woodbury_in_place(b.as_mut());
        let mut r = self.residual_block(rhs.as_ref(), b.as_ref());
        self.woodbury_in_place(r.as_mut());
        for j in 0..b.ncols() {
            for i in 0..b.nrows() {
                b[(i, j)] += r[(i, j)];
            }
        }
    }

    fn woodbury_in_place(&self, mut b: MatMut<'_, f64>) {
        let sh = &*self.shift;
        sh.solve_in_place(b.as_mut());
        let na = sh.z.ncols();
        if na == 0 || self.mu == 0.0 {
            return;
        }
        let k = b.ncols();
        let w = sh.w.as_ref();
        let mut t = Mat::<f64>::zeros(na, k);
        for p in 0..na {
            for (r, v) in w.row_idx_of_col(p).zip(w.val_of_col(p)) {
                for c in 0..k {
                    t[(p, c)] += v * b[(r, c)];
                }
            }
        }
        self.g.solve_in_place(t.as_mut());
        matmul(b, Accum::Add, sh.z.as_ref(), t.as_ref(), self.mu, sh.par);
    }

    /// `B - A X` with `A = K~ - s M~`.
    fn residual_block(&self, b: faer::MatRef<'_, f64>, x: faer::MatRef<'_, f64>) -> Mat<f64> {
        let s = self.shift.s;
        let mut r = b.to_owned();
        for (a, scale) in [(self.qep.k.as_ref(), -1.0), (self.qep.m.as_ref(), s)] {
            for j in 0..a.ncols() {
                for (i, v) in a.row_idx_of_col(j).zip(a.val_of_col(j)) {
                    for c in 0..x.ncols() {
                        r[(i, c)] += scale * v * x[(j, c)];
                    }
                }
            }
        }
        r
    }

    fn relative_residual(&self, b: faer::MatRef<'_, f64>, x: faer::MatRef<'_, f64>) -> f64 {
        let r = self.residual_block(b, x);
        let scale = (norm1(self.qep.k.as_ref()) + self.shift.s.abs() * norm1(self.qep.m.as_ref()))
            * x.norm_l2();
        if scale > 0.0 {
            r.norm_l2() / scale
        } else {
            0.0
        }
    }
}
