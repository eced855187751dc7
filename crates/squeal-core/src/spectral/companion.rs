//! The shift-invert transformation of a QEP in companion form at a complex shift
//! ([`QepShiftInvert`], on a reusable symbolic analysis [`QepSymbolic`]).

use super::{LinOp, SpectralTransform};
use crate::linalg::{spmv_complex, spmv_complex_add};
use crate::operator::{check_qep, FrictionalOperator, Qep};
use crate::{c64, Error, Result, SparseMat, SparseRef};
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Lu, SymbolicLu};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat, Triplet};
use faer::MatMut;
use std::sync::atomic::{AtomicUsize, Ordering};

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
            reason: crate::linalg::explain::generic(&e),
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
                reason: crate::linalg::explain::lu(&e, n),
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

    /// The problem it was built for.
    pub fn qep(&self) -> &Qep {
        self.qep
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

impl SpectralTransform<c64> for QepShiftInvert<'_> {
    /// The shift `sigma` (rad/s); `lambda = sigma + 1/theta`.
    fn shift(&self) -> c64 {
        self.sigma
    }
    fn applications(&self) -> usize {
        self.applications.load(Ordering::Relaxed)
    }
}

impl LinOp<c64> for QepShiftInvert<'_> {
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
