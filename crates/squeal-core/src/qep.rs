//! The non-symmetric quadratic eigenproblem (QEP) of the frictional operator and the
//! machinery every complex backend shares.
//!
//! `(lambda^2 M~ + lambda C~ + K~) u = 0` with `X~ = X_c - mu F_X` (see
//! [`FrictionalOperator`]). Convention
//! `U = u exp(lambda t)`: a mode is unstable iff `Re(lambda) > 0`; its frequency is
//! `Im(lambda) / 2 pi` and its divergence rate `DvR = Re(lambda) / Im(lambda)`. Results keep
//! the `Im(lambda) > 0` member of each conjugate pair.
//!
//! Full-order backends differ only in their Krylov iteration ([`ComplexKernel`]); the
//! shift-invert operator on the companion form ([`QepShiftInvert`]), the band driver
//! ([`solve_qep_band`]), the dense solver for small and reduced problems ([`dense_qep`]) and
//! the backward error ([`backward_error`]) are written once, here.
//! Undamped frictional operators may instead go through the low-rank (Woodbury) path of
//! [`crate::lowrank`] ([`solve_frictional_band`], [`QepBandOptions::low_rank`]).
//!
//! Backward error of a pair on the operator it was computed for:
//! `eta = ||Q(lambda) u|| / ((|lambda|^2 ||M~|| + |lambda| ||C~|| + ||K~||) ||u||)`
//! (1-norms of the matrices, 2-norm of the vectors).

use crate::contact::FrictionalOperator;
use crate::eigen::{validate_params, EigenParams, SolveInfo, StopReason};
use crate::linalg::{check_square_finite, norm1};
use crate::lowrank::{FrictionLowRank, QepLowRankSquared, SymmetricPencil, SymmetricShift};
use crate::{c64, Error, Result, SparseMat, SparseRef};
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Lu, SymbolicLu};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat, Triplet};
use faer::{Mat, MatMut, MatRef};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;
use std::time::Instant;

pub mod condition;
#[cfg(test)]
mod tests;

use condition::LeftSource;
pub use condition::{
    left_eigenvectors, Condition, LeftInfo, CLUSTER_REL, CONDITION_AUTO_MAX_DIM, DENSE_LEFT_MAX_DIM,
};

/// One quadratic eigenproblem `(lambda^2 M + lambda C + K) u = 0` (one mu, one contact set).
#[derive(Debug, Clone)]
pub struct Qep {
    /// Mass part `M~` (kg).
    pub m: SparseMat,
    /// Damping part `C~` (N s/m); `None` means zero.
    pub c: Option<SparseMat>,
    /// Stiffness part `K~` (N/m).
    pub k: SparseMat,
}

impl Qep {
    /// Size of the problem.
    pub fn dim(&self) -> usize {
        self.k.nrows()
    }
}

/// Complex modes of a QEP in a frequency band, sorted by frequency.
#[derive(Debug, Clone)]
pub struct ComplexModes {
    /// Eigenvalues `lambda` (1/s), the `Im > 0` member of each pair.
    pub lambda: Vec<c64>,
    /// Matching mode shapes on the operator's DOFs, one column per mode, unit 2-norm.
    pub vectors: Mat<c64>,
    /// Frequencies `Im(lambda) / 2 pi` (Hz).
    pub freq_hz: Vec<f64>,
    /// Divergence rates `Re(lambda) / Im(lambda)`.
    pub dvr: Vec<f64>,
    /// Backward error of each pair on the operator (see module docs).
    pub backward_error: Vec<f64>,
    /// Condition number of each eigenvalue,
    /// `||y|| ||x|| (|lambda|^2 ||M|| + |lambda| ||C|| + ||K||) / (|lambda| |y^H Q'(lambda) x|)`
    /// with the left eigenvector `y`; NaN where no left vector was computed (see
    /// [`Condition`] and the [`condition`] module for what it promises and where it fails).
    pub cond: Vec<f64>,
    /// First-order estimate of the relative forward error of each eigenvalue,
    /// `|lambda - lambda_exact| / |lambda| <~ cond * backward_error`; NaN where `cond` is.
    pub error_bound: Vec<f64>,
    /// The left eigenvectors behind `cond` (`y^H Q(lambda) = 0`), one column per mode,
    /// unit 2-norm except inside a cluster of (nearly) equal eigenvalues, where they are
    /// bi-orthogonalized against the right vectors; `None` when not computed.
    pub left_vectors: Option<Mat<c64>>,
    /// How the solve went.
    pub info: SolveInfo,
}

impl ComplexModes {
    /// Number of modes.
    pub fn len(&self) -> usize {
        self.lambda.len()
    }
    /// Whether no mode was found.
    pub fn is_empty(&self) -> bool {
        self.lambda.is_empty()
    }
    /// Whether mode `i` is unstable: its divergence rate `DvR = Re / Im` exceeds
    /// `dvr_tol` (the one threshold of every command, `--dvr-tol`).
    pub fn is_unstable(&self, i: usize, dvr_tol: f64) -> bool {
        self.dvr[i] > dvr_tol
    }
}

/// A complex linear operator `y = OP x` (a shift-invert operator, a test matrix...).
pub trait ComplexLinOp: Sync {
    /// Size of the operator.
    fn dim(&self) -> usize;
    /// `y = OP x`; `x` and `y` have length [`dim`](Self::dim).
    fn apply(&self, x: &[c64], y: &mut [c64]);
}

/// Output of a [`ComplexKernel`]: eigenpairs of largest modulus of the operator.
#[derive(Debug, Clone)]
pub struct ComplexKernelOutput {
    /// Converged operator eigenvalues `theta`, any order.
    pub theta: Vec<c64>,
    /// Matching eigenvectors (columns), any scaling.
    pub vectors: Mat<c64>,
    /// Restarts / iterations used.
    pub iterations: usize,
    /// Whether every requested pair converged.
    pub all_converged: bool,
}

/// A Krylov iteration for the `nev` eigenvalues of largest modulus of a general complex
/// operator (ARPACK `znaupd`, Krylov-Schur, ...).
pub trait ComplexKernel: Send + Sync {
    /// Computes the `nev` eigenpairs of largest `|theta|` to relative tolerance `tol`.
    fn largest(
        &self,
        op: &dyn ComplexLinOp,
        nev: usize,
        tol: f64,
        max_restarts: usize,
    ) -> Result<ComplexKernelOutput>;
}

/// Relative size of `Im(lambda)` below which a root counts as real (not an oscillating
/// mode): `|Im(lambda)| <= REAL_ROOT_REL |lambda|`. Such roots are dropped by
/// [`finish_modes`].
pub const REAL_ROOT_REL: f64 = 1e-10;

/// Roots of the scaled companion form (see [`dense_qep`]) with `|mu| <= RIGID_BODY_REL`,
/// i.e. `|lambda| <= RIGID_BODY_REL sqrt(||K|| / ||M||)`, are rigid-body roots: a zero
/// eigenvalue of a defective pencil is computed as `O(sqrt(eps))` (often a tiny
/// imaginary pair); [`dense_qep`] returns them as exact zeros.
pub const RIGID_BODY_REL: f64 = 1e-6;

/// Checks that `M`, `C` and `K` are square of the same size with finite entries.
pub fn check_qep(qep: &Qep) -> Result<()> {
    let n = qep.dim();
    check_square_finite(qep.k.as_ref(), n, "K~")?;
    check_square_finite(qep.m.as_ref(), n, "M~")?;
    if let Some(c) = &qep.c {
        check_square_finite(c.as_ref(), n, "C~")?;
    }
    Ok(())
}

/// `y = A x` for a real sparse matrix and a complex vector (overwrites `y`).
pub fn spmv_complex(a: SparseRef<'_>, x: &[c64], y: &mut [c64]) {
    y.iter_mut().for_each(|v| *v = c64::new(0.0, 0.0));
    spmv_complex_add(a, x, y);
}

/// `y += A x` for a real sparse matrix and a complex vector.
fn spmv_complex_add(a: SparseRef<'_>, x: &[c64], y: &mut [c64]) {
    debug_assert_eq!(x.len(), a.ncols());
    debug_assert_eq!(y.len(), a.nrows());
    for j in 0..a.ncols() {
        let xj = x[j];
        if xj.re == 0.0 && xj.im == 0.0 {
            continue;
        }
        for (i, v) in a.row_idx_of_col(j).zip(a.val_of_col(j)) {
            y[i] += xj * *v;
        }
    }
}

fn norm2_c(x: &[c64]) -> f64 {
    x.iter()
        .map(|v| v.re * v.re + v.im * v.im)
        .sum::<f64>()
        .sqrt()
}

/// Symbolic sparse LU analysis of `Q(sigma) = sigma^2 M + sigma C + K` on the union of
/// the patterns of the matrices it was built from. Build it once and pass it to
/// [`QepShiftInvert::with_symbolic`] for every shift; built with
/// [`for_operator`](Self::for_operator) it also serves every `mu` of one contact set.
#[derive(Debug, Clone)]
pub struct QepSymbolic {
    pattern: SymbolicSparseColMat<usize>,
    lu: SymbolicLu<usize>,
}

impl QepSymbolic {
    /// Analysis of the union pattern of `M`, `C` and `K` of `qep`.
    pub fn new(qep: &Qep) -> Result<Self> {
        let mut mats = vec![qep.m.as_ref(), qep.k.as_ref()];
        if let Some(c) = &qep.c {
            mats.push(c.as_ref());
        }
        Self::from_patterns(qep.dim(), &mats)
    }

    /// Analysis of the union pattern of every part of a frictional operator: valid for
    /// [`op.at(mu)`](FrictionalOperator::at) at any `mu`.
    pub fn for_operator(op: &FrictionalOperator) -> Result<Self> {
        let mut mats = vec![
            op.mc.as_ref(),
            op.kc.as_ref(),
            op.fm.as_ref(),
            op.fk.as_ref(),
        ];
        for c in [&op.cc, &op.fc].into_iter().flatten() {
            mats.push(c.as_ref());
        }
        Self::from_patterns(op.dim(), &mats)
    }

    /// Analysis of the union pattern of `mats` (each `n x n`).
    pub fn from_patterns(n: usize, mats: &[SparseRef<'_>]) -> Result<Self> {
        let mut trip = Vec::with_capacity(mats.iter().map(|a| a.compute_nnz()).sum::<usize>() + n);
        for (k, a) in mats.iter().enumerate() {
            if a.nrows() != n || a.ncols() != n {
                return Err(Error::Dimension {
                    context: format!("QepSymbolic: matrix {k} must be {n} x {n}"),
                    expected: n,
                    got: if a.nrows() != n { a.nrows() } else { a.ncols() },
                });
            }
            for j in 0..n {
                trip.extend(a.row_idx_of_col(j).map(|i| Triplet::new(i, j, 1.0)));
            }
        }
        // The diagonal is always kept: a structurally zero diagonal entry of the union
        // would still be a legitimate pivot position for some shift.
        trip.extend((0..n).map(|i| Triplet::new(i, i, 1.0)));
        let pattern = SparseMat::try_new_from_triplets(n, n, &trip)
            .map_err(|e| Error::Invalid(format!("QepSymbolic: {e:?}")))?
            .into_parts()
            .0;
        let lu = SymbolicLu::try_new(pattern.as_ref()).map_err(|e| Error::Factorization {
            what: format!("Q(sigma) = sigma^2 M + sigma C + K (symbolic, n = {n})"),
            reason: format!("{e:?}"),
        })?;
        Ok(Self { pattern, lu })
    }

    /// Size of `Q`.
    pub fn dim(&self) -> usize {
        self.pattern.nrows()
    }

    /// Stored entries of the union pattern.
    pub fn nnz(&self) -> usize {
        self.pattern.compute_nnz()
    }

    /// Values of `Q(sigma)` on the union pattern.
    fn assemble(&self, qep: &Qep, sigma: c64) -> Result<Vec<c64>> {
        let n = self.dim();
        if qep.dim() != n {
            return Err(Error::Dimension {
                context: "QepShiftInvert: the symbolic analysis was built for another size".into(),
                expected: n,
                got: qep.dim(),
            });
        }
        let pat = self.pattern.as_ref();
        let mut vals = vec![c64::new(0.0, 0.0); pat.compute_nnz()];
        let mut slot = vec![usize::MAX; n];
        let mut parts: Vec<(SparseRef<'_>, c64, &str)> = vec![
            (qep.m.as_ref(), sigma * sigma, "M"),
            (qep.k.as_ref(), c64::new(1.0, 0.0), "K"),
        ];
        if let Some(c) = &qep.c {
            parts.push((c.as_ref(), sigma, "C"));
        }
        for j in 0..n {
            let range = pat.col_range(j);
            for (p, &i) in range.clone().zip(pat.row_idx_of_col_raw(j)) {
                slot[i] = p;
            }
            for (a, s, name) in &parts {
                for (i, v) in a.row_idx_of_col(j).zip(a.val_of_col(j)) {
                    let p = slot[i];
                    if p == usize::MAX {
                        return Err(Error::Invalid(format!(
                            "QepShiftInvert: entry ({i}, {j}) of {name} lies outside the \
                             pattern of the symbolic analysis (built for another operator?)"
                        )));
                    }
                    vals[p] += *s * *v;
                }
            }
            for &i in pat.row_idx_of_col_raw(j) {
                slot[i] = usize::MAX;
            }
        }
        Ok(vals)
    }
}

/// Shift-invert of the companion form at a complex shift `sigma`:
/// `OP = (A - sigma B)^-1 B` with `A = [0 I; -K -C]`, `B = [I 0; 0 M]`, applied through one
/// sparse LU of `Q(sigma) = sigma^2 M + sigma C + K`:
/// `x1 = -Q^-1 [b2 + (C + sigma M) b1]`, `x2 = b1 + sigma x1` where `b = B x`.
/// Eigenvalues map back as `lambda = sigma + 1/theta`.
///
/// Derivation: `(A - sigma B) x = b` reads `-sigma x1 + x2 = b1` and
/// `-K x1 - (C + sigma M) x2 = b2`; substituting the first into the second gives
/// `-(sigma^2 M + sigma C + K) x1 = b2 + (C + sigma M) b1`. An eigenvector of `OP` is a
/// companion eigenvector `z = [u; lambda u]`, so its first `n` components are the mode `u`.
pub struct QepShiftInvert<'a> {
    qep: &'a Qep,
    sigma: c64,
    lu: Lu<usize, c64>,
    applications: AtomicUsize,
}

impl<'a> QepShiftInvert<'a> {
    /// Factorizes `Q(sigma)` (symbolic analysis included).
    pub fn new(qep: &'a Qep, sigma: c64) -> Result<Self> {
        check_qep(qep)?;
        let sym = QepSymbolic::new(qep)?;
        Self::with_symbolic_unchecked(qep, sigma, &sym)
    }

    /// Factorizes `Q(sigma)` reusing a symbolic analysis (same pattern, any shift).
    pub fn with_symbolic(qep: &'a Qep, sigma: c64, symbolic: &QepSymbolic) -> Result<Self> {
        check_qep(qep)?;
        Self::with_symbolic_unchecked(qep, sigma, symbolic)
    }

    fn with_symbolic_unchecked(qep: &'a Qep, sigma: c64, symbolic: &QepSymbolic) -> Result<Self> {
        let n = qep.dim();
        if !(sigma.re.is_finite() && sigma.im.is_finite()) {
            return Err(Error::param(
                "sigma",
                format!("shift must be finite, got {sigma}"),
            ));
        }
        let vals = symbolic.assemble(qep, sigma)?;
        let q = SparseColMatRef::new(symbolic.pattern.as_ref(), &vals);
        let what = || {
            format!(
                "Q(sigma) = sigma^2 M + sigma C + K (sigma = {:.6e}{:+.6e}i rad/s, n = {n})",
                sigma.re, sigma.im
            )
        };
        let lu = Lu::try_new_with_symbolic(symbolic.lu.clone(), q).map_err(|e| {
            Error::Factorization {
                what: what(),
                reason: format!("{e:?}"),
            }
        })?;
        // A singular Q(sigma) (sigma on an eigenvalue) shows up as non-finite solves.
        let probe: Vec<c64> = (0..n)
            .map(|i| c64::new(1.0 + 0.1 * (i as f64).sin(), 0.0))
            .collect();
        let mut y = vec![c64::new(0.0, 0.0); n];
        for j in 0..n {
            for (p, &i) in q.col_range(j).zip(q.symbolic().row_idx_of_col_raw(j)) {
                y[i] += vals[p] * probe[j];
            }
        }
        lu.solve_in_place(MatMut::from_column_major_slice_mut(&mut y, n, 1));
        if y.iter().any(|v| !(v.re.is_finite() && v.im.is_finite())) {
            return Err(Error::Factorization {
                what: what(),
                reason: "numerically singular (is sigma an eigenvalue?)".into(),
            });
        }
        Ok(Self {
            qep,
            sigma,
            lu,
            applications: AtomicUsize::new(0),
        })
    }

    /// The shift.
    pub fn sigma(&self) -> c64 {
        self.sigma
    }
    /// The problem it was built for.
    pub fn qep(&self) -> &Qep {
        self.qep
    }
    /// `lambda = sigma + 1/theta`.
    pub fn lambda_of_theta(&self, theta: c64) -> c64 {
        self.sigma + c64::new(1.0, 0.0) / theta
    }
    /// How many times the operator was applied (one sparse solve each).
    pub fn applications(&self) -> usize {
        self.applications.load(Ordering::Relaxed)
    }
    /// `y <- Q(sigma)^-1 y` (length `n`, not counted as an application).
    pub fn solve_in_place(&self, y: &mut [c64]) {
        let n = y.len();
        self.lu
            .solve_in_place(MatMut::from_column_major_slice_mut(y, n, 1));
    }
    /// `y <- Q(sigma)^-H y` with the same factorization (length `n`): inverse iteration
    /// for left eigenvectors.
    pub fn solve_adjoint_in_place(&self, y: &mut [c64]) {
        let n = y.len();
        self.lu
            .solve_adjoint_in_place(MatMut::from_column_major_slice_mut(y, n, 1));
    }
}

impl ComplexLinOp for QepShiftInvert<'_> {
    fn dim(&self) -> usize {
        2 * self.qep.dim()
    }

    fn apply(&self, x: &[c64], y: &mut [c64]) {
        let n = self.qep.dim();
        assert_eq!(
            x.len(),
            2 * n,
            "QepShiftInvert::apply: x has the wrong length"
        );
        assert_eq!(
            y.len(),
            2 * n,
            "QepShiftInvert::apply: y has the wrong length"
        );
        let (x1, x2) = x.split_at(n);
        let (y1, y2) = y.split_at_mut(n);
        // r = M x2 + (C + sigma M) x1 = M (x2 + sigma x1) + C x1
        let t: Vec<c64> = x2
            .iter()
            .zip(x1)
            .map(|(&a, &b)| a + self.sigma * b)
            .collect();
        spmv_complex(self.qep.m.as_ref(), &t, y1);
        if let Some(c) = &self.qep.c {
            spmv_complex_add(c.as_ref(), x1, y1);
        }
        self.solve_in_place(y1);
        for ((v1, v2), &b1) in y1.iter_mut().zip(y2.iter_mut()).zip(x1) {
            *v1 = -*v1;
            *v2 = b1 + self.sigma * *v1;
        }
        self.applications.fetch_add(1, Ordering::Relaxed);
    }
}

/// The cheaper spectral transformation of an undamped QEP (`C = 0`):
/// `(lambda^2 M + K) u = 0` is `(K - s M) u = 0` with `s = -lambda^2`, so
/// `OP = (K - sigma_s M)^-1 M` on `n`-vectors with a REAL shift `sigma_s` and one real
/// sparse LU (a quarter of the work and half the memory of a complex one, on half the
/// vector length). Eigenvalues map back as `s = sigma_s + 1/theta`,
/// `lambda = i sqrt(s)` (principal root, so `Im(lambda) >= 0`); the conjugate `s` gives
/// the mirror mode `-conj(lambda)`. Complex vectors are applied as two real columns.
pub struct QepSquaredShift<'a> {
    qep: &'a Qep,
    sigma: f64,
    lu: Lu<usize, f64>,
    applications: AtomicUsize,
}

impl<'a> QepSquaredShift<'a> {
    /// Factorizes `K - sigma_s M` (real, non-symmetric in general). `qep.c` must be `None`.
    pub fn new(qep: &'a Qep, sigma_s: f64) -> Result<Self> {
        check_qep(qep)?;
        if qep.c.is_some() {
            return Err(Error::Invalid(
                "the squared spectral transformation needs C = 0".into(),
            ));
        }
        let n = qep.dim();
        let a = crate::linalg::add_scaled(qep.k.as_ref(), 1.0, qep.m.as_ref(), -sigma_s)?;
        let what = || format!("K - s M (s = {sigma_s:.6e} (rad/s)^2, n = {n})");
        let sym = SymbolicLu::try_new(a.symbolic()).map_err(|e| Error::Factorization {
            what: what(),
            reason: format!("{e:?}"),
        })?;
        let lu = Lu::try_new_with_symbolic(sym, a.as_ref()).map_err(|e| Error::Factorization {
            what: what(),
            reason: format!("{e:?}"),
        })?;
        let mut y: Vec<f64> = (0..n).map(|i| 1.0 + 0.1 * (i as f64).sin()).collect();
        lu.solve_in_place(MatMut::from_column_major_slice_mut(&mut y, n, 1));
        if y.iter().any(|v| !v.is_finite()) {
            return Err(Error::Factorization {
                what: what(),
                reason: "numerically singular (is the shift an eigenvalue?)".into(),
            });
        }
        Ok(Self {
            qep,
            sigma: sigma_s,
            lu,
            applications: AtomicUsize::new(0),
        })
    }

    /// How many times the operator was applied.
    pub fn applications(&self) -> usize {
        self.applications.load(Ordering::Relaxed)
    }

    /// `s = sigma_s + 1/theta` and `lambda = i sqrt(s)`.
    pub fn lambda_of_theta(&self, theta: c64) -> (c64, c64) {
        let s = c64::new(self.sigma, 0.0) + c64::new(1.0, 0.0) / theta;
        (s, c64::new(0.0, 1.0) * s.sqrt())
    }
}

impl ComplexLinOp for QepSquaredShift<'_> {
    fn dim(&self) -> usize {
        self.qep.dim()
    }

    fn apply(&self, x: &[c64], y: &mut [c64]) {
        let n = self.qep.dim();
        assert_eq!(x.len(), n, "QepSquaredShift::apply: x has the wrong length");
        assert_eq!(y.len(), n, "QepSquaredShift::apply: y has the wrong length");
        let mut b = Mat::<f64>::zeros(n, 2);
        let m = self.qep.m.as_ref();
        for j in 0..n {
            let (xr, xi) = (x[j].re, x[j].im);
            if xr == 0.0 && xi == 0.0 {
                continue;
            }
            for (i, v) in m.row_idx_of_col(j).zip(m.val_of_col(j)) {
                b[(i, 0)] += v * xr;
                b[(i, 1)] += v * xi;
            }
        }
        self.lu.solve_in_place(b.as_mut());
        for (i, v) in y.iter_mut().enumerate() {
            *v = c64::new(b[(i, 0)], b[(i, 1)]);
        }
        self.applications.fetch_add(1, Ordering::Relaxed);
    }
}

/// The operator of one window of the band driver.
enum WindowOp<'a> {
    Companion(QepShiftInvert<'a>),
    Squared(QepSquaredShift<'a>),
    LowRank(QepLowRankSquared<'a>),
}

impl WindowOp<'_> {
    fn linop(&self) -> &dyn ComplexLinOp {
        match self {
            WindowOp::Companion(o) => o,
            WindowOp::Squared(o) => o,
            WindowOp::LowRank(o) => o,
        }
    }
    /// (point in the plane of the window, lambda).
    fn map(&self, theta: c64) -> (c64, c64) {
        match self {
            WindowOp::Companion(o) => {
                let l = o.lambda_of_theta(theta);
                (l, l)
            }
            WindowOp::Squared(o) => o.lambda_of_theta(theta),
            WindowOp::LowRank(o) => o.lambda_of_theta(theta),
        }
    }
    fn applications(&self) -> usize {
        match self {
            WindowOp::Companion(o) => o.applications(),
            WindowOp::Squared(o) => o.applications(),
            WindowOp::LowRank(o) => o.applications(),
        }
    }
}

/// Tuning of the band driver [`solve_qep_band_with`].
#[derive(Debug, Clone, PartialEq)]
pub struct QepBandOptions {
    /// Cap on `nev` of one Krylov run (also capped by `n - 2`); a window needing more is
    /// split in two.
    pub max_nev: usize,
    /// Window radius `R = radius_factor * half_width + margin_rel * 2 pi f_top` (rad/s):
    /// `radius_factor > 1` lets the circle reach past the band edges off the imaginary axis.
    pub radius_factor: f64,
    /// Extra radius as a fraction of the window's top angular frequency.
    pub margin_rel: f64,
    /// Maximum depth of window splitting (`2^max_depth` windows at most).
    pub max_depth: usize,
    /// First `nev` when [`EigenParams::nev_hint`] is `None`.
    pub nev_default: usize,
    /// Use the real squared transformation ([`QepSquaredShift`]) when `C = 0`.
    pub squared_when_undamped: bool,
    /// Whether the squared transformation of an undamped frictional operator goes through
    /// the low-rank (Woodbury) path ([`QepLowRankSquared`]) instead of a sparse LU of
    /// `K~ - s M~`. Only [`solve_frictional_band_with`] can use it (it needs the parts of
    /// the operator); [`solve_qep_band_with`] ignores it.
    pub low_rank: LowRank,
    /// Whether the modes get left eigenvectors, condition numbers and forward error
    /// estimates (one extra factorization per mode, see [`Condition`]).
    pub condition: Condition,
}

/// Choice of the low-rank (Woodbury) path of the band driver, see
/// [`QepBandOptions::low_rank`] and [`crate::lowrank`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LowRank {
    /// Use it when it applies (`C = 0`, squared transformation on, `friction_loads`
    /// known and recoverable) and `n > LOW_RANK_AUTO_MIN_DIM`; otherwise, or when building
    /// it fails, fall back to the sparse LU (noted in `info`).
    #[default]
    Auto,
    /// Use it whenever the problem is solved iteratively; an error when it does not apply.
    Always,
    /// Never use it (sparse LU of `K~ - s M~`).
    Never,
}

/// Size above which [`LowRank::Auto`] takes the low-rank path.
pub const LOW_RANK_AUTO_MIN_DIM: usize = 20_000;

impl Default for QepBandOptions {
    fn default() -> Self {
        Self {
            max_nev: 400,
            radius_factor: 1.05,
            margin_rel: 0.01,
            max_depth: 10,
            nev_default: 24,
            squared_when_undamped: true,
            low_rank: LowRank::Auto,
            condition: Condition::Auto,
        }
    }
}

/// Band driver shared by the full-order complex backends: shifts `i 2 pi f` chosen to cover
/// `[params.fmin_hz, params.fmax_hz]`, the kernel run on [`QepShiftInvert`] for each, `nev`
/// grown until every window is covered, eigenvalues mapped back, duplicates merged, and the
/// result finished by [`finish_modes`].
///
/// Same as [`solve_qep_band_with`] with default [`QepBandOptions`] and a fresh symbolic
/// analysis.
pub fn solve_qep_band(
    solver: &str,
    kernel: &dyn ComplexKernel,
    qep: &Qep,
    params: &EigenParams,
) -> Result<ComplexModes> {
    solve_qep_band_with(
        solver,
        kernel,
        qep,
        params,
        &QepBandOptions::default(),
        None,
    )
}

/// The band driver with explicit options and an optional reused symbolic analysis.
///
/// - Companion size `2n <= params.dense_below`: solved by [`dense_qep`] (noted in `info`).
/// - Otherwise one window `[fmin, fmax]` to start with: shift `sigma = i 2 pi f_c` at its
///   centre, radius `R` (see [`QepBandOptions`]). The kernel computes the `nev` largest
///   `|theta|` of `OP`, i.e. the `nev` eigenvalues nearest `sigma`; once one of them lies
///   outside the circle `|lambda - sigma| > R`, every eigenvalue inside it has been found.
///   Until then `nev` doubles (from `params.nev_hint`, else `nev_default`); past the cap
///   the window is split in two halves, recursively.
/// - Each window keeps the eigenvalues with `Im > 0` and frequency in its sub-band;
///   copies found by two windows are merged (relative distance `1e-8`, or 100 `tol R`).
/// - The mode `u` is the first block of the companion eigenvector `z = [u; lambda u]`, or
///   the second divided by `lambda` when that has the smaller backward error.
/// - `params.shift_hz` is not used (the shifts are on the imaginary axis).
pub fn solve_qep_band_with(
    solver: &str,
    kernel: &dyn ComplexKernel,
    qep: &Qep,
    params: &EigenParams,
    options: &QepBandOptions,
    symbolic: Option<&QepSymbolic>,
) -> Result<ComplexModes> {
    band_solve(
        solver,
        kernel,
        qep,
        params,
        options,
        symbolic,
        LowRankChoice::Off,
        Instant::now(),
    )
}

/// Band driver on a frictional operator at `mu`: [`solve_frictional_band_with`] with
/// default [`QepBandOptions`].
pub fn solve_frictional_band(
    solver: &str,
    kernel: &dyn ComplexKernel,
    op: &FrictionalOperator,
    mu: f64,
    params: &EigenParams,
) -> Result<ComplexModes> {
    solve_frictional_band_with(solver, kernel, op, mu, params, &QepBandOptions::default())
}

/// Band driver on a frictional operator at `mu`: the same as
/// [`solve_qep_band_with`] on [`op.at(mu)`](FrictionalOperator::at), except that an
/// undamped operator (`C = 0`, squared transformation) may go through the low-rank path
/// ([`crate::lowrank`]: one symmetric `L B L^T` of `K_c - s M_c` per window and a
/// Woodbury correction of rank `nA`) instead of a sparse LU of `K~ - s M~`, as
/// [`QepBandOptions::low_rank`] says. The notes of the result say which path was taken,
/// the number of stored entries of the factor, the rank and the measured accuracy.
pub fn solve_frictional_band_with(
    solver: &str,
    kernel: &dyn ComplexKernel,
    op: &FrictionalOperator,
    mu: f64,
    params: &EigenParams,
    options: &QepBandOptions,
) -> Result<ComplexModes> {
    let start = Instant::now();
    let qep = op.at(mu)?;
    let n = qep.dim();
    let wanted = match options.low_rank {
        LowRank::Never => false,
        LowRank::Always => true,
        LowRank::Auto => n > LOW_RANK_AUTO_MIN_DIM,
    };
    let iterative = 2 * n > params.dense_below;
    let choice = if !wanted || !iterative {
        LowRankChoice::Off
    } else {
        let why_not = if !options.squared_when_undamped {
            Some("the squared transformation is off".to_string())
        } else if qep.c.is_some() {
            Some("the operator is damped (C != 0)".to_string())
        } else if op.friction_loads.is_none() {
            Some("the operator has no friction_loads".to_string())
        } else {
            None
        };
        let built = match why_not {
            Some(w) => Err(Error::Invalid(w)),
            None => FrictionLowRank::new(op).and_then(|fr| {
                let t = Instant::now();
                let pencil = SymmetricPencil::new(op)?;
                if pencil.asymmetry() > crate::lowrank::MAX_ASYMMETRY {
                    return Err(Error::Invalid(format!(
                        "K_c / M_c are not symmetric (relative asymmetry {:.2e})",
                        pencil.asymmetry()
                    )));
                }
                Ok((fr, pencil, t.elapsed().as_secs_f64()))
            }),
        };
        match built {
            Ok((friction, pencil, t_sym)) => LowRankChoice::On(Box::new(LowRankCtx {
                op,
                mu,
                friction,
                pencil: Arc::new(pencil),
                t_symbolic: t_sym,
            })),
            Err(e) if options.low_rank == LowRank::Always => {
                return Err(Error::Invalid(format!(
                    "low-rank path requested (LowRank::Always) but not applicable: {e}"
                )))
            }
            Err(e) => LowRankChoice::Declined(format!(
                "low-rank path not applicable ({e}); sparse LU used"
            )),
        }
    };
    band_solve(solver, kernel, &qep, params, options, None, choice, start)
}

/// Data of the low-rank path of one band solve.
struct LowRankCtx<'a> {
    op: &'a FrictionalOperator,
    mu: f64,
    friction: FrictionLowRank,
    pencil: Arc<SymmetricPencil>,
    t_symbolic: f64,
}

/// Whether a band solve uses the low-rank path.
enum LowRankChoice<'a> {
    /// Not considered.
    Off,
    /// Considered and declined (the note says why).
    Declined(String),
    /// Used.
    On(Box<LowRankCtx<'a>>),
}

/// The band driver proper (see [`solve_qep_band_with`]).
fn band_solve(
    solver: &str,
    kernel: &dyn ComplexKernel,
    qep: &Qep,
    params: &EigenParams,
    options: &QepBandOptions,
    symbolic: Option<&QepSymbolic>,
    low_rank: LowRankChoice<'_>,
    start: Instant,
) -> Result<ComplexModes> {
    validate_params(params)?;
    check_qep(qep)?;
    let n = qep.dim();
    if n == 0 {
        return Err(Error::Invalid("empty quadratic eigenproblem".into()));
    }
    let valid = options.radius_factor.is_finite()
        && options.radius_factor >= 1.0
        && options.margin_rel.is_finite()
        && options.margin_rel >= 0.0;
    if options.max_nev == 0 || !valid {
        return Err(Error::param(
            "qep band options",
            format!("need max_nev >= 1, radius_factor >= 1, margin_rel >= 0; got {options:?}"),
        ));
    }
    let mut info = SolveInfo::new(solver);
    if 2 * n <= params.dense_below {
        info.notes.push(format!(
            "companion size 2n = {} <= {}: solved densely instead of `{solver}`",
            2 * n,
            params.dense_below
        ));
        let (lambda, vectors) = dense_qep(qep)?;
        info.requested = lambda.len();
        info.converged = lambda.len();
        let mut modes = finish_modes_with(
            qep,
            &lambda,
            vectors.as_ref(),
            params,
            info,
            options.condition,
        )?;
        modes.info.time_s = start.elapsed().as_secs_f64();
        return Ok(modes);
    }
    let low_rank = match low_rank {
        LowRankChoice::On(ctx) => Some(*ctx),
        LowRankChoice::Declined(note) => {
            info.notes.push(note);
            None
        }
        LowRankChoice::Off => None,
    };
    let cap = options.max_nev.min(n.saturating_sub(2)).max(1);
    let mut run = BandRun {
        kernel,
        qep,
        params,
        options,
        sym: symbolic,
        sym_owned: None,
        low_rank,
        cap,
        norms: QepNorms::of(qep),
        info,
        lambda: Vec::new(),
        vectors: Vec::new(),
    };
    let nev0 = params.nev_hint.unwrap_or(options.nev_default).clamp(1, cap);
    run.window(params.fmin_hz, params.fmax_hz, 0, nev0)?;
    let mut vectors = Mat::<c64>::zeros(n, run.lambda.len());
    for (c, v) in run.vectors.iter().enumerate() {
        for r in 0..n {
            vectors[(r, c)] = v[r];
        }
    }
    let mut modes = finish_modes_with(
        qep,
        &run.lambda,
        vectors.as_ref(),
        params,
        run.info,
        options.condition,
    )?;
    modes.info.time_s = start.elapsed().as_secs_f64();
    Ok(modes)
}

/// State of one band solve: what is fixed and what has been collected so far.
struct BandRun<'a> {
    kernel: &'a dyn ComplexKernel,
    qep: &'a Qep,
    params: &'a EigenParams,
    options: &'a QepBandOptions,
    /// Symbolic LU analysis given by the caller (companion path only).
    sym: Option<&'a QepSymbolic>,
    /// Symbolic LU analysis built on first use by the companion path.
    sym_owned: Option<QepSymbolic>,
    low_rank: Option<LowRankCtx<'a>>,
    cap: usize,
    norms: QepNorms,
    info: SolveInfo,
    lambda: Vec<c64>,
    vectors: Vec<Vec<c64>>,
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
                     transformation), sparse LU of K~ - s M~"
                        .into(),
                );
            }
            return Ok(WindowOp::Squared(QepSquaredShift::new(qep, sigma)?));
        };
        let t = Instant::now();
        let shift = SymmetricShift::new(ctx.op, ctx.pencil.clone(), &ctx.friction, sigma)?;
        let t_factor = t.elapsed().as_secs_f64();
        let op = QepLowRankSquared::new(qep, Arc::new(shift), ctx.mu)?;
        if first {
            self.info.notes.push(format!(
                "C = 0: real shift-invert of K - s M, s = -lambda^2 (squared \
                 transformation), low-rank path: symmetric LBL^T of K_c - s M_c \
                 (nnz(L) = {} stored entries, symbolic {:.2} s, numeric + Z {:.2} s) + \
                 Woodbury correction of rank nA = {} (U W^T error {:.1e}, asymmetry {:.1e}, \
                 S residual {:.1e}, A residual {:.1e}{})",
                ctx.pencil.factor_entries(),
                ctx.t_symbolic,
                t_factor,
                ctx.friction.rank(),
                ctx.friction.identity_error,
                ctx.pencil.asymmetry(),
                op.shift().s_residual(),
                op.probe_residual(),
                if op.refines() {
                    ", one refinement step per solve"
                } else {
                    ""
                }
            ));
        }
        Ok(WindowOp::LowRank(op))
    }

    /// Covers `[lo, hi]` Hz with one shift, or splits it.
    fn window(&mut self, lo: f64, hi: f64, depth: usize, nev0: usize) -> Result<()> {
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
        let dim = op.linop().dim();
        self.info.factorizations += 1;
        let mut nev = nev0.clamp(1, self.cap);
        let outcome = loop {
            let out =
                self.kernel
                    .largest(op.linop(), nev, self.params.tol, self.params.max_restarts)?;
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
        self.info.op_applications += op.applications();
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

/// All eigenpairs of a small QEP, densely: companion form scaled by
/// `gamma = sqrt(||K|| / ||M||)`, infinite and rigid-body roots filtered out.
/// Returns every finite eigenvalue (both members of conjugate pairs) and its vector `u`.
///
/// Scaling (Fan, Lin & Van Dooren 2004): `lambda = gamma mu`, `delta = 2 / (||K|| +
/// gamma ||C||)`, `M_s = gamma^2 delta M`, `C_s = gamma delta C`, `K_s = delta K`; the
/// companion matrix `[0 I; -M_s^-1 K_s  -M_s^-1 C_s]` (one dense LU of `M_s`) is then
/// diagonalized by faer's real non-symmetric `eigen` (no QZ). Non-finite roots are dropped;
/// roots with `|mu| <= RIGID_BODY_REL` are returned as exact zeros (rigid-body motions;
/// [`finish_modes`] drops them as non-oscillating). The vector is the first block of the
/// companion eigenvector (`u`), or the second divided by `mu` when `|mu| > 1` (the better
/// conditioned of the two). A singular `M` (massless DOFs) is an error. Cost: `O((2n)^3)`,
/// or `O(n^3)` when `C = 0`: the eigenvalues `t` of `M_s^-1 K_s` give `mu = +-sqrt(-t)`.
pub fn dense_qep(qep: &Qep) -> Result<(Vec<c64>, Mat<c64>)> {
    check_qep(qep)?;
    let n = qep.dim();
    if n == 0 {
        return Ok((Vec::new(), Mat::zeros(0, 0)));
    }
    let kn = norm1(qep.k.as_ref());
    let mn = norm1(qep.m.as_ref());
    let cn = qep.c.as_ref().map_or(0.0, |c| norm1(c.as_ref()));
    if mn == 0.0 {
        return Err(Error::Invalid(
            "dense QEP: the mass matrix M~ is zero (the companion form needs M~ invertible)".into(),
        ));
    }
    let gamma = if kn > 0.0 { (kn / mn).sqrt() } else { 1.0 };
    let denom = kn + gamma * cn;
    let delta = if denom > 0.0 {
        2.0 / denom
    } else {
        1.0 / (gamma * gamma * mn)
    };
    let ms = qep.m.as_ref().to_dense() * faer::Scale(gamma * gamma * delta);
    let lu = ms.partial_piv_lu();
    let u = lu.U();
    let (mut pmin, mut pmax) = (f64::INFINITY, 0.0f64);
    for i in 0..n {
        let p = u[(i, i)].abs();
        pmin = pmin.min(p);
        pmax = pmax.max(p);
    }
    if pmin.is_nan() || pmin <= 1e-14 * pmax {
        return Err(Error::Factorization {
            what: format!("M~ (dense, n = {n})"),
            reason: format!(
                "singular mass matrix (pivot ratio {:.2e}): massless DOFs make infinite \
                 eigenvalues; condense them out before the dense companion solve",
                pmin / pmax
            ),
        });
    }
    // W = M_s^-1 [K_s | C_s] (only M_s^-1 K_s when C = 0)
    let undamped = qep.c.is_none();
    let mut w = Mat::<f64>::zeros(n, if undamped { n } else { 2 * n });
    {
        let kd = qep.k.as_ref().to_dense();
        w.as_mut()
            .submatrix_mut(0, 0, n, n)
            .copy_from(kd * faer::Scale(delta));
        if let Some(c) = &qep.c {
            let cd = c.as_ref().to_dense();
            w.as_mut()
                .submatrix_mut(0, n, n, n)
                .copy_from(cd * faer::Scale(gamma * delta));
        }
    }
    lu.solve_in_place(w.as_mut());
    if undamped {
        return dense_qep_squared(w, gamma);
    }
    let mut a = Mat::<f64>::zeros(2 * n, 2 * n);
    for i in 0..n {
        a[(i, n + i)] = 1.0;
    }
    for j in 0..2 * n {
        for i in 0..n {
            a[(n + i, j)] = -w[(i, j)];
        }
    }
    let eig = dense_eigen(a.as_ref(), n, "M~^-1 [K~ C~]", "companion form")?;
    let s = eig.S();
    let z = eig.U();
    let mut lambda = Vec::with_capacity(2 * n);
    let mut cols = Vec::with_capacity(2 * n);
    for k in 0..2 * n {
        let mu = s[k];
        if !(mu.re.is_finite() && mu.im.is_finite()) {
            continue;
        }
        let amu = mu.norm();
        let l = if amu <= RIGID_BODY_REL {
            c64::new(0.0, 0.0)
        } else {
            mu * gamma
        };
        lambda.push(l);
        cols.push((k, mu, amu));
    }
    let mut vectors = Mat::<c64>::zeros(n, lambda.len());
    for (c, &(k, mu, amu)) in cols.iter().enumerate() {
        if amu > 1.0 {
            let inv = c64::new(1.0, 0.0) / mu;
            for r in 0..n {
                vectors[(r, c)] = z[(n + r, k)] * inv;
            }
        } else {
            for r in 0..n {
                vectors[(r, c)] = z[(r, k)];
            }
        }
    }
    Ok((lambda, vectors))
}

/// Eigen decomposition of the dense matrix `a` (`what`, built from `M~^-1` of a QEP of
/// size `n`; `form` names it in errors), refused when it is not finite (singular mass).
fn dense_eigen(
    a: MatRef<'_, f64>,
    n: usize,
    what: &str,
    form: &str,
) -> Result<faer::linalg::solvers::Eigen<f64>> {
    if (0..a.ncols()).any(|j| (0..a.nrows()).any(|i| !a[(i, j)].is_finite())) {
        return Err(Error::Factorization {
            what: format!("M~ (dense, n = {n})"),
            reason: format!("{what} is not finite: the mass matrix is numerically singular"),
        });
    }
    faer::linalg::solvers::Eigen::new_from_real(a).map_err(|e| Error::NotConverged {
        method: format!("dense non-symmetric eigen ({form})"),
        iterations: 0,
        detail: format!("{e:?}"),
    })
}

/// The undamped branch of [`dense_qep`]: with `C = 0`, `mu^2 = -t` for the eigenvalues
/// `t` of `W = M_s^-1 K_s` (`n x n`, against `2n x 2n` for the companion form: 8 times
/// fewer flops), each `t` giving the two roots `mu = +-sqrt(-t)` with the same vector.
fn dense_qep_squared(w: Mat<f64>, gamma: f64) -> Result<(Vec<c64>, Mat<c64>)> {
    let n = w.nrows();
    let eig = dense_eigen(w.as_ref(), n, "M~^-1 K~", "M~^-1 K~, C = 0")?;
    let t = eig.S();
    let z = eig.U();
    let mut lambda = Vec::with_capacity(2 * n);
    let mut cols = Vec::with_capacity(2 * n);
    for k in 0..n {
        let root = (-t[k]).sqrt();
        if !(root.re.is_finite() && root.im.is_finite()) {
            continue;
        }
        for mu in [root, -root] {
            lambda.push(if mu.norm() <= RIGID_BODY_REL {
                c64::new(0.0, 0.0)
            } else {
                mu * gamma
            });
            cols.push(k);
        }
    }
    let vectors = Mat::<c64>::from_fn(n, cols.len(), |r, c| z[(r, cols[c])]);
    Ok((lambda, vectors))
}

/// The three norms entering the backward error.
struct QepNorms {
    m: f64,
    c: f64,
    k: f64,
}

impl QepNorms {
    /// The backward error `||r|| / ((|l|^2 ||M|| + |l| ||C|| + ||K||) ||u||)` from the
    /// residual norm `num` and the vector norm `un`; `0` for a zero residual on a zero
    /// scale, infinite for a nonzero one.
    fn relative(&self, lambda: c64, num: f64, un: f64) -> f64 {
        let al = lambda.norm();
        let den = (al * al * self.m + al * self.c + self.k) * un;
        if den > 0.0 {
            num / den
        } else if num == 0.0 {
            0.0
        } else {
            f64::INFINITY
        }
    }

    fn of(qep: &Qep) -> Self {
        Self {
            m: norm1(qep.m.as_ref()),
            c: qep.c.as_ref().map_or(0.0, |c| norm1(c.as_ref())),
            k: norm1(qep.k.as_ref()),
        }
    }
}

/// A QEP as sums of scaled sparse parts (`M~ = sum a_i M_i`, same for `C~`, `K~`), so
/// that the modes of a frictional operator at mu are checked on `X_c - mu F_X` without
/// assembling it.
struct QepTerms<'a> {
    n: usize,
    m: Vec<(SparseRef<'a>, f64)>,
    c: Vec<(SparseRef<'a>, f64)>,
    k: Vec<(SparseRef<'a>, f64)>,
}

impl<'a> QepTerms<'a> {
    fn of_qep(qep: &'a Qep) -> Self {
        Self {
            n: qep.dim(),
            m: vec![(qep.m.as_ref(), 1.0)],
            c: qep.c.iter().map(|c| (c.as_ref(), 1.0)).collect(),
            k: vec![(qep.k.as_ref(), 1.0)],
        }
    }

    /// The parts of `op.at(mu)` (the caller checks `mu`).
    fn of_operator(op: &'a FrictionalOperator, mu: f64) -> Self {
        let pair = |x: &'a SparseMat, f: &'a SparseMat| vec![(x.as_ref(), 1.0), (f.as_ref(), -mu)];
        let mut c: Vec<(SparseRef<'a>, f64)> = op.cc.iter().map(|c| (c.as_ref(), 1.0)).collect();
        c.extend(op.fc.iter().map(|f| (f.as_ref(), -mu)));
        Self {
            n: op.dim(),
            m: pair(&op.mc, &op.fm),
            c,
            k: pair(&op.kc, &op.fk),
        }
    }

    /// `||sum a_i A_i||_1` without assembling the sum (a dense column accumulator).
    fn norm1(&self, terms: &[(SparseRef<'_>, f64)]) -> f64 {
        match terms {
            [] => 0.0,
            [(a, s)] => s.abs() * norm1(*a),
            _ => {
                let mut acc = vec![0.0; self.n];
                let mut touched = Vec::new();
                let mut best = 0.0f64;
                for j in 0..self.n {
                    for (a, s) in terms {
                        for (&i, &v) in a.row_idx_of_col_raw(j).iter().zip(a.val_of_col(j)) {
                            if acc[i] == 0.0 {
                                touched.push(i);
                            }
                            acc[i] += s * v;
                        }
                    }
                    let sum: f64 = touched.iter().map(|&i| acc[i].abs()).sum();
                    best = best.max(sum);
                    touched.drain(..).for_each(|i| acc[i] = 0.0);
                }
                best
            }
        }
    }

    fn norms(&self) -> QepNorms {
        QepNorms {
            m: self.norm1(&self.m),
            c: self.norm1(&self.c),
            k: self.norm1(&self.k),
        }
    }
}

fn backward_error_with(qep: &Qep, norms: &QepNorms, lambda: c64, u: &[c64]) -> f64 {
    let n = qep.dim();
    assert_eq!(u.len(), n, "backward_error: vector of the wrong length");
    // r = K u + lambda (C u + lambda M u)
    let mut t = vec![c64::new(0.0, 0.0); n];
    spmv_complex(qep.m.as_ref(), u, &mut t);
    t.iter_mut().for_each(|v| *v *= lambda);
    if let Some(c) = &qep.c {
        spmv_complex_add(c.as_ref(), u, &mut t);
    }
    t.iter_mut().for_each(|v| *v *= lambda);
    spmv_complex_add(qep.k.as_ref(), u, &mut t);
    norms.relative(lambda, norm2_c(&t), norm2_c(u))
}

/// Backward errors of the pairs `(lambda[j], u[:, j])` on `qep`, the same numbers as
/// [`backward_error`] one by one, from one pass over each matrix for all vectors at once
/// (real and imaginary parts as `2 k` right-hand sides stored row by row, so every
/// nonzero updates a contiguous row) instead of `2 k` serial sparse products: the per-mu
/// cost of reduced solves is dominated by this check. The right-hand sides are split
/// between two threads.
fn backward_errors(
    qep: &QepTerms<'_>,
    norms: &QepNorms,
    lambda: &[c64],
    u: MatRef<'_, c64>,
) -> Vec<f64> {
    let (n, k) = (u.nrows(), u.ncols());
    if k == 0 {
        return Vec::new();
    }
    // Columns [lo, hi) of the vectors, as interleaved (re, im) rows of width 2 (hi - lo).
    let block = |lo: usize, hi: usize| -> Vec<f64> {
        let w = hi - lo;
        let x: Vec<f64> = (0..n)
            .flat_map(|i| (lo..hi).flat_map(move |j| [u[(i, j)].re, u[(i, j)].im]))
            .collect();
        let times = |terms: &[(SparseRef<'_>, f64)]| -> Vec<f64> {
            let mut y = vec![0.0; n * 2 * w];
            for (a, s) in terms {
                for c in 0..a.ncols() {
                    let xc = &x[c * 2 * w..(c + 1) * 2 * w];
                    for (&i, &v) in a.row_idx_of_col_raw(c).iter().zip(a.val_of_col(c)) {
                        let yi = &mut y[i * 2 * w..(i + 1) * 2 * w];
                        let v = s * v;
                        yi.iter_mut().zip(xc).for_each(|(y, x)| *y += v * x);
                    }
                }
            }
            y
        };
        let (mx, kx) = (times(&qep.m), times(&qep.k));
        let cx = (!qep.c.is_empty()).then(|| times(&qep.c));
        let at = |y: &[f64], i: usize, j: usize| {
            c64::new(y[i * 2 * w + 2 * j], y[i * 2 * w + 2 * j + 1])
        };
        let (mut num, mut un) = (vec![0.0; w], vec![0.0; w]);
        for i in 0..n {
            for j in 0..w {
                let l = lambda[lo + j];
                let mut t = at(&mx, i, j) * l;
                if let Some(cx) = &cx {
                    t += at(cx, i, j);
                }
                num[j] += (t * l + at(&kx, i, j)).norm_sqr();
                un[j] += at(&x, i, j).norm_sqr();
            }
        }
        (0..w)
            .map(|j| norms.relative(lambda[lo + j], num[j].sqrt(), un[j].sqrt()))
            .collect()
    };
    let mid = k / 2;
    if mid == 0 {
        return block(0, k);
    }
    let (mut first, second) = std::thread::scope(|s| {
        let h = s.spawn(|| block(mid, k));
        (block(0, mid), h.join().expect("backward error thread"))
    });
    first.extend(second);
    first
}

/// Backward error of `(lambda, u)` on `qep` (see module docs).
pub fn backward_error(qep: &Qep, lambda: c64, u: &[c64]) -> f64 {
    backward_error_with(qep, &QepNorms::of(qep), lambda, u)
}

/// The eigenvalues [`finish_modes`] keeps, as `(frequency in Hz, index)` sorted by
/// frequency then real part: finite, oscillating (`Im(lambda) > REAL_ROOT_REL |lambda|`)
/// and in the band of `params` (inclusive, relative slack `1e-12`). Reduced solves use it
/// to expand only these vectors.
pub fn band_pairs(lambda: &[c64], params: &EigenParams) -> Vec<(f64, usize)> {
    let two_pi = 2.0 * std::f64::consts::PI;
    let lo = params.fmin_hz * (1.0 - 1e-12);
    let hi = params.fmax_hz * (1.0 + 1e-12);
    let mut keep: Vec<(f64, usize)> = lambda
        .iter()
        .enumerate()
        .filter(|(_, l)| l.re.is_finite() && l.im.is_finite())
        .filter(|(_, l)| l.im > REAL_ROOT_REL * l.norm())
        // heavily damped roots are no vibration modes (see `finish_modes`)
        .filter(|(_, l)| -l.re <= l.im)
        .map(|(i, l)| (l.im / two_pi, i))
        .filter(|&(f, _)| f >= lo && f <= hi)
        .collect();
    keep.sort_by(|a, b| {
        a.0.total_cmp(&b.0)
            .then(lambda[a.1].re.total_cmp(&lambda[b.1].re))
    });
    keep
}

/// Keeps the pairs with `Im(lambda) > 0` and frequency in the band, normalizes the vectors,
/// computes frequencies, DvR and backward errors, and sorts by frequency.
///
/// Real roots (`|Im| <= REAL_ROOT_REL |lambda|`, rigid-body zeros included) are not
/// oscillating modes and are dropped, and so are heavily damped roots with
/// `Re(lambda) < -Im(lambda)` (damping ratio `-Re / |lambda|` above `1/sqrt 2`): a damped
/// operator has them (overdamped modes under stiffness-proportional damping, where a
/// cluster of real roots near `-1/beta` comes out of a dense solver as pairs with
/// round-off imaginary parts), they can never be unstable, and a shift-invert solver aimed
/// at the band does not see them. The band is inclusive with a relative slack of
/// `1e-12`. Vectors get unit 2-norm and a deterministic phase (their largest-modulus
/// component real positive). `info` is passed through (the caller sets `time_s`).
///
/// Left eigenvectors, condition numbers and forward error estimates are computed as
/// [`Condition::Auto`] says (by inverse iteration on `qep`, one factorization per kept
/// mode, counted in `info.factorizations` and noted).
pub fn finish_modes(
    qep: &Qep,
    lambda: &[c64],
    vectors: faer::MatRef<'_, c64>,
    params: &EigenParams,
    info: SolveInfo,
) -> Result<ComplexModes> {
    finish_modes_with(qep, lambda, vectors, params, info, Condition::Auto)
}

/// [`finish_modes`] with an explicit choice of left eigenvectors.
pub fn finish_modes_with(
    qep: &Qep,
    lambda: &[c64],
    vectors: faer::MatRef<'_, c64>,
    params: &EigenParams,
    info: SolveInfo,
    condition: Condition,
) -> Result<ComplexModes> {
    let left = if condition.applies(qep.dim()) {
        LeftSource::InverseIteration(qep)
    } else {
        LeftSource::None
    };
    finish_terms(&QepTerms::of_qep(qep), lambda, vectors, left, params, info)
}

/// [`finish_modes`] on `op.at(mu)`, without assembling it: the backward errors are
/// computed on the parts `X_c - mu F_X` (the same numbers to round-off). No left
/// eigenvectors (`cond` and `error_bound` are NaN); reduced solves use
/// [`finish_operator_modes_with_left`].
pub fn finish_operator_modes(
    op: &FrictionalOperator,
    mu: f64,
    lambda: &[c64],
    vectors: faer::MatRef<'_, c64>,
    params: &EigenParams,
    info: SolveInfo,
) -> Result<ComplexModes> {
    if !mu.is_finite() {
        return Err(Error::param("mu", format!("must be finite, got {mu}")));
    }
    finish_terms(
        &QepTerms::of_operator(op, mu),
        lambda,
        vectors,
        LeftSource::None,
        params,
        info,
    )
}

/// [`finish_operator_modes`] with given left eigenvectors (one column per eigenvalue of
/// `lambda`, e.g. a reduced solve's left vectors expanded by the basis), from which the
/// condition numbers and forward error estimates are computed on `op.at(mu)`.
pub fn finish_operator_modes_with_left(
    op: &FrictionalOperator,
    mu: f64,
    lambda: &[c64],
    vectors: faer::MatRef<'_, c64>,
    left: faer::MatRef<'_, c64>,
    params: &EigenParams,
    info: SolveInfo,
) -> Result<ComplexModes> {
    if !mu.is_finite() {
        return Err(Error::param("mu", format!("must be finite, got {mu}")));
    }
    if left.nrows() != op.dim() || left.ncols() != lambda.len() {
        return Err(Error::Dimension {
            context: "finish_modes: one left vector of the operator size per eigenvalue".into(),
            expected: lambda.len(),
            got: left.ncols(),
        });
    }
    finish_terms(
        &QepTerms::of_operator(op, mu),
        lambda,
        vectors,
        LeftSource::Given(left),
        params,
        info,
    )
}

/// Adds left eigenvectors, condition numbers and forward error estimates to modes of
/// `op` at `mu` that were computed without them (a full-order solve above
/// [`CONDITION_AUTO_MAX_DIM`], where
/// [`Condition::Auto`] skips them): the left vectors by [`left_eigenvectors`] on
/// `op.at(mu)` (one factorization of `Q(lambda)` per mode), then `cond` and
/// `error_bound` from the modes' own backward errors. Modes that already carry left
/// vectors are left as they are. The factorizations are counted in `info` and noted with
/// their time; `info.time_s` is not changed.
///
/// # Errors
/// A non-finite `mu`, modes whose vectors do not have the operator's size, or a failure
/// of the left solves.
pub fn add_condition(op: &FrictionalOperator, mu: f64, modes: &mut ComplexModes) -> Result<()> {
    if modes.left_vectors.is_some() {
        return Ok(());
    }
    if !mu.is_finite() {
        return Err(Error::param("mu", format!("must be finite, got {mu}")));
    }
    if modes.vectors.nrows() != op.dim() || modes.vectors.ncols() != modes.len() {
        return Err(Error::Dimension {
            context: "add_condition: one mode vector of the operator size per eigenvalue".into(),
            expected: op.dim(),
            got: modes.vectors.nrows(),
        });
    }
    let t = Instant::now();
    let qep = op.at(mu)?;
    let (y, how) = left_eigenvectors(&qep, &modes.lambda, modes.vectors.as_ref())?;
    let terms = QepTerms::of_operator(op, mu);
    let (cond, error_bound) = condition::condition_numbers(
        &terms,
        &terms.norms(),
        &modes.lambda,
        modes.vectors.as_ref(),
        y.as_ref(),
        &modes.backward_error,
    );
    modes.info.factorizations += how.factorizations;
    if !modes.is_empty() {
        modes.info.notes.push(format!(
            "left eigenvectors for cond, error_bound (asked for): {}{} factorizations of \
             Q(lambda), {:.3} s",
            if how.transposed_solve {
                "one dense solve of the transposed problem, "
            } else {
                ""
            },
            how.factorizations,
            t.elapsed().as_secs_f64()
        ));
    }
    modes.cond = cond;
    modes.error_bound = error_bound;
    modes.left_vectors = Some(y);
    Ok(())
}

fn finish_terms(
    qep: &QepTerms<'_>,
    lambda: &[c64],
    vectors: faer::MatRef<'_, c64>,
    left: LeftSource<'_>,
    params: &EigenParams,
    mut info: SolveInfo,
) -> Result<ComplexModes> {
    let n = qep.n;
    if vectors.nrows() != n {
        return Err(Error::Dimension {
            context: "finish_modes: rows of the mode vectors".into(),
            expected: n,
            got: vectors.nrows(),
        });
    }
    if vectors.ncols() != lambda.len() {
        return Err(Error::Dimension {
            context: "finish_modes: one vector per eigenvalue".into(),
            expected: lambda.len(),
            got: vectors.ncols(),
        });
    }
    let keep = band_pairs(lambda, params);
    let norms = qep.norms();
    let mut out = Mat::<c64>::zeros(n, keep.len());
    let (mut lam, mut freq, mut dvr) = (vec![], vec![], vec![]);
    for (c, &(f, i)) in keep.iter().enumerate() {
        let l = lambda[i];
        let mut u: Vec<c64> = (0..n).map(|r| vectors[(r, i)]).collect();
        let (mut p, mut big) = (0, 0.0);
        for (r, v) in u.iter().enumerate() {
            if v.norm() > big {
                big = v.norm();
                p = r;
            }
        }
        let nrm = norm2_c(&u);
        if big > 0.0 {
            let phase = u[p].conj() / (big * nrm);
            u.iter_mut().for_each(|v| *v *= phase);
            u[p] = c64::new(u[p].norm(), 0.0);
        }
        for r in 0..n {
            out[(r, c)] = u[r];
        }
        lam.push(l);
        freq.push(f);
        dvr.push(l.re / l.im);
    }
    let be = backward_errors(qep, &norms, &lam, out.as_ref());
    let left = match left {
        LeftSource::None => None,
        LeftSource::Given(y) => Some(Mat::from_fn(n, keep.len(), |r, c| y[(r, keep[c].1)])),
        LeftSource::InverseIteration(q) => {
            let t = Instant::now();
            let (y, how) = left_eigenvectors(q, &lam, out.as_ref())?;
            info.factorizations += how.factorizations;
            if !lam.is_empty() {
                info.notes.push(format!(
                    "left eigenvectors for cond, error_bound: {}{} factorizations of \
                     Q(lambda) for inverse iteration, {:.3} s",
                    if how.transposed_solve {
                        "one dense solve of the transposed problem, "
                    } else {
                        ""
                    },
                    how.factorizations,
                    t.elapsed().as_secs_f64()
                ));
            }
            Some(y)
        }
    };
    let (cond, error_bound) = match &left {
        Some(y) => condition::condition_numbers(qep, &norms, &lam, out.as_ref(), y.as_ref(), &be),
        None => (vec![f64::NAN; lam.len()], vec![f64::NAN; lam.len()]),
    };
    Ok(ComplexModes {
        lambda: lam,
        vectors: out,
        freq_hz: freq,
        dvr,
        backward_error: be,
        cond,
        error_bound,
        left_vectors: left,
        info,
    })
}
