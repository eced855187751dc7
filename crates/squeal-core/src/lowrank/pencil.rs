//! The symbolic analysis of the symmetric pencil `S(s) = K_c - s M_c`, shared by every
//! shift ([`SymmetricPencil`]).

use crate::operator::FrictionalOperator;
use crate::ordering::{symmetric_ordering, FillOrdering};
use crate::{Error, Result, SparseMat, SparseRef};
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, SymbolicCholesky,
};
use faer::sparse::linalg::{SupernodalThreshold, SymbolicSupernodalParams};
use faer::sparse::{SymbolicSparseColMat, Triplet};
use faer::Side;

/// Relative asymmetry of `K_c` or `M_c` above which the low-rank path refuses the operator
/// (its symmetric factorization would solve the wrong matrix).
pub const MAX_ASYMMETRY: f64 = 1e-10;

/// Symbolic analysis of `S(s) = K_c - s M_c`, valid for every shift `s`: the lower
/// triangle of the union pattern of `K_c`, `M_c` and the diagonal, its fill-reducing
/// ordering ([`crate::ordering`]) and
/// the supernodal structure of the factor. `K_c` and `M_c` are used symmetrized,
/// `(X + X^T) / 2`; their measured asymmetry is kept in [`asymmetry`](Self::asymmetry).
#[derive(Debug)]
pub struct SymmetricPencil {
    pub(super) pattern: SymbolicSparseColMat<usize>,
    /// (slot in `pattern`, weight) of every stored entry of `K_c`, in storage order.
    k_slot: Vec<(usize, f64)>,
    /// Same for `M_c`.
    m_slot: Vec<(usize, f64)>,
    pub(super) chol: SymbolicCholesky<usize>,
    asymmetry: f64,
}

impl SymmetricPencil {
    /// Analyses the pencil `(K_c, M_c)` of `op`.
    pub fn new(op: &FrictionalOperator) -> Result<Self> {
        let n = op.dim();
        let (kc, mc) = (op.kc.as_ref(), op.mc.as_ref());
        let mut trip = Vec::with_capacity(kc.compute_nnz() + mc.compute_nnz() + n);
        for a in [kc, mc] {
            for j in 0..n {
                trip.extend(
                    a.row_idx_of_col(j)
                        .map(|i| Triplet::new(i.max(j), i.min(j), 1.0)),
                );
            }
        }
        trip.extend((0..n).map(|i| Triplet::new(i, i, 1.0)));
        let pattern = SparseMat::try_new_from_triplets(n, n, &trip)
            .map_err(|e| Error::Invalid(format!("SymmetricPencil: {e:?}")))?
            .into_parts()
            .0;
        drop(trip);
        let pat = pattern.as_ref();
        let slots = |a: SparseRef<'_>| -> Vec<(usize, f64)> {
            let mut out = Vec::with_capacity(a.compute_nnz());
            for j in 0..n {
                for i in a.row_idx_of_col(j) {
                    let (r, c) = (i.max(j), i.min(j));
                    let rows = pat.row_idx_of_col_raw(c);
                    let p = rows
                        .binary_search(&r)
                        .expect("SymmetricPencil: entry missing from its own pattern");
                    let w = if i == j { 1.0 } else { 0.5 };
                    out.push((pat.col_range(c).start + p, w));
                }
            }
            out
        };
        let (k_slot, m_slot) = (slots(kc), slots(mc));
        // Asymmetry: lower and (transposed) upper parts accumulated apart.
        let mut asymmetry = 0.0f64;
        for (a, slot) in [(kc, &k_slot), (mc, &m_slot)] {
            let nnz = pat.compute_nnz();
            let (mut lo, mut up) = (vec![0.0; nnz], vec![0.0; nnz]);
            let mut q = 0;
            for j in 0..n {
                for (i, v) in a.row_idx_of_col(j).zip(a.val_of_col(j)) {
                    let p = slot[q].0;
                    q += 1;
                    if i >= j {
                        lo[p] += v;
                    }
                    if i <= j {
                        up[p] += v;
                    }
                }
            }
            let diff = lo
                .iter()
                .zip(&up)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            let big = lo.iter().map(|v| v.abs()).fold(0.0, f64::max);
            if big > 0.0 {
                asymmetry = asymmetry.max(diff / big);
            }
        }
        let ordering = FillOrdering::of(pat)?;
        let chol = factorize_symbolic_cholesky(
            pat,
            Side::Lower,
            symmetric_ordering(ordering.as_ref()),
            CholeskySymbolicParams {
                // Bunch-Kaufman pivoting exists only in the supernodal variant.
                supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
                supernodal_params: SymbolicSupernodalParams::default(),
                ..Default::default()
            },
        )
        .map_err(|e| Error::Factorization {
            what: format!("K_c - s M_c (symbolic, n = {n})"),
            reason: crate::linalg::explain::generic(&e),
        })?;
        Ok(Self {
            pattern,
            k_slot,
            m_slot,
            chol,
            asymmetry,
        })
    }

    /// Size of the pencil.
    pub fn dim(&self) -> usize {
        self.pattern.nrows()
    }

    /// Stored entries of the factor `L` (supernodal blocks included).
    pub fn factor_entries(&self) -> usize {
        self.chol.len_val()
    }

    /// Largest relative asymmetry `max |X - X^T| / max |X|` of `K_c` and `M_c`.
    pub fn asymmetry(&self) -> f64 {
        self.asymmetry
    }

    /// Lower-triangle values of `K_c - s M_c` (symmetrized) on the pattern.
    pub(super) fn assemble(&self, op: &FrictionalOperator, s: f64) -> Result<Vec<f64>> {
        let n = self.dim();
        if op.dim() != n
            || op.kc.compute_nnz() != self.k_slot.len()
            || op.mc.compute_nnz() != self.m_slot.len()
        {
            return Err(Error::Invalid(
                "SymmetricPencil: analysis built for another operator".into(),
            ));
        }
        let mut vals = vec![0.0; self.pattern.compute_nnz()];
        for (a, slot, scale) in [(&op.kc, &self.k_slot, 1.0), (&op.mc, &self.m_slot, -s)] {
            let a = a.as_ref();
            let mut q = 0;
            for j in 0..n {
                for v in a.val_of_col(j) {
                    let (p, w) = slot[q];
                    vals[p] += scale * w * v;
                    q += 1;
                }
            }
        }
        Ok(vals)
    }
}
