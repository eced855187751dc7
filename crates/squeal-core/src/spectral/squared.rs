//! The squared transformation of an undamped QEP ([`SquaredShift`]): `(lambda^2 M + K) u = 0`
//! is `(K - s M) u = 0` with `s = -lambda^2`, inverted at a real shift by a sparse LU or by
//! the Woodbury identity on a symmetric factor ([`crate::lowrank::Woodbury`]).

use super::{LinOp, RealOp, SpectralTransform};
use crate::linalg::{add_scaled, spmv_complex_split};
use crate::lowrank::{SymmetricShift, Woodbury};
use crate::operator::{check_qep, Qep};
use crate::{c64, Error, Result};
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Lu, SymbolicLu};
use faer::MatMut;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;

/// The cheaper spectral transformation of an undamped QEP (`C = 0`):
/// `(lambda^2 M + K) u = 0` is `(K - s M) u = 0` with `s = -lambda^2`, so
/// `OP = (K - sigma_s M)^-1 M` on `n`-vectors with a REAL shift `sigma_s` (a quarter of the
/// work and half the memory of the companion form's complex LU, on half the vector
/// length). `K - sigma_s M` is solved by a real sparse LU ([`lu`](Self::lu)) or, for a
/// frictional operator, by the Woodbury identity on a symmetric factor
/// ([`low_rank`](Self::low_rank), [`woodbury`](Self::woodbury)). Eigenvalues map back as
/// `s = sigma_s + 1/theta`, `lambda = i sqrt(s)` ([`lambda_of_s`](Self::lambda_of_s),
/// principal root, so `Im(lambda) >= 0`); the conjugate `s` gives the mirror mode
/// `-conj(lambda)`. Complex vectors are applied as two real columns.
pub struct SquaredShift<'a> {
    qep: &'a Qep,
    sigma: f64,
    solve: ShiftedSolve<'a>,
    applications: AtomicUsize,
}

/// How `K~ - sigma_s M~` is solved.
enum ShiftedSolve<'a> {
    Lu(Lu<usize, f64>),
    Woodbury(Woodbury<'a>),
}

fn undamped(qep: &Qep) -> Result<()> {
    if qep.c.is_some() {
        return Err(Error::Invalid(
            "the squared spectral transformation needs C = 0".into(),
        ));
    }
    Ok(())
}

impl<'a> SquaredShift<'a> {
    /// Factorizes `K - sigma_s M` by a sparse LU (real, non-symmetric in general).
    /// `qep.c` must be `None`.
    pub fn lu(qep: &'a Qep, sigma_s: f64) -> Result<Self> {
        check_qep(qep)?;
        undamped(qep)?;
        let n = qep.dim();
        let a = add_scaled(qep.k.as_ref(), 1.0, qep.m.as_ref(), -sigma_s)?;
        let what = || format!("K - s M (s = {sigma_s:.6e} (rad/s)^2, n = {n})");
        let sym = SymbolicLu::try_new(a.symbolic()).map_err(|e| Error::Factorization {
            what: what(),
            reason: crate::linalg::explain::generic(&e),
        })?;
        let lu = Lu::try_new_with_symbolic(sym, a.as_ref()).map_err(|e| Error::Factorization {
            what: what(),
            reason: crate::linalg::explain::lu(&e, n),
        })?;
        let mut y: Vec<f64> = (0..n).map(|i| 1.0 + 0.1 * (i as f64).sin()).collect();
        lu.solve_in_place(MatMut::from_column_major_slice_mut(&mut y, n, 1));
        if y.iter().any(|v| !v.is_finite()) {
            return Err(Error::Factorization {
                what: what(),
                reason: "numerically singular (is the shift an eigenvalue?)".into(),
            });
        }
        Ok(Self::with(qep, sigma_s, ShiftedSolve::Lu(lu)))
    }

    /// The transformation of `qep = op.at(mu)` (undamped) at the shift `shift.s()`
    /// through the low-rank structure ([`Woodbury::new`]).
    pub fn low_rank(qep: &'a Qep, shift: Arc<SymmetricShift>, mu: f64) -> Result<Self> {
        Self::woodbury(qep, Woodbury::new(qep, shift, mu)?)
    }

    /// The transformation of `qep` by a Woodbury solver built for it.
    pub fn woodbury(qep: &'a Qep, solver: Woodbury<'a>) -> Result<Self> {
        undamped(qep)?;
        if solver.shift().dim() != qep.dim() {
            return Err(Error::Dimension {
                context: "SquaredShift: a Woodbury solver of another size".into(),
                expected: qep.dim(),
                got: solver.shift().dim(),
            });
        }
        let sigma = solver.shift().s();
        Ok(Self::with(qep, sigma, ShiftedSolve::Woodbury(solver)))
    }

    fn with(qep: &'a Qep, sigma: f64, solve: ShiftedSolve<'a>) -> Self {
        Self {
            qep,
            sigma,
            solve,
            applications: AtomicUsize::new(0),
        }
    }

    /// `lambda = i sqrt(s)` of a point `s` of the shift plane.
    pub fn lambda_of_s(s: c64) -> c64 {
        c64::new(0.0, 1.0) * s.sqrt()
    }
}

impl SpectralTransform<c64> for SquaredShift<'_> {
    /// `sigma_s` in (rad/s)^2: `s = sigma_s + 1/theta`.
    fn shift(&self) -> c64 {
        c64::new(self.sigma, 0.0)
    }
    fn applications(&self) -> usize {
        self.applications.load(Ordering::Relaxed)
    }
}

impl SquaredShift<'_> {
    /// `B <- (K~ - sigma_s M~)^-1 B`.
    fn solve_in_place(&self, b: MatMut<'_, f64>) {
        match &self.solve {
            ShiftedSolve::Lu(lu) => lu.solve_in_place(b),
            ShiftedSolve::Woodbury(w) => w.solve_in_place(b),
        }
    }
}

impl RealOp for SquaredShift<'_> {
    fn real(&self) -> &dyn LinOp<f64> {
        self
    }
    fn complex(&self) -> &dyn LinOp<c64> {
        self
    }
}

impl LinOp<f64> for SquaredShift<'_> {
    fn dim(&self) -> usize {
        self.qep.dim()
    }

    fn apply(&self, x: &[f64], y: &mut [f64]) {
        let n = self.qep.dim();
        assert_eq!(x.len(), n, "SquaredShift::apply: x has the wrong length");
        assert_eq!(y.len(), n, "SquaredShift::apply: y has the wrong length");
        crate::linalg::spmv(self.qep.m.as_ref(), x, y);
        self.solve_in_place(MatMut::from_column_major_slice_mut(y, n, 1));
        self.applications.fetch_add(1, Ordering::Relaxed);
    }
}

impl LinOp<c64> for SquaredShift<'_> {
    fn dim(&self) -> usize {
        self.qep.dim()
    }

    fn apply(&self, x: &[c64], y: &mut [c64]) {
        let n = self.qep.dim();
        assert_eq!(x.len(), n, "SquaredShift::apply: x has the wrong length");
        assert_eq!(y.len(), n, "SquaredShift::apply: y has the wrong length");
        let mut b = spmv_complex_split(self.qep.m.as_ref(), x);
        self.solve_in_place(b.as_mut());
        for (i, v) in y.iter_mut().enumerate() {
            *v = c64::new(b[(i, 0)], b[(i, 1)]);
        }
        self.applications.fetch_add(1, Ordering::Relaxed);
    }
}
