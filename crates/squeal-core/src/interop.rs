//! Conversions between squeal's sparse storage ([`SparseMat`], faer's compressed columns)
//! and the sparse types a researcher's Rust code may already use:
//! `nalgebra_sparse::CscMatrix<f64>` (feature `nalgebra-sparse`) and `sprs::CsMat<f64>`
//! (feature `sprs`). Both directions keep every stored entry (explicit zeros included) and
//! its position; matrices coming in are checked (finite values, indices in range, sorted
//! and without duplicates after conversion) and a failure names the matrix.
//!
//! [`OperatorParts`] carries the six parts of a [`FrictionalOperator`] in either type, so a
//! whole operator moves across in one call: `X(mu) = X_c - mu F_X` for `X` in `M, C, K`.

use crate::{Error, FrictionalOperator, Result, SparseMat};
use faer::sparse::Triplet;

/// The parts of a [`FrictionalOperator`] in another sparse type `S`: the mu-independent
/// `M_c`, `C_c`, `K_c` and the friction parts `F_M`, `F_C`, `F_K` (dampings `None` when
/// the operator is undamped). Units as in [`FrictionalOperator`].
#[derive(Debug, Clone, PartialEq)]
pub struct OperatorParts<S> {
    /// `M_c` (kg).
    pub mc: S,
    /// `C_c` (N s/m).
    pub cc: Option<S>,
    /// `K_c` (N/m).
    pub kc: S,
    /// `F_M`.
    pub fm: S,
    /// `F_C`.
    pub fc: Option<S>,
    /// `F_K`.
    pub fk: S,
}

impl<S> OperatorParts<S> {
    /// Converts every part with `f`.
    fn map<T>(self, mut f: impl FnMut(&'static str, S) -> Result<T>) -> Result<OperatorParts<T>> {
        Ok(OperatorParts {
            mc: f("M_c", self.mc)?,
            cc: self.cc.map(|c| f("C_c", c)).transpose()?,
            kc: f("K_c", self.kc)?,
            fm: f("F_M", self.fm)?,
            fc: self.fc.map(|c| f("F_C", c)).transpose()?,
            fk: f("F_K", self.fk)?,
        })
    }
}

impl FrictionalOperator {
    /// The operator's parts, each converted by `f` (e.g. `interop::to_nalgebra`, `interop::to_sprs`).
    pub fn parts_as<S>(&self, f: impl Fn(&SparseMat) -> S) -> OperatorParts<S> {
        OperatorParts {
            mc: f(&self.mc),
            cc: self.cc.as_ref().map(&f),
            kc: f(&self.kc),
            fm: f(&self.fm),
            fc: self.fc.as_ref().map(&f),
            fk: f(&self.fk),
        }
    }

    /// An operator given directly by its parts in another sparse type, each converted by
    /// `f` (e.g. `interop::from_nalgebra`, `interop::from_sprs`); no index map and no friction load
    /// directions (as an operator read from files), real modes from the symmetric parts of
    /// `K_c` and `M_c` ([`crate::operator::RealModePair::Lazy`]). The parts must be square, of one
    /// size, with a damping friction part only beside a damping.
    pub fn from_parts_with<S>(
        parts: OperatorParts<S>,
        f: impl FnMut(&'static str, S) -> Result<SparseMat>,
    ) -> Result<Self> {
        let p = parts.map(f)?;
        let n = p.kc.nrows();
        let all = [
            Some(&p.mc),
            p.cc.as_ref(),
            Some(&p.kc),
            Some(&p.fm),
            p.fc.as_ref(),
            Some(&p.fk),
        ];
        for (name, m) in ["M_c", "C_c", "K_c", "F_M", "F_C", "F_K"].iter().zip(all) {
            if let Some(m) = m {
                if m.nrows() != n || m.ncols() != n {
                    return Err(Error::Invalid(format!(
                        "{name} is {} x {}, expected {n} x {n} (the size of K_c)",
                        m.nrows(),
                        m.ncols()
                    )));
                }
            }
        }
        if p.fc.is_some() && p.cc.is_none() {
            return Err(Error::Invalid(
                "F_C is given without C_c: an undamped operator has no damping friction part"
                    .into(),
            ));
        }
        Ok(FrictionalOperator {
            mc: p.mc,
            cc: p.cc,
            kc: p.kc,
            fm: p.fm,
            fc: p.fc,
            fk: p.fk,
            t: None,
            friction_loads: None,
            modal: crate::operator::RealModePair::lazy(
                None,
                None,
                "symmetric parts of K_c and M_c (an operator given by its parts)",
            ),
        })
    }
}

/// Builds a [`SparseMat`] from `(row, col, value)` entries, checking sizes and values;
/// entries at one position are summed (there are none in a valid compressed matrix).
#[cfg_attr(
    not(any(feature = "nalgebra-sparse", feature = "sprs")),
    allow(dead_code)
)]
fn from_entries(
    name: &str,
    nrows: usize,
    ncols: usize,
    entries: impl Iterator<Item = (usize, usize, f64)>,
) -> Result<SparseMat> {
    let mut triplets = Vec::new();
    for (i, j, v) in entries {
        if i >= nrows || j >= ncols {
            return Err(Error::Invalid(format!(
                "{name}: entry ({i}, {j}) outside its {nrows} x {ncols} shape"
            )));
        }
        if !v.is_finite() {
            return Err(Error::Invalid(format!(
                "{name}: entry ({i}, {j}) is {v}, expected a finite number"
            )));
        }
        triplets.push(Triplet::new(i, j, v));
    }
    SparseMat::try_new_from_triplets(nrows, ncols, &triplets)
        .map_err(|e| Error::Invalid(format!("{name}: {e:?}")))
}

/// The `(row, col, value)` entries of a [`SparseMat`], column by column.
#[cfg_attr(
    not(any(feature = "nalgebra-sparse", feature = "sprs")),
    allow(dead_code)
)]
fn entries(a: &SparseMat) -> impl Iterator<Item = (usize, usize, f64)> + '_ {
    let r = a.as_ref();
    (0..a.ncols()).flat_map(move |j| {
        r.row_idx_of_col(j)
            .zip(r.val_of_col(j).iter())
            .map(move |(i, &v)| (i, j, v))
    })
}

#[cfg(feature = "nalgebra-sparse")]
pub use self::nalgebra_impl::{from_nalgebra, to_nalgebra};

#[cfg(feature = "nalgebra-sparse")]
mod nalgebra_impl {
    use super::*;
    use nalgebra_sparse::{CooMatrix, CscMatrix};

    /// A [`SparseMat`] as an `nalgebra_sparse::CscMatrix<f64>` (the same entries).
    pub fn to_nalgebra(a: &SparseMat) -> CscMatrix<f64> {
        let mut coo = CooMatrix::new(a.nrows(), a.ncols());
        for (i, j, v) in entries(a) {
            coo.push(i, j, v);
        }
        CscMatrix::from(&coo)
    }

    /// An `nalgebra_sparse::CscMatrix<f64>` as a [`SparseMat`]; `name` is used in errors
    /// (a non-finite entry).
    pub fn from_nalgebra(name: &str, a: &CscMatrix<f64>) -> Result<SparseMat> {
        from_entries(
            name,
            a.nrows(),
            a.ncols(),
            a.triplet_iter().map(|(i, j, &v)| (i, j, v)),
        )
    }
}

#[cfg(feature = "sprs")]
pub use self::sprs_impl::{from_sprs, to_sprs};

#[cfg(feature = "sprs")]
mod sprs_impl {
    use super::*;
    use sprs::{CsMat, TriMat};

    /// A [`SparseMat`] as a `sprs::CsMat<f64>` in compressed-column storage.
    pub fn to_sprs(a: &SparseMat) -> CsMat<f64> {
        let mut tri = TriMat::new((a.nrows(), a.ncols()));
        for (i, j, v) in entries(a) {
            tri.add_triplet(i, j, v);
        }
        tri.to_csc()
    }

    /// A `sprs::CsMat<f64>` (row or column storage) as a [`SparseMat`]; `name` is used in
    /// errors (a non-finite entry).
    pub fn from_sprs(name: &str, a: &CsMat<f64>) -> Result<SparseMat> {
        let (nrows, ncols) = a.shape();
        from_entries(name, nrows, ncols, a.iter().map(|(&v, (i, j))| (i, j, v)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> SparseMat {
        from_entries(
            "A",
            3,
            4,
            [
                (0, 0, 2.0),
                (2, 0, -1.5),
                (1, 2, 0.0),
                (0, 3, 7.25),
                (2, 3, 1e-300),
            ]
            .into_iter(),
        )
        .unwrap()
    }

    fn same(a: &SparseMat, b: &SparseMat) -> bool {
        a.nrows() == b.nrows()
            && a.ncols() == b.ncols()
            && entries(a).collect::<Vec<_>>() == entries(b).collect::<Vec<_>>()
    }

    #[test]
    fn entries_outside_the_shape_or_not_finite_are_named() {
        let e = from_entries("K_c", 2, 2, [(2, 0, 1.0)].into_iter()).unwrap_err();
        assert!(
            e.to_string().contains("K_c") && e.to_string().contains("(2, 0)"),
            "{e}"
        );
        let e = from_entries("M_c", 2, 2, [(0, 1, f64::NAN)].into_iter()).unwrap_err();
        assert!(
            e.to_string().contains("M_c") && e.to_string().contains("finite"),
            "{e}"
        );
    }

    #[cfg(feature = "nalgebra-sparse")]
    #[test]
    fn nalgebra_round_trip_keeps_every_entry() {
        let a = sample();
        let n = to_nalgebra(&a);
        assert_eq!(n.nnz(), 5);
        assert_eq!(n.get_entry(2, 0).unwrap().into_value(), -1.5);
        assert!(same(&a, &from_nalgebra("A", &n).unwrap()));
    }

    #[cfg(feature = "sprs")]
    #[test]
    fn sprs_round_trip_keeps_every_entry_from_either_storage() {
        let a = sample();
        let s = to_sprs(&a);
        assert!(s.is_csc());
        assert_eq!(s.get(0, 3), Some(&7.25));
        assert!(same(&a, &from_sprs("A", &s).unwrap()));
        assert!(same(&a, &from_sprs("A", &s.to_csr()).unwrap()));
    }

    #[test]
    fn an_operator_crosses_as_parts_and_mismatched_parts_are_refused() {
        let k = from_entries(
            "K",
            2,
            2,
            [(0, 0, 4.0), (1, 1, 5.0), (0, 1, -1.0), (1, 0, -1.0)].into_iter(),
        )
        .unwrap();
        let m = from_entries("M", 2, 2, [(0, 0, 1.0), (1, 1, 2.0)].into_iter()).unwrap();
        let fk = from_entries("F", 2, 2, [(0, 1, 0.5)].into_iter()).unwrap();
        let zero = from_entries("Z", 2, 2, std::iter::empty()).unwrap();
        let op = FrictionalOperator::from_parts_with(
            OperatorParts {
                mc: m.clone(),
                cc: None,
                kc: k.clone(),
                fm: zero.clone(),
                fc: None,
                fk: fk.clone(),
            },
            |_, s| Ok(s),
        )
        .unwrap();
        let back =
            FrictionalOperator::from_parts_with(op.parts_as(Clone::clone), |_, s| Ok(s)).unwrap();
        assert!(same(&back.kc, &k) && same(&back.mc, &m) && same(&back.fk, &fk));
        assert!(back.cc.is_none() && back.t.is_none());
        let wide = sample();
        let e = FrictionalOperator::from_parts_with(
            OperatorParts {
                mc: m.clone(),
                cc: None,
                kc: k.clone(),
                fm: zero.clone(),
                fc: None,
                fk: wide,
            },
            |_, s| Ok(s),
        )
        .unwrap_err();
        assert!(e.to_string().contains("F_K is 3 x 4"), "{e}");
        let e = FrictionalOperator::from_parts_with(
            OperatorParts {
                mc: m,
                cc: None,
                kc: k,
                fm: zero.clone(),
                fc: Some(zero),
                fk,
            },
            |_, s| Ok(s),
        )
        .unwrap_err();
        assert!(e.to_string().contains("F_C"), "{e}");
    }
}
