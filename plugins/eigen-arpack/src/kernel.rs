//! [`ArpackKernel`]: `dsaupd`/`dseupd` in mode 3 driven by reverse communication.

use crate::error::{ArpackError, Routine};
use arpack_ffi::{a_int, dsaupd_c, dseupd_c, ARPACK_LOCK};
use squeal_core::eigen::{KernelOutput, SymmetricKernel};
use squeal_core::faer::Mat;
use squeal_core::spectral::{LinOp, ShiftInvert, SpectralTransform};
use squeal_core::Result;

/// ARPACK's symmetric driver in shift-invert mode 3 (`bmat = 'G'`, `which = "LM"`) on
/// the operator `OP = (K - sigma M)^-1 M` of a [`ShiftInvert`].
///
/// Lanczos basis size `ncv = min(n, max(2 nev + 1, nev + 20))`; exact shifts
/// (`iparam[0] = 1`); a fixed start vector `1 + 0.1 sin(i)` (`info = 1` on entry), so
/// that runs are reproducible. The iteration cap (`info = 1`) is not an error: the
/// pairs that converged are returned with `all_converged = false`. `iterations` is
/// ARPACK's `iparam[2]` on return, which counts the initial factorization too (it can
/// exceed `max_restarts` by one).
#[derive(Debug, Clone, Copy, Default)]
pub struct ArpackKernel;

/// `a_int` from `usize`, or [`ArpackError::TooLarge`].
pub(crate) fn to_int(what: &'static str, value: usize) -> Result<a_int, ArpackError> {
    a_int::try_from(value).map_err(|_| ArpackError::TooLarge { what, value })
}

/// The input `x = workd[ipntr[src]-1..][..n]` and output `y = workd[ipntr[dst]-1..][..n]`
/// of a reverse-communication request of `routine` (ARPACK's pointers are 1-based
/// Fortran indices, counted in elements of `T`: `f64` or complex).
pub(crate) fn request_io<'w, T>(
    routine: Routine,
    workd: &'w mut [T],
    ipntr: &[a_int],
    src: usize,
    dst: usize,
    ido: a_int,
    n: usize,
) -> Result<(&'w [T], &'w mut [T]), ArpackError> {
    let bad = || ArpackError::BadPointers {
        routine,
        ido,
        ipntr: [ipntr[0], ipntr[1], ipntr[2]],
        n,
    };
    let offset = |p: a_int| -> Result<usize, ArpackError> {
        let p = usize::try_from(p).map_err(|_| bad())?;
        match p.checked_sub(1) {
            Some(o) if o + n <= workd.len() => Ok(o),
            _ => Err(bad()),
        }
    };
    let (s, d) = (offset(ipntr[src])?, offset(ipntr[dst])?);
    if s + n <= d {
        let (a, b) = workd.split_at_mut(d);
        Ok((&a[s..s + n], &mut b[..n]))
    } else if d + n <= s {
        let (a, b) = workd.split_at_mut(s);
        Ok((&b[..n], &mut a[d..d + n]))
    } else {
        Err(bad())
    }
}

impl SymmetricKernel for ArpackKernel {
    fn largest(
        &self,
        op: &ShiftInvert<'_>,
        nev: usize,
        tol: f64,
        max_restarts: usize,
    ) -> Result<KernelOutput> {
        Ok(run(op, nev, tol, max_restarts)?)
    }
}

fn run(
    op: &ShiftInvert<'_>,
    nev: usize,
    tol: f64,
    max_restarts: usize,
) -> Result<KernelOutput, ArpackError> {
    let mut session = Session::new(op.dim(), nev, tol, max_restarts)?;
    // ARPACK keeps its state in Fortran SAVE variables: one run at a time per process.
    let _guard = ARPACK_LOCK.lock().unwrap_or_else(|e| e.into_inner());
    session.iterate(op)?;
    session.extract(op.shift())
}

/// The sizes, settings and work arrays of one `dsaupd`/`dseupd` run.
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
    ipntr: [a_int; 11],
    workd: Vec<f64>,
    workl: Vec<f64>,
}

const BMAT: &std::ffi::CStr = c"G";
const WHICH: &std::ffi::CStr = c"LM";

impl Session {
    /// Checks the sizes against ARPACK's integers and allocates the work arrays.
    fn new(n: usize, nev: usize, tol: f64, max_restarts: usize) -> Result<Self, ArpackError> {
        if nev == 0 || nev >= n {
            return Err(ArpackError::BadRequest { nev, n });
        }
        let ncv = n.min((2 * nev + 1).max(nev + 20));
        let lworkl = ncv * (ncv + 8);
        let n_c = to_int("n", n)?;
        let nev_c = to_int("nev", nev)?;
        let ncv_c = to_int("ncv", ncv)?;
        let lworkl_c = to_int("lworkl = ncv (ncv + 8)", lworkl)?;
        // Buffers whose Fortran length is a product of sizes must not overflow either.
        to_int("n ncv", n.saturating_mul(ncv))?;
        to_int("3 n", n.saturating_mul(3))?;
        let mut iparam = [0 as a_int; 11];
        iparam[0] = 1; // exact shifts
        iparam[2] = a_int::try_from(max_restarts).unwrap_or(a_int::MAX);
        iparam[3] = 1; // block size (must be 1)
        iparam[6] = 3; // shift-invert, generalized
        Ok(Self {
            n,
            nev,
            ncv,
            n_c,
            nev_c,
            ncv_c,
            lworkl_c,
            tol,
            resid: (0..n).map(|i| 1.0 + 0.1 * (i as f64).sin()).collect(),
            v: vec![0.0; n * ncv],
            iparam,
            ipntr: [0 as a_int; 11],
            workd: vec![0.0; 3 * n],
            workl: vec![0.0; lworkl],
        })
    }

    /// The `dsaupd` reverse-communication loop on `op`, to convergence or the iteration
    /// cap (`info = 1`, not an error). The caller holds `ARPACK_LOCK`.
    fn iterate(&mut self, op: &ShiftInvert<'_>) -> Result<(), ArpackError> {
        let n = self.n;
        let mut ido: a_int = 0;
        let mut info: a_int = 1; // use `resid` as the start vector
        loop {
            // SAFETY: `resid` has n entries, `v` n * ncv (ldv = n), `iparam` and `ipntr`
            // 11, `workd` 3 n, `workl` lworkl = ncv (ncv + 8); the strings hold 1 and 2
            // characters; ARPACK is serialized by ARPACK_LOCK (held by the caller).
            unsafe {
                dsaupd_c(
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
            let (workd, ipntr) = (&mut self.workd, &self.ipntr);
            match ido {
                // y = OP x = (K - sigma M)^-1 M x, B x not available (initialization).
                -1 => {
                    let (x, y) = request_io(Routine::Dsaupd, workd, ipntr, 0, 1, ido, n)?;
                    op.apply(x, y);
                }
                // y = OP x with B x = M x already at workd[ipntr[2]-1..].
                1 => {
                    let (mx, y) = request_io(Routine::Dsaupd, workd, ipntr, 2, 1, ido, n)?;
                    op.apply_with_mx(mx, y);
                }
                // y = B x = M x.
                2 => {
                    let (x, y) = request_io(Routine::Dsaupd, workd, ipntr, 0, 1, ido, n)?;
                    op.m_mul(x, y);
                }
                99 => break,
                other => {
                    // An error exit also ends with ido = 99; anything else is a protocol
                    // violation unless info already says what went wrong.
                    if info < 0 {
                        break;
                    }
                    return Err(ArpackError::UnexpectedRequest {
                        routine: Routine::Dsaupd,
                        ido: other,
                    });
                }
            }
        }
        match info {
            0 | 1 => Ok(()),
            code => Err(ArpackError::from_info(
                Routine::Dsaupd,
                code,
                self.nev,
                self.ncv,
                self.iparam[4],
            )),
        }
    }

    /// `dseupd` after [`Session::iterate`]: the converged `theta = 1 / (lambda - sigma)`
    /// and their vectors. The caller holds `ARPACK_LOCK`.
    fn extract(mut self, sigma: f64) -> Result<KernelOutput, ArpackError> {
        let (n, nev) = (self.n, self.nev);
        let iterations = usize::try_from(self.iparam[2]).unwrap_or(0);
        let nconv = usize::try_from(self.iparam[4]).unwrap_or(0).min(nev);
        if nconv == 0 {
            // Only possible with info = 1: nothing to extract (dseupd would say -14).
            return Ok(KernelOutput {
                theta: Vec::new(),
                vectors: Mat::zeros(n, 0),
                iterations,
                all_converged: false,
            });
        }
        let select = vec![0 as a_int; self.ncv];
        let mut d = vec![0.0; nev];
        let mut z = vec![0.0; n * nev];
        let mut info_e: a_int = 0;
        // SAFETY: as in `iterate`, plus `select` (ncv entries, workspace for howmny = 'A'),
        // `d` (nev) and `z` (n * nev, ldz = n); the dsaupd state is passed back unchanged.
        unsafe {
            dseupd_c(
                1,
                c"A".as_ptr(),
                select.as_ptr(),
                d.as_mut_ptr(),
                z.as_mut_ptr(),
                self.n_c,
                sigma,
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
                Routine::Dseupd,
                info_e,
                nev,
                self.ncv,
                self.iparam[4],
            ));
        }
        // dseupd back-transformed to lambda = sigma + 1 / theta; the kernel contract is
        // theta.
        let theta: Vec<f64> = d[..nconv].iter().map(|&l| 1.0 / (l - sigma)).collect();
        let vectors = Mat::from_fn(n, nconv, |i, j| z[j * n + i]);
        Ok(KernelOutput {
            theta,
            vectors,
            iterations,
            all_converged: nconv == nev,
        })
    }
}
