//! One real shift of the low-rank path ([`SymmetricShift`]): the Bunch-Kaufman
//! `L B L^T` of `S(s) = K_c - s M_c`, `W(s)` and `Z = S(s)^-1 U`.

use super::{FrictionLowRank, SymmetricPencil};
use crate::linalg::norm1;
use crate::operator::FrictionalOperator;
use crate::{Error, Result, SparseMat};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::perm::PermRef;
use faer::sparse::linalg::cholesky::IntranodeLbltRef;
use faer::{Conj, Mat, MatMut, Par, Side};
use std::sync::Arc;

/// Columns of `U` solved together when computing `Z = S^-1 U`.
const Z_BLOCK: usize = 64;

/// Everything of one real shift `s` that does not depend on `mu`: the symmetric
/// Bunch-Kaufman factorization of `S(s) = K_c - s M_c`, `W(s) = W_K - s W_M` and
/// `Z = S(s)^-1 U`. Shareable (`Arc`) by the operators of several friction coefficients.
pub struct SymmetricShift {
    pub(super) s: f64,
    pencil: Arc<SymmetricPencil>,
    l_values: Vec<f64>,
    subdiag: Vec<f64>,
    perm_fwd: Vec<usize>,
    perm_inv: Vec<usize>,
    pub(super) w: SparseMat,
    pub(super) z: Mat<f64>,
    pub(super) par: Par,
    /// Relative residual of the probe solve with `S(s)`.
    s_residual: f64,
    /// Seconds of the numeric factorization and of `Z = S^-1 U`.
    times: (f64, f64),
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
        let start = std::time::Instant::now();
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
            times: (0.0, 0.0),
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
        let t_numeric = start.elapsed().as_secs_f64();
        let start = std::time::Instant::now();
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
        this.times = (t_numeric, start.elapsed().as_secs_f64());
        Ok(this)
    }

    /// Seconds of the numeric factorization of `S(s)` (with its probe solve) and of the
    /// `nA` solves `Z = S^-1 U`.
    pub fn times(&self) -> (f64, f64) {
        self.times
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
        crate::linalg::solve_by_columns(b, &|b: MatMut<'_, f64>| {
            let mut mem = MemBuffer::new(chol.solve_in_place_scratch::<f64>(b.ncols(), Par::Seq));
            lblt.solve_in_place_with_conj(Conj::No, b, Par::Seq, MemStack::new(&mut mem));
        });
    }
}
