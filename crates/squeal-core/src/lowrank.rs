//! The low-rank (Woodbury) shift-invert of an undamped frictional operator.
//!
//! For `C = 0` the squared transformation of the band driver needs solves with
//!
//! ```text
//! A(s) = K~ - s M~ = S(s) - mu (F_K - s F_M),     S(s) = K_c - s M_c,
//! F_K - s F_M = U W(s)^T,                          W(s) = W_K - s W_M,
//! ```
//!
//! where `S(s)` is real symmetric (indefinite for `s` inside the spectrum) and
//! `U = T^T P~t^T` ([`FrictionalOperator::friction_loads`], `n x nA`) has one column per
//! active pair. Every column of `U` is supported on DOFs of its own pair only, so the row
//! `r` of the largest `|U_ri|` gives `w_i^T = F_X[r, :] / U[r, i]` ([`FrictionLowRank`]).
//!
//! `S(s)` is factorized once per shift by faer's supernodal Bunch-Kaufman `L B L^T`
//! (pivoting within supernodes, [`SymmetricShift`]) and, with `Z = S^-1 U` (`nA` solves)
//! and the small dense LU of `G = I - mu W^T Z`, the Woodbury identity gives
//!
//! ```text
//! A^-1 b = S^-1 b + mu Z G^-1 W^T S^-1 b
//! ```
//!
//! ([`QepLowRankSquared`]): one symmetric solve and two thin dense products per
//! application. `S(s)`, its factorization, `W(s)` and `Z` depend on `s` only, not on
//! `mu`: a [`SymmetricShift`] is `Arc`-shareable across friction coefficients.
//!
//! Memory: the symmetric factor plus the dense `n x nA` block `Z` (no non-symmetric LU).

use crate::contact::FrictionalOperator;
use crate::linalg::norm1;
use crate::qep::{ComplexLinOp, Qep};
use crate::{c64, Error, Result, SparseMat, SparseRef};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::matmul::matmul;
use faer::linalg::solvers::{PartialPivLu, Solve};
use faer::perm::PermRef;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, IntranodeLbltRef, SymbolicCholesky,
    SymmetricOrdering,
};
use faer::sparse::linalg::{SupernodalThreshold, SymbolicSupernodalParams};
use faer::sparse::{SymbolicSparseColMat, Triplet};
use faer::{Accum, Conj, Mat, MatMut, Par, Side};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;

/// Relative asymmetry of `K_c` or `M_c` above which the low-rank path refuses the operator
/// (its symmetric factorization would solve the wrong matrix).
pub const MAX_ASYMMETRY: f64 = 1e-10;

/// Relative error of `U W^T` against `F_K` / `F_M` above which the friction part is not
/// considered recovered ([`FrictionLowRank::new`]).
pub const MAX_IDENTITY_ERROR: f64 = 1e-10;

/// Relative residual of a probe solve above which [`QepLowRankSquared`] adds one step of
/// iterative refinement to every application.
pub const REFINE_ABOVE: f64 = 1e-11;

/// Columns of `U` solved together when computing `Z = S^-1 U`.
const Z_BLOCK: usize = 64;

/// Symbolic analysis of `S(s) = K_c - s M_c`, valid for every shift `s`: the lower
/// triangle of the union pattern of `K_c`, `M_c` and the diagonal, the AMD ordering and
/// the supernodal structure of the factor. `K_c` and `M_c` are used symmetrized,
/// `(X + X^T) / 2`; their measured asymmetry is kept in [`asymmetry`](Self::asymmetry).
#[derive(Debug)]
pub struct SymmetricPencil {
    pattern: SymbolicSparseColMat<usize>,
    /// (slot in `pattern`, weight) of every stored entry of `K_c`, in storage order.
    k_slot: Vec<(usize, f64)>,
    /// Same for `M_c`.
    m_slot: Vec<(usize, f64)>,
    chol: SymbolicCholesky<usize>,
    asymmetry: f64,
}

impl SymmetricPencil {
    /// Analyses the pencil `(K_c, M_c)` of `op`.
    pub fn new(op: &FrictionalOperator) -> Result<Self> {
        let n = op.dim();
        let (kc, mc) = (op.kc.as_ref(), op.mc.as_ref());
        let mut trip = Vec::with_capacity(kc.compute_nnz() + mc.compute_nnz() + n);
        for a in [kc, mc] {
            for j in 0..n {
                trip.extend(
                    a.row_idx_of_col(j)
                        .map(|i| Triplet::new(i.max(j), i.min(j), 1.0)),
                );
            }
        }
        trip.extend((0..n).map(|i| Triplet::new(i, i, 1.0)));
        let pattern = SparseMat::try_new_from_triplets(n, n, &trip)
            .map_err(|e| Error::Invalid(format!("SymmetricPencil: {e:?}")))?
            .into_parts()
            .0;
        drop(trip);
        let pat = pattern.as_ref();
        let slots = |a: SparseRef<'_>| -> Vec<(usize, f64)> {
            let mut out = Vec::with_capacity(a.compute_nnz());
            for j in 0..n {
                for i in a.row_idx_of_col(j) {
                    let (r, c) = (i.max(j), i.min(j));
                    let rows = pat.row_idx_of_col_raw(c);
                    let p = rows
                        .binary_search(&r)
                        .expect("SymmetricPencil: entry missing from its own pattern");
                    let w = if i == j { 1.0 } else { 0.5 };
                    out.push((pat.col_range(c).start + p, w));
                }
            }
            out
        };
        let (k_slot, m_slot) = (slots(kc), slots(mc));
        // Asymmetry: lower and (transposed) upper parts accumulated apart.
        let mut asymmetry = 0.0f64;
        for (a, slot) in [(kc, &k_slot), (mc, &m_slot)] {
            let nnz = pat.compute_nnz();
            let (mut lo, mut up) = (vec![0.0; nnz], vec![0.0; nnz]);
            let mut q = 0;
            for j in 0..n {
                for (i, v) in a.row_idx_of_col(j).zip(a.val_of_col(j)) {
                    let p = slot[q].0;
                    q += 1;
                    if i >= j {
                        lo[p] += v;
                    }
                    if i <= j {
                        up[p] += v;
                    }
                }
            }
            let diff = lo
                .iter()
                .zip(&up)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            let big = lo.iter().map(|v| v.abs()).fold(0.0, f64::max);
            if big > 0.0 {
                asymmetry = asymmetry.max(diff / big);
            }
        }
        let chol = factorize_symbolic_cholesky(
            pat,
            Side::Lower,
            SymmetricOrdering::Amd,
            CholeskySymbolicParams {
                // Bunch-Kaufman pivoting exists only in the supernodal variant.
                supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
                supernodal_params: SymbolicSupernodalParams::default(),
                ..Default::default()
            },
        )
        .map_err(|e| Error::Factorization {
            what: format!("K_c - s M_c (symbolic, n = {n})"),
            reason: format!("{e:?}"),
        })?;
        Ok(Self {
            pattern,
            k_slot,
            m_slot,
            chol,
            asymmetry,
        })
    }

    /// Size of the pencil.
    pub fn dim(&self) -> usize {
        self.pattern.nrows()
    }

    /// Stored entries of the factor `L` (supernodal blocks included).
    pub fn factor_entries(&self) -> usize {
        self.chol.len_val()
    }

    /// Largest relative asymmetry `max |X - X^T| / max |X|` of `K_c` and `M_c`.
    pub fn asymmetry(&self) -> f64 {
        self.asymmetry
    }

    /// Lower-triangle values of `K_c - s M_c` (symmetrized) on the pattern.
    fn assemble(&self, op: &FrictionalOperator, s: f64) -> Result<Vec<f64>> {
        let n = self.dim();
        if op.dim() != n
            || op.kc.compute_nnz() != self.k_slot.len()
            || op.mc.compute_nnz() != self.m_slot.len()
        {
            return Err(Error::Invalid(
                "SymmetricPencil: analysis built for another operator".into(),
            ));
        }
        let mut vals = vec![0.0; self.pattern.compute_nnz()];
        for (a, slot, scale) in [(&op.kc, &self.k_slot, 1.0), (&op.mc, &self.m_slot, -s)] {
            let a = a.as_ref();
            let mut q = 0;
            for j in 0..n {
                for v in a.val_of_col(j) {
                    let (p, w) = slot[q];
                    vals[p] += scale * w * v;
                    q += 1;
                }
            }
        }
        Ok(vals)
    }
}

/// The friction part as an explicit low-rank product: `F_K = U W_K^T`, `F_M = U W_M^T`,
/// `U = T^T P~t^T` (`n x nA`), `W_K`, `W_M` sparse `n x nA`.
#[derive(Debug, Clone)]
pub struct FrictionLowRank {
    /// The friction load directions `U` (one column per active pair).
    pub u: SparseMat,
    /// `W_K` with `F_K = U W_K^T`.
    pub wk: SparseMat,
    /// `W_M` with `F_M = U W_M^T`.
    pub wm: SparseMat,
    /// Measured `max(||F_K x - U W_K^T x|| / (||F_K||_1 ||x||), same for F_M)` on probe
    /// vectors.
    pub identity_error: f64,
}

impl FrictionLowRank {
    /// Recovers `W_K` and `W_M` from `op.fk`, `op.fm` and `op.friction_loads`: the row `r`
    /// of the largest `|U_ri|` of column `i` carries only pair `i`, so
    /// `w_i^T = F_X[r, :] / U[r, i]`. Fails when `friction_loads` is missing, when such a
    /// row is shared by two columns, or when the recovered product does not reproduce
    /// `F_K` and `F_M` (relative error above [`MAX_IDENTITY_ERROR`]).
    pub fn new(op: &FrictionalOperator) -> Result<Self> {
        let n = op.dim();
        let u = op.friction_loads.as_ref().ok_or_else(|| {
            Error::Invalid("low-rank friction: the operator has no friction_loads (U)".into())
        })?;
        if u.nrows() != n {
            return Err(Error::Dimension {
                context: "low-rank friction: rows of friction_loads".into(),
                expected: n,
                got: u.nrows(),
            });
        }
        let na = u.ncols();
        let ur = u.as_ref();
        let mut row_count = vec![0usize; n];
        for j in 0..na {
            for (i, v) in ur.row_idx_of_col(j).zip(ur.val_of_col(j)) {
                if *v != 0.0 {
                    row_count[i] += 1;
                }
            }
        }
        // pivot row of each column -> (column, 1 / U[r, column])
        let mut pivot_of_row: Vec<Option<(usize, f64)>> = vec![None; n];
        for j in 0..na {
            let best = ur
                .row_idx_of_col(j)
                .zip(ur.val_of_col(j))
                .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()));
            let Some((r, &v)) = best else { continue };
            if v == 0.0 {
                continue;
            }
            if row_count[r] != 1 || pivot_of_row[r].is_some() {
                return Err(Error::Invalid(format!(
                    "low-rank friction: row {r} of U is shared by several pairs (column {j})"
                )));
            }
            pivot_of_row[r] = Some((j, 1.0 / v));
        }
        let recover = |f: SparseRef<'_>| -> Result<SparseMat> {
            let mut trip = Vec::new();
            for c in 0..n {
                for (r, v) in f.row_idx_of_col(c).zip(f.val_of_col(c)) {
                    if let Some((j, inv)) = pivot_of_row[r] {
                        trip.push(Triplet::new(c, j, v * inv));
                    }
                }
            }
            SparseMat::try_new_from_triplets(n, na, &trip)
                .map_err(|e| Error::Invalid(format!("low-rank friction: {e:?}")))
        };
        let wk = recover(op.fk.as_ref())?;
        let wm = recover(op.fm.as_ref())?;
        let mut out = Self {
            u: u.clone(),
            wk,
            wm,
            identity_error: 0.0,
        };
        out.identity_error = out
            .product_error(op.fk.as_ref(), false)
            .max(out.product_error(op.fm.as_ref(), true));
        if out.identity_error.is_nan() || out.identity_error > MAX_IDENTITY_ERROR {
            return Err(Error::Invalid(format!(
                "low-rank friction: U W^T reproduces F_K / F_M only to {:.2e} (relative)",
                out.identity_error
            )));
        }
        Ok(out)
    }

    /// Rank `nA` (number of active pairs).
    pub fn rank(&self) -> usize {
        self.u.ncols()
    }

    /// `max ||F x - U W^T x|| / (||F||_1 ||x||)` over two probe vectors (`W = W_M` when
    /// `mass`, else `W_K`).
    fn product_error(&self, f: SparseRef<'_>, mass: bool) -> f64 {
        let n = f.nrows();
        let w = if mass { &self.wm } else { &self.wk };
        let fnorm = norm1(f);
        let mut worst = 0.0f64;
        for k in 0..2 {
            let x: Vec<f64> = (0..n)
                .map(|i| 1.0 + 0.5 * ((i * (k + 1)) as f64 * 0.37).sin())
                .collect();
            let mut y = vec![0.0; n];
            crate::linalg::spmv(f, &x, &mut y);
            let t = sparse_t_dense(w.as_ref(), &x);
            let ur = self.u.as_ref();
            for j in 0..ur.ncols() {
                for (i, v) in ur.row_idx_of_col(j).zip(ur.val_of_col(j)) {
                    y[i] -= v * t[j];
                }
            }
            let e = crate::linalg::norm2(&y);
            let den = fnorm * crate::linalg::norm2(&x);
            if den > 0.0 {
                worst = worst.max(e / den);
            } else if e > 0.0 {
                worst = f64::INFINITY;
            }
        }
        worst
    }
}

/// `W^T x` for a sparse `n x k` `W` and a dense vector.
fn sparse_t_dense(w: SparseRef<'_>, x: &[f64]) -> Vec<f64> {
    (0..w.ncols())
        .map(|j| {
            w.row_idx_of_col(j)
                .zip(w.val_of_col(j))
                .map(|(i, v)| v * x[i])
                .sum()
        })
        .collect()
}

/// Everything of one real shift `s` that does not depend on `mu`: the symmetric
/// Bunch-Kaufman factorization of `S(s) = K_c - s M_c`, `W(s) = W_K - s W_M` and
/// `Z = S(s)^-1 U`. Shareable (`Arc`) by the operators of several friction coefficients.
pub struct SymmetricShift {
    s: f64,
    pencil: Arc<SymmetricPencil>,
    l_values: Vec<f64>,
    subdiag: Vec<f64>,
    perm_fwd: Vec<usize>,
    perm_inv: Vec<usize>,
    w: SparseMat,
    z: Mat<f64>,
    par: Par,
    /// Relative residual of the probe solve with `S(s)`.
    s_residual: f64,
}

impl SymmetricShift {
    /// Factorizes `S(s)` (numeric only, reusing `pencil`) and computes `Z = S^-1 U`.
    pub fn new(
        op: &FrictionalOperator,
        pencil: Arc<SymmetricPencil>,
        friction: &FrictionLowRank,
        s: f64,
    ) -> Result<Self> {
        let n = pencil.dim();
        if !s.is_finite() {
            return Err(Error::param("sigma_s", format!("must be finite, got {s}")));
        }
        let what = || format!("K_c - s M_c (s = {s:.6e} (rad/s)^2, n = {n}, LBL^T)");
        let vals = pencil.assemble(op, s)?;
        let a = faer::sparse::SparseColMatRef::new(pencil.pattern.as_ref(), &vals);
        let par = faer::get_global_parallelism();
        let chol = &pencil.chol;
        let mut l_values = vec![0.0; chol.len_val()];
        let mut subdiag = vec![0.0; n];
        let mut perm_fwd = vec![0usize; n];
        let mut perm_inv = vec![0usize; n];
        {
            let req = chol.factorize_numeric_intranode_lblt_scratch::<f64>(par, Default::default());
            let mut mem = MemBuffer::try_new(req).map_err(|e| Error::Factorization {
                what: what(),
                reason: format!("workspace: {e:?}"),
            })?;
            chol.factorize_numeric_intranode_lblt(
                &mut l_values,
                &mut subdiag,
                &mut perm_fwd,
                &mut perm_inv,
                a,
                Side::Lower,
                par,
                MemStack::new(&mut mem),
                Default::default(),
            );
        }
        drop(vals);
        let w = crate::linalg::add_scaled(friction.wk.as_ref(), 1.0, friction.wm.as_ref(), -s)?;
        let mut this = Self {
            s,
            pencil,
            l_values,
            subdiag,
            perm_fwd,
            perm_inv,
            w,
            z: Mat::zeros(0, 0),
            par,
            s_residual: 0.0,
        };
        // probe: S x = b
        let b: Vec<f64> = (0..n).map(|i| 1.0 + 0.1 * (i as f64).sin()).collect();
        let mut x = Mat::<f64>::from_fn(n, 1, |i, _| b[i]);
        this.solve_in_place(x.as_mut());
        let xs: Vec<f64> = (0..n).map(|i| x[(i, 0)]).collect();
        if xs.iter().any(|v| !v.is_finite()) {
            return Err(Error::Factorization {
                what: what(),
                reason: "numerically singular (is the shift an eigenvalue of (K_c, M_c)?)".into(),
            });
        }
        let mut r = vec![0.0; n];
        crate::linalg::spmv(op.kc.as_ref(), &xs, &mut r);
        let mut mx = vec![0.0; n];
        crate::linalg::spmv(op.mc.as_ref(), &xs, &mut mx);
        for i in 0..n {
            r[i] = b[i] - (r[i] - s * mx[i]);
        }
        let scale =
            (norm1(op.kc.as_ref()) + s.abs() * norm1(op.mc.as_ref())) * crate::linalg::norm2(&xs);
        this.s_residual = if scale > 0.0 {
            crate::linalg::norm2(&r) / scale
        } else {
            0.0
        };
        // Z = S^-1 U, by blocks of columns
        let na = friction.rank();
        let ur = friction.u.as_ref();
        let mut z = Mat::<f64>::zeros(n, na);
        let mut c0 = 0;
        while c0 < na {
            let k = Z_BLOCK.min(na - c0);
            let mut blk = z.as_mut().submatrix_mut(0, c0, n, k);
            for c in 0..k {
                for (i, v) in ur.row_idx_of_col(c0 + c).zip(ur.val_of_col(c0 + c)) {
                    blk[(i, c)] = *v;
                }
            }
            this.solve_in_place(blk);
            c0 += k;
        }
        this.z = z;
        Ok(this)
    }

    /// The shift `s`.
    pub fn s(&self) -> f64 {
        self.s
    }

    /// Size.
    pub fn dim(&self) -> usize {
        self.pencil.dim()
    }

    /// The symbolic analysis it was factorized with.
    pub fn pencil(&self) -> &Arc<SymmetricPencil> {
        &self.pencil
    }

    /// Relative residual `||b - S x|| / ((||K_c||_1 + |s| ||M_c||_1) ||x||)` of a probe
    /// solve.
    pub fn s_residual(&self) -> f64 {
        self.s_residual
    }

    /// `B <- S(s)^-1 B` (any number of columns).
    pub fn solve_in_place(&self, b: MatMut<'_, f64>) {
        let n = self.dim();
        let chol = &self.pencil.chol;
        let perm = PermRef::new_checked(&self.perm_fwd, &self.perm_inv, n);
        let lblt = IntranodeLbltRef::new(chol, &self.l_values, &self.subdiag, perm);
        let mut mem = MemBuffer::new(chol.solve_in_place_scratch::<f64>(b.ncols(), self.par));
        lblt.solve_in_place_with_conj(Conj::No, b, self.par, MemStack::new(&mut mem));
    }
}

/// Shift-invert of the squared transformation of an undamped frictional QEP through the
/// low-rank structure: `OP = A(s)^-1 M~` with `A(s) = K~ - s M~` applied by the Woodbury
/// identity on a [`SymmetricShift`] (see the module docs). Same contract as
/// [`QepSquaredShift`](crate::qep::QepSquaredShift): `s = sigma_s + 1/theta`,
/// `lambda = i sqrt(s)`.
pub struct QepLowRankSquared<'a> {
    qep: &'a Qep,
    shift: Arc<SymmetricShift>,
    mu: f64,
    g: PartialPivLu<f64>,
    refine: bool,
    residual: f64,
    applications: AtomicUsize,
}

impl<'a> QepLowRankSquared<'a> {
    /// Builds the operator for `qep = op.at(mu)` (undamped) on a factorized shift: forms
    /// and factorizes `G = I - mu W^T Z`, then checks one solve with `A(s)`; when its
    /// relative residual exceeds [`REFINE_ABOVE`], every application adds one step of
    /// iterative refinement.
    pub fn new(qep: &'a Qep, shift: Arc<SymmetricShift>, mu: f64) -> Result<Self> {
        let n = qep.dim();
        if qep.c.is_some() {
            return Err(Error::Invalid(
                "the squared spectral transformation needs C = 0".into(),
            ));
        }
        if shift.dim() != n {
            return Err(Error::Dimension {
                context: "QepLowRankSquared: shift factorization of another size".into(),
                expected: n,
                got: shift.dim(),
            });
        }
        let na = shift.z.ncols();
        // G = I - mu W^T Z
        let w = shift.w.as_ref();
        let mut gm = Mat::<f64>::identity(na, na);
        for p in 0..na {
            for (r, v) in w.row_idx_of_col(p).zip(w.val_of_col(p)) {
                let zr = shift.z.row(r);
                for q in 0..na {
                    gm[(p, q)] -= mu * v * zr[q];
                }
            }
        }
        let g = gm.partial_piv_lu();
        let s_shift = shift.s;
        let what = move || {
            format!("Woodbury capacitance I - mu W^T Z (nA = {na}, mu = {mu}, s = {s_shift:.6e})")
        };
        if na > 0 {
            let u = g.U();
            let (mut pmin, mut pmax) = (f64::INFINITY, 0.0f64);
            for i in 0..na {
                pmin = pmin.min(u[(i, i)].abs());
                pmax = pmax.max(u[(i, i)].abs());
            }
            if pmin.is_nan() || pmin <= 1e-14 * pmax {
                return Err(Error::Factorization {
                    what: what(),
                    reason: "numerically singular (is the shift an eigenvalue?)".into(),
                });
            }
        }
        let mut this = Self {
            qep,
            shift,
            mu,
            g,
            refine: false,
            residual: 0.0,
            applications: AtomicUsize::new(0),
        };
        let b = Mat::<f64>::from_fn(n, 1, |i, _| 1.0 + 0.1 * (i as f64).sin());
        let mut x = b.clone();
        this.solve_in_place(x.as_mut());
        if (0..n).any(|i| !x[(i, 0)].is_finite()) {
            return Err(Error::Factorization {
                what: what(),
                reason: "non-finite solve (is the shift an eigenvalue?)".into(),
            });
        }
        this.residual = this.relative_residual(b.as_ref(), x.as_ref());
        if this.residual > REFINE_ABOVE {
            this.refine = true;
            let mut x = b.clone();
            this.solve_in_place(x.as_mut());
            this.residual = this.relative_residual(b.as_ref(), x.as_ref());
        }
        Ok(this)
    }

    /// The shift data (shareable across `mu`).
    pub fn shift(&self) -> &Arc<SymmetricShift> {
        &self.shift
    }

    /// Relative residual `||b - A x|| / ((||K~||_1 + |s| ||M~||_1) ||x||)` of the probe
    /// solve (after refinement when it is on).
    pub fn probe_residual(&self) -> f64 {
        self.residual
    }

    /// Whether applications add a step of iterative refinement.
    pub fn refines(&self) -> bool {
        self.refine
    }

    /// How many times the operator was applied.
    pub fn applications(&self) -> usize {
        self.applications.load(Ordering::Relaxed)
    }

    /// `s = sigma_s + 1/theta` and `lambda = i sqrt(s)`.
    pub fn lambda_of_theta(&self, theta: c64) -> (c64, c64) {
        let s = c64::new(self.shift.s, 0.0) + c64::new(1.0, 0.0) / theta;
        (s, c64::new(0.0, 1.0) * s.sqrt())
    }

    /// `B <- A(s)^-1 B` by Woodbury (plus refinement when [`refines`](Self::refines)).
    pub fn solve_in_place(&self, mut b: MatMut<'_, f64>) {
        if !self.refine {
            self.woodbury_in_place(b);
            return;
        }
        let rhs = b.to_owned();
        self.woodbury_in_place(b.as_mut());
        let mut r = self.residual_block(rhs.as_ref(), b.as_ref());
        self.woodbury_in_place(r.as_mut());
        for j in 0..b.ncols() {
            for i in 0..b.nrows() {
                b[(i, j)] += r[(i, j)];
            }
        }
    }

    fn woodbury_in_place(&self, mut b: MatMut<'_, f64>) {
        let sh = &*self.shift;
        sh.solve_in_place(b.as_mut());
        let na = sh.z.ncols();
        if na == 0 || self.mu == 0.0 {
            return;
        }
        let k = b.ncols();
        let w = sh.w.as_ref();
        let mut t = Mat::<f64>::zeros(na, k);
        for p in 0..na {
            for (r, v) in w.row_idx_of_col(p).zip(w.val_of_col(p)) {
                for c in 0..k {
                    t[(p, c)] += v * b[(r, c)];
                }
            }
        }
        self.g.solve_in_place(t.as_mut());
        matmul(b, Accum::Add, sh.z.as_ref(), t.as_ref(), self.mu, sh.par);
    }

    /// `B - A X` with `A = K~ - s M~`.
    fn residual_block(&self, b: faer::MatRef<'_, f64>, x: faer::MatRef<'_, f64>) -> Mat<f64> {
        let s = self.shift.s;
        let mut r = b.to_owned();
        for (a, scale) in [(self.qep.k.as_ref(), -1.0), (self.qep.m.as_ref(), s)] {
            for j in 0..a.ncols() {
                for (i, v) in a.row_idx_of_col(j).zip(a.val_of_col(j)) {
                    for c in 0..x.ncols() {
                        r[(i, c)] += scale * v * x[(j, c)];
                    }
                }
            }
        }
        r
    }

    fn relative_residual(&self, b: faer::MatRef<'_, f64>, x: faer::MatRef<'_, f64>) -> f64 {
        let r = self.residual_block(b, x);
        let scale = (norm1(self.qep.k.as_ref()) + self.shift.s.abs() * norm1(self.qep.m.as_ref()))
            * x.norm_l2();
        if scale > 0.0 {
            r.norm_l2() / scale
        } else {
            0.0
        }
    }
}

impl ComplexLinOp for QepLowRankSquared<'_> {
    fn dim(&self) -> usize {
        self.qep.dim()
    }

    fn apply(&self, x: &[c64], y: &mut [c64]) {
        let n = self.qep.dim();
        assert_eq!(
            x.len(),
            n,
            "QepLowRankSquared::apply: x has the wrong length"
        );
        assert_eq!(
            y.len(),
            n,
            "QepLowRankSquared::apply: y has the wrong length"
        );
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
        self.solve_in_place(b.as_mut());
        for (i, v) in y.iter_mut().enumerate() {
            *v = c64::new(b[(i, 0)], b[(i, 1)]);
        }
        self.applications.fetch_add(1, Ordering::Relaxed);
    }
}
