//! Krylov-Schur (Stewart 2001) in complex arithmetic for the eigenvalues of largest
//! modulus of a general (non-Hermitian) operator: the kernel of the `"krylov"` backend for
//! the frictional quadratic eigenproblem (run by [`squeal_core::qep::solve_qep_band`] on
//! the shift-invert operator of the companion form).
//!
//! ## Krylov decomposition
//!
//! The active part of the method is an orthonormal basis `V_m` (`V_m^H V_m = I`), an
//! `m x m` projected matrix `H` and a residual `f = beta v_{m+1}` with
//!
//! ```text
//! OP V_m = Q_L G + V_m H + beta v_{m+1} e_m^T,      [Q_L V_m v_{m+1}] orthonormal,
//! ```
//!
//! where `Q_L` (`p` columns) is the *locked* basis: an orthonormal basis of the invariant
//! subspace spanned by the eigenvectors converged so far (`OP Q_L ~ Q_L T_L`, `T_L` upper
//! triangular). `H` is the projection of the deflated operator `(I - Q_L Q_L^H) OP`,
//! whose spectrum is that of `OP` without the locked eigenvalues, so the eigenvalues of
//! `H` approximate the next ones. For an eigenpair `H y = theta y` (`||y|| = 1`) the
//! vector `x = Q_L z + V_m y` with `(T_L - theta) z = -G y` is a Ritz vector of `OP` with
//! residual exactly `||OP x - theta x|| = beta |y_m|`, so a pair is accepted when
//!
//! ```text
//! beta |e_m^T y| <= tol |theta|.
//! ```
//!
//! **Expansion** is Arnoldi with full reorthogonalization: every new vector `OP v_j` is
//! orthogonalized against `Q_L` and all of `V_j` by classical Gram-Schmidt applied twice
//! (a third pass when less than `1e-6` of its norm survives), the coefficients against
//! `V_j` forming column `j` of `H`. A breakdown (`beta <= 1e-12 ||OP v_j||`) means an
//! invariant subspace: the coupling is set to zero and the iteration continues from a new
//! deterministic pseudo-random vector orthogonal to everything held.
//!
//! ## Restart (Krylov-Schur) and locking
//!
//! The basis holds `ncv = min(n - p, max(2 nev + 1, nev + 16))` vectors. When it is full,
//! the eigenvalues of `H` are computed (faer's dense complex `eigen`), and `keep =
//! want + (ncv - want) / 2` of them are selected: first the converged wanted ones, then
//! the unconverged wanted ones (largest modulus first), then the next largest. An
//! orthonormal basis `Z_k` of the `H`-invariant subspace belonging to the selected
//! eigenvalues is built column by column as in the constructive proof of Schur's theorem
//! (faer does not expose an ordered complex Schur form): for each selected `sigma_j`,
//! an eigenvector `x` of the trailing block `W_22` of the current `W = Z^H H Z` is
//! computed (shifted inverse iteration started from the transformed Ritz vector, dense
//! `eigen` of the block as fallback), and a Householder reflector with first column
//! `x` is applied to `W` and `Z`. Since `W_22 x - (x^H W_22 x) x` is a residual of
//! rounding size, dropping the new sub-diagonal block is a backward-stable deflation,
//! also for repeated and nearly repeated eigenvalues (where individual eigenvectors of
//! `H` are ill-determined, but the invariant subspace is not). Then
//!
//! ```text
//! OP (V_m Z_k) = Q_L (G Z_k) + (V_m Z_k) T_k + v_{m+1} (beta e_m^T Z_k),
//! ```
//!
//! `T_k = Z_k^H H Z_k` upper triangular: a Krylov decomposition with a general coupling
//! row, which is all Krylov-Schur needs. The leading `c` columns (the converged wanted
//! pairs) are **locked**: appended to `Q_L` and their coupling dropped (a perturbation of
//! size `beta |e_m^T y| <= tol |theta|` per eigenvector, the Ritz residual); the other
//! `keep - c` columns stay active with `H <- T_k[c.., c..]`, the coupling row
//! `beta e_m^T Z_k[:, c..]` as the next row of `H`, and `v_{m+1}` as the next basis
//! vector, from which Arnoldi resumes.
//!
//! ## Repeated eigenvalues: validation runs
//!
//! The Krylov space of one start vector contains a single direction of every eigenspace,
//! so one copy of an exactly repeated eigenvalue (a disc doublet) is invisible to it in
//! exact arithmetic. After the first run has locked `nev` pairs, a *validation run* is
//! started from a fresh vector orthogonal to `Q_L`: it works on the deflated operator and
//! stops as soon as its largest converged Ritz value lies below the `nev`-th largest
//! locked modulus (nothing was missed); pairs above it are locked too and the validation
//! is repeated. Each round exposes one more copy, so every multiplicity is resolved (as in
//! the Lanczos kernel of this crate).
//!
//! ## Output and verification
//!
//! At the end, `OP Q_L` is formed (`p` operator applications) and `T_L = Q_L^H OP Q_L`;
//! its strictly lower part (of the order of the dropped couplings) is discarded. The
//! eigenvalues are the diagonal of `T_L` (Rayleigh quotients of the Schur vectors), the
//! eigenvectors `x = Q_L w` with `w` from back-substitution on `T_L`. When a pivot
//! `T_ii - theta` is below `1e-8 |theta|` *and* the right-hand side is below
//! `tol |theta| ||w||`, the pair is a copy of a semisimple repeated eigenvalue and
//! `w_i = 0` is chosen (otherwise ill-determined: `0 / 0`), so the copies get
//! independent eigenvectors. Every pair's true residual `||OP x - theta x||` is computed;
//! pairs above `100 tol |theta|` (plus a rounding floor) are dropped and the call then
//! reports `all_converged = false`. The `nev` largest in modulus are returned, sorted by
//! decreasing modulus, with unit-norm vectors.
//!
//! ## Budget, small problems
//!
//! `max_restarts` caps the restarts summed over all runs of one call (the start of each
//! validation run counts as one); when it is hit, the converged pairs are returned with
//! `all_converged = false` (never an error). Start vectors are deterministic.
//!
//! **`nev >= n` uses a dense fallback**: the operator is formed column by column (`n`
//! applications) and all `n` eigenpairs are computed by faer's dense complex `eigen`,
//! for `n <= 4096` (an error beyond, where asking for every eigenvalue of a matrix-free
//! operator is a mistake).
//!
//! ## References
//!
//! - G. W. Stewart, *A Krylov-Schur algorithm for large eigenproblems*, SIAM J. Matrix
//!   Anal. Appl. 23(3), 601-614, 2001.
//! - V. Hernandez, J. E. Roman, A. Tomas, *Krylov-Schur methods in SLEPc*, SLEPc
//!   technical report STR-7, 2007.
//! - R. B. Lehoucq, D. C. Sorensen, C. Yang, *ARPACK Users' Guide*, SIAM, 1998.

use super::{
    par_for, Directions, BREAKDOWN, CHECK_EVERY, NEW_DIRECTION_MIN, NEW_DIRECTION_TRIES, THIRD_PASS,
};
use squeal_core::faer::linalg::matmul::matmul;
use squeal_core::faer::linalg::solvers::Solve;
use squeal_core::faer::{Accum, Mat, MatMut, MatRef};
use squeal_core::qep::{ComplexKernel, ComplexKernelOutput, ComplexLinOp};
use squeal_core::{c64, Error, Result};

#[cfg(test)]
#[path = "schur_tests.rs"]
mod tests;

/// Largest problem for the dense fallback used when `nev >= n`.
pub const DENSE_MAX: usize = 4096;
/// Verified residuals above this multiple of `tol |theta|` reject a pair.
const VERIFY_FACTOR: f64 = 100.0;
/// Pivots below this fraction of `|theta|` may mark a copy of a repeated eigenvalue.
const REPEAT_REL: f64 = 1e-8;
/// Inverse-iteration steps in the Schur deflation before the dense fallback.
const INVERSE_STEPS: usize = 3;
/// Accepted deflation residual, in units of `eps ||H||_F`.
const DEFLATION_ACCEPT: f64 = 1e3;

const ONE: c64 = c64 { re: 1.0, im: 0.0 };
const ZERO: c64 = c64 { re: 0.0, im: 0.0 };

/// Krylov-Schur for the `nev` eigenvalues of largest modulus of a general complex
/// operator, with full reorthogonalization, locking and validation runs for repeated
/// eigenvalues (see the module docs for the method).
#[derive(Debug, Clone, Copy, Default)]
pub struct KrylovSchurKernel;

impl ComplexKernel for KrylovSchurKernel {
    fn largest(
        &self,
        op: &dyn ComplexLinOp,
        nev: usize,
        tol: f64,
        max_restarts: usize,
    ) -> Result<ComplexKernelOutput> {
        if !(tol.is_finite() && tol > 0.0 && tol < 1.0) {
            return Err(Error::param(
                "tol",
                format!("relative tolerance must be in (0, 1), got {tol}"),
            ));
        }
        let n = op.dim();
        if nev == 0 || n == 0 {
            return Ok(ComplexKernelOutput {
                theta: Vec::new(),
                vectors: Mat::zeros(n, 0),
                iterations: 0,
                all_converged: true,
            });
        }
        if nev >= n {
            return dense_fallback(op, nev);
        }
        let start: Vec<c64> = (0..n)
            .map(|i| {
                let t = i as f64;
                c64::new(1.0 + 0.1 * t.sin(), 0.1 * (0.7 * t).cos())
            })
            .collect();
        let mut ctx = Ctx {
            op,
            tol,
            max_restarts,
            restarts: 0,
            dirs: Directions::new(),
            locked: Vec::new(),
            locked_theta: Vec::new(),
        };

        // First run: the nev largest eigenvalues seen by one Krylov space.
        let first = ctx.run(nev, start, None)?;
        if !first.complete {
            return ctx.finish(nev, false);
        }

        // Validation runs on the deflated operator: anything larger than the nev-th
        // locked modulus (a missed copy of a repeated eigenvalue) is locked too.
        let margin = (10.0 * tol).clamp(1e-10, 1e-4);
        loop {
            if ctx.p() >= n {
                return ctx.finish(nev, true);
            }
            if ctx.restarts >= ctx.max_restarts {
                return ctx.finish(nev, false);
            }
            ctx.restarts += 1;
            let floor = ctx.nth_locked_modulus(nev) * (1.0 + margin);
            let start = complex_random(&mut ctx.dirs, n);
            let check = ctx.run(nev, start, Some(floor))?;
            if check.found == 0 || !check.complete {
                return ctx.finish(nev, check.complete);
            }
        }
    }
}

/// `nev >= n`: every eigenpair of the operator, densely.
fn dense_fallback(op: &dyn ComplexLinOp, nev: usize) -> Result<ComplexKernelOutput> {
    let n = op.dim();
    if n > DENSE_MAX {
        return Err(Error::param(
            "nev",
            format!(
                "krylov: nev = {nev} >= n = {n} asks for every eigenvalue; the dense \
                 fallback is limited to n <= {DENSE_MAX}"
            ),
        ));
    }
    let mut a = Mat::<c64>::zeros(n, n);
    let mut e = vec![ZERO; n];
    let mut col = vec![ZERO; n];
    for j in 0..n {
        e[j] = ONE;
        op.apply(&e, &mut col);
        e[j] = ZERO;
        for i in 0..n {
            a[(i, j)] = col[i];
        }
    }
    let eig = a
        .eigen()
        .map_err(|e| Error::Invalid(format!("krylov: dense eigen fallback: {e:?}")))?;
    let s = eig.S();
    let u = eig.U();
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&i, &j| s[j].norm().total_cmp(&s[i].norm()));
    let theta = order.iter().map(|&i| s[i]).collect();
    let vectors = Mat::from_fn(n, n, |i, c| u[(i, order[c])]);
    let vectors = normalized_columns(vectors);
    Ok(ComplexKernelOutput {
        theta,
        vectors,
        iterations: 0,
        all_converged: true,
    })
}

/// Deterministic pseudo-random complex vector.
fn complex_random(dirs: &mut Directions, n: usize) -> Vec<c64> {
    let re = dirs.vector(n);
    let im = dirs.vector(n);
    re.into_iter()
        .zip(im)
        .map(|(a, b)| c64::new(a, b))
        .collect()
}

/// `sum conj(a_i) b_i`.
fn cdot(a: &[c64], b: &[c64]) -> c64 {
    a.iter().zip(b).fold(ZERO, |s, (x, y)| s + x.conj() * y)
}

/// Euclidean norm.
fn cnorm(a: &[c64]) -> f64 {
    a.iter().map(|x| x.norm_sqr()).sum::<f64>().sqrt()
}

fn scale(a: &mut [c64], s: f64) {
    a.iter_mut().for_each(|x| *x *= s);
}

fn frobenius(a: MatRef<'_, c64>) -> f64 {
    let mut s = 0.0;
    for j in 0..a.ncols() {
        for i in 0..a.nrows() {
            s += a[(i, j)].norm_sqr();
        }
    }
    s.sqrt()
}

fn normalized_columns(mut a: Mat<c64>) -> Mat<c64> {
    for j in 0..a.ncols() {
        let nrm = (0..a.nrows())
            .map(|i| a[(i, j)].norm_sqr())
            .sum::<f64>()
            .sqrt();
        if nrm > 0.0 {
            for i in 0..a.nrows() {
                a[(i, j)] *= 1.0 / nrm;
            }
        }
    }
    a
}

/// `Q Y` for a column-major `n x q` block and a dense `q x c` matrix.
fn times(q: MatRef<'_, c64>, y: MatRef<'_, c64>) -> Mat<c64> {
    let mut out = Mat::<c64>::zeros(q.nrows(), y.ncols());
    matmul(
        out.as_mut(),
        Accum::Replace,
        q,
        y,
        ONE,
        par_for(q.nrows() * q.ncols() * y.ncols()),
    );
    out
}

/// One classical Gram-Schmidt pass: `c = Q^H w`, `w <- w - Q c`. Adds `c` to `acc` (when
/// given) and returns `||c||^2`.
fn cgs_pass(w: &mut [c64], q: MatRef<'_, c64>, acc: Option<&mut [c64]>) -> f64 {
    let k = q.ncols();
    if k == 0 {
        return 0.0;
    }
    let n = w.len();
    let par = par_for(n * k);
    let mut c = vec![ZERO; k];
    matmul(
        MatMut::from_column_major_slice_mut(&mut c, k, 1),
        Accum::Replace,
        q.adjoint(),
        MatRef::from_column_major_slice(w, n, 1),
        ONE,
        par,
    );
    matmul(
        MatMut::from_column_major_slice_mut(w, n, 1),
        Accum::Add,
        q,
        MatRef::from_column_major_slice(&c, k, 1),
        -ONE,
        par,
    );
    if let Some(acc) = acc {
        acc.iter_mut().zip(&c).for_each(|(a, ci)| *a += ci);
    }
    c.iter().map(|x| x.norm_sqr()).sum()
}

/// The Arnoldi basis (`cap` columns), column-major.
struct Basis {
    n: usize,
    v: Vec<c64>,
}

impl Basis {
    fn new(n: usize, cap: usize) -> Self {
        Self {
            n,
            v: vec![ZERO; n * cap],
        }
    }

    fn v(&self, cols: usize) -> MatRef<'_, c64> {
        MatRef::from_column_major_slice(&self.v[..cols * self.n], self.n, cols)
    }

    fn col(&self, j: usize) -> &[c64] {
        &self.v[j * self.n..(j + 1) * self.n]
    }

    fn set(&mut self, j: usize, x: &[c64]) {
        let n = self.n;
        self.v[j * n..(j + 1) * n].copy_from_slice(x);
    }

    fn copy_col(&mut self, from: usize, to: usize) {
        let n = self.n;
        self.v.copy_within(from * n..(from + 1) * n, to * n);
    }
}

/// Rayleigh-Ritz analysis of the current projected matrix.
struct Ritz {
    /// Ritz values.
    theta: Vec<c64>,
    /// Unit eigenvectors of `H` (columns).
    y: Mat<c64>,
    /// All indices by decreasing modulus.
    order: Vec<usize>,
    /// The wanted pairs (a prefix of `order`).
    wanted: usize,
    /// Convergence flag of each pair.
    converged: Vec<bool>,
    /// The basis is too small to hold every wanted pair.
    short: bool,
}

impl Ritz {
    fn wanted(&self) -> &[usize] {
        &self.order[..self.wanted]
    }

    /// Every wanted pair present and converged.
    fn done(&self) -> bool {
        !self.short && self.all_converged()
    }

    /// Every wanted pair the basis holds is converged.
    fn all_converged(&self) -> bool {
        self.wanted().iter().all(|&i| self.converged[i])
    }

    /// Converged wanted pairs that may be locked (above the floor, if any).
    fn lockable(&self, floor: Option<f64>) -> Vec<usize> {
        self.wanted()
            .iter()
            .copied()
            .filter(|&i| self.converged[i] && floor.is_none_or(|f| self.theta[i].norm() > f))
            .collect()
    }
}

/// Result of one run.
struct RunOut {
    /// Pairs locked by the run.
    found: usize,
    /// Whether every wanted pair converged.
    complete: bool,
}

/// State shared by the runs of one [`KrylovSchurKernel::largest`] call.
struct Ctx<'o> {
    op: &'o dyn ComplexLinOp,
    tol: f64,
    max_restarts: usize,
    restarts: usize,
    dirs: Directions,
    /// Locked orthonormal Schur vectors, column-major.
    locked: Vec<c64>,
    /// Ritz values at locking time.
    locked_theta: Vec<c64>,
}

impl Ctx<'_> {
    fn n(&self) -> usize {
        self.op.dim()
    }

    fn p(&self) -> usize {
        self.locked_theta.len()
    }

    fn locked_mat(&self) -> MatRef<'_, c64> {
        MatRef::from_column_major_slice(&self.locked, self.n(), self.p())
    }

    /// The `nev`-th largest locked modulus (the smallest if fewer are locked).
    fn nth_locked_modulus(&self, nev: usize) -> f64 {
        let mut m: Vec<f64> = self.locked_theta.iter().map(|t| t.norm()).collect();
        m.sort_by(|a, b| b.total_cmp(a));
        m.get(nev.min(m.len()).saturating_sub(1))
            .copied()
            .unwrap_or(0.0)
    }

    /// Orthogonalizes `w` against the locked vectors and the first `nb` basis vectors
    /// (`passes` classical Gram-Schmidt passes). Returns the basis coefficients summed
    /// over the passes and `||c||^2` of the first pass.
    fn orthogonalize(
        &self,
        w: &mut [c64],
        basis: &Basis,
        nb: usize,
        passes: usize,
    ) -> (Vec<c64>, f64) {
        let mut h = vec![ZERO; nb];
        let mut first = 0.0;
        for pass in 0..passes {
            let removed =
                cgs_pass(w, self.locked_mat(), None) + cgs_pass(w, basis.v(nb), Some(&mut h));
            if pass == 0 {
                first = removed;
            }
        }
        (h, first)
    }

    /// Makes `x` a unit vector orthogonal to the locked vectors and the first `nb` basis
    /// vectors; on collapse, tries fresh pseudo-random vectors. `None` when the
    /// complement is numerically exhausted.
    fn new_direction(&mut self, mut x: Vec<c64>, basis: &Basis, nb: usize) -> Option<Vec<c64>> {
        let n = x.len();
        for _ in 0..NEW_DIRECTION_TRIES {
            let before = cnorm(&x);
            if before > 0.0 && before.is_finite() {
                self.orthogonalize(&mut x, basis, nb, 3);
                let after = cnorm(&x);
                if after > NEW_DIRECTION_MIN * before {
                    scale(&mut x, 1.0 / after);
                    return Some(x);
                }
            }
            x = complex_random(&mut self.dirs, n);
        }
        None
    }

    /// Rayleigh-Ritz on the leading `m x m` block of `h` with residual norm `beta`.
    fn ritz(
        &self,
        h: &Mat<c64>,
        m: usize,
        beta: f64,
        want: usize,
        floor: Option<f64>,
    ) -> Result<Ritz> {
        let eig = h
            .get(..m, ..m)
            .eigen()
            .map_err(|e| Error::Invalid(format!("krylov: projected eigenproblem: {e:?}")))?;
        let s = eig.S();
        let theta: Vec<c64> = (0..m).map(|i| s[i]).collect();
        if theta
            .iter()
            .any(|t| !(t.re.is_finite() && t.im.is_finite()))
        {
            return Err(Error::Invalid(
                "krylov: non-finite Ritz value: the operator is unusable".into(),
            ));
        }
        let y = normalized_columns(eig.U().to_owned());
        let converged: Vec<bool> = (0..m)
            .map(|i| beta * y[(m - 1, i)].norm() <= self.tol * theta[i].norm())
            .collect();
        let mut order: Vec<usize> = (0..m).collect();
        order.sort_by(|&i, &j| theta[j].norm().total_cmp(&theta[i].norm()));
        // Without a floor: the `want` largest. With one (validation): every Ritz value
        // above the floor plus the next one, which must converge below the floor.
        let count = match floor {
            None => want,
            Some(f) => (theta.iter().filter(|t| t.norm() > f).count() + 1).min(want),
        };
        Ok(Ritz {
            theta,
            y,
            order,
            wanted: count.min(m),
            converged,
            short: count > m,
        })
    }

    /// Locks the Schur vectors `V_m Z[:, ..c]` with Ritz values `theta`.
    fn lock(&mut self, basis: &Basis, m: usize, z: &Mat<c64>, theta: &[c64]) {
        let c = theta.len();
        if c == 0 {
            return;
        }
        let q = times(basis.v(m), z.get(.., ..c));
        for j in 0..c {
            self.locked.extend_from_slice(q.col_as_slice(j));
        }
        self.locked_theta.extend_from_slice(theta);
    }

    /// Locks the lockable pairs of `ritz` and ends the run.
    fn end_run(
        &mut self,
        basis: &Basis,
        h: &Mat<c64>,
        m: usize,
        ritz: &Ritz,
        floor: Option<f64>,
        found: usize,
        complete: bool,
    ) -> Result<RunOut> {
        let sel = ritz.lockable(floor);
        let targets: Vec<c64> = sel.iter().map(|&i| ritz.theta[i]).collect();
        let (z, _) = schur_deflate(h.get(..m, ..m), &targets, &ritz.y, &sel)?;
        self.lock(basis, m, &z, &targets);
        Ok(RunOut {
            found: found + sel.len(),
            complete,
        })
    }

    /// One Krylov-Schur run for the `want` largest eigenpairs of the operator deflated by
    /// the locked vectors, from `start`. With a `floor`, the run only has to find the
    /// pairs above it (and prove the next one lies below).
    fn run(&mut self, want: usize, start: Vec<c64>, floor: Option<f64>) -> Result<RunOut> {
        let op = self.op;
        let n = self.n();
        let dim = n.saturating_sub(self.p());
        let want = want.min(dim);
        let mut out = RunOut {
            found: 0,
            complete: true,
        };
        if want == 0 {
            return Ok(out);
        }
        let ncv = dim.min((2 * want + 1).max(want + 16));
        let mut basis = Basis::new(n, ncv + 1);
        let mut h = Mat::<c64>::zeros(ncv, ncv);
        match self.new_direction(start, &basis, 0) {
            Some(v) => basis.set(0, &v),
            None => return Ok(out),
        }
        let mut k = 0;
        let mut w = vec![ZERO; n];
        loop {
            let want_act = want - out.found;
            // The complement shrinks as pairs are locked.
            let cap = ncv.min(n - self.p());
            if k >= cap {
                // The active basis spans the whole complement: its Ritz pairs are exact.
                let r = self.ritz(&h, k, 0.0, want_act, floor)?;
                let complete = r.all_converged();
                return self.end_run(&basis, &h, k, &r, floor, out.found, complete);
            }
            // Expand the basis from k to cap vectors (or to an exhausted complement).
            let mut beta = 0.0;
            let mut ritz = None;
            for j in k..cap {
                op.apply(basis.col(j), &mut w);
                let (mut hc, first) = self.orthogonalize(&mut w, &basis, j + 1, 2);
                let mut b = cnorm(&w);
                let norm0 = (first + b * b).sqrt();
                if b < THIRD_PASS * norm0 && b > BREAKDOWN * norm0 {
                    let (h3, _) = self.orthogonalize(&mut w, &basis, j + 1, 1);
                    hc.iter_mut().zip(&h3).for_each(|(a, c)| *a += c);
                    b = cnorm(&w);
                }
                if !(b.is_finite() && hc.iter().all(|x| x.re.is_finite() && x.im.is_finite())) {
                    return Err(Error::Invalid(format!(
                        "krylov: non-finite Arnoldi coefficient at step {j} (beta = {b}): \
                         the operator is unusable"
                    )));
                }
                for (i, x) in hc.iter().enumerate() {
                    h[(i, j)] = *x;
                }
                let mut exhausted = false;
                let broke = b <= BREAKDOWN * norm0;
                if !broke {
                    scale(&mut w, 1.0 / b);
                    basis.set(j + 1, &w);
                    beta = b;
                } else {
                    // Invariant subspace: continue with a new direction, coupling 0.
                    beta = 0.0;
                    b = 0.0;
                    let fresh = complex_random(&mut self.dirs, n);
                    match self.new_direction(fresh, &basis, j + 1) {
                        Some(v) => basis.set(j + 1, &v),
                        None => exhausted = true,
                    }
                }
                if j + 1 < cap {
                    h[(j + 1, j)] = c64::new(b, 0.0);
                }
                // Early checks skip breakdown steps: an invariant subspace has exact Ritz
                // pairs that need not be the largest; the new direction may show more.
                let size = j + 1;
                if exhausted || size == cap || (!broke && (size - k) % CHECK_EVERY == 0) {
                    let r = self.ritz(&h, size, beta, want_act, floor)?;
                    if r.done() || exhausted {
                        let complete = r.all_converged();
                        return self.end_run(&basis, &h, size, &r, floor, out.found, complete);
                    }
                    if size == cap {
                        ritz = Some(r);
                    }
                }
            }
            let m = cap;
            let ritz = match ritz {
                Some(r) => r,
                None => self.ritz(&h, m, beta, want_act, floor)?,
            };
            if self.restarts >= self.max_restarts {
                return self.end_run(&basis, &h, m, &ritz, floor, out.found, false);
            }
            self.restarts += 1;

            // Krylov-Schur restart: converged wanted pairs first (locked), then the other
            // wanted ones, then the next largest, up to `keep`.
            let lockable = ritz.lockable(floor);
            let keep = (want_act + (m - want_act) / 2)
                .min(m - 1)
                .max(lockable.len() + 1)
                .min(m);
            let mut sel = lockable.clone();
            sel.extend(ritz.order.iter().copied().filter(|i| !lockable.contains(i)));
            sel.truncate(keep);
            let targets: Vec<c64> = sel.iter().map(|&i| ritz.theta[i]).collect();
            let (z, t) = schur_deflate(h.get(..m, ..m), &targets, &ritz.y, &sel)?;
            let c = lockable.len();
            self.lock(&basis, m, &z, &targets[..c]);
            out.found += c;
            let kk = keep - c;
            let v_new = times(basis.v(m), z.get(.., c..keep));
            basis.copy_col(m, kk);
            for col in 0..kk {
                basis.set(col, v_new.col_as_slice(col));
            }
            h.fill(ZERO);
            for jj in 0..kk {
                for ii in 0..=jj {
                    h[(ii, jj)] = t[(c + ii, c + jj)];
                }
                if kk < ncv {
                    h[(kk, jj)] = z[(m - 1, c + jj)] * beta;
                }
            }
            k = kk;
            if out.found >= want {
                return Ok(out);
            }
        }
    }

    /// Final eigenpairs from the locked Schur vectors, verified on the operator.
    fn finish(&self, nev: usize, mut all_converged: bool) -> Result<ComplexKernelOutput> {
        let n = self.n();
        let p = self.p();
        let q = self.locked_mat();
        let mut aq = Mat::<c64>::zeros(n, p);
        for j in 0..p {
            self.op
                .apply(&self.locked[j * n..(j + 1) * n], aq.col_as_slice_mut(j));
        }
        let mut t = Mat::<c64>::zeros(p, p);
        matmul(
            t.as_mut(),
            Accum::Replace,
            q.adjoint(),
            aq.as_ref(),
            ONE,
            par_for(n * p * p),
        );
        let tnorm = frobenius(t.as_ref());
        let mut order: Vec<usize> = (0..p).collect();
        order.sort_by(|&i, &j| t[(j, j)].norm().total_cmp(&t[(i, i)].norm()));
        order.truncate(nev);
        let mut theta = Vec::new();
        let mut cols: Vec<Vec<c64>> = Vec::new();
        for &j in &order {
            let th = t[(j, j)];
            let wv = triangular_eigvec(t.as_ref(), j, self.tol, tnorm);
            let wm = MatRef::from_column_major_slice(&wv, p, 1);
            let x = times(q, wm);
            let ax = times(aq.as_ref(), wm);
            let xs = x.col_as_slice(0);
            let xn = cnorm(xs);
            let r: Vec<c64> = ax
                .col_as_slice(0)
                .iter()
                .zip(xs)
                .map(|(a, b)| a - th * b)
                .collect();
            let res = cnorm(&r) / xn;
            let bound = VERIFY_FACTOR * self.tol * th.norm() + 1e3 * f64::EPSILON * tnorm;
            if res.is_nan() || res > bound {
                all_converged = false;
                continue;
            }
            theta.push(th);
            cols.push(xs.iter().map(|v| v * (1.0 / xn)).collect());
        }
        if theta.len() < nev.min(n) {
            all_converged = false;
        }
        let vectors = Mat::from_fn(n, cols.len(), |i, j| cols[j][i]);
        Ok(ComplexKernelOutput {
            theta,
            vectors,
            iterations: self.restarts,
            all_converged,
        })
    }
}

/// Eigenvector `w` of the upper triangular part of `t` for `theta = t_jj` (`w_j = 1`,
/// `w_i = 0` for `i > j`), by back-substitution. A copy of a semisimple repeated
/// eigenvalue (tiny pivot *and* tiny right-hand side) gets `w_i = 0`; other tiny pivots
/// are replaced by `eps ||T||` (LAPACK `ztrevc`).
fn triangular_eigvec(t: MatRef<'_, c64>, j: usize, tol: f64, tnorm: f64) -> Vec<c64> {
    let p = t.nrows();
    let th = t[(j, j)];
    let smin = (f64::EPSILON * tnorm).max(f64::MIN_POSITIVE);
    let mut w = vec![ZERO; p];
    w[j] = ONE;
    let mut wnorm2: f64 = 1.0;
    for i in (0..j).rev() {
        let mut s = ZERO;
        for l in i + 1..=j {
            s += t[(i, l)] * w[l];
        }
        let piv = t[(i, i)] - th;
        let scale_ref = th.norm() * wnorm2.sqrt();
        w[i] = if piv.norm() <= REPEAT_REL * th.norm() && s.norm() <= tol * scale_ref {
            ZERO
        } else if piv.norm() < smin {
            -s / c64::new(smin, 0.0)
        } else {
            -s / piv
        };
        wnorm2 += w[i].norm_sqr();
    }
    w
}

/// Orthonormal basis of the `H`-invariant subspace of the eigenvalues `targets` (any
/// order, repeats allowed): returns the unitary `Z` (`m x m`) whose first
/// `targets.len()` columns span it, and `W = Z^H H Z` with the sub-diagonal part of those
/// columns set to zero (upper triangular there, `W_jj ~ targets[j]`). `y[:, guess[j]]`
/// is an eigenvector of `H` for `targets[j]`, used as a start.
fn schur_deflate(
    h: MatRef<'_, c64>,
    targets: &[c64],
    y: &Mat<c64>,
    guess: &[usize],
) -> Result<(Mat<c64>, Mat<c64>)> {
    let m = h.nrows();
    let mut w = h.to_owned();
    let mut z = Mat::<c64>::identity(m, m);
    let hnorm = frobenius(h).max(f64::MIN_POSITIVE);
    for (j, &sigma) in targets.iter().enumerate() {
        let s = m - j;
        // Start: the eigenvector of H in the current coordinates; its tail is an
        // eigenvector of the trailing block unless the eigenvalue was already deflated
        // (a repeated one), in which case a fixed vector is used.
        let g = guess[j];
        let mut x0: Vec<c64> = (j..m)
            .map(|i| (0..m).fold(ZERO, |acc, r| acc + z[(r, i)].conj() * y[(r, g)]))
            .collect();
        if cnorm(&x0) < 1e-3 {
            x0 = (0..s)
                .map(|i| c64::new(1.0 + 0.3 * (i as f64 * 1.3).sin(), 0.2 * (i as f64).cos()))
                .collect();
        }
        let x = trailing_eigvec(w.get(j.., j..), sigma, x0, hnorm)?;
        // Householder reflector P = I - tau v v^H with P x = beta e_1, so P e_1 ~ x.
        let x0n = x[0].norm();
        let phase = if x0n > 0.0 { x[0] / x0n } else { ONE };
        let mut v = x.clone();
        v[0] += phase * cnorm(&x);
        let vv: f64 = v.iter().map(|a| a.norm_sqr()).sum();
        if vv > 0.0 {
            let tau = 2.0 / vv;
            // Rows j.. of W: W <- P W.
            for col in 0..m {
                let mut d = ZERO;
                for i in 0..s {
                    d += v[i].conj() * w[(j + i, col)];
                }
                let d = d * tau;
                for i in 0..s {
                    let vi = v[i];
                    w[(j + i, col)] -= vi * d;
                }
            }
            // Columns j.. of W and Z: A <- A P.
            for a in [&mut w, &mut z] {
                for row in 0..m {
                    let mut d = ZERO;
                    for i in 0..s {
                        d += a[(row, j + i)] * v[i];
                    }
                    let d = d * tau;
                    for i in 0..s {
                        let vc = v[i].conj();
                        a[(row, j + i)] -= d * vc;
                    }
                }
            }
        }
        for i in j + 1..m {
            w[(i, j)] = ZERO;
        }
    }
    Ok((z, w))
}

/// Unit eigenvector of `a` for the eigenvalue nearest `sigma`: shifted inverse iteration
/// from `x0`, dense `eigen` as fallback.
fn trailing_eigvec(a: MatRef<'_, c64>, sigma: c64, x0: Vec<c64>, hnorm: f64) -> Result<Vec<c64>> {
    let s = a.nrows();
    if s == 1 {
        return Ok(vec![ONE]);
    }
    let accept = DEFLATION_ACCEPT * f64::EPSILON * hnorm;
    let residual = |x: &[c64]| -> f64 {
        let xm = MatRef::from_column_major_slice(x, s, 1);
        let ax = times(a, xm);
        let rho = cdot(x, ax.col_as_slice(0));
        let r: Vec<c64> = ax
            .col_as_slice(0)
            .iter()
            .zip(x)
            .map(|(p, q)| p - rho * q)
            .collect();
        cnorm(&r)
    };
    let delta = c64::new(0.6, 0.8) * (16.0 * f64::EPSILON * hnorm);
    let shifted = Mat::from_fn(s, s, |i, j| {
        if i == j {
            a[(i, j)] - sigma - delta
        } else {
            a[(i, j)]
        }
    });
    let lu = shifted.partial_piv_lu();
    let mut x = x0;
    let n0 = cnorm(&x);
    scale(&mut x, 1.0 / n0);
    for _ in 0..INVERSE_STEPS {
        let mut rhs = Mat::from_fn(s, 1, |i, _| x[i]);
        lu.solve_in_place(rhs.as_mut());
        let mut xn: Vec<c64> = rhs.col_as_slice(0).to_vec();
        let nrm = cnorm(&xn);
        if !(nrm.is_finite() && nrm > 0.0) {
            break;
        }
        scale(&mut xn, 1.0 / nrm);
        x = xn;
        if residual(&x) <= accept {
            return Ok(x);
        }
    }
    // Fallback: dense eigen of the block, eigenvalue nearest sigma.
    let eig = a
        .eigen()
        .map_err(|e| Error::Invalid(format!("krylov: Schur deflation: {e:?}")))?;
    let sv = eig.S();
    let best = (0..s)
        .min_by(|&i, &j| (sv[i] - sigma).norm().total_cmp(&(sv[j] - sigma).norm()))
        .unwrap_or(0);
    let mut x: Vec<c64> = (0..s).map(|i| eig.U()[(i, best)]).collect();
    let nrm = cnorm(&x);
    scale(&mut x, 1.0 / nrm);
    Ok(x)
}
