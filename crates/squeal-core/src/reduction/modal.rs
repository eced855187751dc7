//! The real-mode pair of an operator ([`real_mode_pair`]): the symmetric positive definite
//! `(K_s, M_s)` its bases and its tracking draw real modes and static responses from.
//!
//! An operator assembled from a scene is its own pair (`K_c`, `M_c`: symmetric, and
//! positive definite once the contact set's ties restrain the rigid-body motions). An
//! operator read from files names the pair it starts from (`[modal]` of an
//! `operator.toml`: the undamped, non-rotating, friction-free system, as the field
//! does), or starts from the symmetric parts of its own `K_c` and `M_c`. Circulatory
//! terms, a gyroscopic stiffness or a negative geometric stiffness can make that
//! symmetric part indefinite, and then no shift below the band makes `K - sigma M`
//! definite and no static solve with it exists. The pair is then shifted,
//! `K_s = sym(K) + s M_s`, by a shift found from factorizations rather than assumed: a
//! Cholesky factorization that succeeds proves definiteness, the inertia of a
//! Bunch-Kaufman `L B L^T` counts the negative eigenvalues, and the lowest eigenvalue is
//! bracketed by Cholesky factorizations of `sym(K) + g M_s` at growing `g` (a factor 4
//! apart, then bisected). The shift `s = 2 g_hi` (`g_hi` the smallest `g` found definite)
//! leaves the lowest eigenvalue of the shifted pair between `g_hi` and about `2 g_hi`.
//! Shifting leaves the mode shapes as they are: the pair's real modes are those of
//! `(K_s, M_s)` with `omega^2 = omega_s^2 - s`, and a real-mode basis asks for the band
//! `omega_s^2 <= omega_cut^2 + s` ([`PairRef::shifted_cutoff_hz`]).

use crate::linalg::{add_scaled, inertia, norm1, Cholesky};
use crate::operator::{FrictionalOperator, ModalPair, RealModePair, RealModes};
use crate::{Error, Result, SparseMat, SparseRef};
use std::borrow::Cow;
use std::sync::Arc;

/// Growth of the shift between two definiteness tests of the bracketing.
const BRACKET_GROWTH: f64 = 4.0;
/// Bisections of the bracket (each halves its logarithmic width).
const BISECTIONS: usize = 3;
/// First trial shift relative to `||K||_1 / ||M||_1`.
const FIRST_SHIFT_REL: f64 = 1e-9;

/// The real-mode pair of an operator, borrowed from it ([`real_mode_pair`]).
#[derive(Debug, Clone)]
pub struct PairRef<'a> {
    /// `K_s` (N/m), symmetric positive definite (both triangles stored).
    pub k: SparseRef<'a>,
    /// `M_s` (kg), symmetric positive definite.
    pub m: SparseRef<'a>,
    /// The shift (rad/s)^2 in `K_s` (0: none).
    pub shift: f64,
    /// Where the pair comes from and how it was made definite.
    pub source: Cow<'a, str>,
    /// Whether it is the operator's own `(K_c, M_c)` (a scene's operator): then the
    /// operator's stiffness is its static stiffness too.
    pub own: bool,
}

impl PairRef<'_> {
    /// The cutoff of the shifted pair (Hz) of a real-mode band up to `cutoff_hz`:
    /// `sqrt((2 pi f)^2 + shift) / (2 pi)`.
    pub fn shifted_cutoff_hz(&self, cutoff_hz: f64) -> f64 {
        let w = 2.0 * std::f64::consts::PI;
        ((w * cutoff_hz).powi(2) + self.shift).max(0.0).sqrt() / w
    }

    /// Real modes of the shifted pair brought back to the pair's own eigenvalues,
    /// `omega^2 = omega_s^2 - shift` (the frequency of a negative `omega^2` is 0), with a
    /// note in their report; unchanged when there is no shift.
    pub fn unshift(&self, mut modes: RealModes) -> RealModes {
        if self.shift == 0.0 {
            return modes;
        }
        let w = 2.0 * std::f64::consts::PI;
        for (o2, f) in modes.omega2.iter_mut().zip(modes.freq_hz.iter_mut()) {
            *o2 -= self.shift;
            *f = o2.max(0.0).sqrt() / w;
        }
        let negative = modes.omega2.iter().filter(|&&o| o < 0.0).count();
        modes.info.notes.push(format!(
            "real modes of the pair shifted by {:.4e} (rad/s)^2 ({}), {negative} of them with \
             a negative omega^2 (frequency 0 Hz)",
            self.shift, self.source
        ));
        modes
    }
}

/// The real-mode pair of `op` (module docs), built on first use and kept with the
/// operator (its clones share it).
///
/// # Errors
/// A mass that is not positive definite, a stiffness no shift up to `1e3 ||K|| / ||M||`
/// makes definite, or a failed factorization (the message names the pair's source).
pub fn real_mode_pair(op: &FrictionalOperator) -> Result<PairRef<'_>> {
    match &op.modal {
        RealModePair::Own => Ok(PairRef {
            k: op.kc.as_ref(),
            m: op.mc.as_ref(),
            shift: 0.0,
            source: Cow::Borrowed("K_c and M_c of the contact set"),
            own: true,
        }),
        RealModePair::Lazy(lazy) => {
            let built = lazy.built.get_or_init(|| {
                build(
                    lazy.k.as_ref().unwrap_or(&op.kc),
                    lazy.m.as_ref().unwrap_or(&op.mc),
                    &lazy.source,
                )
                .map(Arc::new)
                .map_err(|e| e.to_string())
            });
            match built {
                Ok(p) => Ok(PairRef {
                    k: p.k.as_ref(),
                    m: p.m.as_ref(),
                    shift: p.shift,
                    source: Cow::Borrowed(&p.source),
                    own: false,
                }),
                Err(e) => Err(Error::Invalid(format!(
                    "the real-mode pair ({}): {e}",
                    lazy.source
                ))),
            }
        }
    }
}

/// `(A + A^T) / 2`, both triangles stored.
pub fn symmetric_part(a: SparseRef<'_>) -> Result<SparseMat> {
    let mut t = Vec::with_capacity(a.compute_nnz());
    for j in 0..a.ncols() {
        for (i, v) in a.row_idx_of_col(j).zip(a.val_of_col(j)) {
            t.push(faer::sparse::Triplet::new(j, i, *v));
        }
    }
    let at = SparseMat::try_new_from_triplets(a.ncols(), a.nrows(), &t)
        .map_err(|e| Error::Invalid(format!("transpose: {e:?}")))?;
    add_scaled(a, 0.5, at.as_ref(), 0.5)
}

/// Whether `sym(K) + g M` is positive definite (its Cholesky factorization succeeds).
fn definite(k: SparseRef<'_>, m: SparseRef<'_>, g: f64) -> Result<bool> {
    let a = add_scaled(k, 1.0, m, g)?;
    Ok(Cholesky::new(a.as_ref(), "K_s").is_ok())
}

/// The pair of `k` and `m` (module docs).
fn build(k: &SparseMat, m: &SparseMat, source: &str) -> Result<ModalPair> {
    let m = symmetric_part(m.as_ref())?;
    let k = symmetric_part(k.as_ref())?;
    Cholesky::new(m.as_ref(), "M_s").map_err(|_| {
        Error::Invalid(
            "the mass is not positive definite (its symmetric part's Cholesky factorization \
             fails): real modes need a positive definite mass"
                .into(),
        )
    })?;
    if definite(k.as_ref(), m.as_ref(), 0.0)? {
        return Ok(ModalPair {
            k,
            m,
            shift: 0.0,
            source: format!("{source}; positive definite as it is"),
        });
    }
    let negative = match inertia(k.as_ref(), "the pair's stiffness") {
        Ok(i) => format!(
            "{} negative and {} zero eigenvalue{}",
            i.negative,
            i.zero,
            if i.zero == 1 { "" } else { "s" }
        ),
        Err(_) => "an inertia its L B L^T could not count (a zero pivot)".into(),
    };
    let scale = norm1(k.as_ref()) / norm1(m.as_ref());
    if !(scale.is_finite() && scale > 0.0) {
        return Err(Error::Invalid(format!(
            "the stiffness is zero or not finite (||K||_1 / ||M||_1 = {scale:e})"
        )));
    }
    // bracket the lowest eigenvalue: sym(K) + g M indefinite at g_lo, definite at g_hi
    let (mut g_lo, mut g_hi) = (0.0, FIRST_SHIFT_REL * scale);
    while !definite(k.as_ref(), m.as_ref(), g_hi)? {
        g_lo = g_hi;
        g_hi *= BRACKET_GROWTH;
        if g_hi > 1e3 * scale {
            return Err(Error::Invalid(format!(
                "its symmetric stiffness has {negative}, and no shift up to {g_hi:.3e} (rad/s)^2 \
                 (1e3 ||K||_1 / ||M||_1) makes it positive definite"
            )));
        }
    }
    for _ in 0..BISECTIONS {
        let g = if g_lo > 0.0 {
            (g_lo * g_hi).sqrt()
        } else {
            0.5 * g_hi
        };
        if definite(k.as_ref(), m.as_ref(), g)? {
            g_hi = g;
        } else {
            g_lo = g;
        }
    }
    let shift = 2.0 * g_hi;
    let k = add_scaled(k.as_ref(), 1.0, m.as_ref(), shift)?;
    Ok(ModalPair {
        k,
        m,
        shift,
        source: format!(
            "{source}; its symmetric stiffness has {negative} (inertia of L B L^T), the lowest \
             eigenvalue in [{:.3e}, {:.3e}] (rad/s)^2 (Cholesky factorizations of K + g M): \
             made positive definite by the shift {shift:.3e} (rad/s)^2",
            -g_hi, -g_lo
        ),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::sparse::Triplet;

    /// `tridiag(-1, d, -1)` of size `n` with `c` added above the diagonal on every even
    /// row: a one-sided (circulatory) coupling, which moves the symmetric part's
    /// off-diagonal by `c / 2`.
    fn chain(n: usize, d: f64, c: f64) -> SparseMat {
        let mut t = Vec::new();
        for i in 0..n {
            t.push(Triplet::new(i, i, d));
            if i + 1 < n {
                t.push(Triplet::new(i + 1, i, -1.0));
                t.push(Triplet::new(
                    i,
                    i + 1,
                    -1.0 + if i % 2 == 0 { c } else { 0.0 },
                ));
            }
        }
        SparseMat::try_new_from_triplets(n, n, &t).unwrap()
    }

    fn identity(n: usize) -> SparseMat {
        let t: Vec<_> = (0..n).map(|i| Triplet::new(i, i, 1.0)).collect();
        SparseMat::try_new_from_triplets(n, n, &t).unwrap()
    }

    /// The smallest eigenvalue of a small symmetric matrix, densely.
    fn lowest(a: &SparseMat) -> f64 {
        let d = a.as_ref().to_dense();
        d.self_adjoint_eigenvalues(faer::Side::Lower)
            .unwrap()
            .into_iter()
            .fold(f64::INFINITY, f64::min)
    }

    #[test]
    fn a_definite_pair_is_kept_and_an_indefinite_one_is_shifted_just_enough() {
        let n = 60;
        let m = identity(n);
        // definite: no shift, and the pair is the symmetric part
        let k = chain(n, 2.5, 0.2);
        let p = build(&k, &m, "test").unwrap();
        assert_eq!(p.shift, 0.0);
        let sym = symmetric_part(k.as_ref()).unwrap();
        assert!((lowest(&p.k) - lowest(&sym)).abs() < 1e-12);
        // a large one-sided coupling makes the symmetric part indefinite
        let k = chain(n, 2.5, 10.0);
        let sym = symmetric_part(k.as_ref()).unwrap();
        let l = lowest(&sym);
        assert!(
            l < 0.0,
            "the test needs an indefinite symmetric part, got {l}"
        );
        let p = build(&k, &m, "test").unwrap();
        assert!(p.shift > -l, "shift {} below -lowest {}", p.shift, -l);
        assert!(
            p.shift < -4.0 * l,
            "shift {} far above -lowest {}",
            p.shift,
            -l
        );
        let shifted = lowest(&p.k);
        assert!(shifted > 0.0 && (shifted - (l + p.shift)).abs() < 1e-9 * p.shift);
        assert!(p.source.contains("negative"), "{}", p.source);
    }

    #[test]
    fn an_operator_keeps_its_pair_and_the_cutoff_is_mapped_through_the_shift() {
        let n = 30;
        let op = FrictionalOperator {
            mc: identity(n),
            cc: None,
            kc: chain(n, 2.5, 10.0),
            fm: SparseMat::try_new_from_triplets(n, n, &[]).unwrap(),
            fc: None,
            fk: SparseMat::try_new_from_triplets(n, n, &[]).unwrap(),
            t: None,
            friction_loads: None,
            modal: RealModePair::lazy(None, None, "symmetric parts"),
        };
        let p = real_mode_pair(&op).unwrap();
        assert!(!p.own && p.shift > 0.0);
        let shift = p.shift;
        // built once: a clone shares it
        let clone = op.clone();
        assert_eq!(real_mode_pair(&clone).unwrap().shift, shift);
        let w = 2.0 * std::f64::consts::PI;
        let f = p.shifted_cutoff_hz(10.0);
        assert!(((w * f).powi(2) - (w * 10.0).powi(2) - shift).abs() < 1e-9 * shift);
        // the own pair of a scene's operator
        let own = FrictionalOperator {
            modal: RealModePair::Own,
            ..op
        };
        let p = real_mode_pair(&own).unwrap();
        assert!(p.own && p.shift == 0.0);
        assert_eq!(p.shifted_cutoff_hz(10.0), 10.0);
    }
}
