//! First versions of the contact-side plugin traits: [`ContactLaw`],
//! [`EquilibriumSolver`] and [`ReductionBasis`], with the data they exchange.
//!
//! Conventions (METHODS.md section 0): row `i` of `Pn` carries `+n_i` on the pin node and
//! `-n_i` on the disc node of pair `i` (a positive value opens the gap); `Pt` the same with
//! the sliding direction `e_i`. `Rn >= 0` is compressive and the friction `mu Rn` drags
//! the pin along `+e_i`. The static sliding equilibrium solves
//! `K U = F + (Pn + mu Pt)^T Rn`, `0 <= Rn ⟂ g0 + Pn U >= 0`.

use crate::eigen::{EigenParams, EigenSolver};
use crate::linalg::{add_scaled, norm2, spmv, Cholesky};
use crate::qep::Qep;
use crate::{Error, Result, SparseMat, SparseRef};
use faer::sparse::Triplet;
use faer::Mat;
use faer::MatRef;

/// How the normal reaction of a pair relates to its gap.
pub trait ContactLaw: Send + Sync {
    /// Plugin name (as registered).
    fn name(&self) -> &str;
    /// Normal stiffness per pair (N/m) of a penalty law; `None` for the exact
    /// unilateral (Signorini) constraint.
    fn normal_stiffness(&self) -> Option<f64>;
    /// Normal compliance per pair (m/N) that the law adds to the contact flexibility:
    /// a closed pair satisfies `g + compliance * Rn = 0` instead of `g = 0`.
    fn compliance(&self) -> f64 {
        self.normal_stiffness().map_or(0.0, |k| 1.0 / k)
    }
}

/// The static contact problem on the free DOFs.
#[derive(Clone, Copy)]
pub struct ContactProblem<'a> {
    /// Stiffness on the free DOFs (N/m).
    pub k: SparseRef<'a>,
    /// External load on the free DOFs (N), imposed displacements included.
    pub f: &'a [f64],
    /// Normal projection, `nc x n`.
    pub pn: SparseRef<'a>,
    /// Tangential projection along each pair's sliding direction, `nc x n`.
    pub pt: SparseRef<'a>,
    /// Initial gaps (m), one per pair.
    pub g0: &'a [f64],
}

/// A sliding equilibrium and how it was reached.
#[derive(Debug, Clone)]
pub struct Equilibrium {
    /// Friction coefficient it was computed for.
    pub mu: f64,
    /// Displacements on the free DOFs (m).
    pub u: Vec<f64>,
    /// Normal reactions (N), one per pair.
    pub rn: Vec<f64>,
    /// Pairs in the effective contact set.
    pub active: Vec<bool>,
    /// Outer iterations.
    pub iterations: usize,
    /// Sparse factorizations of `K` performed.
    pub factorizations: usize,
    /// Backward error of the global equilibrium,
    /// `||K U - F - (Pn + mu Pt)^T Rn|| / (||K||_1 ||U|| + ||F + (Pn + mu Pt)^T Rn||)`.
    pub equilibrium_residual: f64,
    /// Complementarity residual, relative to the total normal force.
    pub complementarity_residual: f64,
    /// Wall time (s).
    pub time_s: f64,
}

/// Computes the steady full-sliding equilibrium.
///
/// A solver works on the problem condensed on the contact pairs ([`Condensation`]), so
/// that a sweep over mu factorizes `K` once; [`solve`](Self::solve) condenses and solves.
pub trait EquilibriumSolver: Send + Sync {
    /// Plugin name (as registered).
    fn name(&self) -> &str;
    /// Solves for friction coefficient `mu` under the given law, on a condensation of
    /// `problem`.
    fn solve_condensed(
        &self,
        cond: &Condensation,
        problem: &ContactProblem<'_>,
        law: &dyn ContactLaw,
        mu: f64,
    ) -> Result<Equilibrium>;
    /// Condenses `problem` (one factorization of `K`) and solves it.
    fn solve(
        &self,
        problem: &ContactProblem<'_>,
        law: &dyn ContactLaw,
        mu: f64,
    ) -> Result<Equilibrium> {
        let start = std::time::Instant::now();
        check_mu(mu)?;
        let cond = Condensation::new(problem)?;
        let mut eq = self.solve_condensed(&cond, problem, law, mu)?;
        eq.time_s = start.elapsed().as_secs_f64();
        Ok(eq)
    }
}

/// The constrained frictional operator of one contact set: the mu-independent parts
/// `X_c = T^T X T` and the friction parts `F_X`, kept apart so that
/// `X~_c(mu) = X_c - mu F_X` costs nothing per mu.
#[derive(Debug, Clone)]
pub struct FrictionalOperator {
    /// `M_c` (kg).
    pub mc: SparseMat,
    /// `C_c` (N s/m); `None` when undamped.
    pub cc: Option<SparseMat>,
    /// `K_c` (N/m).
    pub kc: SparseMat,
    /// Friction part of the mass.
    pub fm: SparseMat,
    /// Friction part of the damping; `None` when undamped.
    pub fc: Option<SparseMat>,
    /// Friction part of the stiffness.
    pub fk: SparseMat,
    /// The index map `T`: free DOF `j` of the unconstrained model is constrained DOF
    /// `t[j]` (an eliminated pin-normal DOF points at its disc partner). `None` when the
    /// operator was given directly (then the operator's DOFs are the full DOFs).
    pub t: Option<Vec<usize>>,
    /// The friction load directions `U = T^T P~t^T` (`n_c x nA`, one column per active
    /// pair: `+e_i` on the pin node's in-plane DOFs, `-e_i` on the disc node's), of which
    /// every friction part is a product `F_X = U V_X^T`. Reduction bases use them (static
    /// responses `K_c^-1 U`). `None` when unknown (an operator read from files);
    /// [`crate::reduction::friction_load_directions`] then recovers their span from `F_K`.
    pub friction_loads: Option<SparseMat>,
}

impl FrictionalOperator {
    /// Size of the constrained problem.
    pub fn dim(&self) -> usize {
        self.kc.nrows()
    }

    /// Number of DOFs of the unconstrained model (`dim()` when there is no map).
    pub fn full_dim(&self) -> usize {
        self.t.as_ref().map_or(self.dim(), |t| t.len())
    }

    /// Checks what every operator of a structure satisfies, for operators read from
    /// files: `M_c` has a positive diagonal (a zero or negated mass is not a mass) and
    /// `K_c` a non-negative one (a negated stiffness). The error counts the offending
    /// diagonal entries and names the first.
    pub fn check_pencil(&self) -> Result<()> {
        for (name, mat, strict) in [("M_c", &self.mc, true), ("K_c", &self.kc, false)] {
            let n = mat.nrows();
            let mut diag = vec![0.0f64; n];
            let m = mat.as_ref();
            for j in 0..mat.ncols() {
                for (i, v) in m.row_idx_of_col(j).zip(m.val_of_col(j)) {
                    if i == j {
                        diag[j] += *v;
                    }
                }
            }
            let bad: Vec<usize> = (0..n)
                .filter(|&i| {
                    let d = diag[i];
                    !d.is_finite() || d < 0.0 || (strict && d == 0.0)
                })
                .collect();
            if let Some(&first) = bad.first() {
                return Err(Error::Invalid(format!(
                    "{name}: {} of {n} diagonal entries are {} (first: row {first}, {:e}): \
                     expected a {} matrix",
                    bad.len(),
                    if strict { "not positive" } else { "negative" },
                    diag[first],
                    if strict {
                        "positive definite mass"
                    } else {
                        "positive semi-definite stiffness"
                    }
                )));
            }
        }
        Ok(())
    }

    /// The QEP at friction coefficient `mu`: `X~ = X_c - mu F_X`.
    pub fn at(&self, mu: f64) -> Result<Qep> {
        if !mu.is_finite() {
            return Err(Error::param("mu", format!("must be finite, got {mu}")));
        }
        let comb = |x: &SparseMat, f: &SparseMat| add_scaled(x.as_ref(), 1.0, f.as_ref(), -mu);
        let c = match (&self.cc, &self.fc) {
            (Some(c), Some(f)) => Some(comb(c, f)?),
            (Some(c), None) => Some(c.clone()),
            (None, Some(f)) => Some(add_scaled(f.as_ref(), -mu, f.as_ref(), 0.0)?),
            (None, None) => None,
        };
        Ok(Qep {
            m: comb(&self.mc, &self.fm)?,
            c,
            k: comb(&self.kc, &self.fk)?,
        })
    }

    /// Expands a constrained vector to the unconstrained DOFs, `u = T u_c`.
    pub fn expand<T: Copy>(&self, uc: &[T]) -> Vec<T> {
        match &self.t {
            Some(t) => t.iter().map(|&j| uc[j]).collect(),
            None => uc.to_vec(),
        }
    }
}

/// A real reduction basis on the constrained space, `M_c`-orthonormal
/// (`V^T M_c V = I` to round-off), with how it was built.
#[derive(Debug, Clone)]
pub struct Basis {
    /// Columns of the basis (`n_c x m`).
    pub v: Mat<f64>,
    /// Wall time to build it (s).
    pub time_s: f64,
    /// Candidate vectors removed by the rank cut (and the optional SVD compression).
    pub dropped: usize,
    /// Iterations (iterative bases), else 0.
    pub iterations: usize,
    /// Friction coefficient the basis was built for; `None` when it does not depend on mu
    /// (valid for every mu of the contact set).
    pub mu: Option<f64>,
    /// Final convergence measure of an iterative basis (the residue method's largest
    /// energy-norm residual of its target modes); `None` otherwise.
    pub residual: Option<f64>,
    /// Anything the user should know (what the columns are, non-convergence, ...).
    pub notes: Vec<String>,
}

impl Basis {
    /// A basis of columns `v` (assumed `M_c`-orthonormal) with empty bookkeeping.
    pub fn new(v: Mat<f64>) -> Self {
        Self {
            v,
            time_s: 0.0,
            dropped: 0,
            iterations: 0,
            mu: None,
            residual: None,
            notes: Vec::new(),
        }
    }

    /// Number of columns `m`.
    pub fn len(&self) -> usize {
        self.v.ncols()
    }

    /// Whether the basis has no column.
    pub fn is_empty(&self) -> bool {
        self.v.ncols() == 0
    }
}

/// Everything a [`ReductionBasis`] may use to build its basis.
#[derive(Clone, Copy)]
pub struct BasisRequest<'a> {
    /// The full frictional operator of the contact set.
    pub op: &'a FrictionalOperator,
    /// Friction coefficient (bases fixed in mu ignore it).
    pub mu: f64,
    /// Frequency band of the stability analysis `(fmin, fmax)` (Hz).
    pub band_hz: (f64, f64),
    /// Solver of the full-order symmetric problems a basis needs (the coupled mu = 0
    /// real modes of `(K_c, M_c)`): normally a sparse backend (`arpack`, `krylov`).
    pub modal: &'a dyn EigenSolver,
    /// Solver of the reduced (projected) QEPs an iterative basis solves: normally `dense`.
    pub reduced: &'a dyn EigenSolver,
    /// Tolerances and limits handed to both solvers (their band fields are overridden).
    pub params: &'a EigenParams,
    /// The free-interface synthesis of the model, built once by the caller for a basis
    /// that asks for it ([`ReductionBasis::free_interface_cutoff`]); `None` otherwise.
    pub free: Option<&'a crate::synthesis::FreeInterface>,
}

/// Builds a reduction basis for one frictional operator.
///
/// The shared machinery (orthonormalization with a rank cut, projection, reduced solve,
/// expansion, backward errors on the full operator) lives in [`crate::reduction`]; a basis
/// only chooses its vectors.
pub trait ReductionBasis: Send + Sync {
    /// Plugin name (as registered).
    fn name(&self) -> &str;
    /// Whether the basis depends on mu. `false` (the default) means it is built once per
    /// contact set and reused across a whole mu sweep.
    fn depends_on_mu(&self) -> bool {
        false
    }
    /// The highest free-interface frequency (Hz) the basis needs when it works from a
    /// [`FreeInterface`](crate::synthesis::FreeInterface) of the model, for a band whose
    /// top is `band_top_hz`; `None` (the default) when it does not. The caller then builds
    /// that synthesis once per model and candidate pairs and hands it to every
    /// [`build`](Self::build) in [`BasisRequest::free`].
    fn free_interface_cutoff(&self, band_top_hz: f64) -> Option<f64> {
        let _ = band_top_hz;
        None
    }
    /// Builds the basis described by `request`.
    fn build(&self, request: &BasisRequest<'_>) -> Result<Basis>;
}

/// The contact problem condensed on the pairs after one Cholesky factorization of `K`:
/// gaps `g = q + (W + mu Wnt) Rn` with `q = g0 + Pn K^-1 F`, `W = Pn K^-1 Pn^T` and
/// `Wnt = Pn K^-1 Pt^T` (contact flexibilities, m/N). Shared by every equilibrium
/// solver; it keeps the factorization to recover displacements.
pub struct Condensation {
    factor: Cholesky,
    /// `W = Pn K^-1 Pn^T` (m/N), symmetric positive definite.
    pub w: Mat<f64>,
    /// `Wnt = Pn K^-1 Pt^T` (m/N).
    pub wnt: Mat<f64>,
    /// Gaps under the external load alone, `g0 + Pn K^-1 F` (m).
    pub q: Vec<f64>,
    /// Wall time of the condensation (s).
    pub time_s: f64,
}

impl Condensation {
    /// Factorizes `K` once and solves for the `2 nc` unit contact loads (in blocks).
    pub fn new(problem: &ContactProblem<'_>) -> Result<Self> {
        let start = std::time::Instant::now();
        let n = problem.k.nrows();
        let nc = problem.pn.nrows();
        check_problem(problem)?;
        let factor = Cholesky::new(problem.k, "K (contact condensation)")?;
        let pnt = transpose(problem.pn);
        let ptt = transpose(problem.pt);
        let mut w = Mat::<f64>::zeros(nc, nc);
        let mut wnt = Mat::<f64>::zeros(nc, nc);
        const BLOCK: usize = 64;
        for (src, dst) in [(&pnt, &mut w), (&ptt, &mut wnt)] {
            let mut c0 = 0;
            while c0 < nc {
                let b = BLOCK.min(nc - c0);
                let mut x = Mat::<f64>::zeros(n, b);
                for c in 0..b {
                    let a = src.as_ref();
                    for (r, v) in a.row_idx_of_col(c0 + c).zip(a.val_of_col(c0 + c)) {
                        x[(r, c)] = *v;
                    }
                }
                factor.solve_in_place(x.as_mut());
                let y = crate::linalg::sparse_times(problem.pn, x.as_ref());
                dst.as_mut().subcols_mut(c0, b).copy_from(&y);
                c0 += b;
            }
        }
        let mut kf = problem.f.to_vec();
        factor.solve_vec_in_place(&mut kf);
        let mut q = vec![0.0; nc];
        spmv(problem.pn, &kf, &mut q);
        q.iter_mut().zip(problem.g0).for_each(|(a, b)| *a += b);
        Ok(Self {
            factor,
            w,
            wnt,
            q,
            time_s: start.elapsed().as_secs_f64(),
        })
    }

    /// Number of pairs.
    pub fn pairs(&self) -> usize {
        self.q.len()
    }

    /// The LCP matrix `W + mu Wnt + c I` of a law with compliance `c`.
    pub fn lcp_matrix(&self, mu: f64, compliance: f64) -> Mat<f64> {
        let nc = self.pairs();
        Mat::from_fn(nc, nc, |i, j| {
            self.w[(i, j)] + mu * self.wnt[(i, j)] + if i == j { compliance } else { 0.0 }
        })
    }

    /// Builds the [`Equilibrium`] of reactions `rn`: displacements from one solve with
    /// the kept factorization, the global equilibrium residual as a backward error
    /// `||K U - F - (Pn + mu Pt)^T Rn|| / (||K||_1 ||U|| + ||F + (Pn + mu Pt)^T Rn||)`
    /// (relative to the load alone it would measure the cancellation in `K U`, about
    /// `cond(K)` times round-off, rather than the solve), the complementarity
    /// residual (largest of: negative reaction / total, penetration beyond the law's
    /// compliance / gap scale, `Rn_i g_i` / (total x gap scale)), and the active set
    /// `Rn_i > 1e-9 max Rn`.
    pub fn finish(
        &self,
        problem: &ContactProblem<'_>,
        law: &dyn ContactLaw,
        rn: Vec<f64>,
        mu: f64,
        iterations: usize,
        time_s: f64,
    ) -> Result<Equilibrium> {
        if !rn.iter().any(|&r| r > 0.0) {
            return Err(Error::Invalid(format!(
                "no contact: the load opens every one of the {} pairs (is the disc pressed \
                 towards the pin?)",
                rn.len()
            )));
        }
        let n = problem.k.nrows();
        let mut load = problem.f.to_vec();
        add_transpose_times(problem.pn, &rn, 1.0, &mut load);
        add_transpose_times(problem.pt, &rn, mu, &mut load);
        let mut u = load.clone();
        self.factor.solve_vec_in_place(&mut u);
        let mut ku = vec![0.0; n];
        spmv(problem.k, &u, &mut ku);
        let r: Vec<f64> = ku.iter().zip(&load).map(|(a, b)| a - b).collect();
        let equilibrium_residual = norm2(&r)
            / (crate::linalg::norm1(problem.k) * norm2(&u) + norm2(&load)).max(f64::MIN_POSITIVE);
        let mut g = vec![0.0; rn.len()];
        spmv(problem.pn, &u, &mut g);
        g.iter_mut().zip(problem.g0).for_each(|(a, b)| *a += b);
        let c = law.compliance();
        let total: f64 = rn.iter().sum::<f64>().abs().max(f64::MIN_POSITIVE);
        let gscale = self
            .q
            .iter()
            .fold(0.0f64, |a, b| a.max(b.abs()))
            .max(f64::MIN_POSITIVE);
        let mut comp = 0.0f64;
        for (ri, gi) in rn.iter().zip(&g) {
            let gap = gi + c * ri; // zero for a closed pair under the law
            comp = comp
                .max((-ri).max(0.0) / total)
                .max((-gap).max(0.0) / gscale)
                .max((ri.max(0.0) / total) * (gap.abs() / gscale));
        }
        let rmax = rn.iter().fold(0.0f64, |a, &b| a.max(b));
        let active = rn.iter().map(|&r| r > 1e-9 * rmax).collect();
        Ok(Equilibrium {
            mu,
            u,
            rn,
            active,
            iterations,
            factorizations: 1,
            equilibrium_residual,
            complementarity_residual: comp,
            time_s,
        })
    }
}

/// Rejects a non-finite friction coefficient (a negative one is valid here: it is the
/// same as reversing the rotation; user-facing inputs reject it earlier).
pub fn check_mu(mu: f64) -> Result<()> {
    if mu.is_finite() {
        Ok(())
    } else {
        Err(Error::param(
            "mu",
            format!("expected a finite friction coefficient, got {mu}"),
        ))
    }
}

fn check_problem(p: &ContactProblem<'_>) -> Result<()> {
    let n = p.k.nrows();
    let nc = p.pn.nrows();
    if nc == 0 {
        return Err(Error::Invalid(
            "the contact problem has no contact pairs".into(),
        ));
    }
    for (what, got, want) in [
        ("Pn columns", p.pn.ncols(), n),
        ("Pt columns", p.pt.ncols(), n),
        ("Pt rows", p.pt.nrows(), nc),
        ("F length", p.f.len(), n),
        ("g0 length", p.g0.len(), nc),
    ] {
        if got != want {
            return Err(Error::Dimension {
                context: format!("contact problem: {what}"),
                expected: want,
                got,
            });
        }
    }
    if p.f.iter().chain(p.g0).any(|v| !v.is_finite()) {
        return Err(Error::Invalid(
            "contact problem: F or g0 holds NaN or infinite values".into(),
        ));
    }
    Ok(())
}

fn transpose(a: SparseRef<'_>) -> SparseMat {
    let mut t = Vec::with_capacity(a.compute_nnz());
    for j in 0..a.ncols() {
        for (r, v) in a.row_idx_of_col(j).zip(a.val_of_col(j)) {
            t.push(Triplet::new(j, r, *v));
        }
    }
    SparseMat::try_new_from_triplets(a.ncols(), a.nrows(), &t).expect("valid transpose")
}

/// `y += alpha A^T x`.
pub fn add_transpose_times(a: SparseRef<'_>, x: &[f64], alpha: f64, y: &mut [f64]) {
    for j in 0..a.ncols() {
        let s: f64 = a
            .row_idx_of_col(j)
            .zip(a.val_of_col(j))
            .map(|(r, v)| v * x[r])
            .sum();
        y[j] += alpha * s;
    }
}

/// Outcome of [`solve_lcp`].
#[derive(Debug, Clone)]
pub struct LcpSolution {
    /// The solution `z >= 0`.
    pub z: Vec<f64>,
    /// `w = q + A z >= 0`.
    pub w: Vec<f64>,
    /// Pivoting iterations (one dense solve each).
    pub iterations: usize,
}

/// Solves the linear complementarity problem `0 <= z ⟂ w = q + A z >= 0` exactly by
/// block principal pivoting (Júdice and Pires), falling back to Murty's single
/// least-index pivot when the number of infeasibilities stops decreasing: finite for a
/// P-matrix `A` (e.g. `W + mu Wnt` below the flutter of the contact problem, or a
/// symmetric positive definite `W`). Tolerances are relative to `max |q|` and `max |z|`.
pub fn solve_lcp(a: MatRef<'_, f64>, q: &[f64], max_iterations: usize) -> Result<LcpSolution> {
    let n = q.len();
    if a.nrows() != n || a.ncols() != n {
        return Err(Error::Dimension {
            context: "LCP matrix".into(),
            expected: n,
            got: a.nrows(),
        });
    }
    if q.iter().any(|v| !v.is_finite()) || (0..n).any(|j| (0..n).any(|i| !a[(i, j)].is_finite())) {
        return Err(Error::Invalid(
            "LCP data hold NaN or infinite values".into(),
        ));
    }
    let qscale = q.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let mut basic: Vec<bool> = q.iter().map(|&v| v < 0.0).collect();
    let mut best = usize::MAX;
    let mut trials = 3;
    let mut z = vec![0.0; n];
    let mut w = q.to_vec();
    let mut last = (0usize, 0.0f64, 0.0f64);
    for it in 1..=max_iterations {
        let s: Vec<usize> = (0..n).filter(|&i| basic[i]).collect();
        z.iter_mut().for_each(|v| *v = 0.0);
        if !s.is_empty() {
            let ass = Mat::from_fn(s.len(), s.len(), |i, j| a[(s[i], s[j])]);
            let rhs = Mat::from_fn(s.len(), 1, |i, _| -q[s[i]]);
            let zs = faer::linalg::solvers::Solve::solve(&ass.partial_piv_lu(), &rhs);
            for (k, &i) in s.iter().enumerate() {
                z[i] = zs[(k, 0)];
            }
        }
        for i in 0..n {
            w[i] = q[i] + s.iter().map(|&j| a[(i, j)] * z[j]).sum::<f64>();
        }
        if z.iter().chain(&w).any(|v| !v.is_finite()) {
            return Err(Error::NotConverged {
                method: "LCP block pivoting".into(),
                iterations: it,
                detail: "singular principal submatrix: the LCP matrix is not a P-matrix \
                         (friction too high for a unique sliding equilibrium?)"
                    .into(),
            });
        }
        let zscale = z
            .iter()
            .fold(0.0f64, |m, v| m.max(v.abs()))
            .max(f64::MIN_POSITIVE);
        let (ez, ew) = (1e-12 * zscale, 1e-12 * qscale.max(f64::MIN_POSITIVE));
        let bad: Vec<usize> = (0..n)
            .filter(|&i| (basic[i] && z[i] < -ez) || (!basic[i] && w[i] < -ew))
            .collect();
        if bad.is_empty() {
            for i in 0..n {
                if basic[i] {
                    w[i] = 0.0; // w_S = 0 up to round-off
                } else {
                    z[i] = 0.0;
                }
            }
            return Ok(LcpSolution {
                z: z.iter().map(|v| v.max(0.0)).collect(),
                w,
                iterations: it,
            });
        }
        let worst_z = bad
            .iter()
            .filter(|&&i| basic[i])
            .map(|&i| -z[i])
            .fold(0.0, f64::max);
        let worst_w = bad
            .iter()
            .filter(|&&i| !basic[i])
            .map(|&i| -w[i])
            .fold(0.0, f64::max);
        last = (bad.len(), worst_z, worst_w);
        if bad.len() < best {
            best = bad.len();
            trials = 3;
            bad.iter().for_each(|&i| basic[i] = !basic[i]);
        } else if trials > 0 {
            trials -= 1;
            bad.iter().for_each(|&i| basic[i] = !basic[i]);
        } else {
            let i = bad[0]; // Murty: least index

            basic[i] = !basic[i];
        }
    }
    Err(Error::NotConverged {
        method: "LCP block pivoting".into(),
        iterations: max_iterations,
        detail: format!(
            "{} infeasible pairs left (largest negative reaction {:.3e}, largest \
             penetration {:.3e})",
            last.0, last.1, last.2
        ),
    })
}
