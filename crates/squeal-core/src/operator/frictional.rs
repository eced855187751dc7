//! The constrained frictional operator of one contact set ([`FrictionalOperator`]).

use crate::linalg::add_scaled;
use crate::operator::Qep;
use crate::{Error, Result, SparseMat};
use std::sync::{Arc, OnceLock};

/// The constrained frictional operator of one contact set: the mu-independent parts
/// `X_c = T^T X T` and the friction parts `F_X`, kept apart so that
/// `X~_c(mu) = X_c - mu F_X` costs nothing per mu.
#[derive(Debug, Clone)]
pub struct FrictionalOperator {
    /// `M_c` (kg).
    pub mc: SparseMat,
    /// `C_c` (N s/m); `None` when undamped.
    pub cc: Option<SparseMat>,
    /// `K_c` (N/m).
    pub kc: SparseMat,
    /// Friction part of the mass.
    pub fm: SparseMat,
    /// Friction part of the damping; `None` when undamped.
    pub fc: Option<SparseMat>,
    /// Friction part of the stiffness.
    pub fk: SparseMat,
    /// The index map `T`: free DOF `j` of the unconstrained model is constrained DOF
    /// `t[j]` (an eliminated pin-normal DOF points at its disc partner). `None` when the
    /// operator was given directly (then the operator's DOFs are the full DOFs).
    pub t: Option<Vec<usize>>,
    /// The friction load directions `U = T^T P~t^T` (`n_c x nA`, one column per active
    /// pair: `+e_i` on the pin node's in-plane DOFs, `-e_i` on the disc node's), of which
    /// every friction part is a product `F_X = U V_X^T`. Reduction bases use them (static
    /// responses `K_c^-1 U`). `None` when unknown (an operator read from files);
    /// [`crate::reduction::friction_load_directions`] then recovers their span from `F_K`.
    pub friction_loads: Option<SparseMat>,
    /// The symmetric positive definite pair real modes and static responses are drawn
    /// from ([`RealModePair`], [`crate::reduction::real_mode_pair`]).
    pub modal: RealModePair,
}

/// Where the bases and the tracking of an operator take their real modes from: a
/// symmetric positive definite pair `(K_s, M_s)`.
///
/// An operator squeal assembles from a scene has symmetric `K_c`, `M_c`, positive
/// definite once the contact set's ties restrain the rigid-body motions ([`Own`]). An
/// operator read from files may have circulatory, gyroscopic-stiffness or negative
/// geometric terms in `K_c`, whose symmetric part is then indefinite: its pair is built on
/// first use ([`Lazy`]) from the pair its directory names (`[modal]` of an
/// `operator.toml`) or from the symmetric parts of `K_c` and `M_c`, shifted positive
/// definite by a value found from their inertia ([`crate::reduction::real_mode_pair`]).
///
/// [`Own`]: RealModePair::Own
/// [`Lazy`]: RealModePair::Lazy
#[derive(Debug, Clone, Default)]
pub enum RealModePair {
    /// `(K_c, M_c)` themselves, symmetric positive definite.
    #[default]
    Own,
    /// Built on first use and shared by the operator's clones.
    Lazy(Arc<LazyPair>),
}

impl RealModePair {
    /// A pair built on first use from `k` and `m` (`None`: the operator's own `K_c`,
    /// `M_c`), described by `source` in notes and outputs.
    pub fn lazy(k: Option<SparseMat>, m: Option<SparseMat>, source: impl Into<String>) -> Self {
        RealModePair::Lazy(Arc::new(LazyPair {
            k,
            m,
            source: source.into(),
            built: OnceLock::new(),
            factor: OnceLock::new(),
        }))
    }
}

/// The inputs of a pair built on first use ([`RealModePair::Lazy`]) and, once built, the
/// pair (or why it could not be built).
#[derive(Debug)]
pub struct LazyPair {
    /// The stiffness it starts from (`None`: `K_c`), N/m; its symmetric part is taken.
    pub k: Option<SparseMat>,
    /// The mass it starts from (`None`: `M_c`), kg; its symmetric part is taken.
    pub m: Option<SparseMat>,
    /// What `k` and `m` are (e.g. "`[modal]` of brake/operator.toml: K = K1, M = M").
    pub source: String,
    /// The pair, built by [`crate::reduction::real_mode_pair`].
    pub built: OnceLock<std::result::Result<Arc<ModalPair>, String>>,
    /// The Cholesky factor of the pair's `K_s`, built on first use by
    /// [`crate::reduction::energy_bounds`].
    pub factor: OnceLock<std::result::Result<Arc<crate::linalg::Cholesky>, String>>,
}

/// A symmetric positive definite pair `(K_s, M_s)` ([`RealModePair`]).
#[derive(Debug, Clone)]
pub struct ModalPair {
    /// `K_s` (N/m): the symmetric part of the pair's stiffness plus `shift M_s`, both
    /// triangles stored, positive definite.
    pub k: SparseMat,
    /// `M_s` (kg): the symmetric part of the pair's mass, both triangles stored.
    pub m: SparseMat,
    /// The shift (rad/s)^2 that made `K_s` definite (0 when it was): the pair's real
    /// modes are those of `(K_s, M_s)` with `omega^2 = omega_s^2 - shift`.
    pub shift: f64,
    /// Where it comes from and how it was made definite, for notes and outputs.
    pub source: String,
}

impl FrictionalOperator {
    /// Size of the constrained problem.
    pub fn dim(&self) -> usize {
        self.kc.nrows()
    }

    /// Number of DOFs of the unconstrained model (`dim()` when there is no map).
    pub fn full_dim(&self) -> usize {
        self.t.as_ref().map_or(self.dim(), |t| t.len())
    }

    /// Whether the operator has friction parts (a nonzero `F_M`, `F_C` or `F_K`): without
    /// them mu changes nothing.
    pub fn has_friction(&self) -> bool {
        self.fm.compute_nnz() > 0
            || self.fk.compute_nnz() > 0
            || self.fc.as_ref().is_some_and(|f| f.compute_nnz() > 0)
    }

    /// Checks what every operator of a structure satisfies, for operators read from
    /// files: `M_c` has a positive diagonal (a zero or negated mass is not a mass) and
    /// `K_c` a non-negative one (a negated stiffness). The error counts the offending
    /// diagonal entries and names the first.
    pub fn check_pencil(&self) -> Result<()> {
        for (name, mat, strict) in [("M_c", &self.mc, true), ("K_c", &self.kc, false)] {
            let n = mat.nrows();
            let mut diag = vec![0.0f64; n];
            let m = mat.as_ref();
            for j in 0..mat.ncols() {
                for (i, v) in m.row_idx_of_col(j).zip(m.val_of_col(j)) {
                    if i == j {
                        diag[j] += *v;
                    }
                }
            }
            let bad: Vec<usize> = (0..n)
                .filter(|&i| {
                    let d = diag[i];
                    !d.is_finite() || d < 0.0 || (strict && d == 0.0)
                })
                .collect();
            if let Some(&first) = bad.first() {
                return Err(Error::Invalid(format!(
                    "{name}: {} of {n} diagonal entries are {} (first: row {first}, {:e}): \
                     expected a {} matrix",
                    bad.len(),
                    if strict { "not positive" } else { "negative" },
                    diag[first],
                    if strict {
                        "positive definite mass"
                    } else {
                        "positive semi-definite stiffness"
                    }
                )));
            }
        }
        Ok(())
    }

    /// The QEP at friction coefficient `mu`: `X~ = X_c - mu F_X`.
    pub fn at(&self, mu: f64) -> Result<Qep> {
        if !mu.is_finite() {
            return Err(Error::param("mu", format!("must be finite, got {mu}")));
        }
        let comb = |x: &SparseMat, f: &SparseMat| add_scaled(x.as_ref(), 1.0, f.as_ref(), -mu);
        let c = match (&self.cc, &self.fc) {
            (Some(c), Some(f)) => Some(comb(c, f)?),
            (Some(c), None) => Some(c.clone()),
            (None, Some(f)) => Some(add_scaled(f.as_ref(), -mu, f.as_ref(), 0.0)?),
            (None, None) => None,
        };
        Ok(Qep {
            m: comb(&self.mc, &self.fm)?,
            c,
            k: comb(&self.kc, &self.fk)?,
        })
    }

    /// Expands a constrained vector to the unconstrained DOFs, `u = T u_c`.
    pub fn expand<T: Copy>(&self, uc: &[T]) -> Vec<T> {
        match &self.t {
            Some(t) => t.iter().map(|&j| uc[j]).collect(),
            None => uc.to_vec(),
        }
    }
}
