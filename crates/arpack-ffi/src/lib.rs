//! Raw FFI declarations for the ISO C bindings of ARPACK-NG (`arpack/arpack.h`, >= 3.8).
//!
//! Only the double precision real symmetric (`dsaupd_c`/`dseupd_c`), real non-symmetric
//! (`dnaupd_c`/`dneupd_c`) and complex (`znaupd_c`/`zneupd_c`) drivers are declared.
//! Nothing here is safe: every function is an `unsafe extern "C"` reverse-communication
//! routine that reads and writes caller-owned buffers of the sizes given in its docs.
//!
//! Conventions of the C bindings (see `arpack/arpack.h` and the Fortran sources
//! `ICB/icba.F90`, `ICB/icbz.F90`, ...):
//!
//! - [`a_int`] is C `int` (Debian builds without `INTERFACE64`, see `arpackdef.h`).
//!   Scalars that Fortran only reads (`n`, `nev`, `ncv`, `ldv`, `lworkl`, `tol`,
//!   `rvec`, `sigma`) are passed **by value**; `ido`, `info`, `iparam`, `ipntr` by pointer.
//! - `bmat` and `howmny` are one character, `which` is **two** characters; none needs a
//!   NUL terminator (the Fortran side reads a fixed length), but passing C string
//!   literals such as `c"G".as_ptr()` or `c"LM".as_ptr()` is harmless and convenient.
//! - `rvec` and `select` are integer stand-ins for Fortran `LOGICAL`: nonzero is true.
//!   `select` must hold `ncv` entries even with `howmny = 'A'` (then it is workspace).
//! - `ipntr` entries are **1-based Fortran indices** into `workd`: the vector `x` of a
//!   reverse-communication request starts at `workd[ipntr[0] - 1]`, the output `y` at
//!   `workd[ipntr[1] - 1]`, and (mode 3, `ido == 1`) `B x` at `workd[ipntr[2] - 1]`.
//! - `iparam` and `ipntr` are 11 integers (14 for `ipntr` of the non-symmetric and
//!   complex drivers); `iparam[0]` = shift strategy, `[2]` = max iterations in,
//!   iterations taken out, `[4]` = number of converged Ritz values, `[6]` = mode.
//!
//! ARPACK keeps state between reverse-communication calls in Fortran `SAVE` variables
//! and common blocks: it is **not thread safe and not re-entrant**. Hold [`ARPACK_LOCK`]
//! for a whole run (the `*aupd_c` loop and the following `*eupd_c` call).
//!
//! Reference: R. B. Lehoucq, D. C. Sorensen, C. Yang, *ARPACK Users' Guide: Solution of
//! Large-Scale Eigenvalue Problems with Implicitly Restarted Arnoldi Methods*, SIAM, 1998.
#![allow(non_camel_case_types)]

use core::ffi::{c_char, c_int};

/// ARPACK's integer type `a_int` (C `int` for the LP64 build Debian ships).
pub type a_int = c_int;

/// Process-wide lock serializing every use of the ARPACK library, whose Fortran code
/// keeps its reverse-communication state in static (`SAVE`) storage.
///
/// Every crate calling into ARPACK must hold this guard from the first `*aupd_c` call
/// of a run to the end of the matching `*eupd_c` call. A poisoned lock can be recovered
/// with `into_inner`: a run that starts with `ido = 0` reinitializes ARPACK's state.
pub static ARPACK_LOCK: std::sync::Mutex<()> = std::sync::Mutex::new(());

/// C `double _Complex`: two `f64`, real part first.
///
/// Same layout as `num_complex::Complex<f64>` and `faer::c64`, so pointers to those can
/// be cast to `*mut Complex64`. Passed by value (the `sigma` of [`zneupd_c`]) it follows
/// the platform ABI for `double _Complex`, which on x86-64 System V and AArch64 AAPCS is
/// that of a struct of two doubles.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Complex64 {
    /// Real part.
    pub re: f64,
    /// Imaginary part.
    pub im: f64,
}

#[link(name = "arpack")]
extern "C" {
    /// Reverse-communication implicitly restarted Lanczos iteration for a real symmetric
    /// (generalized) eigenproblem (`dsaupd`).
    ///
    /// - `ido`: 0 on the first call; on return -1/1 ask for `y = OP x` (`ido == 1` in
    ///   mode 3 also provides `B x` at `workd[ipntr[2]-1..]`), 2 for `y = B x`, 3 for
    ///   shifts (only with `iparam[0] == 0`), 99 when done.
    /// - `bmat`: `'I'` (standard) or `'G'` (generalized); `which`: two characters
    ///   (`"LM"`, `"SM"`, `"LA"`, `"SA"`, `"BE"`).
    /// - `resid`: `n` (start vector when `*info != 0` on entry); `v`: `ldv * ncv`
    ///   (Lanczos basis, column major); `iparam`, `ipntr`: 11 each; `workd`: `3 n`;
    ///   `workl`: `lworkl >= ncv (ncv + 8)`.
    /// - `info`: 0 on entry for a random start vector, 1 to use `resid`; on exit 0 = ok,
    ///   1 = maximum iterations, 3 = no shifts could be applied, negative = error.
    pub fn dsaupd_c(
        ido: *mut a_int,
        bmat: *const c_char,
        n: a_int,
        which: *const c_char,
        nev: a_int,
        tol: f64,
        resid: *mut f64,
        ncv: a_int,
        v: *mut f64,
        ldv: a_int,
        iparam: *mut a_int,
        ipntr: *mut a_int,
        workd: *mut f64,
        workl: *mut f64,
        lworkl: a_int,
        info: *mut a_int,
    );

    /// Ritz values and (optionally) Ritz vectors after [`dsaupd_c`] converged (`dseupd`).
    ///
    /// - `rvec`: nonzero to compute vectors; `howmny`: `'A'` (all) or `'S'` (by `select`);
    ///   `select`: `ncv` integers (workspace when `howmny == 'A'`).
    /// - `d`: `nev` eigenvalues of the original problem (back-transformed with `sigma`
    ///   in modes 3-5), ascending; `z`: `ldz * nev` vectors (may alias `v`).
    /// - The remaining arguments must be passed unchanged from the [`dsaupd_c`] run.
    pub fn dseupd_c(
        rvec: a_int,
        howmny: *const c_char,
        select: *const a_int,
        d: *mut f64,
        z: *mut f64,
        ldz: a_int,
        sigma: f64,
        bmat: *const c_char,
        n: a_int,
        which: *const c_char,
        nev: a_int,
        tol: f64,
        resid: *mut f64,
        ncv: a_int,
        v: *mut f64,
        ldv: a_int,
        iparam: *mut a_int,
        ipntr: *mut a_int,
        workd: *mut f64,
        workl: *mut f64,
        lworkl: a_int,
        info: *mut a_int,
    );

    /// Reverse-communication implicitly restarted Arnoldi iteration for a real
    /// non-symmetric (generalized) eigenproblem (`dnaupd`).
    ///
    /// Same protocol as [`dsaupd_c`]; `which` also accepts `"LR"`, `"SR"`, `"LI"`, `"SI"`.
    /// Sizes: `resid` `n`, `v` `ldv * ncv`, `iparam` 11, `ipntr` 14, `workd` `3 n`,
    /// `workl` `lworkl >= 3 ncv^2 + 6 ncv`; requires `nev + 2 <= ncv <= n`.
    pub fn dnaupd_c(
        ido: *mut a_int,
        bmat: *const c_char,
        n: a_int,
        which: *const c_char,
        nev: a_int,
        tol: f64,
        resid: *mut f64,
        ncv: a_int,
        v: *mut f64,
        ldv: a_int,
        iparam: *mut a_int,
        ipntr: *mut a_int,
        workd: *mut f64,
        workl: *mut f64,
        lworkl: a_int,
        info: *mut a_int,
    );

    /// Ritz values and vectors after [`dnaupd_c`] (`dneupd`).
    ///
    /// `dr`, `di`: real and imaginary parts, `nev + 1` each; `z`: `ldz * (nev + 1)`
    /// (complex pairs stored as consecutive real/imaginary columns); `sigmar`, `sigmai`:
    /// the shift; `workev`: `3 ncv`; `select`: `ncv` integers. The remaining arguments
    /// come unchanged from the [`dnaupd_c`] run.
    pub fn dneupd_c(
        rvec: a_int,
        howmny: *const c_char,
        select: *const a_int,
        dr: *mut f64,
        di: *mut f64,
        z: *mut f64,
        ldz: a_int,
        sigmar: f64,
        sigmai: f64,
        workev: *mut f64,
        bmat: *const c_char,
        n: a_int,
        which: *const c_char,
        nev: a_int,
        tol: f64,
        resid: *mut f64,
        ncv: a_int,
        v: *mut f64,
        ldv: a_int,
        iparam: *mut a_int,
        ipntr: *mut a_int,
        workd: *mut f64,
        workl: *mut f64,
        lworkl: a_int,
        info: *mut a_int,
    );

    /// Reverse-communication implicitly restarted Arnoldi iteration for a complex
    /// (generalized) eigenproblem (`znaupd`).
    ///
    /// Same protocol as [`dnaupd_c`] with complex vectors. Sizes: `resid` `n`, `v`
    /// `ldv * ncv`, `iparam` 11, `ipntr` 14, `workd` `3 n`, `workl`
    /// `lworkl >= 3 ncv^2 + 5 ncv` (all [`Complex64`]), `rwork` `ncv` reals;
    /// requires `nev + 1 <= ncv <= n`.
    pub fn znaupd_c(
        ido: *mut a_int,
        bmat: *const c_char,
        n: a_int,
        which: *const c_char,
        nev: a_int,
        tol: f64,
        resid: *mut Complex64,
        ncv: a_int,
        v: *mut Complex64,
        ldv: a_int,
        iparam: *mut a_int,
        ipntr: *mut a_int,
        workd: *mut Complex64,
        workl: *mut Complex64,
        lworkl: a_int,
        rwork: *mut f64,
        info: *mut a_int,
    );

    /// Ritz values and vectors after [`znaupd_c`] (`zneupd`).
    ///
    /// `d`: `nev + 1` eigenvalues; `z`: `ldz * nev` vectors; `sigma`: the shift, passed
    /// **by value** as a C `double _Complex`; `workev`: `2 ncv`; `select`: `ncv` integers;
    /// `rwork`: `ncv` reals. The remaining arguments come unchanged from the [`znaupd_c`]
    /// run. `zneupd` is stricter than `znaupd`: it requires `nev + 2 <= ncv <= n`
    /// (`info = -3` otherwise), so size `ncv` for both.
    pub fn zneupd_c(
        rvec: a_int,
        howmny: *const c_char,
        select: *const a_int,
        d: *mut Complex64,
        z: *mut Complex64,
        ldz: a_int,
        sigma: Complex64,
        workev: *mut Complex64,
        bmat: *const c_char,
        n: a_int,
        which: *const c_char,
        nev: a_int,
        tol: f64,
        resid: *mut Complex64,
        ncv: a_int,
        v: *mut Complex64,
        ldv: a_int,
        iparam: *mut a_int,
        ipntr: *mut a_int,
        workd: *mut Complex64,
        workl: *mut Complex64,
        lworkl: a_int,
        rwork: *mut f64,
        info: *mut a_int,
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Links and calls the library: the standard problem `diag(1..=n) x = lambda x`,
    /// three largest eigenvalues by `dsaupd_c`/`dseupd_c` in mode 1.
    #[test]
    fn dsaupd_finds_largest_of_a_diagonal() {
        let _guard = ARPACK_LOCK.lock().unwrap_or_else(|e| e.into_inner());
        let (n, nev, ncv) = (50usize, 3usize, 12usize);
        let lworkl = ncv * (ncv + 8);
        let mut ido: a_int = 0;
        let mut info: a_int = 0;
        let mut resid = vec![0.0; n];
        let mut v = vec![0.0; n * ncv];
        let mut iparam = [0 as a_int; 11];
        let mut ipntr = [0 as a_int; 11];
        let mut workd = vec![0.0; 3 * n];
        let mut workl = vec![0.0; lworkl];
        iparam[0] = 1;
        iparam[2] = 300;
        iparam[6] = 1;
        let bmat = c"I".as_ptr();
        let which = c"LM".as_ptr();
        loop {
            // SAFETY: all buffers have the sizes documented for dsaupd_c.
            unsafe {
                dsaupd_c(
                    &mut ido,
                    bmat,
                    n as a_int,
                    which,
                    nev as a_int,
                    1e-12,
                    resid.as_mut_ptr(),
                    ncv as a_int,
                    v.as_mut_ptr(),
                    n as a_int,
                    iparam.as_mut_ptr(),
                    ipntr.as_mut_ptr(),
                    workd.as_mut_ptr(),
                    workl.as_mut_ptr(),
                    lworkl as a_int,
                    &mut info,
                )
            };
            if ido != -1 && ido != 1 {
                break;
            }
            let (x0, y0) = (ipntr[0] as usize - 1, ipntr[1] as usize - 1);
            for i in 0..n {
                workd[y0 + i] = (i + 1) as f64 * workd[x0 + i];
            }
        }
        assert_eq!(info, 0);
        assert_eq!(ido, 99);
        assert_eq!(iparam[4] as usize, nev);
        let select = vec![0 as a_int; ncv];
        let mut d = vec![0.0; nev];
        let mut z = vec![0.0; n * nev];
        // SAFETY: as above, plus `select` (ncv), `d` (nev) and `z` (n * nev).
        unsafe {
            dseupd_c(
                1,
                c"A".as_ptr(),
                select.as_ptr(),
                d.as_mut_ptr(),
                z.as_mut_ptr(),
                n as a_int,
                0.0,
                bmat,
                n as a_int,
                which,
                nev as a_int,
                1e-12,
                resid.as_mut_ptr(),
                ncv as a_int,
                v.as_mut_ptr(),
                n as a_int,
                iparam.as_mut_ptr(),
                ipntr.as_mut_ptr(),
                workd.as_mut_ptr(),
                workl.as_mut_ptr(),
                lworkl as a_int,
                &mut info,
            )
        };
        assert_eq!(info, 0);
        let mut d_sorted = d.clone();
        d_sorted.sort_by(f64::total_cmp);
        for (got, want) in d_sorted.iter().zip([48.0, 49.0, 50.0]) {
            approx::assert_relative_eq!(*got, want, max_relative = 1e-12);
        }
        // The vector of eigenvalue 50 is +-e_50.
        let col = d.iter().position(|&x| (x - 50.0).abs() < 1e-8).unwrap();
        approx::assert_relative_eq!(z[col * n + n - 1].abs(), 1.0, max_relative = 1e-10);
    }

    /// `znaupd_c`/`zneupd_c` in shift-invert mode 3 on `A = diag(a_j)`,
    /// `a_j = j + 0.5 i j / n`: the eigenvalues nearest `sigma` come back
    /// back-transformed with the `sigma` passed by value, which checks the ABI of the
    /// `double _Complex` argument.
    #[test]
    fn znaupd_shift_invert_with_complex_sigma_by_value() {
        let _guard = ARPACK_LOCK.lock().unwrap_or_else(|e| e.into_inner());
        let (n, nev, ncv) = (40usize, 4usize, 16usize);
        let a = |j: usize| Complex64 {
            re: (j + 1) as f64,
            im: 0.5 * (j + 1) as f64 / n as f64,
        };
        let sigma = Complex64 { re: 10.3, im: 0.2 };
        let lworkl = 3 * ncv * ncv + 5 * ncv;
        let zero = Complex64::default();
        let mut ido: a_int = 0;
        let mut info: a_int = 0;
        let mut resid = vec![zero; n];
        let mut v = vec![zero; n * ncv];
        let mut iparam = [0 as a_int; 11];
        let mut ipntr = [0 as a_int; 14];
        let mut workd = vec![zero; 3 * n];
        let mut workl = vec![zero; lworkl];
        let mut rwork = vec![0.0; ncv];
        iparam[0] = 1;
        iparam[2] = 300;
        iparam[6] = 3;
        let bmat = c"I".as_ptr();
        let which = c"LM".as_ptr();
        loop {
            // SAFETY: all buffers have the sizes documented for znaupd_c.
            unsafe {
                znaupd_c(
                    &mut ido,
                    bmat,
                    n as a_int,
                    which,
                    nev as a_int,
                    1e-12,
                    resid.as_mut_ptr(),
                    ncv as a_int,
                    v.as_mut_ptr(),
                    n as a_int,
                    iparam.as_mut_ptr(),
                    ipntr.as_mut_ptr(),
                    workd.as_mut_ptr(),
                    workl.as_mut_ptr(),
                    lworkl as a_int,
                    rwork.as_mut_ptr(),
                    &mut info,
                )
            };
            if ido != -1 && ido != 1 {
                break;
            }
            // y = (A - sigma)^-1 x
            let (x0, y0) = (ipntr[0] as usize - 1, ipntr[1] as usize - 1);
            for j in 0..n {
                let (p, q) = (a(j).re - sigma.re, a(j).im - sigma.im);
                let den = p * p + q * q;
                let x = workd[x0 + j];
                workd[y0 + j] = Complex64 {
                    re: (x.re * p + x.im * q) / den,
                    im: (x.im * p - x.re * q) / den,
                };
            }
        }
        assert_eq!((info, ido), (0, 99));
        assert_eq!(iparam[4] as usize, nev);
        let select = vec![0 as a_int; ncv];
        let mut d = vec![zero; nev + 1];
        let mut z = vec![zero; n * nev];
        let mut workev = vec![zero; 2 * ncv];
        // SAFETY: as above, plus `select` (ncv), `d` (nev + 1), `z` (n * nev) and
        // `workev` (2 ncv).
        unsafe {
            zneupd_c(
                1,
                c"A".as_ptr(),
                select.as_ptr(),
                d.as_mut_ptr(),
                z.as_mut_ptr(),
                n as a_int,
                sigma,
                workev.as_mut_ptr(),
                bmat,
                n as a_int,
                which,
                nev as a_int,
                1e-12,
                resid.as_mut_ptr(),
                ncv as a_int,
                v.as_mut_ptr(),
                n as a_int,
                iparam.as_mut_ptr(),
                ipntr.as_mut_ptr(),
                workd.as_mut_ptr(),
                workl.as_mut_ptr(),
                lworkl as a_int,
                rwork.as_mut_ptr(),
                &mut info,
            )
        };
        assert_eq!(info, 0);
        // Nearest to 10.3: a_10, a_11, a_9, a_12 (1-based), i.e. j = 9, 10, 8, 11.
        let mut got: Vec<Complex64> = d[..nev].to_vec();
        got.sort_by(|x, y| x.re.total_cmp(&y.re));
        for (g, j) in got.iter().zip(8..12) {
            approx::assert_relative_eq!(g.re, a(j).re, max_relative = 1e-11);
            approx::assert_relative_eq!(g.im, a(j).im, max_relative = 1e-9);
        }
    }

    /// `dnaupd_c`/`dneupd_c` in mode 1 on a block-diagonal matrix of 2x2 rotations-scalings
    /// `[[a, b], [-b, a]]` (eigenvalues `a +- i b`): the largest pair comes back as a
    /// conjugate pair in `dr`/`di`.
    #[test]
    fn dnaupd_finds_a_complex_conjugate_pair() {
        let _guard = ARPACK_LOCK.lock().unwrap_or_else(|e| e.into_inner());
        let (blocks, nev, ncv) = (20usize, 2usize, 10usize);
        let n = 2 * blocks;
        let ab = |k: usize| ((k + 1) as f64, 0.25 * (k + 1) as f64);
        let lworkl = 3 * ncv * ncv + 6 * ncv;
        let mut ido: a_int = 0;
        let mut info: a_int = 0;
        let mut resid = vec![0.0; n];
        let mut v = vec![0.0; n * ncv];
        let mut iparam = [0 as a_int; 11];
        let mut ipntr = [0 as a_int; 14];
        let mut workd = vec![0.0; 3 * n];
        let mut workl = vec![0.0; lworkl];
        iparam[0] = 1;
        iparam[2] = 300;
        iparam[6] = 1;
        let bmat = c"I".as_ptr();
        let which = c"LM".as_ptr();
        loop {
            // SAFETY: all buffers have the sizes documented for dnaupd_c.
            unsafe {
                dnaupd_c(
                    &mut ido,
                    bmat,
                    n as a_int,
                    which,
                    nev as a_int,
                    1e-12,
                    resid.as_mut_ptr(),
                    ncv as a_int,
                    v.as_mut_ptr(),
                    n as a_int,
                    iparam.as_mut_ptr(),
                    ipntr.as_mut_ptr(),
                    workd.as_mut_ptr(),
                    workl.as_mut_ptr(),
                    lworkl as a_int,
                    &mut info,
                )
            };
            if ido != -1 && ido != 1 {
                break;
            }
            let (x0, y0) = (ipntr[0] as usize - 1, ipntr[1] as usize - 1);
            for k in 0..blocks {
                let (a, b) = ab(k);
                let (x1, x2) = (workd[x0 + 2 * k], workd[x0 + 2 * k + 1]);
                workd[y0 + 2 * k] = a * x1 + b * x2;
                workd[y0 + 2 * k + 1] = -b * x1 + a * x2;
            }
        }
        assert_eq!((info, ido), (0, 99));
        let select = vec![0 as a_int; ncv];
        let (mut dr, mut di) = (vec![0.0; nev + 1], vec![0.0; nev + 1]);
        let mut z = vec![0.0; n * (nev + 1)];
        let mut workev = vec![0.0; 3 * ncv];
        // SAFETY: as above, plus `select` (ncv), `dr`, `di` (nev + 1), `z`
        // (n * (nev + 1)) and `workev` (3 ncv).
        unsafe {
            dneupd_c(
                1,
                c"A".as_ptr(),
                select.as_ptr(),
                dr.as_mut_ptr(),
                di.as_mut_ptr(),
                z.as_mut_ptr(),
                n as a_int,
                0.0,
                0.0,
                workev.as_mut_ptr(),
                bmat,
                n as a_int,
                which,
                nev as a_int,
                1e-12,
                resid.as_mut_ptr(),
                ncv as a_int,
                v.as_mut_ptr(),
                n as a_int,
                iparam.as_mut_ptr(),
                ipntr.as_mut_ptr(),
                workd.as_mut_ptr(),
                workl.as_mut_ptr(),
                lworkl as a_int,
                &mut info,
            )
        };
        assert_eq!(info, 0);
        let (a, b) = ab(blocks - 1);
        for k in 0..nev {
            approx::assert_relative_eq!(dr[k], a, max_relative = 1e-11);
            approx::assert_relative_eq!(di[k].abs(), b, max_relative = 1e-11);
        }
        approx::assert_relative_eq!(di[0], -di[1], max_relative = 1e-11);
    }
}
