//! Thick-restart Lanczos in the `M` inner product (the crate docs give the method).

use super::pairs::Pairs;
use super::{
    par_for, Directions, BREAKDOWN, CHECK_EVERY, NEW_DIRECTION_MIN, NEW_DIRECTION_TRIES, THIRD_PASS,
};
use squeal_core::eigen::KernelOutput;
use squeal_core::faer::linalg::matmul::matmul;
use squeal_core::faer::{Accum, Mat, MatMut, MatRef, Side};
use squeal_core::linalg::dot;
use squeal_core::spectral::{LinOp, ShiftInvert};
use squeal_core::{Error, Result};

/// [`super::LanczosKernel::largest`] from a given start vector.
pub(crate) fn largest_from(
    op: &ShiftInvert<'_>,
    nev: usize,
    tol: f64,
    max_restarts: usize,
    start: Vec<f64>,
) -> Result<KernelOutput> {
    let n = op.dim();
    let nev = nev.min(n);
    let mut ctx = Ctx {
        op,
        tol,
        max_restarts,
        restarts: 0,
        dirs: Directions::new(),
    };
    if nev == 0 {
        return Ok(Pairs::new(n).into_output(0, true));
    }

    // First run: the nev largest Ritz pairs of one Krylov space.
    let first = ctx.run(&Pairs::new(n), nev, start, None)?;
    let mut found = first.pairs;
    if !first.complete {
        return Ok(found.into_output(ctx.restarts, false));
    }

    // Validation runs in the M-complement of what was found: any eigenvalue larger
    // than the smallest found one (a missed copy of a repeated eigenvalue) is merged.
    let margin = (10.0 * tol).clamp(1e-10, 1e-4);
    loop {
        if found.len() >= n {
            return Ok(found.into_output(ctx.restarts, true));
        }
        if ctx.restarts >= ctx.max_restarts {
            return Ok(found.into_output(ctx.restarts, false));
        }
        ctx.restarts += 1;
        let floor = found.min_theta() * (1.0 + margin);
        let start = ctx.dirs.vector(n);
        let check = ctx.run(&found, nev, start, Some(floor))?;
        let above = check.pairs.filtered(|t| t > floor);
        if above.len() == 0 {
            return Ok(found.into_output(ctx.restarts, check.complete));
        }
        found = Pairs::merged(&found, &above, nev);
        if !check.complete {
            return Ok(found.into_output(ctx.restarts, false));
        }
    }
}

/// The Lanczos basis `V` (`cap` columns) and `M V`, column-major.
struct Basis {
    n: usize,
    v: Vec<f64>,
    mv: Vec<f64>,
}

impl Basis {
    fn new(n: usize, cap: usize) -> Self {
        Self {
            n,
            v: vec![0.0; n * cap],
            mv: vec![0.0; n * cap],
        }
    }

    fn v(&self, cols: usize) -> MatRef<'_, f64> {
        MatRef::from_column_major_slice(&self.v[..cols * self.n], self.n, cols)
    }

    fn mv(&self, cols: usize) -> MatRef<'_, f64> {
        MatRef::from_column_major_slice(&self.mv[..cols * self.n], self.n, cols)
    }

    fn mv_col(&self, j: usize) -> &[f64] {
        &self.mv[j * self.n..(j + 1) * self.n]
    }

    fn set(&mut self, j: usize, x: &[f64], mx: &[f64]) {
        let n = self.n;
        self.v[j * n..(j + 1) * n].copy_from_slice(x);
        self.mv[j * n..(j + 1) * n].copy_from_slice(mx);
    }

    fn copy_col(&mut self, from: usize, to: usize) {
        let n = self.n;
        self.v.copy_within(from * n..(from + 1) * n, to * n);
        self.mv.copy_within(from * n..(from + 1) * n, to * n);
    }
}

/// `Q Y` for a column-major `n x q` block and a dense `q x c` matrix.
fn times(q: MatRef<'_, f64>, y: MatRef<'_, f64>) -> Mat<f64> {
    let mut out = Mat::<f64>::zeros(q.nrows(), y.ncols());
    matmul(
        out.as_mut(),
        Accum::Replace,
        q,
        y,
        1.0,
        par_for(q.nrows() * q.ncols() * y.ncols()),
    );
    out
}

/// One classical Gram-Schmidt pass in the `M` inner product: `c = (M Q)^T w`,
/// `w <- w - Q c`. Adds `c` to `acc` (when given) and returns `||c||^2`.
fn cgs_pass(
    w: &mut [f64],
    q: MatRef<'_, f64>,
    mq: MatRef<'_, f64>,
    acc: Option<&mut [f64]>,
) -> f64 {
    let k = q.ncols();
    if k == 0 {
        return 0.0;
    }
    let n = w.len();
    let par = par_for(n * k);
    let mut c = vec![0.0; k];
    matmul(
        MatMut::from_column_major_slice_mut(&mut c, k, 1),
        Accum::Replace,
        mq.transpose(),
        MatRef::from_column_major_slice(w, n, 1),
        1.0,
        par,
    );
    matmul(
        MatMut::from_column_major_slice_mut(w, n, 1),
        Accum::Add,
        q,
        MatRef::from_column_major_slice(&c, k, 1),
        -1.0,
        par,
    );
    if let Some(acc) = acc {
        acc.iter_mut().zip(&c).for_each(|(a, ci)| *a += ci);
    }
    dot(&c, &c)
}

/// State shared by the runs of one [`LanczosKernel::largest`] call.
pub(crate) struct Ctx<'o, 'a> {
    pub(crate) op: &'o ShiftInvert<'a>,
    pub(crate) tol: f64,
    pub(crate) max_restarts: usize,
    pub(crate) restarts: usize,
    pub(crate) dirs: Directions,
}

/// Result of one run: converged wanted pairs, and whether all wanted ones converged.
pub(crate) struct RunOut {
    pub(crate) pairs: Pairs,
    pub(crate) complete: bool,
}

/// Rayleigh-Ritz analysis of the current projected matrix.
struct Ritz {
    /// Ritz values, ascending.
    theta: Vec<f64>,
    /// Eigenvectors of `T` (columns).
    y: Mat<f64>,
    /// Indices of the wanted pairs, largest first.
    wanted: Vec<usize>,
    /// Convergence flag of each pair.
    converged: Vec<bool>,
    /// The basis is too small to hold every wanted pair.
    short: bool,
}

impl Ritz {
    /// Every wanted pair present and converged.
    fn done(&self) -> bool {
        !self.short && self.all_converged()
    }

    /// Every wanted pair the basis holds is converged.
    fn all_converged(&self) -> bool {
        self.wanted.iter().all(|&i| self.converged[i])
    }
}

impl Ctx<'_, '_> {
    /// Orthogonalizes `w` in the `M` inner product against the locked pairs and the
    /// first `nb` basis vectors (`passes` classical Gram-Schmidt passes). Returns the
    /// basis coefficients summed over the passes and `||c||^2` of the first pass.
    fn orthogonalize(
        &self,
        w: &mut [f64],
        locked: &Pairs,
        basis: &Basis,
        nb: usize,
        passes: usize,
    ) -> (Vec<f64>, f64) {
        let mut h = vec![0.0; nb];
        let mut first = 0.0;
        for pass in 0..passes {
            let removed = cgs_pass(w, locked.x_mat(), locked.mx_mat(), None)
                + cgs_pass(w, basis.v(nb), basis.mv(nb), Some(&mut h));
            if pass == 0 {
                first = removed;
            }
        }
        (h, first)
    }

    /// `M`-norm of `w`, leaving `M w` in `mw`.
    fn m_norm(&self, w: &[f64], mw: &mut [f64]) -> f64 {
        self.op.m_mul(w, mw);
        dot(w, mw).max(0.0).sqrt()
    }

    /// Makes `x` a unit vector `M`-orthogonal to the locked pairs and the first `nb`
    /// basis vectors; on collapse, tries fresh pseudo-random vectors. `None` when the
    /// complement is numerically exhausted.
    fn new_direction(
        &mut self,
        mut x: Vec<f64>,
        locked: &Pairs,
        basis: &Basis,
        nb: usize,
    ) -> Option<(Vec<f64>, Vec<f64>)> {
        let n = x.len();
        let mut mx = vec![0.0; n];
        for _ in 0..NEW_DIRECTION_TRIES {
            let before = self.m_norm(&x, &mut mx);
            if before > 0.0 && before.is_finite() {
                self.orthogonalize(&mut x, locked, basis, nb, 3);
                let after = self.m_norm(&x, &mut mx);
                if after > NEW_DIRECTION_MIN * before {
                    x.iter_mut().for_each(|v| *v /= after);
                    mx.iter_mut().for_each(|v| *v /= after);
                    return Some((x, mx));
                }
            }
            x = self.dirs.vector(n);
        }
        None
    }

    /// Rayleigh-Ritz on the leading `m x m` block of `t` with residual norm `beta`.
    fn ritz(
        &self,
        t: &Mat<f64>,
        m: usize,
        beta: f64,
        want: usize,
        floor: Option<f64>,
    ) -> Result<Ritz> {
        let eig = t
            .get(..m, ..m)
            .self_adjoint_eigen(Side::Lower)
            .map_err(|e| Error::Invalid(format!("krylov: projected eigenproblem: {e:?}")))?;
        let s = eig.S();
        let theta: Vec<f64> = (0..m).map(|i| s[i]).collect();
        let y = eig.U().to_owned();
        let converged: Vec<bool> = (0..m)
            .map(|i| (beta * y[(m - 1, i)]).abs() <= self.tol * theta[i].abs())
            .collect();
        // Without a floor: the `want` largest. With one (validation): every Ritz value
        // above the floor plus the next one, which must converge below the floor.
        let count = match floor {
            None => want,
            Some(f) => (theta.iter().filter(|&&t| t > f).count() + 1).min(want),
        };
        let wanted = (0..count.min(m)).map(|r| m - 1 - r).collect();
        Ok(Ritz {
            theta,
            y,
            wanted,
            converged,
            short: count > m,
        })
    }

    /// The converged wanted Ritz pairs of an `m`-vector basis.
    fn converged_pairs(&self, basis: &Basis, m: usize, ritz: &Ritz) -> Pairs {
        let n = self.op.dim();
        let sel: Vec<usize> = ritz
            .wanted
            .iter()
            .copied()
            .filter(|&i| ritz.converged[i])
            .collect();
        let ysel = Mat::from_fn(m, sel.len(), |i, c| ritz.y[(i, sel[c])]);
        let x = times(basis.v(m), ysel.as_ref());
        let mx = times(basis.mv(m), ysel.as_ref());
        let mut out = Pairs::new(n);
        for (c, &i) in sel.iter().enumerate() {
            out.push(ritz.theta[i], x.col_as_slice(c), mx.col_as_slice(c));
        }
        out
    }

    /// One thick-restart Lanczos run for the `want` largest eigenpairs of `OP` restricted
    /// to the `M`-complement of `locked`, from `start`. With a `floor`, the run only has
    /// to find the pairs above it (and prove the next one lies below).
    pub(crate) fn run(
        &mut self,
        locked: &Pairs,
        want: usize,
        start: Vec<f64>,
        floor: Option<f64>,
    ) -> Result<RunOut> {
        let op = self.op;
        let n = op.dim();
        let dim = n.saturating_sub(locked.len());
        let want = want.min(dim);
        let empty = RunOut {
            pairs: Pairs::new(n),
            complete: true,
        };
        if want == 0 {
            return Ok(empty);
        }
        let ncv = dim.min((2 * want + 1).max(want + 20));
        let keep = (want + (ncv - want) / 2).min(ncv - 1).max(1);
        let mut basis = Basis::new(n, ncv + 1);
        let mut t = Mat::<f64>::zeros(ncv, ncv);
        match self.new_direction(start, locked, &basis, 0) {
            Some((v, mv)) => basis.set(0, &v, &mv),
            None => return Ok(empty),
        }
        let mut k = 0;
        let mut w = vec![0.0; n];
        let mut mw = vec![0.0; n];
        loop {
            // Expand the basis from k to ncv vectors (or to an exhausted complement).
            let mut beta = 0.0;
            let mut ritz = None;
            for j in k..ncv {
                op.apply_with_mx(basis.mv_col(j), &mut w);
                let (mut h, first) = self.orthogonalize(&mut w, locked, &basis, j + 1, 2);
                let mut b = self.m_norm(&w, &mut mw);
                let norm0 = (first + b * b).sqrt();
                if b < THIRD_PASS * norm0 && b > BREAKDOWN * norm0 {
                    let (h3, _) = self.orthogonalize(&mut w, locked, &basis, j + 1, 1);
                    h.iter_mut().zip(&h3).for_each(|(a, c)| *a += c);
                    b = self.m_norm(&w, &mut mw);
                }
                if !(b.is_finite() && h[j].is_finite()) {
                    return Err(Error::Invalid(format!(
                        "krylov: non-finite Lanczos coefficient at step {j} (alpha = {}, \
                         beta = {b}): the factorization of K - sigma M is unusable",
                        h[j]
                    )));
                }
                t[(j, j)] = h[j];
                let mut exhausted = false;
                let broke = b <= BREAKDOWN * norm0;
                if !broke {
                    w.iter_mut().for_each(|v| *v /= b);
                    mw.iter_mut().for_each(|v| *v /= b);
                    basis.set(j + 1, &w, &mw);
                    beta = b;
                } else {
                    // Invariant subspace: continue with a new direction, coupling 0.
                    beta = 0.0;
                    b = 0.0;
                    let fresh = self.dirs.vector(n);
                    match self.new_direction(fresh, locked, &basis, j + 1) {
                        Some((v, mv)) => basis.set(j + 1, &v, &mv),
                        None => exhausted = true,
                    }
                }
                if j + 1 < ncv {
                    t[(j + 1, j)] = b;
                    t[(j, j + 1)] = b;
                }
                // Early checks skip breakdown steps: an invariant subspace has exact Ritz
                // pairs that need not be the largest; the new direction may show more.
                let size = j + 1;
                if exhausted || size == ncv || (!broke && (size - k) % CHECK_EVERY == 0) {
                    let r = self.ritz(&t, size, beta, want, floor)?;
                    if r.done() || exhausted {
                        // Exhausted: the basis spans the whole complement, nothing is missing.
                        let complete = r.all_converged();
                        return Ok(RunOut {
                            pairs: self.converged_pairs(&basis, size, &r),
                            complete,
                        });
                    }
                    if size == ncv {
                        ritz = Some(r);
                    }
                }
            }
            let m = ncv;
            let ritz = match ritz {
                Some(r) => r,
                None => self.ritz(&t, m, beta, want, floor)?,
            };
            if self.restarts >= self.max_restarts {
                return Ok(RunOut {
                    pairs: self.converged_pairs(&basis, m, &ritz),
                    complete: false,
                });
            }
            self.restarts += 1;

            // Thick restart: keep the `keep` largest Ritz pairs and the residual vector.
            k = keep.min(m - 1);
            let idx: Vec<usize> = (0..k).map(|r| m - 1 - r).collect();
            let yk = Mat::from_fn(m, k, |i, c| ritz.y[(i, idx[c])]);
            let v_new = times(basis.v(m), yk.as_ref());
            let mv_new = times(basis.mv(m), yk.as_ref());
            basis.copy_col(m, k);
            for c in 0..k {
                basis.set(c, v_new.col_as_slice(c), mv_new.col_as_slice(c));
            }
            t.fill(0.0);
            for (c, &i) in idx.iter().enumerate() {
                let b = beta * ritz.y[(m - 1, i)];
                t[(c, c)] = ritz.theta[i];
                t[(k, c)] = b;
                t[(c, k)] = b;
            }
        }
    }
}
