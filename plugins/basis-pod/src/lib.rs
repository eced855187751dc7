//! # squeal-basis-pod
//!
//! Parametric model reduction by proper orthogonal decomposition (POD), registered as
//! `"pod"` (Graebner, Mehrmann, Quraishi, Schroeder and von Wagner, "Numerical methods for
//! parametric model reduction in the simulation of disk brake squeal", ZAMM 96(12), 2016):
//!
//! 1. solve the FULL frictional QEP at a few snapshot friction coefficients
//!    `mu_1 .. mu_k` (the request's `modal` solver, a sparse full-order backend such as
//!    `arpack` or `krylov`, through [`EigenSolver::solve_frictional`]) and collect the
//!    complex eigenvectors `X_s` of the band, widened by `band_factor` on both sides so
//!    that modes entering the band between snapshots are represented;
//! 2. stack their real and imaginary parts, `S = [Re X_1, Im X_1, .., Re X_k, Im X_k]`
//!    (`n_c x 2 sum k_s`; every mode has unit 2-norm);
//! 3. thin SVD `S = U Sigma W^T` (faer), keep the left singular vectors with
//!    `sigma_i > svd_tol sigma_1`, at most `max_size` of them;
//! 4. `M_c`-orthonormalize them with the shared rank cut of [`squeal_core::reduction`].
//!
//! The result is one real basis for every mu of the contact set
//! ([`ReductionBasis::depends_on_mu`] is `false`): at a snapshot mu it contains the full
//! modes up to the SVD cut, so the reduced solve reproduces them; between snapshots it
//! interpolates. Like every basis it depends on the contact set (a new active set means a
//! new operator and a new basis).
//!
//! ## Cost
//! Building costs `k` full-order complex solves (reported in [`Basis::time_s`] and, per
//! snapshot, in the notes) and one thin SVD; each evaluation afterwards is a projection
//! (once) and a small dense solve per mu ([`squeal_core::ReducedSolve`] reports
//! `basis_time_s` apart from `projection_time_s`, `solve_time_s` and
//! `expansion_time_s`).
//!
//! ## Parameters
//!
//! - `snapshots` (default `0,0.4,0.8`): the snapshot friction coefficients, a list (or a
//!   single number).
//! - `snapshot_count` and `snapshot_range` (`lo,hi`): instead of `snapshots`,
//!   `snapshot_count` values evenly spaced over `[lo, hi]`, both ends included.
//! - `svd_tol` (default [`DEFAULT_SVD_TOL`]): relative singular value cut, in (0, 1).
//! - `max_size` (default 0, no cap): largest number of POD vectors kept.
//! - `band_factor` (default [`DEFAULT_BAND_FACTOR`], `>= 1`): snapshot modes are
//!   collected in `[fmin / band_factor, fmax * band_factor]`.
//! - `rank_tol` (default [`DEFAULT_RANK_TOL`]): relative rank cut of the
//!   orthonormalization.
//!
//! [`EigenSolver::solve_frictional`]: squeal_core::EigenSolver::solve_frictional

use squeal_core::faer::Mat;
use squeal_core::params::fraction;
use squeal_core::reduction::{m_orthonormalize, DEFAULT_RANK_TOL};
use squeal_core::{
    Basis, BasisRequest, EigenParams, Error, ParamValue, Params, ReductionBasis, Registry, Result,
};
use std::time::Instant;

/// Name under which the basis is registered.
pub const NAME: &str = "pod";

/// One-line description shown by the registry.
pub const DESCRIPTION: &str = "proper orthogonal decomposition of full-order complex modes \
                               at snapshot mu values (fixed in mu); options snapshots | \
                               snapshot_count + snapshot_range, svd_tol, max_size, \
                               band_factor, rank_tol";

/// Default snapshot friction coefficients.
pub const DEFAULT_SNAPSHOTS: [f64; 3] = [0.0, 0.4, 0.8];
/// Default of the `svd_tol` parameter.
pub const DEFAULT_SVD_TOL: f64 = 1e-8;
/// Default of the `band_factor` parameter.
pub const DEFAULT_BAND_FACTOR: f64 = 1.1;

/// Registers the `"pod"` basis.
pub fn register(reg: &mut Registry) {
    reg.bases.register(NAME, DESCRIPTION, |params: &Params| {
        let basis: Box<dyn ReductionBasis> = Box::new(PodBasis::from_params(params)?);
        Ok(basis)
    });
}

/// The `"pod"` basis.
#[derive(Debug, Clone, PartialEq)]
pub struct PodBasis {
    /// Snapshot friction coefficients.
    pub snapshots: Vec<f64>,
    /// Relative singular value cut.
    pub svd_tol: f64,
    /// Largest number of POD vectors; `None`: no cap.
    pub max_size: Option<usize>,
    /// Widening of the band for the snapshot solves (`>= 1`).
    pub band_factor: f64,
    /// Relative rank cut of the orthonormalization.
    pub rank_tol: f64,
}

impl PodBasis {
    /// Checks and stores the parameters.
    pub fn new(
        snapshots: Vec<f64>,
        svd_tol: f64,
        max_size: Option<usize>,
        band_factor: f64,
        rank_tol: f64,
    ) -> Result<Self> {
        if snapshots.is_empty() {
            return Err(Error::param("snapshots", "needs at least one value of mu"));
        }
        if let Some(bad) = snapshots.iter().find(|m| !m.is_finite()) {
            return Err(Error::param(
                "snapshots",
                format!("friction coefficients must be finite, got {bad}"),
            ));
        }
        fraction("svd_tol", svd_tol)?;
        fraction("rank_tol", rank_tol)?;
        if max_size == Some(0) {
            return Err(Error::param(
                "max_size",
                "must be at least 1 (0 means no cap)",
            ));
        }
        if !(band_factor.is_finite() && band_factor >= 1.0) {
            return Err(Error::param(
                "band_factor",
                format!("must be a finite number >= 1, got {band_factor}"),
            ));
        }
        Ok(Self {
            snapshots,
            svd_tol,
            max_size,
            band_factor,
            rank_tol,
        })
    }

    /// Reads the parameters of the module docs; unknown keys are refused.
    pub fn from_params(params: &Params) -> Result<Self> {
        let params = &params.tracked();
        let has = |k: &str| params.contains(k);
        let snapshots = if has("snapshot_count") || has("snapshot_range") {
            if has("snapshots") {
                return Err(Error::param(
                    "snapshots",
                    "give either `snapshots` or `snapshot_count` with `snapshot_range`, \
                     not both",
                ));
            }
            if !(has("snapshot_count") && has("snapshot_range")) {
                return Err(Error::param(
                    if has("snapshot_count") {
                        "snapshot_range"
                    } else {
                        "snapshot_count"
                    },
                    "`snapshot_count` and `snapshot_range` go together",
                ));
            }
            let count = params.usize_or("snapshot_count", 0)?;
            let range = params.list_or("snapshot_range", &[])?;
            evenly_spaced(count, &range)?
        } else {
            match params.get("snapshots") {
                None => DEFAULT_SNAPSHOTS.to_vec(),
                Some(ParamValue::Num(x)) => vec![*x],
                Some(_) => params.list_or("snapshots", &[])?,
            }
        };
        let max_size = match params.usize_or("max_size", 0)? {
            0 => None,
            m => Some(m),
        };
        let basis = Self::new(
            snapshots,
            params.num_or("svd_tol", DEFAULT_SVD_TOL)?,
            max_size,
            params.num_or("band_factor", DEFAULT_BAND_FACTOR)?,
            params.num_or("rank_tol", DEFAULT_RANK_TOL)?,
        )?;
        params.refuse_unread("basis", NAME)?;
        Ok(basis)
    }
}

/// `count` values evenly spaced over `range = [lo, hi]`, both ends included.
fn evenly_spaced(count: usize, range: &[f64]) -> Result<Vec<f64>> {
    let [lo, hi] = range else {
        return Err(Error::param(
            "snapshot_range",
            format!("expected two numbers `lo,hi`, got {range:?}"),
        ));
    };
    if !(lo.is_finite() && hi.is_finite() && lo <= hi) {
        return Err(Error::param(
            "snapshot_range",
            format!("expected finite lo <= hi, got {lo}, {hi}"),
        ));
    }
    match count {
        0 => Err(Error::param("snapshot_count", "must be at least 1")),
        1 => Ok(vec![0.5 * (lo + hi)]),
        _ => Ok((0..count)
            .map(|i| lo + (hi - lo) * i as f64 / (count - 1) as f64)
            .collect()),
    }
}

impl ReductionBasis for PodBasis {
    fn name(&self) -> &str {
        NAME
    }

    fn build(&self, request: &BasisRequest<'_>) -> Result<Basis> {
        let start = Instant::now();
        let op = request.op;
        let n = op.dim();
        let (fmin, fmax) = request.band_hz;
        let params = EigenParams {
            fmin_hz: fmin / self.band_factor,
            fmax_hz: fmax * self.band_factor,
            ..request.params.clone()
        };
        let mut notes = Vec::new();
        let mut snapshots = Vec::with_capacity(self.snapshots.len());
        let mut total = 0;
        for &mu in &self.snapshots {
            let t = Instant::now();
            let modes = request.modal.solve_frictional(op, mu, &params)?;
            let dt = t.elapsed().as_secs_f64();
            total += modes.len();
            let worst = modes.backward_error.iter().fold(0.0f64, |a, &b| a.max(b));
            notes.push(format!(
                "{NAME}: snapshot mu = {mu}: {} modes in [{:.1}, {:.1}] Hz by `{}` in \
                 {dt:.3} s (largest backward error {worst:.1e})",
                modes.len(),
                params.fmin_hz,
                params.fmax_hz,
                modes.info.solver
            ));
            snapshots.push(modes);
        }
        let snapshot_s = start.elapsed().as_secs_f64();
        if total == 0 {
            return Err(Error::Invalid(format!(
                "{NAME}: no mode in [{:.1}, {:.1}] Hz at any snapshot mu {:?}: nothing to \
                 build a basis from",
                params.fmin_hz, params.fmax_hz, self.snapshots
            )));
        }
        let t = Instant::now();
        let mut s = Mat::<f64>::zeros(n, 2 * total);
        let mut c = 0;
        for modes in &snapshots {
            for j in 0..modes.len() {
                for r in 0..n {
                    let z = modes.vectors[(r, j)];
                    s[(r, c)] = z.re;
                    s[(r, c + 1)] = z.im;
                }
                c += 2;
            }
        }
        let svd = s.thin_svd().map_err(|e| {
            Error::Invalid(format!(
                "{NAME}: thin SVD of the {n} x {} snapshot matrix failed: {e:?}",
                2 * total
            ))
        })?;
        let sig = svd.S();
        let sigma: Vec<f64> = (0..sig.dim()).map(|i| sig[i]).collect();
        let smax = sigma.iter().fold(0.0f64, |a, &b| a.max(b));
        // largest first (faer's order already; sorted again so that the cap keeps the
        // dominant directions whatever the backend)
        let mut keep: Vec<usize> = (0..sigma.len())
            .filter(|&i| sigma[i] > self.svd_tol * smax)
            .collect();
        keep.sort_by(|&a, &b| sigma[b].total_cmp(&sigma[a]));
        let by_tol = keep.len();
        if let Some(cap) = self.max_size {
            keep.truncate(cap);
        }
        let first_dropped = (0..sigma.len())
            .filter(|i| !keep.contains(i))
            .map(|i| sigma[i])
            .fold(0.0f64, f64::max);
        let u = svd.U();
        let ur = Mat::from_fn(n, keep.len(), |i, j| u[(i, keep[j])]);
        let svd_s = t.elapsed().as_secs_f64();
        let (v, dropped_rank) = m_orthonormalize(op.mc.as_ref(), ur.as_ref(), self.rank_tol)?;
        let mut basis = Basis::new(v);
        basis.dropped = 2 * total - basis.len();
        notes.insert(
            0,
            format!(
                "{NAME}: {} vectors from {} snapshot modes ({} columns) at mu = {:?}: {by_tol} \
                 singular values above {:.1e} sigma_1{}, largest dropped sigma / sigma_1 = \
                 {:.2e}, {dropped_rank} removed by the rank cut; build cost: snapshot solves \
                 {snapshot_s:.3} s, SVD {svd_s:.3} s",
                basis.len(),
                total,
                2 * total,
                self.snapshots,
                self.svd_tol,
                self.max_size
                    .map_or(String::new(), |m| format!(", capped at {m}")),
                if smax > 0.0 {
                    first_dropped / smax
                } else {
                    0.0
                },
            ),
        );
        basis.notes = notes;
        Ok(basis)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parameters_are_read_checked_and_unknown_keys_refused() {
        let p = PodBasis::from_params(&Params::new()).unwrap();
        assert_eq!(p.snapshots, DEFAULT_SNAPSHOTS.to_vec());
        assert_eq!(p.max_size, None);
        let (k, v) = Params::parse_kv("snapshots=0,0.25,0.5").unwrap();
        let p = PodBasis::from_params(&Params::new().with(&k, v)).unwrap();
        assert_eq!(p.snapshots, vec![0.0, 0.25, 0.5]);
        let p = PodBasis::from_params(&Params::new().with_num("snapshots", 0.3)).unwrap();
        assert_eq!(p.snapshots, vec![0.3]);
        let (k, v) = Params::parse_kv("snapshot_range=0.2,0.8").unwrap();
        let p = PodBasis::from_params(
            &Params::new()
                .with(&k, v.clone())
                .with_num("snapshot_count", 4.0)
                .with_num("max_size", 30.0),
        )
        .unwrap();
        assert_eq!(p.snapshots.len(), 4);
        assert!((p.snapshots[1] - 0.4).abs() <= 1e-15 && (p.snapshots[3] - 0.8).abs() <= 1e-15);
        assert_eq!(p.max_size, Some(30));
        // typo, mixed forms, a lone count, bad values: all refused with the key named
        let bad = [
            Params::new().with_num("svd_tolerance", 1e-6),
            Params::new()
                .with_num("snapshots", 0.1)
                .with_num("snapshot_count", 3.0)
                .with(&k, v.clone()),
            Params::new().with_num("snapshot_count", 3.0),
            Params::new().with_num("svd_tol", 1.5),
            Params::new().with_num("band_factor", 0.5),
            Params::new().with_num("snapshot_count", 0.0).with(&k, v),
        ];
        for (i, p) in bad.iter().enumerate() {
            let e = PodBasis::from_params(p).unwrap_err().to_string();
            assert!(e.contains("parameter"), "case {i}: {e}");
        }
        let e = PodBasis::from_params(&Params::new().with_num("svd_tolerance", 1e-6))
            .unwrap_err()
            .to_string();
        assert!(e.contains("svd_tolerance") && e.contains("svd_tol"), "{e}");
    }

    #[test]
    fn registered_fixed_in_mu() {
        let mut reg = Registry::new();
        register(&mut reg);
        assert!(reg.bases.names().contains(&NAME.to_string()));
        let b = reg.bases.create(NAME, &Params::new()).unwrap();
        assert!(!b.depends_on_mu());
        assert_eq!(b.name(), NAME);
    }
}
