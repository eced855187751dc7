//! The MAC between a real and a complex mode ([`mac_real_complex`]).

use crate::linalg::{dot, spmv};
use crate::{c64, SparseRef};

/// MAC between a real mode `phi` and a complex mode `psi` in the `M` inner product,
/// Hermitian form:
/// `|phi^T M conj(psi)|^2 / ((phi^T M phi) (psi^H M psi))`, in [0, 1], independent of
/// the phase of `psi`.
pub fn mac_real_complex(m: SparseRef<'_>, phi: &[f64], psi: &[c64]) -> f64 {
    let n = phi.len();
    let mut mphi = vec![0.0; n];
    spmv(m, phi, &mut mphi);
    let re: Vec<f64> = psi.iter().map(|z| z.re).collect();
    let im: Vec<f64> = psi.iter().map(|z| z.im).collect();
    let (a, b) = (dot(&mphi, &re), dot(&mphi, &im));
    let pp = dot(&mphi, phi);
    let mut t = vec![0.0; n];
    spmv(m, &re, &mut t);
    let mut qq = dot(&t, &re);
    spmv(m, &im, &mut t);
    qq += dot(&t, &im);
    let den = pp * qq;
    if den > 0.0 {
        (a * a + b * b) / den
    } else {
        0.0
    }
}
