//! The inertia of a sparse symmetric matrix ([`inertia`]): how many of its eigenvalues are
//! negative, zero and positive, by Sylvester's law of inertia on a Bunch-Kaufman
//! `L B L^T` factorization (faer's supernodal, pivoting inside supernodes).

use super::check_square_finite;
use crate::ordering::{symmetric_ordering, FillOrdering};
use crate::{Error, Result, SparseRef};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::cholesky::supernodal::SupernodalIntranodeLbltRef;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, SymbolicCholeskyRaw,
};
use faer::sparse::linalg::{SupernodalThreshold, SymbolicSupernodalParams};
use faer::Side;

/// A block of `B` whose eigenvalues are below this fraction of the largest pivot in
/// modulus counts as zero (a numerically singular matrix).
pub const ZERO_PIVOT_REL: f64 = 1e-13;

/// How many eigenvalues of a symmetric matrix are negative, zero (to
/// [`ZERO_PIVOT_REL`]) and positive.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Inertia {
    /// Negative eigenvalues.
    pub negative: usize,
    /// Numerically zero eigenvalues.
    pub zero: usize,
    /// Positive eigenvalues.
    pub positive: usize,
}

impl Inertia {
    /// Whether the matrix is positive definite.
    pub fn is_positive_definite(&self) -> bool {
        self.negative == 0 && self.zero == 0
    }
}

/// The inertia of the symmetric matrix `a` (its lower triangle is read; `what` names it
/// in errors): `A = P L B P^T L^T` with `B` block diagonal (1 x 1 and 2 x 2 blocks) has
/// the inertia of `B`.
///
/// # Errors
/// A non-square or non-finite matrix, or a failed symbolic analysis (out of memory).
pub fn inertia(a: SparseRef<'_>, what: &str) -> Result<Inertia> {
    let n = a.nrows();
    check_square_finite(a, n, what)?;
    let fail = |reason: String| Error::Factorization {
        what: format!("{what} (n = {n}, L B L^T for its inertia)"),
        reason,
    };
    let ordering = FillOrdering::of(a.symbolic())?;
    let symbolic = factorize_symbolic_cholesky(
        a.symbolic(),
        Side::Lower,
        symmetric_ordering(ordering.as_ref()),
        CholeskySymbolicParams {
            // Bunch-Kaufman pivoting exists only in the supernodal variant.
            supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
            supernodal_params: SymbolicSupernodalParams::default(),
            ..Default::default()
        },
    )
    .map_err(|e| fail(super::explain::generic(&e)))?;
    let SymbolicCholeskyRaw::Supernodal(supernodal) = symbolic.raw() else {
        return Err(fail("the symbolic analysis is not supernodal".into()));
    };
    let mut values = Vec::new();
    values.try_reserve_exact(symbolic.len_val()).map_err(|_| {
        fail(format!(
            "out of memory for {} entries of L",
            symbolic.len_val()
        ))
    })?;
    values.resize(symbolic.len_val(), 0.0f64);
    let mut subdiag = vec![0.0f64; n];
    let (mut fwd, mut inv) = (vec![0usize; n], vec![0usize; n]);
    let par = faer::get_global_parallelism();
    let mut mem = MemBuffer::try_new(
        symbolic.factorize_numeric_intranode_lblt_scratch::<f64>(par, Default::default()),
    )
    .map_err(|_| fail("out of memory for the factorization's workspace".into()))?;
    symbolic.factorize_numeric_intranode_lblt(
        &mut values,
        &mut subdiag,
        &mut fwd,
        &mut inv,
        a,
        Side::Lower,
        par,
        MemStack::new(&mut mem),
        Default::default(),
    );
    let perm = faer::perm::PermRef::new_checked(&fwd, &inv, n);
    let factor = SupernodalIntranodeLbltRef::new(supernodal, &values, &subdiag, perm);
    // the eigenvalues of every block of B
    let mut eig = Vec::with_capacity(n);
    for s in 0..supernodal.n_supernodes() {
        let node = factor.supernode(s);
        let b = node.val();
        let size = b.ncols();
        let mut k = 0;
        while k < size {
            let off = subdiag[node.start() + k];
            if off == 0.0 || k + 1 == size {
                eig.push(b[(k, k)]);
                k += 1;
            } else {
                let (d1, d2) = (b[(k, k)], b[(k + 1, k + 1)]);
                let (mid, rad) = (
                    0.5 * (d1 + d2),
                    (0.25 * (d1 - d2).powi(2) + off * off).sqrt(),
                );
                eig.push(mid - rad);
                eig.push(mid + rad);
                k += 2;
            }
        }
    }
    if eig.iter().any(|d| !d.is_finite()) {
        return Err(fail("a pivot is not finite".into()));
    }
    let big = eig.iter().fold(0.0f64, |m, d| m.max(d.abs()));
    let tiny = ZERO_PIVOT_REL * big;
    let mut out = Inertia {
        negative: 0,
        zero: 0,
        positive: 0,
    };
    for d in eig {
        if d.abs() <= tiny {
            out.zero += 1;
        } else if d < 0.0 {
            out.negative += 1;
        } else {
            out.positive += 1;
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::SparseMat;
    use faer::sparse::Triplet;

    /// A symmetric tridiagonal `tridiag(-1, d_i, -1)` of size `n`.
    fn tridiagonal(d: &[f64]) -> SparseMat {
        let n = d.len();
        let mut t = Vec::new();
        for (i, &di) in d.iter().enumerate() {
            t.push(Triplet::new(i, i, di));
            if i + 1 < n {
                t.push(Triplet::new(i + 1, i, -1.0));
                t.push(Triplet::new(i, i + 1, -1.0));
            }
        }
        SparseMat::try_new_from_triplets(n, n, &t).unwrap()
    }

    #[test]
    fn the_inertia_counts_the_eigenvalues_below_a_shift() {
        // tridiag(-1, 2, -1) of size n has eigenvalues 2 - 2 cos(k pi / (n + 1)): shifted
        // by s, exactly those below s are negative
        let n = 200;
        let exact: Vec<f64> = (1..=n)
            .map(|k| 2.0 - 2.0 * (k as f64 * std::f64::consts::PI / (n as f64 + 1.0)).cos())
            .collect();
        for s in [-0.5, 0.0137, 0.517, 1.03, 2.71, 3.93, 4.5] {
            let a = tridiagonal(&vec![2.0 - s; n]);
            let got = inertia(a.as_ref(), "A").unwrap();
            let below = exact.iter().filter(|&&l| l < s).count();
            assert_eq!(got.negative, below, "shift {s}");
            assert_eq!(got.positive, n - below, "shift {s}");
            assert_eq!(got.zero, 0);
            assert_eq!(got.is_positive_definite(), below == 0);
        }
    }

    #[test]
    fn a_matrix_needing_two_by_two_pivots_and_a_singular_one_are_counted() {
        // [[0, 1], [1, 0]] blocks: eigenvalues -1 and 1, no 1 x 1 pivot possible
        let n = 40;
        let mut t = Vec::new();
        for b in 0..n / 2 {
            t.push(Triplet::new(2 * b + 1, 2 * b, 1.0));
            t.push(Triplet::new(2 * b, 2 * b + 1, 1.0));
        }
        let a = SparseMat::try_new_from_triplets(n, n, &t).unwrap();
        let got = inertia(a.as_ref(), "A").unwrap();
        assert_eq!((got.negative, got.zero, got.positive), (n / 2, 0, n / 2));
        // the path Laplacian tridiag(-1, 2, -1) with free ends is singular (constants)
        let mut d = vec![2.0; 30];
        d[0] = 1.0;
        d[29] = 1.0;
        let got = inertia(tridiagonal(&d).as_ref(), "A").unwrap();
        assert_eq!((got.negative, got.zero, got.positive), (0, 1, 29));
    }
}
