//! [`ArpackComplexKernel`]: `znaupd`/`zneupd` in standard mode 1 driven by reverse
//! communication on a user operator.

use crate::error::{ArpackError, Routine};
use crate::kernel::{request_io, to_int};
use arpack_ffi::{a_int, znaupd_c, zneupd_c, Complex64, ARPACK_LOCK};
use squeal_core::c64;
use squeal_core::faer::Mat;
use squeal_core::qep::{ComplexKernel, ComplexKernelOutput};
use squeal_core::spectral::LinOp;
use squeal_core::spectral::RealOp;
use squeal_core::Result;

// `c64` (`num_complex::Complex<f64>`) and ARPACK's `double _Complex` must share their
// layout: the buffers below are `c64` and handed to ARPACK as `Complex64` pointers.
const _: () = {
    assert!(std::mem::size_of::<c64>() == std::mem::size_of::<Complex64>());
    assert!(std::mem::align_of::<c64>() == std::mem::align_of::<Complex64>());
    assert!(std::mem::size_of::<c64>() == 2 * std::mem::size_of::<f64>());
};

/// ARPACK's complex driver (`znaupd`/`zneupd`) in standard mode 1 (`bmat = 'I'`,
/// `iparam[6] = 1`, `which = "LM"`): the `nev` eigenvalues of largest modulus of a
/// general complex operator given only by its action `y = OP x` (a
/// [`LinOp<c64>`](squeal_core::spectral::LinOp), e.g. the companion shift-invert operator
/// [`QepShiftInvert`](squeal_core::spectral::QepShiftInvert), whose `B` is not positive
/// definite, so ARPACK's generalized modes do not apply).
///
/// - Arnoldi basis size `ncv = min(n, max(2 nev + 1, 20))`; ARPACK needs
///   `nev + 2 <= ncv <= n` (`zneupd` rejects `ncv = nev + 1`), so an operator with
///   `n < nev + 2` (or `nev = 0`) is an [`ArpackError::TooSmall`] error: such small
///   problems belong to a dense solver.
/// - Exact shifts (`iparam[0] = 1`), `tol` passed through (`tol <= 0` means machine
///   precision to ARPACK), at most `max_restarts` Arnoldi updates (`iparam[2]`).
/// - A fixed pseudo-random complex start vector (`info = 1` on entry): runs are
///   reproducible bit for bit.
/// - Ritz vectors of all converged values (`rvec = 1`, `howmny = 'A'`), unit 2-norm.
/// - The iteration cap (`info = 1`) is not an error: the `iparam[4]` pairs that did
///   converge are returned with `all_converged = false` (none at all skips `zneupd`).
///   `iterations` is ARPACK's `iparam[2]` on return.
///
/// The whole run (the `znaupd_c` loop and the `zneupd_c` call) holds
/// [`arpack_ffi::ARPACK_LOCK`]: ARPACK keeps its state in Fortran `SAVE` variables.
#[derive(Debug, Clone, Copy, Default)]
pub struct ArpackComplexKernel;

impl ArpackComplexKernel {
    /// Arnoldi basis size used for `nev` wanted pairs of an operator of dimension `n`:
    /// `min(n, max(2 nev + 1, 20))`.
    pub fn ncv(n: usize, nev: usize) -> usize {
        n.min((2 * nev + 1).max(20))
    }
}

impl ComplexKernel for ArpackComplexKernel {
    fn largest(
        &self,
        op: &dyn LinOp<c64>,
        nev: usize,
        tol: f64,
        max_restarts: usize,
    ) -> Result<ComplexKernelOutput> {
        Ok(run(op, nev, tol, max_restarts)?)
    }

    /// ARPACK's real non-symmetric driver (`dnaupd`/`dneupd`, mode 1) on the real view:
    /// one real column per application (see [`ComplexKernel::largest_real`]).
    fn largest_real(
        &self,
        op: &dyn RealOp,
        nev: usize,
        tol: f64,
        max_restarts: usize,
    ) -> Result<ComplexKernelOutput> {
        Ok(crate::real::run(op.real(), nev, tol, max_restarts)?)
    }
}

/// The fixed start vector: entries with real and imaginary parts uniform in `[-1, 1)`
/// from a SplitMix64 stream with a constant seed (deterministic, and with no structure
/// that could make it deficient in some eigendirection).
pub(crate) fn start_vector(n: usize) -> Vec<c64> {
    let mut state: u64 = 0x5eed_a59a_c0de_2024;
    let mut next = || {
        state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^= z >> 31;
        // 53 random bits -> [0, 1) -> [-1, 1)
        2.0 * ((z >> 11) as f64 / (1u64 << 53) as f64) - 1.0
    };
    (0..n)
        .map(|_| {
            let re = next();
            c64::new(re, next())
        })
        .collect()
}

fn as_arpack(p: *mut c64) -> *mut Complex64 {
    p.cast::<Complex64>()
}

fn run(
    op: &dyn LinOp<c64>,
    nev: usize,
    tol: f64,
    max_restarts: usize,
) -> Result<ComplexKernelOutput, ArpackError> {
    let mut session = Session::new(op.dim(), nev, tol, max_restarts)?;
    // ARPACK keeps its state in Fortran SAVE variables: one run at a time per process.
    let _guard = ARPACK_LOCK.lock().unwrap_or_else(|e| e.into_inner());
    session.iterate(op)?;
    session.extract()
}

const ZERO: c64 = c64 { re: 0.0, im: 0.0 };
const BMAT: &std::ffi::CStr = c"I";
const WHICH: &std::ffi::CStr = c"LM";

/// The sizes, settings and work arrays of one `znaupd`/`zneupd` run.
struct Session {
    n: usize,
    nev: usize,
    ncv: usize,
    n_c: a_int,
    nev_c: a_int,
    ncv_c: a_int,
    lworkl_c: a_int,
    tol: f64,
    resid: Vec<c64>,
    v: Vec<c64>,
    iparam: [a_int; 11],
    ipntr: [a_int; 14],
    workd: Vec<c64>,
    workl: Vec<c64>,
    rwork: Vec<f64>,
}

impl Session {
    /// Checks the sizes against ARPACK's integers and allocates the work arrays.
    fn new(n: usize, nev: usize, tol: f64, max_restarts: usize) -> Result<Self, ArpackError> {
        let ncv = ArpackComplexKernel::ncv(n, nev);
        if nev == 0 || nev + 2 > ncv {
            return Err(ArpackError::TooSmall {
                routine: Routine::Znaupd,
                nev,
                n,
            });
        }
        let lworkl = 3 * ncv * ncv + 5 * ncv;
        let n_c = to_int("n", n)?;
        let nev_c = to_int("nev", nev)?;
        let ncv_c = to_int("ncv", ncv)?;
        let lworkl_c = to_int("lworkl = 3 ncv^2 + 5 ncv", lworkl)?;
        // Buffers whose Fortran length is a product of sizes must not overflow either.
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
            resid: start_vector(n),
            v: vec![ZERO; n * ncv],
            iparam,
            ipntr: [0 as a_int; 14],
            workd: vec![ZERO; 3 * n],
            workl: vec![ZERO; lworkl],
            rwork: vec![0.0f64; ncv],
        })
    }

    /// The `znaupd` reverse-communication loop on `op`, to convergence or the iteration
    /// cap (`info = 1`, not an error). The caller holds `ARPACK_LOCK`.
    fn iterate(&mut self, op: &dyn LinOp<c64>) -> Result<(), ArpackError> {
        let n = self.n;
        let mut ido: a_int = 0;
        let mut info: a_int = 1; // use `resid` as the start vector
        loop {
            // SAFETY: `resid` has n entries, `v` n * ncv (ldv = n), `iparam` 11, `ipntr`
            // 14, `workd` 3 n, `workl` lworkl = 3 ncv^2 + 5 ncv (all `c64`,
            // layout-identical to `Complex64`, checked at compile time), `rwork` ncv
            // reals; the strings hold 1 and 2 characters; ARPACK is serialized by
            // ARPACK_LOCK (held by the caller).
            unsafe {
                znaupd_c(
                    &mut ido,
                    BMAT.as_ptr(),
                    self.n_c,
                    WHICH.as_ptr(),
                    self.nev_c,
                    self.tol,
                    as_arpack(self.resid.as_mut_ptr()),
                    self.ncv_c,
                    as_arpack(self.v.as_mut_ptr()),
                    self.n_c,
                    self.iparam.as_mut_ptr(),
                    self.ipntr.as_mut_ptr(),
                    as_arpack(self.workd.as_mut_ptr()),
                    as_arpack(self.workl.as_mut_ptr()),
                    self.lworkl_c,
                    self.rwork.as_mut_ptr(),
                    &mut info,
                );
            }
            match ido {
                // y = OP x (mode 1: -1 during initialization, 1 afterwards; same request).
                -1 | 1 => {
                    let (x, y) =
                        request_io(Routine::Znaupd, &mut self.workd, &self.ipntr, 0, 1, ido, n)?;
                    op.apply(x, y);
                }
                99 => break,
                other => {
                    // An error exit also ends with ido = 99; anything else (2 = B x with
                    // bmat = 'I', 3 = user shifts with iparam[0] = 1) is a protocol
                    // violation unless info already says what went wrong.
                    if info < 0 {
                        break;
                    }
                    return Err(ArpackError::UnexpectedRequest {
                        routine: Routine::Znaupd,
                        ido: other,
                    });
                }
            }
        }
        match info {
            0 | 1 => Ok(()),
            code => Err(ArpackError::from_info(
                Routine::Znaupd,
                code,
                self.nev,
                self.ncv,
                self.iparam[4],
            )),
        }
    }

    /// `zneupd` after [`Session::iterate`]: the converged values and their unit 2-norm
    /// vectors. The caller holds `ARPACK_LOCK`.
    fn extract(mut self) -> Result<ComplexKernelOutput, ArpackError> {
        let (n, nev) = (self.n, self.nev);
        let iterations = usize::try_from(self.iparam[2]).unwrap_or(0);
        // znaup2 counts converged values among the nev wanted ones only: nconv <= nev.
        let nconv = usize::try_from(self.iparam[4]).unwrap_or(0).min(nev);
        if nconv == 0 {
            // Only possible with info = 1: nothing to extract (zneupd would say -14).
            return Ok(ComplexKernelOutput {
                theta: Vec::new(),
                vectors: Mat::zeros(n, 0),
                iterations,
                all_converged: false,
            });
        }
        let select = vec![0 as a_int; self.ncv];
        let mut d = vec![ZERO; nev + 1];
        let mut z = vec![ZERO; n * nev];
        let mut workev = vec![ZERO; 2 * self.ncv];
        let mut info_e: a_int = 0;
        // SAFETY: as in `iterate`, plus `select` (ncv entries, workspace for howmny =
        // 'A'), `d` (nev + 1), `z` (n * nev, ldz = n; zneupd writes nconv <= nev columns)
        // and `workev` (2 ncv); sigma is passed by value (unused in mode 1); the znaupd
        // state is passed back unchanged.
        unsafe {
            zneupd_c(
                1,
                c"A".as_ptr(),
                select.as_ptr(),
                as_arpack(d.as_mut_ptr()),
                as_arpack(z.as_mut_ptr()),
                self.n_c,
                Complex64::default(),
                as_arpack(workev.as_mut_ptr()),
                BMAT.as_ptr(),
                self.n_c,
                WHICH.as_ptr(),
                self.nev_c,
                self.tol,
                as_arpack(self.resid.as_mut_ptr()),
                self.ncv_c,
                as_arpack(self.v.as_mut_ptr()),
                self.n_c,
                self.iparam.as_mut_ptr(),
                self.ipntr.as_mut_ptr(),
                as_arpack(self.workd.as_mut_ptr()),
                as_arpack(self.workl.as_mut_ptr()),
                self.lworkl_c,
                self.rwork.as_mut_ptr(),
                &mut info_e,
            );
        }
        if info_e != 0 {
            return Err(ArpackError::from_info(
                Routine::Zneupd,
                info_e,
                nev,
                self.ncv,
                self.iparam[4],
            ));
        }
        // zneupd may lower its internal count when ztrsen reorders fewer values than
        // asked (without always reporting it): its untouched output columns stay exactly
        // zero. Keep only genuine, finite pairs.
        let keep: Vec<usize> = (0..nconv)
            .filter(|&j| {
                let col = &z[j * n..(j + 1) * n];
                let finite = d[j].re.is_finite()
                    && d[j].im.is_finite()
                    && col.iter().all(|x| x.re.is_finite() && x.im.is_finite());
                finite && col.iter().any(|x| *x != ZERO)
            })
            .collect();
        let theta: Vec<c64> = keep.iter().map(|&j| d[j]).collect();
        let vectors = Mat::from_fn(n, keep.len(), |i, c| z[keep[c] * n + i]);
        Ok(ComplexKernelOutput {
            all_converged: theta.len() >= nev,
            theta,
            vectors,
            iterations,
        })
    }
}
