//! A basis that grows by columns and keeps the images of its columns under the large
//! parts of the operator ([`GrowingBasis`]), so that an iterative basis (the residue
//! method) multiplies the sparse `K_c`, `M_c` (and `C_c`) by its new columns only:
//! projection, orthonormalization and residuals of the reduced modes then reuse the
//! images of the columns kept before.

use super::orthonormal::m_orthonormal_extend_in_place;
use super::project::{dense_to_sparse, is_symmetric, project_loads, project_part};
use super::statics::{energy_norms, StaticSolver};
use super::{expand, sparse_times, tmul};
use crate::linalg::{spmv_complex, symmetric_times};
use crate::operator::FrictionalOperator;
use crate::{c64, Error, Result, SparseMat};
use faer::{Mat, MatRef};

/// An `M_c`-orthonormal basis `V` of a frictional operator's space with the images
/// `M_c V`, `K_c V` (and `C_c V` when damped), each computed once per column.
pub struct GrowingBasis<'a> {
    op: &'a FrictionalOperator,
    v: Mat<f64>,
    mv: Mat<f64>,
    kv: Mat<f64>,
    cv: Option<Mat<f64>>,
    /// Whether `M_c` and `K_c` are exactly symmetric (their images by the gather product).
    symmetric: [bool; 2],
}

/// Room for `more` columns after the ones of `a`, the column capacity grown in powers of
/// two: a matrix extended many times is reallocated only when it doubles.
fn reserve_doubling(a: &mut Mat<f64>, more: usize) {
    a.reserve(a.nrows(), (a.ncols() + more).next_power_of_two());
}

/// `a <- [a | b]` ([`reserve_doubling`]).
fn append(a: &mut Mat<f64>, b: MatRef<'_, f64>) {
    let (n, m) = (a.nrows(), a.ncols());
    reserve_doubling(a, b.ncols());
    a.resize_with(n, m + b.ncols(), |_, _| 0.0);
    a.as_mut().subcols_mut(m, b.ncols()).copy_from(b);
}

impl<'a> GrowingBasis<'a> {
    /// The basis of the `M_c`-orthonormal columns `v` of `op`'s space.
    pub fn new(op: &'a FrictionalOperator, v: Mat<f64>) -> Result<Self> {
        if v.nrows() != op.dim() {
            return Err(Error::Dimension {
                context: "growing basis: rows of the columns".into(),
                expected: op.dim(),
                got: v.nrows(),
            });
        }
        let symmetric = [is_symmetric(op.mc.as_ref()), is_symmetric(op.kc.as_ref())];
        let mv = times(op.mc.as_ref(), v.as_ref(), symmetric[0]);
        let kv = times(op.kc.as_ref(), v.as_ref(), symmetric[1]);
        let cv = op.cc.as_ref().map(|c| sparse_times(c.as_ref(), v.as_ref()));
        Ok(Self {
            op,
            v,
            mv,
            kv,
            cv,
            symmetric,
        })
    }

    /// Number of columns.
    pub fn len(&self) -> usize {
        self.v.ncols()
    }

    /// Whether the basis has no column.
    pub fn is_empty(&self) -> bool {
        self.v.ncols() == 0
    }

    /// The columns `V`.
    pub fn columns(&self) -> MatRef<'_, f64> {
        self.v.as_ref()
    }

    /// The columns, giving up the images.
    pub fn into_columns(self) -> Mat<f64> {
        self.v
    }

    /// Appends the directions of `new` outside the span of the basis, `M_c`-orthonormalized
    /// with the rank cut `rank_tol` ([`m_orthonormal_extend`](super::m_orthonormal_extend));
    /// returns how many columns of `new` were dropped.
    pub fn extend(&mut self, new: MatRef<'_, f64>, rank_tol: f64) -> Result<usize> {
        let mc = self.op.mc.as_ref();
        let before = self.len();
        reserve_doubling(&mut self.v, new.ncols());
        reserve_doubling(&mut self.mv, new.ncols());
        let dropped = m_orthonormal_extend_in_place(mc, &mut self.v, &mut self.mv, new, rank_tol)?;
        let w = self.v.as_ref().subcols(before, self.len() - before);
        if w.ncols() > 0 {
            // the images of the new columns by exact sparse products (the orthonormalization
            // carried `M w` through its projections, with their roundoff)
            let mw = times(mc, w, self.symmetric[0]);
            self.mv
                .as_mut()
                .subcols_mut(before, w.ncols())
                .copy_from(&mw);
            append(
                &mut self.kv,
                times(self.op.kc.as_ref(), w, self.symmetric[1]).as_ref(),
            );
            if let (Some(cv), Some(c)) = (&mut self.cv, &self.op.cc) {
                append(cv, sparse_times(c.as_ref(), w).as_ref());
            }
        }
        Ok(dropped)
    }

    /// The operator projected on the basis, as [`project`](super::project) computes it:
    /// `V^T X V` from the kept images for `M_c`, `K_c`, `C_c`, the (few-row) friction
    /// parts projected directly.
    pub fn project(&self) -> Result<FrictionalOperator> {
        if self.is_empty() {
            return Err(Error::Invalid("projection on an empty basis".into()));
        }
        let v = self.v.as_ref();
        let dense = |xv: &Mat<f64>| dense_to_sparse(tmul(v, xv.as_ref()).as_ref());
        let part = |x: &Option<SparseMat>| -> Result<Option<SparseMat>> {
            x.as_ref().map(|x| project_part(x.as_ref(), v)).transpose()
        };
        Ok(FrictionalOperator {
            mc: dense(&self.mv)?,
            cc: self.cv.as_ref().map(dense).transpose()?,
            kc: dense(&self.kv)?,
            fm: project_part(self.op.fm.as_ref(), v)?,
            fc: part(&self.op.fc)?,
            fk: project_part(self.op.fk.as_ref(), v)?,
            t: None,
            friction_loads: project_loads(self.op, v)?,
            modal: Default::default(),
        })
    }

    /// Energy-norm residuals of the reduced modes `(lambda_j, u_j = V q_j)` on the full
    /// operator at `mu`, as [`energy_residuals`](super::energy_residuals) defines them,
    /// with `Q(lambda) u` and `K_s u` formed from the kept images (no sparse product by
    /// the large parts). Returns the `eps_j` and `d_j = K_s^-1 Q(lambda_j) u_j`.
    pub fn energy_residuals(
        &self,
        mu: f64,
        ks: &StaticSolver,
        lambda: &[c64],
        q: MatRef<'_, c64>,
    ) -> (Vec<f64>, Mat<c64>) {
        let n = self.v.nrows();
        let k = lambda.len();
        let own = ks.is_own();
        let u = expand(self.v.as_ref(), q);
        let mu_ = expand(self.mv.as_ref(), q);
        let ku = expand(self.kv.as_ref(), q);
        let cu = self.cv.as_ref().map(|cv| expand(cv.as_ref(), q));
        let op = self.op;
        let mut rr = Mat::<f64>::zeros(n, 2 * k);
        let mut ur = Mat::<f64>::zeros(n, 2 * k);
        let mut ksu = Mat::<f64>::zeros(n, 2 * k);
        let zero = c64::new(0.0, 0.0);
        let (mut fm, mut fc, mut fk) = (vec![zero; n], vec![zero; n], vec![zero; n]);
        for (j, &l) in lambda.iter().enumerate() {
            let uj: Vec<c64> = (0..n).map(|r| u[(r, j)]).collect();
            // the friction parts: few nonzero rows, products on the vector
            spmv_complex(op.fm.as_ref(), &uj, &mut fm);
            spmv_complex(op.fk.as_ref(), &uj, &mut fk);
            if let Some(f) = &op.fc {
                spmv_complex(f.as_ref(), &uj, &mut fc);
            }
            for r in 0..n {
                // r = K~ u + l (C~ u + l M~ u),  X~ = X_c - mu F_X
                let m_ = mu_[(r, j)] - mu * fm[r];
                let c_ = cu.as_ref().map_or(zero, |c| c[(r, j)]) - mu * fc[r];
                let k_ = ku[(r, j)] - mu * fk[r];
                let v = k_ + l * (c_ + l * m_);
                rr[(r, 2 * j)] = v.re;
                rr[(r, 2 * j + 1)] = v.im;
                if own {
                    let s = ku[(r, j)] + ks.shift * mu_[(r, j)];
                    ksu[(r, 2 * j)] = s.re;
                    ksu[(r, 2 * j + 1)] = s.im;
                }
                ur[(r, 2 * j)] = uj[r].re;
                ur[(r, 2 * j + 1)] = uj[r].im;
            }
        }
        if !own {
            // a real-mode pair that is not the operator's own stiffness: K_s u directly
            ksu = symmetric_times(ks.matrix(), ur.as_ref());
        }
        energy_norms(ks, rr, ur.as_ref(), ksu.as_ref())
    }
}

/// `X V`, by the gather product when `X` is symmetric.
fn times(x: crate::SparseRef<'_>, v: MatRef<'_, f64>, symmetric: bool) -> Mat<f64> {
    if symmetric {
        symmetric_times(x, v)
    } else {
        sparse_times(x, v)
    }
}
