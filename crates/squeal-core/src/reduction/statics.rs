//! Static responses with one reused factorization ([`StaticSolver`]) and the
//! energy-norm residuals of reduced modes ([`energy_residuals`]).

use super::{friction_load_directions, real_mode_pair, PairSolves, TiedSolve};
use crate::linalg::{add_scaled, BlockSolve, Cholesky};
use crate::linalg::{spmv_complex, symmetric_times};
use crate::operator::FrictionalOperator;
use crate::spectral::ShiftInvert;
use crate::{c64, Error, Result, SparseMat, SparseRef};
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Lu, SymbolicLu};
use faer::{Mat, MatRef};
use std::borrow::Cow;
use std::time::Instant;

/// How a [`StaticSolver`] solves.
enum Backend<'a> {
    /// A factorization of `K_s`.
    Factor(Cholesky),
    /// The free model's factor and the ties of the contact set.
    Tied(TiedSolve<'a>),
}

impl BlockSolve for Backend<'_> {
    fn solve_block(&self, b: faer::MatMut<'_, f64>) {
        match self {
            Self::Factor(f) => f.solve_block(b),
            Self::Tied(t) => t.solve_block(b),
        }
    }
}

/// Static responses `K_s^-1 R` with `K_s = K_c + shift M_c` (`shift` in (rad/s)^2,
/// `>= 0`): factorized once (sparse Cholesky, [`StaticSolver::new`]), or, at shift 0,
/// solved through the free model's factor and the pairs of the contact set
/// ([`StaticSolver::tied`]).
///
/// `K_c`, `M_c` here are the operator's real-mode pair ([`real_mode_pair`]): the
/// operator's own for a scene, else the pair its directory names or its symmetric
/// parts shifted definite. The responses to the friction loads
/// ([`friction_statics`](Self::friction_statics)) of an operator that is not its own pair
/// are solved with the operator's own stiffness `K_c` (a sparse LU of the
/// non-symmetric matrix, built on first use), since they are the static deformation of
/// that stiffness; the real modes and [`solve_in_place`](Self::solve_in_place) (the
/// residue method's energy-norm residuals) use the pair.
pub struct StaticSolver<'a> {
    factor: Backend<'a>,
    ks: Cow<'a, SparseMat>,
    /// Whether `K_s` is the operator's own stiffness (its friction statics solve with it).
    own: bool,
    /// The sparse LU of the operator's own `K_c`, for the friction statics of an operator
    /// that is not its own pair (built on first use).
    own_lu: std::sync::OnceLock<std::result::Result<Lu<usize, f64>, String>>,
    /// The shift (rad/s)^2.
    pub shift: f64,
    /// Set-up time (s): the factorization, or the Schur complement of the tied solve.
    pub time_s: f64,
    /// How `K_s` is solved, for a basis's note.
    pub method: String,
}

impl<'a> StaticSolver<'a> {
    /// Factorizes `K_c + shift M_c`.
    pub fn new(op: &FrictionalOperator, shift: f64) -> Result<Self> {
        let start = Instant::now();
        if !(shift.is_finite() && shift >= 0.0) {
            return Err(Error::param(
                "shift",
                format!("static shift must be finite and >= 0 (rad/s)^2, got {shift}"),
            ));
        }
        let pair = real_mode_pair(op)?;
        let ks = add_scaled(pair.k, 1.0, pair.m, shift)?;
        let what = if pair.own {
            "K_c + shift M_c (static responses)".to_string()
        } else {
            format!("K_s + shift M_s of the real-mode pair ({})", pair.source)
        };
        let factor = Cholesky::new(ks.as_ref(), &what)?;
        let method = if pair.own {
            "K_c factorization".to_string()
        } else {
            format!(
                "real modes and static solves of the real-mode pair ({}; Cholesky \
                 factorization)",
                pair.source
            )
        };
        Ok(Self {
            factor: Backend::Factor(factor),
            ks: Cow::Owned(ks),
            own: pair.own,
            own_lu: std::sync::OnceLock::new(),
            shift,
            time_s: start.elapsed().as_secs_f64(),
            method,
        })
    }

    /// Solves with `K_c` (shift 0) of the contact set of `op` through the free model's
    /// `pairs` ([`PairSolves::on`]): no factorization of its own.
    pub fn tied(op: &'a FrictionalOperator, pairs: &'a PairSolves) -> Result<Self> {
        let start = Instant::now();
        let solve = pairs.on(op)?;
        let method = format!(
            "K_c solved through the free model's factor ({} tied pairs)",
            solve.active_pairs()
        );
        Ok(Self {
            factor: Backend::Tied(solve),
            ks: Cow::Borrowed(&op.kc),
            own: true,
            own_lu: std::sync::OnceLock::new(),
            shift: 0.0,
            time_s: start.elapsed().as_secs_f64(),
            method,
        })
    }

    /// The tied solve behind this solver, when it solves through the free model's pairs
    /// ([`tied`](Self::tied)).
    pub fn tied_solve(&self) -> Option<&TiedSolve<'a>> {
        match &self.factor {
            Backend::Tied(t) => Some(t),
            Backend::Factor(_) => None,
        }
    }

    /// [`tied`](Self::tied) when the basis has the free model's `pairs` (its model stage)
    /// and `shift` is 0, else [`new`](Self::new).
    pub fn tied_or_new(
        op: &'a FrictionalOperator,
        pairs: Option<&'a PairSolves>,
        shift: f64,
    ) -> Result<Self> {
        match pairs {
            Some(p) if shift == 0.0 && op.t.is_some() => Self::tied(op, p),
            _ => Self::new(op, shift),
        }
    }

    /// `R <- K_s^-1 R` for a block of right-hand sides.
    pub fn solve_in_place(&self, r: faer::MatMut<'_, f64>) {
        self.factor.solve_block(r);
    }

    /// The static responses to the friction loads `K_s^-1 U` (`U`: the operator's friction
    /// load directions, [`friction_load_directions`]) and whether they came from the free
    /// model's kept responses to the pairs' friction loads
    /// ([`TiedSolve::friction_statics`]: no solve of the whole block) rather than a solve.
    pub fn friction_statics(&self, op: &FrictionalOperator) -> Result<(Mat<f64>, bool)> {
        if let (Backend::Tied(tied), Some(u)) = (&self.factor, &op.friction_loads) {
            if let Some(x) = tied.friction_statics(u.as_ref()) {
                return Ok((x, true));
            }
        }
        let mut u = friction_load_directions(op)?;
        if self.own {
            self.solve_in_place(u.as_mut());
        } else {
            let lu = self
                .own_lu
                .get_or_init(|| own_lu(op).map_err(|e| e.to_string()))
                .as_ref()
                .map_err(|e| Error::Invalid(e.clone()))?;
            lu.solve_in_place(u.as_mut());
        }
        Ok((u, false))
    }

    /// The shift-invert operator `(K_c + shift M_c)^-1 M_c` (`sigma = -shift`) on this
    /// solver's factorization, for the real modes of `(K_c, M_c)` by
    /// [`super::coupled_real_modes_on`]: `m` must be the operator's `M_c`.
    pub fn shift_invert<'s>(&'s self, m: SparseRef<'s>) -> Result<ShiftInvert<'s>> {
        if m.nrows() != self.ks.nrows() || m.ncols() != self.ks.ncols() {
            return Err(Error::Dimension {
                context: "static solver: M_c of the shift-invert operator".into(),
                expected: self.ks.nrows(),
                got: m.nrows(),
            });
        }
        Ok(ShiftInvert::with_factor(
            m,
            -self.shift,
            self.ks.as_ref().as_ref(),
            &self.factor,
        ))
    }

    /// Whether `K_s` is the operator's own `K_c` (plus `shift M_c`): a scene's operator,
    /// not a real-mode pair of its own ([`real_mode_pair`]).
    pub fn is_own(&self) -> bool {
        self.own
    }

    /// The matrix `K_s` this solver solves with.
    pub fn matrix(&self) -> SparseRef<'_> {
        self.ks.as_ref().as_ref()
    }
}

/// The sparse LU of the operator's own (non-symmetric) `K_c`, checked on a probe solve.
fn own_lu(op: &FrictionalOperator) -> Result<Lu<usize, f64>> {
    let n = op.dim();
    let what = || format!("K_c of the operator (n = {n}, sparse LU for the friction statics)");
    let sym = SymbolicLu::try_new(op.kc.symbolic()).map_err(|e| Error::Factorization {
        what: what(),
        reason: crate::linalg::explain::generic(&e),
    })?;
    let lu = Lu::try_new_with_symbolic(sym, op.kc.as_ref()).map_err(|e| Error::Factorization {
        what: what(),
        reason: crate::linalg::explain::lu(&e, n),
    })?;
    let mut y: Vec<f64> = (0..n).map(|i| 1.0 + 0.1 * (i as f64).sin()).collect();
    lu.solve_in_place(faer::MatMut::from_column_major_slice_mut(&mut y, n, 1));
    if y.iter().any(|v| !v.is_finite()) {
        return Err(Error::Factorization {
            what: what(),
            reason: "numerically singular: the operator's stiffness has no static solution \
                     (unrestrained rigid-body motions?)"
                .into(),
        });
    }
    Ok(lu)
}

/// Residual of the reduced modes `(lambda_j, u_j = V q_j)` on the full `qep`, in the
/// energy norm of `K_s` ([`StaticSolver`]): `d_j = K_s^-1 r_j`, `r_j = Q(lambda_j) u_j`,
/// `eps_j = sqrt(d_j^H K_s d_j) / sqrt(u_j^H K_s u_j)`. Returns the `eps_j` and the
/// static responses `d_j` (complex, one column each).
pub fn energy_residuals(
    qep: &crate::operator::Qep,
    ks: &StaticSolver,
    lambda: &[c64],
    u: MatRef<'_, c64>,
) -> (Vec<f64>, Mat<c64>) {
    let n = qep.dim();
    let k = lambda.len();
    let mut rr = Mat::<f64>::zeros(n, 2 * k);
    let (mut t, mut s) = (vec![c64::new(0.0, 0.0); n], vec![c64::new(0.0, 0.0); n]);
    for (j, &l) in lambda.iter().enumerate() {
        let uj: Vec<c64> = (0..n).map(|r| u[(r, j)]).collect();
        // r = K u + l (C u + l M u)
        spmv_complex(qep.m.as_ref(), &uj, &mut t);
        t.iter_mut().for_each(|v| *v *= l);
        if let Some(c) = &qep.c {
            spmv_complex(c.as_ref(), &uj, &mut s);
            t.iter_mut().zip(&s).for_each(|(a, b)| *a += *b);
        }
        t.iter_mut().for_each(|v| *v *= l);
        spmv_complex(qep.k.as_ref(), &uj, &mut s);
        for r in 0..n {
            let v = t[r] + s[r];
            rr[(r, 2 * j)] = v.re;
            rr[(r, 2 * j + 1)] = v.im;
        }
    }
    let ur = Mat::from_fn(n, 2 * k, |r, c| {
        let z = u[(r, c / 2)];
        if c % 2 == 0 {
            z.re
        } else {
            z.im
        }
    });
    let ksu = symmetric_times(ks.matrix(), ur.as_ref());
    energy_norms(ks, rr, ur.as_ref(), ksu.as_ref())
}

/// The energy-norm residuals from the residuals `rr` and the vectors `ur` with their
/// images `ksu = K_s ur`, all `n x 2k` (real and imaginary parts of mode `j` in columns
/// `2j` and `2j + 1`): `eps_j` and `d_j = K_s^-1 r_j` (see [`energy_residuals`]).
pub(super) fn energy_norms(
    ks: &StaticSolver,
    rr: Mat<f64>,
    ur: MatRef<'_, f64>,
    ksu: MatRef<'_, f64>,
) -> (Vec<f64>, Mat<c64>) {
    let (n, k) = (rr.nrows(), rr.ncols() / 2);
    let mut d = rr.clone();
    ks.solve_in_place(d.as_mut());
    let mut eps = Vec::with_capacity(k);
    for j in 0..k {
        let num: f64 = (0..n)
            .map(|r| rr[(r, 2 * j)] * d[(r, 2 * j)] + rr[(r, 2 * j + 1)] * d[(r, 2 * j + 1)])
            .sum();
        let den: f64 = (0..n)
            .map(|r| ur[(r, 2 * j)] * ksu[(r, 2 * j)] + ur[(r, 2 * j + 1)] * ksu[(r, 2 * j + 1)])
            .sum();
        eps.push(if den > 0.0 {
            (num.max(0.0) / den).sqrt()
        } else {
            f64::INFINITY
        });
    }
    let dc = Mat::from_fn(n, k, |r, j| c64::new(d[(r, 2 * j)], d[(r, 2 * j + 1)]));
    (eps, dc)
}
