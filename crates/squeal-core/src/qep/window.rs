//! One window of the band driver: the operator of its shift (companion, squared or
//! low-rank) and the Krylov runs that cover the window, growing `nev` or splitting it.

use super::band::{LowRankCtx, QepBandOptions};
use super::residual::{backward_error_with, QepNorms};
use super::ComplexKernel;
use crate::eigen::EigenParams;
use crate::lowrank::{SymmetricShift, Woodbury};
use crate::operator::{Qep, SolveInfo, StopReason};
use crate::spectral::{QepShiftInvert, QepSymbolic, SpectralTransform, SquaredShift};
use crate::{c64, Error, Result};
use std::sync::Arc;

/// The spectral transformation of one window of the band driver: the companion form
/// (complex) or the squared one (real; its points are `s = -lambda^2`).
enum WindowOp<'a> {
    Companion(QepShiftInvert<'a>),
    Squared(SquaredShift<'a>),
}

impl WindowOp<'_> {
    fn transform(&self) -> &dyn SpectralTransform<c64> {
        match self {
            WindowOp::Companion(op) => op,
            WindowOp::Squared(op) => op,
        }
    }

    fn squared(&self) -> bool {
        matches!(self, WindowOp::Squared(_))
    }

    /// The kernel's `nev` eigenvalues of largest modulus: the real iteration of the
    /// kernel on the squared transformation, the complex one on the companion form.
    fn largest(
        &self,
        kernel: &dyn ComplexKernel,
        nev: usize,
        tol: f64,
        max_restarts: usize,
    ) -> Result<super::ComplexKernelOutput> {
        match self {
            WindowOp::Companion(op) => kernel.largest(op, nev, tol, max_restarts),
            WindowOp::Squared(op) => kernel.largest_real(op, nev, tol, max_restarts),
        }
    }

    /// (point in the plane of the window, lambda).
    fn map(&self, theta: c64) -> (c64, c64) {
        let point = self.transform().pencil_eigenvalue(theta);
        if self.squared() {
            (point, SquaredShift::lambda_of_s(point))
        } else {
            (point, point)
        }
    }
}

/// State of one band solve: what is fixed and what has been collected so far.
pub(super) struct BandRun<'a> {
    pub(super) kernel: &'a dyn ComplexKernel,
    pub(super) qep: &'a Qep,
    pub(super) params: &'a EigenParams,
    pub(super) options: &'a QepBandOptions,
    /// Symbolic LU analysis given by the caller (companion path only).
    pub(super) sym: Option<&'a QepSymbolic>,
    /// Symbolic LU analysis built on first use by the companion path.
    pub(super) sym_owned: Option<QepSymbolic>,
    pub(super) low_rank: Option<LowRankCtx<'a>>,
    pub(super) cap: usize,
    pub(super) norms: QepNorms,
    pub(super) info: SolveInfo,
    pub(super) lambda: Vec<c64>,
    pub(super) vectors: Vec<Vec<c64>>,
}

impl<'a> BandRun<'a> {
    /// The symbolic analysis of the companion path (built on first use).
    fn symbolic(&mut self) -> Result<&QepSymbolic> {
        if let Some(s) = self.sym {
            return Ok(s);
        }
        if self.sym_owned.is_none() {
            self.sym_owned = Some(QepSymbolic::new(self.qep)?);
        }
        Ok(self.sym_owned.as_ref().expect("built above"))
    }

    /// The operator of a squared window at `sigma_s`: low-rank when chosen, else LU.
    fn squared_op(&mut self, sigma: f64, first: bool) -> Result<WindowOp<'a>> {
        let qep: &'a Qep = self.qep;
        let Some(ctx) = &self.low_rank else {
            if first {
                self.info.notes.push(
                    "C = 0: real shift-invert of K - s M, s = -lambda^2 (squared \
                     transformation, real Krylov iteration where the kernel has one), \
                     sparse LU of K~ - s M~"
                        .into(),
                );
            }
            return Ok(WindowOp::Squared(SquaredShift::lu(qep, sigma)?));
        };
        let shift = SymmetricShift::new(ctx.op, ctx.pencil.clone(), &ctx.friction, sigma)?;
        let (t_numeric, t_z) = shift.times();
        let woodbury = Woodbury::new(qep, Arc::new(shift), ctx.mu)?;
        if first {
            self.info.notes.push(format!(
                "C = 0: real shift-invert of K - s M, s = -lambda^2 (squared \
                 transformation, real Krylov iteration where the kernel has one), low-rank path: symmetric LBL^T of K_c - s M_c \
                 (nnz(L) = {} stored entries, symbolic {:.2} s, numeric {:.2} s) + \
                 Woodbury correction of rank nA = {} (Z = S^-1 U {:.2} s, U W^T error {:.1e}, asymmetry {:.1e}, \
                 S residual {:.1e}, A residual {:.1e}{})",
                ctx.pencil.factor_entries(),
                ctx.t_symbolic,
                t_numeric,
                ctx.friction.rank(),
                t_z,
                ctx.friction.identity_error,
                ctx.pencil.asymmetry(),
                woodbury.shift().s_residual(),
                woodbury.probe_residual(),
                if woodbury.refines() {
                    ", one refinement step per solve"
                } else {
                    ""
                }
            ));
        }
        Ok(WindowOp::Squared(SquaredShift::woodbury(qep, woodbury)?))
    }

    /// Covers `[lo, hi]` Hz with one shift, or splits it.
    pub(super) fn window(&mut self, lo: f64, hi: f64, depth: usize, nev0: usize) -> Result<()> {
        let n = self.qep.dim();
        let two_pi = 2.0 * std::f64::consts::PI;
        let squared = self.options.squared_when_undamped && self.qep.c.is_none();
        let first = self.info.factorizations == 0;
        let (sigma, radius, op) = if squared {
            // the window in the plane of s = -lambda^2 = omega^2
            let (a, b) = ((two_pi * lo).powi(2), (two_pi * hi).powi(2));
            let sigma = 0.5 * (a + b);
            let radius = self.options.radius_factor * 0.5 * (b - a)
                + self.options.margin_rel * (two_pi * hi).powi(2);
            let op = self.squared_op(sigma, first)?;
            (c64::new(sigma, 0.0), radius, op)
        } else {
            let sigma = c64::new(0.0, two_pi * 0.5 * (lo + hi));
            let half = two_pi * 0.5 * (hi - lo);
            let radius = self.options.radius_factor * half + self.options.margin_rel * two_pi * hi;
            let qep: &'a Qep = self.qep;
            let op = QepShiftInvert::with_symbolic(qep, sigma, self.symbolic()?)?;
            (sigma, radius, WindowOp::Companion(op))
        };
        let dim = op.transform().dim();
        self.info.factorizations += 1;
        let mut nev = nev0.clamp(1, self.cap);
        let outcome = loop {
            let out = op.largest(self.kernel, nev, self.params.tol, self.params.max_restarts)?;
            if out.vectors.nrows() != dim || out.vectors.ncols() < out.theta.len() {
                return Err(Error::Dimension {
                    context: format!(
                        "complex kernel returned {} x {} vectors for {} eigenvalues",
                        out.vectors.nrows(),
                        out.vectors.ncols(),
                        out.theta.len()
                    ),
                    expected: dim,
                    got: out.vectors.nrows(),
                });
            }
            self.info.iterations += out.iterations;
            self.info.requested = nev;
            self.info.converged = out.theta.len();
            let mapped: Vec<(c64, c64)> = out.theta.iter().map(|&t| op.map(t)).collect();
            let reach = mapped
                .iter()
                .map(|p| p.0)
                .filter(|l| l.re.is_finite() && l.im.is_finite())
                .map(|l| (l - sigma).norm())
                .fold(0.0, f64::max);
            let lam: Vec<c64> = mapped.iter().map(|p| p.1).collect();
            if !out.all_converged {
                self.info.reason = StopReason::MaxIterations;
                self.info.notes.push(format!(
                    "window [{lo:.6e}, {hi:.6e}] Hz: only {} of {nev} pairs converged",
                    out.theta.len()
                ));
                break Some((out, lam));
            }
            if reach > radius {
                break Some((out, lam));
            }
            if nev >= self.cap {
                if depth < self.options.max_depth {
                    self.info.notes.push(format!(
                        "window [{lo:.6e}, {hi:.6e}] Hz: {nev} pairs reach only \
                         |lambda - sigma| = {reach:.4e} < R = {radius:.4e}; split in two"
                    ));
                    break None;
                }
                self.info.reason = StopReason::MaxIterations;
                self.info.notes.push(format!(
                    "window [{lo:.6e}, {hi:.6e}] Hz not covered: {nev} pairs reach only \
                     |lambda - sigma| = {reach:.4e} < R = {radius:.4e} at the split depth limit"
                ));
                break Some((out, lam));
            }
            let grown = (2 * nev).min(self.cap);
            self.info.notes.push(format!(
                "window [{lo:.6e}, {hi:.6e}] Hz: {nev} pairs all inside R; retried with {grown}"
            ));
            nev = grown;
        };
        self.info.op_applications += op.transform().applications();
        drop(op);
        let Some((out, lam)) = outcome else {
            let mid = 0.5 * (lo + hi);
            let next = (nev / 2).max(nev0).min(self.cap);
            self.window(lo, mid, depth + 1, next)?;
            return self.window(mid, hi, depth + 1, next);
        };
        // Keep this window's sub-band, merge copies found by earlier windows.
        let before = self.lambda.len();
        let mut matched = vec![false; before];
        let slack = 1e-8 * hi;
        for (k, &l) in lam.iter().enumerate() {
            if !(l.re.is_finite() && l.im.is_finite()) || l.im <= 0.0 {
                continue;
            }
            let f = l.im / two_pi;
            if f < lo - slack || f > hi + slack {
                continue;
            }
            let tol = (1e-8 * l.norm()).max(100.0 * self.params.tol * l.norm());
            if let Some(p) =
                (0..before).find(|&p| !matched[p] && (self.lambda[p] - l).norm() <= tol)
            {
                matched[p] = true;
                continue;
            }
            // The companion eigenvector is z = [u; lambda u]: both blocks approximate u.
            // The first is the documented choice; the second (divided by lambda) is kept
            // when its backward error is smaller (its error is not amplified by |lambda|).
            let u1: Vec<c64> = (0..n).map(|r| out.vectors[(r, k)]).collect();
            if squared {
                self.lambda.push(l);
                self.vectors.push(u1);
                continue;
            }
            let u2: Vec<c64> = (0..n).map(|r| out.vectors[(n + r, k)] / l).collect();
            let (e1, e2) = (
                backward_error_with(self.qep, &self.norms, l, &u1),
                backward_error_with(self.qep, &self.norms, l, &u2),
            );
            self.lambda.push(l);
            self.vectors.push(if e2 < e1 { u2 } else { u1 });
        }
        if self.lambda.len() > self.params.max_modes {
            return Err(crate::eigen::too_many_modes(self.params));
        }
        Ok(())
    }
}
