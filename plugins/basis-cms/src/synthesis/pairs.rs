//! The projection of a contact set's operator assembled on the pairs alone
//! ([`FreeInterface::project_on_pairs`]): no `n x m` basis is formed, no sparse product
//! or solve is made per contact set but forming the columns for the modes returned.
//!
//! Every vector of the `cms` basis is `u = Phi e + Z a + Y b` on the free modes `Phi` and
//! the static responses to the unit pair loads `L = (Pn^T | Pt^T)` of the candidate
//! pairs, deflated M-orthogonally of the modes at every level:
//! `Z = K^-1 L - Phi C_0`, `Y = K^-1 M Z - Phi C_1` (`C = Phi^T M (.)`, computed), with
//! `a`, `b` nonzero on the active pairs only. Because `K Z = L - K Phi C_0`,
//! `K Y = M Z - K Phi C_1` and `Phi^T M (Z, Y, K^-1 M Y) = 0` hold to round-off whatever the
//! accuracy of the modes, every Gram block of `(Z, Y)` in `K` and `M` is a pair-row product
//! of `Z`, `K^-1 M Z`, `K^-1 M Y` or `K^-1 M (K^-1 M Y)_deflated` plus a small modal term
//! (`C^T D`, `D = Phi^T K (Z, Y)`): the model stage computes them once, three block solves
//! more per block of pairs, `288 nR^2` bytes in all (`PairMoments`). (Subtracting the
//! modal parts through `K^-1 M Phi = Phi Omega^-2` instead loses the second-order blocks
//! entirely: with eigen solver accuracy, `Omega^-4` amplifies the error to O(1).)
//!
//! The vectors satisfy the ties, so `V^T X_c V = U^T X U` for the free `X` (`U` the
//! vectors on the unconstrained DOFs), and the friction parts `V^T F_X V =
//! (Pt U)^T (E_s X U)` need the pin-normal rows `E_s X U`: `E_s K Z = E_s L - E_s K Phi
//! C_0`, `E_s K Y = E_s M Z - E_s K Phi C_1`, with `E_s M Z`, `E_s M Y`, `E_s M Phi`,
//! `E_s K Phi` kept. The basis is `M`-orthonormalized through its Gram matrix (the
//! eigenvectors of the scaled Gram matrix above a relative cut [`GRAM_CUT`]); its columns
//! are formed once, on the first expansion, for the modes a solve returns ([`PairColumns`],
//! two block solves).
//!
//! Undamped operators only: the `cms` basis projects a damped one the explicit way. The
//! per-case products on the pairs grow as `(2 nA)^2` per column: this pays for contact
//! sets of a few hundred pairs, not for thousands.

use super::{add_pair_load, par, pn_rows, pt_rows, FreeInterface, PairDofs, Synthesized};
use squeal_core::faer::linalg::matmul::matmul;
use squeal_core::faer::linalg::solvers::Solve;
use squeal_core::faer::{Accum, Mat, MatRef, Par, Side};
use squeal_core::linalg::{symmetric_times, Cholesky};

use squeal_core::reduction::dense_to_sparse;
use squeal_core::{
    c64, Error, FrictionalOperator, ImplicitColumns, RealModes, Result, SparseMat, SparseRef,
};
use std::sync::Arc;

/// Largest memory (bytes) the moments on the pairs may take (`288 nR^2` bytes).
pub const PAIR_MOMENTS_LIMIT_BYTES: usize = 4 << 30;

/// Relative cut on the eigenvalues of the scaled Gram matrix (squared `M`-norms): a
/// direction whose `M`-norm is below `1e-6` of the largest is dropped, since the Gram
/// matrix squares the condition of the columns.
pub const GRAM_CUT: f64 = 1e-12;

/// The moments of the static contact responses on the candidate pairs (module docs).
pub(crate) struct PairMoments {
    /// The residual Gram blocks (`2nR x 2nR`; rows and columns: the pairs' normal loads,
    /// then their sliding loads), in the order `Z^T K Z`, `Z^T K Y`, `Y^T K Y`,
    /// `Z^T M Z`, `Z^T M Y`, `Y^T M Y` (`Z`, `Y` the deflated responses).
    pub(super) gram: [Mat<f64>; 6],
    /// `L^T Z`, `L^T Y` (`2nR x 2nR`): normal gaps and sliding of the responses.
    pub(super) rows: [Mat<f64>; 2],
    /// `E_s M Z`, `E_s M Y` (`nR x 2nR`: the pin-normal rows).
    esm: [Mat<f64>; 2],
    /// The modal coordinates taken out: `C_0 = Phi^T M K^-1 L`, `C_1 = Phi^T M K^-1 M Z`
    /// (`m x 2nR`), and the stiffness coupling left, `D_0 = Phi^T K Z`, `D_1 = Phi^T K Y`.
    c: [Mat<f64>; 2],
    d: [Mat<f64>; 2],
    /// `Phi^T K Phi`, `Phi^T M Phi` (`m x m`, computed: `Omega^2` and `I` to round-off).
    k_phi: Mat<f64>,
    m_phi: Mat<f64>,
    /// `M Phi` (`n x m`), for the deflations.
    mphi: Mat<f64>,
    /// `E_s M Phi`, `E_s K Phi` (`nR x m`).
    esm_phi: Mat<f64>,
    esk_phi: Mat<f64>,
}

/// `L^T x`: the normal gaps of the pairs, then their sliding displacements (`2nR` rows).
fn l_rows(pairs: &[PairDofs], x: MatRef<'_, f64>) -> Mat<f64> {
    let (n, t) = (pn_rows(pairs, x), pt_rows(pairs, x));
    let nr = pairs.len();
    Mat::from_fn(2 * nr, x.ncols(), |i, c| {
        if i < nr {
            n[(i, c)]
        } else {
            t[(i - nr, c)]
        }
    })
}

impl PairMoments {
    /// Empty moments for `pairs`, with the modal products; an error when they would pass
    /// `limit_bytes` ([`PAIR_MOMENTS_LIMIT_BYTES`] in the model stage).
    pub(super) fn zeros(
        k: SparseRef<'_>,
        m: SparseRef<'_>,
        pairs: &[PairDofs],
        modes: &RealModes,
        limit_bytes: usize,
    ) -> Result<Self> {
        let nr = pairs.len();
        let bytes = 288usize.saturating_mul(nr).saturating_mul(nr);
        if bytes > limit_bytes {
            return Err(Error::param(
                "projection",
                format!(
                    "`pairs` needs {:.2} GiB of moments for {nr} candidate pairs (limit \
                     {:.2} GiB): use projection=full",
                    bytes as f64 / (1u64 << 30) as f64,
                    limit_bytes as f64 / (1u64 << 30) as f64
                ),
            ));
        }
        let phi = modes.vectors.as_ref();
        let nm = phi.ncols();
        let mphi = symmetric_times(m, phi);
        let kphi = symmetric_times(k, phi);
        let pin_rows = |x: &Mat<f64>| Mat::from_fn(nr, nm, |i, c| x[(pairs[i].pin[2], c)]);
        let big = || Mat::zeros(2 * nr, 2 * nr);
        let wide = || Mat::zeros(nm, 2 * nr);
        Ok(Self {
            gram: std::array::from_fn(|_| big()),
            rows: std::array::from_fn(|_| big()),
            esm: std::array::from_fn(|_| Mat::zeros(nr, 2 * nr)),
            c: std::array::from_fn(|_| wide()),
            d: std::array::from_fn(|_| wide()),
            k_phi: tmul(phi, kphi.as_ref()),
            m_phi: tmul(phi, mphi.as_ref()),
            esm_phi: pin_rows(&mphi),
            esk_phi: pin_rows(&kphi),
            mphi,
        })
    }

    /// Adds the columns of the pairs `c0 .. c0 + b` from their static responses `z`
    /// (`n x 2b`: `K^-1` of the `b` unit normal loads, then of the `b` sliding loads).
    /// Each level is deflated of its modal part `Phi Phi^T M x` before the next:
    /// `Z = z - Phi C_0`, `Y = K^-1 M Z - Phi C_1`, `X = K^-1 M Y - Phi C_2`; with
    /// `K Z = L - K Phi C_0`, `K Y = M Z - K Phi C_1` and `Phi^T M (Z, Y, X) = 0` the Gram
    /// blocks are pair rows of `Z`, `K^-1 M Z`, `K^-1 M Y`, `K^-1 M X` and small modal terms.
    pub(super) fn add_block(
        &mut self,
        factor: &Cholesky,
        m: SparseRef<'_>,
        pairs: &[PairDofs],
        (phi, pn_phi, pt_phi): (&Mat<f64>, &Mat<f64>, &Mat<f64>),
        c0: usize,
        b: usize,
        z: &Mat<f64>,
    ) {
        let nr = pairs.len();
        let cols: Vec<usize> = (0..2 * b)
            .map(|j| if j < b { c0 + j } else { nr + c0 + j - b })
            .collect();
        let put = |dst: &mut Mat<f64>, src: &Mat<f64>| {
            for (j, &c) in cols.iter().enumerate() {
                dst.as_mut().col_mut(c).copy_from(src.as_ref().col(j));
            }
        };
        // x - Phi (M Phi)^T x, and the coordinates taken out. The dense products of the
        // model stage are small next to its solves and run on one thread (a whole
        // `stability --basis-opt projection=pairs` run on the rig: 78.3 s so, 77.6 s with
        // faer's parallel products).
        let deflate = |x: &mut Mat<f64>| {
            let c = tmul_with(self.mphi.as_ref(), x.as_ref(), Par::Seq);
            matmul(
                x.as_mut(),
                Accum::Add,
                phi.as_ref(),
                c.as_ref(),
                -1.0,
                Par::Seq,
            );
            c
        };
        // E_s M x and K^-1 M x
        let step = |x: &Mat<f64>| {
            let mut mx = symmetric_times(m, x.as_ref());
            let es = Mat::from_fn(nr, 2 * b, |i, j| mx[(pairs[i].pin[2], j)]);
            factor.solve_in_place(mx.as_mut());
            (es, mx)
        };
        let mut zr = z.clone();
        let c_0 = deflate(&mut zr);
        let lz = l_rows(pairs, zr.as_ref());
        let (esm0, mut yr) = step(&zr);
        let ly_raw = l_rows(pairs, yr.as_ref());
        let c_1 = deflate(&mut yr);
        let ly = l_rows(pairs, yr.as_ref());
        let (esm1, mut x3) = step(&yr);
        let lx3 = l_rows(pairs, x3.as_ref());
        deflate(&mut x3);
        let lx4 = l_rows(pairs, step(&x3).1.as_ref());
        // D_0 = Phi^T L - (Phi^T K Phi) C_0 (the columns' own rows of P = L^T Phi),
        // D_1 = Phi^T M Z - (Phi^T K Phi) C_1
        let p_cols = Mat::from_fn(phi.ncols(), 2 * b, |i, j| {
            if j < b {
                pn_phi[(c0 + j, i)]
            } else {
                pt_phi[(c0 + j - b, i)]
            }
        });
        let d_0 = p_cols - mul_with(self.k_phi.as_ref(), c_0.as_ref(), Par::Seq);
        let d_1 = tmul_with(self.mphi.as_ref(), zr.as_ref(), Par::Seq)
            - mul_with(self.k_phi.as_ref(), c_1.as_ref(), Par::Seq);
        put(&mut self.rows[0], &lz);
        put(&mut self.rows[1], &ly);
        put(&mut self.esm[0], &esm0);
        put(&mut self.esm[1], &esm1);
        put(&mut self.c[0], &c_0);
        put(&mut self.c[1], &c_1);
        put(&mut self.d[0], &d_0);
        put(&mut self.d[1], &d_1);
        // the Gram columns of this block; the C^T D terms need all columns and are added
        // in `finish`
        put(&mut self.gram[0], &lz);
        put(&mut self.gram[1], &ly);
        put(&mut self.gram[2], &lx3);
        put(&mut self.gram[3], &ly_raw);
        put(&mut self.gram[4], &lx3);
        put(&mut self.gram[5], &lx4);
    }

    /// Adds the modal terms of the stiffness Gram blocks once every block is in:
    /// `Z^T K Z = L^T Z - C_0^T D_0`, `Z^T K Y = L^T Y - C_0^T D_1`,
    /// `Y^T K Y = L^T K^-1 M Y - C_1^T D_1`.
    pub(super) fn finish(&mut self) {
        for (g, ci, di) in [(0, 0, 0), (1, 0, 1), (2, 1, 1)] {
            matmul(
                self.gram[g].as_mut(),
                Accum::Add,
                self.c[ci].transpose(),
                self.d[di].as_ref(),
                -1.0,
                par(),
            );
        }
        self.mphi = Mat::zeros(0, 0);
    }
}

/// The projection of one contact set's operator on the `cms` basis, assembled on the
/// pairs ([`FreeInterface::project_on_pairs`]).
pub struct PairsProjection {
    /// `V^T X V` of every part (undamped), `V^T U` of the friction load directions.
    pub reduced: FrictionalOperator,
    /// The basis columns by their action.
    pub columns: PairColumns,
    /// Candidate columns removed by the Gram cut.
    pub dropped: usize,
    /// Largest normal gap `|Pn_A u|` of the columns relative to their largest sliding
    /// displacement `|Pt_A u|` (the ties hold to round-off).
    pub tie_residual: f64,
}

/// The columns `V` of a `cms` basis projected on the pairs, kept by their coefficients on
/// `(Phi, Z, Y)` of the active pairs (module docs), relabelled onto the constrained DOFs
/// when formed.
pub struct PairColumns {
    factor: Arc<Cholesky>,
    phi: Arc<Mat<f64>>,
    m: Arc<SparseMat>,
    /// The active pairs, in the order of the rows of `a`, `b`.
    active: Vec<PairDofs>,
    /// The modal coordinates `C_0`, `C_1` of the active pairs' columns (`m x 2nA`).
    c_a: [Mat<f64>; 2],
    /// The index map of the operator, and its constrained size.
    t: Vec<usize>,
    nc: usize,
    e: Mat<f64>,
    a: Mat<f64>,
    b: Mat<f64>,
    /// The columns on the constrained DOFs, formed on the first expansion (the right and
    /// left vectors of a solve then share two block solves).
    formed: std::sync::OnceLock<Mat<f64>>,
}

impl PairColumns {
    /// Unconstrained vectors `Phi e + Z a + Y b` of real coefficients (`q`: `m x c`):
    /// `Z a = K^-1 L_A a - Phi C_0 a`, `Y b = K^-1 M Z b - Phi C_1 b`.
    pub(super) fn unconstrained(&self, q: MatRef<'_, f64>) -> Mat<f64> {
        let n = self.phi.nrows();
        let na = self.active.len();
        let c = q.ncols();
        let (e, a, b) = (
            mul(self.e.as_ref(), q),
            mul(self.a.as_ref(), q),
            mul(self.b.as_ref(), q),
        );
        let loads = |x: &mut Mat<f64>, coef: &Mat<f64>| {
            for (row, p) in self.active.iter().enumerate() {
                for col in 0..c {
                    let (nv, tv) = (coef[(row, col)], coef[(na + row, col)]);
                    if nv != 0.0 || tv != 0.0 {
                        add_pair_load(x, p, col, nv, tv);
                    }
                }
            }
        };
        let phi: &Mat<f64> = &self.phi;
        let mut x = Mat::<f64>::zeros(n, c);
        let mut coef = e - mul(self.c_a[0].as_ref(), a.as_ref());
        if b.norm_max() > 0.0 {
            loads(&mut x, &b);
            self.factor.solve_in_place(x.as_mut());
            let c0b = mul(self.c_a[0].as_ref(), b.as_ref());
            matmul(
                x.as_mut(),
                Accum::Add,
                phi.as_ref(),
                c0b.as_ref(),
                -1.0,
                par(),
            );
            x = symmetric_times(self.m.as_ref().as_ref(), x.as_ref());
            coef -= mul(self.c_a[1].as_ref(), b.as_ref());
        }
        loads(&mut x, &a);
        self.factor.solve_in_place(x.as_mut());
        matmul(
            x.as_mut(),
            Accum::Add,
            phi.as_ref(),
            coef.as_ref(),
            1.0,
            par(),
        );
        x
    }
}

impl std::fmt::Debug for PairColumns {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PairColumns")
            .field("dofs", &self.t.len())
            .field("constrained_dofs", &self.nc)
            .field("active_pairs", &self.active.len())
            .field("columns", &self.e.ncols())
            .finish()
    }
}

impl ImplicitColumns for PairColumns {
    fn nrows(&self) -> usize {
        self.nc
    }

    fn ncols(&self) -> usize {
        self.e.ncols()
    }

    fn apply(&self, q: MatRef<'_, c64>) -> Result<Mat<c64>> {
        if q.nrows() != self.ncols() {
            return Err(Error::Dimension {
                context: "cms pairs projection: reduced vectors".into(),
                expected: self.ncols(),
                got: q.nrows(),
            });
        }
        let v = self.formed.get_or_init(|| {
            let m = self.ncols();
            let u = self.unconstrained(Mat::<f64>::identity(m, m).as_ref());
            let mut v = Mat::<f64>::zeros(self.nc, m);
            for (j, &tj) in self.t.iter().enumerate() {
                for c in 0..m {
                    v[(tj, c)] = u[(j, c)];
                }
            }
            v
        });
        Ok(squeal_core::reduction::expand(v.as_ref(), q))
    }
}

/// `a^T b` (`a`: `r x p`, `b`: `r x q`).
fn tmul(a: MatRef<'_, f64>, b: MatRef<'_, f64>) -> Mat<f64> {
    tmul_with(a, b, par())
}

/// [`tmul`] with the given parallelism.
fn tmul_with(a: MatRef<'_, f64>, b: MatRef<'_, f64>, p: Par) -> Mat<f64> {
    let mut c = Mat::<f64>::zeros(a.ncols(), b.ncols());
    matmul(c.as_mut(), Accum::Replace, a.transpose(), b, 1.0, p);
    c
}

/// `a b`.
fn mul(a: MatRef<'_, f64>, b: MatRef<'_, f64>) -> Mat<f64> {
    mul_with(a, b, par())
}

/// [`mul`] with the given parallelism.
fn mul_with(a: MatRef<'_, f64>, b: MatRef<'_, f64>, p: Par) -> Mat<f64> {
    let mut c = Mat::<f64>::zeros(a.nrows(), b.ncols());
    matmul(c.as_mut(), Accum::Replace, a, b, 1.0, p);
    c
}

/// `x + x^T`.
fn sym(x: &Mat<f64>) -> Mat<f64> {
    Mat::from_fn(x.nrows(), x.ncols(), |i, j| x[(i, j)] + x[(j, i)])
}

/// `(x + x^T) / 2`.
fn half_sym(x: &Mat<f64>) -> Mat<f64> {
    Mat::from_fn(x.nrows(), x.ncols(), |i, j| 0.5 * (x[(i, j)] + x[(j, i)]))
}

impl FreeInterface {
    /// The operator of the contact set of `syn` at its mu, projected on the `cms` basis of
    /// the synthesized modes `which` (and their second-order directions when
    /// `second_order`), assembled on the pairs alone (module docs). `t` and `nc` are the
    /// operator's index map and constrained size. An error when the moments were not built
    /// ([`FreeInterface::with_pair_moments`]).
    pub fn project_on_pairs(
        &self,
        syn: &Synthesized,
        which: &[usize],
        second_order: bool,
        t: &[usize],
        nc: usize,
    ) -> Result<PairsProjection> {
        let mo = self.moments.as_ref().ok_or_else(|| {
            Error::Invalid("cms: the pair moments were not built for this model".into())
        })?;
        if t.len() != self.dofs() {
            return Err(Error::Dimension {
                context: "cms pairs projection: the operator's index map".into(),
                expected: self.dofs(),
                got: t.len(),
            });
        }
        let nr = self.pairs();
        let nm = self.modes();
        let act = &syn.active;
        let na = act.len();
        let mu = syn.mu;
        // rows of the active pairs in the moments: normal loads, then sliding loads
        let idx: Vec<usize> = act
            .iter()
            .copied()
            .chain(act.iter().map(|&i| nr + i))
            .collect();
        let gather = |w: &Mat<f64>| Mat::from_fn(2 * na, 2 * na, |i, j| w[(idx[i], idx[j])]);
        let g: Vec<Mat<f64>> = mo.gram.iter().map(gather).collect();
        let ly = gather(&mo.rows[1]);
        let lz = gather(&mo.rows[0]);
        let modal = |x: &Mat<f64>| Mat::from_fn(nm, 2 * na, |i, j| x[(i, idx[j])]);
        let (c0a, c1a) = (modal(&mo.c[0]), modal(&mo.c[1]));
        let (d0a, d1a) = (modal(&mo.d[0]), modal(&mo.d[1]));
        let pa = Mat::from_fn(2 * na, nm, |i, c| {
            if i < na {
                self.pn_phi[(act[i], c)]
            } else {
                self.pt_phi[(act[i - na], c)]
            }
        });
        // complex coefficients of the candidate columns
        let kk = if second_order { 2 } else { 1 } * which.len();
        let mut ec = Mat::<c64>::zeros(nm, kk);
        let mut ac = Mat::<c64>::zeros(2 * na, kk);
        let mut bc = Mat::<c64>::zeros(2 * na, kk);
        let lu = (na > 0 && second_order)
            .then(|| Mat::from_fn(na, na, |i, j| self.wfull[(act[i], act[j])]).partial_piv_lu());
        // K^-1 L = Z + Phi C_0 and G L = K^-1 L - Phi Omega^-2 P^T: the synthesis's
        // G L = Z + Phi (C_0 - Omega^-2 P^T)
        let delta = Mat::from_fn(nm, 2 * na, |i, j| c0a[(i, j)] - pa[(j, i)] / self.omega2[i]);
        for (c, &w) in which.iter().enumerate() {
            // u = Phi eta + G B^T r
            for row in 0..na {
                let r = syn.r[(row, w)];
                ac[(row, c)] = r;
                ac[(na + row, c)] = r * mu;
            }
            for j in 0..nm {
                let mut v = syn.eta[(j, w)];
                for i in 0..2 * na {
                    v += ac[(i, c)] * delta[(j, i)];
                }
                ec[(j, c)] = v;
            }
            if second_order {
                // Y B^T r made to satisfy the ties: - K^-1 Pn_A^T cf with
                // cf = W_AA^-1 Pn_A Y B^T r, K^-1 Pn^T = Z_n + Phi C_0n (a zero column when
                // no pair is tied: the Gram cut drops it)
                let c2 = which.len() + c;
                for row in 0..na {
                    bc[(row, c2)] = ac[(row, c)];
                    bc[(na + row, c2)] = ac[(na + row, c)];
                }
            }
        }
        if let Some(lu) = &lu {
            // all the normal gaps Pn_A Y b at once (real and imaginary parts side by side)
            let k = which.len();
            let bs = Mat::from_fn(2 * na, 2 * k, |i, j| {
                let v = bc[(i, k + j % k)];
                if j < k {
                    v.re
                } else {
                    v.im
                }
            });
            let gaps = mul(ly.as_ref().subrows(0, na), bs.as_ref());
            let cf = lu.solve(&gaps);
            for c in 0..k {
                for row in 0..na {
                    let v = c64::new(cf[(row, c)], cf[(row, k + c)]);
                    ac[(row, k + c)] = -v;
                    for j in 0..nm {
                        ec[(j, k + c)] -= v * c0a[(j, row)];
                    }
                }
            }
        }
        // real and imaginary parts as columns
        let split = |x: &Mat<c64>| {
            Mat::from_fn(x.nrows(), 2 * kk, |i, j| {
                if j < kk {
                    x[(i, j)].re
                } else {
                    x[(i, j - kk)].im
                }
            })
        };
        let (e, a, b) = (split(&ec), split(&ac), split(&bc));
        // Gram matrices of K and M (blocks Phi, Z, Y)
        let ga = |x: &Mat<f64>, y: &Mat<f64>, z: &Mat<f64>| {
            tmul(x.as_ref(), mul(y.as_ref(), z.as_ref()).as_ref())
        };
        let mut gk = ga(&e, &mo.k_phi, &e);
        gk += sym(&ga(&e, &d0a, &a));
        gk += sym(&ga(&e, &d1a, &b));
        gk += ga(&a, &g[0], &a);
        gk += sym(&ga(&a, &g[1], &b));
        gk += ga(&b, &g[2], &b);
        let mut gm = ga(&e, &mo.m_phi, &e);
        gm += ga(&a, &g[3], &a);
        gm += sym(&ga(&a, &g[4], &b));
        gm += ga(&b, &g[5], &b);
        let (gk, gm) = (half_sym(&gk), half_sym(&gm));
        // tangential and normal relative displacements, pin-normal rows of K U and M U
        let rows = |x: &Mat<f64>, from: usize| Mat::from_fn(na, x.ncols(), |i, j| x[(from + i, j)]);
        let phi_rows = |src: &Mat<f64>| Mat::from_fn(na, nm, |i, c| src[(act[i], c)]);
        let lu_ = mul(lz.as_ref(), a.as_ref()) + mul(ly.as_ref(), b.as_ref());
        let pt_u = mul(phi_rows(&self.pt_phi).as_ref(), e.as_ref()) + rows(&lu_, na);
        let pn_u = mul(phi_rows(&self.pn_phi).as_ref(), e.as_ref()) + rows(&lu_, 0);
        let esm_act = |x: &Mat<f64>| Mat::from_fn(na, 2 * na, |i, j| x[(act[i], idx[j])]);
        let (esm0, esm1) = (esm_act(&mo.esm[0]), esm_act(&mo.esm[1]));
        let (esm_phi, esk_phi) = (phi_rows(&mo.esm_phi), phi_rows(&mo.esk_phi));
        let esm_u = mul(esm_phi.as_ref(), e.as_ref())
            + mul(esm0.as_ref(), a.as_ref())
            + mul(esm1.as_ref(), b.as_ref());
        // E_s K Z a = a_n - E_s K Phi C_0 a, E_s K Y b = E_s M Z b - E_s K Phi C_1 b
        let modal_k = e.clone() - mul(c0a.as_ref(), a.as_ref()) - mul(c1a.as_ref(), b.as_ref());
        let esk_u =
            mul(esk_phi.as_ref(), modal_k.as_ref()) + rows(&a, 0) + mul(esm0.as_ref(), b.as_ref());
        let scale = pt_u.norm_max().max(1e-300);
        let tie_residual = pn_u.norm_max() / scale;
        // M-orthonormalization through the scaled Gram matrix
        let ncand = 2 * kk;
        let d: Vec<f64> = (0..ncand).map(|j| gm[(j, j)].max(0.0).sqrt()).collect();
        let dmax = d.iter().fold(0.0f64, |x, &y| x.max(y));
        let keep: Vec<usize> = (0..ncand)
            .filter(|&j| {
                // an imaginary part that is nothing against its real part is not a column
                let partner = if j < kk { j + kk } else { j - kk };
                d[j] > 1e-8 * d[partner].max(1e-300) && d[j] > 1e-14 * dmax
            })
            .collect();
        let gn = Mat::from_fn(keep.len(), keep.len(), |i, j| {
            gm[(keep[i], keep[j])] / (d[keep[i]] * d[keep[j]])
        });
        let eig = gn
            .self_adjoint_eigen(Side::Lower)
            .map_err(|err| Error::NotConverged {
                method: "cms pairs projection (Gram matrix)".into(),
                iterations: 0,
                detail: format!("{err:?}"),
            })?;
        let lmax = (0..keep.len()).map(|i| eig.S()[i]).fold(0.0f64, f64::max);
        let kept: Vec<usize> = (0..keep.len())
            .filter(|&i| eig.S()[i] > GRAM_CUT * lmax)
            .collect();
        if kept.is_empty() {
            return Err(Error::Invalid("cms: no synthesized column left".into()));
        }
        let cmat = Mat::from_fn(ncand, kept.len(), |i, j| {
            match keep.iter().position(|&k| k == i) {
                Some(p) => eig.U()[(p, kept[j])] / (d[i] * eig.S()[kept[j]].sqrt()),
                None => 0.0,
            }
        });
        let dropped = ncand - kept.len();
        let congruent = |g: &Mat<f64>| tmul(cmat.as_ref(), mul(g.as_ref(), cmat.as_ref()).as_ref());
        let (ptc, esmc, eskc) = (
            mul(pt_u.as_ref(), cmat.as_ref()),
            mul(esm_u.as_ref(), cmat.as_ref()),
            mul(esk_u.as_ref(), cmat.as_ref()),
        );
        let sparse = |x: Mat<f64>| dense_to_sparse(x.as_ref());
        let reduced = FrictionalOperator {
            mc: sparse(congruent(&gm))?,
            cc: None,
            kc: sparse(congruent(&gk))?,
            fm: sparse(tmul(ptc.as_ref(), esmc.as_ref()))?,
            fc: None,
            fk: sparse(tmul(ptc.as_ref(), eskc.as_ref()))?,
            t: None,
            friction_loads: Some(sparse(ptc.transpose().to_owned())?),
            modal: Default::default(),
        };
        let columns = PairColumns {
            factor: self.factor.clone(),
            phi: self.phi.clone(),
            m: self.m.clone(),
            active: act.iter().map(|&i| self.pairs[i]).collect(),
            c_a: [c0a, c1a],
            t: t.to_vec(),
            nc,
            e: mul(e.as_ref(), cmat.as_ref()),
            a: mul(a.as_ref(), cmat.as_ref()),
            b: mul(b.as_ref(), cmat.as_ref()),
            formed: std::sync::OnceLock::new(),
        };
        Ok(PairsProjection {
            reduced,
            columns,
            dropped,
            tie_residual,
        })
    }
}
