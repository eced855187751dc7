//! The synthesized modes of one contact set at one mu ([`Synthesized`],
//! [`FreeInterface::synthesize`]).

use super::{par, FreeInterface};
use squeal_core::faer::linalg::matmul::matmul;
use squeal_core::faer::{Accum, Mat};
use squeal_core::{c64, Error, Result};

/// The synthesized modes of one contact set at one mu.
#[derive(Debug, Clone)]
pub struct Synthesized {
    /// Eigenvalues `s = -lambda^2` ((rad/s)^2), one per free-interface mode.
    pub s: Vec<c64>,
    /// Modal coordinates `eta` (`m x m`, one column per `s`).
    pub eta: Mat<c64>,
    /// Normal reactions `r = -S^-1 P eta` of the active pairs (`nA x m`, N).
    pub r: Mat<c64>,
    /// Region indices of the active pairs (rows of `r`).
    pub active: Vec<usize>,
    /// Friction coefficient.
    pub mu: f64,
}

impl Synthesized {
    /// `lambda = i sqrt(s)` on the branch with `Im(lambda) >= 0`; its frequency (Hz) is
    /// `Im(lambda) / 2 pi`.
    pub fn lambda(&self, k: usize) -> c64 {
        let root = self.s[k].sqrt();
        c64::new(-root.im, root.re)
    }

    /// Frequency of synthesized mode `k` (Hz).
    pub fn freq_hz(&self, k: usize) -> f64 {
        self.lambda(k).im / (2.0 * std::f64::consts::PI)
    }
}

impl FreeInterface {
    /// The synthesized modes of the contact set `active` (region indices) at `mu`.
    pub fn synthesize(&self, active: &[usize], mu: f64) -> Result<Synthesized> {
        if !mu.is_finite() {
            return Err(Error::param("mu", format!("must be finite, got {mu}")));
        }
        if let Some(&i) = active.iter().find(|&&i| i >= self.pairs.len()) {
            return Err(Error::Invalid(format!(
                "free-interface synthesis: pair index {i} beyond the {} candidates",
                self.pairs.len()
            )));
        }
        let na = active.len();
        let nm = self.modes();
        let p = Mat::from_fn(na, nm, |i, c| self.pn_phi[(active[i], c)]);
        let q = Mat::from_fn(na, nm, |i, c| {
            self.pn_phi[(active[i], c)] + mu * self.pt_phi[(active[i], c)]
        });
        let mut a = Mat::from_fn(nm, nm, |i, j| if i == j { self.omega2[i] } else { 0.0 });
        let mut x = Mat::<f64>::zeros(na, nm);
        if na > 0 {
            let s = Mat::from_fn(na, na, |i, j| {
                self.wn[(active[i], active[j])] + mu * self.wt[(active[i], active[j])]
            });
            let lu = s.partial_piv_lu();
            let u = lu.U();
            let (mut pmin, mut pmax) = (f64::INFINITY, 0.0f64);
            for i in 0..na {
                pmin = pmin.min(u[(i, i)].abs());
                pmax = pmax.max(u[(i, i)].abs());
            }
            if pmin.is_nan() || pmin <= 1e-13 * pmax {
                return Err(Error::Factorization {
                    what: format!("residual contact flexibility S ({na} pairs)"),
                    reason: format!(
                        "numerically singular (pivot ratio {:.2e}): a pair repeated, or \
                         the free-interface modes span the contact motions exactly",
                        pmin / pmax
                    ),
                });
            }
            x = squeal_core::faer::linalg::solvers::Solve::solve(&lu, &p);
            matmul(
                a.as_mut(),
                Accum::Add,
                q.transpose(),
                x.as_ref(),
                1.0,
                par(),
            );
        }
        let eig =
            squeal_core::faer::linalg::solvers::Eigen::new_from_real(a.as_ref()).map_err(|e| {
                Error::NotConverged {
                    method: "free-interface synthesis (dense eigen)".into(),
                    iterations: 0,
                    detail: format!("{e:?}"),
                }
            })?;
        let s: Vec<c64> = (0..nm).map(|k| eig.S()[k]).collect();
        let eta = eig.U().to_owned();
        let mut r = Mat::<c64>::zeros(na, nm);
        for k in 0..nm {
            for i in 0..na {
                let mut acc = c64::new(0.0, 0.0);
                for c in 0..nm {
                    acc += eta[(c, k)] * x[(i, c)];
                }
                r[(i, k)] = -acc;
            }
        }
        Ok(Synthesized {
            s,
            eta,
            r,
            active: active.to_vec(),
            mu,
        })
    }
}
