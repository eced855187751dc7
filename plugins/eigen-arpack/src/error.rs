//! [`ArpackError`]: ARPACK's `info` codes as typed errors.

use std::fmt;
use thiserror::Error;

/// The ARPACK routine that reported a code.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Routine {
    /// `dsaupd`, the implicitly restarted Lanczos iteration (real symmetric).
    Dsaupd,
    /// `dseupd`, the Ritz value and vector extraction after `dsaupd`.
    Dseupd,
    /// `znaupd`, the implicitly restarted Arnoldi iteration (complex).
    Znaupd,
    /// `zneupd`, the Ritz value and vector extraction after `znaupd`.
    Zneupd,
    /// `dnaupd`, the implicitly restarted Arnoldi iteration (real non-symmetric).
    Dnaupd,
    /// `dneupd`, the Ritz value and vector extraction after `dnaupd`.
    Dneupd,
}

impl Routine {
    /// The Krylov factorization the routine builds: `"Lanczos"` or `"Arnoldi"`.
    pub fn krylov(self) -> &'static str {
        match self {
            Routine::Dsaupd | Routine::Dseupd => "Lanczos",
            Routine::Znaupd | Routine::Zneupd | Routine::Dnaupd | Routine::Dneupd => "Arnoldi",
        }
    }

    /// The iteration routine whose data an extraction routine consumes (`dsaupd` for
    /// `dseupd`, `znaupd` for `zneupd`; an iteration routine is its own).
    pub fn iteration(self) -> Routine {
        match self {
            Routine::Dsaupd | Routine::Dseupd => Routine::Dsaupd,
            Routine::Znaupd | Routine::Zneupd => Routine::Znaupd,
            Routine::Dnaupd | Routine::Dneupd => Routine::Dnaupd,
        }
    }
}

impl fmt::Display for Routine {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Routine::Dsaupd => "dsaupd",
            Routine::Dseupd => "dseupd",
            Routine::Znaupd => "znaupd",
            Routine::Zneupd => "zneupd",
            Routine::Dnaupd => "dnaupd",
            Routine::Dneupd => "dneupd",
        })
    }
}

/// A failure of the ARPACK backend: an `info` code of `dsaupd`/`dseupd` or
/// `znaupd`/`zneupd`, or a request that cannot be handed to ARPACK at all.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum ArpackError {
    /// `info = 1` of `dsaupd`/`znaupd`: the iteration cap was reached. The kernels do not
    /// raise this one (they return the converged pairs instead); it exists for
    /// completeness.
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
    /// `info = 3` (or the deprecated 2) of `dsaupd`/`znaupd`: no shifts could be applied
    /// during a cycle of the implicit restart; `ncv` is too small relative to `nev`.
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
        /// Krylov basis size.
        ncv: usize,
    },
    /// `info = -9999`: the Lanczos (`dsaupd`) or Arnoldi (`znaupd`) factorization could not
    /// be built (an invariant subspace or a loss of orthogonality; for `dsaupd` typically
    /// an `M` that is not positive definite or an operator that is not `M`-symmetric).
    #[error(
        "{routine}: could not build the {} factorization (info = -9999); \
         it stopped at size {size}",
        routine.krylov()
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
    /// `info = -8` of `znaupd`/`zneupd`: LAPACK (`zlahqr`/`ztrevc`) failed on the
    /// projected upper Hessenberg eigenproblem.
    #[error(
        "{routine}: LAPACK failed on the upper Hessenberg eigenproblem (zlahqr/ztrevc or dlahqr/dtrevc, info = -8)"
    )]
    Hessenberg {
        /// Reporting routine.
        routine: Routine,
    },
    /// `info = -9` of `zneupd`: LAPACK `ztrevc` failed to compute the eigenvectors of the
    /// Schur form.
    #[error("{routine}: LAPACK ztrevc/dtrevc failed to compute the Ritz vectors (info = -9)")]
    Eigenvectors {
        /// Reporting routine.
        routine: Routine,
    },
    /// `info = 1` of `zneupd`: LAPACK `ztrsen` could not reorder the Schur form to bring
    /// the converged Ritz values to the front.
    #[error("{routine}: LAPACK ztrsen/dtrsen could not reorder the Schur form (info = 1)")]
    Reorder {
        /// Reporting routine.
        routine: Routine,
    },
    /// `info = -14` of `dseupd`/`zneupd`: no Ritz value met the tolerance.
    #[error("{routine}: no Ritz value converged to the requested accuracy (info = -14)")]
    NoneConverged {
        /// Reporting routine.
        routine: Routine,
    },
    /// `info = -17` of `dseupd` (`-15` of `zneupd`): it counted a different number of
    /// converged Ritz values than `dsaupd` (`znaupd`), i.e. the reverse-communication data
    /// was altered in between.
    #[error(
        "{routine}: converged Ritz value count differs from {}'s (info = {code}): \
         the data passed from {} was modified",
        routine.iteration(),
        routine.iteration()
    )]
    ConvergedCountMismatch {
        /// Reporting routine.
        routine: Routine,
        /// The raw code (`-17` for `dseupd`, `-15` for `zneupd`).
        code: i32,
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
    /// The iteration routine returned a reverse-communication request the kernel never
    /// asks for (`ido = 3`, user shifts, is only issued with `iparam[0] = 0`; `ido = 2`,
    /// `y = B x`, never with `bmat = 'I'`).
    #[error("{routine}: unexpected reverse-communication request ido = {ido}")]
    UnexpectedRequest {
        /// Reporting routine.
        routine: Routine,
        /// The `ido` value.
        ido: i32,
    },
    /// `ipntr` pointed outside `workd`, or input and output overlap.
    #[error(
        "{routine}: workspace pointers out of range for ido = {ido}: ipntr = {ipntr:?}, n = {n}"
    )]
    BadPointers {
        /// Reporting routine.
        routine: Routine,
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
    /// The operator is too small for `znaupd`/`zneupd` or `dnaupd`/`dneupd` with this
    /// `nev` (or `nev = 0`):
    /// ARPACK needs `nev + 2 <= ncv <= n`, i.e. `1 <= nev <= n - 2`. Small problems
    /// belong to a dense solver.
    #[error(
        "{routine}: cannot compute {nev} eigenpairs of an operator of dimension {n}: \
         ARPACK needs 1 <= nev <= n - 2 (nev + 2 <= ncv <= n); the operator is too small \
         for ARPACK, use a dense eigensolver"
    )]
    TooSmall {
        /// The iteration routine.
        routine: Routine,
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
    /// Interprets a nonzero `info` returned by `routine` (codes as documented in the
    /// prologues of `dsaupd.f`, `dseupd.f`, `znaupd.f` and `zneupd.f`).
    ///
    /// `nev` and `ncv` are the run's sizes, `iparam5` the value of `iparam[4]` on return
    /// (converged count, or factorization size for `-9999`).
    pub fn from_info(routine: Routine, info: i32, nev: usize, ncv: usize, iparam5: i32) -> Self {
        use Routine::{Dnaupd, Dneupd, Dsaupd, Dseupd, Znaupd, Zneupd};
        let size = usize::try_from(iparam5).unwrap_or(0);
        let invalid = |meaning: &'static str| ArpackError::InvalidArgument {
            routine,
            code: info,
            meaning,
        };
        match (routine, info) {
            // Codes common to all four routines.
            (Dsaupd | Dseupd | Znaupd | Dnaupd, 1) => ArpackError::MaxIterations {
                routine,
                converged: size,
                requested: nev,
            },
            (Dsaupd | Znaupd | Dnaupd, 2 | 3) => ArpackError::NoShifts {
                routine,
                code: info,
                nev,
                ncv,
            },
            (_, -9999) => ArpackError::NoFactorization { routine, size },
            (Dseupd | Zneupd | Dneupd, -14) => ArpackError::NoneConverged { routine },
            (_, -1) => invalid("N must be positive"),
            (_, -2) => invalid("NEV must be positive"),
            (Dsaupd | Znaupd | Dnaupd, -4) => {
                invalid("the maximum number of update iterations (iparam[2]) must be positive")
            }
            (_, -6) => invalid("BMAT must be one of I or G"),
            (Dsaupd | Dseupd | Znaupd | Dnaupd, -9) => invalid("the starting vector is zero"),
            (_, -11) => invalid("IPARAM(7) = 1 and BMAT = G are incompatible"),
            (Dsaupd | Znaupd | Dnaupd, -12) => invalid("IPARAM(1) (shift strategy) must be 0 or 1"),

            // Symmetric routines.
            (Dsaupd | Dseupd, -8) => ArpackError::Tridiagonal { routine },
            (Dseupd, -17) => ArpackError::ConvergedCountMismatch {
                routine,
                code: info,
            },
            (Dsaupd | Dseupd, -3) => invalid("NCV must satisfy NEV < NCV <= N"),
            (Dsaupd | Dseupd, -5) => invalid("WHICH must be one of LM, SM, LA, SA or BE"),
            (Dsaupd | Dseupd, -7) => {
                invalid("WORKL is too short: LWORKL must be at least NCV (NCV + 8)")
            }
            (Dsaupd | Dseupd, -10) => invalid("IPARAM(7) (mode) must be 1, 2, 3, 4 or 5"),
            (Dseupd, -12) | (Dsaupd, -13) => invalid("NEV and WHICH = BE are incompatible"),
            (Dseupd, -15) => invalid("HOWMNY must be A or S when RVEC is true"),
            (Dseupd, -16) => invalid("HOWMNY = S is not implemented"),

            // Complex routines.
            (Zneupd, 1) => ArpackError::Reorder { routine },
            (Znaupd | Zneupd, -8) => ArpackError::Hessenberg { routine },
            (Zneupd, -9) => ArpackError::Eigenvectors { routine },
            (Zneupd, -15) => ArpackError::ConvergedCountMismatch {
                routine,
                code: info,
            },
            (Znaupd, -3) => invalid("NCV must satisfy NEV < NCV <= N"),
            (Zneupd, -3) => invalid("NCV must satisfy NEV + 2 <= NCV <= N"),
            (Znaupd | Zneupd, -5) => invalid("WHICH must be one of LM, SM, LR, SR, LI or SI"),
            (Znaupd, -7) => invalid("WORKL is too short: LWORKL must be at least 3 NCV^2 + 5 NCV"),
            (Zneupd, -7) => invalid("WORKL is too short: LWORKL must be at least 3 NCV^2 + 4 NCV"),
            (Znaupd | Zneupd, -10) => invalid("IPARAM(7) (mode) must be 1, 2 or 3"),
            (Zneupd, -12) => invalid("HOWMNY = S is not implemented"),
            (Zneupd, -13) => invalid("HOWMNY must be A or P when RVEC is true"),

            // Real non-symmetric routines.
            (Dneupd, 1) => ArpackError::Reorder { routine },
            (Dnaupd | Dneupd, -8) => ArpackError::Hessenberg { routine },
            (Dneupd, -9) => ArpackError::Eigenvectors { routine },
            (Dneupd, -15) => ArpackError::ConvergedCountMismatch {
                routine,
                code: info,
            },
            (Dnaupd | Dneupd, -3) => invalid("NCV must satisfy NEV + 2 <= NCV <= N"),
            (Dnaupd | Dneupd, -5) => invalid("WHICH must be one of LM, SM, LR, SR, LI or SI"),
            (Dnaupd | Dneupd, -7) => {
                invalid("WORKL is too short: LWORKL must be at least 3 NCV^2 + 6 NCV")
            }
            (Dnaupd | Dneupd, -10) => invalid("IPARAM(7) (mode) must be 1, 2, 3 or 4"),
            (Dneupd, -12) => invalid("HOWMNY = S is not implemented"),
            (Dneupd, -13) => invalid("HOWMNY must be A or P when RVEC is true"),

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
