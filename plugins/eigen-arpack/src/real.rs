//! `dnaupd`/`dneupd` in standard mode 1 driven by reverse communication on a real
//! operator whose eigenvalues may be complex: the kernel of
//! [`ArpackComplexKernel::largest_real`](squeal_core::qep::ComplexKernel::largest_real).

use crate::complex::start_vector;
use crate::error::{ArpackError, Routine};
use crate::kernel::{request_io, to_int};
use arpack_ffi::{a_int, dnaupd_c, dneupd_c, ARPACK_LOCK};
use squeal_core::c64;
use squeal_core::faer::Mat;
use squeal_core::qep::ComplexKernelOutput;
use squeal_core::spectral::LinOp;

const BMAT: &std::ffi::CStr = c"I";
const WHICH: &std::ffi::CStr = c"LM";

/// Arnoldi basis size of the real driver for `nev` wanted values of an operator of
/// dimension `n`: `min(n, max(2 nev + 1, 20))`, as the complex driver's.
fn ncv(n: usize, nev: usize) -> usize {
    n.min((2 * nev + 1).max(20))
}

/// The `nev` eigenvalues of largest modulus of a real operator, by ARPACK's real
/// non-symmetric driver; complex values come in conjugate pairs and both members are
/// returned, each with its complex vector. Holds [`ARPACK_LOCK`] for the whole run.
pub(crate) fn run(
    op: &dyn LinOp<f64>,
    nev: usize,
    tol: f64,
    max_restarts: usize,
) -> Result<ComplexKernelOutput, ArpackError> {
    let mut session = Session::new(op.dim(), nev, tol, max_restarts)?;
    let _guard = ARPACK_LOCK.lock().unwrap_or_else(|e| e.into_inner());
    session.iterate(op)?;
    session.extract()
}

/// The sizes, settings and work arrays of one `dnaupd`/`dneupd` run.
struct Session {
    n: usize,
    nev: usize,
    ncv: usize,
    n_c: a_int,
    nev_c: a_int,
    ncv_c: a_int,
    lworkl_c: a_int,
    tol: f64,
    resid: Vec<f64>,
    v: Vec<f64>,
    iparam: [a_int; 11],
    ipntr: [a_int; 14],
    workd: Vec<f64>,
    workl: Vec<f64>,
}

impl Session {
    /// Checks the sizes against ARPACK's integers and allocates the work arrays.
    fn new(n: usize, nev: usize, tol: f64, max_restarts: usize) -> Result<Self, ArpackError> {
        let ncv = ncv(n, nev);
        // dnaupd needs nev + 2 <= ncv <= n (a conjugate pair may take one more place)
        if nev == 0 || nev + 2 > ncv {
            return Err(ArpackError::TooSmall {
                routine: Routine::Dnaupd,
                nev,
                n,
            });
        }
        let lworkl = 3 * ncv * ncv + 6 * ncv;
        let n_c = to_int("n", n)?;
        let nev_c = to_int("nev", nev)?;
        let ncv_c = to_int("ncv", ncv)?;
        let lworkl_c = to_int("lworkl = 3 ncv^2 + 6 ncv", lworkl)?;
        to_int("n ncv", n.saturating_mul(ncv))?;
        to_int("3 n", n.saturating_mul(3))?;
        let mut iparam = [0 as a_int; 11];
        iparam[0] = 1; // exact shifts
        iparam[2] = a_int::try_from(max_restarts).unwrap_or(a_int::MAX);
        iparam[3] = 1; // block size (must be 1)
        iparam[6] = 1; // standard problem, OP = A
        Ok(Self {
            n,
            nev,
            ncv,
            n_c,
            nev_c,
            ncv_c,
            lworkl_c,
            tol,
            // the real parts of the complex driver's start vector
            resid: start_vector(n).iter().map(|z| z.re).collect(),
            v: vec![0.0; n * ncv],
            iparam,
            ipntr: [0 as a_int; 14],
            workd: vec![0.0; 3 * n],
            workl: vec![0.0; lworkl],
        })
    }

    /// The `dnaupd` reverse-communication loop. The caller holds `ARPACK_LOCK`.
    fn iterate(&mut self, op: &dyn LinOp<f64>) -> Result<(), ArpackError> {
        let n = self.n;
        let mut ido: a_int = 0;
        let mut info: a_int = 1; // use `resid` as the start vector
        loop {
            // SAFETY: `resid` has n entries, `v` n * ncv (ldv = n), `iparam` 11, `ipntr`
            // 14, `workd` 3 n, `workl` lworkl = 3 ncv^2 + 6 ncv; the strings hold 1 and
            // 2 characters; ARPACK is serialized by ARPACK_LOCK (held by the caller).
            unsafe {
                dnaupd_c(
                    &mut ido,
                    BMAT.as_ptr(),
                    self.n_c,
                    WHICH.as_ptr(),
                    self.nev_c,
                    self.tol,
                    self.resid.as_mut_ptr(),
                    self.ncv_c,
                    self.v.as_mut_ptr(),
                    self.n_c,
                    self.iparam.as_mut_ptr(),
                    self.ipntr.as_mut_ptr(),
                    self.workd.as_mut_ptr(),
                    self.workl.as_mut_ptr(),
                    self.lworkl_c,
                    &mut info,
                );
            }
            match ido {
                -1 | 1 => {
                    let (x, y) =
                        request_io(Routine::Dnaupd, &mut self.workd, &self.ipntr, 0, 1, ido, n)?;
                    op.apply(x, y);
                }
                99 => break,
                other => {
                    if info < 0 {
                        break;
                    }
                    return Err(ArpackError::UnexpectedRequest {
                        routine: Routine::Dnaupd,
                        ido: other,
                    });
                }
            }
        }
        match info {
            0 | 1 => Ok(()),
            code => Err(ArpackError::from_info(
                Routine::Dnaupd,
                code,
                self.nev,
                self.ncv,
                self.iparam[4],
            )),
        }
    }

    /// `dneupd` after [`Session::iterate`]: the converged values and their complex
    /// vectors (a conjugate pair's vectors are `z_j +- i z_(j+1)`). The caller holds
    /// `ARPACK_LOCK`.
    fn extract(mut self) -> Result<ComplexKernelOutput, ArpackError> {
        let (n, nev) = (self.n, self.nev);
        let iterations = usize::try_from(self.iparam[2]).unwrap_or(0);
        // dnaupd may count nev + 1 values when the last wanted one is half of a pair
        let nconv = usize::try_from(self.iparam[4]).unwrap_or(0).min(nev + 1);
        if nconv == 0 {
            return Ok(ComplexKernelOutput {
                theta: Vec::new(),
                vectors: Mat::zeros(n, 0),
                iterations,
                all_converged: false,
            });
        }
        let select = vec![0 as a_int; self.ncv];
        let mut dr = vec![0.0; nev + 1];
        let mut di = vec![0.0; nev + 1];
        let mut z = vec![0.0; n * (nev + 1)];
        let mut workev = vec![0.0; 3 * self.ncv];
        let mut info_e: a_int = 0;
        // SAFETY: as in `iterate`, plus `select` (ncv), `dr`, `di` (nev + 1 each), `z`
        // (n (nev + 1), ldz = n) and `workev` (3 ncv); the shift is unused in mode 1; the
        // dnaupd state is passed back unchanged.
        unsafe {
            dneupd_c(
                1,
                c"A".as_ptr(),
                select.as_ptr(),
                dr.as_mut_ptr(),
                di.as_mut_ptr(),
                z.as_mut_ptr(),
                self.n_c,
                0.0,
                0.0,
                workev.as_mut_ptr(),
                BMAT.as_ptr(),
                self.n_c,
                WHICH.as_ptr(),
                self.nev_c,
                self.tol,
                self.resid.as_mut_ptr(),
                self.ncv_c,
                self.v.as_mut_ptr(),
                self.n_c,
                self.iparam.as_mut_ptr(),
                self.ipntr.as_mut_ptr(),
                self.workd.as_mut_ptr(),
                self.workl.as_mut_ptr(),
                self.lworkl_c,
                &mut info_e,
            );
        }
        if info_e != 0 {
            return Err(ArpackError::from_info(
                Routine::Dneupd,
                info_e,
                nev,
                self.ncv,
                self.iparam[4],
            ));
        }
        let nconv = usize::try_from(self.iparam[4]).unwrap_or(0).min(nev + 1);
        let col = |j: usize| &z[j * n..(j + 1) * n];
        let genuine = |j: usize| {
            dr[j].is_finite()
                && di[j].is_finite()
                && col(j).iter().all(|x| x.is_finite())
                && col(j).iter().any(|&x| x != 0.0)
        };
        let mut theta = Vec::with_capacity(nconv + 1);
        let mut vecs: Vec<Vec<c64>> = Vec::with_capacity(nconv + 1);
        let mut j = 0;
        while j < nconv {
            if di[j] == 0.0 {
                if genuine(j) {
                    theta.push(c64::new(dr[j], 0.0));
                    vecs.push(col(j).iter().map(|&x| c64::new(x, 0.0)).collect());
                }
                j += 1;
                continue;
            }
            // a conjugate pair: columns j (real part) and j + 1 (imaginary part) hold the
            // vector of dr[j] + i di[j]; the conjugate value has the conjugate vector
            if j + 1 > nev || !genuine(j) {
                j += 2;
                continue;
            }
            let (re, im) = (col(j), col(j + 1));
            let t = c64::new(dr[j], di[j]);
            theta.push(t);
            vecs.push(re.iter().zip(im).map(|(&a, &b)| c64::new(a, b)).collect());
            theta.push(t.conj());
            vecs.push(re.iter().zip(im).map(|(&a, &b)| c64::new(a, -b)).collect());
            j += 2;
        }
        let vectors = Mat::from_fn(n, vecs.len(), |i, c| vecs[c][i]);
        Ok(ComplexKernelOutput {
            all_converged: theta.len() >= nev,
            theta,
            vectors,
            iterations,
        })
    }
}
