//! Forward error estimates of QEP eigenvalues (`docs/error-estimate.md`).
//!
//! The backward error `eta` of a computed pair `(lambda, x)` says how far the pair is
//! from an exact pair of a nearby problem. The error of the eigenvalue itself is, to
//! first order, `cond(lambda) eta`, with the normwise condition number of a simple
//! eigenvalue (Tisseur, "Backward error and condition of polynomial eigenvalue
//! problems", Linear Algebra Appl. 309, 2000)
//!
//! `cond(lambda) = ||y|| ||x|| (|lambda|^2 ||M|| + |lambda| ||C|| + ||K||)
//!                 / (|lambda| |y^H Q'(lambda) x|)`,  `Q'(lambda) = 2 lambda M + C`,
//!
//! `y` the left eigenvector (`y^H Q(lambda) = 0`). The product
//! `error_bound = cond * eta = ||y|| ||Q(lambda) x|| / (|lambda| |y^H Q'(lambda) x|)`
//! does not depend on the matrix norms used (1-norms here, as for `eta`): it estimates
//! the RELATIVE forward error `|lambda - lambda_exact| / |lambda|`.
//!
//! ## What it promises and where it fails
//! - It is a first-order estimate: valid while `error_bound` is small (say below 1e-2),
//!   i.e. while the perturbation that makes the pair exact does not move the eigenvalue
//!   out of the region where it is a simple, isolated root.
//! - At an exact coalescence (a defective double eigenvalue, where flutter is born)
//!   `y^H Q'(lambda) x = 0` and `cond` is infinite; near it the true error grows like the
//!   square root of the perturbation, so a huge `cond` means "the eigenvalue is only
//!   known to about `sqrt(eta)`", not the product.
//! - For a (nearly) repeated semisimple eigenvalue (a disc doublet) the individual
//!   vectors are not determined; the left vectors of a cluster (relative distance below
//!   [`CLUSTER_REL`]) are bi-orthogonalized against the right ones,
//!   `Y^H Q'(lambda) X = I`, which gives the condition of each member in that basis.
//! - Left eigenvectors come from inverse iteration on `Q(lambda)^H` at the computed
//!   eigenvalue (two solves with the adjoint of one factorization per mode: a dense LU up
//!   to [`DENSE_LEFT_MAX_DIM`], else a sparse LU on the reused symbolic analysis), from
//!   one dense solve of the transposed problem when that is cheaper, or,
//!   for modes of a reduced solve, the reduced problem's left vectors expanded by the
//!   basis (`y = V p`). The latter is the Galerkin approximation of the full left vector:
//!   when the basis does not contain the full left eigenvector the estimate can be off
//!   (the missing part of `y` is where the true first-order error lives).

use super::dense_qep;
use super::residual::QepTerms;
use crate::operator::{check_qep, Qep};
use crate::spectral::{QepShiftInvert, QepSymbolic};
use crate::{c64, Error, Result, SparseRef};
use faer::linalg::solvers::Solve;
use faer::{Mat, MatRef};

/// Problems up to this size get their left eigenvectors densely: from one dense solve of
/// the transposed problem (`Q(lambda)^T conj(y) = 0`, [`dense_qep`]) or from one dense LU
/// of `Q(lambda)` per mode, whichever costs fewer flops; larger ones from a sparse LU per
/// mode on a shared symbolic analysis.
pub const DENSE_LEFT_MAX_DIM: usize = 1000;

/// Size up to which [`Condition::Auto`] computes left eigenvectors for every mode (so
/// every reduced solve, and full-order solves of small models). Past it the sparse complex
/// LU per mode costs several times the band solve itself (measured on the 1773-DOF coarse
/// rig, 18 modes: 0.38 s without, 2.9 s with), and undamped operators past
/// [`LOW_RANK_AUTO_MIN_DIM`](super::LOW_RANK_AUTO_MIN_DIM) are solved without any LU at
/// all: there [`Condition::Auto`] computes them only for the modes whose stability class
/// depends on them ([`needs_condition`](crate::operator::needs_condition)), and
/// [`Condition::Always`] for every mode.
pub const CONDITION_AUTO_MAX_DIM: usize = 1000;

/// Eigenvalues closer than this (relative) are treated as one cluster when their left
/// vectors are bi-orthogonalized.
pub const CLUSTER_REL: f64 = 1e-8;

/// Whether a solve computes left eigenvectors (and so `cond` and `error_bound`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Condition {
    /// For every mode when the problem size is at most [`CONDITION_AUTO_MAX_DIM`]; above,
    /// for the modes whose stability class depends on them
    /// ([`needs_condition`](crate::operator::needs_condition): a real part between the
    /// smallest bound any condition gives and the square-root rule), usually none or a
    /// few.
    #[default]
    Auto,
    /// Always (one factorization per mode).
    Always,
    /// Never: `cond` and `error_bound` are NaN.
    Never,
}

impl Condition {
    /// Whether a problem of size `n` gets left eigenvectors for every mode.
    pub fn applies(self, n: usize) -> bool {
        match self {
            Condition::Auto => n <= CONDITION_AUTO_MAX_DIM,
            Condition::Always => true,
            Condition::Never => false,
        }
    }

    /// Whether a problem of size `n` gets left eigenvectors for the modes whose class
    /// depends on them, when not for every mode.
    pub fn where_needed(self, n: usize) -> bool {
        self == Condition::Auto && n > CONDITION_AUTO_MAX_DIM
    }
}

/// Where the left eigenvectors of [`super::modes::finish_terms`] come from.
pub(super) enum LeftSource<'a> {
    /// Not computed.
    None,
    /// Given, one column per input eigenvalue (aligned with `lambda`).
    Given(MatRef<'a, c64>),
    /// Inverse iteration on this assembled problem.
    InverseIteration(&'a Qep),
    /// Inverse iteration on this problem for the modes whose class depends on their
    /// condition only ([`crate::operator::needs_condition`]); the problem is assembled
    /// when one does.
    WhereNeeded(NeededProblem<'a>),
}

/// The problem [`LeftSource::WhereNeeded`] solves with, assembled or not.
pub(super) enum NeededProblem<'a> {
    /// Assembled.
    Qep(&'a Qep),
    /// A frictional operator at `mu`, assembled only if a mode needs it.
    Operator(&'a crate::operator::FrictionalOperator, f64),
}

impl NeededProblem<'_> {
    pub(super) fn qep(&self) -> Result<std::borrow::Cow<'_, Qep>> {
        Ok(match self {
            NeededProblem::Qep(q) => std::borrow::Cow::Borrowed(*q),
            NeededProblem::Operator(op, mu) => std::borrow::Cow::Owned(op.at(*mu)?),
        })
    }
}

/// `y = sum s_i A_i x` over `terms`.
fn apply_terms(n: usize, terms: &[(SparseRef<'_>, f64)], x: &[c64]) -> Vec<c64> {
    let mut y = vec![c64::new(0.0, 0.0); n];
    for (a, s) in terms {
        for j in 0..a.ncols() {
            let xj = x[j] * *s;
            if xj.re == 0.0 && xj.im == 0.0 {
                continue;
            }
            for (i, v) in a.row_idx_of_col(j).zip(a.val_of_col(j)) {
                y[i] += xj * *v;
            }
        }
    }
    y
}

/// `Q'(lambda) x = 2 lambda M x + C x` on the parts.
fn derivative_times(q: &QepTerms<'_>, lambda: c64, x: &[c64]) -> Vec<c64> {
    let mut y = apply_terms(q.n, &q.m, x);
    y.iter_mut().for_each(|v| *v *= lambda * 2.0);
    if !q.c.is_empty() {
        let cx = apply_terms(q.n, &q.c, x);
        y.iter_mut().zip(cx).for_each(|(a, b)| *a += b);
    }
    y
}

fn norm(x: &[c64]) -> f64 {
    x.iter().map(|v| v.norm_sqr()).sum::<f64>().sqrt()
}

fn dot_h(y: &[c64], x: &[c64]) -> c64 {
    y.iter().zip(x).map(|(a, b)| a.conj() * b).sum()
}

/// A deterministic pseudo-random unit start vector, different for every `seed`.
fn start_vector(n: usize, seed: usize) -> Vec<c64> {
    let mut state = 0x9e37_79b9_7f4a_7c15u64 ^ (seed as u64).wrapping_mul(0x2545_f491_4f6c_dd1d);
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    let v: Vec<c64> = (0..n).map(|_| c64::new(next(), next())).collect();
    let s = 1.0 / norm(&v);
    v.into_iter().map(|z| z * s).collect()
}

/// A factorization of `Q(lambda)` that solves with its adjoint.
enum Factor<'a> {
    Dense(faer::linalg::solvers::PartialPivLu<c64>),
    Sparse(Box<QepShiftInvert<'a>>),
}

impl Factor<'_> {
    fn solve_adjoint(&self, y: &mut [c64]) {
        let n = y.len();
        match self {
            Factor::Dense(lu) => {
                lu.solve_adjoint_in_place(faer::MatMut::from_column_major_slice_mut(y, n, 1))
            }
            Factor::Sparse(op) => op.solve_adjoint_in_place(y),
        }
    }
}

fn dense_q(qep: &Qep, lambda: c64) -> Mat<c64> {
    let n = qep.dim();
    let mut q = Mat::<c64>::zeros(n, n);
    let mut add = |a: SparseRef<'_>, s: c64| {
        for j in 0..n {
            for (i, v) in a.row_idx_of_col(j).zip(a.val_of_col(j)) {
                q[(i, j)] += s * *v;
            }
        }
    };
    add(qep.m.as_ref(), lambda * lambda);
    if let Some(c) = &qep.c {
        add(c.as_ref(), lambda);
    }
    add(qep.k.as_ref(), c64::new(1.0, 0.0));
    q
}

/// How [`left_eigenvectors`] got its vectors.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LeftInfo {
    /// Sparse or dense LU factorizations of `Q(lambda)` (one per mode solved by inverse
    /// iteration).
    pub factorizations: usize,
    /// Whether a dense solve of the transposed problem supplied them.
    pub transposed_solve: bool,
}

/// Whether one dense solve of the transposed problem (`~25 N^3` flops for the real
/// companion matrix of size `N = 2n`, or `n` when undamped) is cheaper than `k` complex
/// dense LUs of size `n` (`~(8/3) 4 n^3` flops each).
fn transposed_is_cheaper(n: usize, k: usize, damped: bool) -> bool {
    let n = n as f64;
    let big = if damped { 2.0 * n } else { n };
    25.0 * big.powi(3) < (32.0 / 3.0) * k as f64 * n.powi(3)
}

/// Left eigenvectors of `qep` at the eigenvalues `lambda` (with right vectors `right`,
/// one column each).
///
/// - Up to [`DENSE_LEFT_MAX_DIM`], when cheaper: one dense solve of the transposed problem
///   `(lambda^2 M^T + lambda C^T + K^T) conj(y) = 0`, each eigenvalue matched to its
///   nearest unused transposed eigenvalue (relative distance at most `1e-6`; an unmatched
///   one falls back to inverse iteration).
/// - Otherwise inverse iteration on `Q(lambda_j)^H`: one factorization per mode (dense up
///   to [`DENSE_LEFT_MAX_DIM`], else sparse on one shared symbolic analysis), two adjoint
///   solves from a start vector particular to the mode.
///
/// The clusters are then bi-orthogonalized (module docs). Returns the vectors (unit
/// 2-norm outside clusters, a column of NaN where a factorization failed) and how they
/// were obtained.
pub fn left_eigenvectors(
    qep: &Qep,
    lambda: &[c64],
    right: MatRef<'_, c64>,
) -> Result<(Mat<c64>, LeftInfo)> {
    check_qep(qep)?;
    let n = qep.dim();
    if right.nrows() != n || right.ncols() != lambda.len() {
        return Err(Error::Dimension {
            context: "left eigenvectors: one right vector of the problem size per eigenvalue"
                .into(),
            expected: lambda.len(),
            got: right.ncols(),
        });
    }
    let mut left = Mat::<c64>::zeros(n, lambda.len());
    let mut info = LeftInfo {
        factorizations: 0,
        transposed_solve: false,
    };
    let mut todo: Vec<usize> = (0..lambda.len()).collect();
    if n <= DENSE_LEFT_MAX_DIM
        && !lambda.is_empty()
        && transposed_is_cheaper(n, lambda.len(), qep.c.is_some())
    {
        info.transposed_solve = true;
        todo = from_transposed(qep, lambda, left.as_mut())?;
    }
    if !todo.is_empty() {
        let sparse = n > DENSE_LEFT_MAX_DIM;
        info.factorizations = inverse_iteration(qep, lambda, &todo, sparse, left.as_mut())?;
    }
    let terms = QepTerms::of_qep(qep);
    biorthogonalize_clusters(&terms, lambda, right, left.as_mut());
    Ok((left, info))
}

/// The transposed matrix.
fn transposed(a: SparseRef<'_>) -> Result<crate::SparseMat> {
    let mut t = Vec::with_capacity(a.compute_nnz());
    for j in 0..a.ncols() {
        for (i, v) in a.row_idx_of_col(j).zip(a.val_of_col(j)) {
            t.push(faer::sparse::Triplet::new(j, i, *v));
        }
    }
    crate::SparseMat::try_new_from_triplets(a.ncols(), a.nrows(), &t)
        .map_err(|e| Error::Invalid(format!("transpose: {e:?}")))
}

/// Left vectors from the right vectors of the transposed problem (see
/// [`left_eigenvectors`]); returns the modes left without a match.
fn from_transposed(
    qep: &Qep,
    lambda: &[c64],
    mut left: faer::MatMut<'_, c64>,
) -> Result<Vec<usize>> {
    let qt = Qep {
        m: transposed(qep.m.as_ref())?,
        c: qep.c.as_ref().map(|c| transposed(c.as_ref())).transpose()?,
        k: transposed(qep.k.as_ref())?,
    };
    let (lt, vt) = dense_qep(&qt)?;
    // every (mode, transposed root) pair close enough, nearest first
    let mut pairs = Vec::new();
    for (j, &l) in lambda.iter().enumerate() {
        for (p, &m) in lt.iter().enumerate() {
            let d = (m - l).norm();
            if d <= 1e-6 * l.norm() {
                pairs.push((d, j, p));
            }
        }
    }
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    let (mut done, mut taken) = (vec![false; lambda.len()], vec![false; lt.len()]);
    let n = qep.dim();
    for (_, j, p) in pairs {
        if done[j] || taken[p] {
            continue;
        }
        done[j] = true;
        taken[p] = true;
        let y: Vec<c64> = (0..n).map(|r| vt[(r, p)].conj()).collect();
        let s = norm(&y);
        for r in 0..n {
            left[(r, j)] = if s > 0.0 {
                y[r] / s
            } else {
                c64::new(f64::NAN, f64::NAN)
            };
        }
    }
    Ok((0..lambda.len()).filter(|&j| !done[j]).collect())
}

/// Inverse iteration on `Q(lambda_j)^H` for the modes `which` (see
/// [`left_eigenvectors`]), by sparse or dense LU; returns the number of factorizations.
fn inverse_iteration(
    qep: &Qep,
    lambda: &[c64],
    which: &[usize],
    sparse: bool,
    mut left: faer::MatMut<'_, c64>,
) -> Result<usize> {
    let n = qep.dim();
    let sym = if sparse {
        Some(QepSymbolic::new(qep)?)
    } else {
        None
    };
    let mut factorizations = 0;
    for &j in which {
        let l = lambda[j];
        // the computed eigenvalue itself; if Q is exactly singular there, a shift by a
        // relative 1e-12 (inverse iteration converges all the same)
        let mut factor = None;
        for shift in [l, l * c64::new(1.0, 1e-12)] {
            factorizations += 1;
            let f = match &sym {
                None => {
                    let lu = dense_q(qep, shift).partial_piv_lu();
                    let u = lu.U();
                    let ok = (0..n).all(|i| u[(i, i)].norm() > 0.0 && u[(i, i)].norm().is_finite());
                    ok.then_some(Factor::Dense(lu))
                }
                Some(sym) => QepShiftInvert::with_symbolic(qep, shift, sym)
                    .ok()
                    .map(|f| Factor::Sparse(Box::new(f))),
            };
            if f.is_some() {
                factor = f;
                break;
            }
        }
        let y = match factor {
            Some(f) => {
                let mut y = start_vector(n, j);
                for _ in 0..2 {
                    f.solve_adjoint(&mut y);
                    let s = norm(&y);
                    if !(s.is_finite() && s > 0.0) {
                        break;
                    }
                    y.iter_mut().for_each(|v| *v /= s);
                }
                y
            }
            None => vec![c64::new(f64::NAN, f64::NAN); n],
        };
        for r in 0..n {
            left[(r, j)] = y[r];
        }
    }
    Ok(factorizations)
}

/// Within every cluster of eigenvalues (relative distance below [`CLUSTER_REL`], chained),
/// replaces the left vectors `Y` by `Y G^-H` with `G = Y^H Q'(lambda_c) X` (`lambda_c`
/// the cluster mean), so that `Y^H Q'(lambda_c) X = I`; columns keep their order. A
/// singular `G` (the left vectors do not span the cluster) leaves them unchanged.
fn biorthogonalize_clusters(
    q: &QepTerms<'_>,
    lambda: &[c64],
    right: MatRef<'_, c64>,
    mut left: faer::MatMut<'_, c64>,
) {
    let k = lambda.len();
    let mut group = (0..k).collect::<Vec<usize>>();
    fn find(g: &mut [usize], i: usize) -> usize {
        let mut r = i;
        while g[r] != r {
            r = g[r];
        }
        g[i] = r;
        r
    }
    for i in 0..k {
        for j in i + 1..k {
            let d = (lambda[i] - lambda[j]).norm();
            if d <= CLUSTER_REL * lambda[i].norm().max(lambda[j].norm()) {
                let (a, b) = (find(&mut group, i), find(&mut group, j));
                group[b] = a;
            }
        }
    }
    let n = q.n;
    let mut seen = vec![false; k];
    for i in 0..k {
        let root = find(&mut group, i);
        if seen[root] {
            continue;
        }
        seen[root] = true;
        let members: Vec<usize> = (0..k).filter(|&j| find(&mut group, j) == root).collect();
        if members.len() < 2 {
            continue;
        }
        let lc = members.iter().map(|&j| lambda[j]).sum::<c64>() / members.len() as f64;
        let p = members.len();
        let dx: Vec<Vec<c64>> = members
            .iter()
            .map(|&j| {
                let x: Vec<c64> = (0..n).map(|r| right[(r, j)]).collect();
                derivative_times(q, lc, &x)
            })
            .collect();
        let g = Mat::<c64>::from_fn(p, p, |a, b| {
            let y: Vec<c64> = (0..n).map(|r| left[(r, members[a])]).collect();
            dot_h(&y, &dx[b])
        });
        // Y' = Y G^-H, i.e. Y'^H = G^-1 Y^H
        let lu = g.partial_piv_lu();
        let u = lu.U();
        let (mut umin, mut umax) = (f64::INFINITY, 0.0f64);
        for d in 0..p {
            umin = umin.min(u[(d, d)].norm());
            umax = umax.max(u[(d, d)].norm());
        }
        if !(umin > 1e-12 * umax && umax.is_finite()) {
            continue;
        }
        let yh = Mat::<c64>::from_fn(p, n, |a, r| left[(r, members[a])].conj());
        let new = lu.solve(&yh);
        for (a, &j) in members.iter().enumerate() {
            for r in 0..n {
                left[(r, j)] = new[(a, r)].conj();
            }
        }
    }
}

/// `cond` and `error_bound` of the pairs `(lambda_j, x_j)` with left vectors `y_j` and
/// backward errors `eta_j` on the problem `q` (module docs). A NaN left vector gives NaN;
/// `y^H Q' x = 0` (exact coalescence) gives infinity.
pub(super) fn condition_numbers(
    q: &QepTerms<'_>,
    norms: &super::residual::QepNorms,
    lambda: &[c64],
    right: MatRef<'_, c64>,
    left: MatRef<'_, c64>,
    eta: &[f64],
) -> (Vec<f64>, Vec<f64>) {
    let (_, products) = super::residual::check_pairs(q, norms, lambda, right, Some(left), false);
    condition_from_products(norms, lambda, &products, eta)
}

/// [`condition_numbers`] from the pairs' [`DerivativeProducts`]
/// (`|y^H Q'(lambda) x|`, `||x||`, `||y||`, [`super::residual::check_pairs`]).
///
/// [`DerivativeProducts`]: super::residual::DerivativeProducts
pub(super) fn condition_from_products(
    norms: &super::residual::QepNorms,
    lambda: &[c64],
    products: &[super::residual::DerivativeProducts],
    eta: &[f64],
) -> (Vec<f64>, Vec<f64>) {
    let mut cond = Vec::with_capacity(lambda.len());
    let mut bound = Vec::with_capacity(lambda.len());
    for (j, &l) in lambda.iter().enumerate() {
        let (d, nx, ny) = products[j];
        let al = l.norm();
        let w = al * al * norms.m + al * norms.c + norms.k;
        let c = if !(ny.is_finite() && ny > 0.0) || al == 0.0 {
            f64::NAN
        } else if d > 0.0 {
            ny * nx * w / (al * d)
        } else {
            f64::INFINITY
        };
        cond.push(c);
        bound.push(c * eta[j]);
    }
    (cond, bound)
}

#[cfg(test)]
mod tests;
