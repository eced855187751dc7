//! The Krylov-Schur iteration: the Arnoldi basis, Ritz values, locking and restarts.

use super::*;
use squeal_core::faer::linalg::matmul::matmul;
use squeal_core::faer::{Accum, Mat, MatRef};
use squeal_core::qep::ComplexKernelOutput;
use squeal_core::spectral::LinOp;
use squeal_core::{c64, Error, Result};

/// The Arnoldi basis (`cap` columns), column-major.
pub(super) struct Basis {
    pub(super) n: usize,
    pub(super) v: Vec<c64>,
}

impl Basis {
    pub(super) fn new(n: usize, cap: usize) -> Self {
        Self {
            n,
            v: vec![ZERO; n * cap],
        }
    }

    pub(super) fn v(&self, cols: usize) -> MatRef<'_, c64> {
        MatRef::from_column_major_slice(&self.v[..cols * self.n], self.n, cols)
    }

    pub(super) fn col(&self, j: usize) -> &[c64] {
        &self.v[j * self.n..(j + 1) * self.n]
    }

    pub(super) fn set(&mut self, j: usize, x: &[c64]) {
        let n = self.n;
        self.v[j * n..(j + 1) * n].copy_from_slice(x);
    }

    pub(super) fn copy_col(&mut self, from: usize, to: usize) {
        let n = self.n;
        self.v.copy_within(from * n..(from + 1) * n, to * n);
    }
}

/// Rayleigh-Ritz analysis of the current projected matrix.
pub(super) struct Ritz {
    /// Ritz values.
    pub(super) theta: Vec<c64>,
    /// Unit eigenvectors of `H` (columns).
    pub(super) y: Mat<c64>,
    /// All indices by decreasing modulus.
    pub(super) order: Vec<usize>,
    /// The wanted pairs (a prefix of `order`).
    pub(super) wanted: usize,
    /// Convergence flag of each pair.
    pub(super) converged: Vec<bool>,
    /// The basis is too small to hold every wanted pair.
    pub(super) short: bool,
}

impl Ritz {
    pub(super) fn wanted(&self) -> &[usize] {
        &self.order[..self.wanted]
    }

    /// Every wanted pair present and converged.
    pub(super) fn done(&self) -> bool {
        !self.short && self.all_converged()
    }

    /// Every wanted pair the basis holds is converged.
    pub(super) fn all_converged(&self) -> bool {
        self.wanted().iter().all(|&i| self.converged[i])
    }

    /// Converged wanted pairs that may be locked (above the floor, if any).
    pub(super) fn lockable(&self, floor: Option<f64>) -> Vec<usize> {
        self.wanted()
            .iter()
            .copied()
            .filter(|&i| self.converged[i] && floor.is_none_or(|f| self.theta[i].norm() > f))
            .collect()
    }
}

/// Result of one run.
pub(super) struct RunOut {
    /// Pairs locked by the run.
    pub(super) found: usize,
    /// Whether every wanted pair converged.
    pub(super) complete: bool,
}

/// State shared by the runs of one [`KrylovSchurKernel::largest`] call.
pub(super) struct Ctx<'o> {
    pub(super) op: &'o dyn LinOp<c64>,
    pub(super) tol: f64,
    pub(super) max_restarts: usize,
    pub(super) restarts: usize,
    pub(super) dirs: Directions,
    /// Locked orthonormal Schur vectors, column-major.
    pub(super) locked: Vec<c64>,
    /// Ritz values at locking time.
    pub(super) locked_theta: Vec<c64>,
}

impl Ctx<'_> {
    pub(super) fn n(&self) -> usize {
        self.op.dim()
    }

    pub(super) fn p(&self) -> usize {
        self.locked_theta.len()
    }

    pub(super) fn locked_mat(&self) -> MatRef<'_, c64> {
        MatRef::from_column_major_slice(&self.locked, self.n(), self.p())
    }

    /// The `nev`-th largest locked modulus (the smallest if fewer are locked).
    pub(super) fn nth_locked_modulus(&self, nev: usize) -> f64 {
        let mut m: Vec<f64> = self.locked_theta.iter().map(|t| t.norm()).collect();
        m.sort_by(|a, b| b.total_cmp(a));
        m.get(nev.min(m.len()).saturating_sub(1))
            .copied()
            .unwrap_or(0.0)
    }

    /// Orthogonalizes `w` against the locked vectors and the first `nb` basis vectors
    /// (`passes` classical Gram-Schmidt passes). Returns the basis coefficients summed
    /// over the passes and `||c||^2` of the first pass.
    pub(super) fn orthogonalize(
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
    pub(super) fn new_direction(
        &mut self,
        mut x: Vec<c64>,
        basis: &Basis,
        nb: usize,
    ) -> Option<Vec<c64>> {
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
    pub(super) fn ritz(
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
    pub(super) fn lock(&mut self, basis: &Basis, m: usize, z: &Mat<c64>, theta: &[c64]) {
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
    pub(super) fn end_run(
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
    pub(super) fn run(
        &mut self,
        want: usize,
        start: Vec<c64>,
        floor: Option<f64>,
    ) -> Result<RunOut> {
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
    pub(super) fn finish(
        &self,
        nev: usize,
        mut all_converged: bool,
    ) -> Result<ComplexKernelOutput> {
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
