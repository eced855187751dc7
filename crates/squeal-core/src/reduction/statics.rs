//! Static responses with one reused factorization ([`StaticSolver`]) and the
//! energy-norm residuals of reduced modes ([`energy_residuals`]).

use super::{friction_load_directions, PairSolves, TiedSolve};
use crate::linalg::{add_scaled, BlockSolve, Cholesky};
use crate::linalg::{spmv_complex, symmetric_times};
use crate::operator::FrictionalOperator;
use crate::spectral::ShiftInvert;
use crate::{c64, Error, Result, SparseMat, SparseRef};
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
pub struct StaticSolver<'a> {
    factor: Backend<'a>,
    ks: Cow<'a, SparseMat>,
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
        let ks = add_scaled(op.kc.as_ref(), 1.0, op.mc.as_ref(), shift)?;
        let factor = Cholesky::new(ks.as_ref(), "K_c + shift M_c (static responses)")?;
        Ok(Self {
            factor: Backend::Factor(factor),
            ks: Cow::Owned(ks),
            shift,
            time_s: start.elapsed().as_secs_f64(),
            method: "K_c factorization".into(),
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
        self.solve_in_place(u.as_mut());
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

    /// The matrix `K_s` this solver solves with.
    pub fn matrix(&self) -> SparseRef<'_> {
        self.ks.as_ref().as_ref()
    }
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
