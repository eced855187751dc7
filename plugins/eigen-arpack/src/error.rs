//! [`ArpackError`]: ARPACK's `info` codes as typed errors.

use std::fmt;
use thiserror::Error;

/// The ARPACK routine that reported a code.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Routine {
    /// `dsaupd`, the implicitly restarted Lanczos iteration.
    Dsaupd,
    /// `dseupd`, the Ritz value and vector extraction.
    Dseupd,
}

impl fmt::Display for Routine {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Routine::Dsaupd => "dsaupd",
            Routine::Dseupd => "dseupd",
        })
    }
}

/// A failure of the ARPACK backend: an `info` code of `dsaupd`/`dseupd`, or a request
/// that cannot be handed to ARPACK at all.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum ArpackError {
    /// `info = 1` of `dsaupd`: the iteration cap was reached. The kernel does not raise
    /// this one (it returns the converged pairs instead); it exists for completeness.
    #[error(
        "{routine}: maximum number of iterations taken (info = 1): \
         {converged} of {requested} Ritz values converged"
    )]
    MaxIterations {
        /// Reporting routine.
        routine: Routine,
        /// Converged Ritz values (`iparam[4]`).
        converged: usize,
        /// Requested Ritz values (`nev`).
        requested: usize,
    },
    /// `info = 3` (or the deprecated 2) of `dsaupd`: no shifts could be applied during a
    /// cycle of the implicit restart; `ncv` is too small relative to `nev`.
    #[error(
        "{routine}: no shifts could be applied during an implicit restart (info = {code}): \
         ncv = {ncv} is too small relative to nev = {nev}"
    )]
    NoShifts {
        /// Reporting routine.
        routine: Routine,
        /// The raw code (3, or 2 from pre-2.0 ARPACK).
        code: i32,
        /// Requested pairs.
        nev: usize,
        /// Lanczos basis size.
        ncv: usize,
    },
    /// `info = -9999`: the Lanczos factorization could not be built (an invariant
    /// subspace or a loss of `M`-orthogonality, typically an `M` that is not positive
    /// definite or an operator that is not `M`-symmetric).
    #[error(
        "{routine}: could not build a Lanczos factorization (info = -9999); \
         it stopped at size {size}"
    )]
    NoFactorization {
        /// Reporting routine.
        routine: Routine,
        /// Size of the factorization reached (`iparam[4]`).
        size: usize,
    },
    /// `info = -8`: LAPACK `dsteqr` failed on the projected tridiagonal eigenproblem.
    #[error("{routine}: LAPACK dsteqr failed on the tridiagonal eigenproblem (info = -8)")]
    Tridiagonal {
        /// Reporting routine.
        routine: Routine,
    },
    /// `info = -14` of `dseupd`: no Ritz value met the tolerance.
    #[error("{routine}: no Ritz value converged to the requested accuracy (info = -14)")]
    NoneConverged {
        /// Reporting routine.
        routine: Routine,
    },
    /// `info = -17` of `dseupd`: it counted a different number of converged Ritz values
    /// than `dsaupd`, i.e. the reverse-communication data was altered in between.
    #[error(
        "{routine}: converged Ritz value count differs from dsaupd's (info = -17): \
         the data passed from dsaupd was modified"
    )]
    ConvergedCountMismatch {
        /// Reporting routine.
        routine: Routine,
    },
    /// A documented negative `info`: an invalid argument (size, string, workspace, mode).
    #[error("{routine}: invalid argument (info = {code}): {meaning}")]
    InvalidArgument {
        /// Reporting routine.
        routine: Routine,
        /// The raw code.
        code: i32,
        /// What ARPACK's documentation says it means.
        meaning: &'static str,
    },
    /// An `info` value the ARPACK documentation does not list.
    #[error("{routine}: undocumented info code {code}")]
    Unknown {
        /// Reporting routine.
        routine: Routine,
        /// The raw code.
        code: i32,
    },
    /// `dsaupd` returned a reverse-communication request the kernel never asks for
    /// (`ido = 3`, user shifts, is only issued with `iparam[0] = 0`).
    #[error("dsaupd: unexpected reverse-communication request ido = {ido}")]
    UnexpectedRequest {
        /// The `ido` value.
        ido: i32,
    },
    /// `ipntr` pointed outside `workd`, or input and output overlap.
    #[error("dsaupd: workspace pointers out of range for ido = {ido}: ipntr = {ipntr:?}, n = {n}")]
    BadPointers {
        /// The `ido` value of the request.
        ido: i32,
        /// The first three (1-based) pointers.
        ipntr: [i32; 3],
        /// Problem size.
        n: usize,
    },
    /// `nev` is outside `1..n`: ARPACK needs `nev < ncv <= n`.
    #[error("cannot compute {nev} eigenpairs of an operator of dimension {n} (need 1 <= nev < n)")]
    BadRequest {
        /// Requested pairs.
        nev: usize,
        /// Operator dimension.
        n: usize,
    },
    /// A size does not fit ARPACK's 32-bit `a_int`.
    #[error("{what} = {value} exceeds ARPACK's 32-bit integers")]
    TooLarge {
        /// Which size.
        what: &'static str,
        /// Its value.
        value: usize,
    },
}

impl ArpackError {
    /// Interprets a nonzero `info` returned by `routine`.
    ///
    /// `nev` and `ncv` are the run's sizes, `iparam5` the value of `iparam[4]` on return
    /// (converged count, or factorization size for `-9999`).
    pub fn from_info(routine: Routine, info: i32, nev: usize, ncv: usize, iparam5: i32) -> Self {
        let size = usize::try_from(iparam5).unwrap_or(0);
        let invalid = |meaning: &'static str| ArpackError::InvalidArgument {
            routine,
            code: info,
            meaning,
        };
        match (routine, info) {
            (_, 1) => ArpackError::MaxIterations {
                routine,
                converged: size,
                requested: nev,
            },
            (Routine::Dsaupd, 2 | 3) => ArpackError::NoShifts {
                routine,
                code: info,
                nev,
                ncv,
            },
            (_, -9999) => ArpackError::NoFactorization { routine, size },
            (_, -8) => ArpackError::Tridiagonal { routine },
            (Routine::Dseupd, -14) => ArpackError::NoneConverged { routine },
            (Routine::Dseupd, -17) => ArpackError::ConvergedCountMismatch { routine },
            (_, -1) => invalid("N must be positive"),
            (_, -2) => invalid("NEV must be positive"),
            (_, -3) => invalid("NCV must satisfy NEV < NCV <= N"),
            (Routine::Dsaupd, -4) => {
                invalid("the maximum number of update iterations (iparam[2]) must be positive")
            }
            (_, -5) => invalid("WHICH must be one of LM, SM, LA, SA or BE"),
            (_, -6) => invalid("BMAT must be one of I or G"),
            (_, -7) => invalid("WORKL is too short: LWORKL must be at least NCV (NCV + 8)"),
            (_, -9) => invalid("the starting vector is zero"),
            (_, -10) => invalid("IPARAM(7) (mode) must be 1, 2, 3, 4 or 5"),
            (_, -11) => invalid("IPARAM(7) = 1 and BMAT = G are incompatible"),
            (Routine::Dsaupd, -12) => invalid("IPARAM(1) (shift strategy) must be 0 or 1"),
            (Routine::Dseupd, -12) | (Routine::Dsaupd, -13) => {
                invalid("NEV and WHICH = BE are incompatible")
            }
            (Routine::Dseupd, -15) => invalid("HOWMNY must be A or S when RVEC is true"),
            (Routine::Dseupd, -16) => invalid("HOWMNY = S is not implemented"),
            _ => ArpackError::Unknown {
                routine,
                code: info,
            },
        }
    }
}

impl From<ArpackError> for squeal_core::Error {
    fn from(e: ArpackError) -> Self {
        squeal_core::Error::Backend(Box::new(e))
    }
}
